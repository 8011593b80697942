//! Prometheus metrics (`prometheus-client`) and a minimal HTTP endpoint
//! serving them as text at `/metrics`.
//!
//! Label sets are bounded: at most `max_rooms` rooms are open at once and a
//! room's series are removed when it closes, reasons are enums, and the
//! per-client byte counters are labelled by player id and removed when the
//! player leaves, so at most `max_connections` client series exist.

use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use prometheus_client::encoding::{EncodeLabelSet, EncodeLabelValue};
use prometheus_client::metrics::counter::Counter;
use prometheus_client::metrics::family::Family;
use prometheus_client::metrics::gauge::Gauge;
use prometheus_client::metrics::histogram::{exponential_buckets, Histogram};
pub use prometheus_client::registry::Registry;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpListener;
use tokio::sync::{mpsc, watch};
use tracing::{debug, warn};

pub use crate::admission::Refusal;
pub use crate::link::{Transport, Wire};
pub use crate::web::guard::WebRefusal;

/// Label: a room.
#[derive(Debug, Clone, Hash, PartialEq, Eq, EncodeLabelSet)]
pub struct RoomLabel {
    /// The room's name.
    pub room: String,
}

/// Label: a connected player.
#[derive(Debug, Clone, Hash, PartialEq, Eq, EncodeLabelSet)]
pub struct ClientLabel {
    /// The player id, as a number.
    pub client: u32,
}

/// Which channel a message came in or went out on.
#[derive(Debug, Clone, Copy, Hash, PartialEq, Eq, EncodeLabelValue)]
pub enum Channel {
    /// Unreliable datagrams (inputs, snapshots).
    Datagram,
    /// The reliable control stream.
    Stream,
    /// A WebSocket message that is neither (text, empty, unknown tag,
    /// too large: [`ledge_shared::protocol::web::WebError`]).
    WebSocket,
}

/// Label: a channel.
#[derive(Debug, Clone, Hash, PartialEq, Eq, EncodeLabelSet)]
pub struct ChannelLabel {
    /// The channel.
    pub channel: Channel,
}

/// Why a message was dropped.
#[derive(Debug, Clone, Copy, Hash, PartialEq, Eq, EncodeLabelValue)]
pub enum DropReason {
    /// An input datagram over the client's rate limit.
    DatagramRateLimited,
    /// A control message over the client's rate limit.
    ControlRateLimited,
    /// An input for a tick already simulated (arrived too late).
    InputLate,
    /// An input for a tick too far in the future.
    InputTooEarly,
    /// A message for a client whose control queue was full.
    ControlQueueFull,
    /// A message for a client whose control stream writer is gone: it
    /// stopped reading the stream (or its session is ending).
    ClientNotReading,
    /// A snapshot not sent because a stream snapshot is still unacknowledged.
    SnapshotDeferred,
    /// A snapshot datagram quinn refused to send.
    SnapshotSendFailed,
}

/// Label: a drop reason.
#[derive(Debug, Clone, Hash, PartialEq, Eq, EncodeLabelSet)]
pub struct DropLabel {
    /// The reason.
    pub reason: DropReason,
}

/// Label: why a connection was refused ([`Refusal`]).
#[derive(Debug, Clone, Hash, PartialEq, Eq, EncodeLabelSet)]
pub struct RefusalLabel {
    /// The reason.
    pub reason: Refusal,
}

/// Label: why the web port turned a request or connection away.
#[derive(Debug, Clone, Hash, PartialEq, Eq, EncodeLabelSet)]
pub struct WebRefusalLabel {
    /// The reason.
    pub reason: WebRefusal,
}

/// What kind of network an address is on (a bounded label: addresses
/// themselves would grow the exposition without end).
#[derive(Debug, Clone, Copy, Hash, PartialEq, Eq, EncodeLabelValue)]
pub enum AddressClass {
    /// This machine.
    Loopback,
    /// A private or link-local network (the LAN).
    Private,
    /// Anything else (the internet).
    Public,
}

