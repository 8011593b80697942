//! Running a bot: a [`Brain`] plays through a [`Session`] with prediction,
//! on the caller's tokio runtime (many bots share one).

use std::fmt;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use ledge_shared::game::state::player_flags;
use ledge_shared::game::RUN_ID_BASE;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{NoticeKind, PlayerId, Standing};

use super::brain::Brain;
use crate::game::ClientGame;
use crate::net::bundle::{fetch_level, FetchOptions, Fetched, LevelCache};
use crate::net::levels::level_for;
use crate::net::session::{JoinOptions, Session, SessionEvent, SnapshotUpdate};
use crate::net::trust::{connect_trusted, Trust};
use crate::netstats::TransportSample;
use crate::view::NetStats;

/// How often a bot reads QUIC's byte counters and RTT.
const TRANSPORT_EVERY: Duration = Duration::from_millis(250);
/// With `stop_when_done`, how long a bot keeps playing after its brain is
/// done: the server runs the ticks we predicted a few ticks later, and
/// leaving at once could remove our player before it gets there.
pub const LINGER: Duration = Duration::from_millis(500);
/// With `stop_when_done`, how long at most a bot that reached the goal
/// waits for the server to say its run is recorded.
pub const RECORD_WAIT: Duration = Duration::from_secs(3);

/// How a bot plays.
#[derive(Debug, Clone)]
pub struct BotOptions {
    /// Player name.
    pub name: String,
    /// Room to join (`None`: any).
    pub room: Option<String>,
    /// How long to play.
    pub duration: Duration,
    /// Leave as soon as the brain is done (a runner at the goal).
    pub stop_when_done: bool,
    /// A copy of the server's level file; `None` (the usual): use the
    /// embedded default level, the cache, or download it.
    pub level: Option<PathBuf>,
    /// Where downloaded levels are cached (`None`: in memory only).
    pub level_cache: Option<PathBuf>,
    /// Smallest input margin the clock keeps, ticks (`None`: the default).
    pub min_margin: Option<f64>,
}

impl BotOptions {
    /// `name` plays for `duration` in any room on the default level.
    pub fn new(name: &str, duration: Duration) -> BotOptions {
        BotOptions {
            name: name.to_owned(),
            room: None,
            duration,
            stop_when_done: false,
            level: None,
            level_cache: None,
            min_margin: None,
        }
    }
}

/// What a bot did.
#[derive(Debug, Clone, Default)]
pub struct BotReport {
    /// Its name.
    pub name: String,
    /// Its brain's name.
    pub brain: &'static str,
    /// Its player id, once welcomed.
    pub player: Option<PlayerId>,
    /// Local ticks run.
    pub ticks: u64,
    /// Snapshots received.
    pub snapshots: u64,
    /// Server ticks the snapshots received account for: each one's distance
    /// from the one the server sent before it, when that one arrived too (a
    /// lost snapshot's ticks are not covered). A quiet server sends a few
    /// snapshots a second but covers every tick.
    pub covered_ticks: u64,
    /// The newest snapshot's tick.
    pub(crate) last_snapshot: Option<u64>,
    /// Snapshots where our state differed from the prediction.
    pub mispredictions: u64,
    /// Corrections of our predicted position.
    pub corrections: u64,
    /// Largest correction, pixels.
    pub max_correction_px: f32,
    /// The network figures at the end.
    pub net: NetStats,
    /// The server's snapshots showed our player at the goal.
    pub won: bool,
    /// The snapshot tick that first showed it.
    pub won_at_tick: Option<u64>,
    /// The run's time in ticks at its first finish, as the server's run
    /// record said.
    pub finish_ticks: Option<u32>,
    /// Where its last finished run stands in the server's records (`Err`:
    /// why it was not recorded), once the server said.
    pub standing: Option<Result<Standing, String>>,
    /// Runs the server said it recorded.
    pub recorded: u32,
    /// Runs the server said it did not record.
    pub not_recorded: u32,
    /// Runs the server's snapshots showed finishing (our player's goal
    /// flag turning on).
    pub finishes: u32,
    /// Our player's goal flag in the newest snapshot.
    pub(crate) was_won: bool,
    /// The brain's progress note.
    pub progress: String,
    /// Why it stopped early (connection refused, closed by the server...).
    pub ended: Option<String>,
    /// Wall-clock time played.
    pub played: Duration,
    /// How the server's level was had (`None`: from `level`, a file).
    pub level: Option<Fetched>,
}

