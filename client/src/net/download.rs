//! The server's level, received as a stream of bytes and checked, sans IO:
//! [`Download`] takes the chunks of the level stream (from a QUIC stream
//! natively, from WebTransport or WebSocket messages in a browser), never
//! holds more than the server offered (itself at most
//! [`MAX_LEVEL_BUNDLE`]), and gives the decoded level only when its
//! SHA-256 is the one the server announced. A server playing the embedded
//! default level sends nothing ([`embedded`]).

use std::sync::OnceLock;

use ledge_levels::bundle::sha256;
use ledge_levels::LevelBundle;
use ledge_shared::protocol::{LevelOffer, Welcome, MAX_LEVEL_BUNDLE};

use crate::error::ClientError;

/// How the level was had.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Fetched {
    /// Bytes downloaded now (0: from the cache or embedded).
    pub downloaded: u64,
    /// Where the download started (non-zero: a cut one was resumed).
    pub resumed_from: u64,
    /// Found in the cache.
    pub cached: bool,
    /// The embedded default level.
    pub embedded: bool,
}

impl Fetched {
    /// In words, for logs: where the level of `size` bytes came from.
    pub fn describe(&self, size: u64) -> String {
        if self.embedded {
            "the server plays the embedded default level".to_owned()
        } else if self.cached {
            format!("the server's level ({size} bytes) was in the level cache")
        } else if self.resumed_from > 0 {
            format!(
                "downloaded the rest of the server's level: {} of {size} bytes (resumed)",
                self.downloaded
            )
        } else {
            format!("downloaded the server's level: {size} bytes")
        }
    }
}

/// The embedded default level's bundle and offer (built once).
pub fn embedded() -> &'static (LevelBundle, LevelOffer) {
    static EMBEDDED: OnceLock<(LevelBundle, LevelOffer)> = OnceLock::new();
    EMBEDDED.get_or_init(|| {
        let bundle = LevelBundle::default_level();
        let offer = LevelBundle::offer(&bundle.encode());
        (bundle, offer)
    })
}

/// A level download in progress: the bytes so far of the offered bundle.
#[derive(Debug)]
pub struct Download {
    offer: LevelOffer,
    bytes: Vec<u8>,
    resumed_from: u64,
}

impl Download {
    /// Starts downloading `offer` from `have` (bytes kept from a cut
    /// download: the request asks for the rest). Refuses an offer bigger
    /// than any client downloads, before allocating.
    pub fn new(offer: LevelOffer, have: Vec<u8>) -> Result<Download, ClientError> {
        if offer.size > MAX_LEVEL_BUNDLE {
            return Err(ClientError::LevelTooLarge {
                size: offer.size,
                max: MAX_LEVEL_BUNDLE,
            });
        }
        let mut have = have;
        if have.len() as u64 > offer.size {
            have.clear();
        }
        Ok(Download {
            offer,
            resumed_from: have.len() as u64,
            bytes: have,
        })
    }

    /// The offer being downloaded.
    pub fn offer(&self) -> &LevelOffer {
        &self.offer
    }

    /// Where the download starts (the `GetLevel` offset).
    pub fn resumed_from(&self) -> u64 {
        self.resumed_from
    }

    /// Bytes so far, and the bundle's size.
    pub fn progress(&self) -> (u64, u64) {
        (self.bytes.len() as u64, self.offer.size)
    }

    /// Whether every offered byte arrived.
    pub fn is_complete(&self) -> bool {
        self.bytes.len() as u64 == self.offer.size
    }

    /// The bytes so far (for a cache's part file).
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// Adds the next chunk of the level stream; more than offered is an
    /// error (nothing beyond the offer is kept).
    pub fn push(&mut self, chunk: &[u8]) -> Result<(), ClientError> {
        if self.bytes.len() as u64 + chunk.len() as u64 > self.offer.size {
            return Err(ClientError::LevelDownload(format!(
                "the server sent more than the {} bytes it offered",
                self.offer.size
            )));
        }
        self.bytes.extend_from_slice(chunk);
        Ok(())
    }

