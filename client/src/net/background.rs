//! The network on a background thread, for front ends that own the main
//! thread (macroquad).
//!
//! [`NetThread::spawn`] starts a thread running a small tokio runtime that
//! connects, then pings once a second so the front end can show the
//! round-trip time, sends the inputs the front end hands it
//! ([`NetThread::send_input`], once per tick) and chat lines, and reports
//! decoded snapshots, chat, notices and players joining or leaving as
//! [`NetEvent`]s; the room's roster is also readable at any time
//! ([`NetThread::players`]). The front end polls
//! [`NetThread::try_recv`] once per frame (never blocking) and folds events
//! into a [`NetStatus`]. Both directions are bounded queues: when one is
//! full (a front end that stopped polling), new events or commands are
//! dropped and counted rather than piling up.
//!
//! When the room moves to another level, the thread gets that level
//! (embedded, cached or downloaded, with [`NetEvent::LevelProgress`]) and
//! reports it ([`NetEvent::Level`]), then the change
//! ([`NetEvent::LevelChanged`]); a session resumed after the room moved on
//! while we were away is reported the same way. Votes go out with
//! [`NetThread::vote`].

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

use ledge_levels::LevelBundle;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{CloseCode, Fingerprint, LevelOffer, PlayerId, Welcome};
use tokio::sync::oneshot;

use crate::error::ClientError;
use crate::net::bundle::{fetch_level, FetchOptions, Fetched, LevelCache};
use crate::net::download::level_change_failed;
use crate::net::session::{handshake, JoinOptions, Session, SessionEvent};
use crate::net::trust::{dial_trusted, Trust};
use crate::net::Network;
pub use crate::net::{NetEvent, NetStatus};
use crate::netstats::TransportSample;

/// How often the background thread pings the server.
const PING_INTERVAL: Duration = Duration::from_secs(1);
/// How long a client keeps trying to reconnect after losing a joined
/// session (the server's default reconnect grace).
pub const RECONNECT_FOR: Duration = Duration::from_secs(30);
/// Longest the QUIC handshake of one reconnect attempt may take.
const RECONNECT_ATTEMPT: Duration = Duration::from_secs(3);
/// First wait between reconnect attempts (doubling up to the max).
const RECONNECT_BACKOFF: Duration = Duration::from_millis(250);
/// Longest wait between reconnect attempts.
const RECONNECT_BACKOFF_MAX: Duration = Duration::from_secs(2);
/// How often the background thread reads QUIC's counters.
const TRANSPORT_INTERVAL: Duration = Duration::from_millis(250);
/// Events waiting for the front end; more are dropped.
pub const EVENT_QUEUE: usize = 512;
/// Commands waiting for the network thread; more are dropped.
pub const COMMAND_QUEUE: usize = 256;

/// Where and as whom to connect.
#[derive(Debug, Clone)]
pub struct ConnectRequest {
    /// `HOST:PORT` of the server.
    pub server: String,
    /// The pinned SHA-256 fingerprint of the server's certificate.
    pub cert_fingerprint: Fingerprint,
    /// Our player name.
    pub player_name: String,
}

/// Extra choices for [`NetThread::spawn_with`].
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct NetOptions {
    /// The room to join; `None`: the server picks the least full one.
    pub room: Option<String>,
    /// How to trust the server's certificate; `None`: pinned to
    /// [`ConnectRequest::cert_fingerprint`]. With
    /// [`Trust::KnownHosts`] (trust on first use) the request's
    /// fingerprint is ignored.
    pub trust: Option<Trust>,
    /// Get the server's level after joining (embedded, cached or
    /// downloaded: [`crate::net::bundle::fetch_level`]) and send it as
    /// [`NetEvent::Level`] before [`NetEvent::Connected`]; `false` when the
    /// front end has the level file.
    pub download_level: bool,
    /// Where downloaded levels are cached (`None`: in memory only).
    pub level_cache: Option<PathBuf>,
    /// Join to watch ([`JoinOptions::spectate`]): no body in the game.
    pub spectate: bool,
}

/// What the front end asks the network thread to do.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum NetCommand {
    /// Send our buttons for `tick` (with the redundant ticks before it).
    Input {
        /// The tick the buttons are for.
        tick: u64,
        /// The buttons held.
        buttons: Buttons,
    },
    /// Say something in the room.
    Chat(String),
    /// Vote for the level the room plays next (an index into the
    /// [`NetEvent::Levels`] list).
    Vote(u32),
}

