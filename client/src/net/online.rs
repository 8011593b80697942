//! [`OnlineGame`]: everything a GUI front end needs, on its own thread's
//! terms: the network on a [`NetThread`] and the predicted game
//! ([`ClientGame`]) on the caller's thread, polled once per frame.
//!
//! ```no_run
//! use std::time::Instant;
//! use ledge_client::{OnlineGame, OnlineRequest, Trust};
//! use ledge_shared::input::Buttons;
//!
//! let trust = Trust::KnownHosts("known_hosts".into());
//! let mut online = OnlineGame::connect(OnlineRequest::new("127.0.0.1:4433", trust, "ada"))?;
//! loop {
//!     // Each frame: feed the held buttons, then draw the view and the HUD.
//!     online.update(Instant::now(), Buttons::NONE);
//!     if let (Some(view), Some(level)) = (online.view(), online.level()) {
//!         let _ = (view.tick, level.name.as_str());
//!     }
//!     let _ = (online.status(), online.net_stats(Instant::now()));
//! }
//! # #[allow(unreachable_code)]
//! # Ok::<(), std::io::Error>(())
//! ```
//!
//! Nothing here blocks (but [`OnlineGame::wait`]): events are drained with
//! `try_recv`, inputs queued with `try_send`.

use std::collections::VecDeque;
#[cfg(not(target_arch = "wasm32"))]
use std::path::PathBuf;
use std::time::Duration;

use ledge_levels::art::LevelArt;
use ledge_levels::LevelBundle;
use ledge_shared::input::Buttons;
use ledge_shared::level::Level;
#[cfg(not(target_arch = "wasm32"))]
use ledge_shared::protocol::Fingerprint;
use ledge_shared::protocol::{
    GhostRun, LevelList, NoticeKind, PlayerId, Standing, StateSnapshot, Welcome,
};

use crate::game::ClientGame;
use crate::ghost::{Ghost, GhostBuilder, GHOST_TICKS_PER_FRAME};
#[cfg(not(target_arch = "wasm32"))]
use crate::net::background::{ConnectRequest, NetOptions, NetThread};
#[cfg(not(target_arch = "wasm32"))]
use crate::net::bundle::LevelCache;
use crate::net::download::Fetched;
use crate::net::levels::{check_level, level_for};
#[cfg(not(target_arch = "wasm32"))]
use crate::net::trust::Trust;
use crate::net::{NetEvent, NetStatus, Network};
use crate::time::Instant;
use crate::view::{FrameView, NetStats};

/// Chat lines kept.
pub const CHAT_LINES: usize = 32;

/// After this long without a snapshot (a server sends 30 a second) a
/// joined game says the connection is stalled ([`OnlineGame::stalled`]),
/// long before QUIC's idle timeout (10 s) gives up on it.
pub const STALL_AFTER: Duration = Duration::from_secs(1);

/// Where, as whom, and how to trust.
#[cfg(not(target_arch = "wasm32"))]
#[derive(Debug, Clone)]
pub struct OnlineRequest {
    /// `HOST:PORT`.
    pub server: String,
    /// Pinned fingerprint or trust on first use.
    pub trust: Trust,
    /// Our name.
    pub player_name: String,
    /// Room to join (`None`: any).
    pub room: Option<String>,
    /// A copy of the server's level file; `None` (the usual): the
    /// embedded default level, the cache, or downloaded.
    pub level: Option<PathBuf>,
    /// Where downloaded levels are cached (`None`: in memory only;
    /// [`crate::net::bundle::LevelCache::default_dir`] is the usual place).
    pub level_cache: Option<PathBuf>,
    /// Watch rather than play ([`crate::net::session::JoinOptions::spectate`]):
    /// the game has no player of ours ([`ClientGame::set_spectating`]).
    pub spectate: bool,
}

#[cfg(not(target_arch = "wasm32"))]
impl OnlineRequest {
    /// Joins any room of `server` as `player_name` on the default level.
    pub fn new(server: &str, trust: Trust, player_name: &str) -> OnlineRequest {
        OnlineRequest {
            server: server.to_owned(),
            trust,
            player_name: player_name.to_owned(),
            room: None,
            level: None,
            level_cache: LevelCache::default_dir(),
            spectate: false,
        }
    }
}

