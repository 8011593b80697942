//! The web port's limits per source address (sans-IO): open HTTP
//! connections, requests a second, downloads (at once and a minute), and
//! the bytes a second their bodies may take of the host's uplink.
//!
//! Addresses are keyed as admission keys them ([`AddressKey`]: an IPv4
//! address, an IPv6 /64), so one machine is one address on both ports; its
//! WebSocket sessions count in admission beside its QUIC connections. Every
//! decision takes the time from the caller. Permits count until dropped. An
//! address is forgotten once it holds nothing open and its buckets are full
//! again, so the map only holds addresses active in the last few seconds,
//! never more than [`MAX_ADDRESSES`].
//!
//! Bodies are paced with two debt buckets, the address's and the uplink's:
//! each chunk takes its bytes from both at once (they may go below zero)
//! and waits until both are paid back, so an address gets at most its own
//! rate and all of them together at most the uplink.

use std::collections::BTreeMap;
use std::net::IpAddr;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use prometheus_client::encoding::EncodeLabelValue;

use crate::admission::AddressKey;
use crate::ratelimit::TokenBucket;

/// Most addresses tracked at once; past it new addresses are refused
/// ([`WebRefusal::Addresses`]) until idle ones are forgotten.
pub const MAX_ADDRESSES: usize = 4096;

/// Default most HTTP connections from one address (a browser opens up to
/// six to one host; a few players behind one router share the rest).
pub const DEFAULT_CONNECTIONS_PER_ADDRESS: usize = 16;
/// Default requests a second from one address, once its burst is spent.
pub const DEFAULT_REQUESTS_PER_SECOND: f64 = 20.0;
/// Default burst of requests from one address (a page load is about six).
pub const DEFAULT_REQUEST_BURST: f64 = 60.0;
/// Default most downloads (bodies of at least [`PACED_FROM`] bytes: the
/// level, the page's code) at once from one address.
pub const DEFAULT_DOWNLOADS_PER_ADDRESS: usize = 4;
/// Default most downloads a minute from one address (a page load is
/// three; a reload with the files cached none).
pub const DEFAULT_DOWNLOADS_PER_MINUTE: u32 = 30;
/// Default uplink budget of the web port, Mbit/s.
pub const DEFAULT_UPLINK_MBPS: f64 = 100.0;
/// Default share of the uplink one address may take.
pub const DEFAULT_ADDRESS_SHARE: f64 = 0.25;
/// Bodies this large or larger are downloads: counted and paced.
pub const PACED_FROM: usize = 16 * 1024;
/// Seconds of rate a byte bucket may run ahead (its burst).
const BURST_SECONDS: f64 = 0.1;

/// The web port's limits (`[web_limits]` in the configuration file).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WebLimits {
    /// Most open HTTP connections from one address.
    pub connections_per_address: usize,
    /// Requests a second from one address.
    pub requests_per_second: f64,
    /// Requests one address may make at once before the rate applies.
    pub request_burst: f64,
    /// Most downloads at once from one address.
    pub downloads_per_address: usize,
    /// Most downloads a minute from one address.
    pub downloads_per_minute: u32,
    /// Bytes a second of downloads, all addresses together.
    pub uplink_bytes_per_second: f64,
    /// Bytes a second of downloads to one address.
    pub address_bytes_per_second: f64,
}

/// Bytes a second of `mbps` megabits a second.
pub fn mbps_to_bytes(mbps: f64) -> f64 {
    mbps * 1e6 / 8.0
}

impl Default for WebLimits {
    fn default() -> WebLimits {
        let uplink = mbps_to_bytes(DEFAULT_UPLINK_MBPS);
        WebLimits {
            connections_per_address: DEFAULT_CONNECTIONS_PER_ADDRESS,
            requests_per_second: DEFAULT_REQUESTS_PER_SECOND,
            request_burst: DEFAULT_REQUEST_BURST,
            downloads_per_address: DEFAULT_DOWNLOADS_PER_ADDRESS,
            downloads_per_minute: DEFAULT_DOWNLOADS_PER_MINUTE,
            uplink_bytes_per_second: uplink,
            address_bytes_per_second: uplink * DEFAULT_ADDRESS_SHARE,
        }
    }
}

