//! OGMO Editor 3 levels and projects from any bytes: `Ok` or a clean `Err`,
//! never a panic, within the bounds of `ledge_levels::limits`.
#![no_main]

use ledge_levels::{ogmo, LoadOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let options = LoadOptions {
        require_spawn: false,
        ..LoadOptions::default()
    };
    if let Err(e) = ogmo::load_str("fuzz.json", &text, None, &options) {
        assert_eq!(e.file(), "fuzz.json");
    }
    let _ = ogmo::parse_project("fuzz.ogmo", &text);
});
