//! The game being played, offline or online, behind one interface for the
//! render loop: a local [`ledge_client::game::ClientGame`], or a
//! [`ledge_client::OnlineGame`] (the network thread feeding the predicted
//! game).

use std::time::Duration;

use crate::draw::anim::{spread, Animator, Pose};
use crate::draw::card::Records;
use glam::IVec2;
use ledge_client::game::ClientGame;
use ledge_client::net::NetStatus;
use ledge_client::time::Instant;
use ledge_client::view::{EntityDraw, FrameView, NetStats, PlayerDraw};
#[cfg(not(target_arch = "wasm32"))]
use ledge_client::OnlineRequest;

/// A server's game: the network thread natively, the page's connection in
/// a browser.
#[cfg(not(target_arch = "wasm32"))]
type OnlineGame = ledge_client::OnlineGame;
#[cfg(target_arch = "wasm32")]
type OnlineGame = ledge_client::OnlineGame<crate::page::WebNet>;
use ledge_shared::game::PlayerView;
use ledge_shared::input::Buttons;
use ledge_shared::level::Level;

use crate::draw::render::{EntitySprite, PlayerSprite};

impl From<&PlayerDraw> for PlayerSprite {
    fn from(p: &PlayerDraw) -> PlayerSprite {
        PlayerSprite {
            id: p.id.0,
            name: p.name.clone(),
            pos: p.pos,
            size: p.size,
            facing: p.facing,
            won: p.won,
            dead: p.dead,
            pose: Pose::still(p),
        }
    }
}

/// The players of `view` to draw this frame (ours, then the others):
/// posed by `animator` (advanced by `dt` seconds, the frame's duration)
/// and, where several stand on one spot, fanned out sideways
/// (`crate::draw::anim::spread`: ours never moves). Dead players keep
/// their place and take no part in the fanning.
pub fn sprites(
    view: &FrameView,
    animator: &mut Animator,
    dt: f32,
) -> (Option<PlayerSprite>, Vec<PlayerSprite>) {
    let all: Vec<&PlayerDraw> = view.local.iter().chain(&view.remotes).collect();
    let poses = animator.update(dt, all.iter().copied());
    let mut sprites: Vec<PlayerSprite> = all
        .iter()
        .zip(poses)
        .map(|(p, pose)| PlayerSprite {
            pose,
            ..PlayerSprite::from(*p)
        })
        .collect();
    let alive: Vec<usize> = (0..all.len()).filter(|&i| !all[i].dead).collect();
    let placed: Vec<_> = alive.iter().map(|&i| (all[i].id, all[i].pos)).collect();
    let ours = view.local.as_ref().map(|p| p.id);
    for (&i, pos) in alive.iter().zip(spread(&placed, ours)) {
        sprites[i].pos = pos;
    }
    let remotes = sprites.split_off(view.local.is_some() as usize);
    (sprites.pop(), remotes)
}

impl From<&EntityDraw> for EntitySprite {
    fn from(e: &EntityDraw) -> EntitySprite {
        EntitySprite {
            id: e.id,
            kind: e.kind,
            pos: e.pos,
            size: e.size,
            active: e.active,
            one_way: e.one_way,
            facing: e.facing,
        }
    }
}

/// Offline or online (both large: boxed).
enum Mode {
    /// A local game, no server.
    Offline(Box<ClientGame>),
    /// A server's game (once welcomed).
    Online(Box<OnlineGame>),
}

/// Which of the server's standings speak of our current run: those it
/// sent after the run was last seen unfinished (a standing is sent once
/// the finished run is stored, so after we see the finish; one the run
/// before left behind must not be shown as this run's, even if it reads
/// the same).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RunStandings {
    /// [`ledge_client::OnlineGame::standings`] when our run was last seen
    /// unfinished.
    before: u64,
}

impl RunStandings {
    /// Notes the server's count of standings so far, `count`, while our
    /// run is not `finished`.
    pub fn watch(&mut self, finished: bool, count: u64) {
        if !finished {
            self.before = count;
        }
    }

