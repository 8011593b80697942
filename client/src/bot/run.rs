//! Running a bot: a [`Brain`] plays through a [`Session`] with prediction,
//! on the caller's tokio runtime (many bots share one).

use std::fmt;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use ledge_shared::game::state::player_flags;
use ledge_shared::game::RUN_ID_BASE;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{LevelList, NoticeKind, PlayerId, Standing, Welcome};

use super::brain::Brain;
use crate::error::ClientError;
use crate::game::ClientGame;
use crate::net::bundle::{fetch_level, FetchOptions, Fetched, LevelCache};
use crate::net::download::level_change_failed;
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
    /// Vote for this level (an index into the server's level list) once
    /// the list arrives (`None`: no vote).
    pub vote: Option<u32>,
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
            vote: None,
        }
    }
}

/// A level a bot played, in the order played (a level played again is
/// listed again), and the runs it finished there.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct LevelPlayed {
    /// The level's id (the welcome's `level_id`).
    pub id: String,
    /// Runs the server's snapshots showed finishing on it.
    pub finishes: u32,
}

impl LevelPlayed {
    /// Level `id`, no run finished yet.
    pub fn new(id: &str) -> LevelPlayed {
        LevelPlayed {
            id: id.to_owned(),
            finishes: 0,
        }
    }
}

/// Prediction counters of the games of levels played before the current
/// one (each level's game counts afresh).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Earlier {
    pub(crate) corrections: u64,
    pub(crate) mispredictions: u64,
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
    /// The levels played, in order, with the runs finished on each.
    pub levels: Vec<LevelPlayed>,
    /// What came of [`BotOptions::vote`], in words (`None`: no vote asked,
    /// or no level list yet).
    pub vote: Option<String>,
    /// The prediction counters of the levels before the current one.
    pub(crate) earlier: Earlier,
}

impl BotReport {
    /// Follows our player's run in a server snapshot: the goal flag turning
    /// on (a finish), the first finish's tick and time.
    pub(crate) fn observe_run(&mut self, update: &SnapshotUpdate, me: PlayerId) {
        if let Some(mine) = update.state.get(me.0) {
            let won = mine.flags & player_flags::WON != 0;
            if won && !self.was_won {
                self.finishes += 1;
                if let Some(level) = self.levels.last_mut() {
                    level.finishes += 1;
                }
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

    /// The room moved to level `id`: its runs are counted from now on (our
    /// player starts there afresh).
    pub(crate) fn next_level(&mut self, id: &str) {
        self.levels.push(LevelPlayed::new(id));
        self.was_won = false;
    }

    /// The levels played and the runs finished on each, as the report's
    /// line says them: `"ID" finished N` for each, in order, comma
    /// separated.
    pub fn levels_line(&self) -> String {
        self.levels
            .iter()
            .map(|l| format!("{:?} finished {}", l.id, l.finishes))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Takes what the server said about our finished run's record.
    fn told(&mut self, standing: Result<Standing, String>) {
        match &standing {
            Ok(_) => self.recorded += 1,
            Err(_) => self.not_recorded += 1,
        }
        self.standing = Some(standing);
    }

    /// Counts a snapshot received ([`BotReport::snapshots`],
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
        if !self.levels.is_empty() {
            write!(f, "  levels: {}", self.levels_line())?;
        }
        if let Some(vote) = &self.vote {
            write!(f, "  vote: {vote}")?;
        }
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
/// brain is done, with `stop_when_done`), then leaves. When the room moves
/// to another level the bot gets that level, plays on there (its brain
/// told: [`Brain::on_level`]), and the report counts the runs finished on
/// each ([`BotReport::levels`]).
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
        levels: vec![LevelPlayed::new(&welcome.level_id)],
        ..BotReport::default()
    };
    let mut game = match first_game(&mut session, options, &mut report).await {
        Ok(game) => game,
        Err(e) => {
            report.ended = Some(e.to_string());
            session.close().await;
            return report;
        }
    };
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
        let mut bot = Playing {
            session: &mut session,
            game: &mut game,
            brain: &mut *brain,
            report: &mut report,
            options,
        };
        if let Err(why) = bot.event(event).await {
            break Some(why);
        }
    };
    let now = Instant::now();
    game.on_transport(TransportSample::of(session.connection()), now);
    report.net = game.net_stats(now);
    report.corrections = report.net.corrections + report.earlier.corrections;
    report.mispredictions = report.net.mispredictions + report.earlier.mispredictions;
    report.progress = brain.progress();
    report.played = started.elapsed();
    report.ended = ended;
    if report.ended.is_none() {
        session.close().await;
    }
    report
}

/// The game of the level we joined on: that of `options.level` (a file),
/// or fetched (embedded, cached or downloaded; how, in `report.level`).
async fn first_game(
    session: &mut Session,
    options: &BotOptions,
    report: &mut BotReport,
) -> Result<ClientGame, ClientError> {
    let welcome = session.welcome().clone();
    let level = match &options.level {
        Some(file) => level_for(&welcome, Some(file))?,
        None => {
            let (bundle, fetched) =
                fetch_level(session, &fetch_options(options), |_, _| {}).await?;
            report.level = Some(fetched);
            bundle.level
        }
    };
    let rtt = session.connection().rtt();
    let mut game = ClientGame::new(&welcome, level, rtt, Instant::now())?;
    game.set_name(&options.name);
    if let Some(m) = options.min_margin {
        game.set_base_margin(m);
    }
    Ok(game)
}

/// How a bot fetches levels.
fn fetch_options(options: &BotOptions) -> FetchOptions {
    FetchOptions {
        cache: options.level_cache.clone().map(LevelCache::new),
        cut_after: None,
    }
}

/// A playing bot, as one event from the server changes it.
struct Playing<'a> {
    session: &'a mut Session,
    game: &'a mut ClientGame,
    brain: &'a mut dyn Brain,
    report: &'a mut BotReport,
    options: &'a BotOptions,
}

impl Playing<'_> {
    /// Takes one event (or the session's end); `Err`: why the bot stops.
    async fn event(&mut self, event: Result<SessionEvent, ClientError>) -> Result<(), String> {
        let me = self.report.player.unwrap_or(self.game.me());
        match event.map_err(|e| e.to_string())? {
            SessionEvent::Snapshot(update) => {
                self.report.snapshot(&update);
                self.report.observe_run(&update, me);
                if let Some(r) = self.game.on_snapshot(&update) {
                    if r.mispredicted || r.correction_px > 0.0 {
                        self.brain.on_correction();
                    }
                    self.report.max_correction_px =
                        self.report.max_correction_px.max(r.correction_px);
                }
            }
            SessionEvent::Pong { rtt: Some(rtt), .. } => self.game.on_rtt(rtt),
            SessionEvent::RunRecorded(standing) => self.report.told(standing),
            SessionEvent::Notice(NoticeKind::Kick { reason }) => {
                return Err(format!("kicked: {reason}"))
            }
            SessionEvent::Notice(NoticeKind::Shutdown) => return Err("server shut down".into()),
            SessionEvent::Levels(list) => {
                vote_once(self.session, self.options.vote, &list, self.report).await
            }
            // The latest change only (another may be queued after it), and
            // not the one our game already plays (a change read with the
            // welcome).
            SessionEvent::LevelChange(welcome)
                if welcome == *self.session.welcome() && self.game.welcome() != Some(&welcome) =>
            {
                self.next_level(&welcome).await?;
            }
            _ => {}
        }
        Ok(())
    }

