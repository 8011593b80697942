//! Which server certificates to trust: a pinned fingerprint, or trust on
//! first use (TOFU) with a known-hosts file.
//!
//! ledge servers use self-signed certificates. A player either pins the
//! SHA-256 fingerprint the server prints (`--cert-hash`), or lets the client
//! remember the certificate the first time it connects to an address, like
//! SSH: the fingerprint is appended to a known-hosts file, later connections
//! to that address accept only that certificate, and a different one is
//! refused with [`TrustError::Changed`], which says what to do.
//!
//! The file has one `HOST:PORT FINGERPRINT` line per server (64 hex
//! digits; `#` starts a comment). Its default place is
//! [`default_known_hosts`].

use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};

use ledge_shared::protocol::{Fingerprint, RoomInfo};

use crate::error::{ClientError, TrustError};
use crate::net::session::{handshake, list_rooms, JoinOptions, Session};
use crate::net::transport::{dial_any_or, resolve, Dialed};

/// How to trust the server's certificate.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Trust {
    /// Only the certificate with this SHA-256 fingerprint.
    Pinned(Fingerprint),
    /// Trust on first use, remembered in this known-hosts file.
    KnownHosts(PathBuf),
}

impl Trust {
    /// Pinned when `cert_hash` is given, else trust on first use with
    /// `known_hosts` (or [`default_known_hosts`]).
    pub fn from_args(cert_hash: Option<Fingerprint>, known_hosts: Option<PathBuf>) -> Trust {
        match cert_hash {
            Some(pin) => Trust::Pinned(pin),
            None => Trust::KnownHosts(known_hosts.unwrap_or_else(default_known_hosts)),
        }
    }
}

/// The default known-hosts file: `$XDG_CONFIG_HOME/ledge/known_hosts`, else
/// `$HOME/.config/ledge/known_hosts` (`%APPDATA%\ledge\known_hosts` on
/// Windows), else `./known_hosts`.
pub fn default_known_hosts() -> PathBuf {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
    let base = if cfg!(windows) {
        var("APPDATA").map(PathBuf::from)
    } else {
        var("XDG_CONFIG_HOME")
            .map(PathBuf::from)
            .or_else(|| var("HOME").map(|h| PathBuf::from(h).join(".config")))
    };
    match base {
        Some(dir) => dir.join("ledge").join("known_hosts"),
        None => PathBuf::from("known_hosts"),
    }
}

/// One remembered server.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KnownHost {
    /// `HOST:PORT` as the player typed it.
    pub host: String,
    /// Its certificate's fingerprint.
    pub fingerprint: Fingerprint,
    /// Line in the file (1-based).
    pub line: usize,
}

/// A known-hosts file, read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KnownHosts {
    path: PathBuf,
    hosts: Vec<KnownHost>,
    lines: usize,
}

impl KnownHosts {
    /// Reads `path`; a missing file is empty.
    pub fn load(path: &Path) -> Result<KnownHosts, TrustError> {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
            Err(e) => {
                return Err(TrustError::Io {
                    path: path.to_owned(),
                    message: e.to_string(),
                })
            }
        };
        let mut hosts = Vec::new();
        let mut lines = 0;
        for (i, raw) in text.lines().enumerate() {
            lines = i + 1;
            let content = raw.split('#').next().unwrap_or("").trim();
            if content.is_empty() {
                continue;
            }
            let bad = |message: &str| TrustError::Malformed {
                path: path.to_owned(),
                line: i + 1,
                message: message.to_owned(),
            };
            let mut words = content.split_whitespace();
            let (Some(host), Some(hex), None) = (words.next(), words.next(), words.next()) else {
                return Err(bad("expected two words"));
            };
            let fingerprint = hex
                .parse::<Fingerprint>()
                .map_err(|e| bad(&format!("bad fingerprint: {e}")))?;
            hosts.push(KnownHost {
                host: host.to_owned(),
                fingerprint,
                line: i + 1,
            });
        }
        Ok(KnownHosts {
            path: path.to_owned(),
            hosts,
            lines,
        })
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The entries, in file order.
    pub fn hosts(&self) -> &[KnownHost] {
        &self.hosts
    }

    /// The first entry for `host` (`HOST:PORT`, compared ASCII
    /// case-insensitively).
    pub fn get(&self, host: &str) -> Option<&KnownHost> {
        self.hosts
            .iter()
            .find(|h| h.host.eq_ignore_ascii_case(host))
    }

    /// Checks `presented` for `host`: `Ok(true)` when it is the stored one,
    /// `Ok(false)` when the host is unknown, the error when it changed.
    pub fn check(&self, host: &str, presented: Fingerprint) -> Result<bool, TrustError> {
        match self.get(host) {
            None => Ok(false),
            Some(k) if k.fingerprint == presented => Ok(true),
            Some(k) => Err(TrustError::Changed {
                host: host.to_owned(),
                presented,
                stored: k.fingerprint,
                path: self.path.clone(),
                line: k.line,
            }),
        }
    }

