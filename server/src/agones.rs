//! The Agones SDK driver (cargo feature `agones`, flag `--agones`): makes
//! the [`Call`]s of the fleet logic ([`crate::fleet`]) through the Agones
//! SDK sidecar (gRPC on `localhost:$AGONES_SDK_GRPC_PORT`, default 9357),
//! and feeds it the rooms' load and the GameServer's state.
//!
//! * At start, [`connect`] waits for the sidecar (at most
//!   [`FleetConfig::connect_timeout`]); a sidecar that never answers stops
//!   the server with an error saying so.
//! * Every [`POLL`], the rooms' load goes to [`Fleet::poll`] and its calls
//!   are made in order. A call that fails, or gets no answer within
//!   [`CALL_TIMEOUT`], is logged (a warning at most every [`WARN_EVERY`])
//!   and made again at the next poll; play goes on.
//! * The GameServer is watched (re-watched after a lost stream) for its
//!   state: `Allocated` starts the empty-server clock.
//! * Health pings go through the SDK's health stream, reopened when the
//!   sidecar drops it.
//! * After a successful `Shutdown` the server drains as on SIGTERM (Agones
//!   would send one; without a cluster nothing else stops it).

use std::sync::Arc;
use std::time::{Duration, Instant};

use agones::Sdk;
use tokio::sync::{mpsc, watch};
use tracing::{debug, info, warn};

use crate::fleet::{Call, Fleet, FleetConfig, ROOMS};
use crate::shared::Shared;
use crate::shutdown::ShutdownHandle;

/// Time between two polls of the fleet logic.
pub const POLL: Duration = Duration::from_millis(250);

/// Shortest time between two warnings about failed SDK calls.
pub const WARN_EVERY: Duration = Duration::from_secs(10);

/// Longest an SDK call may take before it counts as failed (a sidecar that
/// accepts and never answers must not hold up the health pings for long).
pub const CALL_TIMEOUT: Duration = Duration::from_secs(2);

/// The sidecar's port: `config.sdk_port`, else `AGONES_SDK_GRPC_PORT`,
/// else 9357 (as the SDK reads it).
pub fn sidecar_port(config: &FleetConfig) -> u16 {
    if let Some(port) = config.sdk_port {
        return port;
    }
    std::env::var("AGONES_SDK_GRPC_PORT")
        .ok()
        .and_then(|p| p.parse().ok())
        .unwrap_or(9357)
}

/// Why the server could not join its fleet.
#[derive(Debug, thiserror::Error)]
pub enum AgonesError {
    /// The sidecar did not answer in time.
    #[error(
        "--agones: no Agones SDK sidecar answered on localhost:{port} within {secs} s ({reason}); \
         run the server in an Agones GameServer pod (docs/DEPLOY.md), set \
         AGONES_SDK_GRPC_PORT to the sidecar's port, or start without --agones"
    )]
    Connect {
        /// The port tried.
        port: u16,
        /// Seconds waited.
        secs: u64,
        /// What went wrong.
        reason: String,
    },
}

/// What an SDK error says, in words (the SDK's own `Display` hides the
/// gRPC status).
fn describe(e: &agones::errors::Error) -> String {
    match e {
        agones::errors::Error::Rpc(status) => {
            format!("{:?}: {}", status.code(), status.message())
        }
        agones::errors::Error::Transport(t) => format!("transport: {t}"),
        other => other.to_string(),
    }
}

/// Waits for the sidecar (at most `config.connect_timeout`).
pub async fn connect(config: &FleetConfig) -> Result<Sdk, AgonesError> {
    let port = sidecar_port(config);
    let error = |reason: String| AgonesError::Connect {
        port,
        secs: config.connect_timeout.as_secs().max(1),
        reason,
    };
    match tokio::time::timeout(config.connect_timeout, Sdk::new(Some(port), None)).await {
        Ok(Ok(sdk)) => {
            info!(port, "connected to the Agones SDK sidecar");
            Ok(sdk)
        }
        Ok(Err(e)) => Err(error(describe(&e))),
        Err(_) => Err(error("timed out".into())),
    }
}

