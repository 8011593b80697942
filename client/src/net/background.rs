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

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

use ledge_shared::input::Buttons;
use ledge_shared::protocol::{CloseCode, Fingerprint, PlayerId};
use tokio::sync::oneshot;

use crate::error::ClientError;
use crate::net::bundle::{fetch_level, FetchOptions, LevelCache};
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
    // Set once joined: then a lost connection is resumed.
    let mut lost: Option<(Instant, u32)> = None;
    let mut joined_once = false;
    loop {
        let connecting = async {
            let hello = join.hello();
            ledge_shared::protocol::Message::validate(&hello)?;
            let dial = dial_trusted(&request.server, &trust);
            let (dialed, trusted) = if joined_once {
                // A reconnect attempt through a dead link must not hang for
                // the whole QUIC idle timeout, but only the QUIC handshake
                // is cut short: once our hello is out, the server may have
                // given our player to this connection, and dropping it
                // then closes it without a `Leave`, which the server takes
                // as leaving (the player gone, the next attempt a new
                // player). Past the handshake the link works, and the idle
                // timeout bounds the rest.
                tokio::time::timeout(RECONNECT_ATTEMPT, dial)
                    .await
                    .unwrap_or(Err(ClientError::Timeout))?
            } else {
                dial.await?
            };
            Ok::<_, ClientError>((handshake(dialed, hello).await?, trusted))
        };
        let result = tokio::select! {
            _ = &mut quit => return,
            result = connecting => result,
        };
        let mut session = match (result, lost) {
            (Ok((session, _)), _) => session,
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
                if !reconnectable(&e) || since.elapsed() >= RECONNECT_FOR {
                    events.send(NetEvent::Disconnected(format!(
                        "lost the connection and could not reconnect within {} s: {e}",
                        RECONNECT_FOR.as_secs()
                    )));
                    return;
                }
                let attempt = attempt + 1;
                lost = Some((since, attempt));
                events.send(NetEvent::Reconnecting { attempt });
                let backoff = RECONNECT_BACKOFF * 2u32.pow(attempt.min(4));
                tokio::select! {
                    _ = &mut quit => return,
                    () = tokio::time::sleep(backoff.min(RECONNECT_BACKOFF_MAX)) => {}
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
        if options.download_level && !joined_once {
            let fetch = FetchOptions {
                cache: options.level_cache.clone().map(LevelCache::new),
                cut_after: None,
            };
            let total = session.welcome().level.size;
            let mut shown = 0;
            let fetched = fetch_level(&mut session, &fetch, |got, total| {
                // A few dozen updates, not one per read.
                if got == total || got >= shown + total / 32 {
                    shown = got;
                    events.send(NetEvent::LevelProgress { got, total });
                }
            });
            let result = tokio::select! {
                _ = &mut quit => return,
                result = fetched => result,
            };
            match result {
                Ok((bundle, fetched)) => {
                    tracing::info!("{}", fetched.describe(total));
                    events.send(NetEvent::Level(Box::new(bundle), fetched));
                }
                Err(e) => {
                    events.send(NetEvent::Failed(e.to_string()));
                    session.close().await;
                    return;
                }
            }
        }
        joined_once = true;
        match serve(&mut session, &events, &mut commands, &mut quit).await {
            Served::Quit => {
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

/// How a joined session's loop ended.
enum Served {
    /// The front end is gone or asked to quit.
    Quit,
    /// The session failed.
    Failed(ClientError),
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

/// Runs a joined session: inputs and chat out, events in, until it fails
/// or the front end quits.
async fn serve(
    session: &mut Session,
    events: &Events,
    commands: &mut tokio::sync::mpsc::Receiver<NetCommand>,
    quit: &mut oneshot::Receiver<()>,
) -> Served {
    let sample = |s: &Session| {
        if let Ok(mut slot) = events.transport.lock() {
            *slot = Some(TransportSample::of(s.connection()));
        }
    };
    let roster = |s: &Session| {
        if let Ok(mut slot) = events.players.lock() {
            slot.clone_from(s.players());
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
                Some(NetCommand::Input { tick, buttons }) => {
                    // A full datagram queue is not fatal: the next input
                    // repeats this one.
                    if let Err(e) = session.send_input(tick, buttons) {
                        tracing::debug!("input not sent: {e}");
                    }
                    Ok(true)
                }
                Some(NetCommand::Chat(text)) => session.chat(&text).await.map(|()| true),
                None => return Served::Quit,
            },
            _ = ticker.tick() => session.send_ping().await.map(|_| true),
            event = session.recv() => event.map(|event| {
                if matches!(
                    event,
                    SessionEvent::PlayerJoined { .. } | SessionEvent::PlayerLeft { .. }
                ) {
                    roster(session);
                }
                NetEvent::from_session(event).is_none_or(|event| events.send(event))
            }),
        };
        match result {
            Ok(true) => {}
            Ok(false) => return Served::Quit,
            Err(e) => return Served::Failed(e),
        }
    }
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