impl AddressClass {
    /// The class of `ip`.
    pub fn of(ip: std::net::IpAddr) -> AddressClass {
        use std::net::IpAddr;
        let ip = match ip {
            IpAddr::V6(v6) => v6.to_ipv4_mapped().map_or(IpAddr::V6(v6), IpAddr::V4),
            v4 => v4,
        };
        match ip {
            _ if ip.is_loopback() => AddressClass::Loopback,
            IpAddr::V4(v4) if v4.is_private() || v4.is_link_local() => AddressClass::Private,
            // Unique local (fc00::/7) and link-local (fe80::/10).
            IpAddr::V6(v6) if (v6.segments()[0] & 0xfe00) == 0xfc00 => AddressClass::Private,
            IpAddr::V6(v6) if (v6.segments()[0] & 0xffc0) == 0xfe80 => AddressClass::Private,
            _ => AddressClass::Public,
        }
    }
}

/// Label: an [`AddressClass`].
#[derive(Debug, Clone, Hash, PartialEq, Eq, EncodeLabelSet)]
pub struct AddressClassLabel {
    /// The class.
    pub class: AddressClass,
}

/// Label: a transport.
#[derive(Debug, Clone, Hash, PartialEq, Eq, EncodeLabelSet)]
pub struct TransportLabel {
    /// The transport.
    pub transport: Transport,
}

/// Label: a transport and why one of its connections was refused.
#[derive(Debug, Clone, Hash, PartialEq, Eq, EncodeLabelSet)]
pub struct TransportRefusalLabel {
    /// The transport.
    pub transport: Transport,
    /// The reason.
    pub reason: Refusal,
}

/// Full or delta snapshot.
#[derive(Debug, Clone, Copy, Hash, PartialEq, Eq, EncodeLabelValue)]
pub enum SnapshotKind {
    /// Encoded without a baseline.
    Full,
    /// Encoded against an acknowledged snapshot.
    Delta,
}

/// Label: snapshot kind and the channel it went on.
#[derive(Debug, Clone, Hash, PartialEq, Eq, EncodeLabelSet)]
pub struct SnapshotLabel {
    /// Full or delta.
    pub kind: SnapshotKind,
    /// Datagram or control stream.
    pub channel: Channel,
}

/// Why a client was disconnected by the server.
#[derive(Debug, Clone, Copy, Hash, PartialEq, Eq, EncodeLabelValue)]
pub enum KickReason {
    /// Too many malformed messages, or a broken control stream.
    Malformed,
    /// Kept exceeding its rate limits.
    Flooding,
    /// Joined, then sent no input for the idle time (a silent seat).
    Idle,
}

/// Label: a kick reason.
#[derive(Debug, Clone, Hash, PartialEq, Eq, EncodeLabelSet)]
pub struct KickLabel {
    /// The reason.
    pub reason: KickReason,
}

/// A client's byte counters (shared with the family: removing the label
/// from the family does not invalidate these handles).
#[derive(Debug, Clone, Default)]
pub struct ClientBytes {
    /// Bytes received from the client (datagrams and stream).
    pub bytes_in: Counter,
    /// Bytes sent to the client (datagrams and stream).
    pub bytes_out: Counter,
}

