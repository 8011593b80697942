//! How the pre-scan ([`super`]) rewrites a Tiled document before the
//! `tiled` crate reads it: byte ranges of the document replaced
//! ([`Patch`]), for attributes old files lack (a tileset's `tilecount`
//! and `columns`, an image's `width` and `height`) and for tile data that
//! crate cannot read as built here (zstd-compressed base64, one
//! `<tile gid=".."/>` element per cell), re-encoded as CSV.
//!
//! Kept apart from the limits so that the checks read as checks, and the
//! rewriting, with its one rule for applying the patches, in one place.

use std::fmt::Write as _;

/// Replaces `bytes[start..end]` with `text` in what the Tiled reader sees
/// (an empty range inserts).
pub struct Patch {
    start: usize,
    end: usize,
    text: String,
}

impl Patch {
    /// Adds `width` and `height` to an `<image>`'s start tag, at `at`.
    pub fn image_size(at: usize, width: u32, height: u32) -> Patch {
        Patch {
            start: at,
            end: at,
            text: format!(" width=\"{width}\" height=\"{height}\""),
        }
    }

    /// Adds `tilecount` (and `columns`, when given) to a tileset's start
    /// tag, at `at`.
    pub fn tileset_count(at: usize, count: u64, columns: Option<u64>) -> Patch {
        let mut text = format!(" tilecount=\"{count}\"");
        if let Some(columns) = columns {
            text.push_str(&format!(" columns=\"{columns}\""));
        }
        Patch {
            start: at,
            end: at,
            text,
        }
    }

    /// Replaces a `<data>` start tag (`start..end`; `empty`: `<data/>`)
    /// with one saying its content is CSV.
    pub fn csv_data_tag(start: usize, end: usize, empty: bool) -> Patch {
        let close = if empty { "/>" } else { ">" };
        Patch {
            start,
            end,
            text: format!("<data encoding=\"csv\"{close}"),
        }
    }

    /// Replaces the tile data at `start..end` with `gids` as CSV.
    pub fn csv_data(start: usize, end: usize, gids: &[u32]) -> Patch {
        Patch {
            start,
            end,
            text: csv_text(gids),
        }
    }
}

/// Whether tile data of this encoding and compression is handed to the
/// `tiled` crate (built without zstd, and not reading `<tile>` children)
/// rewritten as CSV.
pub fn is_rewritten(encoding: Option<&str>, compression: Option<&str>) -> bool {
    encoding.is_none() || (encoding == Some("base64") && compression == Some("zstd"))
}

/// The document `bytes` with `patches` applied (`bytes` itself when there
/// are none).
pub fn apply(bytes: Vec<u8>, mut patches: Vec<Patch>) -> Vec<u8> {
    if patches.is_empty() {
        return bytes;
    }
    // Ranges never overlap (each is a start tag, an insertion point in one,
    // or the content of one element); a stable sort keeps insertions at the
    // same point in document order.
    patches.sort_by_key(|p| p.start);
    let extra: usize = patches.iter().map(|p| p.text.len()).sum();
    let mut out = Vec::with_capacity(bytes.len() + extra);
    let mut at = 0;
    for p in patches {
        let start = p.start.max(at);
        out.extend_from_slice(&bytes[at..start]);
        out.extend_from_slice(p.text.as_bytes());
        at = p.end.max(start);
    }
    out.extend_from_slice(&bytes[at..]);
    out
}

/// The gids as the `tiled` crate reads CSV tile data.
fn csv_text(gids: &[u32]) -> String {
    let mut s = String::with_capacity(gids.len() * 4);
    for (i, g) in gids.iter().enumerate() {
        if i > 0 {
            s.push(',');
        }
        let _ = write!(s, "{g}");
    }
    s
}