/// Makes one call; `Ok` when done (or already so: a name already in the
/// list, or already gone from it), else what went wrong.
async fn make(sdk: &mut Sdk, call: &Call) -> Result<(), String> {
    let mut beta = sdk.beta().clone();
    // `fine`: the gRPC code that means "already done".
    let result = |r: agones::errors::Result<()>, fine: Option<tonic::Code>| match r {
        Ok(()) => Ok(()),
        Err(agones::errors::Error::Rpc(s)) if Some(s.code()) == fine => Ok(()),
        Err(e) => Err(describe(&e)),
    };
    match call {
        Call::Ready => result(sdk.ready().await, None),
        Call::Health => Ok(()),
        Call::Counter {
            name,
            count,
            capacity,
        } => {
            result(beta.set_counter_capacity(name, *capacity).await, None)?;
            result(beta.set_counter_count(name, *count).await, None)
        }
        Call::ListCapacity(capacity) => {
            result(beta.set_list_capacity(ROOMS, *capacity).await, None)
        }
        Call::ListAdd(name) => result(
            beta.append_list_value(ROOMS, name).await,
            Some(tonic::Code::AlreadyExists),
        ),
        Call::ListRemove(name) => result(
            beta.delete_list_value(ROOMS, name).await,
            Some(tonic::Code::NotFound),
        ),
        Call::Label { key, value } => result(sdk.set_label(*key, value.clone()).await, None),
        Call::Annotation { key, value } => {
            result(sdk.set_annotation(*key, value.clone()).await, None)
        }
        Call::Shutdown => result(sdk.shutdown().await, None),
    }
}

/// Watches the GameServer, sending each state seen (re-watching after a
/// lost stream) until `states` is closed.
async fn watch_states(mut sdk: Sdk, states: mpsc::UnboundedSender<String>) {
    let mut backoff = Duration::from_millis(250);
    while !states.is_closed() {
        match sdk.watch_gameserver().await {
            Ok(mut stream) => loop {
                match stream.message().await {
                    Ok(Some(gs)) => {
                        backoff = Duration::from_millis(250);
                        let state = gs.status.map(|s| s.state).unwrap_or_default();
                        if states.send(state).is_err() {
                            return;
                        }
                    }
                    Ok(None) => {
                        debug!("the GameServer watch ended; watching again");
                        break;
                    }
                    Err(e) => {
                        warn!("watching the GameServer failed ({e}); watching again");
                        break;
                    }
                }
            },
            Err(e) => debug!("cannot watch the GameServer yet: {}", describe(&e)),
        }
        tokio::time::sleep(backoff).await;
        backoff = (backoff * 2).min(Duration::from_secs(5));
    }
}

/// Starts the driver on a thread of its own (with its own small runtime),
/// once the sidecar answered: the health pings must not depend on the
/// runtime whose tick loops they vouch for (a room blocking a worker
/// thread must stop the pings, not the watchdog). Returns the thread, or
/// why the sidecar could not be reached.
pub async fn start(
    config: FleetConfig,
    fingerprint: String,
    shared: Arc<Shared>,
    stop: watch::Receiver<bool>,
    shutdown: ShutdownHandle,
) -> Result<std::thread::JoinHandle<()>, AgonesError> {
    let (connected_tx, connected) = tokio::sync::oneshot::channel();
    let thread = std::thread::Builder::new()
        .name("agones".into())
        .spawn(move || {
            let runtime = match tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
            {
                Ok(runtime) => runtime,
                Err(e) => {
                    let _ = connected_tx.send(Err(AgonesError::Connect {
                        port: sidecar_port(&config),
                        secs: 0,
                        reason: format!("cannot start its runtime: {e}"),
                    }));
                    return;
                }
            };
            runtime.block_on(async move {
                let sdk = match connect(&config).await {
                    Ok(sdk) => sdk,
                    Err(e) => {
                        let _ = connected_tx.send(Err(e));
                        return;
                    }
                };
                let _ = connected_tx.send(Ok(()));
                let fleet = Fleet::new(config, &fingerprint);
                drive(sdk, fleet, shared, stop, shutdown, config.health_every).await;
            });
        })
        .map_err(|e| AgonesError::Connect {
            port: sidecar_port(&config),
            secs: 0,
            reason: format!("cannot start its thread: {e}"),
        })?;
    match connected.await {
        Ok(Ok(())) => Ok(thread),
        Ok(Err(e)) => {
            let _ = thread.join();
            Err(e)
        }
        Err(_) => Err(AgonesError::Connect {
            port: sidecar_port(&config),
            secs: 0,
            reason: "its thread ended".into(),
        }),
    }
}