/// Every metric of the server.
#[derive(Debug)]
pub struct Metrics {
    /// Time to run one tick (inputs, step, snapshots), per room.
    pub tick_duration: Family<RoomLabel, Histogram, fn() -> Histogram>,
    /// Ticks skipped because the loop fell too far behind, per room.
    pub missed_ticks: Family<RoomLabel, Counter>,
    /// Players in each room.
    pub players: Family<RoomLabel, Gauge>,
    /// Open rooms.
    pub rooms: Gauge,
    /// Sessions resumed after a lost connection (same player back).
    pub sessions_resumed: Counter,
    /// Lost players removed after the reconnect grace time.
    pub sessions_expired: Counter,
    /// Level bundle downloads started (a resumed one counts again).
    pub level_downloads: Counter,
    /// Level bundle downloads sent to their end.
    pub level_downloads_completed: Counter,
    /// Level bundle bytes sent.
    pub level_download_bytes: Counter,
    /// Open connections (including handshakes).
    pub connections: Gauge,
    /// Connections refused, or closed before their hello, by reason
    /// ([`crate::admission`]).
    pub connections_refused: Family<RefusalLabel, Counter>,
    /// New connections sent a QUIC Retry (address validation under load).
    pub retries: Counter,
    /// Open connections by transport.
    pub transport_connections: Family<TransportLabel, Gauge>,
    /// Connections opened by transport (handshakes included).
    pub transport_connections_opened: Family<TransportLabel, Counter>,
    /// [`Metrics::connections_refused`] by transport too.
    pub transport_connections_refused: Family<TransportRefusalLabel, Counter>,
    /// Connections not yet past their hello.
    pub pending_connections: Gauge,
    /// Open HTTP connections on the web port.
    pub web_connections: Gauge,
    /// Addresses the web port keeps limits for ([`crate::web::guard`]).
    pub web_addresses: Gauge,
    /// Requests and connections the web port turned away, by reason.
    pub web_refused: Family<WebRefusalLabel, Counter>,
    /// Bytes of downloads (the level, the page's larger files) sent by the
    /// web port, by the class of the address they went to.
    pub web_download_bytes: Family<AddressClassLabel, Counter>,
    /// Finished runs stored in the records.
    pub records_stored: Counter,
    /// Finished runs not stored (records off or failing, queue full).
    pub records_failed: Counter,
    /// Time to store a batch of runs (first try to commit), in fine
    /// buckets.
    pub records_write_seconds: Histogram,
    /// The replays writer's counters.
    pub replays: crate::replays::writer::ReplayMetrics,
    /// Bytes received per client.
    pub client_bytes_in: Family<ClientLabel, Counter>,
    /// Bytes sent per client.
    pub client_bytes_out: Family<ClientLabel, Counter>,
    /// Bytes received, all clients, per channel.
    pub bytes_in: Family<ChannelLabel, Counter>,
    /// Bytes sent, all clients, per channel.
    pub bytes_out: Family<ChannelLabel, Counter>,
    /// UDP datagrams received from native QUIC players (every packet, ACKs
    /// included), sampled once a second by their rooms.
    pub wire_datagrams_in: Counter,
    /// Their UDP payload bytes (IP and UDP headers not included).
    pub wire_bytes_in: Counter,
    /// UDP datagrams sent to native QUIC players, sampled likewise.
    pub wire_datagrams_out: Counter,
    /// Their UDP payload bytes.
    pub wire_bytes_out: Counter,
    /// Snapshots not sent to a quiet client: it sent nothing since the
    /// last one and they would have changed nothing.
    pub snapshots_skipped: Counter,
    /// Encoded snapshot sizes in bytes.
    pub snapshot_bytes: Family<SnapshotLabel, Histogram, fn() -> Histogram>,
    /// Ticks a player's input was missing and the previous one repeated.
    pub input_starvation: Family<RoomLabel, Counter>,
    /// Messages dropped, by reason.
    pub dropped: Family<DropLabel, Counter>,
    /// Messages that failed to decode, per channel.
    pub malformed: Family<ChannelLabel, Counter>,
    /// Clients disconnected by the server, by reason.
    pub kicks: Family<KickLabel, Counter>,
    /// Time to run one tick, all rooms, in fine buckets ([`fine_buckets`]):
    /// p50/p99 of a window, from two scrapes, within one bucket (4.4 %).
    pub tick_duration_fine: Histogram,
    /// How late the tick loop woke up after a tick's deadline, all rooms,
    /// in fine buckets: scheduling delay, which the tick duration misses.
    pub tick_lateness: Histogram,
}

fn tick_histogram() -> Histogram {
    // 50 µs .. ~100 ms.
    Histogram::new(exponential_buckets(0.000_05, 2.0, 12))
}

/// Buckets per doubling of the fine timing histograms.
pub const FINE_BUCKETS_PER_OCTAVE: u16 = 16;
/// Upper bound of the first fine bucket, seconds.
pub const FINE_FIRST_BUCKET: f64 = 1e-6;
/// Number of fine buckets: 20 octaves, 1 µs .. ~1 s (then `+Inf`).
pub const FINE_BUCKETS: u16 = 20 * FINE_BUCKETS_PER_OCTAVE;