impl WebLimits {
    /// Whether every limit can let something through (a zero or negative
    /// rate would refuse everyone); the message names the bad one.
    pub fn check(&self) -> Result<(), String> {
        let positive = [
            (
                "connections_per_address",
                self.connections_per_address as f64,
            ),
            ("requests_per_second", self.requests_per_second),
            ("request_burst", self.request_burst),
            ("downloads_per_address", self.downloads_per_address as f64),
            ("downloads_per_minute", f64::from(self.downloads_per_minute)),
            ("uplink_mbps", self.uplink_bytes_per_second * 8e-6),
            ("address_mbps", self.address_bytes_per_second * 8e-6),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(format!("web_limits.{name} must be above 0 (it is {value})"));
            }
        }
        if self.request_burst < 1.0 {
            return Err("web_limits.request_burst must be at least 1".into());
        }
        Ok(())
    }
}

/// Why the web port turned a client away (a metric label).
#[derive(Debug, Clone, Copy, Hash, PartialEq, Eq, PartialOrd, Ord, EncodeLabelValue)]
pub enum WebRefusal {
    /// Its address has `connections_per_address` connections open.
    Connections,
    /// Its address made requests faster than `requests_per_second`.
    Requests,
    /// Its address has `downloads_per_address` downloads going, or started
    /// `downloads_per_minute` in the last minute.
    Downloads,
    /// The request had a body (no route takes one).
    Body,
    /// [`MAX_ADDRESSES`] addresses are active.
    Addresses,
}

/// A refusal and when to try again (`Retry-After`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limited {
    /// Which limit.
    pub reason: WebRefusal,
    /// When the limit lets the next one through.
    pub retry_after: Duration,
}

/// A debt bucket of bytes: takes any amount (its level may go below zero)
/// and says how long until the debt is paid back at its rate.
#[derive(Debug, Clone)]
struct Pacer {
    rate: f64,
    burst: f64,
    level: f64,
    last: Instant,
}

impl Pacer {
    fn new(rate: f64, now: Instant) -> Pacer {
        let burst = rate * BURST_SECONDS;
        Pacer {
            rate,
            burst,
            level: burst,
            last: now,
        }
    }

    fn refill(&mut self, now: Instant) {
        let elapsed = now.saturating_duration_since(self.last).as_secs_f64();
        self.level = (self.level + elapsed * self.rate).min(self.burst);
        self.last = self.last.max(now);
    }

    /// Takes `bytes`; the wait until they are paid for.
    fn take(&mut self, bytes: usize, now: Instant) -> Duration {
        self.refill(now);
        self.level -= bytes as f64;
        if self.level >= 0.0 {
            Duration::ZERO
        } else {
            Duration::from_secs_f64(-self.level / self.rate)
        }
    }

    fn full(&mut self, now: Instant) -> bool {
        self.refill(now);
        self.level >= self.burst
    }
}

/// What one address holds.
#[derive(Debug)]
struct Address {
    connections: usize,
    downloads: usize,
    requests: TokenBucket,
    download_starts: TokenBucket,
    bytes: Pacer,
}

impl Address {
    fn new(limits: &WebLimits, now: Instant) -> Address {
        let per_minute = f64::from(limits.downloads_per_minute);
        Address {
            connections: 0,
            downloads: 0,
            requests: TokenBucket::new(limits.request_burst, limits.requests_per_second, now),
            download_starts: TokenBucket::new(per_minute, per_minute / 60.0, now),
            bytes: Pacer::new(limits.address_bytes_per_second, now),
        }
    }

    /// Nothing open and every bucket full: as if never seen.
    fn idle(&mut self, limits: &WebLimits, now: Instant) -> bool {
        self.connections == 0
            && self.downloads == 0
            && self.requests.available(now) >= limits.request_burst
            && self.download_starts.available(now) >= f64::from(limits.downloads_per_minute)
            && self.bytes.full(now)
    }
}

#[derive(Debug)]
struct State {
    addresses: BTreeMap<AddressKey, Address>,
    uplink: Pacer,
    /// When idle addresses were last swept.
    swept: Instant,
}

