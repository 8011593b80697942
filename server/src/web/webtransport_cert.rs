//! WebTransport certificates and their rotation.
//!
//! A browser accepts a self-signed certificate only through
//! `serverCertificateHashes`, and then only an ECDSA P-256 one valid for at
//! most 14 days. So the server makes its own ([`generate`]: 13 days, from
//! an hour ago against clock skew), never stores it, and replaces it
//! before it expires. [`Rotation`] decides when, sans-IO (the time is
//! passed in; the tests use a fake clock):
//!
//! * at 40 % of the current certificate's life the *next* one is made and
//!   listed in `/web.json` beside it, so a page that fetched the list
//!   before the switch knows the certificate it will meet after it;
//! * at 50 % the next becomes current: new sessions get it, running
//!   sessions go on with theirs.
//!
//! A certificate is thus current from about 10 % to 50 % of its life and
//! never near its end. The native QUIC endpoint's certificate (the one
//! `ledge-client --cert-hash` pins) is another, kept on disk, unchanged
//! ([`crate::quic_cert`]).

use std::time::{Duration, SystemTime};

/// Validity of a certificate made now: 13 days from its `not_before`
/// (browsers accept at most 14).
pub const VALIDITY: Duration = Duration::from_secs(13 * 24 * 3600);
/// How far back `not_before` is set, against clients whose clock is a
/// little behind.
pub const BACKDATE: Duration = Duration::from_secs(3600);

/// How long certificates live: [`VALIDITY`] from [`BACKDATE`] before they
/// are made, unless a test shortens it (browsers accept at most 14 days).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CertLife {
    /// From `not_before` to `not_after`.
    pub validity: Duration,
    /// How far before its making `not_before` is.
    pub backdate: Duration,
}

impl Default for CertLife {
    fn default() -> CertLife {
        CertLife {
            validity: VALIDITY,
            backdate: BACKDATE,
        }
    }
}

/// When a certificate is valid and what it hashes to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CertInfo {
    /// Its `not_before`.
    pub not_before: SystemTime,
    /// Its `not_after`.
    pub not_after: SystemTime,
    /// SHA-256 of its DER encoding (what browsers are given).
    pub sha256: [u8; 32],
}

impl CertInfo {
    /// The time `num / den` of the way through its validity.
    fn at(&self, num: u32, den: u32) -> SystemTime {
        let life = self
            .not_after
            .duration_since(self.not_before)
            .unwrap_or_default();
        self.not_before + life * num / den
    }
}

/// What is due.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// Make the next certificate ([`Rotation::prepared`]).
    Prepare,
    /// Serve the next certificate to new sessions ([`Rotation::promote`]).
    Promote,
}

/// The current certificate, the next one once made, and when to act.
#[derive(Debug, Clone)]
pub struct Rotation {
    current: CertInfo,
    next: Option<CertInfo>,
}

impl Rotation {
    /// Starting with `current`.
    pub fn new(current: CertInfo) -> Rotation {
        Rotation {
            current,
            next: None,
        }
    }

    /// The certificate new sessions get.
    pub fn current(&self) -> &CertInfo {
        &self.current
    }

    /// The next certificate, once made.
    pub fn next(&self) -> Option<&CertInfo> {
        self.next.as_ref()
    }

    /// When the next step is due: preparing at 40 % of the current
    /// certificate's life, promoting at 50 %.
    pub fn due_at(&self) -> SystemTime {
        match self.next {
            None => self.current.at(2, 5),
            Some(_) => self.current.at(1, 2),
        }
    }

    /// The step due at `now`, if any.
    pub fn poll(&self, now: SystemTime) -> Option<Step> {
        if now < self.due_at() {
            return None;
        }
        Some(match self.next {
            None => Step::Prepare,
            Some(_) => Step::Promote,
        })
    }

    /// The next certificate was made.
    pub fn prepared(&mut self, next: CertInfo) {
        self.next = Some(next);
    }

    /// The next certificate becomes current; returns the one it replaces
    /// (`None`, and nothing changes, if there is no next one yet).
    pub fn promote(&mut self) -> Option<CertInfo> {
        let next = self.next.take()?;
        Some(std::mem::replace(&mut self.current, next))
    }

    /// The hashes a page may meet: the current certificate's, then the
    /// next one's once made.
    pub fn hashes(&self) -> Vec<[u8; 32]> {
        std::iter::once(self.current.sha256)
            .chain(self.next.map(|n| n.sha256))
            .collect()
    }
}

/// A generated certificate and its key.
pub struct WebCert {
    /// The certificate, DER.
    pub der: Vec<u8>,
    /// Its private key, PKCS#8 DER.
    pub key: Vec<u8>,
    /// Validity and hash.
    pub info: CertInfo,
}

impl std::fmt::Debug for WebCert {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WebCert").field("info", &self.info).finish()
    }
}