    /// The room moved to the level of `welcome`: fetch it (or take the
    /// level file, if it is that one), play on there with the clock going
    /// on, the brain told.
    async fn next_level(&mut self, welcome: &Welcome) -> Result<(), String> {
        let file = self
            .options
            .level
            .as_deref()
            .and_then(|file| level_for(welcome, Some(file)).ok());
        let level = match file {
            Some(level) => level,
            None => {
                let fetch = fetch_options(self.options);
                fetch_level(self.session, &fetch, |_, _| {})
                    .await
                    .map_err(|e| level_change_failed(welcome, &e))?
                    .0
                    .level
            }
        };
        let next = self
            .game
            .next_level(welcome, level, Instant::now())
            .map_err(|e| level_change_failed(welcome, &e))?;
        let old = std::mem::replace(self.game, next);
        let stats = old.predictor().stats();
        self.report.earlier.corrections += stats.corrections;
        self.report.earlier.mispredictions += stats.mispredictions;
        self.report.next_level(&welcome.level_id);
        self.brain.on_level(self.game.level());
        Ok(())
    }
}

/// Votes for level `vote` (an index into `list`) the first time a list
/// comes, saying in `report.vote` what was done.
pub(crate) async fn vote_once(
    session: &mut Session,
    vote: Option<u32>,
    list: &LevelList,
    report: &mut BotReport,
) {
    let Some(level) = vote.filter(|_| report.vote.is_none()) else {
        return;
    };
    report.vote = Some(match list.levels.get(level as usize) {
        None => format!(
            "no level {level} to vote for (the server has {})",
            list.levels.len()
        ),
        Some(choice) => match session.vote(level).await {
            Ok(()) => format!("voted for level {level} ({:?})", choice.id),
            Err(e) => format!("the vote for level {level} was not sent: {e}"),
        },
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_shared::protocol::{EntityState, StateSnapshot};

    /// A snapshot of `tick` with player `me` at the goal or not.
    fn update(tick: u64, me: PlayerId, won: bool) -> SnapshotUpdate {
        let flags = if won { player_flags::WON } else { 0 };
        SnapshotUpdate {
            state: StateSnapshot {
                tick,
                entities: vec![EntityState {
                    flags,
                    ..EntityState::zero(me.0)
                }],
            },
            baseline_tick: None,
            previous_tick: None,
            last_input_tick: None,
            input_timing: 0,
            via_stream: false,
            wire_bytes: 0,
            received: Instant::now(),
        }
    }

    /// Runs finished are counted on the level they were run on, and the
    /// report's line says so, in the documented format.
    #[test]
    fn the_report_counts_the_runs_finished_on_each_level() {
        let me = PlayerId(4);
        let mut report = BotReport {
            name: "bot-1".into(),
            brain: "runner",
            player: Some(me),
            levels: vec![LevelPlayed::new("default")],
            ..BotReport::default()
        };
        report.observe_run(&update(10, me, false), me);
        report.observe_run(&update(20, me, true), me);
        report.observe_run(&update(30, me, true), me);
        // The room moves on while our player stands at the goal: the new
        // level's first finish counts there.
        report.next_level("second");
        report.observe_run(&update(40, me, false), me);
        report.observe_run(&update(50, me, true), me);
        report.next_level("third");
        assert_eq!(report.finishes, 2);
        assert_eq!(
            report.levels,
            [
                LevelPlayed {
                    id: "default".into(),
                    finishes: 1
                },
                LevelPlayed {
                    id: "second".into(),
                    finishes: 1
                },
                LevelPlayed::new("third"),
            ]
        );
        let line = report.to_string();
        assert!(
            line.contains(
                r#"  levels: "default" finished 1, "second" finished 1, "third" finished 0"#
            ),
            "{line}"
        );
        assert!(!line.contains("vote:"), "{line}");
        report.vote = Some("voted for level 1 (\"second\")".into());
        assert!(
            report
                .to_string()
                .contains(r#"vote: voted for level 1 ("second")"#),
            "{line}"
        );
    }
}