/// Upper bounds of the fine timing histograms: `1 µs * 2^(i/16)`. Each bucket
/// is 4.4 % wider than the previous one, so a quantile read from bucket
/// counts (such as the difference of two scrapes) is within 4.4 % of the
/// exact value, from 1 µs to 1 s, where the default buckets are a factor 2
/// apart. One series per server (not per room) keeps the exposition small.
pub fn fine_buckets() -> impl Iterator<Item = f64> {
    exponential_buckets(
        FINE_FIRST_BUCKET,
        2f64.powf(1.0 / f64::from(FINE_BUCKETS_PER_OCTAVE)),
        FINE_BUCKETS,
    )
}

fn size_histogram() -> Histogram {
    // 16 B .. 64 KiB.
    Histogram::new(exponential_buckets(16.0, 2.0, 13))
}

impl Metrics {
    /// New metrics, registered in a new registry (with the prefix `ledge`,
    /// in the order they are exposed).
    pub fn new() -> (Arc<Metrics>, Registry) {
        let m = Metrics::unregistered();
        let mut r = Registry::with_prefix("ledge");
        m.register_rooms(&mut r);
        m.register_connections(&mut r);
        m.register_traffic(&mut r);
        m.register_faults_and_timing(&mut r);
        (Arc::new(m), r)
    }

    /// Every metric at zero, in no registry yet.
    fn unregistered() -> Metrics {
        Metrics {
            tick_duration: Family::new_with_constructor(tick_histogram as fn() -> Histogram),
            missed_ticks: Family::default(),
            players: Family::default(),
            rooms: Gauge::default(),
            sessions_resumed: Counter::default(),
            sessions_expired: Counter::default(),
            level_downloads: Counter::default(),
            level_downloads_completed: Counter::default(),
            level_download_bytes: Counter::default(),
            connections: Gauge::default(),
            connections_refused: Family::default(),
            retries: Counter::default(),
            transport_connections: Family::default(),
            transport_connections_opened: Family::default(),
            transport_connections_refused: Family::default(),
            pending_connections: Gauge::default(),
            web_connections: Gauge::default(),
            web_addresses: Gauge::default(),
            web_refused: Family::default(),
            web_download_bytes: Family::default(),
            records_stored: Counter::default(),
            records_failed: Counter::default(),
            records_write_seconds: Histogram::new(fine_buckets()),
            replays: Default::default(),
            client_bytes_in: Family::default(),
            client_bytes_out: Family::default(),
            bytes_in: Family::default(),
            bytes_out: Family::default(),
            wire_datagrams_in: Counter::default(),
            wire_bytes_in: Counter::default(),
            wire_datagrams_out: Counter::default(),
            wire_bytes_out: Counter::default(),
            snapshots_skipped: Counter::default(),
            snapshot_bytes: Family::new_with_constructor(size_histogram as fn() -> Histogram),
            input_starvation: Family::default(),
            dropped: Family::default(),
            malformed: Family::default(),
            kicks: Family::default(),
            tick_duration_fine: Histogram::new(fine_buckets()),
            tick_lateness: Histogram::new(fine_buckets()),
        }
    }

    /// Registers the rooms' metrics: tick times, players, sessions, level
    /// downloads.
    fn register_rooms(&self, r: &mut Registry) {
        r.register(
            "tick_duration_seconds",
            "Time to run one tick (inputs, simulation step, snapshots)",
            self.tick_duration.clone(),
        );
        r.register(
            "missed_ticks",
            "Ticks skipped because the tick loop fell too far behind",
            self.missed_ticks.clone(),
        );
        r.register("players", "Players in the room", self.players.clone());
        r.register("rooms", "Open rooms", self.rooms.clone());
        r.register(
            "sessions_resumed",
            "Sessions resumed after a lost connection",
            self.sessions_resumed.clone(),
        );
        r.register(
            "sessions_expired",
            "Lost players removed after the reconnect grace time",
            self.sessions_expired.clone(),
        );
        r.register(
            "level_downloads",
            "Level bundle downloads started (resumed ones included)",
            self.level_downloads.clone(),
        );
        r.register(
            "level_downloads_completed",
            "Level bundle downloads sent to their end",
            self.level_downloads_completed.clone(),
        );
        r.register(
            "level_download_bytes",
            "Level bundle bytes sent",
            self.level_download_bytes.clone(),
        );
    }