/// A running network thread. Dropping it leaves the server and joins the
/// thread (bounded by the session's close linger).
#[derive(Debug)]
pub struct NetThread {
    events: mpsc::Receiver<NetEvent>,
    commands: tokio::sync::mpsc::Sender<NetCommand>,
    dropped: Arc<AtomicU64>,
    transport: Arc<Mutex<Option<TransportSample>>>,
    players: Arc<Mutex<BTreeMap<PlayerId, String>>>,
    quit: Option<oneshot::Sender<()>>,
    thread: Option<thread::JoinHandle<()>>,
}

impl NetThread {
    /// Starts the thread and begins connecting (to any room).
    pub fn spawn(request: ConnectRequest) -> std::io::Result<NetThread> {
        NetThread::spawn_with(request, NetOptions::default())
    }

    /// Starts the thread and begins connecting, with `options`.
    pub fn spawn_with(request: ConnectRequest, options: NetOptions) -> std::io::Result<NetThread> {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()?;
        let (events_tx, events) = mpsc::sync_channel(EVENT_QUEUE);
        let (commands, commands_rx) = tokio::sync::mpsc::channel(COMMAND_QUEUE);
        let (quit, quit_rx) = oneshot::channel();
        let dropped = Arc::new(AtomicU64::new(0));
        let transport = Arc::new(Mutex::new(None));
        let players = Arc::new(Mutex::new(BTreeMap::new()));
        let events_tx = Events {
            tx: events_tx,
            dropped: dropped.clone(),
            transport: transport.clone(),
            players: players.clone(),
        };
        let thread = thread::Builder::new()
            .name("ledge-net".into())
            .spawn(move || {
                runtime.block_on(run(request, options, events_tx, commands_rx, quit_rx))
            })?;
        Ok(NetThread {
            events,
            commands,
            dropped,
            transport,
            players,
            quit: Some(quit),
            thread: Some(thread),
        })
    }

    /// The next pending event, if any; never blocks.
    pub fn try_recv(&self) -> Option<NetEvent> {
        self.events.try_recv().ok()
    }

    /// Queues a command; `false` if it was dropped (queue full, or the
    /// network thread has ended). Never blocks.
    pub fn send(&self, command: NetCommand) -> bool {
        let sent = self.commands.try_send(command).is_ok();
        if !sent {
            self.dropped.fetch_add(1, Ordering::Relaxed);
        }
        sent
    }

    /// Sends our buttons for `tick` (call once per simulated tick).
    pub fn send_input(&self, tick: u64, buttons: Buttons) -> bool {
        self.send(NetCommand::Input { tick, buttons })
    }

    /// Says `text` in the room.
    pub fn chat(&self, text: &str) -> bool {
        self.send(NetCommand::Chat(text.to_owned()))
    }

    /// Votes for the level the room plays next (an index into the
    /// [`NetEvent::Levels`] list).
    pub fn vote(&self, level: u32) -> bool {
        self.send(NetCommand::Vote(level))
    }

    /// QUIC's byte counters and RTT, read by the network thread every
    /// quarter second (`None` before connecting).
    pub fn transport(&self) -> Option<TransportSample> {
        self.transport.lock().ok().and_then(|t| *t)
    }

    /// Who is in our room, by id (us included), as the network thread last
    /// heard: at most [`ledge_shared::protocol::MAX_ROSTER`] names. Unlike
    /// the [`NetEvent::PlayerJoined`] events it cannot miss an update when
    /// the event queue overflows.
    pub fn players(&self) -> BTreeMap<PlayerId, String> {
        self.players.lock().map(|p| p.clone()).unwrap_or_default()
    }

    /// Events and commands dropped so far because a queue was full.
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }

    /// Waits up to `timeout` for the next event (for headless callers).
    pub fn recv_timeout(&self, timeout: Duration) -> Option<NetEvent> {
        self.events.recv_timeout(timeout).ok()
    }
}

impl Network for NetThread {
    fn try_recv(&mut self) -> Option<NetEvent> {
        NetThread::try_recv(self)
    }

    fn send_input(&mut self, tick: u64, buttons: Buttons) -> bool {
        NetThread::send_input(self, tick, buttons)
    }

    fn chat(&mut self, text: &str) -> bool {
        NetThread::chat(self, text)
    }

    fn vote(&mut self, level: u32) -> bool {
        NetThread::vote(self, level)
    }

    fn transport(&self) -> Option<TransportSample> {
        NetThread::transport(self)
    }