impl BotReport {
    /// Counts a snapshot received ([`BotReport::snapshots`],
    /// Follows our player's run in a server snapshot: the goal flag turning
    /// on (a finish), the first finish's tick and time.
    fn observe_run(&mut self, update: &SnapshotUpdate, me: PlayerId) {
        if let Some(mine) = update.state.get(me.0) {
            let won = mine.flags & player_flags::WON != 0;
            if won && !self.was_won {
                self.finishes += 1;
            }
            self.was_won = won;
            if won && !self.won {
                self.won = true;
                self.won_at_tick = Some(update.state.tick);
            }
        }
        if let Some(run) = update.state.get(RUN_ID_BASE + me.0) {
            // A finished run has its order; its ticks are final.
            if run.aux != 0 && self.finish_ticks.is_none() {
                self.finish_ticks = u32::try_from(run.pos.x).ok();
            }
        }
    }

    /// Takes what the server said about our finished run's record.
    fn told(&mut self, standing: Result<Standing, String>) {
        match &standing {
            Ok(_) => self.recorded += 1,
            Err(_) => self.not_recorded += 1,
        }
        self.standing = Some(standing);
    }

    /// [`BotReport::covered_ticks`]).
    pub fn snapshot(&mut self, update: &SnapshotUpdate) {
        self.snapshots += 1;
        let tick = update.state.tick;
        if let (Some(previous), Some(last)) = (update.previous_tick, self.last_snapshot) {
            if previous == last {
                self.covered_ticks += tick - previous;
            }
        }
        self.last_snapshot = Some(tick);
    }
}

impl fmt::Display for BotReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let id = self
            .player
            .map_or_else(|| "-".to_owned(), |p| p.to_string());
        write!(
            f,
            "{:<10} {:<7} player {:>4}  ticks {:>5}  snapshots {:>4}  corrections {:>3} \
             (max {:>5.1} px, mispredicted {:>3})  covered {:>5} ticks  rtt {:>6.2} ms  jitter {:>5.2} ms  \
             loss {:>4.1}%  goal {}",
            self.name,
            self.brain,
            id,
            self.ticks,
            self.snapshots,
            self.corrections,
            self.max_correction_px,
            self.mispredictions,
            self.covered_ticks,
            self.net.rtt_ms,
            self.net.jitter_ms,
            self.net.loss * 100.0,
            match self.won_at_tick {
                Some(t) => format!("reached at tick {t}"),
                None => "no".to_owned(),
            }
        )?;
        if !self.progress.is_empty() {
            write!(f, "  [{}]", self.progress)?;
        }
        if let Some(why) = &self.ended {
            write!(f, "  ended: {why}")?;
        }
        Ok(())
    }
}

/// Connects to `server` (`HOST:PORT`) trusting as `trust` says, then
/// [`run_bot`]. A failed connection is reported in [`BotReport::ended`].
pub async fn connect_and_run(
    server: &str,
    trust: &Trust,
    brain: &mut dyn Brain,
    options: &BotOptions,
) -> BotReport {
    let join = JoinOptions {
        player_name: options.name.clone(),
        room: options.room.clone(),
        resume: None,
        spectate: false,
    };
    match connect_trusted(server, trust, &join).await {
        Ok((session, _)) => run_bot(session, brain, options).await,
        Err(e) => BotReport {
            name: options.name.clone(),
            brain: brain.name(),
            ended: Some(format!("cannot connect: {e}")),
            ..BotReport::default()
        },
    }
}

