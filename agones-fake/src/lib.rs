//! A fake Agones SDK sidecar for tests: the SDK's own gRPC services
//! (`agones.dev.sdk.SDK` and `agones.dev.sdk.beta.SDK`, built from the
//! definitions the SDK is built from, `vendor/agones/proto`) served with tonic on
//! `127.0.0.1:PORT`, keeping a GameServer as the real sidecar does (state,
//! labels and annotations prefixed `agones.dev/sdk-`, counters and lists
//! declared up front with their capacities) and recording every call with
//! the time it arrived.
//!
//! What the real sidecar does and this one does too: `Ready` makes the
//! GameServer `Ready`, `Shutdown` makes it `Shutdown`, `Allocate` (or
//! [`FakeSidecar::allocate`], as a `GameServerAllocation` would) makes it
//! `Allocated`; watchers get the GameServer at once and after each change;
//! a counter or list not declared is `NOT_FOUND`; a count outside
//! `0..=capacity` and an append to a full list are `OUT_OF_RANGE`; a value
//! already in a list is `ALREADY_EXISTS`, a missing one `NOT_FOUND`.
//! [`FakeSidecar::set_failing`] makes every call fail with `UNAVAILABLE`
//! (a sidecar in trouble).

// tonic's service traits answer with `Result<_, tonic::Status>`; the
// helpers here produce those statuses, so boxing them would only be undone
// at the boundary.
#![allow(clippy::result_large_err)]

use std::net::SocketAddr;
use std::pin::Pin;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Instant;

use tokio::sync::{oneshot, watch};
use tokio_stream::{Stream, StreamExt};
use tonic::{Request, Response, Status, Streaming};

/// The generated messages and services of `agones.dev.sdk`.
#[allow(missing_docs, clippy::all, clippy::pedantic)]
pub mod sdk {
    tonic::include_proto!("agones.dev.sdk");
}

/// The generated messages and services of `agones.dev.sdk.beta`.
#[allow(missing_docs, clippy::all, clippy::pedantic)]
pub mod beta {
    tonic::include_proto!("agones.dev.sdk.beta");
}

use sdk::game_server::status::{CounterStatus, ListStatus};
use sdk::game_server::{ObjectMeta, Status as GsStatus};
use sdk::GameServer;

/// The prefix the sidecar puts before label and annotation keys.
pub const SDK_PREFIX: &str = "agones.dev/sdk-";

/// One call the sidecar received.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Call {
    /// `Ready`.
    Ready,
    /// `Allocate`.
    Allocate,
    /// `Shutdown`.
    Shutdown,
    /// One message of the health stream.
    Health,
    /// `GetGameServer`.
    GetGameServer,
    /// `WatchGameServer` (opened).
    Watch,
    /// `SetLabel` (the key as sent, without the prefix).
    Label(String, String),
    /// `SetAnnotation` (the key as sent).
    Annotation(String, String),
    /// `Reserve` (seconds).
    Reserve(i64),
    /// `GetCounter`.
    GetCounter(String),
    /// `UpdateCounter`: name, count and capacity when set, count diff.
    UpdateCounter {
        /// The counter.
        name: String,
        /// The count set, if any.
        count: Option<i64>,
        /// The capacity set, if any.
        capacity: Option<i64>,
        /// The change of the count.
        diff: i64,
    },
    /// `GetList`.
    GetList(String),
    /// `UpdateList` (name, capacity).
    UpdateList(String, i64),
    /// `AddListValue` (list, value).
    AddListValue(String, String),
    /// `RemoveListValue` (list, value).
    RemoveListValue(String, String),
}

/// A call and when it arrived.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Event {
    /// When it arrived.
    pub at: Instant,
    /// What it was.
    pub call: Call,
}

#[derive(Debug, Default)]
struct Inner {
    events: Vec<Event>,
    failing: bool,
}

#[derive(Debug, Clone)]
struct State {
    inner: Arc<Mutex<Inner>>,
    gs: Arc<watch::Sender<GameServer>>,
}