/// A networked game for a GUI: a network driver (natively the network
/// thread) plus the predicted game.
#[derive(Debug)]
pub struct OnlineGame<
    #[cfg(not(target_arch = "wasm32"))] N: Network = NetThread,
    #[cfg(target_arch = "wasm32")] N: Network,
> {
    net: N,
    status: NetStatus,
    game: Option<ClientGame>,
    level_file: Option<std::path::PathBuf>,
    name: String,
    chat: VecDeque<(PlayerId, String)>,
    /// Chat lines received in all ([`OnlineGame::chat_count`]).
    chat_count: u64,
    notices: VecDeque<NoticeKind>,
    /// A problem with the game itself (wrong level): shown, not fatal to
    /// the connection.
    error: Option<String>,
    /// Why the server's certificate was refused, if it was.
    untrusted: Option<String>,
    /// The server's level and art, once fetched.
    bundle: Option<LevelBundle>,
    /// How it was fetched.
    fetched: Option<Fetched>,
    /// The newest authoritative state.
    latest: Option<StateSnapshot>,
    /// Where our last finished run stands in the server's records, or why
    /// it was not recorded.
    standing: Option<Result<Standing, String>>,
    /// How many standings (or refusals) the server sent: tells a new one
    /// from the last when both say the same.
    standings: u64,
    /// The runs to race against, played from their replays.
    ghosts: Vec<Ghost>,
    /// Ghosts still being played from their replays (at most one of
    /// each kind), [`GHOST_TICKS_PER_FRAME`] ticks per update.
    building: Vec<GhostBuilder>,
    /// Why the last ghost the server sent could not be played, if so.
    ghost_error: Option<String>,
    /// Snapshots arrived since the last [`OnlineGame::take_arrivals`].
    arrivals: u32,
    /// When the last snapshot (or the welcome) arrived.
    last_news: Option<Instant>,
    /// The game was just created: the ticks due at its first update are
    /// nobody's play (e.g. a window was opening after a wait).
    fresh: bool,
    /// We watch rather than play ([`OnlineGame::spectating`]).
    spectate: bool,
    /// The room's levels and votes, as last heard.
    levels: Option<LevelList>,
    /// The room is moving to another level and we are downloading it:
    /// bytes so far and the level's size.
    changing: Option<(u64, u64)>,
    /// Level changes taken so far ([`OnlineGame::level_changes`]).
    level_changes: u64,
}

#[cfg(not(target_arch = "wasm32"))]
impl OnlineGame<NetThread> {
    /// Starts connecting in the background.
    pub fn connect(request: OnlineRequest) -> std::io::Result<OnlineGame> {
        let pin = match &request.trust {
            Trust::Pinned(pin) => *pin,
            Trust::KnownHosts(_) => Fingerprint([0; 32]),
        };
        let net = NetThread::spawn_with(
            ConnectRequest {
                server: request.server.clone(),
                cert_fingerprint: pin,
                player_name: request.player_name.clone(),
            },
            NetOptions {
                room: request.room.clone(),
                trust: Some(request.trust.clone()),
                download_level: request.level.is_none(),
                level_cache: request.level_cache.clone(),
                spectate: request.spectate,
            },
        )?;
        let mut game = OnlineGame::with_network(net, &request.server, &request.player_name);
        game.level_file = request.level;
        game.spectate = request.spectate;
        Ok(game)
    }

    /// Waits up to `timeout` for the network thread's first word (joined,
    /// refused, failed) and takes it, so that a refused certificate is
    /// known before, say, a window opens.
    pub fn wait(&mut self, timeout: Duration) {
        let deadline = Instant::now() + timeout;
        while let Some(event) = self
            .net
            .recv_timeout(deadline.saturating_duration_since(Instant::now()))
        {
            // The level (and its download's progress) comes before the
            // first word.
            let first_word = !matches!(event, NetEvent::Level(..) | NetEvent::LevelProgress { .. });
            self.take(event, Instant::now());
            if first_word {
                break;
            }
        }
    }