/// The web port's per-address state, shared by its connection tasks.
#[derive(Debug)]
pub struct WebGuard {
    limits: WebLimits,
    state: Mutex<State>,
}

/// How often at most a full map is swept for idle addresses.
const SWEEP_EVERY: Duration = Duration::from_secs(1);

/// The wait before one more token of `bucket`, at least a second (the
/// unit of `Retry-After`).
fn retry_after(bucket: &mut TokenBucket, rate: f64, now: Instant) -> Duration {
    let missing = (1.0 - bucket.available(now)).max(0.0);
    Duration::from_secs_f64((missing / rate).ceil().max(1.0))
}

impl WebGuard {
    /// A guard enforcing `limits`, starting at `now`.
    pub fn new(limits: WebLimits, now: Instant) -> Arc<WebGuard> {
        Arc::new(WebGuard {
            limits,
            state: Mutex::new(State {
                addresses: BTreeMap::new(),
                uplink: Pacer::new(limits.uplink_bytes_per_second, now),
                swept: now,
            }),
        })
    }

    /// The limits.
    pub fn limits(&self) -> &WebLimits {
        &self.limits
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        // Counting never panics midway, so a poisoned lock is still sound.
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// A new connection from `ip`: its permit, or why not.
    pub fn connect(
        self: &Arc<Self>,
        ip: IpAddr,
        now: Instant,
    ) -> Result<ConnectionPermit, Limited> {
        let key = AddressKey::of(ip);
        let limits = self.limits;
        let mut s = self.lock();
        if !s.addresses.contains_key(&key) && s.addresses.len() >= MAX_ADDRESSES {
            if now.saturating_duration_since(s.swept) >= SWEEP_EVERY {
                s.swept = now;
                s.addresses.retain(|_, a| !a.idle(&limits, now));
            }
            if s.addresses.len() >= MAX_ADDRESSES {
                return Err(Limited {
                    reason: WebRefusal::Addresses,
                    retry_after: SWEEP_EVERY.max(Duration::from_secs(1)),
                });
            }
        }
        let a = s
            .addresses
            .entry(key)
            .or_insert_with(|| Address::new(&limits, now));
        if a.connections >= limits.connections_per_address {
            return Err(Limited {
                reason: WebRefusal::Connections,
                retry_after: Duration::from_secs(1),
            });
        }
        a.connections += 1;
        Ok(ConnectionPermit {
            guard: self.clone(),
            key,
        })
    }

    /// A request on `permit`'s connection at `now`: through, or limited.
    pub fn request(&self, permit: &ConnectionPermit, now: Instant) -> Result<(), Limited> {
        let rate = self.limits.requests_per_second;
        let mut s = self.lock();
        let Some(a) = s.addresses.get_mut(&permit.key) else {
            return Ok(());
        };
        if a.requests.try_take(now) {
            Ok(())
        } else {
            Err(Limited {
                reason: WebRefusal::Requests,
                retry_after: retry_after(&mut a.requests, rate, now),
            })
        }
    }

    /// A download (a body of at least [`PACED_FROM`] bytes) on `permit`'s
    /// connection at `now`: its permit, which paces the body, or why not.
    pub fn download(
        self: &Arc<Self>,
        permit: &ConnectionPermit,
        now: Instant,
    ) -> Result<DownloadPermit, Limited> {
        let limits = self.limits;
        let mut s = self.lock();
        let Some(a) = s.addresses.get_mut(&permit.key) else {
            return Err(Limited {
                reason: WebRefusal::Downloads,
                retry_after: Duration::from_secs(1),
            });
        };
        if a.downloads >= limits.downloads_per_address {
            return Err(Limited {
                reason: WebRefusal::Downloads,
                retry_after: Duration::from_secs(1),
            });
        }
        if !a.download_starts.try_take(now) {
            let rate = f64::from(limits.downloads_per_minute) / 60.0;
            return Err(Limited {
                reason: WebRefusal::Downloads,
                retry_after: retry_after(&mut a.download_starts, rate, now),
            });
        }
        a.downloads += 1;
        Ok(DownloadPermit {
            guard: self.clone(),
            key: permit.key,
        })
    }

    /// Addresses tracked now, after forgetting the idle ones (for the
    /// metrics and the tests: back to 0 a few seconds after the last
    /// client).
    pub fn addresses(&self, now: Instant) -> usize {
        let limits = self.limits;
        let mut s = self.lock();
        s.addresses.retain(|_, a| !a.idle(&limits, now));
        s.addresses.len()
    }

    /// Lowers `key`'s counts by `connections` and `downloads`, forgetting
    /// the address if that leaves it idle.
    fn release(&self, key: AddressKey, connections: usize, downloads: usize) {
        let limits = self.limits;
        let now = Instant::now();
        let mut s = self.lock();
        if let Some(a) = s.addresses.get_mut(&key) {
            a.connections -= connections;
            a.downloads -= downloads;
            if a.idle(&limits, now) {
                s.addresses.remove(&key);
            }
        }
    }
}

/// One open HTTP connection, counted until dropped.
#[derive(Debug)]
pub struct ConnectionPermit {
    guard: Arc<WebGuard>,
    key: AddressKey,
}

impl Drop for ConnectionPermit {
    fn drop(&mut self) {
        self.guard.release(self.key, 1, 0);
    }
}

/// One download going, counted until dropped; paces its body.
#[derive(Debug)]
pub struct DownloadPermit {
    guard: Arc<WebGuard>,
    key: AddressKey,
}

impl DownloadPermit {
    /// Takes `bytes` of the address's and the uplink's budgets at `now`:
    /// how long to wait before sending them.
    pub fn pace(&self, bytes: usize, now: Instant) -> Duration {
        let mut s = self.guard.lock();
        let uplink = s.uplink.take(bytes, now);
        let own = s
            .addresses
            .get_mut(&self.key)
            .map_or(Duration::ZERO, |a| a.bytes.take(bytes, now));
        uplink.max(own)
    }
}

impl Drop for DownloadPermit {
    fn drop(&mut self) {
        self.guard.release(self.key, 0, 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ip(last: u8) -> IpAddr {
        IpAddr::from([127, 0, 0, last])
    }

    fn limits() -> WebLimits {
        WebLimits {
            connections_per_address: 3,
            requests_per_second: 2.0,
            request_burst: 4.0,
            downloads_per_address: 2,
            downloads_per_minute: 3,
            uplink_bytes_per_second: 1_000_000.0,
            address_bytes_per_second: 250_000.0,
        }
    }

    #[test]
    fn one_address_is_capped_and_others_are_not() {
        let t0 = Instant::now();
        let g = WebGuard::new(limits(), t0);
        let held: Vec<_> = (0..3).map(|_| g.connect(ip(3), t0).unwrap()).collect();
        let refused = g.connect(ip(3), t0).unwrap_err();
        assert_eq!(refused.reason, WebRefusal::Connections);
        assert!(refused.retry_after >= Duration::from_secs(1));
        // Another address, and the same address as IPv4-mapped IPv6 is the
        // same one.
        assert!(g.connect(ip(2), t0).is_ok());
        let mapped = std::net::Ipv4Addr::new(127, 0, 0, 3).to_ipv6_mapped();
        assert!(g.connect(mapped.into(), t0).is_err());
        drop(held);
        assert!(g.connect(ip(3), t0).is_ok());
    }

    #[test]
    fn requests_get_the_burst_then_the_rate_with_a_retry_time() {
        let t0 = Instant::now();
        let g = WebGuard::new(limits(), t0);
        let c = g.connect(ip(3), t0).unwrap();
        assert!((0..4).all(|_| g.request(&c, t0).is_ok()));
        let limited = g.request(&c, t0).unwrap_err();
        assert_eq!(limited.reason, WebRefusal::Requests);
        assert_eq!(limited.retry_after, Duration::from_secs(1));
        // Honouring it: 2 a second come through again.
        let t1 = t0 + limited.retry_after;
        assert!(g.request(&c, t1).is_ok());
        assert!(g.request(&c, t1).is_ok());
        assert!(g.request(&c, t1).is_err());
        // A new connection does not reset the address's bucket.
        let c2 = g.connect(ip(3), t1).unwrap();
        assert!(g.request(&c2, t1).is_err());
    }

    #[test]
    fn downloads_are_capped_at_once_and_per_minute() {
        let t0 = Instant::now();
        let g = WebGuard::new(limits(), t0);
        let c = g.connect(ip(3), t0).unwrap();
        let a = g.download(&c, t0).unwrap();
        let b = g.download(&c, t0).unwrap();
        assert_eq!(
            g.download(&c, t0).unwrap_err().reason,
            WebRefusal::Downloads
        );
        drop((a, b));
        let c3 = g.download(&c, t0).unwrap();
        drop(c3);
        // Three a minute: the fourth waits for the bucket (20 s a token).
        let limited = g.download(&c, t0).unwrap_err();
        assert_eq!(limited.reason, WebRefusal::Downloads);
        assert_eq!(limited.retry_after, Duration::from_secs(20));
        assert!(g.download(&c, t0 + Duration::from_secs(20)).is_ok());
    }

    /// Bytes sent by `permits` taking turns in chunks over `secs` seconds
    /// of simulated time, each chunk sent when its wait is over.
    fn paced(permits: &[&DownloadPermit], t0: Instant, secs: f64) -> Vec<f64> {
        let chunk = 8 * 1024;
        let mut ready = vec![t0; permits.len()];
        let mut sent = vec![0.0; permits.len()];
        let end = t0 + Duration::from_secs_f64(secs);
        loop {
            let (i, &at) = ready
                .iter()
                .enumerate()
                .min_by_key(|(_, &t)| t)
                .expect("permits");
            if at >= end {
                return sent;
            }
            ready[i] = at + permits[i].pace(chunk, at);
            sent[i] += chunk as f64;
        }
    }

    #[test]
    fn an_address_gets_its_rate_and_all_together_the_uplink() {
        let t0 = Instant::now();
        let g = WebGuard::new(limits(), t0);
        let c = g.connect(ip(3), t0).unwrap();
        let (a, b) = (g.download(&c, t0).unwrap(), g.download(&c, t0).unwrap());
        // Two downloads to one address share its 250 kB/s.
        let sent = paced(&[&a, &b], t0, 10.0);
        let rate = sent.iter().sum::<f64>() / 10.0;
        assert!((rate / 250_000.0 - 1.0).abs() < 0.05, "{rate}");
        // Six addresses asking for 1.5 MB/s get the uplink's 1 MB/s, about
        // evenly.
        let t1 = t0 + Duration::from_secs(20);
        let conns: Vec<_> = (10..16).map(|i| g.connect(ip(i), t1).unwrap()).collect();
        let downloads: Vec<_> = conns.iter().map(|c| g.download(c, t1).unwrap()).collect();
        let refs: Vec<&DownloadPermit> = downloads.iter().collect();
        let sent = paced(&refs, t1, 10.0);
        let total = sent.iter().sum::<f64>() / 10.0;
        assert!((total / 1_000_000.0 - 1.0).abs() < 0.05, "{total}");
        let (min, max) = sent
            .iter()
            .fold((f64::MAX, 0f64), |(lo, hi), &s| (lo.min(s), hi.max(s)));
        assert!(max / min < 1.2, "{sent:?}");
    }

    #[test]
    fn idle_addresses_are_forgotten_and_the_map_is_bounded() {
        let t0 = Instant::now();
        let g = WebGuard::new(limits(), t0);
        let c = g.connect(ip(3), t0).unwrap();
        g.request(&c, t0).unwrap();
        drop(c);
        // The spent request token keeps it for half a second.
        assert_eq!(g.addresses(t0), 1);
        assert_eq!(g.addresses(t0 + Duration::from_secs(1)), 0);

        let many: Vec<_> = (0..MAX_ADDRESSES as u32)
            .map(|i| {
                g.connect(IpAddr::from((0x0a00_0000 + i).to_be_bytes()), t0)
                    .unwrap()
            })
            .collect();
        let full = g.connect(ip(3), t0).unwrap_err();
        assert_eq!(full.reason, WebRefusal::Addresses);
        drop(many);
        assert!(g.connect(ip(3), t0 + Duration::from_secs(2)).is_ok());
    }
}
