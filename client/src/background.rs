//! The network on a background thread, for front ends that own the main
//! thread (macroquad).
//!
//! [`NetThread::spawn`] starts a thread running a small tokio runtime that
//! connects, then pings once a second so the front end can show the
//! round-trip time. The front end polls [`NetThread::try_recv`] once per
//! frame (never blocking) and folds events into a [`NetStatus`].

use std::fmt;
use std::sync::mpsc;
use std::thread;
use std::time::Duration;

use ledge_server::protocol::Welcome;
use ledge_server::Fingerprint;
use tokio::sync::oneshot;

use crate::session::connect;
use crate::transport::resolve;

/// How often the background thread pings the server.
const PING_INTERVAL: Duration = Duration::from_secs(1);

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

/// What the background thread reports.
#[derive(Debug, Clone, PartialEq)]
pub enum NetEvent {
    /// The server welcomed us.
    Connected(Welcome),
    /// A fresh round-trip measurement.
    Rtt(Duration),
    /// Connecting failed; the thread has ended.
    Failed(String),
    /// An established session ended; the thread has ended.
    Disconnected(String),
}

/// A running network thread. Dropping it leaves the server and joins the
/// thread (bounded by the session's close linger).
#[derive(Debug)]
pub struct NetThread {
    events: mpsc::Receiver<NetEvent>,
    quit: Option<oneshot::Sender<()>>,
    thread: Option<thread::JoinHandle<()>>,
}

impl NetThread {
    /// Starts the thread and begins connecting.
    pub fn spawn(request: ConnectRequest) -> std::io::Result<NetThread> {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()?;
        let (events_tx, events) = mpsc::channel();
        let (quit, quit_rx) = oneshot::channel();
        let thread = thread::Builder::new()
            .name("ledge-net".into())
            .spawn(move || runtime.block_on(run(request, events_tx, quit_rx)))?;
        Ok(NetThread {
            events,
            quit: Some(quit),
            thread: Some(thread),
        })
    }

    /// The next pending event, if any; never blocks.
    pub fn try_recv(&self) -> Option<NetEvent> {
        self.events.try_recv().ok()
    }

    /// Waits up to `timeout` for the next event (for headless callers).
    pub fn recv_timeout(&self, timeout: Duration) -> Option<NetEvent> {
        self.events.recv_timeout(timeout).ok()
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

async fn run(
    request: ConnectRequest,
    events: mpsc::Sender<NetEvent>,
    mut quit: oneshot::Receiver<()>,
) {
    let connecting = async {
        let (addr, server_name) = resolve(&request.server).await?;
        connect(
            addr,
            &server_name,
            request.cert_fingerprint,
            &request.player_name,
        )
        .await
    };
    let mut session = tokio::select! {
        _ = &mut quit => return,
        result = connecting => match result {
            Ok(session) => session,
            Err(e) => {
                let _ = events.send(NetEvent::Failed(e.to_string()));
                return;
            }
        },
    };
    let _ = events.send(NetEvent::Connected(session.welcome().clone()));
    let mut ticker = tokio::time::interval(PING_INTERVAL);
    loop {
        tokio::select! {
            _ = &mut quit => break,
            _ = ticker.tick() => match session.ping().await {
                Ok(rtt) => {
                    if events.send(NetEvent::Rtt(rtt)).is_err() {
                        break;
                    }
                }
                Err(e) => {
                    let _ = events.send(NetEvent::Disconnected(e.to_string()));
                    return;
                }
            },
        }
    }
    session.close().await;
}

/// What a front end shows about the network.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum NetStatus {
    /// Playing locally, no server.
    #[default]
    Offline,
    /// Connecting to the named server.
    Connecting(String),
    /// Joined.
    Connected {
        /// The server's welcome.
        welcome: Welcome,
        /// The latest round-trip time, once measured.
        rtt: Option<Duration>,
    },
    /// Connecting failed, with the reason.
    Failed(String),
    /// The session ended, with the reason.
    Disconnected(String),
}

impl NetStatus {
    /// Folds one event into the status.
    pub fn apply(&mut self, event: NetEvent) {
        *self = match (std::mem::take(self), event) {
            (_, NetEvent::Connected(welcome)) => NetStatus::Connected { welcome, rtt: None },
            (NetStatus::Connected { welcome, .. }, NetEvent::Rtt(rtt)) => NetStatus::Connected {
                welcome,
                rtt: Some(rtt),
            },
            (status, NetEvent::Rtt(_)) => status,
            (_, NetEvent::Failed(reason)) => NetStatus::Failed(reason),
            (_, NetEvent::Disconnected(reason)) => NetStatus::Disconnected(reason),
        };
    }
}

impl fmt::Display for NetStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NetStatus::Offline => write!(f, "offline (local simulation)"),
            NetStatus::Connecting(server) => write!(f, "connecting to {server}..."),
            NetStatus::Connected { welcome, rtt } => {
                write!(
                    f,
                    "welcome, player {} (joined at tick {}, hash {:016x}, {} Hz)",
                    welcome.player_id, welcome.tick, welcome.state_hash, welcome.tick_rate
                )?;
                if let Some(rtt) = rtt {
                    write!(f, ", rtt {:.1} ms", rtt.as_secs_f64() * 1000.0)?;
                }
                Ok(())
            }
            NetStatus::Failed(reason) => write!(f, "connection failed: {reason}"),
            NetStatus::Disconnected(reason) => write!(f, "disconnected: {reason}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_server::protocol::PlayerId;

    fn welcome() -> Welcome {
        Welcome {
            player_id: PlayerId(3),
            tick: 10,
            state_hash: 0xabc,
            tick_rate: 60,
        }
    }

    #[test]
    fn status_follows_events() {
        let mut status = NetStatus::Connecting("x:1".into());
        status.apply(NetEvent::Rtt(Duration::from_millis(5)));
        assert_eq!(status, NetStatus::Connecting("x:1".into()));
        status.apply(NetEvent::Connected(welcome()));
        status.apply(NetEvent::Rtt(Duration::from_millis(5)));
        assert_eq!(
            status,
            NetStatus::Connected {
                welcome: welcome(),
                rtt: Some(Duration::from_millis(5))
            }
        );
        let text = status.to_string();
        assert!(
            text.contains("player #3") && text.contains("rtt 5.0 ms"),
            "{text}"
        );
        status.apply(NetEvent::Disconnected("gone".into()));
        assert_eq!(status, NetStatus::Disconnected("gone".into()));
    }

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
