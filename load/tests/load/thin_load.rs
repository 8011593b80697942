//! Thin bots (the library behind `ledge-bot --brain thin`, which
//! `ledge-load --client thin` starts) against a real server in-process on
//! loopback: they join, send inputs, receive snapshots and leave, their
//! report lines are the ones `ledge-load` counts, and the server's metrics,
//! scraped over HTTP as `ledge-load` does, show their traffic and the fine
//! tick histogram. (`client/tests/headless/thin_bot.rs` runs the binary itself.)

use std::net::SocketAddr;
use std::time::Duration;

use ledge_client::bot::{run_thin, BotOptions, RandomWalker};
use ledge_client::Trust;
use ledge_load::prom::scrape;
use ledge_load::run::BotReports;
use ledge_server::{Server, ServerConfig};

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn thin_bots_play_and_the_metrics_show_it() {
    let cert_dir = tempfile::tempdir().unwrap();
    let config = ServerConfig {
        bind: SocketAddr::from(([127, 0, 0, 1], 0)),
        metrics_bind: Some(SocketAddr::from(([127, 0, 0, 1], 0))),
        cert_dir: cert_dir.path().to_owned(),
        ..ServerConfig::default()
    };
    let server = Server::bind(config).unwrap();
    let addr = server.local_addr().to_string();
    let metrics = server.metrics_addr().unwrap();
    let trust = Trust::Pinned(server.fingerprint());
    let shutdown = server.shutdown_handle();
    let task = tokio::spawn(server.run());

    let bots: Vec<_> = (1..=3u64)
        .map(|i| {
            let (addr, trust) = (addr.clone(), trust.clone());
            tokio::spawn(async move {
                let options = BotOptions::new(&format!("p1-{i}"), Duration::from_secs(2));
                run_thin(&addr, &trust, &mut RandomWalker::new(i), &options).await
            })
        })
        .collect();
    let mut output = String::new();
    for bot in bots {
        let report = tokio::time::timeout(Duration::from_secs(60), bot)
            .await
            .expect("the bots finish in time")
            .unwrap();
        assert_eq!(report.ended, None, "{report}");
        assert!(report.player.is_some(), "{report}");
        // 2 s at 60 Hz and 30 Hz, with room for a slow machine.
        assert!(report.ticks >= 60, "{report}");
        assert!(report.snapshots >= 15, "{report}");
        assert!(report.net.bytes_in_per_s > 0.0, "{report}");
        output.push_str(&format!("{report}\n"));
    }
    assert_eq!(
        BotReports::parse(&output),
        BotReports {
            reports: 3,
            ended: 0
        },
        "{output}"
    );

    let scraped = tokio::task::spawn_blocking(move || scrape(metrics).unwrap())
        .await
        .unwrap();
    // 3 clients x ~60 input datagrams (2 s, 30 a second) of 6 bytes or more.
    assert!(scraped.sum("ledge_bytes_in_total") > 3.0 * 50.0 * 6.0);
    // Each room samples its players' connections once a second.
    assert!(scraped.sum("ledge_wire_datagrams_in_total") >= 3.0 * 25.0);
    assert!(scraped.sum("ledge_wire_bytes_out_total") > scraped.sum("ledge_bytes_out_total"));
    assert!(scraped.sum("ledge_bytes_out_total") > 3.0 * 15.0 * 20.0);
    let ticks = scraped
        .histogram("ledge_tick_duration_fine_seconds")
        .unwrap();
    assert!(ticks.total() >= 60, "{}", ticks.total());
    let p99 = ticks.quantile(0.99).unwrap();
    assert!(p99 > 0.0 && p99 < 1.0, "{p99}");
    assert!(!scraped
        .histogram("ledge_tick_lateness_seconds")
        .unwrap()
        .is_empty());

    shutdown.shutdown();
    tokio::time::timeout(Duration::from_secs(10), task)
        .await
        .expect("server stops")
        .unwrap()
        .unwrap();
}
