//! Helpers for whole-match tests: the server's tick counter and per-player
//! state read from its metrics, a watch for panics in tokio tasks, bots
//! spawned on the test's runtime.

use std::collections::BTreeSet;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Once;
use std::time::{Duration, Instant};

use ledge_client::bot::{run_bot, BotOptions, BotReport, Brain};
use ledge_client::{InputClock, Session, SessionEvent};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::StateSnapshot;
use tokio::task::JoinHandle;

use crate::{metric, TestServer};

/// Ticks room `room` has run so far: the count of its tick-duration
/// histogram (one observation per tick run).
pub fn ticks_run(metrics: &str, room: &str) -> f64 {
    metric(
        metrics,
        &format!("ledge_tick_duration_seconds_count{{room=\"{room}\"}}"),
    )
}

/// The server's tick rate over a window: ticks run and wall-clock time
/// between two [`TickProbe`]s.
#[derive(Debug, Clone, Copy)]
pub struct TickProbe {
    /// Ticks run by then.
    pub ticks: f64,
    /// When it was read.
    pub at: Instant,
}

impl TickProbe {
    /// Reads room `room`'s tick count now.
    pub fn read(server: &TestServer, room: &str) -> TickProbe {
        TickProbe {
            ticks: ticks_run(&server.metrics(), room),
            at: Instant::now(),
        }
    }

    /// Ticks per second from `self` to `later`.
    pub fn rate_until(&self, later: &TickProbe) -> f64 {
        let secs = later.at.duration_since(self.at).as_secs_f64();
        (later.ticks - self.ticks) / secs.max(1e-9)
    }
}

/// Asserts the tick rate `rate` is within 10 % of `nominal` Hz.
pub fn assert_steady(what: &str, rate: f64, nominal: f64) {
    assert!(
        (rate - nominal).abs() <= nominal * 0.10,
        "{what}: the server ticked at {rate:.2} Hz, not {nominal} Hz"
    );
}

/// The server's per-player state, as its metrics show it: what must return
/// to its baseline when players come and go.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlayerState {
    /// Players in room `room-1` (the room's member table).
    pub room_players: i64,
    /// Open connections (connection tasks and their open-slot count).
    pub connections: i64,
    /// Per-client metric series (`client_bytes_in`/`_out`), by client id.
    pub client_series: BTreeSet<u32>,
}

impl PlayerState {
    /// Reads it from `server`'s metrics.
    pub fn read(server: &TestServer) -> PlayerState {
        let text = server.metrics();
        let client_series = text
            .lines()
            .filter(|l| l.starts_with("ledge_client_bytes_"))
            .filter_map(|l| l.split("client=\"").nth(1)?.split('"').next()?.parse().ok())
            .collect();
        PlayerState {
            room_players: metric(&text, "ledge_players{room=\"room-1\"}") as i64,
            connections: metric(&text, "ledge_connections") as i64,
            client_series,
        }
    }
}

static PANICS: AtomicU64 = AtomicU64::new(0);
static HOOK: Once = Once::new();

/// Panics on tokio worker threads (server and bot tasks: a test's own
/// assertions run on the test's thread) since the process started. The
/// first call installs a panic hook that counts them (and then prints as
/// usual).
pub fn task_panics() -> u64 {
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let thread = std::thread::current();
            if thread
                .name()
                .is_some_and(|n| n.starts_with("tokio-runtime-worker"))
            {
                PANICS.fetch_add(1, Ordering::SeqCst);
            }
            previous(info);
        }));
    });
    PANICS.load(Ordering::SeqCst)
}

/// Runs `brain` as a bot named `name` on `session` on the current runtime.
pub fn spawn_bot<B: Brain + 'static>(
    session: Session,
    mut brain: B,
    options: BotOptions,
) -> JoinHandle<(BotReport, B)> {
    tokio::spawn(async move {
        let report = run_bot(session, &mut brain, &options).await;
        (report, brain)
    })
}

/// Bot options for the tests: `name` plays `duration` with a 4-tick input
/// margin (inputs arrive on time on a loaded machine: exact prediction
/// needs them on time).
pub fn bot_options(name: &str, duration: Duration) -> BotOptions {
    BotOptions {
        min_margin: Some(4.0),
        ..BotOptions::new(name, duration)
    }
}

/// Watches the server's authoritative state through `session` (an idle
/// player: it sends no-button inputs each tick) until `done` says so or
/// `within` has passed; returns whether `done` did.
pub async fn watch(
    session: &mut Session,
    within: Duration,
    mut done: impl FnMut(&StateSnapshot) -> bool,
) -> bool {
    let mut clock = InputClock::new(session.welcome(), Instant::now());
    let deadline = Instant::now() + within;
    while Instant::now() < deadline {
        let _ = session.send_input(clock.input_tick(Instant::now()), Buttons::NONE);
        let wait = clock
            .until_next_tick(Instant::now())
            .min(deadline.saturating_duration_since(Instant::now()));
        let Ok(event) = tokio::time::timeout(wait, session.recv()).await else {
            continue;
        };
        if let SessionEvent::Snapshot(update) = event.expect("the observer stays connected") {
            clock.observe(update.input_timing);
            if done(&update.state) {
                return true;
            }
        }
    }
    false
}
