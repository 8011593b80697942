//! A misbehaving client, to check that the server drops or ignores it
//! without hurting anyone else.
//!
//! Each [`Misbehavior`] is one kind of abuse; [`misbehave`] connects,
//! commits it for a while and reports how the server reacted
//! ([`Outcome`]): a refusal, a close (with the server's close code), or
//! nothing (the abuse was ignored and the session is still up).

use std::fmt;
use std::net::SocketAddr;
use std::str::FromStr;
use std::time::{Duration, Instant};

use ledge_shared::input::Buttons;
use ledge_shared::protocol::{
    ClientControl, CloseCode, Fingerprint, InputPacket, Message, PROTOCOL_VERSION,
};

use super::brain::SplitMix64;
use crate::error::ClientError;
use crate::net::session::{handshake, Session, SessionEvent};
use crate::net::transport::dial;

/// One kind of abuse.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Misbehavior {
    /// Random bytes on the control stream (breaks the framing).
    ControlGarbage,
    /// A control frame whose length prefix is far over the limit.
    OversizedFrame,
    /// Valid input datagrams, hundreds per second.
    DatagramFlood,
    /// Random bytes as datagrams (malformed inputs).
    GarbageDatagrams,
    /// Inputs for ticks long past.
    StaleInputs,
    /// Inputs for ticks far in the future.
    FutureInputs,
    /// A hello with another protocol version.
    WrongVersion,
}

impl Misbehavior {
    /// Every mode.
    pub const ALL: [Misbehavior; 7] = [
        Misbehavior::ControlGarbage,
        Misbehavior::OversizedFrame,
        Misbehavior::DatagramFlood,
        Misbehavior::GarbageDatagrams,
        Misbehavior::StaleInputs,
        Misbehavior::FutureInputs,
        Misbehavior::WrongVersion,
    ];

    /// Its command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Misbehavior::ControlGarbage => "garbage",
            Misbehavior::OversizedFrame => "oversized",
            Misbehavior::DatagramFlood => "flood",
            Misbehavior::GarbageDatagrams => "garbage-datagrams",
            Misbehavior::StaleInputs => "stale",
            Misbehavior::FutureInputs => "future",
            Misbehavior::WrongVersion => "version",
        }
    }
}

impl fmt::Display for Misbehavior {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Misbehavior {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Misbehavior::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Misbehavior::ALL.iter().map(|m| m.name()).collect();
                format!("unknown misbehavior {s:?} (known: {})", names.join(", "))
            })
    }
}

/// How the server reacted.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome {
    /// It refused the hello.
    Rejected(String),
    /// It closed the connection (with this close code, if known).
    Closed {
        /// The close code.
        code: Option<CloseCode>,
        /// The close reason or error.
        reason: String,
    },
    /// The session is still up: the abuse was ignored.
    Ignored {
        /// Snapshots received meanwhile.
        snapshots: u64,
    },
    /// Connecting failed for another reason.
    Failed(String),
}

/// What a misbehaving client did and how it ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MisbehaveReport {
    /// The abuse.
    pub mode: Misbehavior,
    /// Messages (frames, datagrams) sent.
    pub sent: u64,
    /// The server's reaction.
    pub outcome: Outcome,
    /// How long until the server reacted (or the run ended).
    pub after: Duration,
}

impl fmt::Display for MisbehaveReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let outcome = match &self.outcome {
            Outcome::Rejected(r) => format!("rejected: {r}"),
            Outcome::Closed { code, reason } => format!("closed ({code:?}): {reason}"),
            Outcome::Ignored { snapshots } => {
                format!("ignored (still connected, {snapshots} snapshots)")
            }
            Outcome::Failed(e) => format!("failed: {e}"),
        };
        write!(
            f,
            "{:<17} sent {:>6} in {:>6.2} s: {outcome}",
            self.mode.name(),
            self.sent,
            self.after.as_secs_f64()
        )
    }
}

