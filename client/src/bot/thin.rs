//! Thin bots: real QUIC sessions that send one input per tick (a
//! [`RandomWalker`]'s walk) and read (decode and acknowledge) every
//! snapshot, without predicting or planning.
//!
//! The server does exactly the work it does for predicting bots (inputs,
//! simulation, per-client delta snapshots), but a thin bot costs a fraction
//! of one: a predicting bot re-simulates its whole room, so 256 of them
//! cannot run beside the server on a small machine, and 256 thin ones can.
//! `ledge-bot --brain thin` runs them, for load generation.

use std::time::Instant;

use ledge_shared::input::Buttons;
use ledge_shared::protocol::NoticeKind;

use super::brain::RandomWalker;
use super::run::{vote_once, BotOptions, BotReport, LevelPlayed};
use crate::game::clock::InputClock;
use crate::net::session::{JoinOptions, SessionEvent};
use crate::net::trust::{connect_trusted, Trust};
use crate::netstats::TransportSample;

/// The brain name thin bots report.
pub const THIN: &str = "thin";

/// Connects to `server` (`HOST:PORT`) trusting as `trust` says, sends
/// `walker`'s buttons once per server tick for `options.duration`, reads
/// every snapshot, and leaves.
///
/// Of `options`, the name, room, duration and vote apply (no prediction: no
/// level, margin or goal; a level change is only counted, the clock going
/// on). In the report, `ticks` counts the inputs sent and `net`
/// holds the round-trip time and QUIC's bytes per second; failures end up
/// in [`BotReport::ended`].
pub async fn run_thin(
    server: &str,
    trust: &Trust,
    walker: &mut RandomWalker,
    options: &BotOptions,
) -> BotReport {
    run_thin_with(server, trust, &mut || walker.next_buttons(), options).await
}

/// [`run_thin`] with the buttons of each tick from `next` (e.g. none at
/// all: an idle player, to measure what a quiet room costs).
pub async fn run_thin_with(
    server: &str,
    trust: &Trust,
    next: &mut (dyn FnMut() -> Buttons + Send),
    options: &BotOptions,
) -> BotReport {
    let mut report = BotReport {
        name: options.name.clone(),
        brain: THIN,
        ..BotReport::default()
    };
    let join = JoinOptions {
        player_name: options.name.clone(),
        room: options.room.clone(),
        resume: None,
        spectate: false,
    };
    let mut session = match connect_trusted(server, trust, &join).await {
        Ok((session, _)) => session,
        Err(e) => {
            report.ended = Some(format!("cannot connect: {e}"));
            return report;
        }
    };
    report.player = Some(session.welcome().player_id);
    report.levels = vec![LevelPlayed::new(&session.welcome().level_id)];
    // The welcome of the level played (a change read with the welcome is
    // that level already).
    let mut playing = session.welcome().clone();
    let started = Instant::now();
    let deadline = started + options.duration;
    let mut clock = InputClock::new(session.welcome(), started);
    let mut last_sent: Option<u64> = None;
    let ended = loop {
        let now = Instant::now();
        if now >= deadline {
            break None;
        }
        let tick = clock.input_tick(now);
        if last_sent.is_none_or(|t| tick > t) {
            let buttons = next();
            if let Err(e) = session.send_input(tick, buttons) {
                break Some(format!("input not sent: {e}"));
            }
            report.ticks += 1;
            last_sent = Some(tick);
        }
        let wait = clock
            .until_next_tick(Instant::now())
            .min(deadline.saturating_duration_since(Instant::now()));
        let event = tokio::select! {
            event = session.recv() => event,
            () = tokio::time::sleep(wait) => continue,
        };
        match event {
            Ok(SessionEvent::Snapshot(update)) => {
                report.snapshot(&update);
                report.observe_run(&update, session.welcome().player_id);
                clock.observe(update.input_timing);
            }
            // The room's tick goes on across a level change: so does our
            // clock (no level to predict, none to fetch).
            Ok(SessionEvent::LevelChange(welcome))
                if welcome == *session.welcome() && welcome != playing =>
            {
                report.next_level(&welcome.level_id);
                playing = welcome;
            }
            Ok(SessionEvent::Levels(list)) => {
                vote_once(&mut session, options.vote, &list, &mut report).await;
            }
            Ok(SessionEvent::Notice(NoticeKind::Kick { reason })) => {
                break Some(format!("kicked: {reason}"))
            }
            Ok(SessionEvent::Notice(NoticeKind::Shutdown)) => {
                break Some("server shut down".into())
            }
            Ok(_) => {}
            Err(e) => break Some(e.to_string()),
        }
    };
    report.played = started.elapsed();
    let transport = TransportSample::of(session.connection());
    let secs = report.played.as_secs_f32().max(1e-3);
    report.net.rtt_ms = transport.rtt.as_secs_f32() * 1e3;
    report.net.bytes_in_per_s = transport.bytes_in as f32 / secs;
    report.net.bytes_out_per_s = transport.bytes_out as f32 / secs;
    report.net.snapshot_hz = report.snapshots as f32 / secs;
    report.ended = ended;
    if report.ended.is_none() {
        session.close().await;
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    fn walk(seed: u64, ticks: usize) -> Vec<Buttons> {
        let mut w = RandomWalker::new(seed);
        (0..ticks).map(|_| w.next_buttons()).collect()
    }

    #[test]
    fn the_walk_is_seeded_and_holds_its_buttons() {
        let a = walk(7, 500);
        assert_eq!(a, walk(7, 500));
        assert_ne!(a, walk(8, 500));
        // Held for at least 5 ticks at a time, and it moves both ways.
        let changes = a.windows(2).filter(|p| p[0] != p[1]).count();
        assert!(changes <= 500 / 5, "{changes}");
        assert!(a.iter().any(|b| b.held(Buttons::LEFT)));
        assert!(a.iter().any(|b| b.held(Buttons::RIGHT)));
        assert!(a.iter().any(|b| b.held(Buttons::JUMP)));
    }

    #[tokio::test]
    async fn a_bad_address_is_reported_not_panicked() {
        let options = BotOptions::new("p1-1", std::time::Duration::from_secs(1));
        let trust = Trust::Pinned(crate::Fingerprint([0; 32]));
        let report = run_thin("127.0.0.1", &trust, &mut RandomWalker::new(1), &options).await;
        assert_eq!(report.brain, THIN);
        assert_eq!((report.player, report.ticks), (None, 0));
        let why = report.ended.clone().expect("it ended");
        assert!(why.starts_with("cannot connect"), "{why}");
        assert!(report.to_string().starts_with("p1-1       thin "));
    }
}