fn lock(m: &Mutex<Inner>) -> MutexGuard<'_, Inner> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl State {
    /// Records `call`; `Err(UNAVAILABLE)` while failing.
    fn record(&self, call: Call) -> Result<(), Status> {
        let mut inner = lock(&self.inner);
        inner.events.push(Event {
            at: Instant::now(),
            call,
        });
        if inner.failing {
            return Err(Status::unavailable("the fake sidecar is failing"));
        }
        Ok(())
    }

    /// Changes the GameServer with `f` (watchers see the result) and
    /// returns what `f` returned.
    fn change<T>(&self, f: impl FnOnce(&mut GsStatus, &mut ObjectMeta) -> T) -> T {
        let mut out = None;
        self.gs.send_modify(|gs| {
            let status = gs.status.get_or_insert_with(Default::default);
            let meta = gs.object_meta.get_or_insert_with(Default::default);
            out = Some(f(status, meta));
        });
        out.expect("send_modify runs the closure")
    }

    fn set_state(&self, state: &str) {
        self.change(|s, _| s.state = state.to_owned());
    }
}

type Reply<T> = Result<Response<T>, Status>;

#[tonic::async_trait]
impl sdk::sdk_server::Sdk for State {
    async fn ready(&self, _: Request<sdk::Empty>) -> Reply<sdk::Empty> {
        self.record(Call::Ready)?;
        self.set_state("Ready");
        Ok(Response::new(sdk::Empty {}))
    }

    async fn allocate(&self, _: Request<sdk::Empty>) -> Reply<sdk::Empty> {
        self.record(Call::Allocate)?;
        self.set_state("Allocated");
        Ok(Response::new(sdk::Empty {}))
    }

    async fn shutdown(&self, _: Request<sdk::Empty>) -> Reply<sdk::Empty> {
        self.record(Call::Shutdown)?;
        self.set_state("Shutdown");
        Ok(Response::new(sdk::Empty {}))
    }

    async fn health(&self, request: Request<Streaming<sdk::Empty>>) -> Reply<sdk::Empty> {
        let mut stream = request.into_inner();
        while let Some(ping) = stream.next().await {
            ping?;
            self.record(Call::Health)?;
        }
        Ok(Response::new(sdk::Empty {}))
    }

    async fn get_game_server(&self, _: Request<sdk::Empty>) -> Reply<GameServer> {
        self.record(Call::GetGameServer)?;
        Ok(Response::new(self.gs.borrow().clone()))
    }

    type WatchGameServerStream = Pin<Box<dyn Stream<Item = Result<GameServer, Status>> + Send>>;

    async fn watch_game_server(
        &self,
        _: Request<sdk::Empty>,
    ) -> Reply<Self::WatchGameServerStream> {
        self.record(Call::Watch)?;
        let updates = tokio_stream::wrappers::WatchStream::new(self.gs.subscribe()).map(Ok);
        Ok(Response::new(Box::pin(updates)))
    }

    async fn set_label(&self, request: Request<sdk::KeyValue>) -> Reply<sdk::Empty> {
        let kv = request.into_inner();
        self.record(Call::Label(kv.key.clone(), kv.value.clone()))?;
        self.change(|_, meta| {
            meta.labels
                .insert(format!("{SDK_PREFIX}{}", kv.key), kv.value)
        });
        Ok(Response::new(sdk::Empty {}))
    }

    async fn set_annotation(&self, request: Request<sdk::KeyValue>) -> Reply<sdk::Empty> {
        let kv = request.into_inner();
        self.record(Call::Annotation(kv.key.clone(), kv.value.clone()))?;
        self.change(|_, meta| {
            meta.annotations
                .insert(format!("{SDK_PREFIX}{}", kv.key), kv.value)
        });
        Ok(Response::new(sdk::Empty {}))
    }

    async fn reserve(&self, request: Request<sdk::Duration>) -> Reply<sdk::Empty> {
        self.record(Call::Reserve(request.into_inner().seconds))?;
        self.set_state("Reserved");
        Ok(Response::new(sdk::Empty {}))
    }
}

fn no_counter(name: &str) -> Status {
    Status::not_found(format!("counter not found: {name}"))
}

fn no_list(name: &str) -> Status {
    Status::not_found(format!("list not found: {name}"))
}

fn list_reply(name: &str, l: &ListStatus) -> beta::List {
    beta::List {
        name: name.to_owned(),
        capacity: l.capacity,
        values: l.values.clone(),
    }
}

