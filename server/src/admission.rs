//! Admission: which new connections the server takes on, and which
//! not-yet-joined connection goes when there is no room for them all.
//!
//! A connection is *pending* from its first packet until its hello has
//! been read, then *joined* (a player, or a client listing rooms). Pending
//! connections cost the server a QUIC handshake and a task but give it
//! nothing yet, so they have a pool of their own, much smaller than the
//! joined ones' ([`AdmissionConfig::pending`]), and a short deadline
//! ([`AdmissionConfig::hello_timeout`], enforced by the connection task).
//! Per source address (an IPv4 address, an IPv6 /64) there is a cap on
//! connections and a smaller one on pending connections, so one machine
//! cannot fill either pool; when many addresses fill the pending pool, the
//! oldest pending connection of the address holding the most goes first
//! (never a joined one). Above [`AdmissionConfig::retry_above`] pending
//! connections, or from an address that already has one pending, a source
//! must first prove it receives packets (QUIC Retry), so spoofed addresses
//! hold no state.
//!
//! Sans-IO: [`Admission::consider`] decides from the address and what
//! quinn knows of it, the accept loop acts (accept, retry, refuse), and a
//! [`Ticket`] held by the connection task keeps the counts true until it
//! ends.

use std::collections::BTreeMap;
use std::net::IpAddr;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use prometheus_client::encoding::EncodeLabelValue;
use tokio::sync::Notify;

/// Default most connections from one address.
pub const DEFAULT_PER_ADDRESS: usize = 4;
/// Default most pending (not yet joined) connections from one address: as
/// many as its connections, so players behind one router (or bots on one
/// machine) may all start at once; the pending pool and its eviction keep
/// one address from filling it.
pub const DEFAULT_PENDING_PER_ADDRESS: usize = DEFAULT_PER_ADDRESS;
/// Default size of the pending pool.
pub const DEFAULT_PENDING: usize = 32;
/// Default time from a connection's first packet to its hello.
pub const DEFAULT_HELLO_TIMEOUT: Duration = Duration::from_secs(2);
/// Default pending connections above which unvalidated sources get a
/// Retry.
pub const DEFAULT_RETRY_ABOVE: usize = 8;
/// How long a connection may say nothing after its handshake before a full
/// pool counts it silent. A client sends its hello with the handshake's
/// last flight, so the server reads it within moments; until then a
/// connection that just finished its handshake is ranked like one still in
/// it (by age), not ahead of them: under a flood of handshakes an honest
/// newcomer would otherwise be the one silent connection, and go first.
pub const SILENT_AFTER: Duration = Duration::from_millis(250);

/// The admission limits (the configuration file's `[admission]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdmissionConfig {
    /// Most connections (pending or joined) from one address.
    pub per_address: usize,
    /// Most pending connections from one address.
    pub pending_per_address: usize,
    /// Most pending connections in all.
    pub pending: usize,
    /// Time a connection has from its first packet to a complete hello.
    pub hello_timeout: Duration,
    /// Pending connections above which a source whose address is not
    /// validated is sent a QUIC Retry first.
    pub retry_above: usize,
}

impl Default for AdmissionConfig {
    fn default() -> AdmissionConfig {
        AdmissionConfig {
            per_address: DEFAULT_PER_ADDRESS,
            pending_per_address: DEFAULT_PENDING_PER_ADDRESS,
            pending: DEFAULT_PENDING,
            hello_timeout: DEFAULT_HELLO_TIMEOUT,
            retry_above: DEFAULT_RETRY_ABOVE,
        }
    }
}

/// Why a connection was refused or closed before joining (a metric label).
#[derive(Debug, Clone, Copy, Hash, PartialEq, Eq, EncodeLabelValue)]
pub enum Refusal {
    /// As many connections as `max_connections` have joined.
    ServerFull,
    /// Its address has `per_address` connections.
    AddressConnections,
    /// Its address has `pending_per_address` pending connections.
    AddressPending,
    /// The pending pool is full and its address holds the most of it.
    PendingFull,
    /// Closed to make room in the pending pool for another address.
    Evicted,
    /// Closed: no hello within `hello_timeout`.
    HelloTimeout,
    /// The server is shutting down.
    ShuttingDown,
}

