//! A level as a server sends it to its clients: the level model and the
//! art it is drawn with ([`LevelBundle`]), bincode-encoded and named by the
//! SHA-256 of those bytes.
//!
//! The bundle carries what the loaders made of the editor's files, not the
//! files: a client never parses a server's Tiled XML or OGMO JSON (nor
//! needs the settings file that shaped it), only this bounded encoding,
//! checked on decoding like any input from the network
//! ([`LevelBundle::decode`]).

use ledge_shared::level::Level;
use ledge_shared::protocol::{LevelOffer, MAX_LEVEL_BUNDLE};
use serde::{Deserialize, Serialize};

use crate::art::LevelArt;

/// Why bundle bytes are not a playable level.
#[derive(Debug, thiserror::Error)]
pub enum BundleError {
    /// More bytes than any bundle may have.
    #[error("the level bundle is {size} bytes, more than the limit of {max}")]
    TooLarge {
        /// Its size.
        size: u64,
        /// [`MAX_LEVEL_BUNDLE`].
        max: u64,
    },
    /// The bytes do not decode as a bundle.
    #[error("the level bundle does not decode: {0}")]
    Decode(String),
    /// It decodes, but breaks a bound (art indices, image sizes).
    #[error("the level bundle's art is invalid: {0}")]
    Art(String),
}

/// The level and its art: what a client needs to play and draw a server's
/// level.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LevelBundle {
    /// The level.
    pub level: Level,
    /// What to draw (empty for ledge's own flat colours).
    pub art: LevelArt,
}

fn config() -> impl bincode::config::Config {
    bincode::config::standard().with_limit::<{ MAX_LEVEL_BUNDLE as usize }>()
}

impl LevelBundle {
    /// The embedded default level, with no art: what a server without
    /// `--level` offers (so a client finds it without a download).
    pub fn default_level() -> LevelBundle {
        LevelBundle {
            level: crate::default_level(),
            art: LevelArt::default(),
        }
    }

    /// Encodes the bundle (what [`LevelOffer::sha256`] hashes).
    pub fn encode(&self) -> Vec<u8> {
        bincode::serde::encode_to_vec(self, bincode::config::standard())
            .expect("a bundle always encodes")
    }

    /// Decodes and checks bytes from elsewhere: at most
    /// [`MAX_LEVEL_BUNDLE`] bytes, every length bounded by them before it is
    /// allocated, no trailing bytes, the tilemap and art checked.
    pub fn decode(bytes: &[u8]) -> Result<LevelBundle, BundleError> {
        if bytes.len() as u64 > MAX_LEVEL_BUNDLE {
            return Err(BundleError::TooLarge {
                size: bytes.len() as u64,
                max: MAX_LEVEL_BUNDLE,
            });
        }
        let (bundle, used): (LevelBundle, usize) =
            bincode::serde::decode_from_slice(bytes, config())
                .map_err(|e| BundleError::Decode(e.to_string()))?;
        if used != bytes.len() {
            return Err(BundleError::Decode(format!(
                "{} bytes after the end",
                bytes.len() - used
            )));
        }
        bundle.art.check().map_err(BundleError::Art)?;
        Ok(bundle)
    }

    /// The offer naming `bytes` (this bundle's encoding).
    pub fn offer(bytes: &[u8]) -> LevelOffer {
        LevelOffer {
            sha256: sha256(bytes),
            size: bytes.len() as u64,
        }
    }
}

/// SHA-256 of `bytes` (ring natively, already built for rustls; the
/// pure-Rust sha2 for wasm32, where ring would need a C compiler).
pub fn sha256(bytes: &[u8]) -> [u8; 32] {
    #[cfg(not(target_arch = "wasm32"))]
    {
        let digest = ring::digest::digest(&ring::digest::SHA256, bytes);
        let mut out = [0u8; 32];
        out.copy_from_slice(digest.as_ref());
        out
    }
    #[cfg(target_arch = "wasm32")]
    {
        use sha2::Digest;
        sha2::Sha256::digest(bytes).into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_is_sha_256() {
        // FIPS 180-2's "abc" vector.
        let expected = "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad";
        let got: String = sha256(b"abc").iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(got, expected);
    }

    #[test]
    fn bundles_round_trip_and_refuse_trailing_bytes_and_bad_art() {
        let bundle = LevelBundle::default_level();
        let bytes = bundle.encode();
        assert_eq!(LevelBundle::decode(&bytes).unwrap(), bundle);
        let offer = LevelBundle::offer(&bytes);
        assert_eq!(offer.size, bytes.len() as u64);
        assert_eq!(offer.sha256, sha256(&bytes));
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(matches!(
            LevelBundle::decode(&longer),
            Err(BundleError::Decode(_))
        ));
        assert!(LevelBundle::decode(&bytes[..bytes.len() / 2]).is_err());
        // A layer drawing from a tileset the bundle lacks.
        let mut bad = bundle.clone();
        bad.art.layers.push(crate::art::ArtLayer {
            name: "l".into(),
            offset: (0.0, 0.0),
            parallax: (1.0, 1.0),
            opacity: 1.0,
            content: crate::art::ArtContent::Image {
                image: 3,
                repeat_x: false,
                repeat_y: false,
            },
        });
        let err = LevelBundle::decode(&bad.encode()).unwrap_err().to_string();
        assert!(err.contains("not in the bundle"), "{err}");
    }
}
