//! Random and mutated level files into both importers: a clean `Ok` or
//! `Err`, never a panic (a hook counts them, caught or not), and a bounded
//! peak of heap memory (a counting global allocator). Seeds: the Tiled
//! fixtures, the default OGMO level and project, and the OGMO files of
//! `shared/testdata/levels` when that folder is there.

use std::path::Path;

use ledge_levels::{ogmo, tmx, LoadOptions};
use proptest::prelude::*;

use crate::peak;

use peak::{measured, serial};

const TILED: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/levels/tiled");
const DEFAULT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/default");
const SHARED: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/testdata/levels");

/// `(path, text)` of every file with one of `exts` under `dir` (recursive).
fn files(dir: &str, exts: &[&str]) -> Vec<(String, String)> {
    fn walk(d: &Path, exts: &[&str], out: &mut Vec<(String, String)>) {
        let Ok(rd) = std::fs::read_dir(d) else {
            return;
        };
        let mut paths: Vec<_> = rd.filter_map(|e| e.ok().map(|e| e.path())).collect();
        paths.sort();
        for p in paths {
            if p.is_dir() {
                walk(&p, exts, out);
            } else if p
                .extension()
                .is_some_and(|e| exts.iter().any(|x| e.eq_ignore_ascii_case(x)))
            {
                if let Ok(t) = std::fs::read_to_string(&p) {
                    out.push((p.display().to_string(), t));
                }
            }
        }
    }
    let mut out = Vec::new();
    walk(Path::new(dir), exts, &mut out);
    out
}

fn tmx_seeds() -> &'static [(String, String)] {
    static S: std::sync::OnceLock<Vec<(String, String)>> = std::sync::OnceLock::new();
    S.get_or_init(|| {
        let s = files(TILED, &["tmx"]);
        assert!(!s.is_empty(), "no Tiled fixtures in {TILED}");
        s
    })
}

fn ogmo_seeds() -> &'static [(String, String)] {
    static S: std::sync::OnceLock<Vec<(String, String)>> = std::sync::OnceLock::new();
    S.get_or_init(|| {
        let mut s = files(DEFAULT, &["json", "ogmo"]);
        s.extend(files(SHARED, &["json", "ogmo"]));
        assert!(!s.is_empty(), "no OGMO files in {DEFAULT}");
        s
    })
}

/// Fragments that push the importers towards their bounds and edge cases.
const TMX_TOKENS: &[&str] = &[
    "<group>",
    "</group>",
    r#" tilecount="1000000000""#,
    r#" width="4096""#,
    r#" height="0""#,
    r#" infinite="1""#,
    r#"<chunk x="2147483647" y="0" width="16" height="16">0</chunk>"#,
    r#"<data encoding="base64" compression="zlib">eJzt0DEBAAAAwqD1T20ND6IAAAAAAAAAAAAAAAD4GxwAAAE=</data>"#,
    r#"<data encoding="base64" compression="zstd">AAAA</data>"#,
    r#"<data encoding="csv">1,2</data>"#,
    r#"<polygon points="0,0 1e30,5 -1e30,NaN"/>"#,
    r#"<object template="x.tx"/>"#,
    r#"<image source="x.png" width="-5" height="99999999"/>"#,
    r#" margin="99999" spacing="4294967295""#,
    "<![CDATA[",
    "]]>",
    "&amp;",
    "&#0;",
    "<tile id=\"4294967295\"/>",
    r#"<property name="p" type="class"><properties>"#,
];

const JSON_TOKENS: &[&str] = &[
    "[[[[[[[[",
    "]]]]",
    "{\"a\":",
    "1e400",
    "-0",
    "4294967296",
    "\"\\u0000\"",
    "null",
    "\"data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAAB\"",
    "99999999",
];

/// One edit: at a position (fraction of the length), flip a byte, delete a
/// run, duplicate a run or insert a token.
fn mutate(text: &str, edits: &[(u32, u8, u8)], tokens: &[&str]) -> String {
    let mut b = text.as_bytes().to_vec();
    for &(at, kind, arg) in edits {
        let len = b.len();
        let i = if len == 0 { 0 } else { (at as usize) % len };
        match kind % 5 {
            0 if len > 0 => b[i] ^= arg | 1,
            1 => {
                let end = (i + arg as usize % 64).min(len);
                b.drain(i..end);
            }
            2 => {
                let end = (i + arg as usize % 256).min(len);
                let run = b[i..end].to_vec();
                for _ in 0..(arg % 4 + 1) {
                    b.splice(i..i, run.iter().copied());
                }
            }
            3 => b.truncate(i),
            _ => {
                let t = tokens[arg as usize % tokens.len()];
                b.splice(i..i, t.bytes());
            }
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

/// Runs `f` under [`peak::measured`] (no panic, bounded peak heap),
/// naming the seed when it fails.
fn guarded(what: &str, f: impl FnOnce()) {
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| measured(f)));
    if let Err(e) = r {
        panic!("{what}: {e:?}");
    }
}

fn opts() -> LoadOptions {
    LoadOptions {
        require_spawn: false,
        skip_unknown_entities: true,
        ..LoadOptions::default()
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 48,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn tmx_mutations_never_panic(
        seed in any::<prop::sample::Index>(),
        edits in prop::collection::vec((any::<u32>(), any::<u8>(), any::<u8>()), 1..10),
    ) {
        let _s = serial();
        let seeds = tmx_seeds();
        let (path, text) = &seeds[seed.index(seeds.len())];
        let m = mutate(text, &edits, TMX_TOKENS);
        guarded(path, || {
            let _ = tmx::load_str(path, &m, &opts());
        });
    }

    #[test]
    fn ogmo_mutations_never_panic(
        seed in any::<prop::sample::Index>(),
        edits in prop::collection::vec((any::<u32>(), any::<u8>(), any::<u8>()), 1..10),
    ) {
        let _s = serial();
        let seeds = ogmo_seeds();
        let (path, text) = &seeds[seed.index(seeds.len())];
        let m = mutate(text, &edits, JSON_TOKENS);
        guarded(path, || {
            let _ = ogmo::load_str(path, &m, None, &opts());
            let _ = ogmo::parse_project(path, &m);
        });
    }

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        let _s = serial();
        let text = String::from_utf8_lossy(&bytes);
        let xml = format!("<?xml version=\"1.0\"?><map {text}");
        guarded("random", || {
            let _ = tmx::load_str("fuzz.tmx", &text, &opts());
            let _ = tmx::load_str("fuzz.tmx", &xml, &opts());
            let _ = ogmo::load_str("fuzz.json", &text, None, &opts());
        });
    }
}
