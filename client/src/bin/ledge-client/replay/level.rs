//! The level a replay was played on, which its header names by the
//! bundle's SHA-256 and size ([`LevelOffer`]), looked for in turn:
//!
//! 1. the embedded default level;
//! 2. the level cache (`--level-cache`, by default the client's);
//! 3. `--level FILE` (with `--level-settings`), if its bundle is the one;
//! 4. for a replay from a server, that server's `/levels/HEX`: at most the
//!    offered size (itself at most [`MAX_LEVEL_BUNDLE`]), its SHA-256
//!    checked, then kept in the cache.
//!
//! Nowhere: an error naming the level and its hash, and what to do.

use std::path::Path;

use anyhow::{bail, Context};
use ledge_client::net::bundle::LevelCache;
use ledge_client::net::download::{embedded, Download};
use ledge_levels::bundle::sha256;
use ledge_levels::LevelBundle;
use ledge_shared::protocol::{LevelOffer, MAX_LEVEL_BUNDLE};
use ledge_shared::replay::ReplayHeader;

use crate::replay::http;
use crate::replay::source::ReplayUrl;

/// Where to look for a replay's level.
pub struct LevelSearch<'a> {
    /// `--level FILE`.
    pub file: Option<&'a Path>,
    /// `--level-settings FILE`.
    pub settings: Option<&'a Path>,
    /// The level cache, if there is one.
    pub cache: Option<LevelCache>,
    /// The server the replay came from, if it did.
    pub server: Option<&'a ReplayUrl>,
}

/// A replay's level, and where it was found (for the log).
pub struct FoundLevel {
    /// The level and its art.
    pub bundle: LevelBundle,
    /// Where it came from, in words.
    pub from: String,
}

/// The level `header` names (see the module documentation).
pub fn find(header: &ReplayHeader, search: &LevelSearch) -> anyhow::Result<FoundLevel> {
    let offer = &header.level;
    if *offer == embedded().1 {
        return Ok(FoundLevel {
            bundle: embedded().0.clone(),
            from: "the embedded default level".to_owned(),
        });
    }
    if let Some(cache) = &search.cache {
        if let Some(bytes) = cache.get(offer) {
            let bundle = LevelBundle::decode(&bytes).with_context(|| {
                format!(
                    "the cached level {} does not decode: delete it and try again",
                    cache.bundle_path(offer).display()
                )
            })?;
            return Ok(FoundLevel {
                bundle,
                from: format!("the level cache ({})", cache.bundle_path(offer).display()),
            });
        }
    }
    let mut mismatch = String::new();
    if let Some(file) = search.file {
        match from_file(file, search.settings, offer)? {
            Ok(bundle) => {
                return Ok(FoundLevel {
                    bundle,
                    from: file.display().to_string(),
                })
            }
            Err(note) => mismatch = note,
        }
    }
    if let Some(server) = search.server {
        let bundle = download(server, offer, search.cache.as_ref())?;
        return Ok(FoundLevel {
            bundle,
            from: server.level_url(offer),
        });
    }
    let cache = search.cache.as_ref().map_or_else(
        || "no level cache".to_owned(),
        |c| format!("not in the level cache {}", c.dir().display()),
    );
    bail!(
        "the replay's level \"{}\" (level {}, bundle sha256 {}, {} bytes) is not the embedded \
         default level and {cache}{mismatch}: pass its file with --level FILE (and \
         --level-settings FILE if it has one), or play the replay from its server's URL \
         (http://HOST:PORT/replays/ID), which downloads the level",
        header.level_name,
        header.level_id,
        offer.hex(),
        offer.size
    )
}

/// `file` loaded as a server loads it, as a bundle: the one `offer` names,
/// or why not (`Err` inside: the note for the final message).
fn from_file(
    file: &Path,
    settings: Option<&Path>,
    offer: &LevelOffer,
) -> anyhow::Result<Result<LevelBundle, String>> {
    let loaded = ledge_levels::load_level(file, settings)
        .map_err(|e| anyhow::anyhow!("loading the level {}: {e}", file.display()))?;
    let bundle = LevelBundle {
        level: loaded.level,
        art: loaded.art,
    };
    let bytes = bundle.encode();
    if sha256(&bytes) == offer.sha256 {
        return Ok(Ok(bundle));
    }
    Ok(Err(format!(
        "; {} is another level (its bundle hashes to {}, the replay's to {}: another file, \
         another version of it, or other settings)",
        file.display(),
        LevelBundle::offer(&bytes).hex(),
        offer.hex()
    )))
}

/// The level from the replay's server, checked, kept in `cache`.
fn download(
    server: &ReplayUrl,
    offer: &LevelOffer,
    cache: Option<&LevelCache>,
) -> anyhow::Result<LevelBundle> {
    let url = server.level_url(offer);
    if offer.size > MAX_LEVEL_BUNDLE {
        bail!(
            "the replay's level is {} bytes, more than any level ledge downloads \
             ({MAX_LEVEL_BUNDLE} bytes): it cannot be played",
            offer.size
        );
    }
    let bytes = http::get(
        &url,
        offer.size,
        "level",
        "the server no longer plays the replay's level: pass its file with --level FILE",
    )?;
    let refused = |e: ledge_client::ClientError| {
        anyhow::anyhow!("{url}: {e}: try again, or pass the level's file with --level FILE")
    };
    let mut download = Download::new(*offer, Vec::new()).map_err(refused)?;
    download.push(&bytes).map_err(refused)?;
    let (bundle, _) = download.finish().map_err(refused)?;
    if let Some(cache) = cache {
        if let Err(e) = cache.store(offer, &bytes) {
            tracing::warn!("the downloaded level is not kept: {e}");
        }
    }
    Ok(bundle)
}
