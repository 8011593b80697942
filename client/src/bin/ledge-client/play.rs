//! The game being played, offline or online, behind one interface for the
//! render loop: [`ledge_client::game::ClientGame`] (prediction,
//! reconciliation, the remote players' interpolation, the network figures)
//! fed by the network thread.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use glam::IVec2;
use ledge_client::background::{ConnectRequest, NetEvent, NetOptions, NetStatus, NetThread};
use ledge_client::game::{ClientGame, MAX_SENDS_PER_UPDATE};
use ledge_client::levels::level_for;
use ledge_client::view::{EntityDraw, FrameView, NetStats, PlayerDraw};
use ledge_client::Trust;
use ledge_shared::game::PlayerView;
use ledge_shared::input::Buttons;
use ledge_shared::level::Level;
use ledge_shared::protocol::StateSnapshot;

use crate::render::{EntitySprite, PlayerSprite};

/// The round-trip time guessed when QUIC has not measured one.
const RTT_GUESS: Duration = Duration::from_millis(50);

impl From<&PlayerDraw> for PlayerSprite {
    fn from(p: &PlayerDraw) -> PlayerSprite {
        PlayerSprite {
            id: p.id.0,
            name: p.name.clone(),
            pos: p.pos,
            size: p.size,
            facing: p.facing,
            won: p.won,
        }
    }
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

/// The network side of an online game.
struct Net {
    thread: NetThread,
    status: NetStatus,
    /// The newest authoritative snapshot.
    latest: Option<StateSnapshot>,
    /// Snapshots arrived since the last [`Play::take_arrivals`].
    arrivals: u32,
    /// Why the server's certificate was refused, if it was.
    untrusted: Option<String>,
}

/// What is being played.
pub struct Play {
    level: Level,
    level_file: Option<PathBuf>,
    name: String,
    game: Option<ClientGame>,
    net: Option<Net>,
    failure: Option<String>,
    started: Instant,
    /// The game was just created: the ticks due at the first update are
    /// before play starts (the window was opening), run idle.
    fresh: bool,
}

impl Play {
    /// The default level offline.
    pub fn offline(level: Level, name: &str) -> anyhow::Result<Play> {
        let mut game = ClientGame::offline(level.clone(), Instant::now())?;
        game.set_name(name);
        Ok(Play {
            level,
            level_file: None,
            name: name.to_owned(),
            game: Some(game),
            net: None,
            failure: None,
            started: Instant::now(),
            fresh: false,
        })
    }

    /// Connects on a background thread, trusting the server's certificate
    /// as `trust` says; the game starts when welcomed. `level_file`: the
    /// server's level when it is not the embedded one.
    pub fn online(
        request: ConnectRequest,
        trust: Trust,
        level: Level,
        level_file: Option<PathBuf>,
    ) -> anyhow::Result<Play> {
        let name = request.player_name.clone();
        let status = NetStatus::Connecting(request.server.clone());
        let options = NetOptions {
            room: None,
            trust: Some(trust),
        };
        let thread = NetThread::spawn_with(request, options)
            .map_err(|e| anyhow::anyhow!("starting the network thread: {e}"))?;
        Ok(Play {
            level,
            level_file,
            name,
            game: None,
            net: Some(Net {
                thread,
                status,
                latest: None,
                arrivals: 0,
                untrusted: None,
            }),
            failure: None,
            started: Instant::now(),
            fresh: false,
        })
    }

    /// Polls the network, then runs the ticks due now, at most
    /// `remaining`; `buttons(i)` gives the buttons of the i-th tick run in
    /// this call. Returns the ticks run.
    pub fn update(&mut self, remaining: u64, mut buttons: impl FnMut(u64) -> Buttons) -> u64 {
        let now = Instant::now();
        self.poll(now);
        let Some(game) = &mut self.game else {
            return 0;
        };
        if std::mem::take(&mut self.fresh) {
            // Welcomed before the window opened: the clock ran on since.
            // Those ticks are nobody's play: idle, and not sent (the
            // server assumes no buttons until our first input).
            for _ in 0..game.advance(now) {
                game.step(Buttons::NONE);
            }
        }
        let due = u64::from(game.advance(now)).min(remaining);
        for i in 0..due {
            let b = buttons(i);
            let tick = game.step(b);
            // After a long frame only the newest inputs are sent: each
            // packet repeats the ticks before it anyway.
            if let Some(net) = &self.net {
                if due - i <= u64::from(MAX_SENDS_PER_UPDATE) {
                    net.thread.send_input(tick, b);
                }
            }
        }
        due
    }

    /// Waits up to `timeout` for the network thread's first word (joined,
    /// refused, failed) and takes it, so a refused certificate is known
    /// before any window opens. Returns at once offline.
    pub fn wait_for_network(&mut self, timeout: Duration) {
        let Some(net) = &mut self.net else { return };
        if let Some(event) = net.thread.recv_timeout(timeout) {
            self.handle(event, Instant::now());
        }
    }