    /// What the card says of the records: `standing`, the newest (its
    /// count `count`), once it is our current run's; saving until then.
    pub fn records<'a>(
        &self,
        count: u64,
        standing: Option<&'a Result<ledge_shared::protocol::Standing, String>>,
    ) -> Records<'a> {
        match standing {
            Some(Ok(standing)) if count > self.before => Records::Recorded(standing),
            Some(Err(reason)) if count > self.before => Records::NotRecorded(reason),
            _ => Records::Saving,
        }
    }
}

/// What is being played.
pub struct Play {
    /// The level drawn until the server's is known.
    level: Level,
    mode: Mode,
    /// The server's address as the player gave it (online).
    server: String,
    started: Instant,
    /// Which standings are our current run's (online).
    standings: RunStandings,
}

impl Play {
    /// The default level offline.
    pub fn offline(level: Level, name: &str) -> anyhow::Result<Play> {
        let mut game = ClientGame::offline(level.clone(), Instant::now())?;
        game.set_name(name);
        Ok(Play {
            level,
            mode: Mode::Offline(Box::new(game)),
            server: String::new(),
            started: Instant::now(),
            standings: RunStandings::default(),
        })
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// Connects on a background thread as `request` says; the game starts
    /// when welcomed. `level` is drawn until then.
    pub fn online(request: OnlineRequest, level: Level) -> anyhow::Result<Play> {
        let server = request.server.clone();
        let online = OnlineGame::connect(request)
            .map_err(|e| anyhow::anyhow!("starting the network thread: {e}"))?;
        Ok(Play {
            level,
            mode: Mode::Online(Box::new(online)),
            server,
            started: Instant::now(),
            standings: RunStandings::default(),
        })
    }

    /// Joins the server that served the page over `net`; the game starts
    /// when welcomed. `level` is drawn until then.
    #[cfg(target_arch = "wasm32")]
    pub fn web(net: crate::page::WebNet, server: &str, level: Level, name: &str) -> Play {
        Play {
            level,
            mode: Mode::Online(Box::new(OnlineGame::with_network(net, server, name))),
            server: server.to_owned(),
            started: Instant::now(),
            standings: RunStandings::default(),
        }
    }

    /// Polls the network, then runs the ticks due now, at most
    /// `remaining`; `buttons(i)` gives the buttons of the i-th tick run in
    /// this call. Returns the ticks run.
    pub fn update(&mut self, remaining: u64, buttons: impl FnMut(u64) -> Buttons) -> u64 {
        let now = Instant::now();
        let ran = match &mut self.mode {
            Mode::Online(online) => online.update_ticks(now, remaining, buttons),
            Mode::Offline(game) => game.update(now, remaining, buttons, |_, _| {}),
        };
        let finished = self.me().is_some_and(|me| me.place.is_some());
        if let Some(count) = self.connection().map(OnlineGame::standings) {
            self.standings.watch(finished, count);
        }
        ran
    }

    /// Where our finished run stands in the server's records, for the
    /// results card: `None` offline (no records), saving until the server
    /// speaks of this run.
    pub fn records(&self) -> Option<Records<'_>> {
        let online = self.connection()?;
        Some(
            self.standings
                .records(online.standings(), online.standing()),
        )
    }