    /// The network thread (queues, counters).
    pub fn net(&self) -> &NetThread {
        &self.net
    }
}

impl<N: Network> OnlineGame<N> {
    /// A game fed by `net`, connecting to `server` as `name`.
    pub fn with_network(net: N, server: &str, name: &str) -> OnlineGame<N> {
        OnlineGame {
            net,
            status: NetStatus::Connecting(server.to_owned()),
            game: None,
            level_file: None,
            name: name.to_owned(),
            chat: VecDeque::new(),
            chat_count: 0,
            notices: VecDeque::new(),
            error: None,
            untrusted: None,
            bundle: None,
            fetched: None,
            latest: None,
            standing: None,
            standings: 0,
            ghosts: Vec::new(),
            building: Vec::new(),
            ghost_error: None,
            arrivals: 0,
            last_news: None,
            fresh: false,
            spectate: false,
            levels: None,
            changing: None,
            level_changes: 0,
        }
    }

    /// Call once per frame: takes the network's events, runs the due ticks
    /// with `buttons` and queues our inputs.
    pub fn update(&mut self, now: Instant, buttons: Buttons) {
        self.update_ticks(now, u64::MAX, |_| buttons);
    }

    /// [`OnlineGame::update`] for a fixed-step loop: runs at most
    /// `max_ticks` of the due ticks, the i-th of this call with
    /// `buttons(i)`; returns the ticks run. Those due at the game's first
    /// update (the clock ran on since the welcome) are run idle and not
    /// sent: the server assumes no buttons until our first input.
    pub fn update_ticks(
        &mut self,
        now: Instant,
        max_ticks: u64,
        buttons: impl FnMut(u64) -> Buttons,
    ) -> u64 {
        while let Some(event) = self.net.try_recv() {
            self.take(event, now);
        }
        self.build_ghosts(GHOST_TICKS_PER_FRAME);
        let Some(game) = &mut self.game else {
            return 0;
        };
        if let Some(t) = self.net.transport() {
            game.on_transport(t, now);
        }
        if std::mem::take(&mut self.fresh) {
            for _ in 0..game.advance(now) {
                game.step(Buttons::NONE);
            }
        }
        let net = &mut self.net;
        game.update(now, max_ticks, buttons, |tick, b| {
            net.send_input(tick, b);
        })
    }

    /// Takes one event from the network thread.
    fn take(&mut self, event: NetEvent, now: Instant) {
        if let NetEvent::Level(bundle, fetched) = event {
            // Kept without a copy: the game is made from it on `Connected`.
            self.fetched = Some(fetched);
            self.bundle = Some(*bundle);
            return;
        }
        self.handle(&event, now);
        match event {
            // Kept without a copy (the status has no use for it).
            NetEvent::Snapshot(update) => self.latest = Some(update.state),
            event => self.status.apply(event),
        }
    }

    fn handle(&mut self, event: &NetEvent, now: Instant) {
        match event {
            NetEvent::Connected(welcome) => {
                self.changing = None;
                self.start_game(welcome, now, false);
            }
            NetEvent::LevelChanged(welcome) => self.level_changed(welcome, now),
            NetEvent::Levels(list) => self.levels = Some((**list).clone()),
            NetEvent::LevelProgress { got, total } if self.game.is_some() => {
                self.changing = Some((*got, *total));
            }
            NetEvent::Snapshot(update) => {
                self.last_news = Some(now);
                self.arrivals = self.arrivals.saturating_add(1);
                if let Some(game) = &mut self.game {
                    game.on_snapshot(update);
                }
            }
            NetEvent::Rtt(rtt) => {
                if let Some(game) = &mut self.game {
                    game.on_rtt(*rtt);
                }
            }
            NetEvent::Chat { from, text } => {
                if self.chat.len() == CHAT_LINES {
                    self.chat.pop_front();
                }
                self.chat.push_back((*from, text.clone()));
                self.chat_count += 1;
            }
            NetEvent::Notice(kind) => {
                if self.notices.len() == CHAT_LINES {
                    self.notices.pop_front();
                }
                self.notices.push_back(kind.clone());
            }
            NetEvent::PlayerJoined { id, name } => {
                if let Some(game) = &mut self.game {
                    game.on_player_joined(*id, name);
                }
            }
            NetEvent::PlayerLeft { id } => {
                if let Some(game) = &mut self.game {
                    game.on_player_left(*id);
                }
            }
            NetEvent::RunRecorded(r) => {
                self.standing = Some(r.clone());
                self.standings += 1;
            }
            NetEvent::Ghost(run) => self.add_ghost(run),
            NetEvent::Untrusted(reason) => self.untrusted = Some(reason.clone()),
            NetEvent::Failed(_) | NetEvent::Disconnected(_) => self.changing = None,
            NetEvent::Reconnecting { .. }
            | NetEvent::LevelProgress { .. }
            | NetEvent::Level(..) => {}
        }
    }

