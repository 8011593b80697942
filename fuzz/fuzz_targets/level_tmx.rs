//! Tiled maps from any bytes: the importer returns `Ok` or a clean `Err`,
//! never panics, and stays within the bounds of `ledge_levels::limits`
//! (libFuzzer's `-rss_limit_mb` catches an allocation past them).
#![no_main]

use ledge_levels::{tmx, LoadOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let options = LoadOptions {
        require_spawn: false,
        ..LoadOptions::default()
    };
    if let Err(e) = tmx::load_str("fuzz.tmx", &text, &options) {
        // Every refusal names a file (the map, or a tileset it refers to).
        assert!(!e.file().is_empty());
    }
});