    fn players(&self) -> BTreeMap<PlayerId, String> {
        NetThread::players(self)
    }
}

impl Drop for NetThread {
    fn drop(&mut self) {
        if let Some(quit) = self.quit.take() {
            let _ = quit.send(());
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The bounded event queue to the front end.
struct Events {
    tx: mpsc::SyncSender<NetEvent>,
    dropped: Arc<AtomicU64>,
    transport: Arc<Mutex<Option<TransportSample>>>,
    players: Arc<Mutex<BTreeMap<PlayerId, String>>>,
}

impl Events {
    /// Queues an event; `false` once the front end is gone.
    fn send(&self, event: NetEvent) -> bool {
        match self.tx.try_send(event) {
            Ok(()) => true,
            Err(mpsc::TrySendError::Full(_)) => {
                self.dropped.fetch_add(1, Ordering::Relaxed);
                true
            }
            Err(mpsc::TrySendError::Disconnected(_)) => false,
        }
    }
}

async fn run(
    request: ConnectRequest,
    options: NetOptions,
    events: Events,
    mut commands: tokio::sync::mpsc::Receiver<NetCommand>,
    mut quit: oneshot::Receiver<()>,
) {
    let trust = options
        .trust
        .clone()
        .unwrap_or(Trust::Pinned(request.cert_fingerprint));
    let mut join = JoinOptions {
        player_name: request.player_name.clone(),
        room: options.room.clone(),
        resume: None,
        spectate: options.spectate,
    };
    let mut levels = Levels {
        fetch: FetchOptions {
            cache: options.level_cache.clone().map(LevelCache::new),
            cut_after: None,
        },
        have: None,
        reported: None,
    };
    // Set once joined: then a lost connection is resumed.
    let mut lost: Option<(Instant, u32)> = None;
    loop {
        let joined_once = levels.have.is_some();
        let result = tokio::select! {
            _ = &mut quit => return,
            result = connect(&request.server, &trust, &join, joined_once) => result,
        };
        let mut session = match (result, lost) {
            (Ok(session), _) => session,
            (Err(e), None) => {
                let untrusted = matches!(
                    e,
                    ClientError::Trust(_) | ClientError::FingerprintMismatch { .. }
                );
                events.send(if untrusted {
                    NetEvent::Untrusted(e.to_string())
                } else {
                    NetEvent::Failed(e.to_string())
                });
                return;
            }
            (Err(e), Some((since, attempt))) => {
                match retry(&e, since, attempt, &events, &mut quit).await {
                    Some(again) => lost = Some(again),
                    None => return,
                }
                continue;
            }
        };
        join.resume = Some(session.welcome().session_token);
        if let Some((since, _)) = lost.take() {
            tracing::info!(
                "reconnected after {:.1} s as player {}",
                since.elapsed().as_secs_f32(),
                session.welcome().player_id
            );
        }
        let served = match levels
            .joined(&mut session, &options, &events, &mut quit)
            .await
        {
            Ok(()) => serve(&mut session, &mut levels, &events, &mut commands, &mut quit).await,
            Err(served) => served,
        };
        match served {
            Served::Quit => {
                session.close().await;
                return;
            }
            Served::NoLevel(message) => {
                events.send(NetEvent::Failed(message));
                session.close().await;
                return;
            }
            Served::Failed(e) if reconnectable(&e) => {
                tracing::info!("connection lost ({e}); reconnecting");
                events.send(NetEvent::Reconnecting { attempt: 0 });
                lost = Some((Instant::now(), 0));
            }
            Served::Failed(e) => {
                events.send(NetEvent::Disconnected(e.to_string()));
                return;
            }
        }
    }
}

/// A reconnect attempt (`attempt` failed ones since the connection was
/// lost at `since`) failed with `e`: waits before the next one and
/// returns the new count, or `None` when reconnecting is over (not
/// reconnectable, too late: reported; or the front end quit).
async fn retry(
    e: &ClientError,
    since: Instant,
    attempt: u32,
    events: &Events,
    quit: &mut oneshot::Receiver<()>,
) -> Option<(Instant, u32)> {
    if !reconnectable(e) || since.elapsed() >= RECONNECT_FOR {
        events.send(NetEvent::Disconnected(format!(
            "lost the connection and could not reconnect within {} s: {e}",
            RECONNECT_FOR.as_secs()
        )));
        return None;
    }
    let attempt = attempt + 1;
    events.send(NetEvent::Reconnecting { attempt });
    let backoff = RECONNECT_BACKOFF * 2u32.pow(attempt.min(4));
    tokio::select! {
        _ = &mut *quit => None,
        () = tokio::time::sleep(backoff.min(RECONNECT_BACKOFF_MAX)) => Some((since, attempt)),
    }
}

/// Dials `server` and sends the hello `join` says. A reconnect attempt
/// (`reconnecting`) gives the QUIC handshake [`RECONNECT_ATTEMPT`].
async fn connect(
    server: &str,
    trust: &Trust,
    join: &JoinOptions,
    reconnecting: bool,
) -> Result<Session, ClientError> {
    let hello = join.hello();
    ledge_shared::protocol::Message::validate(&hello)?;
    let dial = dial_trusted(server, trust);
    let (dialed, _trusted) = if reconnecting {
        // A reconnect attempt through a dead link must not hang for the
        // whole QUIC idle timeout, but only the QUIC handshake is cut
        // short: once our hello is out, the server may have given our
        // player to this connection, and dropping it then closes it
        // without a `Leave`, which the server takes as leaving (the player
        // gone, the next attempt a new player). Past the handshake the
        // link works, and the idle timeout bounds the rest.
        tokio::time::timeout(RECONNECT_ATTEMPT, dial)
            .await
            .unwrap_or(Err(ClientError::Timeout))?
    } else {
        dial.await?
    };
    handshake(dialed, hello).await
}

/// The levels the front end was given: how to fetch one, and which it has.
struct Levels {
    fetch: FetchOptions,
    /// The level the front end has (`None`: not joined yet).
    have: Option<LevelOffer>,
    /// The welcome the front end was last given (on joining or by a level
    /// change): a level change the join already had is not one.
    reported: Option<Welcome>,
}

impl Levels {
    /// A session was welcomed: on the first join the level is fetched if
    /// the options say so ([`NetOptions::download_level`]); on a resume,
    /// if the room plays another level than the front end has (it moved
    /// on while we were away), that one is fetched and reported as a level
    /// change. `Err`: the session ends so.
    async fn joined(
        &mut self,
        session: &mut Session,
        options: &NetOptions,
        events: &Events,
        quit: &mut oneshot::Receiver<()>,
    ) -> Result<(), Served> {
        let offer = session.welcome().level;
        let first = self.have.is_none();
        // `serve` reports this welcome first.
        self.reported = Some(session.welcome().clone());
        if (first && !options.download_level) || self.have == Some(offer) {
            self.have = Some(offer);
            return Ok(());
        }
        let (bundle, fetched) = match fetch(session, &self.fetch, events, quit).await {
            None => return Err(Served::Quit),
            Some(Ok(level)) => level,
            Some(Err(e)) if first => return Err(Served::NoLevel(e.to_string())),
            Some(Err(e)) => {
                return Err(Served::NoLevel(level_change_failed(session.welcome(), &e)))
            }
        };
        self.have = Some(offer);
        events.send(NetEvent::Level(Box::new(bundle), fetched));
        if !first {
            events.send(NetEvent::LevelChanged(Box::new(session.welcome().clone())));
        }
        Ok(())
    }

    /// The room moved to the level of `welcome`: fetch it (the session's
    /// latest welcome; an older change still queued is skipped), then
    /// report it and the change.
    async fn changed(
        &mut self,
        session: &mut Session,
        welcome: &Welcome,
        events: &Events,
        quit: &mut oneshot::Receiver<()>,
    ) -> Result<(), Served> {
        if welcome != session.welcome() || self.reported.as_ref() == Some(welcome) {
            // Another change came after this one (that one is fetched), or
            // the welcome of our join already was this level's.
            return Ok(());
        }
        let (bundle, fetched) = match fetch(session, &self.fetch, events, quit).await {
            None => return Err(Served::Quit),
            Some(Ok(level)) => level,
            Some(Err(e)) => return Err(Served::NoLevel(level_change_failed(welcome, &e))),
        };
        self.have = Some(welcome.level);
        self.reported = Some(welcome.clone());
        events.send(NetEvent::Level(Box::new(bundle), fetched));
        events.send(NetEvent::LevelChanged(Box::new(welcome.clone())));
        Ok(())
    }
}

/// Gets the session's current level (embedded, cached or downloaded),
/// reporting the download's progress; `None` if the front end quit
/// meanwhile.
async fn fetch(
    session: &mut Session,
    options: &FetchOptions,
    events: &Events,
    quit: &mut oneshot::Receiver<()>,
) -> Option<Result<(LevelBundle, Fetched), ClientError>> {
    let total = session.welcome().level.size;
    let mut shown = 0;
    let fetched = fetch_level(session, options, |got, total| {
        // A few dozen updates, not one per read.
        if got == total || got >= shown + total / 32 {
            shown = got;
            events.send(NetEvent::LevelProgress { got, total });
        }
    });
    let result = tokio::select! {
        _ = &mut *quit => return None,
        result = fetched => result,
    };
    if let Ok((_, fetched)) = &result {
        tracing::info!("{}", fetched.describe(total));
    }
    Some(result)
}

/// How a joined session's loop ended.
enum Served {
    /// The front end is gone or asked to quit.
    Quit,
    /// The session failed.
    Failed(ClientError),
    /// The level could not be had (the message says which and why).
    NoLevel(String),
}

/// Whether a session that failed with `e` may come back by reconnecting:
/// a lost link or a server going away (it may be restarting), not a kick,
/// a refusal or a protocol error.
fn reconnectable(e: &ClientError) -> bool {
    match e {
        ClientError::Connection(_)
        | ClientError::Timeout
        | ClientError::Stream(_)
        | ClientError::StreamEnded
        | ClientError::Socket(_) => true,
        ClientError::ClosedByServer { code, .. } => {
            matches!(code, Some(CloseCode::ServerShutdown | CloseCode::Timeout))
        }
        _ => false,
    }
}

/// Runs a joined session: inputs, chat and votes out, events in (a level
/// change fetched on the way), until it fails or the front end quits.
async fn serve(
    session: &mut Session,
    levels: &mut Levels,
    events: &Events,
    commands: &mut tokio::sync::mpsc::Receiver<NetCommand>,
    quit: &mut oneshot::Receiver<()>,
) -> Served {
    let sample = |s: &Session| {
        if let Ok(mut slot) = events.transport.lock() {
            *slot = Some(TransportSample::of(s.connection()));
        }
    };
    sample(session);
    events.send(NetEvent::Connected(session.welcome().clone()));
    let mut ticker = tokio::time::interval(PING_INTERVAL);
    let mut transport_ticker = tokio::time::interval(TRANSPORT_INTERVAL);
    loop {
        let result = tokio::select! {
            _ = &mut *quit => return Served::Quit,
            _ = transport_ticker.tick() => {
                sample(session);
                Ok(true)
            }
            command = commands.recv() => match command {
                Some(command) => run_command(session, command).await,
                None => return Served::Quit,
            },
            _ = ticker.tick() => session.send_ping().await.map(|_| true),
            event = session.recv() => match event {
                Ok(SessionEvent::LevelChange(welcome)) => {
                    if let Err(served) = levels.changed(session, &welcome, events, quit).await {
                        return served;
                    }
                    Ok(true)
                }
                Ok(event) => Ok(report(session, events, event)),
                Err(e) => Err(e),
            },
        };
        match result {
            Ok(true) => {}
            Ok(false) => return Served::Quit,
            Err(e) => return Served::Failed(e),
        }
    }
}

/// Does what the front end asked.
async fn run_command(session: &mut Session, command: NetCommand) -> Result<bool, ClientError> {
    match command {
        NetCommand::Input { tick, buttons } => {
            // A full datagram queue is not fatal: the next input repeats
            // this one.
            if let Err(e) = session.send_input(tick, buttons) {
                tracing::debug!("input not sent: {e}");
            }
            Ok(true)
        }
        NetCommand::Chat(text) => session.chat(&text).await.map(|()| true),
        NetCommand::Vote(level) => session.vote(level).await.map(|()| true),
    }
}

/// Hands a session's event to the front end (the roster kept up to date
/// first); `false` once the front end is gone.
fn report(session: &Session, events: &Events, event: SessionEvent) -> bool {
    if matches!(
        event,
        SessionEvent::PlayerJoined { .. } | SessionEvent::PlayerLeft { .. }
    ) {
        if let Ok(mut slot) = events.players.lock() {
            slot.clone_from(session.players());
        }
    }
    NetEvent::from_session(event).is_none_or(|event| events.send(event))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bad_address_fails_without_blocking() {
        let net = NetThread::spawn(ConnectRequest {
            server: "no port here".into(),
            cert_fingerprint: Fingerprint([0; 32]),
            player_name: "ada".into(),
        })
        .unwrap();
        let event = net.recv_timeout(Duration::from_secs(5));
        assert!(matches!(event, Some(NetEvent::Failed(_))), "{event:?}");
    }
}