    /// Registers the connections' metrics (open, refused, pending), and
    /// zeroes the per-transport gauges so every transport has a series.
    fn register_connections(&self, r: &mut Registry) {
        r.register(
            "connections",
            "Open QUIC connections",
            self.connections.clone(),
        );
        r.register(
            "connections_refused",
            "Connections refused, or closed before their hello, by reason",
            self.connections_refused.clone(),
        );
        r.register(
            "web_connections",
            "Open HTTP connections on the web port",
            self.web_connections.clone(),
        );
        r.register(
            "web_addresses",
            "Addresses the web port keeps per-address limits for",
            self.web_addresses.clone(),
        );
        r.register(
            "web_refused",
            "Requests and connections the web port turned away, by reason",
            self.web_refused.clone(),
        );
        r.register(
            "web_download_bytes",
            "Bytes of downloads sent by the web port, by address class",
            self.web_download_bytes.clone(),
        );
        r.register(
            "records_stored",
            "Finished runs stored in the records",
            self.records_stored.clone(),
        );
        r.register(
            "records_failed",
            "Finished runs not stored in the records",
            self.records_failed.clone(),
        );
        r.register(
            "records_write_seconds",
            "Time to store a batch of finished runs, first try to commit",
            self.records_write_seconds.clone(),
        );
        r.register(
            "replays_saved",
            "Replays saved (finished runs and matches)",
            self.replays.saved.clone(),
        );
        r.register(
            "replays_saved_bytes",
            "Bytes of the replays saved",
            self.replays.saved_bytes.clone(),
        );
        r.register(
            "replays_failed",
            "Replays not saved (queue full, disk failed)",
            self.replays.failed.clone(),
        );
        r.register(
            "replays_pruned",
            "Replays deleted past --replays-cap-mib",
            self.replays.pruned.clone(),
        );
        r.register(
            "retries",
            "New connections sent a QUIC Retry to validate their address",
            self.retries.clone(),
        );
        r.register(
            "transport_connections",
            "Open connections (in their handshake or joined) by transport",
            self.transport_connections.clone(),
        );
        r.register(
            "transport_connections_opened",
            "Connections admitted by transport",
            self.transport_connections_opened.clone(),
        );
        r.register(
            "transport_connections_refused",
            "Connections refused, or closed before their hello, by transport and reason",
            self.transport_connections_refused.clone(),
        );
        for transport in Transport::ALL {
            self.transport_connections
                .get_or_create(&TransportLabel { transport })
                .set(0);
        }
        r.register(
            "pending_connections",
            "Connections not yet past their hello",
            self.pending_connections.clone(),
        );
    }

    /// Registers the traffic metrics: bytes per client and channel, UDP
    /// datagrams, snapshots.
    fn register_traffic(&self, r: &mut Registry) {
        r.register(
            "client_bytes_in",
            "Bytes received from a connected player",
            self.client_bytes_in.clone(),
        );
        r.register(
            "client_bytes_out",
            "Bytes sent to a connected player",
            self.client_bytes_out.clone(),
        );
        r.register(
            "bytes_in",
            "Bytes received from all clients",
            self.bytes_in.clone(),
        );
        r.register(
            "bytes_out",
            "Bytes sent to all clients",
            self.bytes_out.clone(),
        );
        r.register(
            "wire_datagrams_in",
            "UDP datagrams received from native QUIC players, sampled each second",
            self.wire_datagrams_in.clone(),
        );
        r.register(
            "wire_bytes_in",
            "UDP payload bytes received from native QUIC players, sampled each second",
            self.wire_bytes_in.clone(),
        );
        r.register(
            "wire_datagrams_out",
            "UDP datagrams sent to native QUIC players, sampled each second",
            self.wire_datagrams_out.clone(),
        );
        r.register(
            "wire_bytes_out",
            "UDP payload bytes sent to native QUIC players, sampled each second",
            self.wire_bytes_out.clone(),
        );
        r.register(
            "snapshots_skipped",
            "Snapshots not sent to a quiet client because they would change nothing for it",
            self.snapshots_skipped.clone(),
        );
        r.register(
            "snapshot_bytes",
            "Encoded snapshot sizes",
            self.snapshot_bytes.clone(),
        );
    }