    /// Makes the game for `welcome` at `now`: on the level downloaded (or
    /// cached, or embedded), or else the level file or the embedded level,
    /// each checked against the server's hash. `next`: the room's next
    /// level, continuing the current game's clock
    /// ([`ClientGame::next_level`]). A level that is not the server's is
    /// an error shown ([`OnlineGame::error`]), with no game.
    fn start_game(&mut self, welcome: &Welcome, now: Instant, next: bool) {
        // The clock starts from QUIC's round-trip estimate of the
        // handshake (or a guess).
        let rtt = self
            .net
            .transport()
            .map_or(Duration::from_millis(50), |t| t.rtt);
        let level = match &self.bundle {
            Some(bundle) => check_level(welcome, &bundle.level, "the downloaded level")
                .map(|()| bundle.level.clone()),
            None => level_for(welcome, self.level_file.as_deref()),
        };
        let made = level.and_then(|level| match (&self.game, next) {
            (Some(old), true) => old.next_level(welcome, level, now),
            _ => ClientGame::new(welcome, level, rtt, now),
        });
        match made {
            Ok(mut game) => {
                game.set_name(&self.name);
                game.set_spectating(self.spectate);
                game.set_player_names(&self.net.players());
                self.game = Some(game);
                // A next level's game goes on with the clock: its due
                // ticks are play.
                self.fresh = !next;
                self.last_news = Some(now);
            }
            Err(e) => {
                self.game = None;
                self.error = Some(e.to_string());
            }
        }
    }

    /// The room moved to another level (its bundle came just before): a
    /// new game on it, as on joining; the ghosts, the last run's standing
    /// and the old level's state are forgotten, the chat stays.
    fn level_changed(&mut self, welcome: &Welcome, now: Instant) {
        self.changing = None;
        self.level_changes += 1;
        self.ghosts.clear();
        self.building.clear();
        self.ghost_error = None;
        self.standing = None;
        self.latest = None;
        self.start_game(welcome, now, true);
    }

    /// Whether we watch rather than play: joined as a spectator, no
    /// player of ours in the game (every player is drawn as a remote one).
    pub fn spectating(&self) -> bool {
        self.spectate
    }

    /// Watch rather than play, for a game made with
    /// [`OnlineGame::with_network`] on a network that joined as a
    /// spectator; before the welcome.
    pub fn set_spectating(&mut self, spectate: bool) {
        self.spectate = spectate;
        if let Some(game) = &mut self.game {
            game.set_spectating(spectate);
        }
    }

    /// Where our last finished run stands in the server's records (`Err`:
    /// why it was not recorded), once the server said.
    pub fn standing(&self) -> Option<&Result<Standing, String>> {
        self.standing.as_ref()
    }

    /// How many times the server said where a finished run of ours stands
    /// (or that it was not recorded) this session: a front end that
    /// remembers this count when a run starts knows that a
    /// [`OnlineGame::standing`] is that run's once the count has grown,
    /// even when it reads the same as the run before's.
    pub fn standings(&self) -> u64 {
        self.standings
    }

    /// What to draw, once the server welcomed us and we have its level.
    pub fn view(&self) -> Option<FrameView> {
        self.game.as_ref().map(ClientGame::view)
    }

