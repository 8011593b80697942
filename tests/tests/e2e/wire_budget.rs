//! What one player costs on the wire, through the real QUIC stack on
//! loopback: input datagrams at most 30 a second at 60 Hz ticks (each
//! carrying the tick between), the ACKs of both ends riding on the game's
//! own packets instead of going alone, and the inputs still on time; and
//! an idle player in a still room going quiet, under 1 KB/s each way, until
//! something moves. The figures are quinn's own counts of UDP datagrams and
//! their payload bytes on both ends, and the server's wire metrics.

use std::time::{Duration, Instant};

use ledge_client::net::session::{Session, SessionEvent, SnapshotUpdate};
use ledge_client::InputClock;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::PlayerId;
use ledge_tests::{metric, starvation, TestServer};

/// IPv4 and UDP headers of a datagram, bytes.
const IP_UDP_HEADERS: u64 = 28;

/// How long the player plays.
const PLAY: Duration = Duration::from_secs(4);

/// Plays `players` for `time` on one clock, each holding `buttons(i,
/// tick)`; returns every snapshot each received.
async fn play_all(
    players: &mut [&mut Session],
    clock: &mut InputClock,
    last: &mut Option<u64>,
    time: Duration,
    buttons: impl Fn(usize, u64) -> Buttons,
) -> Vec<Vec<SnapshotUpdate>> {
    let mut got = vec![Vec::new(); players.len()];
    let end = Instant::now() + time;
    while Instant::now() < end {
        let tick = clock.input_tick(Instant::now());
        if last.is_none_or(|t| tick > t) {
            for (i, p) in players.iter_mut().enumerate() {
                p.send_input(tick, buttons(i, tick)).unwrap();
            }
            *last = Some(tick);
        }
        let wait = clock.until_next_tick(Instant::now());
        let deadline = tokio::time::Instant::now() + wait;
        // Everything already received, then wait for the next tick.
        for (i, p) in players.iter_mut().enumerate() {
            loop {
                let event = tokio::time::timeout_at(deadline, p.recv()).await;
                match event {
                    Ok(Ok(SessionEvent::Snapshot(update))) => {
                        if i == 0 {
                            clock.observe(update.input_timing);
                        }
                        got[i].push(update);
                    }
                    Ok(Ok(_)) => {}
                    Ok(Err(e)) => panic!("player {i}: {e}"),
                    Err(_) => break,
                }
                if tokio::time::Instant::now() >= deadline {
                    break;
                }
            }
        }
    }
    got
}

/// Walking right, jumping now and then, so the buttons change.
fn walk(_: usize, tick: u64) -> Buttons {
    let jump = if tick % 40 < 5 { Buttons::JUMP } else { 0 };
    Buttons(Buttons::RIGHT | jump)
}

#[tokio::test]
async fn a_player_sends_and_gets_about_thirty_packets_a_second() {
    let server = TestServer::start().await;
    let mut ada = server.join("ada").await;
    let mut clock = InputClock::new(ada.welcome(), Instant::now());
    let mut last = None;
    // A second for the clock to settle (its first inputs may be late).
    let one_second = Duration::from_secs(1);
    play_all(&mut [&mut ada], &mut clock, &mut last, one_second, walk).await;
    let starved_before = starvation(&server, "room-1");
    let before = ada.connection().stats();
    let server_before = server.metrics();
    let started = Instant::now();
    let got = play_all(&mut [&mut ada], &mut clock, &mut last, PLAY, walk).await;
    let snapshots = got[0].len();
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

/// Checks what a quiet client is promised: between two snapshots it got
/// (`a`, then `b` naming `a` as the one before), every state the server had
/// up to `b`'s tick less one interval was `a`'s extrapolated. `truth` is
/// what a client that is never quiet got: every snapshot. Returns the
/// states checked.
fn check_gaps(quiet: &[SnapshotUpdate], truth: &[SnapshotUpdate]) -> usize {
    let mut checked = 0;
    for pair in quiet.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if b.previous_tick != Some(a.state.tick) {
            continue;
        }
        for t in truth
            .iter()
            .filter(|t| t.state.tick > a.state.tick && t.state.tick + 2 <= b.state.tick)
        {
            assert!(
                a.state.extrapolates_to(&t.state),
                "the state of tick {} is not that of {} carried on (the next came at {})",
                t.state.tick,
                a.state.tick,
                b.state.tick
            );
            checked += 1;
        }
    }
    checked
}