    /// Waits up to `timeout` for the network thread's first word (joined,
    /// refused, failed) and takes it, so a refused certificate is known
    /// before any window opens. Returns at once offline.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn wait_for_network(&mut self, timeout: Duration) {
        if let Mode::Online(online) = &mut self.mode {
            online.wait(timeout);
        }
    }

    /// The server's address as the player gave it (empty offline).
    pub fn server(&self) -> &str {
        &self.server
    }

    /// Says `text` in the room (checked by [`crate::chat`] first); why
    /// not, if it cannot be sent (offline, not joined, the queue full).
    pub fn say(&mut self, text: &str) -> Result<(), String> {
        match &mut self.mode {
            Mode::Offline(_) => Err("offline: nobody to chat with".to_owned()),
            Mode::Online(online) if online.game().is_none() => {
                Err("not in a game yet: wait to join".to_owned())
            }
            Mode::Online(online) => {
                if online.say(text) {
                    Ok(())
                } else {
                    Err("the connection is busy: try again".to_owned())
                }
            }
        }
    }

    /// The chat lines received since `seen` lines (a count from this
    /// call, 0 at first), oldest first, each `(sender's name, text)`
    /// with names from the roster; and the new count. Lines older than
    /// the last [`ledge_client::net::online::CHAT_LINES`] are lost.
    pub fn chat_since(&self, seen: u64) -> (u64, Vec<(String, String)>) {
        let Some(online) = self.connection() else {
            return (seen, Vec::new());
        };
        let count = online.chat_count();
        let new = usize::try_from(count.saturating_sub(seen)).unwrap_or(usize::MAX);
        let kept: Vec<_> = online.chat_lines().collect();
        let name = |id: ledge_shared::protocol::PlayerId| {
            online
                .game()
                .and_then(|g| g.player_names().get(&id).cloned())
                .unwrap_or_else(|| format!("player #{}", id.0))
        };
        let lines = kept[kept.len().saturating_sub(new)..]
            .iter()
            .map(|(from, text)| (name(*from), text.clone()))
            .collect();
        (count, lines)
    }

    /// The server's levels, votes and when the room moves on (online,
    /// once the server said).
    pub fn levels(&self) -> Option<&ledge_shared::protocol::LevelList> {
        self.connection()?.levels()
    }

    /// Votes for level `index` (0: the first of [`Play::levels`]) to be
    /// played next; why not, in words, if it cannot be.
    pub fn vote(&mut self, index: u32) -> Result<(), String> {
        let spectating = self.spectating();
        let Mode::Online(online) = &mut self.mode else {
            return Err("offline: there are no levels to vote for".to_owned());
        };
        let Some(list) = online.levels() else {
            return Err("the server has not sent its levels yet".to_owned());
        };
        if list.rule == ledge_shared::protocol::VoteRule::Off {
            return Err("this server takes no votes: its levels come in turn".to_owned());
        }
        if index as usize >= list.levels.len() {
            return Err(format!("there is no level {}", index + 1));
        }
        if spectating {
            return Err("spectators cannot vote: join as a player to vote".to_owned());
        }
        if online.vote(index) {
            Ok(())
        } else {
            Err("the connection is busy: try again".to_owned())
        }
    }

    /// How long until the room moves to its next level, when decided.
    pub fn next_level_in(&self) -> Option<Duration> {
        self.connection()?.next_level_in()
    }

    /// A level downloading: what (the server's level on joining, or the
    /// room's next one), and bytes so far of its size.
    pub fn downloading(&self) -> Option<(&'static str, u64, u64)> {
        let online = self.connection()?;
        if let Some((got, total)) = online.changing_level() {
            return Some(("the next level", got, total));
        }
        match online.status() {
            NetStatus::Downloading { got, total } => Some(("the server's level", *got, *total)),
            _ => None,
        }
    }

    /// How many times the room moved to another level (0 offline): the
    /// window forgets what it drew of the old one when this grows.
    pub fn level_changes(&self) -> u64 {
        self.connection().map_or(0, OnlineGame::level_changes)
    }

    /// The runs to race against the server sent (the level's record,
    /// our best; none offline).
    pub fn ghosts(&self) -> &[ledge_client::ghost::Ghost] {
        self.connection().map_or(&[], OnlineGame::ghosts)
    }

    /// Whether we watch rather than play (`--spectate`).
    pub fn spectating(&self) -> bool {
        self.connection().is_some_and(OnlineGame::spectating)
    }

    /// Watch rather than play (a browser page's `?spectate`; natively the
    /// request says it); before the welcome.
    #[cfg(target_arch = "wasm32")]
    pub fn set_spectating(&mut self, spectate: bool) {
        if let Mode::Online(online) = &mut self.mode {
            online.set_spectating(spectate);
        }
    }

    /// The room's name, once welcomed.
    pub fn room(&self) -> Option<&str> {
        Some(self.game()?.welcome()?.room.as_str())
    }

    /// The players in the game (ascending ids), ours left out.
    pub fn players(&self) -> Vec<ledge_shared::protocol::PlayerId> {
        let mut ids: Vec<_> = self.game().map_or_else(Vec::new, |g| {
            g.game()
                .players()
                .map(|(id, _)| id)
                .filter(|&id| id != g.me())
                .collect()
        });
        ids.sort_unstable();
        ids
    }

    /// Player `id` in the newest authoritative state: `(tick, centre in
    /// units)` (online).
    pub fn server_player(&self, id: ledge_shared::protocol::PlayerId) -> Option<(u64, IVec2)> {
        let s = self.connection()?.server_state()?;
        Some((s.tick, s.get(id.0)?.pos))
    }

    /// The online game, if online.
    fn connection(&self) -> Option<&OnlineGame> {
        match &self.mode {
            Mode::Online(online) => Some(online),
            Mode::Offline(_) => None,
        }
    }

    /// Why the server's certificate was refused (the message says what to
    /// do), if it was.
    pub fn untrusted(&self) -> Option<&str> {
        self.connection()?.untrusted()
    }

    /// The art of the server's level, once downloaded (or found in the
    /// cache); `None` offline or with a level file.
    pub fn level_art(&self) -> Option<&ledge_levels::art::LevelArt> {
        self.connection()?.level_art()
    }

    /// The server's level (online, once welcomed): its id and how many
    /// times the room moved to another level since we joined.
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    pub fn level_id(&self) -> Option<(&str, u64)> {
        let online = self.connection()?;
        let welcome = online.game()?.welcome()?;
        Some((welcome.level_id.as_str(), online.level_changes()))
    }

    /// The level played (the server's, once welcomed).
    pub fn level(&self) -> &Level {
        self.game().map_or(&self.level, ClientGame::level)
    }

    /// Whether we are in a game (offline, or welcomed and started).
    pub fn joined(&self) -> bool {
        self.game().is_some()
    }

    /// Why the game cannot go on, if so: one sentence or more, in words,
    /// naming the server and saying what to do (the window shows it, and
    /// stderr).
    pub fn failure(&self) -> Option<String> {
        let online = self.connection()?;
        let server = &self.server;
        if let Some(e) = online.error() {
            return Some(format!("cannot play on {server}: {e}"));
        }
        match online.status() {
            NetStatus::Failed(r) => Some(format!("cannot join {server}: {r}")),
            NetStatus::Disconnected(r) => Some(format!("disconnected from {server}: {r}")),
            _ => None,
        }
    }

    /// What to draw (once in a game).
    pub fn view(&self) -> Option<FrameView> {
        self.game().map(ClientGame::view)
    }

    /// The client's game (clock, predictor, the predicted world).
    pub fn game(&self) -> Option<&ClientGame> {
        match &self.mode {
            Mode::Offline(game) => Some(game),
            Mode::Online(online) => online.game(),
        }
    }

    /// Simulation ticks per second (the server's; 60 offline).
    pub fn tick_rate(&self) -> u32 {
        self.game()
            .and_then(ClientGame::welcome)
            .map_or(60, |w| w.timing.tick_rate)
    }

    /// Our predicted player.
    pub fn me(&self) -> Option<PlayerView> {
        let g = self.game()?;
        g.game().player(g.me())
    }

    /// Our player as the server last said: `(tick, id, centre, half
    /// extents)` in units. Offline: the local game.
    pub fn server_me(&self) -> Option<(u64, u32, IVec2, IVec2)> {
        let g = self.game()?;
        match self.connection() {
            None => {
                let me = g.game().player(g.me())?;
                Some((g.game().tick(), me.id.0, me.pos, me.half))
            }
            Some(online) => {
                let s = online.server_state()?;
                let e = s.get(g.me().0)?;
                let half = g.game().config().player.half;
                Some((s.tick, e.id, e.pos, half))
            }
        }
    }

    /// Snapshots arrived since the last call.
    pub fn take_arrivals(&mut self) -> u32 {
        match &mut self.mode {
            Mode::Online(online) => online.take_arrivals(),
            Mode::Offline(_) => 0,
        }
    }

    /// The network figures (online, once in a game).
    pub fn net_stats(&self) -> Option<NetStats> {
        Some(self.connection()?.game()?.net_stats(Instant::now()))
    }

    /// How long the server has been silent, when that is unusual.
    fn stalled(&self) -> Option<Duration> {
        self.connection()?.stalled(Instant::now())
    }

    /// One short line about the game (a failure's reason is the
    /// banner's, not this line's: it would not fit).
    pub fn status_line(&self) -> String {
        match self.connection().map(OnlineGame::status) {
            None => format!("offline: {}", self.level.name),
            Some(NetStatus::Connected { welcome, .. }) => match self.stalled() {
                Some(silent) => format!(
                    "reconnecting... (nothing from {} for {:.0} s)",
                    self.server,
                    silent.as_secs_f32()
                ),
                None if self.spectating() => format!(
                    "spectating: {} on {}{}",
                    welcome.room,
                    welcome.level_id,
                    self.via()
                ),
                None => format!(
                    "online: {} on {}, you are player {}{}",
                    welcome.room,
                    welcome.level_id,
                    welcome.player_id.0,
                    self.via()
                ),
            },
            Some(NetStatus::Failed(_)) => format!("could not join {}", self.server),
            Some(NetStatus::Disconnected(_)) => format!("disconnected from {}", self.server),
            Some(status) => status.to_string(),
        }
    }

    /// How the browser reached the server (" via WebTransport"); nothing
    /// natively (always QUIC).
    fn via(&self) -> String {
        #[cfg(target_arch = "wasm32")]
        if let Some(name) = self.connection().and_then(|o| o.network().transport_name()) {
            return format!(" via {name}");
        }
        String::new()
    }

    /// A message for the middle of the screen while connecting or waiting,
    /// if any (failures: [`Play::failure`]).
    pub fn banner(&self) -> Option<String> {
        match self.connection()?.status() {
            NetStatus::Connecting(server) => Some(format!(
                "connecting to {server}... ({:.0} s)",
                self.started.elapsed().as_secs_f32()
            )),
            NetStatus::Connected { .. } if self.game().is_none_or(|g| !g.synced()) => {
                Some("joined: waiting for the first snapshot...".into())
            }
            NetStatus::Connected { .. } => self.stalled().map(|silent| {
                format!(
                    "reconnecting... nothing from {} for {:.0} s",
                    self.server,
                    silent.as_secs_f32()
                )
            }),
            NetStatus::Reconnecting { attempt } => Some(format!(
                "connection to {} lost: reconnecting... (attempt {}; your player is kept \
                 for 30 s; Esc quits)",
                self.server,
                attempt + 1
            )),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::RunStandings;
    use crate::draw::card::Records;
    use ledge_shared::protocol::Standing;

    fn standing(millis: u64) -> Standing {
        Standing {
            millis,
            personal_best: millis,
            new_personal_best: true,
            new_record: false,
            rank: 2,
            top: Vec::new(),
        }
    }

    /// A standing counts for the run it came after: saving until the
    /// server speaks of the run seen finishing, even when what it said of
    /// the run before reads the same.
    #[test]
    fn only_a_standing_sent_after_the_run_shows_on_its_card() {
        let first = Ok(standing(9_950));
        let mut runs = RunStandings::default();
        // Running, then finished: nothing from the server yet.
        runs.watch(false, 0);
        runs.watch(true, 0);
        assert_eq!(runs.records(0, None), Records::Saving);
        // The server's word on it: shown.
        runs.watch(true, 1);
        assert_eq!(
            runs.records(1, Some(&first)),
            Records::Recorded(&standing(9_950))
        );
        // Run again: that word belongs to the first run, even read the
        // same as the next one's will.
        runs.watch(false, 1);
        runs.watch(true, 1);
        assert_eq!(runs.records(1, Some(&first)), Records::Saving);
        let refused = Err("the records are off".to_owned());
        runs.watch(true, 2);
        assert_eq!(
            runs.records(2, Some(&refused)),
            Records::NotRecorded("the records are off")
        );
        // A word that came in the same frame as the finish counts.
        let mut late = RunStandings::default();
        late.watch(false, 3);
        late.watch(true, 4);
        assert_eq!(
            late.records(4, Some(&first)),
            Records::Recorded(&standing(9_950))
        );
    }
}