#[tonic::async_trait]
impl beta::sdk_server::Sdk for State {
    async fn get_counter(&self, request: Request<beta::GetCounterRequest>) -> Reply<beta::Counter> {
        let name = request.into_inner().name;
        self.record(Call::GetCounter(name.clone()))?;
        let gs = self.gs.borrow();
        let c = gs
            .status
            .as_ref()
            .and_then(|s| s.counters.get(&name))
            .ok_or_else(|| no_counter(&name))?;
        Ok(Response::new(beta::Counter {
            name,
            count: c.count,
            capacity: c.capacity,
        }))
    }

    async fn update_counter(
        &self,
        request: Request<beta::UpdateCounterRequest>,
    ) -> Reply<beta::Counter> {
        let update = request
            .into_inner()
            .counter_update_request
            .ok_or_else(|| Status::invalid_argument("no counterUpdateRequest"))?;
        let name = update.name.clone();
        self.record(Call::UpdateCounter {
            name: name.clone(),
            count: update.count,
            capacity: update.capacity,
            diff: update.count_diff,
        })?;
        let counter = self.change(|s, _| {
            let c = s.counters.get_mut(&name).ok_or_else(|| no_counter(&name))?;
            let capacity = update.capacity.unwrap_or(c.capacity);
            let count = update.count.unwrap_or(c.count) + update.count_diff;
            if capacity < 0 || !(0..=capacity).contains(&count) {
                return Err(Status::out_of_range(format!(
                    "counter {name}: count {count} is outside 0..={capacity}"
                )));
            }
            *c = CounterStatus { count, capacity };
            Ok(beta::Counter {
                name: name.clone(),
                count,
                capacity,
            })
        })?;
        Ok(Response::new(counter))
    }

    async fn get_list(&self, request: Request<beta::GetListRequest>) -> Reply<beta::List> {
        let name = request.into_inner().name;
        self.record(Call::GetList(name.clone()))?;
        let gs = self.gs.borrow();
        let l = gs
            .status
            .as_ref()
            .and_then(|s| s.lists.get(&name))
            .ok_or_else(|| no_list(&name))?;
        Ok(Response::new(list_reply(&name, l)))
    }

    async fn update_list(&self, request: Request<beta::UpdateListRequest>) -> Reply<beta::List> {
        let list = request
            .into_inner()
            .list
            .ok_or_else(|| Status::invalid_argument("no list"))?;
        self.record(Call::UpdateList(list.name.clone(), list.capacity))?;
        let reply = self.change(|s, _| {
            let l = s
                .lists
                .get_mut(&list.name)
                .ok_or_else(|| no_list(&list.name))?;
            if !(0..=1000).contains(&list.capacity) {
                return Err(Status::out_of_range("list capacity must be 0..=1000"));
            }
            l.capacity = list.capacity;
            l.values.truncate(list.capacity as usize);
            Ok(list_reply(&list.name, l))
        })?;
        Ok(Response::new(reply))
    }

    async fn add_list_value(
        &self,
        request: Request<beta::AddListValueRequest>,
    ) -> Reply<beta::List> {
        let r = request.into_inner();
        self.record(Call::AddListValue(r.name.clone(), r.value.clone()))?;
        let reply = self.change(|s, _| {
            let l = s.lists.get_mut(&r.name).ok_or_else(|| no_list(&r.name))?;
            if l.values.contains(&r.value) {
                return Err(Status::already_exists(format!(
                    "{} is already in list {}",
                    r.value, r.name
                )));
            }
            if l.values.len() as i64 >= l.capacity {
                return Err(Status::out_of_range(format!("list {} is full", r.name)));
            }
            l.values.push(r.value.clone());
            Ok(list_reply(&r.name, l))
        })?;
        Ok(Response::new(reply))
    }

    async fn remove_list_value(
        &self,
        request: Request<beta::RemoveListValueRequest>,
    ) -> Reply<beta::List> {
        let r = request.into_inner();
        self.record(Call::RemoveListValue(r.name.clone(), r.value.clone()))?;
        let reply = self.change(|s, _| {
            let l = s.lists.get_mut(&r.name).ok_or_else(|| no_list(&r.name))?;
            let Some(i) = l.values.iter().position(|v| *v == r.value) else {
                return Err(Status::not_found(format!(
                    "{} is not in list {}",
                    r.value, r.name
                )));
            };
            l.values.remove(i);
            Ok(list_reply(&r.name, l))
        })?;
        Ok(Response::new(reply))
    }
}