#[tokio::test]
async fn an_idle_player_in_a_still_room_goes_quiet_until_something_moves() {
    let server = TestServer::start().await;
    let mut ada = server.join("ada").await;
    let mut bo = server.join("bo").await;
    // Cy flips a button the game ignores (bit 6) every tick: never quiet,
    // it gets every snapshot, the truth the quiet ones are checked against.
    let mut cy = server.join("cy").await;
    let bo_id = bo.welcome().player_id;
    let mut clock = InputClock::new(ada.welcome(), Instant::now());
    let mut last = None;
    let idle = |i: usize, tick: u64| Buttons(if i == 2 { (tick as u8 & 1) << 6 } else { 0 });
    // They land on the ground and stand there.
    let mut players = [&mut ada, &mut bo, &mut cy];
    play_all(
        &mut players,
        &mut clock,
        &mut last,
        Duration::from_secs(2),
        idle,
    )
    .await;
    assert!(
        players[0].is_quiet() && players[1].is_quiet(),
        "ada and bo went quiet"
    );
    assert!(!players[2].is_quiet(), "cy's buttons change");
    let starved_before = starvation(&server, "room-1");
    let before = players[0].connection().stats();
    let server_before = server.metrics();
    let started = Instant::now();
    let quiet = play_all(
        &mut players,
        &mut clock,
        &mut last,
        Duration::from_secs(4),
        idle,
    )
    .await;
    let secs = started.elapsed().as_secs_f64();
    let after = players[0].connection().stats();
    let per_s = |a: u64, b: u64| (b - a) as f64 / secs;
    let up = per_s(before.udp_tx.datagrams, after.udp_tx.datagrams);
    let down = per_s(before.udp_rx.datagrams, after.udp_rx.datagrams);
    let wire = |d: u64, b: u64| b + IP_UDP_HEADERS * d;
    let down_bytes = per_s(
        wire(before.udp_rx.datagrams, before.udp_rx.bytes),
        wire(after.udp_rx.datagrams, after.udp_rx.bytes),
    );
    let up_bytes = per_s(
        wire(before.udp_tx.datagrams, before.udp_tx.bytes),
        wire(after.udp_tx.datagrams, after.udp_tx.bytes),
    );
    let figures = format!(
        "idle: {up:.1} datagrams/s up ({up_bytes:.0} B/s on the wire), {down:.1} down \
         ({down_bytes:.0} B/s), {:.1} snapshots/s (cy, never quiet: {:.1})",
        quiet[0].len() as f64 / secs,
        quiet[2].len() as f64 / secs,
    );
    eprintln!("{figures}");
    // At most 1 KB/s down, IP and UDP headers included (30 snapshots a
    // second alone were ~2.4 KB/s); up is as small.
    assert!(down_bytes <= 1000.0, "{figures}");
    assert!(up_bytes <= 1000.0, "{figures}");
    // Still heard several times a second (its clock and loss figure).
    assert!(quiet[0].len() as f64 / secs >= 3.0, "{figures}");
    assert!(quiet[2].len() as f64 / secs >= 24.0, "{figures}");
    // The gaps are said to be skipped, not lost, and the state held.
    let skipped = quiet[0]
        .iter()
        .filter(|u| u.previous_tick.is_some_and(|p| u.state.tick - p > 2))
        .count();
    assert!(
        skipped * 2 >= quiet[0].len(),
        "{skipped} after a gap; {figures}"
    );
    let checked = check_gaps(&quiet[0], &quiet[2]);
    assert!(checked >= 60, "{checked} states checked");
    let server_after = server.metrics();
    let skipped_metric = metric(&server_after, "ledge_snapshots_skipped_total")
        - metric(&server_before, "ledge_snapshots_skipped_total");
    assert!(
        skipped_metric >= 2.0 * 20.0 * secs,
        "{skipped_metric} skipped"
    );
    // Held, not starved.
    let starved = starvation(&server, "room-1") - starved_before;
    assert!(starved <= 0.02 * 60.0 * secs, "{starved} starved ticks");

    // Bo runs right: ada sees it start within a few ticks, and every state
    // between the snapshots she gets is the one before carried on (a
    // steady run needs none: it extrapolates).
    let x_of = |u: &SnapshotUpdate, id: PlayerId| u.state.get(id.0).map(|e| e.pos.x);
    let resting = x_of(quiet[0].last().unwrap(), bo_id).expect("bo is in ada's snapshots");
    let go = last.unwrap() + 1;
    let run = |i: usize, tick: u64| {
        if i == 1 && tick >= go {
            Buttons(Buttons::RIGHT)
        } else {
            idle(i, tick)
        }
    };
    let moving = play_all(
        &mut players,
        &mut clock,
        &mut last,
        Duration::from_secs(2),
        run,
    )
    .await;
    let seen = moving[0]
        .iter()
        .find(|u| x_of(u, bo_id).is_some_and(|x| x != resting))
        .expect("ada saw bo move");
    let checked = check_gaps(&moving[0], &moving[2]);
    let ran = x_of(moving[0].last().unwrap(), bo_id).unwrap() - resting;
    eprintln!(
        "bo ran from tick {go}; ada saw it in the snapshot of tick {} ({} snapshots in 2 s, \
         cy {}; {checked} states between them checked; bo ran {ran} units)",
        seen.state.tick,
        moving[0].len(),
        moving[2].len(),
    );
    assert!(
        seen.state.tick <= go + 6,
        "seen at {} for {go}",
        seen.state.tick
    );
    assert!(ran > 0, "bo ran right");
    assert!(checked >= 20, "{checked} states checked");
    ada.close().await;
    bo.close().await;
    cy.close().await;
    server.stop().await.unwrap();
}
