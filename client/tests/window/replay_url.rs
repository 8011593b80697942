//! `ledge-client --replay http://HOST:PORT/replays/ID` through the real
//! binary, against a tiny web port on loopback (`replay_files::serve`):
//! the replay is fetched, its level downloaded from the same server,
//! checked and kept in the level cache (the next time it is found there);
//! a server without the replay, one refusing for a while (429,
//! Retry-After), one announcing more than any replay and no server at all
//! are each told in words, with exit code 2.

use std::net::TcpListener;
use std::path::Path;
use std::process::{Command, Output};
use std::time::Duration;

use crate::common::run_to_end;
use crate::replay_files::{record, serve, Answer};
use ledge_levels::{default_level, LevelBundle};
use ledge_shared::replay;

const TIMEOUT: Duration = Duration::from_secs(120);
const ID: &str = "00112233445566ff";

fn check(url: &str, cache: &Path) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_ledge-client"));
    command
        .args(["--replay", url, "--check", "--level-cache"])
        .arg(cache);
    run_to_end(command, TIMEOUT)
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn a_replay_from_a_server_comes_with_its_level_which_is_kept() {
    // The default level renamed: another bundle, which only the server has.
    let mut level = default_level();
    level.name = "Renamed".into();
    let bundle = LevelBundle {
        level,
        art: Default::default(),
    };
    let bundle_bytes = bundle.encode();
    let offer = LevelBundle::offer(&bundle_bytes);
    let rec = record(&bundle.level, offer, 900);
    let file = replay::encode(&rec.replay()).unwrap();
    let cache = tempfile::tempdir().unwrap();
    let addr = serve(
        vec![
            (format!("/replays/{ID}"), Answer::Bytes(file.clone())),
            (
                format!("/levels/{}", offer.hex()),
                Answer::Bytes(bundle_bytes.clone()),
            ),
        ],
        2,
    );
    let url = format!("http://{addr}/replays/{ID}");
    let out = check(&url, cache.path());
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stdout).starts_with("replay OK: 900 ticks"));
    let kept = cache.path().join(format!("{}.bundle", offer.hex()));
    assert_eq!(
        std::fs::read(&kept).unwrap(),
        bundle_bytes,
        "kept in the cache"
    );

    // The next time, the level comes from the cache: the server serves
    // the replay only.
    let addr = serve(vec![(format!("/replays/{ID}"), Answer::Bytes(file))], 1);
    let out = check(&format!("http://{addr}/replays/{ID}"), cache.path());
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
}

#[test]
fn a_level_the_server_sends_wrong_is_refused() {
    let mut level = default_level();
    level.name = "Renamed".into();
    let bundle = LevelBundle {
        level,
        art: Default::default(),
    };
    let bytes = bundle.encode();
    let offer = LevelBundle::offer(&bytes);
    let rec = record(&bundle.level, offer, 120);
    let mut wrong = bytes.clone();
    let last = wrong.len() - 1;
    wrong[last] ^= 1;
    let cache = tempfile::tempdir().unwrap();
    let addr = serve(
        vec![
            (
                format!("/replays/{ID}"),
                Answer::Bytes(replay::encode(&rec.replay()).unwrap()),
            ),
            (format!("/levels/{}", offer.hex()), Answer::Bytes(wrong)),
        ],
        2,
    );
    let out = check(&format!("http://{addr}/replays/{ID}"), cache.path());
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(&offer.hex()), "{stderr}");
    assert!(
        !cache
            .path()
            .join(format!("{}.bundle", offer.hex()))
            .exists(),
        "a wrong level is not kept"
    );
}

#[test]
fn a_server_without_the_replay_or_refusing_says_so() {
    let cache = tempfile::tempdir().unwrap();
    let max = ledge_shared::replay::MAX_REPLAY_BYTES + ledge_shared::replay::file::HEADER_LEN;
    let addr = serve(
        vec![
            ("/replays/aaaaaaaaaaaaaaaa".into(), Answer::TooMany(7)),
            (
                "/replays/bbbbbbbbbbbbbbbb".into(),
                Answer::Claims(max as u64 + 1),
            ),
        ],
        3,
    );
    let cases = [
        (
            "cccccccccccccccc",
            "the server has no such replay (404 Not Found): check its ID",
        ),
        (
            "aaaaaaaaaaaaaaaa",
            "(429 Too Many Requests): try again in 7 s",
        ),
        (
            "bbbbbbbbbbbbbbbb",
            &format!("more than a replay can be ({max} bytes)"),
        ),
    ];
    for (id, said) in cases {
        let out = check(&format!("http://{addr}/replays/{id}"), cache.path());
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{id}: {stderr}");
        assert!(stderr.contains(said), "{id}: {stderr}");
    }
    // Nothing listening there.
    let port = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let out = check(
        &format!("http://127.0.0.1:{port}/replays/{ID}"),
        cache.path(),
    );
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("check the address and port"), "{stderr}");
    // Not a replay's address.
    let out = check(
        &format!("https://127.0.0.1:{port}/replays/{ID}"),
        cache.path(),
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("plain HTTP"),
        "{}",
        text(&out.stderr)
    );
}

/// The real thing: a server's web port serves the replay of a run a bot
/// just finished there, and the client checks it to the server's hashes.
#[test]
fn a_run_finished_on_a_server_checks_out_from_its_web_port() {
    let page = tempfile::tempdir().unwrap();
    let server = crate::common::TestServer::start_with(|c| {
        let mut web = ledge_server::config::WebConfig::new(([127, 0, 0, 1], 0).into());
        web.root = page.path().to_owned();
        web.webtransport = None;
        c.web = Some(web);
    });
    let bob = server.runner_to_goal("bob");
    assert!(matches!(bob.standing, Some(Ok(_))), "bob's run: {bob}");
    // His run's replay, by the id the records keep (the file's name).
    let (id, _) = crate::common::run_replay(server.cert_dir(), "bob");
    let web = server.web_addr.expect("a web port");
    let cache = tempfile::tempdir().unwrap();
    let out = check(&format!("http://{web}/replays/{id}"), cache.path());
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(stdout.starts_with("replay OK: "), "{stdout}");
    server.stop();
}