/// A running fake sidecar (stops when dropped).
#[derive(Debug)]
pub struct FakeSidecar {
    addr: SocketAddr,
    state: State,
    stop: Option<oneshot::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl FakeSidecar {
    /// Serves on `127.0.0.1` (any free port), on a thread and runtime of
    /// its own (so a test may block its own runtime without delaying the
    /// sidecar's clock), a GameServer named `name` in state `Scheduled`
    /// with the `counters` and `lists` declared (name, capacity), as a
    /// GameServer spec would.
    pub fn start(
        name: &str,
        counters: &[(&str, i64)],
        lists: &[(&str, i64)],
    ) -> std::io::Result<FakeSidecar> {
        let gs = GameServer {
            object_meta: Some(ObjectMeta {
                name: name.to_owned(),
                namespace: "default".into(),
                ..Default::default()
            }),
            spec: None,
            status: Some(GsStatus {
                state: "Scheduled".into(),
                address: "127.0.0.1".into(),
                counters: counters
                    .iter()
                    .map(|&(n, capacity)| (n.to_owned(), CounterStatus { count: 0, capacity }))
                    .collect(),
                lists: lists
                    .iter()
                    .map(|&(n, capacity)| {
                        let values = Vec::new();
                        (n.to_owned(), ListStatus { capacity, values })
                    })
                    .collect(),
                ..Default::default()
            }),
        };
        let state = State {
            inner: Arc::default(),
            gs: Arc::new(watch::Sender::new(gs)),
        };
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()?;
        let listener = std::net::TcpListener::bind("127.0.0.1:0")?;
        listener.set_nonblocking(true)?;
        let addr = listener.local_addr()?;
        let (stop, stopped) = oneshot::channel::<()>();
        let services = state.clone();
        let thread = std::thread::Builder::new()
            .name("fake-agones-sidecar".into())
            .spawn(move || {
                let _entered = runtime.enter();
                let Ok(listener) = tokio::net::TcpListener::from_std(listener) else {
                    return;
                };
                let server = tonic::transport::Server::builder()
                    .add_service(sdk::sdk_server::SdkServer::new(services.clone()))
                    .add_service(beta::sdk_server::SdkServer::new(services))
                    .serve_with_incoming(tokio_stream::wrappers::TcpListenerStream::new(listener));
                // Stopping drops the server, then the runtime ends its
                // connections (an open health stream included).
                runtime.block_on(async {
                    tokio::select! {
                        _ = server => {}
                        _ = stopped => {}
                    }
                });
            })?;
        Ok(FakeSidecar {
            addr,
            state,
            stop: Some(stop),
            thread: Some(thread),
        })
    }

    /// The port the SDK connects to (`AGONES_SDK_GRPC_PORT`).
    pub fn port(&self) -> u16 {
        self.addr.port()
    }

    /// Every call so far, in order.
    pub fn events(&self) -> Vec<Event> {
        lock(&self.state.inner).events.clone()
    }

    /// The calls so far, without their times.
    pub fn calls(&self) -> Vec<Call> {
        self.events().into_iter().map(|e| e.call).collect()
    }

    /// When each health ping arrived.
    pub fn health_pings(&self) -> Vec<Instant> {
        self.events()
            .into_iter()
            .filter(|e| e.call == Call::Health)
            .map(|e| e.at)
            .collect()
    }

    /// The GameServer now.
    pub fn game_server(&self) -> GameServer {
        self.state.gs.borrow().clone()
    }

    /// The GameServer's state (`Scheduled`, `Ready`, `Allocated`,
    /// `Shutdown`...).
    pub fn state(&self) -> String {
        self.game_server()
            .status
            .map(|s| s.state)
            .unwrap_or_default()
    }

    /// A counter's `(count, capacity)`.
    pub fn counter(&self, name: &str) -> Option<(i64, i64)> {
        let gs = self.game_server();
        let c = gs.status?.counters.get(name).cloned()?;
        Some((c.count, c.capacity))
    }

    /// A list's values, in the order added.
    pub fn list(&self, name: &str) -> Option<Vec<String>> {
        let gs = self.game_server();
        Some(gs.status?.lists.get(name)?.values.clone())
    }

    /// A label, by the key the SDK sent (the stored key has
    /// [`SDK_PREFIX`]).
    pub fn label(&self, key: &str) -> Option<String> {
        let meta = self.game_server().object_meta?;
        meta.labels.get(&format!("{SDK_PREFIX}{key}")).cloned()
    }

    /// An annotation, by the key the SDK sent.
    pub fn annotation(&self, key: &str) -> Option<String> {
        let meta = self.game_server().object_meta?;
        meta.annotations.get(&format!("{SDK_PREFIX}{key}")).cloned()
    }

    /// Allocates the GameServer, as a `GameServerAllocation` would.
    pub fn allocate(&self) {
        self.state.set_state("Allocated");
    }

    /// Makes every call fail with `UNAVAILABLE` (still recorded), or work
    /// again.
    pub fn set_failing(&self, failing: bool) {
        lock(&self.state.inner).failing = failing;
    }
}

impl Drop for FakeSidecar {
    fn drop(&mut self) {
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// What a `GameServerAllocation` asks for (deploy/agones/allocation-*.yaml).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Want<'a> {
    /// A server with a free room: an Allocated one with `rooms` count
    /// below capacity first, the fullest of them (Packed scheduling,
    /// priority on the `rooms` counter, ascending available), else a Ready
    /// one likewise.
    AnyRoom,
    /// The server whose `rooms` list holds this room name (an Allocated
    /// one first).
    Room(&'a str),
}

/// Allocates a GameServer of `fleet` as Agones' allocator would for
/// `want`, with ledge's allocation manifests: marks it `Allocated` and
/// returns its index, or `None` when no server qualifies (the fleet is
/// full: its autoscaler would add one). Ties go to the earlier server.
pub fn allocate(fleet: &[&FakeSidecar], want: Want<'_>) -> Option<usize> {
    const ROOMS: &str = "rooms";
    let pick = |state: &str| -> Option<usize> {
        let candidates = fleet.iter().enumerate().filter(|(_, s)| s.state() == state);
        match want {
            Want::AnyRoom => candidates
                .filter_map(|(i, s)| {
                    let (count, capacity) = s.counter(ROOMS)?;
                    (count < capacity).then_some((capacity - count, i))
                })
                .min()
                .map(|(_, i)| i),
            Want::Room(name) => candidates
                .filter(|(_, s)| s.list(ROOMS).is_some_and(|l| l.iter().any(|v| v == name)))
                .map(|(i, _)| i)
                .next(),
        }
    };
    let chosen = pick("Allocated").or_else(|| pick("Ready"))?;
    fleet[chosen].allocate();
    Some(chosen)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fleet(n: usize) -> Vec<FakeSidecar> {
        (0..n)
            .map(|i| {
                FakeSidecar::start(&format!("gs-{i}"), &[("rooms", 2)], &[("rooms", 2)])
                    .expect("starts")
            })
            .collect()
    }

    #[test]
    fn allocation_packs_rooms_onto_allocated_servers_then_takes_a_ready_one() {
        let servers = fleet(3);
        let all: Vec<&FakeSidecar> = servers.iter().collect();
        // Nobody Ready yet: nothing to allocate.
        assert_eq!(allocate(&all, Want::AnyRoom), None);
        for s in &servers[1..] {
            s.state.set_state("Ready");
        }
        // The first Ready one (gs-1), then it again while it has room.
        assert_eq!(allocate(&all, Want::AnyRoom), Some(1));
        assert_eq!(servers[1].state(), "Allocated");
        let set_rooms = |s: &FakeSidecar, count: i64| {
            s.state.change(|st, _| {
                st.counters.get_mut("rooms").unwrap().count = count;
            })
        };
        set_rooms(&servers[1], 1);
        assert_eq!(allocate(&all, Want::AnyRoom), Some(1));
        set_rooms(&servers[1], 2);
        // Full: the next Ready one.
        assert_eq!(allocate(&all, Want::AnyRoom), Some(2));
        set_rooms(&servers[2], 2);
        assert_eq!(allocate(&all, Want::AnyRoom), None);
        // By room name.
        servers[2].state.change(|st, _| {
            st.lists.get_mut("rooms").unwrap().values = vec!["friends".into()];
        });
        assert_eq!(allocate(&all, Want::Room("friends")), Some(2));
        assert_eq!(allocate(&all, Want::Room("nobody")), None);
    }
}