    /// How long the server has been silent, once that is more than
    /// [`STALL_AFTER`] while joined (`None` otherwise, and once the session
    /// ended: then [`OnlineGame::status`] says why).
    pub fn stalled(&self, now: Instant) -> Option<Duration> {
        if !matches!(self.status, NetStatus::Connected { .. }) {
            return None;
        }
        let silent = now.saturating_duration_since(self.last_news?);
        (silent > STALL_AFTER).then_some(silent)
    }

    /// The network panel.
    pub fn net_stats(&self, now: Instant) -> NetStats {
        self.game
            .as_ref()
            .map_or_else(NetStats::default, |g| g.net_stats(now))
    }

    /// Connection status (for the HUD line).
    pub fn status(&self) -> &NetStatus {
        &self.status
    }

    /// The game, once welcomed.
    pub fn game(&self) -> Option<&ClientGame> {
        self.game.as_ref()
    }

    /// The runs to race against (the level's record, our best), as the
    /// server sent them.
    pub fn ghosts(&self) -> &[Ghost] {
        &self.ghosts
    }

    /// Why the last ghost could not be played, if so.
    pub fn ghost_error(&self) -> Option<&str> {
        self.ghost_error.as_deref()
    }

    /// Ghosts still being played from their replays: each is added to
    /// [`OnlineGame::ghosts`] once complete (a few updates after it
    /// arrived; a 30-minute run in about a hundred).
    pub fn ghosts_building(&self) -> usize {
        self.building.len()
    }

    /// Starts playing a ghost's replay into its track
    /// ([`OnlineGame::build_ghosts`] goes on each update); it replaces the
    /// ghost of the same kind once complete, and one of its kind still
    /// being built at once.
    fn add_ghost(&mut self, run: &GhostRun) {
        let Some(level) = self.level() else {
            self.ghost_error = Some("a ghost came before the level".into());
            return;
        };
        match GhostBuilder::new(level, run) {
            Ok(builder) => {
                self.building.retain(|b| b.record() != run.record);
                self.building.push(builder);
            }
            Err(e) => {
                tracing::warn!("ghost of {} not shown: {e}", run.player);
                self.ghost_error = Some(e.to_string());
            }
        }
    }

    /// Steps the ghosts being built, `max_ticks` in all (the oldest
    /// first); a complete one replaces the ghost of its kind, one that
    /// fails is dropped with its reason ([`OnlineGame::ghost_error`]).
    fn build_ghosts(&mut self, max_ticks: u64) {
        let mut budget = max_ticks;
        let mut i = 0;
        while i < self.building.len() && budget > 0 {
            let builder = &mut self.building[i];
            match builder.build(budget) {
                Ok(n) => budget -= n,
                Err(e) => {
                    let b = self.building.remove(i);
                    tracing::warn!("ghost of {} not shown: {e}", b.player());
                    self.ghost_error = Some(e.to_string());
                    continue;
                }
            }
            if !self.building[i].is_done() {
                i += 1;
                continue;
            }
            if let Some(ghost) = self.building.remove(i).finish() {
                self.ghosts.retain(|g| g.record != ghost.record);
                self.ghosts.push(ghost);
                self.ghosts.sort_by_key(|g| !g.record);
            }
        }
    }

    /// The level, once welcomed (draw its tilemap).
    pub fn level(&self) -> Option<&Level> {
        self.game.as_ref().map(ClientGame::level)
    }

    /// The downloaded (or cached) level's art, once it arrived (`None`
    /// with a level file, or before).
    pub fn level_art(&self) -> Option<&LevelArt> {
        self.bundle.as_ref().map(|b| &b.art)
    }

    /// How the server's level was had, once it was (`None` with a level
    /// file).
    pub fn level_fetched(&self) -> Option<Fetched> {
        self.fetched
    }

    /// A problem that keeps us from playing (the server's level is not
    /// ours), if any.
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    /// Why the server's certificate was refused (the message says what to
    /// do), if it was.
    pub fn untrusted(&self) -> Option<&str> {
        self.untrusted.as_deref()
    }