    /// Registers what went wrong (missing inputs, drops, malformed
    /// messages, kicks) and the fine tick timings.
    fn register_faults_and_timing(&self, r: &mut Registry) {
        r.register(
            "input_starvation",
            "Ticks a player's input had not arrived (the previous one was repeated)",
            self.input_starvation.clone(),
        );
        r.register("dropped_messages", "Messages dropped", self.dropped.clone());
        r.register(
            "malformed_messages",
            "Messages that failed to decode",
            self.malformed.clone(),
        );
        r.register(
            "kicks",
            "Clients disconnected for misbehaving",
            self.kicks.clone(),
        );
        r.register(
            "tick_duration_fine_seconds",
            "Time to run one tick, all rooms, in fine buckets (4.4 % apart)",
            self.tick_duration_fine.clone(),
        );
        r.register(
            "tick_lateness_seconds",
            "How late the tick loop woke after a tick's deadline, all rooms",
            self.tick_lateness.clone(),
        );
    }

    /// Adds what a connection put through its socket since `seen` (its
    /// previous sample), and makes `now` the new one.
    pub fn wire(&self, seen: &mut Wire, now: Wire) {
        self.wire_datagrams_in
            .inc_by(now.datagrams_in.saturating_sub(seen.datagrams_in));
        self.wire_bytes_in
            .inc_by(now.bytes_in.saturating_sub(seen.bytes_in));
        self.wire_datagrams_out
            .inc_by(now.datagrams_out.saturating_sub(seen.datagrams_out));
        self.wire_bytes_out
            .inc_by(now.bytes_out.saturating_sub(seen.bytes_out));
        *seen = now;
    }

    /// Counts one dropped message.
    pub fn count_drop(&self, reason: DropReason) {
        self.dropped.get_or_create(&DropLabel { reason }).inc();
    }

    /// Counts a message that could not be queued for a client's control
    /// stream: a full queue, or a client whose writer is gone because it
    /// stopped reading the stream (or is leaving).
    pub fn count_queue_error<T>(&self, sent: Result<(), mpsc::error::TrySendError<T>>) {
        match sent {
            Ok(()) => {}
            Err(mpsc::error::TrySendError::Full(_)) => {
                self.count_drop(DropReason::ControlQueueFull)
            }
            Err(mpsc::error::TrySendError::Closed(_)) => {
                self.count_drop(DropReason::ClientNotReading)
            }
        }
    }

    /// Counts a connection refused, or closed before its hello.
    pub fn refused(&self, reason: Refusal) {
        self.connections_refused
            .get_or_create(&RefusalLabel { reason })
            .inc();
    }

    /// Counts a connection of `transport` refused, or closed before its
    /// hello (in both families).
    pub fn refused_on(&self, transport: Transport, reason: Refusal) {
        self.refused(reason);
        self.refused_by_transport(transport, reason);
    }

    /// Counts a refusal in the per-transport family only.
    pub fn refused_by_transport(&self, transport: Transport, reason: Refusal) {
        self.transport_connections_refused
            .get_or_create(&TransportRefusalLabel { transport, reason })
            .inc();
    }

    /// Counts a connection of `transport` evicted from the pending pool
    /// (per transport: the unlabelled family counts it when the newcomer
    /// that evicted it is admitted).
    pub fn evicted_on(&self, transport: Transport) {
        self.refused_by_transport(transport, Refusal::Evicted);
    }

    /// Counts a connection opened (the `connections` gauges).
    pub fn opened_connection(&self, transport: Transport) {
        self.connections.inc();
        let label = TransportLabel { transport };
        self.transport_connections.get_or_create(&label).inc();
        self.transport_connections_opened
            .get_or_create(&label)
            .inc();
    }

