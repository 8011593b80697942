//! The server's level, downloaded: the [`LevelOffer`] in the `Welcome`
//! names a level bundle by SHA-256 and size; a client that does not have
//! it asks for it ([`ClientControl::GetLevel`]) and reads it from a stream
//! of its own, into a cache on disk ([`LevelCache`]).
//!
//! * The embedded default level is never downloaded (its bundle is built
//!   here and compared by hash).
//! * A cached bundle is used only if its bytes still hash to its name (a
//!   damaged file is deleted and downloaded again).
//! * A download writes `HASH.part`; a cut one is resumed from its length
//!   the next time (`GetLevel{offset}`), and the whole is hashed before it
//!   becomes `HASH.bundle`: a mismatch deletes it and fails, saying so.
//! * Nothing bigger than [`ledge_shared::protocol::MAX_LEVEL_BUNDLE`] is read, whatever the server
//!   offers or sends; the cache keeps its newest bundles within
//!   [`CACHE_BYTES`].

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

use ledge_levels::bundle::sha256;
use ledge_levels::LevelBundle;
use ledge_shared::protocol::{ClientControl, LevelOffer};

use crate::error::ClientError;
pub use crate::net::download::Fetched;
use crate::net::download::{decode, embedded, Download};
use crate::net::session::Session;

/// Most bytes the cache keeps; older bundles are deleted past it.
pub const CACHE_BYTES: u64 = 512 << 20;

/// How long the server has to open the level stream, and then between two
/// reads of it.
pub const LEVEL_STREAM_TIMEOUT: Duration = Duration::from_secs(10);

/// Where downloaded levels are kept: `HASH.bundle` files (and `HASH.part`
/// while downloading).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LevelCache {
    dir: PathBuf,
}

impl LevelCache {
    /// A cache in `dir` (created when first written).
    pub fn new(dir: impl Into<PathBuf>) -> LevelCache {
        LevelCache { dir: dir.into() }
    }

