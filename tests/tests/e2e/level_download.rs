//! Thin clients need nothing but an address: a server running a real Tiled
//! map (Tiled's platformer example, Sticker Knight, with its images) offers
//! its level bundle in the `Welcome`; a client with an empty cache
//! downloads it and plays, the next join uses the cache; a cut download
//! resumes where it stopped; a tampered download or cached file is refused
//! (or replaced); a level too big for the server's cap stops the server at
//! start, saying what to do.

use std::path::{Path, PathBuf};
use std::time::Duration;

use ledge_client::bot::{BotOptions, RandomWalker};
use ledge_client::net::bundle::{fetch_level, FetchOptions, LevelCache};
use ledge_client::ClientError;
use ledge_levels::bundle::sha256;
use ledge_server::levels::LevelLoadError;
use ledge_server::{Server, ServerConfig, ServerError};
use ledge_tests::e2e::{bot_options, spawn_bot};
use ledge_tests::{corpus_file, metric, TestServer};

/// Tiled's platformer example map (images beside it, in the same folder).
const STICKER_KNIGHT: &str = "tiled-examples/sticker-knight/map/sandbox2.tmx";

fn downloads(server: &TestServer) -> (f64, f64, f64) {
    let m = server.metrics();
    (
        metric(&m, "ledge_level_downloads_total"),
        metric(&m, "ledge_level_downloads_completed_total"),
        metric(&m, "ledge_level_download_bytes_total"),
    )
}

async fn level_server(map: &Path) -> TestServer {
    let map = map.to_owned();
    TestServer::start_with(move |c| c.levels = vec![map]).await
}

fn cache_options(dir: &Path) -> FetchOptions {
    FetchOptions {
        cache: Some(LevelCache::new(dir)),
        cut_after: None,
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_downloads_a_level_it_never_saw_plays_it_then_uses_its_cache() {
    let Some(map) = corpus_file(STICKER_KNIGHT) else {
        return;
    };
    let server = level_server(&map).await;
    let cache = tempfile::tempdir().unwrap();
    let play = |name: &str| {
        let options = BotOptions {
            level_cache: Some(cache.path().to_owned()),
            ..bot_options(name, Duration::from_secs(3))
        };
        let server = &server;
        async move {
            let session = server.join(&options.name).await;
            let offer = session.welcome().level;
            let (report, _) = spawn_bot(session, RandomWalker::new(7), options)
                .await
                .expect("the bot did not panic");
            (report, offer)
        }
    };

    let (first, offer) = play("newcomer").await;
    assert_eq!(first.ended, None, "{first}");
    let fetched = first.level.expect("the level was fetched");
    assert!(!fetched.cached && !fetched.embedded, "{fetched:?}");
    assert_eq!((fetched.downloaded, fetched.resumed_from), (offer.size, 0));
    // It played the downloaded level: ticks, snapshots, and predictions
    // the server agreed with.
    assert!(first.ticks > 60 && first.snapshots > 30, "{first}");
    assert_eq!(first.mispredictions, 0, "{first}");
    let cached = LevelCache::new(cache.path()).bundle_path(&offer);
    assert_eq!(sha256(&std::fs::read(&cached).unwrap()), offer.sha256);
    assert_eq!(downloads(&server), (1.0, 1.0, offer.size as f64));
    // The bundle carries the map's art: its images travelled too.
    assert!(offer.size > 50_000, "{offer:?}");

    let (second, _) = play("regular").await;
    assert_eq!(second.ended, None, "{second}");
    assert!(second.level.expect("fetched").cached);
    assert_eq!(
        downloads(&server),
        (1.0, 1.0, offer.size as f64),
        "no download"
    );
    server.stop().await.expect("clean stop");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_cut_download_resumes_and_a_tampered_one_is_downloaded_again() {
    let Some(map) = corpus_file(STICKER_KNIGHT) else {
        return;
    };
    let server = level_server(&map).await;
    let dir = tempfile::tempdir().unwrap();
    let cache = LevelCache::new(dir.path());

    // Cut halfway (the client drops the stream as if the link died).
    let mut session = server.join("cut").await;
    let offer = session.welcome().level;
    let half = offer.size / 2;
    let cut = FetchOptions {
        cut_after: Some(half),
        ..cache_options(dir.path())
    };
    let err = fetch_level(&mut session, &cut, |_, _| {})
        .await
        .expect_err("cut short");
    assert!(matches!(err, ClientError::LevelDownload(_)), "{err}");
    session.close().await;
    let part = std::fs::metadata(cache.part_path(&offer)).unwrap().len();
    assert!(
        part >= half && part < offer.size,
        "{part} of {}",
        offer.size
    );

    // The next join resumes from there, and only the rest is sent.
    let mut session = server.join("resumed").await;
    let sent_before = downloads(&server).2;
    let (bundle, fetched) = fetch_level(&mut session, &cache_options(dir.path()), |_, _| {})
        .await
        .expect("the download resumes");
    assert_eq!(fetched.resumed_from, part);
    assert_eq!(fetched.downloaded, offer.size - part);
    assert_eq!(
        downloads(&server).2 - sent_before,
        (offer.size - part) as f64
    );
    assert!(!bundle.art.images.is_empty(), "the map's images came along");
    session.close().await;

    // A damaged cached bundle is noticed and downloaded again.
    let path = cache.bundle_path(&offer);
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[10] ^= 0xff;
    std::fs::write(&path, &bytes).unwrap();
    let mut session = server.join("damaged").await;
    let (_, fetched) = fetch_level(&mut session, &cache_options(dir.path()), |_, _| {})
        .await
        .expect("downloaded again");
    assert!(!fetched.cached && fetched.downloaded == offer.size);
    session.close().await;

    // A tampered partial download: the whole does not hash to the offer,
    // so the part is thrown away and the level downloaded again from the
    // start (a part another client sharing the cache wrote into looks the
    // same); what is cached is the level itself.
    std::fs::remove_file(&path).unwrap();
    std::fs::write(cache.part_path(&offer), vec![0u8; half as usize]).unwrap();
    let mut session = server.join("tampered").await;
    let (_, fetched) = fetch_level(&mut session, &cache_options(dir.path()), |_, _| {})
        .await
        .expect("downloaded again from the start");
    assert_eq!((fetched.resumed_from, fetched.downloaded), (0, offer.size));
    assert!(!cache.part_path(&offer).exists());
    assert_eq!(sha256(&std::fs::read(&path).unwrap()), offer.sha256);
    session.close().await;
    server.stop().await.expect("clean stop");
}

/// Writes `pixels` (RGBA, `side` x `side`) as a PNG at `path`.
pub(crate) fn write_png(path: &Path, side: u32, pixels: &[u8]) {
    let file = std::fs::File::create(path).unwrap();
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), side, side);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().unwrap();
    writer.write_image_data(pixels).unwrap();
    writer.finish().unwrap();
}

/// Writes a map whose tileset image is `side` x `side` pixels of noise
/// (which no PNG compresses): `side * side * 4` bytes of image.
pub(crate) fn noisy_map(dir: &Path, side: u32) -> PathBuf {
    let mut pixels = Vec::with_capacity((side * side * 4) as usize);
    let mut x = 0x2545_f491_4f6c_dd1du64;
    for _ in 0..side * side * 4 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        pixels.push(x as u8);
    }
    write_png(&dir.join("noise.png"), side, &pixels);
    let map = dir.join("big.tmx");
    std::fs::write(
        &map,
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<map version="1.10" orientation="orthogonal" renderorder="right-down" width="4" height="3" tilewidth="16" tileheight="16" infinite="0" nextlayerid="2" nextobjectid="1">
 <tileset firstgid="1" name="noise" tilewidth="16" tileheight="16" tilecount="{n}" columns="{c}">
  <image source="noise.png" width="{side}" height="{side}"/>
 </tileset>
 <layer id="1" name="ground" width="4" height="3">
  <data encoding="csv">
0,0,0,0,
0,0,0,0,
1,1,1,1
</data>
 </layer>
</map>
"#,
            c = side / 16,
            n = (side / 16) * (side / 16),
        ),
    )
    .unwrap();
    map
}

