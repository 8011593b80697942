//! Prediction and reconciliation over real QUIC: unimpaired clients
//! predict the server exactly for a minute; a lost input burst is corrected, blended
//! (small) or snapped (large), and the prediction converges again.

use std::time::{Duration, Instant};

use ledge_client::bot::brain::drill;
use ledge_client::game::predict::BLEND_KEEP;
use ledge_client::view::Vec2;
use ledge_client::ClientGame;
use ledge_shared::input::Buttons;
use ledge_tests::e2e::{assert_steady, TickProbe};
use ledge_tests::{starvation, PredictedClient, TestServer};

fn late_inputs(server: &TestServer) -> f64 {
    ledge_tests::metric(
        &server.metrics(),
        "ledge_dropped_messages_total{reason=\"InputLate\"}",
    )
}

/// Clients playing at once in the exactness test.
const CLIENTS: u64 = 4;
/// How long they play, after a warm-up second.
const EXACT_FOR: Duration = Duration::from_secs(59);

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn unimpaired_clients_predict_the_server_exactly_for_sixty_seconds() {
    let server = TestServer::start().await;
    let started = Instant::now();
    let mut clients = Vec::new();
    for k in 0..CLIENTS {
        // Four ticks of margin (67 ms) so a loaded test machine does not
        // make inputs late: exact timing is the precondition of exact
        // prediction. Each client plays the script from another point.
        let c = PredictedClient::join(&server, &format!("scripted-{k}"), 4.0).await;
        clients.push(c);
    }
    // The server counts the ticks between its tick at the join and our
    // first input as starved, and the first inputs, sent before the
    // client's clock has heard from the server, may arrive a tick late
    // (and be mispredicted): count only after a warm-up second.
    let warm_up = Instant::now() + Duration::from_secs(1);
    let until = warm_up + EXACT_FOR;
    let mut tasks = Vec::new();
    for (k, mut c) in clients.into_iter().enumerate() {
        let offset = k as u64 * 57;
        tasks.push(tokio::spawn(async move {
            let me = c.game.me();
            c.run(
                warm_up,
                |_, tick| (drill(tick + offset), true),
                |_, _, _| {},
            )
            .await;
            let (mut min_x, mut max_x) = (i32::MAX, i32::MIN);
            let (mut compared, mut wrong) = (0usize, 0usize);
            let snapshots_before = c.snapshots;
            c.run(
                until,
                |_, tick| (drill(tick + offset), true),
                |_, update, r| {
                    if let Some(e) = update.state.get(me.0) {
                        min_x = min_x.min(e.pos.x);
                        max_x = max_x.max(e.pos.x);
                    }
                    compared += usize::from(r.compared);
                    wrong += usize::from(r.mispredicted || r.correction_px > 0.0);
                },
            )
            .await;
            (c, compared, wrong, snapshots_before, max_x - min_x)
        }));
    }
    tokio::time::sleep_until(warm_up.into()).await;
    let starved_before = starvation(&server, "room-1");
    let late_before = late_inputs(&server);
    let ticks_before = TickProbe::read(&server, "room-1");
    let mut results = Vec::new();
    for t in tasks {
        results.push(t.await.expect("the client task did not panic"));
    }
    let ticks_after = TickProbe::read(&server, "room-1");
    let starved = starvation(&server, "room-1") - starved_before;
    let late = late_inputs(&server) - late_before;
    let rate = ticks_before.rate_until(&ticks_after);
    eprintln!(
        "{CLIENTS} clients for {:?}: server at {rate:.2} Hz, starved {starved}, late {late}",
        started.elapsed()
    );
    let mut failures = Vec::new();
    for (c, compared, wrong, snapshots_before, moved) in &results {
        let stats = c.game.predictor().stats();
        let net = c.game.net_stats(Instant::now());
        let snapshots = c.snapshots - snapshots_before;
        eprintln!(
            "{} ticks, {snapshots} snapshots ({compared} compared), {stats:?}, \
             margin {:.2} (target {:.2}), rtt {:.2} ms, jitter {:.3} ms, moved {} px",
            c.ticks,
            net.input_margin_ticks,
            net.target_margin_ticks,
            net.rtt_ms,
            net.jitter_ms,
            moved / 256
        );
        let secs = EXACT_FOR.as_secs_f64();
        assert!(
            snapshots as f64 >= secs * 30.0 * 0.9,
            "{snapshots} snapshots in {secs} s"
        );
        assert!(
            *compared as f64 >= secs * 30.0 * 0.85,
            "predictions compared: {compared}"
        );
        assert!(
            stats.replayed_ticks >= stats.snapshots,
            "the client ran ahead of the server"
        );
        assert!(*moved > 40 * 256, "the player moved");
        if *wrong != 0 {
            failures.push(format!(
                "{wrong} snapshots mispredicted or corrected ({stats:?}), the last: {:?}",
                c.game.predictor().last_mismatch()
            ));
        }
    }
    assert_eq!(starved, 0.0, "inputs arrived late: timing was not exact");
    assert!(
        failures.is_empty(),
        "mispredicted or corrected: {failures:?}"
    );
    assert_steady("while the clients played", rate, 60.0);
    for (c, ..) in results {
        c.session.close().await;
    }
    server.stop().await.unwrap();
}