/// Makes a self-signed ECDSA P-256 certificate valid from `now` −
/// `life.backdate` for `life.validity` (by default [`BACKDATE`] and
/// [`VALIDITY`]), for `names` (host names or addresses).
pub fn generate(
    now: SystemTime,
    names: &[String],
    life: CertLife,
) -> Result<WebCert, rcgen::Error> {
    let key = rcgen::KeyPair::generate_for(&rcgen::PKCS_ECDSA_P256_SHA256)?;
    let mut params = rcgen::CertificateParams::new(names.to_vec())?;
    let not_before = now.checked_sub(life.backdate).unwrap_or(now);
    // Whole seconds: the certificate stores no more.
    let secs = |t: SystemTime| {
        t.duration_since(SystemTime::UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or_default()
    };
    let not_before = SystemTime::UNIX_EPOCH + Duration::from_secs(secs(not_before));
    let not_after = not_before + life.validity;
    params.not_before = time::OffsetDateTime::from(not_before);
    params.not_after = time::OffsetDateTime::from(not_after);
    params
        .distinguished_name
        .push(rcgen::DnType::CommonName, "ledge WebTransport");
    let cert = params.self_signed(&key)?;
    let der = cert.der().to_vec();
    let sha256 = crate::fingerprint::of_der(&der).0;
    Ok(WebCert {
        der,
        key: key.serialize_der(),
        info: CertInfo {
            not_before,
            not_after,
            sha256,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const HOUR: Duration = Duration::from_secs(3600);
    const DAY: Duration = Duration::from_secs(24 * 3600);

    /// A fake certificate made at `now`, numbered by `n`.
    fn fake(now: SystemTime, n: u8) -> CertInfo {
        CertInfo {
            not_before: now - BACKDATE,
            not_after: now - BACKDATE + VALIDITY,
            sha256: [n; 32],
        }
    }

    #[test]
    fn the_next_certificate_is_listed_before_it_is_served() {
        let start = SystemTime::UNIX_EPOCH + 1000 * DAY;
        let mut r = Rotation::new(fake(start, 0));
        assert_eq!(r.hashes(), vec![[0; 32]]);
        assert_eq!(r.poll(start), None);
        // 40 % of 13 days is 5.2 days after not_before.
        let prepare = start - BACKDATE + VALIDITY * 2 / 5;
        assert_eq!(r.due_at(), prepare);
        assert_eq!(r.poll(prepare - Duration::from_secs(1)), None);
        assert_eq!(r.poll(prepare), Some(Step::Prepare));
        r.prepared(fake(prepare, 1));
        assert_eq!(r.hashes(), vec![[0; 32], [1; 32]], "current first");
        assert_eq!(r.poll(prepare), None);
        let promote = start - BACKDATE + VALIDITY / 2;
        assert_eq!(r.poll(promote), Some(Step::Promote));
        assert_eq!(r.promote().map(|old| old.sha256), Some([0; 32]));
        assert_eq!(r.hashes(), vec![[1; 32]]);
        assert_eq!(r.promote(), None, "nothing to promote");
        assert_eq!(r.current().sha256, [1; 32]);
    }

    #[test]
    fn sixty_days_on_a_fake_clock_never_serve_an_expired_or_unlisted_certificate() {
        let start = SystemTime::UNIX_EPOCH + 20_000 * DAY;
        let mut r = Rotation::new(fake(start, 0));
        let mut n = 0u8;
        let mut listed_since = std::collections::HashMap::new();
        listed_since.insert([0u8; 32], start);
        let mut promotions = 0;
        let mut now = start;
        while now < start + 60 * DAY {
            while let Some(step) = r.poll(now) {
                match step {
                    Step::Prepare => {
                        n += 1;
                        let next = fake(now, n);
                        listed_since.insert(next.sha256, now);
                        r.prepared(next);
                    }
                    Step::Promote => {
                        r.promote().unwrap();
                        promotions += 1;
                        // The new current was listed for over a day.
                        let since = listed_since[&r.current().sha256];
                        assert!(now.duration_since(since).unwrap() > DAY, "{promotions}");
                    }
                }
            }
            let c = r.current();
            assert!(c.not_before <= now && now < c.not_after, "valid now");
            assert!(
                c.not_after.duration_since(now).unwrap() > 6 * DAY,
                "far from expiring"
            );
            assert!(c.not_after.duration_since(c.not_before).unwrap() <= 14 * DAY);
            assert_eq!(r.hashes()[0], c.sha256);
            now += HOUR;
        }
        // 60 days at one switch every 5.2 days.
        assert_eq!(promotions, 11);
    }

    #[test]
    fn a_late_wake_up_catches_up_at_once() {
        let start = SystemTime::UNIX_EPOCH + 500 * DAY;
        let mut r = Rotation::new(fake(start, 0));
        let late = start + 12 * DAY;
        assert_eq!(r.poll(late), Some(Step::Prepare));
        r.prepared(fake(late, 1));
        assert_eq!(r.poll(late), Some(Step::Promote));
        r.promote();
        assert_eq!(r.poll(late), None);
        assert_eq!(r.current().sha256, [1; 32]);
    }

    #[test]
    fn generated_certificates_are_p256_and_valid_13_days_from_an_hour_ago() {
        let now = SystemTime::now();
        let cert = generate(now, &["localhost".to_owned()], CertLife::default()).unwrap();
        let i = cert.info;
        assert_eq!(i.not_after.duration_since(i.not_before).unwrap(), VALIDITY);
        let back = now.duration_since(i.not_before).unwrap();
        assert!(back >= BACKDATE && back < BACKDATE + Duration::from_secs(2));
        assert_eq!(i.sha256, crate::fingerprint::of_der(&cert.der).0);
        // The ecPublicKey and prime256v1 object identifiers, DER-encoded.
        let ec_public_key = [0x06, 0x07, 0x2a, 0x86, 0x48, 0xce, 0x3d, 0x02, 0x01];
        let p256 = [0x06, 0x08, 0x2a, 0x86, 0x48, 0xce, 0x3d, 0x03, 0x01, 0x07];
        let has = |needle: &[u8]| cert.der.windows(needle.len()).any(|w| w == needle);
        assert!(has(&ec_public_key) && has(&p256));
        let other = generate(now, &["localhost".to_owned()], CertLife::default()).unwrap();
        assert_ne!(other.info.sha256, i.sha256, "a new key each time");
    }
}