/// A source address as admission counts it: an IPv4 address (also when
/// mapped into IPv6), or the /64 network of an IPv6 address, since one
/// host usually has a whole /64.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct AddressKey(IpAddr);

impl AddressKey {
    /// The key of `ip`.
    pub fn of(ip: IpAddr) -> AddressKey {
        match ip {
            IpAddr::V4(v4) => AddressKey(IpAddr::V4(v4)),
            IpAddr::V6(v6) => match v6.to_ipv4_mapped() {
                Some(v4) => AddressKey(IpAddr::V4(v4)),
                None => {
                    let net = u128::from(v6) & !((1u128 << 64) - 1);
                    AddressKey(IpAddr::V6(net.into()))
                }
            },
        }
    }
}

/// What to do with a new connection.
#[derive(Debug)]
pub enum Verdict {
    /// Take it on; the ticket counts it until dropped. `evicted` tells
    /// whether another pending connection was closed to make room.
    Admit {
        /// Held by the connection's task.
        ticket: Ticket,
        /// Another pending connection was evicted for it.
        evicted: bool,
    },
    /// Send a QUIC Retry: the source must show it receives packets.
    Retry,
    /// Refuse it (a stateless close).
    Refuse(Refusal),
}

#[derive(Debug, Default, Clone, Copy)]
struct Counts {
    open: usize,
    pending: usize,
}

#[derive(Debug)]
struct Pending {
    key: AddressKey,
    evict: Arc<Notify>,
    /// When its QUIC handshake finished (then only its hello is missing).
    handshaken: Option<Instant>,
}

impl Pending {
    /// Its handshake finished at least [`SILENT_AFTER`] before `now` and
    /// it has still said nothing.
    fn silent(&self, now: Instant) -> bool {
        self.handshaken
            .is_some_and(|at| now.saturating_duration_since(at) >= SILENT_AFTER)
    }
}

#[derive(Debug, Default)]
struct State {
    /// Per address, only while it has a connection.
    addresses: BTreeMap<AddressKey, Counts>,
    /// Pending connections by admission order (oldest first).
    pending: BTreeMap<u64, Pending>,
    joined: usize,
    next: u64,
}

impl State {
    fn counts(&mut self, key: AddressKey) -> &mut Counts {
        self.addresses.entry(key).or_default()
    }

    /// Lowers `key`'s counts, forgetting the address once it has none.
    fn release(&mut self, key: AddressKey, open: usize, pending: usize) {
        if let Some(c) = self.addresses.get_mut(&key) {
            c.open -= open;
            c.pending -= pending;
            if c.open == 0 {
                self.addresses.remove(&key);
            }
        }
    }

    /// The pending connection to close for a newcomer at `now`: of the
    /// addresses holding the most pending ones, the oldest connection that
    /// finished its handshake and has said nothing since (for
    /// [`SILENT_AFTER`]; a client sends its hello at once), else the oldest
    /// one.
    fn eviction_candidate(&self, now: Instant) -> Option<(u64, AddressKey, usize)> {
        let most = self.addresses.values().map(|c| c.pending).max()?;
        self.pending
            .iter()
            .filter(|(_, p)| self.addresses.get(&p.key).map(|c| c.pending) == Some(most))
            .min_by_key(|(&seq, p)| (!p.silent(now), seq))
            .map(|(&seq, p)| (seq, p.key, most))
    }
}

/// The admission state of one server (shared by the accept loop and the
/// connection tasks' tickets).
#[derive(Debug)]
pub struct Admission {
    config: AdmissionConfig,
    max_joined: usize,
    state: Mutex<State>,
}

impl Admission {
    /// Admission with these limits; at most `max_joined` joined
    /// connections.
    pub fn new(config: AdmissionConfig, max_joined: usize) -> Arc<Admission> {
        Arc::new(Admission {
            config,
            max_joined,
            state: Mutex::new(State::default()),
        })
    }