    /// Counts a connection closed.
    pub fn closed_connection(&self, transport: Transport) {
        self.connections.dec();
        self.transport_connections
            .get_or_create(&TransportLabel { transport })
            .dec();
    }

    /// Counts `n` dropped messages.
    pub fn count_drops(&self, reason: DropReason, n: u64) {
        if n > 0 {
            self.dropped.get_or_create(&DropLabel { reason }).inc_by(n);
        }
    }

    /// Counts one malformed message.
    pub fn malformed(&self, channel: Channel) {
        self.malformed
            .get_or_create(&ChannelLabel { channel })
            .inc();
    }

    /// The byte counters of a client (created now, series removed by
    /// [`Metrics::forget_client`]).
    pub fn client(&self, client: u32) -> ClientBytes {
        let label = ClientLabel { client };
        ClientBytes {
            bytes_in: self.client_bytes_in.get_or_create_owned(&label),
            bytes_out: self.client_bytes_out.get_or_create_owned(&label),
        }
    }

    /// Removes a closed room's series.
    pub fn forget_room(&self, room: &str) {
        let label = RoomLabel { room: room.into() };
        self.tick_duration.remove(&label);
        self.missed_ticks.remove(&label);
        self.players.remove(&label);
        self.input_starvation.remove(&label);
    }

    /// Removes a departed client's byte series.
    pub fn forget_client(&self, client: u32) {
        let label = ClientLabel { client };
        self.client_bytes_in.remove(&label);
        self.client_bytes_out.remove(&label);
    }

    /// Counts bytes received on `channel` from a client.
    pub fn received(&self, client: &ClientBytes, channel: Channel, bytes: usize) {
        client.bytes_in.inc_by(bytes as u64);
        self.bytes_in
            .get_or_create(&ChannelLabel { channel })
            .inc_by(bytes as u64);
    }

    /// Counts bytes sent on `channel` to a client.
    pub fn sent(&self, client: &ClientBytes, channel: Channel, bytes: usize) {
        client.bytes_out.inc_by(bytes as u64);
        self.bytes_out
            .get_or_create(&ChannelLabel { channel })
            .inc_by(bytes as u64);
    }
}

/// The registry in the text exposition format.
pub fn encode(registry: &Registry) -> String {
    let mut text = String::new();
    prometheus_client::encoding::text::encode(&mut text, registry)
        .expect("writing to a String cannot fail");
    text
}

/// How long a metrics client has to send its request.
const REQUEST_TIMEOUT: Duration = Duration::from_secs(2);
/// Largest request head read.
const MAX_REQUEST: usize = 4096;

/// Serves `GET /metrics` on `listener` until `stop` turns true. One request
/// per connection, handled one at a time (a scraper, not a web server).
pub async fn serve(
    listener: TcpListener,
    registry: Arc<Registry>,
    mut stop: watch::Receiver<bool>,
) {
    loop {
        tokio::select! {
            () = crate::shutdown::stopped(&mut stop) => break,
            accepted = listener.accept() => match accepted {
                Ok((stream, peer)) => {
                    let answer = tokio::time::timeout(REQUEST_TIMEOUT, respond(stream, &registry));
                    if let Ok(Err(e)) | Err(e) = answer.await.map_err(std::io::Error::other) {
                        debug!(%peer, "metrics request failed: {e}");
                    }
                }
                Err(e) => {
                    warn!("metrics listener: {e}");
                    tokio::time::sleep(Duration::from_millis(100)).await;
                }
            }
        }
    }
}

