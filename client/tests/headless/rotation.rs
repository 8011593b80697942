//! Level rotation against a real server in-process on loopback (two
//! levels, votes by majority): `OnlineGame` votes, downloads the room's
//! next level and makes its game anew; `ledge-bot --vote` moves the room,
//! and its runner plays on there, its report line saying which levels it
//! played and the runs it finished on each.

use crate::common;

use std::process::Command;
use std::time::{Duration, Instant};

use common::{run_to_end, TestServer};
use ledge_client::net::background::NetStatus;
use ledge_client::{OnlineGame, OnlineRequest, Trust};
use ledge_shared::input::Buttons;

/// Plays `online` idle until `done` says so (or `within` passes).
fn play_until(
    online: &mut OnlineGame,
    within: Duration,
    mut done: impl FnMut(&OnlineGame) -> bool,
) {
    let deadline = Instant::now() + within;
    while !done(online) {
        assert!(
            Instant::now() < deadline,
            "not in time: {} (error {:?})",
            online.status(),
            online.error()
        );
        online.update(Instant::now(), Buttons::NONE);
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn a_vote_moves_the_room_and_the_online_game_follows_to_the_next_level() {
    let dir = tempfile::tempdir().unwrap();
    let cache = tempfile::tempdir().unwrap();
    let server = TestServer::rotating(dir.path());
    let request = OnlineRequest {
        level_cache: Some(cache.path().to_owned()),
        ..OnlineRequest::new(
            &server.addr.to_string(),
            Trust::Pinned(server.fingerprint),
            "ada",
        )
    };
    let mut online = OnlineGame::connect(request).unwrap();
    online.wait(Duration::from_secs(20));
    let within = Duration::from_secs(20);
    play_until(&mut online, within, |o| {
        o.levels().is_some() && o.game().is_some_and(|g| g.synced())
    });
    let list = online.levels().unwrap().clone();
    assert_eq!(list.levels.len(), 2);
    assert_eq!((list.current, list.change_at), (0, None));
    assert_eq!(online.level().map(|l| l.name.as_str()), Some("default"));
    assert!(!online.vote(2), "no such level");
    // Alone in the room: our vote is the majority.
    assert!(online.vote(1));
    play_until(&mut online, within, |o| {
        o.levels().is_some_and(|l| l.change_at.is_some())
    });
    let left = online.next_level_in().expect("the change is announced");
    assert!(left <= Duration::from_secs(2), "{left:?}");

    play_until(&mut online, within, |o| {
        o.level_changes() == 1 && o.game().is_some_and(|g| g.synced())
    });
    assert_eq!(online.error(), None);
    assert_eq!(online.level().map(|l| l.name.as_str()), Some("second"));
    assert_eq!(online.changing_level(), None);
    let fetched = online
        .level_fetched()
        .expect("the second level was fetched");
    assert!(!fetched.embedded, "{fetched:?}");
    let welcome = online.game().and_then(|g| g.welcome()).unwrap().clone();
    assert_eq!(welcome.level_id, "second");
    assert!(matches!(online.status(), NetStatus::Connected { welcome: w, .. } if *w == welcome));
    // Our player is back in the game, on the new level's ticks.
    play_until(&mut online, within, |o| {
        o.view().is_some_and(|v| v.local.is_some())
            && o.server_state()
                .is_some_and(|s| s.tick >= welcome.server_tick)
    });
    play_until(&mut online, within, |o| {
        o.levels().is_some_and(|l| l.current == 1)
    });
    drop(online);
    server.stop();
}

#[test]
fn a_voting_runner_bot_plays_the_next_level_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let cache = tempfile::tempdir().unwrap();
    let server = TestServer::rotating(dir.path());
    let mut command = Command::new(env!("CARGO_BIN_EXE_ledge-bot"));
    command
        .args(["--connect", &server.addr.to_string()])
        .args(["--cert-hash", &server.fingerprint.to_string()])
        .args(["--brain", "runner", "--count", "1", "--seconds", "25"])
        .args(["--vote", "1", "--margin", "4"])
        .arg("--level-cache")
        .arg(cache.path())
        .args(["--name", "rot"])
        .env("RUST_LOG", "warn");
    let out = run_to_end(command, Duration::from_secs(90));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{}\n{stdout}\n{stderr}", out.status);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("rot-1"))
        .unwrap_or_else(|| panic!("no report line: {stdout}"));
    assert!(!line.contains("ended:"), "{line}");
    assert!(
        line.contains(r#"vote: voted for level 1 ("second")"#),
        "{line}"
    );
    // Moved to the second level by its vote (before the first was run),
    // it finished it; the room then moved back to the first.
    assert!(
        line.contains(r#"levels: "default" finished 0, "second" finished 1, "default""#),
        "{line}"
    );
    server.stop();
}

/// A UDP relay on loopback to `server` that can drop everything both ways
/// (`cut`): a dead link. Each client address gets a socket of its own
/// toward the server (a reconnecting client dials from a new port).
async fn relay(
    server: std::net::SocketAddr,
    cut: std::sync::Arc<std::sync::atomic::AtomicBool>,
) -> std::net::SocketAddr {
    use std::collections::HashMap;
    use std::sync::atomic::Ordering;
    use std::sync::Arc;
    use tokio::net::UdpSocket;
    let front = Arc::new(UdpSocket::bind("127.0.0.1:0").await.unwrap());
    let addr = front.local_addr().unwrap();
    tokio::spawn(async move {
        let mut ups: HashMap<std::net::SocketAddr, Arc<UdpSocket>> = HashMap::new();
        let mut buf = vec![0u8; 65536];
        while let Ok((n, from)) = front.recv_from(&mut buf).await {
            if cut.load(Ordering::Relaxed) {
                continue;
            }
            let up = match ups.get(&from) {
                Some(up) => up.clone(),
                None => {
                    let up = Arc::new(UdpSocket::bind("127.0.0.1:0").await.unwrap());
                    up.connect(server).await.unwrap();
                    let (back, front, cut) = (up.clone(), front.clone(), cut.clone());
                    tokio::spawn(async move {
                        let mut buf = vec![0u8; 65536];
                        while let Ok(n) = back.recv(&mut buf).await {
                            if !cut.load(Ordering::Relaxed) {
                                let _ = front.send_to(&buf[..n], from).await;
                            }
                        }
                    });
                    ups.insert(from, up.clone());
                    up
                }
            };
            let _ = up.send(&buf[..n]).await;
        }
    });
    addr
}

/// The host of the room (it joined first): plays idle, votes for the
/// level it is told, and leaves two seconds after the level change (or
/// after `within`); returns the change it saw.
async fn host(
    server: std::net::SocketAddr,
    fingerprint: ledge_client::Fingerprint,
    vote: tokio::sync::oneshot::Receiver<u32>,
    within: Duration,
) -> Option<ledge_shared::protocol::Welcome> {
    use ledge_client::{InputClock, SessionEvent};
    let mut bob = ledge_client::connect(server, "localhost", fingerprint, "bob")
        .await
        .expect("bob is welcomed");
    let clock = InputClock::new(bob.welcome(), Instant::now());
    let mut deadline = tokio::time::Instant::now() + within;
    let mut vote = Some(vote);
    let mut changed = None;
    while tokio::time::Instant::now() < deadline {
        let _ = bob.send_input(clock.input_tick(Instant::now()), Buttons::NONE);
        if let Some(level) = vote.as_mut().and_then(|v| v.try_recv().ok()) {
            bob.vote(level).await.expect("bob's vote goes");
            vote = None;
        }
        let wait = clock.until_next_tick(Instant::now());
        if let Ok(event) = tokio::time::timeout(wait, bob.recv()).await {
            if let SessionEvent::LevelChange(w) = event.expect("bob's session holds") {
                changed = Some(w);
                deadline = deadline.min(tokio::time::Instant::now() + Duration::from_secs(2));
            }
        }
    }
    bob.close().await;
    changed
}

/// The room moves on while our link is dead: the background thread
/// resumes the session on the new level, fetches it and reports the
/// change, and the online game plays on there.
#[test]
fn a_session_resumed_after_the_room_moved_on_follows_it_to_the_new_level() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let dir = tempfile::tempdir().unwrap();
    let cache = tempfile::tempdir().unwrap();
    let server = TestServer::rotating_with(dir.path(), ledge_shared::protocol::VoteRule::Host);
    let cut = Arc::new(AtomicBool::new(false));
    let through = server.block_on(relay(server.addr, cut.clone()));
    let (vote, told) = tokio::sync::oneshot::channel();
    let (addr, pin) = (server.addr, server.fingerprint);
    let bob = std::thread::spawn(move || {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        runtime.block_on(host(addr, pin, told, Duration::from_secs(45)))
    });
    std::thread::sleep(Duration::from_millis(500));
    let request = OnlineRequest {
        level_cache: Some(cache.path().to_owned()),
        ..OnlineRequest::new(&through.to_string(), Trust::Pinned(pin), "ada")
    };
    let mut online = OnlineGame::connect(request).unwrap();
    online.wait(Duration::from_secs(20));
    let within = Duration::from_secs(30);
    play_until(&mut online, within, |o| {
        o.levels().is_some() && o.game().is_some_and(|g| g.synced())
    });
    assert_eq!(online.level().map(|l| l.name.as_str()), Some("default"));

    // The link dies; the host moves the room on meanwhile.
    cut.store(true, Ordering::Relaxed);
    vote.send(1).unwrap();
    play_until(&mut online, within, |o| {
        matches!(o.status(), NetStatus::Reconnecting { .. })
    });
    assert_eq!(online.level_changes(), 0, "the change never reached us");
    cut.store(false, Ordering::Relaxed);
    play_until(&mut online, within, |o| {
        o.level_changes() == 1
            && matches!(o.status(), NetStatus::Connected { .. })
            && o.view().is_some_and(|v| v.local.is_some())
    });
    assert_eq!(online.error(), None);
    assert_eq!(online.level().map(|l| l.name.as_str()), Some("second"));
    let welcome = online.game().and_then(|g| g.welcome()).unwrap().clone();
    assert_eq!(welcome.level_id, "second");
    drop(online);
    let seen = bob.join().unwrap().expect("bob saw the change");
    assert_eq!(seen.level_id, "second");
    server.stop();
}