    /// The newest authoritative state (where the server says things are).
    pub fn server_state(&self) -> Option<&StateSnapshot> {
        self.latest.as_ref()
    }

    /// Snapshots arrived since the last call (for an arrivals graph).
    pub fn take_arrivals(&mut self) -> u32 {
        std::mem::take(&mut self.arrivals)
    }

    /// The last chat lines, oldest first.
    pub fn chat_lines(&self) -> impl Iterator<Item = &(PlayerId, String)> {
        self.chat.iter()
    }

    /// How many chat lines were received in all (more than
    /// [`OnlineGame::chat_lines`] keeps, [`CHAT_LINES`]): a front end
    /// takes the lines that came since it last looked.
    pub fn chat_count(&self) -> u64 {
        self.chat_count
    }

    /// The last notices, oldest first.
    pub fn notices(&self) -> impl Iterator<Item = &NoticeKind> {
        self.notices.iter()
    }

    /// Says `text` in the room; `false` if it could not be queued.
    pub fn say(&mut self, text: &str) -> bool {
        self.net.chat(text)
    }

    /// The room's levels (rotation order), which is played and next, the
    /// votes, the rule and when it moves on, as last heard.
    pub fn levels(&self) -> Option<&LevelList> {
        self.levels.as_ref()
    }

    /// Votes for `level` (an index into [`OnlineGame::levels`]) to be
    /// played next; `false` when there is no such level in the list (or
    /// no list yet) or the vote could not be queued.
    pub fn vote(&mut self, level: u32) -> bool {
        let known = self
            .levels
            .as_ref()
            .is_some_and(|l| (level as usize) < l.levels.len());
        known && self.net.vote(level)
    }

    /// While the room's next level downloads: bytes so far and its size
    /// (for a progress bar); `None` otherwise (the first join's download
    /// is [`NetStatus::Downloading`]).
    pub fn changing_level(&self) -> Option<(u64, u64)> {
        self.changing
    }

    /// How many times the room moved to another level since we joined: a
    /// front end that remembers it knows when to forget what it drew of
    /// the old level (its art, the splits).
    pub fn level_changes(&self) -> u64 {
        self.level_changes
    }

    /// How long until the room moves to its next level, when that is
    /// decided ([`LevelList::change_at`]), from the newest server tick
    /// known (the game's clock before any snapshot).
    pub fn next_level_in(&self) -> Option<Duration> {
        let at = self.levels.as_ref()?.change_at?;
        let game = self.game.as_ref()?;
        let rate = game.welcome()?.timing.tick_rate.max(1);
        let now = self
            .latest
            .as_ref()
            .map_or_else(|| game.clock().tick(), |s| s.tick);
        // A tick far away (whatever the server says) is a long time, not
        // a panic.
        let secs = at.saturating_sub(now) as f64 / f64::from(rate);
        Some(Duration::try_from_secs_f64(secs).unwrap_or(Duration::MAX))
    }

    /// The network driver.
    pub fn network(&self) -> &N {
        &self.net
    }
}

#[cfg(test)]
mod tests {
    use std::collections::{BTreeMap, VecDeque};

    use std::time::Duration;

    use ledge_levels::LevelBundle;
    use ledge_shared::input::Buttons;
    use ledge_shared::protocol::{
        GhostRun, LevelChoice, LevelList, PlayerId, Standing, VoteRule, Welcome,
    };

    use super::OnlineGame;
    use crate::net::download::Fetched;
    use crate::net::{NetEvent, NetStatus, Network};
    use crate::netstats::TransportSample;
    use crate::time::Instant;

    /// A network that hands over the events queued in it.
    struct Queued(VecDeque<NetEvent>);

    impl Network for Queued {
        fn try_recv(&mut self) -> Option<NetEvent> {
            self.0.pop_front()
        }
        fn send_input(&mut self, _: u64, _: Buttons) -> bool {
            true
        }
        fn chat(&mut self, _: &str) -> bool {
            true
        }
        fn vote(&mut self, _: u32) -> bool {
            true
        }
        fn transport(&self) -> Option<TransportSample> {
            None
        }
        fn players(&self) -> BTreeMap<PlayerId, String> {
            BTreeMap::new()
        }
    }