async fn respond(mut stream: tokio::net::TcpStream, registry: &Registry) -> std::io::Result<()> {
    let mut head = Vec::with_capacity(512);
    let mut buf = [0u8; 1024];
    while !head.windows(4).any(|w| w == b"\r\n\r\n") && !head.windows(2).any(|w| w == b"\n\n") {
        let n = stream.read(&mut buf).await?;
        if n == 0 {
            break;
        }
        head.extend_from_slice(&buf[..n]);
        if head.len() > MAX_REQUEST {
            break;
        }
    }
    let line = head.split(|&b| b == b'\n').next().unwrap_or_default();
    let line = String::from_utf8_lossy(line);
    let mut parts = line.split_whitespace();
    let (method, path) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
    let (status, content_type, body) = if method == "GET" && (path == "/metrics" || path == "/") {
        (
            "200 OK",
            "application/openmetrics-text; version=1.0.0; charset=utf-8",
            encode(registry),
        )
    } else {
        (
            "404 Not Found",
            "text/plain; charset=utf-8",
            "not found: try GET /metrics\n".to_owned(),
        )
    };
    let response = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    );
    stream.write_all(response.as_bytes()).await?;
    stream.shutdown().await
}

/// Binds the metrics listener now (so a bad address fails the start-up and
/// the real port is known).
pub fn bind(addr: SocketAddr) -> std::io::Result<TcpListener> {
    let listener = std::net::TcpListener::bind(addr)?;
    listener.set_nonblocking(true)?;
    TcpListener::from_std(listener)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_encode_with_their_labels() {
        let (m, registry) = Metrics::new();
        m.count_drop(DropReason::InputLate);
        m.malformed(Channel::Datagram);
        let client = m.client(7);
        m.sent(&client, Channel::Datagram, 100);
        m.players
            .get_or_create(&RoomLabel {
                room: "room-1".into(),
            })
            .set(3);
        let text = encode(&registry);
        for needle in [
            "ledge_dropped_messages_total{reason=\"InputLate\"} 1",
            "ledge_malformed_messages_total{channel=\"Datagram\"} 1",
            "ledge_client_bytes_out_total{client=\"7\"} 100",
            "ledge_bytes_out_total{channel=\"Datagram\"} 100",
            "ledge_players{room=\"room-1\"} 3",
        ] {
            assert!(text.contains(needle), "{needle} missing from\n{text}");
        }
        m.forget_client(7);
        assert!(!encode(&registry).contains("client=\"7\""));
    }

    #[test]
    fn fine_buckets_are_log_spaced_from_a_microsecond_to_a_second() {
        let bounds: Vec<f64> = fine_buckets().collect();
        assert_eq!(bounds.len(), usize::from(FINE_BUCKETS));
        assert_eq!(bounds[0], FINE_FIRST_BUCKET);
        let last = *bounds.last().unwrap();
        assert!((1.0..1.1).contains(&last), "last bound {last}");
        let step = 2f64.powf(1.0 / 16.0);
        for w in bounds.windows(2) {
            assert!((w[1] / w[0] - step).abs() < 1e-9, "{w:?}");
        }
    }

    #[test]
    fn fine_tick_histogram_puts_a_tick_in_its_narrow_bucket() {
        let (m, registry) = Metrics::new();
        m.tick_duration_fine.observe(150e-6);
        m.tick_lateness.observe(2e-3);
        let text = encode(&registry);
        // Cumulative counts: 0 below 150 µs, 1 from the bucket holding it.
        let bucket = |line: &str| -> Option<(f64, u64)> {
            let rest = line.strip_prefix("ledge_tick_duration_fine_seconds_bucket{le=\"")?;
            let (le, count) = rest.split_once("\"} ")?;
            Some((le.parse().ok()?, count.trim().parse().ok()?))
        };
        let buckets: Vec<(f64, u64)> = text.lines().filter_map(bucket).collect();
        // The fine bounds, then `+Inf`.
        assert_eq!(buckets.len(), usize::from(FINE_BUCKETS) + 1);
        assert_eq!(buckets[buckets.len() - 1].0, f64::INFINITY);
        let first_full = buckets
            .iter()
            .find(|b| b.1 == 1)
            .expect("a bucket holds it");
        assert!(
            (150e-6..150e-6 * 1.045).contains(&first_full.0),
            "{first_full:?}"
        );
        assert!(buckets.iter().all(|b| (b.1 == 1) == (b.0 >= 150e-6)));
        assert!(text.contains("ledge_tick_duration_fine_seconds_count 1"));
        assert!(text.contains("ledge_tick_lateness_seconds_count 1"));
    }
}