    /// Appends `host` with `fingerprint` to the file (creating it and its
    /// folder) and to this list.
    pub fn add(&mut self, host: &str, fingerprint: Fingerprint) -> Result<(), TrustError> {
        let io = |e: std::io::Error| TrustError::Io {
            path: self.path.clone(),
            message: e.to_string(),
        };
        if let Some(dir) = self.path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(io)?;
        }
        let existed = self.path.exists();
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&self.path)
            .map_err(io)?;
        let mut text = String::new();
        if !existed {
            text.push_str("# ledge known hosts (trust on first use): HOST:PORT SHA-256\n");
            self.lines += 1;
        }
        text.push_str(&format!("{host} {fingerprint}\n"));
        file.write_all(text.as_bytes()).map_err(io)?;
        self.lines += 1;
        self.hosts.push(KnownHost {
            host: host.to_owned(),
            fingerprint,
            line: self.lines,
        });
        Ok(())
    }
}

impl fmt::Display for Trust {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Trust::Pinned(pin) => write!(f, "pinned certificate {pin}"),
            Trust::KnownHosts(path) => write!(f, "trust on first use ({})", path.display()),
        }
    }
}

/// How a connection's certificate was trusted.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Trusted {
    /// It matched the pinned fingerprint.
    Pinned,
    /// It matched the known-hosts entry for the address.
    Known,
    /// First connection to this address: the fingerprint was stored.
    FirstUse(Fingerprint),
}

/// Connects to `server` (`HOST:PORT`) and joins with `options`, trusting
/// the certificate as `trust` says (see [`dial_trusted`]).
pub async fn connect_trusted(
    server: &str,
    trust: &Trust,
    options: &JoinOptions,
) -> Result<(Session, Trusted), ClientError> {
    let hello = options.hello();
    ledge_shared::protocol::Message::validate(&hello)?;
    let (dialed, trusted) = dial_trusted(server, trust).await?;
    let session = handshake(dialed, hello).await?;
    Ok((session, trusted))
}

/// Lists the rooms of `server` (`HOST:PORT`), trusting its certificate as
/// `trust` says (see [`dial_trusted`]).
pub async fn list_rooms_trusted(
    server: &str,
    trust: &Trust,
) -> Result<(Vec<RoomInfo>, Trusted), ClientError> {
    let (dialed, trusted) = dial_trusted(server, trust).await?;
    Ok((list_rooms(dialed).await?, trusted))
}

/// Connects to `server` (`HOST:PORT`), trusting the certificate as `trust`
/// says. With [`Trust::KnownHosts`], an address not in the file is trusted
/// and stored (after the TLS handshake proved the server holds the
/// certificate's key); a known address must present the stored
/// certificate, else [`TrustError::Changed`].
pub async fn dial_trusted(server: &str, trust: &Trust) -> Result<(Dialed, Trusted), ClientError> {
    let (addr, server_name) = resolve(server).await?;
    let (pin, known) = match trust {
        Trust::Pinned(pin) => (Some(*pin), None),
        Trust::KnownHosts(path) => {
            let known = KnownHosts::load(path)?;
            (known.get(server).map(|k| k.fingerprint), Some(known))
        }
    };
    let dialed = dial_any_or(addr, &server_name, pin).await;
    let (dialed, presented) = match (dialed, &known) {
        (Err(ClientError::FingerprintMismatch { presented, .. }), Some(known)) => {
            // Says which file and line, and what to do.
            return Err(known.check(server, presented).err().map_or_else(
                || ClientError::Config("fingerprint mismatch".into()),
                ClientError::Trust,
            ));
        }
        (other, _) => other?,
    };
    let trusted = match (known, pin) {
        (None, _) => Trusted::Pinned,
        (Some(_), Some(_)) => Trusted::Known,
        (Some(mut known), None) => {
            known.add(server, presented)?;
            Trusted::FirstUse(presented)
        }
    };
    Ok((dialed, trusted))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fp(b: u8) -> Fingerprint {
        Fingerprint([b; 32])
    }

    #[test]
    fn known_hosts_round_trip_and_refuse_a_changed_certificate() {
        let dir = std::env::temp_dir().join(format!("ledge-kh-{}", std::process::id()));
        let path = dir.join("sub").join("known_hosts");
        let _ = std::fs::remove_dir_all(&dir);
        let mut kh = KnownHosts::load(&path).unwrap();
        assert!(kh.hosts().is_empty());
        assert_eq!(kh.check("a:1", fp(1)), Ok(false));
        kh.add("a:1", fp(1)).unwrap();
        kh.add("b:2", fp(2)).unwrap();
        let again = KnownHosts::load(&path).unwrap();
        assert_eq!(again, kh);
        assert_eq!(again.check("A:1", fp(1)), Ok(true));
        let err = again.check("b:2", fp(9)).unwrap_err();
        assert!(
            matches!(err, TrustError::Changed { line: 3, .. }),
            "{err:?}"
        );
        let text = err.to_string();
        assert!(
            text.contains("CHANGED") && text.contains("remove line 3"),
            "{text}"
        );
        assert!(text.contains(&fp(9).to_string()) && text.contains("--cert-hash"));

        std::fs::write(&path, "a:1 nothex\n").unwrap();
        let err = KnownHosts::load(&path).unwrap_err();
        assert!(
            matches!(err, TrustError::Malformed { line: 1, .. }),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn trust_from_arguments() {
        assert_eq!(Trust::from_args(Some(fp(1)), None), Trust::Pinned(fp(1)));
        assert_eq!(
            Trust::from_args(None, Some("x/kh".into())),
            Trust::KnownHosts("x/kh".into())
        );
        assert!(matches!(Trust::from_args(None, None), Trust::KnownHosts(_)));
    }
}