/// Connects to `addr` (pinned `fingerprint`) as `name` and misbehaves as
/// `mode` for at most `duration`, returning when the server closes or the
/// time is up.
pub async fn misbehave(
    addr: SocketAddr,
    fingerprint: Fingerprint,
    name: &str,
    mode: Misbehavior,
    duration: Duration,
    seed: u64,
) -> MisbehaveReport {
    let started = Instant::now();
    let mut report = MisbehaveReport {
        mode,
        sent: 0,
        outcome: Outcome::Failed(String::new()),
        after: Duration::ZERO,
    };
    let dialed = match dial(addr, "localhost", fingerprint).await {
        Ok(d) => d,
        Err(e) => {
            report.outcome = Outcome::Failed(e.to_string());
            return report;
        }
    };
    let hello = ClientControl::Hello {
        version: if mode == Misbehavior::WrongVersion {
            PROTOCOL_VERSION + 1000
        } else {
            PROTOCOL_VERSION
        },
        name: name.to_owned(),
    };
    let session = match handshake(dialed, hello).await {
        Ok(s) => s,
        Err(ClientError::Rejected(reason)) => {
            report.sent = 1;
            report.outcome = Outcome::Rejected(reason.to_string());
            report.after = started.elapsed();
            return report;
        }
        Err(e) => {
            report.outcome = outcome_of(e);
            report.after = started.elapsed();
            return report;
        }
    };
    let (sent, outcome) = abuse(session, mode, started + duration, seed).await;
    report.sent = sent;
    report.outcome = outcome;
    report.after = started.elapsed();
    report
}

fn outcome_of(e: ClientError) -> Outcome {
    match e {
        ClientError::ClosedByServer { code, reason } => Outcome::Closed { code, reason },
        ClientError::Rejected(r) => Outcome::Rejected(r.to_string()),
        other => Outcome::Closed {
            code: None,
            reason: other.to_string(),
        },
    }
}

/// Commits the abuse on a joined session until `until` or the server ends
/// it; returns (messages sent, outcome).
async fn abuse(
    mut session: Session,
    mode: Misbehavior,
    until: Instant,
    seed: u64,
) -> (u64, Outcome) {
    let mut rng = SplitMix64(seed);
    let mut sent = 0u64;
    let mut snapshots = 0u64;
    let rate = f64::from(session.welcome().timing.tick_rate.max(1));
    let start_tick = session.welcome().server_tick;
    let t0 = Instant::now();
    // Flooders send every millisecond; the others once per tick.
    let period = match mode {
        Misbehavior::DatagramFlood | Misbehavior::GarbageDatagrams => Duration::from_millis(1),
        _ => Duration::from_secs_f64(1.0 / rate),
    };
    let mut ticker = tokio::time::interval(period);
    loop {
        if Instant::now() >= until {
            session.close().await;
            return (sent, Outcome::Ignored { snapshots });
        }
        let server_tick = start_tick + (t0.elapsed().as_secs_f64() * rate) as u64;
        let result: Result<(), ClientError> = tokio::select! {
            event = session.recv() => match event {
                Ok(SessionEvent::Snapshot(_)) => { snapshots += 1; Ok(()) }
                Ok(_) => Ok(()),
                Err(e) => return (sent, outcome_of(e)),
            },
            _ = ticker.tick() => {
                sent += 1;
                match mode {
                    Misbehavior::ControlGarbage => {
                        let bytes: Vec<u8> = (0..64).map(|_| rng.next_u64() as u8).collect();
                        session.send_raw_control(&bytes).await
                    }
                    Misbehavior::OversizedFrame => {
                        let mut frame = (16u32 << 20).to_le_bytes().to_vec();
                        frame.extend(std::iter::repeat_n(0u8, 512));
                        session.send_raw_control(&frame).await
                    }
                    Misbehavior::DatagramFlood => {
                        let tick = server_tick + 2;
                        send_raw(&session, InputPacket::new(tick, &[Buttons(Buttons::RIGHT)], None))
                    }
                    Misbehavior::GarbageDatagrams => {
                        let n = 1 + rng.below(100) as usize;
                        let bytes: Vec<u8> = (0..n).map(|_| rng.next_u64() as u8).collect();
                        session
                            .connection()
                            .send_datagram(bytes.into())
                            .map_err(ClientError::from)
                    }
                    Misbehavior::StaleInputs => {
                        let tick = server_tick.saturating_sub(600);
                        let b = [Buttons(Buttons::RIGHT | Buttons::JUMP); 16];
                        send_raw(&session, InputPacket::new(tick, &b, None))
                    }
                    Misbehavior::FutureInputs => {
                        let tick = server_tick + 100_000;
                        let b = [Buttons(Buttons::RIGHT | Buttons::JUMP); 16];
                        send_raw(&session, InputPacket::new(tick, &b, None))
                    }
                    Misbehavior::WrongVersion => Ok(()),
                }
            }
        };
        if let Err(e) = result {
            // Writing failed: the server has (most likely) closed; read why.
            let why = match session.connection().close_reason() {
                Some(reason) => outcome_of(ClientError::from_connection_error(reason)),
                None => outcome_of(e),
            };
            return (sent, why);
        }
    }
}

/// Sends an input packet as is (any ticks), without the session's history.
fn send_raw(session: &Session, packet: InputPacket) -> Result<(), ClientError> {
    let bytes = packet.encode()?;
    session.connection().send_datagram(bytes.into())?;
    Ok(())
}