    /// The stream ended: the level, if every byte arrived, its hash is the
    /// announced one and it decodes (every bound checked).
    pub fn finish(self) -> Result<(LevelBundle, Fetched), ClientError> {
        if !self.is_complete() {
            return Err(ClientError::LevelDownload(format!(
                "the level stream ended after {} of {} bytes",
                self.bytes.len(),
                self.offer.size
            )));
        }
        if sha256(&self.bytes) != self.offer.sha256 {
            return Err(ClientError::LevelHashMismatch {
                expected: self.offer.hex(),
            });
        }
        let level = decode(&self.bytes)?;
        let fetched = Fetched {
            downloaded: self.offer.size - self.resumed_from,
            resumed_from: self.resumed_from,
            ..Fetched::default()
        };
        Ok((level, fetched))
    }
}

/// Why the room's next level, that of the level change's `welcome`,
/// cannot be played: the level's id and what failed, `e` (the session
/// ends with it).
pub fn level_change_failed(welcome: &Welcome, e: &ClientError) -> String {
    format!(
        "the room moved to level {:?}, and getting it failed: {e}",
        welcome.level_id
    )
}

/// Decodes a bundle (every bound checked by `ledge-levels`).
pub fn decode(bytes: &[u8]) -> Result<LevelBundle, ClientError> {
    LevelBundle::decode(bytes).map_err(|e| ClientError::Level(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn offer_of(bytes: &[u8]) -> LevelOffer {
        LevelBundle::offer(bytes)
    }

    #[test]
    fn a_level_arrives_in_chunks_and_is_checked() {
        let bytes = LevelBundle::default_level().encode();
        let mut d = Download::new(offer_of(&bytes), Vec::new()).unwrap();
        for chunk in bytes.chunks(1000) {
            assert!(!d.is_complete());
            d.push(chunk).unwrap();
        }
        let (bundle, fetched) = d.finish().unwrap();
        assert_eq!(bundle.level.name, LevelBundle::default_level().level.name);
        assert_eq!(fetched.downloaded, bytes.len() as u64);
    }

    #[test]
    fn a_resumed_download_counts_only_the_rest() {
        let bytes = LevelBundle::default_level().encode();
        let mut d = Download::new(offer_of(&bytes), bytes[..100].to_vec()).unwrap();
        assert_eq!(d.resumed_from(), 100);
        d.push(&bytes[100..]).unwrap();
        let (_, fetched) = d.finish().unwrap();
        assert_eq!(fetched.resumed_from, 100);
        assert_eq!(fetched.downloaded, bytes.len() as u64 - 100);
    }

    #[test]
    fn too_much_too_little_or_wrong_bytes_are_refused() {
        let bytes = LevelBundle::default_level().encode();
        let offer = offer_of(&bytes);
        let mut d = Download::new(offer, Vec::new()).unwrap();
        d.push(&bytes).unwrap();
        assert!(matches!(d.push(&[0]), Err(ClientError::LevelDownload(_))));

        let mut short = Download::new(offer, Vec::new()).unwrap();
        short.push(&bytes[..10]).unwrap();
        assert!(matches!(short.finish(), Err(ClientError::LevelDownload(_))));

        let mut wrong = bytes.clone();
        wrong[5] ^= 1;
        let mut d = Download::new(offer, Vec::new()).unwrap();
        d.push(&wrong).unwrap();
        assert!(matches!(
            d.finish(),
            Err(ClientError::LevelHashMismatch { .. })
        ));

        let huge = LevelOffer {
            size: MAX_LEVEL_BUNDLE + 1,
            ..offer
        };
        assert!(matches!(
            Download::new(huge, Vec::new()),
            Err(ClientError::LevelTooLarge { .. })
        ));
    }
}