    /// The default folder: `$XDG_CACHE_HOME/ledge/levels`, else
    /// `$HOME/.cache/ledge/levels` (`%LOCALAPPDATA%\ledge\levels` on
    /// Windows); `None` when none is known (then levels are kept in memory
    /// only).
    pub fn default_dir() -> Option<PathBuf> {
        let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
        let base = if cfg!(windows) {
            var("LOCALAPPDATA").map(PathBuf::from)
        } else {
            var("XDG_CACHE_HOME")
                .map(PathBuf::from)
                .or_else(|| var("HOME").map(|h| PathBuf::from(h).join(".cache")))
        };
        base.map(|b| b.join("ledge").join("levels"))
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The complete bundle's path.
    pub fn bundle_path(&self, offer: &LevelOffer) -> PathBuf {
        self.dir.join(format!("{}.bundle", offer.hex()))
    }

    /// The partial download's path.
    pub fn part_path(&self, offer: &LevelOffer) -> PathBuf {
        self.dir.join(format!("{}.part", offer.hex()))
    }

    /// The cached bundle's bytes if present, of the offered size and hash;
    /// a damaged one is deleted.
    pub fn get(&self, offer: &LevelOffer) -> Option<Vec<u8>> {
        let path = self.bundle_path(offer);
        let len = std::fs::metadata(&path).ok()?.len();
        if len == offer.size {
            if let Ok(bytes) = std::fs::read(&path) {
                if sha256(&bytes) == offer.sha256 {
                    return Some(bytes);
                }
            }
        }
        tracing::warn!("{} is damaged; downloading it again", path.display());
        let _ = std::fs::remove_file(&path);
        None
    }

    /// Keeps `bytes`, the bundle `offer` names (refused unless they are:
    /// size and SHA-256), as its complete file: written beside it, then
    /// renamed into place; the cache is then trimmed. Returns the file.
    pub fn store(&self, offer: &LevelOffer, bytes: &[u8]) -> Result<PathBuf, ClientError> {
        if bytes.len() as u64 != offer.size || sha256(bytes) != offer.sha256 {
            return Err(ClientError::LevelHashMismatch {
                expected: offer.hex(),
            });
        }
        let fail = |e: std::io::Error| {
            ClientError::LevelDownload(format!(
                "cannot write the level cache {}: {e} (choose another folder with --level-cache)",
                self.dir.display()
            ))
        };
        std::fs::create_dir_all(&self.dir).map_err(fail)?;
        // A name of this writer's own, not the shared part file.
        static WRITES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let n = WRITES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let part = (self.dir).join(format!("{}.{}-{n}.tmp", offer.hex(), std::process::id()));
        std::fs::write(&part, bytes).map_err(fail)?;
        let done = self.bundle_path(offer);
        std::fs::rename(&part, &done).map_err(fail)?;
        self.trim(&done);
        Ok(done)
    }

    /// Makes the part file of a download that checked out the cached
    /// bundle, if the file holds exactly that bundle: another client
    /// sharing the cache may have written into it meanwhile (every client
    /// of a room fetches a new level at the same moment), and then it is
    /// deleted instead (the level in memory is the checked one).
    fn keep_part(&self, offer: &LevelOffer) {
        let part = self.part_path(offer);
        let intact = std::fs::metadata(&part).is_ok_and(|m| m.len() == offer.size)
            && std::fs::read(&part).is_ok_and(|bytes| sha256(&bytes) == offer.sha256);
        let done = self.bundle_path(offer);
        if intact && std::fs::rename(&part, &done).is_ok() {
            self.trim(&done);
        } else {
            tracing::debug!(
                "{} was written by another client too; not cached",
                part.display()
            );
            let _ = std::fs::remove_file(&part);
        }
    }

    /// What a cut download left (at most the offered size; more is
    /// deleted).
    fn partial(&self, offer: &LevelOffer) -> Vec<u8> {
        let path = self.part_path(offer);
        match std::fs::metadata(&path) {
            Ok(m) if m.len() <= offer.size => std::fs::read(&path).unwrap_or_default(),
            Ok(_) => {
                let _ = std::fs::remove_file(&path);
                Vec::new()
            }
            Err(_) => Vec::new(),
        }
    }

    /// Deletes the oldest bundles (by modification time) until the cache
    /// holds at most [`CACHE_BYTES`]; `keep` is never deleted.
    fn trim(&self, keep: &Path) {
        let Ok(entries) = std::fs::read_dir(&self.dir) else {
            return;
        };
        let mut files: Vec<(std::time::SystemTime, u64, PathBuf)> = entries
            .filter_map(Result::ok)
            .filter(|e| e.path().extension().is_some_and(|x| x == "bundle"))
            .filter_map(|e| {
                let m = e.metadata().ok()?;
                Some((m.modified().ok()?, m.len(), e.path()))
            })
            .collect();
        let mut total: u64 = files.iter().map(|f| f.1).sum();
        files.sort();
        for (_, len, path) in files {
            if total <= CACHE_BYTES {
                break;
            }
            if path != keep && std::fs::remove_file(&path).is_ok() {
                total -= len;
            }
        }
    }
}

/// Options of [`fetch_level`].
#[derive(Debug, Clone, Default)]
pub struct FetchOptions {
    /// The cache; `None`: download into memory each time.
    pub cache: Option<LevelCache>,
    /// For tests of resuming: stop the download (as if cut) after this
    /// many bytes, keeping the part.
    pub cut_after: Option<u64>,
}

/// The level the session's server offers (the welcome's, or the latest
/// level change's: [`Session::welcome`]): the embedded default, the
/// cached copy, or downloaded (resuming a cut download; the request names
/// the bundle by its SHA-256, so a server rotating levels sends this one),
/// checked by hash and decoded with every bound checked.
/// `progress(got, total)` is called as bytes arrive. A download resumed
/// from a part file that does not check out (another client sharing the
/// cache wrote into it) is made once more from the start.
pub async fn fetch_level(
    session: &mut Session,
    options: &FetchOptions,
    mut progress: impl FnMut(u64, u64),
) -> Result<(LevelBundle, Fetched), ClientError> {
    let offer = session.welcome().level;
    let resumed = options
        .cache
        .as_ref()
        .is_some_and(|c| c.part_path(&offer).is_file());
    match fetch_once(session, options, &mut progress).await {
        Err(ClientError::LevelHashMismatch { .. }) if resumed => {
            tracing::info!("the partial level download did not check out; downloading it again");
            fetch_once(session, options, &mut progress).await
        }
        result => result,
    }
}

/// One try of [`fetch_level`].
async fn fetch_once(
    session: &mut Session,
    options: &FetchOptions,
    mut progress: impl FnMut(u64, u64),
) -> Result<(LevelBundle, Fetched), ClientError> {
    let offer = session.welcome().level;
    if offer == embedded().1 {
        let fetched = Fetched {
            embedded: true,
            ..Fetched::default()
        };
        return Ok((embedded().0.clone(), fetched));
    }
    let cache = options.cache.as_ref();
    if let Some(bytes) = cache.and_then(|c| c.get(&offer)) {
        let fetched = Fetched {
            cached: true,
            ..Fetched::default()
        };
        return Ok((decode(&bytes)?, fetched));
    }
    let mut download = Download::new(offer, cache.map(|c| c.partial(&offer)).unwrap_or_default())?;
    let resumed_from = download.resumed_from();
    let mut part = match cache {
        Some(c) => open_part(c, &offer, resumed_from)?,
        None => None,
    };
    let caching = part.is_some();
    if !download.is_complete() {
        session
            .send_control(&ClientControl::GetLevel {
                offset: resumed_from,
                sha256: offer.sha256,
            })
            .await?;
        let mut stream =
            tokio::time::timeout(LEVEL_STREAM_TIMEOUT, session.connection().accept_uni())
                .await
                .map_err(|_| {
                    ClientError::LevelDownload("the server did not send the level".into())
                })?
                .map_err(ClientError::from_connection_error)?;
        let mut buf = vec![0u8; 64 * 1024];
        progress(resumed_from, offer.size);
        loop {
            let (got, size) = download.progress();
            // One byte more than is left, to notice a server sending more.
            let mut want = (size - got + 1).min(buf.len() as u64);
            if let Some(cut) = options.cut_after {
                want = want.min((resumed_from + cut).saturating_sub(got).max(1));
            }
            let want = want as usize;
            let read = tokio::time::timeout(LEVEL_STREAM_TIMEOUT, stream.read(&mut buf[..want]))
                .await
                .map_err(|_| ClientError::LevelDownload("the level download stalled".into()))?
                .map_err(|e| ClientError::LevelDownload(e.to_string()))?;
            let Some(n) = read else { break };
            download.push(&buf[..n])?;
            if let Some(f) = &mut part {
                f.write_all(&buf[..n])
                    .map_err(|e| ClientError::LevelDownload(format!("writing the cache: {e}")))?;
            }
            let (got, size) = download.progress();
            progress(got, size);
            if options
                .cut_after
                .is_some_and(|cut| got - resumed_from >= cut)
            {
                return Err(ClientError::LevelDownload(
                    "cut short (a test's cut_after)".into(),
                ));
            }
        }
    }
    drop(part);
    let finished = download.finish();
    if let (Err(ClientError::LevelHashMismatch { .. }), Some(c)) = (&finished, cache) {
        let _ = std::fs::remove_file(c.part_path(&offer));
    }
    let (level, fetched) = finished?;
    if let (Some(c), true) = (cache, caching) {
        c.keep_part(&offer);
    }
    Ok((level, fetched))
}

/// Opens (creating the folder) the part file for appending at `len`;
/// `None` when another client sharing the cache is writing it (the
/// download then goes to memory only).
fn open_part(
    cache: &LevelCache,
    offer: &LevelOffer,
    len: u64,
) -> Result<Option<std::fs::File>, ClientError> {
    let fail = |e: std::io::Error| {
        ClientError::LevelDownload(format!(
            "cannot write the level cache {}: {e} (choose another folder with --level-cache)",
            cache.dir().display()
        ))
    };
    std::fs::create_dir_all(cache.dir()).map_err(fail)?;
    let file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(cache.part_path(offer))
        .map_err(fail)?;
    // Not what was read a moment ago: another client is downloading it.
    if file.metadata().map_err(fail)?.len() != len {
        tracing::debug!("another client is downloading this level into the cache too");
        return Ok(None);
    }
    Ok(Some(file))
}