/// Runs the fleet logic against the sidecar until the server stops (or,
/// after a `Shutdown` call, stops it). `stop` turns true at shutdown.
async fn drive(
    mut sdk: Sdk,
    mut fleet: Fleet,
    shared: Arc<Shared>,
    mut stop: watch::Receiver<bool>,
    shutdown: ShutdownHandle,
    health_every: Duration,
) {
    let (states_tx, mut states) = mpsc::unbounded_channel();
    let watcher = tokio::spawn(watch_states(sdk.clone(), states_tx));
    let mut health = sdk.health_check();
    let mut poll = tokio::time::interval(POLL);
    poll.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let mut failures: u64 = 0;
    let mut last_warning: Option<Instant> = None;
    let mut warned_stuck = std::collections::BTreeSet::new();
    loop {
        tokio::select! {
            changed = stop.changed() => if changed.is_err() || *stop.borrow() { break },
            _ = poll.tick() => {}
        }
        while let Ok(state) = states.try_recv() {
            if state == "Allocated" && !fleet.allocated() {
                info!("the GameServer was allocated");
            }
            fleet.on_state(&state);
        }
        let now = Instant::now();
        let load = shared.rooms.load();
        let mut shut_down = false;
        for call in fleet.poll(&load, now) {
            if call == Call::Health {
                if let Err(mpsc::error::TrySendError::Closed(())) = health.try_send(()) {
                    debug!("the health stream closed; opening another");
                    health = sdk.health_check();
                    let _ = health.try_send(());
                }
                continue;
            }
            let made = tokio::time::timeout(CALL_TIMEOUT, make(&mut sdk, &call))
                .await
                .unwrap_or_else(|_| Err(format!("no answer within {CALL_TIMEOUT:?}")));
            match made {
                Ok(()) => {
                    debug!(?call, "Agones SDK call made");
                    if call == Call::Shutdown {
                        shut_down = true;
                    }
                    if call == Call::Ready {
                        info!("told Agones the server is ready");
                    }
                }
                Err(e) => {
                    fleet.failed(&call);
                    failures += 1;
                    let due = last_warning.is_none_or(|t| now.duration_since(t) >= WARN_EVERY);
                    if due {
                        last_warning = Some(now);
                        warn!(
                            failures,
                            "an Agones SDK call failed ({call:?}: {e}); retrying; play goes on"
                        );
                    }
                }
            }
        }
        // A room whose tick loop stalls withholds the health pings.
        let stuck = fleet.stuck(now);
        for (room, since) in &stuck {
            if *since >= health_every && warned_stuck.insert(room.clone()) {
                warn!(
                    %room,
                    "the room's tick loop has not advanced for {:.1} s: no health pings until it does",
                    since.as_secs_f64()
                );
            }
        }
        warned_stuck.retain(|r| stuck.iter().any(|(s, _)| s == r));
        if shut_down {
            info!("empty since the allocation for the configured time: shutting down (Agones Shutdown)");
            shutdown.shutdown();
            break;
        }
    }
    watcher.abort();
}
