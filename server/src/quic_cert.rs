//! The native QUIC endpoint's TLS identity: a self-signed certificate kept
//! on disk, the one `ledge-client --cert-hash` pins. (WebTransport's
//! short-lived, rotating certificates are another:
//! [`crate::web::webtransport_cert`].)
//!
//! Generated with rcgen on first start (SANs `localhost` and `127.0.0.1`)
//! and reused afterwards, so the fingerprint clients pinned stays valid
//! across restarts. Stored as PEM (`cert.pem`, `key.pem`), the key readable
//! by its owner only.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use rustls::pki_types::pem::PemObject;
use rustls::pki_types::{CertificateDer, PrivateKeyDer};

use crate::fingerprint::{self, Fingerprint};

/// File name of the certificate inside the certificate directory.
pub const CERT_FILE: &str = "cert.pem";
/// File name of the private key inside the certificate directory.
pub const KEY_FILE: &str = "key.pem";

/// Subject alternative names of a generated certificate.
const SUBJECT_ALT_NAMES: [&str; 2] = ["localhost", "127.0.0.1"];

/// A certificate with its private key and fingerprint.
#[derive(Debug)]
pub struct Identity {
    /// The DER-encoded certificate.
    pub cert: CertificateDer<'static>,
    /// The private key matching `cert`.
    pub key: PrivateKeyDer<'static>,
    /// SHA-256 of `cert`, what clients pin.
    pub fingerprint: Fingerprint,
    /// Whether this start generated the files (`false`: loaded from disk).
    pub generated: bool,
}

/// Why the identity could not be loaded or created.
#[derive(Debug, thiserror::Error)]
pub enum CertError {
    /// Reading, writing or creating a file or directory failed.
    #[error("{action} {path}: {source}")]
    Io {
        /// What was being done.
        action: &'static str,
        /// The file or directory concerned.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A stored file is not valid PEM of the expected kind.
    #[error("cannot parse {path}: {message}")]
    Parse {
        /// The file concerned.
        path: PathBuf,
        /// What the parser said.
        message: String,
    },
    /// Exactly one of certificate and key exists: refuse to overwrite it.
    #[error(
        "{present} exists but {missing} does not; remove the other file to generate a new pair"
    )]
    HalfPair {
        /// The file that exists.
        present: PathBuf,
        /// The file that is missing.
        missing: PathBuf,
    },
    /// rcgen failed to generate the certificate.
    #[error("cannot generate a certificate: {0}")]
    Generate(#[from] rcgen::Error),
}

impl Identity {
    /// Loads `cert.pem`/`key.pem` from `dir`, or generates and stores a new
    /// self-signed pair when neither exists (creating `dir` if needed).
    pub fn load_or_generate(dir: &Path) -> Result<Identity, CertError> {
        let cert_path = dir.join(CERT_FILE);
        let key_path = dir.join(KEY_FILE);
        match (cert_path.exists(), key_path.exists()) {
            (true, true) => Self::load(&cert_path, &key_path),
            (false, false) => Self::generate(dir, &cert_path, &key_path),
            (true, false) => Err(CertError::HalfPair {
                present: cert_path,
                missing: key_path,
            }),
            (false, true) => Err(CertError::HalfPair {
                present: key_path,
                missing: cert_path,
            }),
        }
    }

    fn load(cert_path: &Path, key_path: &Path) -> Result<Identity, CertError> {
        let cert = CertificateDer::from_pem_file(cert_path).map_err(|e| CertError::Parse {
            path: cert_path.to_owned(),
            message: e.to_string(),
        })?;
        let key = PrivateKeyDer::from_pem_file(key_path).map_err(|e| CertError::Parse {
            path: key_path.to_owned(),
            message: e.to_string(),
        })?;
        Ok(Identity {
            fingerprint: fingerprint::of_der(&cert),
            cert,
            key,
            generated: false,
        })
    }

    fn generate(dir: &Path, cert_path: &Path, key_path: &Path) -> Result<Identity, CertError> {
        let names: Vec<String> = SUBJECT_ALT_NAMES.iter().map(|s| s.to_string()).collect();
        let rcgen::CertifiedKey { cert, key_pair } = rcgen::generate_simple_self_signed(names)?;
        fs::create_dir_all(dir).map_err(|source| CertError::Io {
            action: "create directory",
            path: dir.to_owned(),
            source,
        })?;
        // Key first: a crash in between leaves a key without a certificate,
        // which `load_or_generate` reports instead of silently replacing.
        write_file(key_path, key_pair.serialize_pem().as_bytes(), true)?;
        write_file(cert_path, cert.pem().as_bytes(), false)?;
        let der = cert.der().clone();
        Ok(Identity {
            fingerprint: fingerprint::of_der(&der),
            cert: der,
            key: PrivateKeyDer::Pkcs8(key_pair.serialize_der().into()),
            generated: true,
        })
    }
}

/// Writes a new file (never replacing one), owner-only when `private`.
fn write_file(path: &Path, contents: &[u8], private: bool) -> Result<(), CertError> {
    let io_err = |action| {
        move |source| CertError::Io {
            action,
            path: path.to_owned(),
            source,
        }
    };
    let mut options = fs::OpenOptions::new();
    options.write(true).create_new(true);
    #[cfg(unix)]
    if private {
        use std::os::unix::fs::OpenOptionsExt;
        options.mode(0o600);
    }
    #[cfg(not(unix))]
    let _ = private;
    let mut file = options.open(path).map_err(io_err("create"))?;
    file.write_all(contents).map_err(io_err("write"))?;
    file.sync_all().map_err(io_err("sync"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generates_once_then_reuses() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("nested/certs");
        let first = Identity::load_or_generate(&sub).unwrap();
        assert!(first.generated);
        let second = Identity::load_or_generate(&sub).unwrap();
        assert!(!second.generated);
        assert_eq!(first.fingerprint, second.fingerprint);
        assert_eq!(first.cert, second.cert);
        assert_eq!(first.key.secret_der(), second.key.secret_der());
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = fs::metadata(sub.join(KEY_FILE))
                .unwrap()
                .permissions()
                .mode();
            assert_eq!(mode & 0o077, 0, "key readable by others: {mode:o}");
        }
    }

    #[test]
    fn half_pair_is_an_error_not_an_overwrite() {
        let dir = tempfile::tempdir().unwrap();
        Identity::load_or_generate(dir.path()).unwrap();
        fs::remove_file(dir.path().join(CERT_FILE)).unwrap();
        let err = Identity::load_or_generate(dir.path()).unwrap_err();
        assert!(matches!(err, CertError::HalfPair { .. }), "{err}");
    }

    #[test]
    fn corrupt_files_are_reported() {
        let dir = tempfile::tempdir().unwrap();
        fs::write(dir.path().join(CERT_FILE), "not pem").unwrap();
        fs::write(dir.path().join(KEY_FILE), "not pem").unwrap();
        let err = Identity::load_or_generate(dir.path()).unwrap_err();
        assert!(matches!(err, CertError::Parse { .. }), "{err}");
    }
}
