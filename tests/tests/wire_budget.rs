//! What one player costs on the wire, through the real QUIC stack on
//! loopback: input datagrams at most 30 a second at 60 Hz ticks (each
//! carrying the tick between), the ACKs of both ends riding on the game's
//! own packets instead of going alone, and the inputs still on time. The
//! figures are quinn's own counts of UDP datagrams and their payload bytes
//! on both ends, and the server's wire metrics.

use std::time::{Duration, Instant};

use ledge_client::session::{Session, SessionEvent};
use ledge_client::InputClock;
use ledge_shared::input::Buttons;
use ledge_tests::{metric, starvation, TestServer};

/// How long the player plays.
const PLAY: Duration = Duration::from_secs(4);

/// Plays `ada` for `time`: an input for every tick of `clock` (walking
/// right, jumping now and then, so the buttons change), every snapshot
/// read and steering the clock. Returns the snapshots received.
async fn play(
    ada: &mut Session,
    clock: &mut InputClock,
    last: &mut Option<u64>,
    time: Duration,
) -> u64 {
    let mut snapshots = 0;
    let end = Instant::now() + time;
    while Instant::now() < end {
        let tick = clock.input_tick(Instant::now());
        if last.is_none_or(|t| tick > t) {
            let jump = if tick % 40 < 5 { Buttons::JUMP } else { 0 };
            ada.send_input(tick, Buttons(Buttons::RIGHT | jump))
                .unwrap();
            *last = Some(tick);
        }
        let wait = clock.until_next_tick(Instant::now());
        tokio::select! {
            event = ada.recv() => {
                if let Ok(SessionEvent::Snapshot(update)) = event {
                    snapshots += 1;
                    clock.observe(update.input_timing);
                }
            }
            () = tokio::time::sleep(wait) => {}
        }
    }
    snapshots
}

#[tokio::test]
async fn a_player_sends_and_gets_about_thirty_packets_a_second() {
    let server = TestServer::start().await;
    let mut ada = server.join("ada").await;
    let mut clock = InputClock::new(ada.welcome(), Instant::now());
    let mut last = None;
    // A second for the clock to settle (its first inputs may be late).
    play(&mut ada, &mut clock, &mut last, Duration::from_secs(1)).await;
    let starved_before = starvation(&server, "room-1");
    let before = ada.connection().stats();
    let server_before = server.metrics();
    let started = Instant::now();
    let snapshots = play(&mut ada, &mut clock, &mut last, PLAY).await;
    let secs = started.elapsed().as_secs_f64();
    let after = ada.connection().stats();
    let per_s = |a: u64, b: u64| (b - a) as f64 / secs;
    let up = per_s(before.udp_tx.datagrams, after.udp_tx.datagrams);
    let down = per_s(before.udp_rx.datagrams, after.udp_rx.datagrams);
    let up_bytes = per_s(before.udp_tx.bytes, after.udp_tx.bytes);
    let figures = format!(
        "{up:.1} datagrams/s up ({up_bytes:.0} B/s), {down:.1} down, \
         {:.1} snapshots/s, acks sent {} received {}",
        snapshots as f64 / secs,
        after.frame_tx.acks - before.frame_tx.acks,
        after.frame_rx.acks - before.frame_rx.acks,
    );
    eprintln!("{figures}");
    // 60 Hz ticks, 30 Hz snapshots: an input datagram every other tick,
    // landing just before the server sends snapshots, so that hardly any
    // packet only acknowledges (sent in the other tick, the server's ACK
    // timer beats its next snapshot and about 30 ACK-only packets a second
    // come down besides the snapshots).
    assert!(snapshots as f64 / secs >= 24.0, "{figures}");
    assert!((24.0..=36.0).contains(&up), "{figures}");
    assert!(down <= 36.0, "{figures}");
    // Payload of the UDP datagrams (QUIC's headers, tags and ACKs
    // included): at most 2 KB/s up.
    assert!(up_bytes <= 2000.0, "{figures}");
    // The batched inputs arrive in time: the clock leads by the tick a
    // datagram waits (a few starved ticks while it steers are allowed).
    let starved = starvation(&server, "room-1") - starved_before;
    assert!(
        starved <= 0.05 * 60.0 * secs,
        "{starved} starved ticks; {figures}"
    );
    // The server counts the same traffic in its wire metrics.
    let server_after = server.metrics();
    let counted = |name: &str| metric(&server_after, name) - metric(&server_before, name);
    let server_in = counted("ledge_wire_datagrams_in_total");
    assert!(server_in > 0.0, "{server_after}");
    assert!(
        server_in <= 36.0 * (secs + 1.0),
        "{server_in} in; {figures}"
    );
    ada.close().await;
    server.stop().await.unwrap();
}