/// Plays `brain` on a joined `session` for `options.duration` (or until the
/// brain is done, with `stop_when_done`), then leaves.
pub async fn run_bot(
    mut session: Session,
    brain: &mut dyn Brain,
    options: &BotOptions,
) -> BotReport {
    let started = Instant::now();
    let welcome = session.welcome().clone();
    let me = welcome.player_id;
    let mut report = BotReport {
        name: options.name.clone(),
        brain: brain.name(),
        player: Some(me),
        ..BotReport::default()
    };
    let level = match &options.level {
        Some(file) => level_for(&welcome, Some(file)),
        None => {
            let fetch = FetchOptions {
                cache: options.level_cache.clone().map(LevelCache::new),
                cut_after: None,
            };
            fetch_level(&mut session, &fetch, |_, _| {})
                .await
                .map(|(bundle, fetched)| {
                    report.level = Some(fetched);
                    bundle.level
                })
        }
    };
    let level = match level {
        Ok(level) => level,
        Err(e) => {
            report.ended = Some(e.to_string());
            session.close().await;
            return report;
        }
    };
    let rtt = session.connection().rtt();
    let mut game = match ClientGame::new(&welcome, level, rtt, Instant::now()) {
        Ok(g) => g,
        Err(e) => {
            report.ended = Some(e.to_string());
            session.close().await;
            return report;
        }
    };
    game.set_name(&options.name);
    if let Some(m) = options.min_margin {
        game.set_base_margin(m);
    }
    let mut deadline = started + options.duration;
    let mut next_transport = started;
    let mut lingering = false;
    let mut linger_started = Instant::now();
    let ended = loop {
        let now = Instant::now();
        if options.stop_when_done && brain.done() && !lingering {
            lingering = true;
            linger_started = now;
            deadline = deadline.min(now + LINGER);
        }
        // A bot at the goal waits a little longer for its record.
        let until = if lingering && report.won && report.standing.is_none() {
            deadline.max(linger_started + RECORD_WAIT)
        } else {
            deadline
        };
        if now >= until {
            break None;
        }
        if now >= next_transport {
            game.on_transport(TransportSample::of(session.connection()), now);
            next_transport = now + TRANSPORT_EVERY;
        }
        let due = game.advance(now);
        for _ in 0..due {
            let buttons = if game.synced() {
                brain.buttons(game.game(), me)
            } else {
                Buttons::NONE
            };
            let tick = game.step(buttons);
            report.ticks += 1;
            if let Err(e) = session.send_input(tick, buttons) {
                tracing::debug!("{}: input not sent: {e}", options.name);
            }
        }
        let wait = game
            .clock()
            .until_next_tick(Instant::now())
            .min(until.saturating_duration_since(Instant::now()));
        let event = tokio::select! {
            event = session.recv() => event,
            () = tokio::time::sleep(wait) => continue,
        };
        match event {
            Ok(SessionEvent::Snapshot(update)) => {
                report.snapshot(&update);
                report.observe_run(&update, me);
                if let Some(r) = game.on_snapshot(&update) {
                    if r.mispredicted || r.correction_px > 0.0 {
                        brain.on_correction();
                    }
                    report.max_correction_px = report.max_correction_px.max(r.correction_px);
                }
            }
            Ok(SessionEvent::Pong { rtt: Some(rtt), .. }) => game.on_rtt(rtt),
            Ok(SessionEvent::RunRecorded(standing)) => report.told(standing),
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
    let now = Instant::now();
    game.on_transport(TransportSample::of(session.connection()), now);
    report.net = game.net_stats(now);
    report.corrections = report.net.corrections;
    report.mispredictions = report.net.mispredictions;
    report.progress = brain.progress();
    report.played = started.elapsed();
    report.ended = ended;
    if report.ended.is_none() {
        session.close().await;
    }
    report
}