#[tokio::test]
async fn a_level_bigger_than_the_cap_stops_the_server_at_start() {
    let dir = tempfile::tempdir().unwrap();
    // About 1.2 MiB of image: over a 1 MiB cap, under the default 32.
    let map = noisy_map(dir.path(), 560);
    let config = |cap| ServerConfig {
        bind: "127.0.0.1:0".parse().unwrap(),
        cert_dir: dir.path().join("certs"),
        levels: vec![map.clone()],
        max_level_mib: cap,
        ..ServerConfig::default()
    };
    match Server::bind(config(1)) {
        Err(e @ ServerError::Level(LevelLoadError::TooLarge { .. })) => {
            let text = e.to_string();
            assert!(text.contains("--max-level-mib"), "{text}");
            assert!(text.contains("1 MiB"), "{text}");
        }
        other => panic!("expected LevelTooLarge, got {:?}", other.map(|_| ())),
    }
    let server = Server::bind(config(2)).expect("fits 2 MiB");
    assert!(server.level_offer().size > 1 << 20);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn clients_sharing_a_cache_download_one_level_at_once_and_the_cache_stays_sound() {
    // Every client of a room fetches a new level at the same moment: on
    // one machine (bots, two windows) they share the level cache.
    let dir = tempfile::tempdir().unwrap();
    let map = noisy_map(dir.path(), 400);
    let server = level_server(&map).await;
    let cache_dir = tempfile::tempdir().unwrap();
    let mut sessions = Vec::new();
    for name in ["c1", "c2", "c3"] {
        sessions.push(server.join(name).await);
    }
    let offer = sessions[0].welcome().level;
    let fetches = sessions.iter_mut().map(|s| {
        let options = cache_options(cache_dir.path());
        async move { fetch_level(s, &options, |_, _| {}).await }
    });
    for result in futures_util::future::join_all(fetches).await {
        let (bundle, _) = result.expect("each client gets the level");
        assert_eq!(bundle.level.name, "big");
    }
    // Whatever was cached is the level itself, never the downloads mixed.
    let cache = LevelCache::new(cache_dir.path());
    let cached = cache.bundle_path(&offer);
    if cached.exists() {
        assert_eq!(sha256(&std::fs::read(&cached).unwrap()), offer.sha256);
    }
    assert!(!cache.part_path(&offer).exists(), "no part file left");
    let mut later = server.join("c4").await;
    let (bundle, _) = fetch_level(&mut later, &cache_options(cache_dir.path()), |_, _| {})
        .await
        .expect("and a later client too");
    assert_eq!(bundle.level.name, "big");
    server.stop().await.unwrap();
}
