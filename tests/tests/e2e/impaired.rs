//! The client over an impaired network (a relay adding loss, delay and
//! jitter): the figures are measured, the clock keeps inputs on time, the
//! prediction stays exact, and remote players play out of a deeper buffer.

use std::time::{Duration, Instant};

use ledge_client::bot::{run_bot, BotOptions, RandomWalker};
use ledge_shared::input::Buttons;
use ledge_tests::{starvation, Impairment, PredictedClient, TestServer, UdpRelay};

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn loss_delay_and_jitter_are_measured_and_prediction_stays_exact() {
    let server = TestServer::start().await;
    // Someone to watch: a random walker, unimpaired.
    let other = server.join("other").await;
    let walker = tokio::spawn(async move {
        let mut brain = RandomWalker::new(3);
        run_bot(
            other,
            &mut brain,
            &BotOptions::new("other", Duration::from_secs(9)),
        )
        .await
    });
    let relay = UdpRelay::start(server.addr).await;
    let mut c = PredictedClient::join_via(&server, relay.addr, "impaired", 1.0).await;
    relay.impair(Impairment {
        loss_up: 0.1,
        loss_down: 0.1,
        delay: Duration::from_millis(20),
        jitter: Duration::from_millis(15),
    });
    let script = |tick: u64| {
        Buttons(match tick % 120 {
            0..=40 => Buttons::RIGHT,
            41..=50 => Buttons::JUMP,
            51..=95 => Buttons::LEFT,
            _ => 0,
        })
    };
    // Warm up: the clock and the buffers adapt.
    c.run(
        Instant::now() + Duration::from_secs(3),
        |_, t| (script(t), true),
        |_, _, _| {},
    )
    .await;
    let starved_before = starvation(&server, "room-1");
    let mispredicted_before = c.game.predictor().stats().mispredictions;
    let underruns_before = c.game.interpolator().stats().underruns;
    let mut max_delay: f64 = 0.0;
    let mut remote_seen = 0;
    c.run(
        Instant::now() + Duration::from_secs(5),
        |game, t| {
            remote_seen += game.view().remotes.len().min(1);
            max_delay = max_delay.max(game.interpolator().delay());
            (script(t), true)
        },
        |_, _, _| {},
    )
    .await;
    let now = Instant::now();
    let net = c.game.net_stats(now);
    let stats = c.game.predictor().stats();
    let interp = c.game.interpolator().stats();
    let starved = starvation(&server, "room-1") - starved_before;
    let mispredicted = stats.mispredictions - mispredicted_before;
    eprintln!("{net:?}");
    eprintln!("{stats:?}, {interp:?}, starved {starved}, max interp delay {max_delay:.2} ticks");
    assert!((0.04..=0.2).contains(&net.loss), "loss {}", net.loss);
    assert!(
        net.rtt_ms >= 40.0 && net.rtt_ms < 120.0,
        "rtt {}",
        net.rtt_ms
    );
    assert!(net.jitter_ms > 1.5, "jitter {}", net.jitter_ms);
    assert!((20.0..=31.0).contains(&net.snapshot_hz), "{net:?}");
    assert!(
        net.bytes_in_per_s > 1000.0 && net.bytes_out_per_s > 1000.0,
        "{net:?}"
    );
    // The clock keeps a margin above the base, for the jitter, and inputs
    // arrive in time: the prediction is exact despite loss and jitter.
    assert!(net.target_margin_ticks > 1.5, "{net:?}");
    assert_eq!(starved, 0.0, "inputs arrived late");
    assert_eq!(mispredicted, 0, "{stats:?}");
    // Remote players: drawn from a buffer deeper than one interval.
    assert!(remote_seen > 200, "the other player is drawn");
    assert!(net.interp_delay_ms > 2.5 * 1000.0 / 60.0, "{net:?}");
    assert!(
        interp.underruns - underruns_before < 60,
        "the buffer rarely runs dry: {interp:?}"
    );
    let report = walker.await.unwrap();
    assert!(report.ended.is_none(), "{report}");
    c.session.close().await;
    server.stop().await.unwrap();
}