    /// A welcome to `level`, at `tick`.
    fn welcome_to(level: &ledge_shared::level::Level, tick: u64) -> Welcome {
        Welcome {
            player_id: PlayerId(2),
            room: "room-1".into(),
            level_id: level.name.clone(),
            level_hash: level.content_hash(),
            level: Default::default(),
            session_token: Default::default(),
            server_tick: tick,
            timing: ledge_shared::protocol::NetTiming {
                tick_rate: 60,
                snapshot_interval: 2,
                input_redundancy: 16,
            },
            sim_config: vec![],
        }
    }

    fn bundle(name: &str) -> Box<LevelBundle> {
        let mut bundle = LevelBundle::default_level();
        bundle.level.name = name.into();
        Box::new(bundle)
    }

    fn two_levels(change_at: Option<u64>) -> Box<LevelList> {
        Box::new(LevelList {
            levels: ["first", "second"]
                .map(|n| LevelChoice {
                    id: n.into(),
                    name: n.into(),
                })
                .to_vec(),
            current: 0,
            next: 1,
            votes: vec![0, 1],
            rule: VoteRule::Majority,
            change_at,
        })
    }

    /// The room moves on: a new game on the new level, the old run's
    /// standing and the ghosts forgotten, the chat kept; a level that is
    /// not the server's is refused as on joining.
    #[test]
    fn a_level_change_makes_a_new_game_and_forgets_the_last_run() {
        let now = Instant::now();
        let first = bundle("first");
        let w1 = welcome_to(&first.level, 10);
        let mut game = OnlineGame::with_network(Queued(VecDeque::new()), "server", "ada");
        game.net.0.extend([
            NetEvent::Level(first.clone(), Fetched::default()),
            NetEvent::Connected(w1.clone()),
            NetEvent::Chat {
                from: PlayerId(2),
                text: "hi".into(),
            },
            NetEvent::RunRecorded(Err("records are off".into())),
            NetEvent::Levels(two_levels(Some(10 + 120))),
        ]);
        game.update(now, Buttons::NONE);
        assert_eq!(game.level().map(|l| l.name.as_str()), Some("first"));
        assert!(game.standing().is_some());
        assert_eq!(game.levels().map(|l| l.next), Some(1));
        let left = game.next_level_in().expect("change_at is set");
        assert!(left <= Duration::from_secs(2), "{left:?}");
        game.net
            .0
            .push_back(NetEvent::Levels(two_levels(Some(u64::MAX))));
        game.update(now, Buttons::NONE);
        assert!(game.next_level_in().unwrap() > Duration::from_secs(1 << 40));
        game.net
            .0
            .push_back(NetEvent::Levels(two_levels(Some(10 + 120))));
        assert!(game.vote(1));
        assert!(!game.vote(2), "no such level");
        assert_eq!(game.changing_level(), None);

        // Downloading the next level: the old game plays on meanwhile.
        game.net.0.push_back(NetEvent::LevelProgress {
            got: 100,
            total: 400,
        });
        game.update(now, Buttons::NONE);
        assert_eq!(game.changing_level(), Some((100, 400)));
        assert_eq!(game.level().map(|l| l.name.as_str()), Some("first"));

        let second = bundle("second");
        let w2 = welcome_to(&second.level, 200);
        game.net.0.extend([
            NetEvent::Level(second.clone(), Fetched::default()),
            NetEvent::LevelChanged(Box::new(w2.clone())),
        ]);
        game.update(now, Buttons::NONE);
        assert_eq!(game.error(), None);
        assert_eq!(game.level().map(|l| l.name.as_str()), Some("second"));
        assert_eq!(game.game().and_then(|g| g.welcome()), Some(&w2));
        assert_eq!(game.changing_level(), None);
        assert_eq!(game.level_changes(), 1);
        assert_eq!(game.standing(), None, "the old level's run is gone");
        assert!(game.ghosts().is_empty());
        assert_eq!(game.chat_count(), 1, "the chat stays");
        assert!(matches!(game.status(), NetStatus::Connected { welcome, .. } if *welcome == w2));

        // A level change whose level is not the one the server names.
        game.net.0.extend([
            NetEvent::Level(first, Fetched::default()),
            NetEvent::LevelChanged(Box::new(welcome_to(&second.level, 400))),
        ]);
        game.update(now, Buttons::NONE);
        assert!(game.game().is_none());
        assert!(
            game.error().is_some_and(|e| e.contains("second")),
            "{:?}",
            game.error()
        );
    }