    /// The limits.
    pub fn config(&self) -> &AdmissionConfig {
        &self.config
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        // Counting never panics midway, so a poisoned lock is still sound.
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Decides on a new connection from `ip`, arriving at `now`.
    /// `validated`: quinn knows the source receives packets (it answered a
    /// Retry, or showed a token); `may_retry`: a Retry can still be sent.
    pub fn consider(
        self: &Arc<Self>,
        ip: IpAddr,
        validated: bool,
        may_retry: bool,
        now: Instant,
    ) -> Verdict {
        let key = AddressKey::of(ip);
        let c = &self.config;
        let mut s = self.lock();
        let here = s.addresses.get(&key).copied().unwrap_or_default();
        if !validated && may_retry && (s.pending.len() >= c.retry_above || here.pending > 0) {
            return Verdict::Retry;
        }
        if here.open >= c.per_address {
            return Verdict::Refuse(Refusal::AddressConnections);
        }
        if here.pending >= c.pending_per_address {
            return Verdict::Refuse(Refusal::AddressPending);
        }
        if s.joined >= self.max_joined {
            return Verdict::Refuse(Refusal::ServerFull);
        }
        let mut evicted = false;
        if s.pending.len() >= c.pending {
            match s.eviction_candidate(now) {
                Some((seq, victim, most)) if here.pending < most => {
                    let gone = s.pending.remove(&seq).expect("candidate is pending");
                    s.counts(victim).pending -= 1;
                    gone.evict.notify_one();
                    evicted = true;
                }
                _ => return Verdict::Refuse(Refusal::PendingFull),
            }
        }
        let seq = s.next;
        s.next += 1;
        let evict = Arc::new(Notify::new());
        s.pending.insert(
            seq,
            Pending {
                key,
                evict: evict.clone(),
                handshaken: None,
            },
        );
        let counts = s.counts(key);
        counts.open += 1;
        counts.pending += 1;
        Verdict::Admit {
            ticket: Ticket {
                admission: self.clone(),
                key,
                seq,
                joined: false,
                evict,
            },
            evicted,
        }
    }

    /// Connections pending now.
    pub fn pending(&self) -> usize {
        self.lock().pending.len()
    }

    /// Connections joined now.
    pub fn joined(&self) -> usize {
        self.lock().joined
    }

    /// Addresses with a connection now (for tests: back to 0 when all are
    /// gone).
    pub fn addresses(&self) -> usize {
        self.lock().addresses.len()
    }
}

/// One admitted connection, counted until dropped.
#[derive(Debug)]
pub struct Ticket {
    admission: Arc<Admission>,
    key: AddressKey,
    seq: u64,
    joined: bool,
    evict: Arc<Notify>,
}

impl Ticket {
    /// Resolves when the connection was evicted from the pending pool (it
    /// should close at once). Never resolves once joined.
    pub async fn evicted(&self) {
        if self.joined {
            std::future::pending::<()>().await;
        }
        self.evict.notified().await;
    }

    /// Its QUIC handshake finished at `now`: from then on only its hello
    /// is missing, and once it has been silent for [`SILENT_AFTER`] a full
    /// pool evicts it before those still in their handshake.
    pub fn handshaken(&self, now: Instant) {
        if let Some(p) = self.admission.lock().pending.get_mut(&self.seq) {
            p.handshaken = Some(now);
        }
    }