    /// Why the server's certificate was refused (the message says what to
    /// do), if it was.
    pub fn untrusted(&self) -> Option<&str> {
        self.net.as_ref()?.untrusted.as_deref()
    }

    fn poll(&mut self, now: Instant) {
        while let Some(event) = self.net.as_ref().and_then(|n| n.thread.try_recv()) {
            self.handle(event, now);
        }
        let Some(net) = &mut self.net else { return };
        if let (Some(t), Some(game)) = (net.thread.transport(), &mut self.game) {
            game.on_transport(t, now);
        }
    }

    /// Takes one event from the network thread.
    fn handle(&mut self, event: NetEvent, now: Instant) {
        let Some(net) = &mut self.net else { return };
        match &event {
            NetEvent::Connected(welcome) => {
                // The clock starts from QUIC's round-trip estimate of
                // the handshake.
                let rtt = net.thread.transport().map_or(RTT_GUESS, |t| t.rtt);
                let made = level_for(welcome, self.level_file.as_deref())
                    .and_then(|level| ClientGame::new(welcome, level, rtt, now));
                match made {
                    Ok(mut game) => {
                        game.set_name(&self.name);
                        game.set_player_names(&net.thread.players());
                        self.level = game.level().clone();
                        self.game = Some(game);
                        self.fresh = true;
                    }
                    Err(e) => self.failure = Some(e.to_string()),
                }
            }
            NetEvent::Rtt(rtt) => {
                if let Some(game) = &mut self.game {
                    game.on_rtt(*rtt);
                }
            }
            NetEvent::Snapshot(update) => {
                net.arrivals += 1;
                if let Some(game) = &mut self.game {
                    game.on_snapshot(update);
                }
                net.latest = Some(update.state.clone());
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
            NetEvent::Untrusted(reason) => net.untrusted = Some(reason.clone()),
            _ => {}
        }
        net.status.apply(event);
    }

    /// The level played (the server's, once welcomed).
    pub fn level(&self) -> &Level {
        &self.level
    }

    /// Whether we are in a game (offline, or welcomed and started).
    pub fn joined(&self) -> bool {
        self.game.is_some()
    }

    /// Why the game cannot go on, if so.
    pub fn failure(&self) -> Option<String> {
        if let Some(f) = &self.failure {
            return Some(f.clone());
        }
        match &self.net.as_ref()?.status {
            NetStatus::Failed(r) => Some(format!("connection failed: {r}")),
            NetStatus::Disconnected(r) => Some(format!("disconnected: {r}")),
            _ => None,
        }
    }

    /// What to draw (once in a game).
    pub fn view(&self) -> Option<FrameView> {
        self.game.as_ref().map(|g| g.view())
    }

    /// The client's game (clock, predictor, the predicted world).
    pub fn game(&self) -> Option<&ClientGame> {
        self.game.as_ref()
    }

    /// Our predicted player.
    pub fn me(&self) -> Option<PlayerView> {
        let g = self.game.as_ref()?;
        g.game().player(g.me())
    }

    /// Our player as the server last said: `(tick, id, centre, half
    /// extents)` in units. Offline: the local game.
    pub fn server_me(&self) -> Option<(u64, u32, IVec2, IVec2)> {
        let g = self.game.as_ref()?;
        match &self.net {
            None => {
                let me = g.game().player(g.me())?;
                Some((g.game().tick(), me.id.0, me.pos, me.half))
            }
            Some(net) => {
                let s = net.latest.as_ref()?;
                let e = s.get(g.me().0)?;
                let half = g.game().config().player.half;
                Some((s.tick, e.id, e.pos, half))
            }
        }
    }

    /// Snapshots arrived since the last call.
    pub fn take_arrivals(&mut self) -> u32 {
        self.net
            .as_mut()
            .map_or(0, |n| std::mem::take(&mut n.arrivals))
    }

    /// The network figures (online, once in a game).
    pub fn net_stats(&self) -> Option<NetStats> {
        self.net.as_ref()?;
        Some(self.game.as_ref()?.net_stats(Instant::now()))
    }

    /// One line about the game.
    pub fn status_line(&self) -> String {
        match &self.net {
            None => format!("offline: {}", self.level.name),
            Some(net) => match &net.status {
                NetStatus::Connected { welcome, .. } => format!(
                    "online: {} on {}, you are player {}",
                    welcome.room, welcome.level_id, welcome.player_id.0
                ),
                status => status.to_string(),
            },
        }
    }

    /// A message for the middle of the screen, if any.
    pub fn banner(&self) -> Option<String> {
        if let Some(f) = self.failure() {
            return Some(f);
        }
        let net = self.net.as_ref()?;
        match &net.status {
            NetStatus::Connecting(server) => Some(format!(
                "connecting to {server}... ({:.0} s)",
                self.started.elapsed().as_secs_f32()
            )),
            NetStatus::Connected { .. } if self.game.as_ref().is_none_or(|g| !g.synced()) => {
                Some("joined: waiting for the first snapshot...".into())
            }
            _ => None,
        }
    }
}
