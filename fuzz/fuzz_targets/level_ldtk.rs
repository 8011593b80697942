//! LDtk projects from any bytes: the importer returns `Ok` or a clean
//! `Err`, never panics, and stays within the bounds of
//! `ledge_levels::limits` (libFuzzer's `-rss_limit_mb` catches an
//! allocation past them). The first level is loaded, and the one named by
//! the input's first line when it is short (so a level picked by name is
//! reached too).
#![no_main]

use ledge_levels::{ldtk, LoadOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let options = LoadOptions {
        require_spawn: false,
        ..LoadOptions::default()
    };
    let named = text.lines().next().filter(|l| l.len() <= 32);
    for level in [None, named] {
        if let Err(e) = ldtk::load_str("fuzz.ldtk", &text, level, &options) {
            // Every refusal names a file (the project, or a level file).
            assert!(!e.file().is_empty());
        }
    }
});