    /// Its hello was read: it leaves the pending pool for the joined
    /// connections. False if it was evicted meanwhile (it must close).
    pub fn join(&mut self) -> bool {
        if self.joined {
            return true;
        }
        let mut s = self.admission.lock();
        if s.pending.remove(&self.seq).is_none() {
            return false;
        }
        s.counts(self.key).pending -= 1;
        s.joined += 1;
        drop(s);
        self.joined = true;
        true
    }
}

impl Drop for Ticket {
    fn drop(&mut self) {
        let mut s = self.admission.lock();
        let pending = if self.joined {
            s.joined -= 1;
            0
        } else {
            // Not there any more when it was evicted (already uncounted).
            usize::from(s.pending.remove(&self.seq).is_some())
        };
        s.release(self.key, 1, pending);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::net::{Ipv4Addr, Ipv6Addr};

    fn v4(last: u8) -> IpAddr {
        IpAddr::V4(Ipv4Addr::new(10, 0, 0, last))
    }

    fn config() -> AdmissionConfig {
        AdmissionConfig {
            per_address: 3,
            pending_per_address: 2,
            pending: 4,
            hello_timeout: Duration::from_secs(1),
            retry_above: 100,
        }
    }

    #[track_caller]
    fn admit(a: &Arc<Admission>, ip: IpAddr) -> (Ticket, bool) {
        admit_at(a, ip, Instant::now())
    }

    #[track_caller]
    fn admit_at(a: &Arc<Admission>, ip: IpAddr, now: Instant) -> (Ticket, bool) {
        match a.consider(ip, true, false, now) {
            Verdict::Admit { ticket, evicted } => (ticket, evicted),
            other => panic!("{ip} admitted, not {other:?}"),
        }
    }

    #[track_caller]
    fn refused(a: &Arc<Admission>, ip: IpAddr) -> Refusal {
        match a.consider(ip, true, false, Instant::now()) {
            Verdict::Refuse(why) => why,
            other => panic!("{ip} refused, not {other:?}"),
        }
    }

    #[test]
    fn ipv6_counts_by_64_and_mapped_ipv4_as_ipv4() {
        let a: Ipv6Addr = "2001:db8:1:2:aaaa::1".parse().unwrap();
        let b: Ipv6Addr = "2001:db8:1:2:ffff::9".parse().unwrap();
        let c: Ipv6Addr = "2001:db8:1:3::1".parse().unwrap();
        assert_eq!(AddressKey::of(a.into()), AddressKey::of(b.into()));
        assert_ne!(AddressKey::of(a.into()), AddressKey::of(c.into()));
        let mapped = Ipv4Addr::new(192, 0, 2, 7).to_ipv6_mapped();
        assert_eq!(
            AddressKey::of(mapped.into()),
            AddressKey::of(Ipv4Addr::new(192, 0, 2, 7).into())
        );
    }

    #[test]
    fn one_address_gets_its_pending_and_connection_caps_not_more() {
        let a = Admission::new(config(), 100);
        let (mut first, _) = admit(&a, v4(1));
        let (_second, _) = admit(&a, v4(1));
        assert_eq!(refused(&a, v4(1)), Refusal::AddressPending);
        // Another address is not affected.
        let _other = admit(&a, v4(2));
        // Joining frees a pending place but still counts as a connection.
        assert!(first.join());
        let (_third, _) = admit(&a, v4(1));
        assert_eq!(refused(&a, v4(1)), Refusal::AddressConnections);
        drop(first);
        assert_eq!(a.joined(), 0);
        assert_eq!(refused(&a, v4(1)), Refusal::AddressPending);
    }

    #[test]
    fn the_joined_cap_refuses_newcomers() {
        let a = Admission::new(config(), 1);
        let (mut t, _) = admit(&a, v4(1));
        assert!(t.join());
        assert_eq!(refused(&a, v4(2)), Refusal::ServerFull);
        drop(t);
        let _ = admit(&a, v4(2));
    }

    #[test]
    fn a_full_pool_evicts_the_oldest_of_the_address_holding_most() {
        let a = Admission::new(config(), 100);
        let (x1, _) = admit(&a, v4(1));
        let (y1, _) = admit(&a, v4(2));
        let (x2, _) = admit(&a, v4(1));
        let (z1, _) = admit(&a, v4(3));
        assert_eq!(a.pending(), 4);
        // Address 1 holds the most: its oldest goes.
        let (w1, evicted) = admit(&a, v4(4));
        assert!(evicted);
        assert_eq!(a.pending(), 4);
        let mut x1 = x1;
        assert!(!x1.join(), "the evicted one cannot join");
        let mut x2 = x2;
        assert!(x2.join(), "its younger one stays");
        // Now 2, 3, 4 hold one each and a newcomer from 2 holds as many:
        // refused, nobody evicted.
        let (y2, evicted) = admit(&a, v4(5));
        assert!(!evicted, "one free place after the join");
        assert_eq!(refused(&a, v4(2)), Refusal::PendingFull);
        // A newcomer holding none evicts the oldest of the tied ones (y1).
        let (_v, evicted) = admit(&a, v4(6));
        assert!(evicted);
        let mut y1 = y1;
        assert!(!y1.join());
        drop((x1, x2, y1, y2, z1, w1));
        assert_eq!((a.pending(), a.joined()), (1, 0));
    }

    #[test]
    fn a_silent_connection_goes_before_one_still_in_its_handshake() {
        let a = Admission::new(config(), 100);
        let t0 = Instant::now();
        let (mut handshaking, _) = admit_at(&a, v4(1), t0);
        let (mut silent, _) = admit_at(&a, v4(2), t0);
        silent.handshaken(t0);
        let (_c, _) = admit_at(&a, v4(3), t0);
        let (_d, _) = admit_at(&a, v4(4), t0);
        let (_e, evicted) = admit_at(&a, v4(5), t0 + SILENT_AFTER);
        assert!(evicted);
        assert!(!silent.join(), "the younger but silent one went");
        assert!(handshaking.join());
    }

    /// The order of events under a flood from many addresses: every
    /// address holds one pending connection, the flood's still in their
    /// handshakes (each is evicted soon after it is admitted), and an
    /// honest client has just finished its handshake, its hello in flight.
    /// A newcomer evicts the oldest flood connection, not the honest one.
    #[test]
    fn a_connection_just_past_its_handshake_is_not_yet_silent() {
        let a = Admission::new(config(), 100);
        let t0 = Instant::now();
        let (mut oldest, _) = admit_at(&a, v4(1), t0);
        let (_b, _) = admit_at(&a, v4(2), t0);
        let (_c, _) = admit_at(&a, v4(3), t0);
        let (mut honest, _) = admit_at(&a, v4(4), t0);
        let hello_in_flight = t0 + Duration::from_millis(5);
        honest.handshaken(hello_in_flight);
        let (_e, evicted) = admit_at(&a, v4(5), hello_in_flight + SILENT_AFTER / 2);
        assert!(evicted);
        assert!(!oldest.join(), "the oldest in its handshake went");
        assert!(honest.join(), "the one whose hello is in flight stays");
    }

    #[tokio::test]
    async fn an_evicted_ticket_is_told() {
        let a = Admission::new(
            AdmissionConfig {
                pending: 1,
                ..config()
            },
            100,
        );
        let (victim, _) = admit(&a, v4(1));
        let (_new, evicted) = admit(&a, v4(2));
        assert!(evicted);
        tokio::time::timeout(Duration::from_secs(1), victim.evicted())
            .await
            .expect("the victim learns it was evicted");
    }

    #[test]
    fn unvalidated_sources_retry_under_load_or_beside_their_own_pending() {
        let a = Admission::new(
            AdmissionConfig {
                retry_above: 2,
                ..config()
            },
            100,
        );
        let retry = |ip| matches!(a.consider(ip, false, true, Instant::now()), Verdict::Retry);
        let _t1 = admit(&a, v4(1));
        assert!(retry(v4(1)), "an address with a handshake pending");
        assert!(!retry(v4(2)), "below the threshold");
        let _t2 = admit(&a, v4(2));
        assert!(retry(v4(3)), "at the threshold");
        assert!(
            matches!(
                a.consider(v4(3), false, false, Instant::now()),
                Verdict::Admit { .. }
            ),
            "a source that already answered a Retry is not sent another"
        );
    }

    #[test]
    fn counts_return_to_zero() {
        let a = Admission::new(config(), 100);
        let tickets: Vec<_> = (1..=4).map(|i| admit(&a, v4(i)).0).collect();
        let mut joined = admit(&a, v4(9)).0;
        assert!(joined.join());
        drop(tickets);
        drop(joined);
        assert_eq!((a.pending(), a.joined(), a.addresses()), (0, 0, 0));
    }
}