/// The local player as drawn minus as predicted (the blending offset).
fn drawn_offset(game: &ClientGame) -> f32 {
    let v = game.view();
    let me = game.game().player(game.me()).unwrap();
    let local = v.local.unwrap();
    // `alpha` blends from the previous tick: compare with that blend.
    let cur = ledge_client::view::px2(me.pos);
    let prev = game
        .predictor()
        .prev_pos()
        .map_or(cur, ledge_client::view::px2);
    (local.pos - prev.lerp(cur, v.alpha)).length()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_lost_input_burst_is_corrected_with_blending_and_prediction_converges() {
    let server = TestServer::start().await;
    let mut c = PredictedClient::join(&server, "lossy", 3.0).await;
    // Stand still until the prediction runs.
    c.run(
        Instant::now() + Duration::from_millis(500),
        |_, _| (Buttons::NONE, true),
        |_, _, _| {},
    )
    .await;
    assert!(c.game.synced());
    let t0 = c.game.next_tick();
    // 8 ticks of RIGHT predicted but never sent: the server applies the
    // previous buttons (none) instead, so our player did not move there.
    let burst = t0 + 30..t0 + 38;
    let mut corrections = Vec::new();
    let mut blending = Vec::new();
    c.run(
        Instant::now() + Duration::from_millis(3000),
        |game, t| {
            if game.predictor().offset() != Vec2::ZERO {
                blending.push((t, game.predictor().offset().length(), drawn_offset(game)));
            }
            if burst.contains(&t) {
                (Buttons(Buttons::RIGHT), false)
            } else {
                (Buttons::NONE, true)
            }
        },
        |game, update, r| {
            if r.correction_px > 0.0 || r.mispredicted {
                corrections.push((
                    update.state.tick,
                    *r,
                    game.predictor().offset().length(),
                    game.next_tick(),
                ));
            }
        },
    )
    .await;
    let stats = c.game.predictor().stats();
    eprintln!("{stats:?}");
    for (tick, r, offset, local) in &corrections {
        eprintln!("snapshot {tick} (local {local}): {r:?}, offset {offset:.2} px");
    }
    let first = corrections
        .iter()
        .find(|(_, r, _, _)| r.correction_px > 0.0)
        .expect("the burst was corrected");
    assert!(
        first.1.correction_px >= 0.5 && !first.1.snapped,
        "blended, not snapped: {first:?}"
    );
    assert!(
        (first.2 - first.1.correction_px).abs() < 0.5,
        "the drawn position starts where it was: offset {} for a {} px correction",
        first.2,
        first.1.correction_px
    );
    // The visible offset is drawn, decays tick by tick, and is gone within
    // 40 ticks of the last correction.
    let last_fix = corrections.iter().map(|c| c.3).max().unwrap();
    assert!(blending.len() >= 5, "{blending:?}");
    let mut decays = 0;
    for w in blending.windows(2) {
        // Consecutive ticks with no correction in between.
        if w[1].0 == w[0].0 + 1 && !corrections.iter().any(|c| c.3 == w[1].0) {
            assert!(w[1].1 <= w[0].1 * BLEND_KEEP + 1e-3, "decays: {w:?}");
            decays += 1;
        }
    }
    assert!(decays >= 5, "{blending:?}");
    for (_, offset, drawn) in &blending {
        assert!((offset - drawn).abs() < 1e-3, "drawn with the offset");
    }
    assert!(
        blending.iter().all(|(t, _, _)| *t < last_fix + 40 + 10),
        "gone within 40 ticks: {blending:?}"
    );
    assert_eq!(c.game.predictor().offset(), Vec2::ZERO);
    // Converged: no misprediction later than 20 ticks after the burst,
    // and the last second of snapshots were all compared and right.
    assert!(
        corrections.iter().all(|(tick, ..)| *tick <= burst.end + 20),
        "not converged: {corrections:?}"
    );
    // (Standing still, the client is quiet: a few snapshots a second.)
    let newest = c.log.iter().map(|r| r.tick).max().unwrap();
    let tail: Vec<_> = c.log.iter().filter(|r| r.tick + 60 > newest).collect();
    assert!(
        tail.len() >= 4 && tail.iter().all(|r| r.compared && !r.mispredicted),
        "{tail:?}"
    );
    assert!(stats.mispredictions >= 1 && stats.corrections >= 1);
    c.session.close().await;
    server.stop().await.unwrap();
}