    /// Two equal standings in a row are two: the count tells them apart.
    #[test]
    fn every_standing_the_server_sends_is_counted() {
        let standing = Standing {
            millis: 9_950,
            personal_best: 9_950,
            new_personal_best: false,
            new_record: false,
            rank: 1,
            top: Vec::new(),
        };
        let mut game = OnlineGame::with_network(Queued(VecDeque::new()), "server", "ada");
        assert_eq!((game.standings(), game.standing()), (0, None));
        game.net.0.extend([
            NetEvent::RunRecorded(Ok(standing.clone())),
            NetEvent::RunRecorded(Ok(standing.clone())),
        ]);
        game.update(Instant::now(), Buttons::NONE);
        assert_eq!(game.standings(), 2);
        assert_eq!(game.standing(), Some(&Ok(standing)));
        game.net
            .0
            .push_back(NetEvent::RunRecorded(Err("records are off".into())));
        game.update(Instant::now(), Buttons::NONE);
        assert_eq!(game.standings(), 3);
        assert_eq!(game.standing(), Some(&Err("records are off".into())));
    }

    /// Ghosts are built a budget of ticks at a time and shown once
    /// complete; a newer one of the same kind replaces the one being
    /// built; one whose replay fails says why and leaves the ghosts as
    /// they were.
    #[test]
    fn ghosts_are_built_across_updates_and_shown_once_complete() {
        use crate::ghost::tests::{diverging_run, recorded_run};
        use crate::ghost::Ghost;
        let level = bundle("default");
        let mut game = OnlineGame::with_network(Queued(VecDeque::new()), "server", "ada");
        game.net.0.extend([
            NetEvent::Level(level.clone(), Fetched::default()),
            NetEvent::Connected(welcome_to(&level.level, 10)),
        ]);
        game.update(Instant::now(), Buttons::NONE);
        let record = recorded_run(true);
        let expected = Ghost::from_run(&level.level, &record).unwrap();
        let now = Instant::now();
        game.take(NetEvent::Ghost(Box::new(recorded_run(true))), now);
        game.build_ghosts(50);
        assert_eq!(game.ghosts_building(), 1);
        assert!(game.ghosts().is_empty(), "not shown before complete");
        // A newer record replaces the one being built.
        let newer = GhostRun {
            millis: 1,
            ..record.clone()
        };
        game.take(NetEvent::Ghost(Box::new(newer)), now);
        game.take(NetEvent::Ghost(Box::new(recorded_run(false))), now);
        assert_eq!(game.ghosts_building(), 2);
        let mut updates = 0;
        while game.ghosts_building() > 0 {
            game.build_ghosts(50);
            updates += 1;
        }
        assert!(updates > 2 * u64::from(expected.ticks()) / 50, "{updates}");
        let ghosts = game.ghosts();
        assert_eq!(ghosts.len(), 2, "the record and our best");
        assert_eq!(
            ghosts[0],
            Ghost {
                millis: 1,
                ..expected.clone()
            }
        );
        assert!(!ghosts[1].record);
        assert_eq!(game.ghost_error(), None);
        // A broken best: its reason, and the ghosts stay.
        game.take(
            NetEvent::Ghost(Box::new(GhostRun {
                record: false,
                ..diverging_run()
            })),
            now,
        );
        while game.ghosts_building() > 0 {
            game.update(Instant::now(), Buttons::NONE);
        }
        assert!(
            game.ghost_error()
                .is_some_and(|e| e.contains("differently") || e.contains("hash")),
            "{:?}",
            game.ghost_error()
        );
        assert_eq!(game.ghosts().len(), 2);
    }
}
