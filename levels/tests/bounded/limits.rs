//! The bounds of `ledge_levels::limits`: for each one, a generated file that
//! goes past it gets a clean `Err` naming the file, the element and the
//! bound, with no panic (a panic hook records any) and a bounded peak of
//! heap memory (a counting global allocator); the real Tiled examples that
//! lack `tilecount` now get past the Tiled reader.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Instant;

use ledge_levels::limits::*;
use ledge_levels::{ogmo, tmx, LevelError, LoadOptions};

use crate::peak;

use peak::{measured, serial, CURRENT, PEAK};

fn opts() -> LoadOptions {
    LoadOptions {
        require_spawn: false,
        ..LoadOptions::default()
    }
}

fn load_tmx(file: &str, text: &str) -> Result<ledge_levels::LoadedLevel, LevelError> {
    measured(|| tmx::load_str(file, text, &opts())).0
}

/// A map of `w` x `h` 16 px tiles with one embedded tileset, and `body`.
fn map(w: u32, h: u32, body: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<map version="1.10" orientation="orthogonal" renderorder="right-down" width="{w}" height="{h}" tilewidth="16" tileheight="16" infinite="0">
 <tileset firstgid="1" name="ledge" tilewidth="16" tileheight="16" tilecount="4" columns="2"/>
{body}
</map>
"#
    )
}

fn csv(n: u64) -> String {
    vec!["0"; n as usize].join(",")
}

fn zlib(bytes: &[u8]) -> String {
    use base64::Engine;
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
    z.write_all(bytes).unwrap();
    base64::engine::general_purpose::STANDARD.encode(z.finish().unwrap())
}

/// Base64 of zlib-compressed `n` zero bytes, made a MiB at a time.
fn zlib_zeros(n: usize) -> String {
    use base64::Engine;
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
    let mib = vec![0u8; 1 << 20];
    for _ in 0..n >> 20 {
        z.write_all(&mib).unwrap();
    }
    base64::engine::general_purpose::STANDARD.encode(z.finish().unwrap())
}

fn gzip(bytes: &[u8]) -> String {
    use base64::Engine;
    let mut z = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    z.write_all(bytes).unwrap();
    base64::engine::general_purpose::STANDARD.encode(z.finish().unwrap())
}

/// Checks a refusal by a bound: the file, the field (a prefix) and the bound
/// are named, in the value and in the message.
#[track_caller]
fn expect_limit<T: std::fmt::Debug>(
    r: Result<T, LevelError>,
    file: &str,
    field: &str,
    bound: &str,
    limit: u64,
) -> String {
    let e = r.expect_err("the file must be refused");
    let msg = e.to_string();
    match &e {
        LevelError::Limit {
            file: f,
            field: fl,
            bound: b,
            limit: l,
            found,
            ..
        } => {
            assert_eq!(f, file, "{msg}");
            assert!(
                fl.starts_with(field),
                "field {fl:?} is not {field:?}: {msg}"
            );
            assert_eq!(*b, bound, "{msg}");
            assert_eq!(*l, limit, "{msg}");
            assert!(found > l, "{msg}");
        }
        other => panic!("expected a Limit error for {bound}, got {other:?}"),
    }
    assert!(msg.starts_with(&format!("{file}: {field}")), "{msg}");
    assert!(
        msg.contains(&limit.to_string()) && msg.contains(bound),
        "{msg}"
    );
    msg
}

#[test]
fn tilecount_beyond_the_bound_is_refused_before_allocating() {
    let _s = serial();
    // The brief's 400-byte map that aborted the process (431 GB allocation).
    let text = map(2, 2, "").replace(r#"tilecount="4""#, r#"tilecount="1000000000""#);
    assert!(text.len() < 500);
    let msg = expect_limit(
        load_tmx("maps/x.tmx", &text),
        "maps/x.tmx",
        "map.tileset[0].tilecount",
        "MAX_TILESET_TILES",
        MAX_TILESET_TILES,
    );
    assert!(
        msg.contains("1000000000 tiles is more than the limit of 65536"),
        "{msg}"
    );
}

#[test]
fn nesting_beyond_the_depth_bound_is_refused() {
    let _s = serial();
    let deep = format!("{}{}", "<group>".repeat(5000), "</group>".repeat(5000));
    expect_limit(
        load_tmx("deep.tmx", &map(2, 2, &deep)),
        "deep.tmx",
        "map.layers[0].layers[0]",
        "MAX_XML_DEPTH",
        MAX_XML_DEPTH as u64,
    );
    // Just under the bound, the Tiled reader's recursion fits in a test
    // thread's stack (2 MiB).
    let n = MAX_XML_DEPTH - 2;
    let ok = format!("{}{}", "<group>".repeat(n), "</group>".repeat(n));
    load_tmx("deep.tmx", &map(2, 2, &ok)).unwrap();
    let props = format!(
        "<properties>{}{}</properties>",
        r#"<property name="p" type="class"><properties>"#.repeat(20),
        "</properties></property>".repeat(20)
    );
    let r = load_tmx("deep.tmx", &map(2, 2, &props));
    assert!(!matches!(r, Err(LevelError::Limit { .. })), "{r:?}");
}

#[test]
fn compressed_bombs_stop_at_the_cell_bound_while_inflating() {
    let _s = serial();
    // ~1.4 MB of zlib that inflates to 1.4 GB (the brief's bomb): refused at
    // MAX_LEVEL_CELLS cells, inflating at most 16 MiB.
    for (enc, b64) in [
        ("zlib", zlib_zeros(1400 << 20)),
        ("gzip", gzip(&[0u8; 64 << 20])),
    ] {
        let body = format!(
            r#"<layer id="1" name="L" width="2" height="2"><data encoding="base64" compression="{enc}">{b64}</data></layer>"#
        );
        let text = map(2, 2, &body);
        let t = Instant::now();
        let (r, peak) = measured(|| tmx::load_str("bomb.tmx", &text, &opts()));
        let secs = t.elapsed().as_secs_f64();
        eprintln!(
            "{enc} bomb ({} bytes of TMX): refused in {secs:.2} s, peak heap {peak} bytes",
            text.len()
        );
        expect_limit(
            r,
            "bomb.tmx",
            "map.layers[0].data",
            "MAX_LEVEL_CELLS",
            MAX_LEVEL_CELLS,
        );
        assert!(peak < 64 << 20, "peak {peak}");
        assert!(secs < 10.0, "{secs} s");
    }
}

#[test]
fn data_must_have_exactly_width_times_height_cells() {
    let _s = serial();
    let four = [0u8; 16];
    for (what, data, got) in [
        (
            "short csv",
            r#"<data encoding="csv">1,1,1</data>"#.to_owned(),
            3,
        ),
        (
            "long csv",
            r#"<data encoding="csv">1,1,1,1,1</data>"#.to_owned(),
            5,
        ),
        ("empty", r#"<data encoding="csv"/>"#.to_owned(), 1),
        (
            "short zlib",
            format!(
                r#"<data encoding="base64" compression="zlib">{}</data>"#,
                zlib(&four[..12])
            ),
            3,
        ),
        (
            "long gzip",
            format!(
                r#"<data encoding="base64" compression="gzip">{}</data>"#,
                gzip(&[0u8; 24])
            ),
            6,
        ),
        (
            "empty base64",
            r#"<data encoding="base64"></data>"#.to_owned(),
            0,
        ),
    ] {
        let body = format!(r#"<layer id="1" name="L" width="2" height="2">{data}</layer>"#);
        let e = load_tmx("short.tmx", &map(2, 2, &body)).expect_err(what);
        assert_eq!(
            e,
            LevelError::Length {
                file: "short.tmx".into(),
                field: "map.layers[0].data".into(),
                expected: 4,
                got,
            },
            "{what}: {e}"
        );
        assert!(e
            .to_string()
            .contains(&format!("expected 4 entries, got {got}")));
    }
    // The right count loads (the catch_unwind probe in the importer is not
    // reached: the panic hook would have counted it).
    let body = format!(
        r#"<layer id="1" name="L" width="2" height="2"><data encoding="base64" compression="zlib">{}</data></layer>"#,
        zlib(&four)
    );
    load_tmx("ok.tmx", &map(2, 2, &body)).unwrap();
    // Infinite maps: each chunk's own size.
    let text = map(2, 2, r#"<layer id="1" name="L" width="2" height="2"><data encoding="csv"><chunk x="0" y="0" width="16" height="16">0,0</chunk></data></layer>"#)
        .replace(r#"infinite="0""#, r#"infinite="1""#);
    let e = load_tmx("inf.tmx", &text).unwrap_err();
    assert!(
        matches!(&e, LevelError::Length { field, expected: 256, got: 2, .. } if field == "map.layers[0].data.chunk[0]"),
        "{e:?}"
    );
}

/// Base64 of `bytes` compressed by the pure-Rust zstd encoder.
fn zstd(bytes: &[u8]) -> String {
    use base64::Engine;
    let z = ruzstd::encoding::compress_to_vec(bytes, ruzstd::encoding::CompressionLevel::Fastest);
    base64::engine::general_purpose::STANDARD.encode(z)
}

/// A zstd frame (no content size, a 128 KiB window) of `blocks` RLE blocks
/// of 128 KiB zero bytes each: 4 bytes of input per 128 KiB of output.
fn zstd_rle_zeros(blocks: usize) -> Vec<u8> {
    let mut f = vec![0x28, 0xb5, 0x2f, 0xfd, 0x00, 0x38];
    for i in 0..blocks {
        let last = (i + 1 == blocks) as u32;
        let header = (128 << 10) << 3 | 1 << 1 | last;
        f.extend_from_slice(&header.to_le_bytes()[..3]);
        f.push(0);
    }
    f
}

fn le_bytes(gids: &[u32]) -> Vec<u8> {
    gids.iter().flat_map(|g| g.to_le_bytes()).collect()
}

/// Tile data as CSV, zstd and XML (`<tile/>` for an empty cell).
fn csv_data(gids: &[u32]) -> String {
    let v: Vec<String> = gids.iter().map(u32::to_string).collect();
    v.join(",")
}

fn xml_tiles(gids: &[u32]) -> String {
    gids.iter()
        .map(|&g| match g {
            0 => "\n   <tile/>".to_owned(),
            g => format!("\n   <tile gid=\"{g}\"/>"),
        })
        .collect()
}

/// Every tile of layer `L` collides, a kind per tile id (so the level's
/// grid tells the gids apart).
fn kinds_opts() -> LoadOptions {
    use ledge_shared::tilemap::Tile;
    let mut o = opts();
    o.collision_layers = Some(vec!["L".into()]);
    for (id, t) in [
        (0, Tile::Solid),
        (1, Tile::OneWay),
        (2, Tile::Hazard),
        (3, Tile::Solid),
    ] {
        o.tile_kinds.insert(("ledge".into(), id), t);
    }
    o
}

/// A PNG of `w` x `h` grey pixels.
fn png(w: u32, h: u32) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    let mut wr = enc.write_header().unwrap();
    wr.write_image_data(&vec![128; (w * h) as usize]).unwrap();
    wr.finish().unwrap();
    out
}

/// `text` with the tileset of [`map`] drawn from `t.png` (2 x 2 tiles, in
/// `dir`), so that the level's art holds every cell.
fn with_atlas(dir: &Path, text: &str) -> String {
    std::fs::write(dir.join("t.png"), png(32, 32)).unwrap();
    text.replace(
        r#"tilecount="4" columns="2"/>"#,
        r#"tilecount="4" columns="2"><image source="t.png" width="32" height="32"/></tileset>"#,
    )
}

#[track_caller]
fn same_level(what: &str, got: &ledge_levels::LoadedLevel, want: &ledge_levels::LoadedLevel) {
    assert_eq!(got.art, want.art, "{what}: art");
    assert_eq!(
        format!("{:?}", got.level),
        format!("{:?}", want.level),
        "{what}: level"
    );
}

#[test]
fn zstd_and_xml_tile_data_load_like_csv() {
    let _s = serial();
    const H: u32 = 0x8000_0000;
    const V: u32 = 0x4000_0000;
    const D: u32 = 0x2000_0000;
    // A 4 x 3 layer: every tile, every flip bit, empty cells.
    let gids = [1, 2, 0, 3, 4 | H, 0, 2 | V, 1 | D, 3 | H | V | D, 0, 0, 4];
    let dir = temp_dir("encodings");
    let layer = |data: String| {
        with_atlas(
            &dir,
            &map(
                4,
                3,
                &format!(
                    "<layer id=\"1\" name=\"L\" width=\"4\" height=\"3\">\n  {data}\n </layer>"
                ),
            ),
        )
    };
    let o = kinds_opts();
    let load = |file: &str, text: &str| {
        let file = dir.join(file).display().to_string();
        measured(|| tmx::load_str(&file, text, &o)).0
    };
    let want = load(
        "map.tmx",
        &layer(format!(
            r#"<data encoding="csv">{}</data>"#,
            csv_data(&gids)
        )),
    )
    .unwrap();
    // The flips are in the art (so the comparison sees them).
    let ledge_levels::art::ArtContent::Tiles(grid) = &want.art.layers[0].content else {
        panic!("{:?}", want.art.layers)
    };
    let c = grid.get(0, 1).unwrap();
    assert!(
        (c.tile, c.flip_h, c.flip_v, c.flip_d) == (3, true, false, false),
        "{c:?}"
    );
    let c = grid.get(0, 2).unwrap();
    assert!(
        (c.tile, c.flip_h, c.flip_v, c.flip_d) == (2, true, true, true),
        "{c:?}"
    );
    for (what, data) in [
        (
            "zstd",
            format!(
                "<data encoding=\"base64\" compression=\"zstd\">\n   {}\n  </data>",
                zstd(&le_bytes(&gids))
            ),
        ),
        (
            "zstd in CDATA",
            format!(
                r#"<data encoding="base64" compression="zstd"><![CDATA[{}]]></data>"#,
                zstd(&le_bytes(&gids))
            ),
        ),
        (
            "zstd, two frames",
            format!(r#"<data encoding="base64" compression="zstd">{}</data>"#, {
                use base64::Engine;
                let c = |b: &[u8]| {
                    ruzstd::encoding::compress_to_vec(
                        b,
                        ruzstd::encoding::CompressionLevel::Uncompressed,
                    )
                };
                let bytes = le_bytes(&gids);
                let mut z = c(&bytes[..20]);
                z.extend(c(&bytes[20..]));
                base64::engine::general_purpose::STANDARD.encode(z)
            }),
        ),
        ("xml", format!("<data>{}\n  </data>", xml_tiles(&gids))),
    ] {
        let got = load("map.tmx", &layer(data)).unwrap_or_else(|e| panic!("{what}: {e}"));
        same_level(what, &got, &want);
    }

    // An infinite map: two 16 x 16 chunks (one left of the origin), each
    // zstd-compressed, or as <tile> elements.
    let chunk_gids = |k: u32| -> Vec<u32> {
        (0..256u32)
            .map(|i| match (i * 7 + k) % 6 {
                0 | 1 => 0,
                n => (n - 1) | [0, H, V, D][(i % 4) as usize],
            })
            .collect()
    };
    let infinite = |enc: &str, chunk: &dyn Fn(u32) -> String| {
        let chunks: String = [(-16, 0u32), (0, 1)]
            .iter()
            .map(|&(x, k)| {
                format!(
                    "\n   <chunk x=\"{x}\" y=\"0\" width=\"16\" height=\"16\">{}</chunk>",
                    chunk(k)
                )
            })
            .collect();
        map(
            4,
            3,
            &format!(
                "<layer id=\"1\" name=\"L\" width=\"32\" height=\"16\">\n  <data{enc}>{chunks}\n  </data>\n </layer>"
            ),
        )
        .replace(r#"infinite="0""#, r#"infinite="1""#)
    };
    let want = load(
        "map.tmx",
        &infinite(r#" encoding="csv""#, &|k| csv_data(&chunk_gids(k))),
    )
    .unwrap();
    assert!(format!("{:?}", want.level).contains("OneWay"));
    for (what, text) in [
        (
            "infinite zstd",
            infinite(r#" encoding="base64" compression="zstd""#, &|k| {
                zstd(&le_bytes(&chunk_gids(k)))
            }),
        ),
        (
            "infinite xml",
            infinite("", &|k| format!("{}\n   ", xml_tiles(&chunk_gids(k)))),
        ),
    ] {
        let got = load("map.tmx", &text).unwrap_or_else(|e| panic!("{what}: {e}"));
        same_level(what, &got, &want);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The `tiled` crate's own test map `assets/tiled_base64_zstandard.tmx`
/// (saved by Tiled 1.4, compressed by the reference zstd library): its
/// 100 x 100 layer, and the same layer from `tiled_base64_zlib.tmx`.
const TILED_ZSTD: &str = "KLUv/WBAm6UFAPgjAAAAIREtLgAAAC8RACMfHy0tLi0tLSMjIyMjIyMjSaBguwAAg0JmtQEFA2qvb+Al6lHUO91VvxpMveegXVabfkkjaEj1wZVZeNWPbSrdISdZk1b145uYEEFAvQmwiF5zTMi2QsOb9Vhv7ZxsK27ZJBXC9lYf2mVdhuqWjb8/hITgZAMw1ctxfXIOXBaofKbranfWDTtJ/Xyz7E2ZNWzVKauthC4r26Ry1TnnDqtmvUfyDw==";
const TILED_ZLIB: &str = "eJzt1zEKwzAMBVBdIScIJXPS+9+uDY1BuHbpULvLeyDIkEkfIXmLiK2qW6cYb7lqv+p41r1TcpmjZFLPyamVEXOcGSzpu66SixkZb41Xz9dO7fE+O4yR+703KmdyhExGK32v+1zv+rxLZDJO7vO5G3KvSyY1eYxT31Dlrm3t9AhZzNC6a+v3RsmhNzP83qdc8ttdHuO07thWLlt4E87w7S6wM+bo7e3ef8z1KRt5/N+388N88gAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAIHsArPIXTA==";

#[test]
fn a_zstd_layer_saved_by_tiled_loads() {
    let _s = serial();
    let text = |enc: &str, b64: &str| {
        format!(
            r##"<?xml version="1.0" encoding="UTF-8"?>
<map version="1.4" tiledversion="1.4.0" orientation="orthogonal" renderorder="right-down" width="100" height="100" tilewidth="32" tileheight="32" infinite="0" backgroundcolor="#ff00ff" nextlayerid="3" nextobjectid="5">
 <tileset firstgid="1" name="tilesheet" tilewidth="32" tileheight="32" tilecount="84" columns="14">
  <image source="tilesheet.png" width="448" height="192"/>
  <tile id="1">
   <properties>
    <property name="a tile property" value="123"/>
   </properties>
  </tile>
 </tileset>
 <layer id="1" name="L" width="100" height="100">
  <data encoding="base64" compression="{enc}">
   {b64}
  </data>
 </layer>
</map>
"##
        )
    };
    let dir = temp_dir("tiled-zstd");
    std::fs::write(dir.join("tilesheet.png"), png(448, 192)).unwrap();
    let file = dir.join("tiled.tmx").display().to_string();
    let mut o = opts();
    o.collision_layers = Some(vec!["L".into()]);
    let zlib = measured(|| tmx::load_str(&file, &text("zlib", TILED_ZLIB), &o))
        .0
        .unwrap();
    let zstd = measured(|| tmx::load_str(&file, &text("zstd", TILED_ZSTD), &o))
        .0
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    same_level("Tiled's zstd", &zstd, &zlib);
    // Its first row: 35,35,35,35,35,33,33,33,33,33,33,0,...
    let ledge_levels::art::ArtContent::Tiles(grid) = &zstd.art.layers[0].content else {
        panic!("{:?}", zstd.art.layers)
    };
    let row: Vec<Option<u32>> = (0..12).map(|x| grid.get(x, 0).map(|c| c.tile)).collect();
    let (a, b) = (Some(34), Some(32));
    assert_eq!(row, [a, a, a, a, a, b, b, b, b, b, b, None]);
}

#[test]
fn zstd_bombs_stop_at_the_cell_bound_while_decoding() {
    let _s = serial();
    use base64::Engine;
    let b64 = |b: &[u8]| base64::engine::general_purpose::STANDARD.encode(b);
    // 44 KB of zstd (RLE blocks) that decodes to 1.4 GB.
    let rle = zstd_rle_zeros(11_200);
    // The encoder's own output for 64 MiB of zeros.
    let zeros = zstd(&vec![0u8; 64 << 20]);
    for (what, data) in [("RLE", b64(&rle)), ("encoder", zeros)] {
        let body = format!(
            r#"<layer id="1" name="L" width="2" height="2"><data encoding="base64" compression="zstd">{data}</data></layer>"#
        );
        let text = map(2, 2, &body);
        let t = Instant::now();
        let (r, peak) = measured(|| tmx::load_str("bomb.tmx", &text, &opts()));
        let secs = t.elapsed().as_secs_f64();
        eprintln!(
            "zstd bomb ({what}, {} bytes of TMX): refused in {secs:.2} s, peak heap {peak} bytes",
            text.len()
        );
        expect_limit(
            r,
            "bomb.tmx",
            "map.layers[0].data",
            "MAX_LEVEL_CELLS",
            MAX_LEVEL_CELLS,
        );
        assert!(peak < 64 << 20, "peak {peak}");
        assert!(secs < 10.0, "{secs} s");
    }
    // A frame asking for a huge window (a 2 GiB one, then a 1 TiB single
    // segment) is refused before the decoder reserves it.
    let mut huge_window = vec![0x28, 0xb5, 0x2f, 0xfd, 0x00, 0xa8];
    huge_window.extend_from_slice(&[0x01, 0x00, 0x00]);
    let mut huge_segment = vec![0x28, 0xb5, 0x2f, 0xfd, 0xe0];
    huge_segment.extend_from_slice(&(1u64 << 40).to_le_bytes());
    huge_segment.extend_from_slice(&[0x01, 0x00, 0x00]);
    for frame in [huge_window, huge_segment] {
        let body = format!(
            r#"<layer id="1" name="L" width="2" height="2"><data encoding="base64" compression="zstd">{}</data></layer>"#,
            b64(&frame)
        );
        let (r, peak) = measured(|| tmx::load_str("window.tmx", &map(2, 2, &body), &opts()));
        let e = r.unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(e, LevelError::Syntax { .. })
                && msg.starts_with("window.tmx: map.layers[0].data")
                && msg.contains("cannot decode the tile data"),
            "{msg}"
        );
        assert!(peak < 1 << 20, "peak {peak}: {msg}");
    }
}

#[test]
fn xml_and_zstd_tile_data_are_checked_like_the_others() {
    let _s = serial();
    let layer = |data: &str| {
        map(
            2,
            2,
            &format!(r#"<layer id="1" name="L" width="2" height="2">{data}</layer>"#),
        )
    };
    for (what, data, got) in [
        (
            "xml short",
            "<data><tile/><tile/><tile/></data>".to_owned(),
            3,
        ),
        (
            "xml long",
            format!("<data>{}</data>", r#"<tile gid="1"/>"#.repeat(5)),
            5,
        ),
        ("xml empty", "<data/>".to_owned(), 0),
        (
            "zstd short",
            format!(
                r#"<data encoding="base64" compression="zstd">{}</data>"#,
                zstd(&[0u8; 12])
            ),
            3,
        ),
    ] {
        let e = load_tmx("n.tmx", &layer(&data)).expect_err(what);
        assert_eq!(
            e,
            LevelError::Length {
                file: "n.tmx".into(),
                field: "map.layers[0].data".into(),
                expected: 4,
                got,
            },
            "{what}: {e}"
        );
    }
    let e = load_tmx(
        "g.tmx",
        &layer(r#"<data><tile gid="1"/><tile gid="x"/><tile/><tile/></data>"#),
    )
    .unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, LevelError::BadValue { .. })
            && msg.starts_with("g.tmx: map.layers[0].data.tile[1].gid"),
        "{msg}"
    );
    let e = load_tmx(
        "z.tmx",
        &layer(r#"<data encoding="base64" compression="zstd">AAAA</data>"#),
    )
    .unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.starts_with("z.tmx: map.layers[0].data: ")
            && msg.contains("cannot decode the tile data"),
        "{msg}"
    );
    // XML data is one element per cell: the element bound holds.
    let body = format!(
        r#"<layer id="1" name="L" width="1024" height="1025"><data>{}</data></layer>"#,
        "<tile/>".repeat(1024 * 1025)
    );
    let (r, peak) = measured(|| tmx::load_str("xml.tmx", &map(1024, 1025, &body), &opts()));
    expect_limit(
        r,
        "xml.tmx",
        "map.layers[0].data.tile",
        "MAX_ELEMENTS",
        MAX_ELEMENTS,
    );
    assert!(peak < 32 << 20, "peak {peak}");
}

#[test]
fn ogmo_padded_rows_count_towards_the_cell_bound() {
    let _s = serial();
    let opts = opts();
    let layer = |i: usize, side: usize| {
        format!(
            r#"{{"name": "t{i}", "gridCellWidth": 16, "gridCellHeight": 16, "gridCellsX": {side}, "gridCellsY": {side}, "tileset": "t", "data2D": [{}]}}"#,
            vec!["[]"; side].join(",")
        )
    };
    let level = |layers: Vec<String>| {
        format!(
            r#"{{"width": 64, "height": 64, "layers": [{}]}}"#,
            layers.join(",")
        )
    };
    // The bomb: 1000 layers of 4096 empty rows (16 Mi cells each) from
    // 4 Mi JSON values; refused at the first, before allocating it.
    let text = level((0..1000).map(|i| layer(i, 4096)).collect());
    let (r, peak) = measured(|| ogmo::load_str("pad.json", &text, None, &opts));
    let msg = expect_limit(
        r,
        "pad.json",
        "layers[0].data2D",
        "MAX_LEVEL_CELLS",
        MAX_LEVEL_CELLS,
    );
    // As docs/LEVELS.md shows it.
    assert_eq!(
        msg,
        "pad.json: layers[0].data2D: 16777216 tile and grid cells in all layers is more than the limit of 4194304 (MAX_LEVEL_CELLS)"
    );
    eprintln!(
        "OGMO padding bomb ({} bytes): peak heap {peak} bytes",
        text.len()
    );
    // The bound is on the document's total: four 1024 x 1024 layers fit,
    // the fifth does not.
    let text = level((0..5).map(|i| layer(i, 1024)).collect());
    let (r, _) = measured(|| ogmo::load_str("pad.json", &text, None, &opts));
    expect_limit(
        r,
        "pad.json",
        "layers[4].data2D",
        "MAX_LEVEL_CELLS",
        MAX_LEVEL_CELLS,
    );
}

#[test]
fn layer_sizes_and_the_total_cell_count_are_bounded() {
    let _s = serial();
    let body =
        r#"<layer id="1" name="L" width="5000" height="1"><data encoding="csv">0</data></layer>"#;
    expect_limit(
        load_tmx("wide.tmx", &map(2, 2, body)),
        "wide.tmx",
        "map.layers[0].width",
        "MAX_LEVEL_TILES",
        4096,
    );
    expect_limit(
        load_tmx("wide.tmx", &map(5000, 2, "")),
        "wide.tmx",
        "map.width",
        "MAX_LEVEL_TILES",
        4096,
    );
    // Two 2048 x 2048 layers: 8 Mi cells (the second is refused before its
    // data is decoded).
    let zeros = zlib(&vec![0u8; 4 * 2048 * 2048]);
    let layer = |i| {
        format!(
            r#"<layer id="{i}" name="L{i}" width="2048" height="2048"><data encoding="base64" compression="zlib">{zeros}</data></layer>"#
        )
    };
    let text = map(2048, 2048, &format!("{}{}", layer(1), layer(2)));
    expect_limit(
        load_tmx("cells.tmx", &text),
        "cells.tmx",
        "map.layers[1].data",
        "MAX_LEVEL_CELLS",
        MAX_LEVEL_CELLS,
    );
    let body = r#"<layer id="1" name="L" width="2" height="2"><data encoding="csv"><chunk x="99999999" y="0" width="1" height="1">0</chunk></data></layer>"#;
    let text = map(2, 2, body).replace(r#"infinite="0""#, r#"infinite="1""#);
    expect_limit(
        load_tmx("chunk.tmx", &text),
        "chunk.tmx",
        "map.layers[0].data.chunk[0].x",
        "MAX_CHUNK_COORD",
        MAX_CHUNK_COORD as u64,
    );
    // The most negative coordinate there is: as far from 0 as any (its
    // absolute value does not fit an i64).
    let text = text.replace("99999999", &i64::MIN.to_string());
    expect_limit(
        load_tmx("chunk.tmx", &text),
        "chunk.tmx",
        "map.layers[0].data.chunk[0].x",
        "MAX_CHUNK_COORD",
        MAX_CHUNK_COORD as u64,
    );
}

#[test]
fn counts_of_layers_tilesets_tiles_objects_points_and_properties_are_bounded() {
    let _s = serial();
    let n = |k: u64| k as usize;
    let cases: Vec<(String, &str, &str, u64)> = vec![
        (
            "<objectgroup/>".repeat(n(MAX_LAYERS + 1)),
            "map.layers[1024]",
            "MAX_LAYERS",
            MAX_LAYERS,
        ),
        (
            r#"<tileset firstgid="1" name="t" tilewidth="16" tileheight="16" tilecount="1" columns="1"/>"#
                .repeat(n(MAX_TILESETS)),
            "map.tileset[256]",
            "MAX_TILESETS",
            MAX_TILESETS,
        ),
        (
            format!(
                r#"<tileset firstgid="9" name="t" tilewidth="16" tileheight="16" tilecount="1" columns="1">{}</tileset>"#,
                "<tile/>".repeat(n(MAX_TILESET_TILES + 1))
            ),
            "map.tileset[1].tile[65536]",
            "MAX_TILESET_TILES",
            MAX_TILESET_TILES,
        ),
        (
            r#"<tileset firstgid="9" name="t" tilewidth="16" tileheight="16" tilecount="65536" columns="256"/>"#
                .repeat(5),
            "map.tileset[4].tilecount",
            "MAX_TOTAL_TILESET_TILES",
            MAX_TOTAL_TILESET_TILES,
        ),
        (
            format!(
                "<objectgroup>{}</objectgroup>",
                "<object/>".repeat(n(MAX_OBJECTS + 1))
            ),
            "map.layers[0].objects[65536]",
            "MAX_OBJECTS",
            MAX_OBJECTS,
        ),
        (
            format!(
                r#"<objectgroup><object><polygon points="{}"/></object></objectgroup>"#,
                "1,2 ".repeat(n(MAX_SHAPE_POINTS + 1))
            ),
            "map.layers[0].objects[0].polygon.points",
            "MAX_SHAPE_POINTS",
            MAX_SHAPE_POINTS,
        ),
        (
            format!(
                "<objectgroup>{}</objectgroup>",
                format!(
                    r#"<object><polyline points="{}"/></object>"#,
                    "1,2 ".repeat(n(MAX_SHAPE_POINTS))
                )
                .repeat(n(MAX_TOTAL_POINTS / MAX_SHAPE_POINTS + 1))
            ),
            "map.layers[0].objects[256].polyline.points",
            "MAX_TOTAL_POINTS",
            MAX_TOTAL_POINTS,
        ),
        (
            format!(
                "<properties>{}</properties>",
                r#"<property name="a" value="b"/>"#.repeat(n(MAX_PROPERTIES + 1))
            ),
            "map.properties.properties[65536]",
            "MAX_PROPERTIES",
            MAX_PROPERTIES,
        ),
        (
            format!("<x{}/>", (0..65).map(|i| format!(" a{i}=\"\"")).collect::<String>()),
            "map.x",
            "MAX_ATTRIBUTES",
            MAX_ATTRIBUTES as u64,
        ),
        (
            format!(
                r#"<properties><property name="{}"/></properties>"#,
                "a".repeat(MAX_ATTRIBUTE_BYTES + 1)
            ),
            "map.properties.properties[0].name",
            "MAX_ATTRIBUTE_BYTES",
            MAX_ATTRIBUTE_BYTES as u64,
        ),
        (
            format!(
                r#"<properties><property name="a">{}</property></properties>"#,
                "a".repeat(MAX_TEXT_BYTES + 1)
            ),
            "map.properties.properties[0]",
            "MAX_TEXT_BYTES",
            MAX_TEXT_BYTES as u64,
        ),
        (
            "<a/>".repeat(n(MAX_ELEMENTS)),
            "map.a",
            "MAX_ELEMENTS",
            MAX_ELEMENTS,
        ),
        (
            r#"<imagelayer><image source="a.png" width="20000" height="2"/></imagelayer>"#
                .into(),
            "map.layers[0].image.width",
            "MAX_IMAGE_SIDE",
            MAX_IMAGE_SIDE,
        ),
        (
            r#"<imagelayer><image source="a.png" width="16000" height="16000"/></imagelayer>"#
                .into(),
            "map.layers[0].image",
            "MAX_IMAGE_PIXELS",
            MAX_IMAGE_PIXELS,
        ),
    ];
    for (body, field, bound, limit) in cases {
        expect_limit(
            load_tmx("count.tmx", &map(2, 2, &body)),
            "count.tmx",
            field,
            bound,
            limit,
        );
    }
}

/// A fresh folder for files of one test.
fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ledge-limits-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn documents_and_templates_are_bounded_across_one_load() {
    let _s = serial();
    let dir = temp_dir("docs");
    for i in 0..MAX_DOCUMENTS {
        std::fs::write(
            dir.join(format!("t{i}.tsx")),
            r#"<tileset name="t" tilewidth="16" tileheight="16" tilecount="1" columns="1"/>"#,
        )
        .unwrap();
    }
    let body: String = (0..MAX_DOCUMENTS)
        .map(|i| format!(r#"<tileset firstgid="{}" source="t{i}.tsx"/>"#, i + 10))
        .collect();
    let file = dir.join("many.tmx").display().to_string();
    let tsx63 = dir.join("t63.tsx").display().to_string();
    expect_limit(
        load_tmx(&file, &map(2, 2, &body)),
        &tsx63,
        "(document)",
        "MAX_DOCUMENTS",
        MAX_DOCUMENTS,
    );
    // A template copied into many objects: its bytes count once per object.
    let big = format!(
        r#"<template><object name="{}" width="16" height="16"/></template>"#,
        "n".repeat(4000)
    );
    std::fs::write(dir.join("big.tx"), big).unwrap();
    let objects = r#"<object template="big.tx" x="0" y="0"/>"#.repeat(20_000);
    let file = dir.join("tpl.tmx").display().to_string();
    let tx = dir.join("big.tx").display().to_string();
    expect_limit(
        load_tmx(
            &file,
            &map(2, 2, &format!("<objectgroup>{objects}</objectgroup>")),
        ),
        &tx,
        "template",
        "MAX_TEMPLATE_BYTES",
        MAX_TEMPLATE_BYTES,
    );
    // A template that uses itself would recurse forever in the Tiled reader.
    std::fs::write(
        dir.join("self.tx"),
        r#"<template><object template="self.tx"/></template>"#,
    )
    .unwrap();
    let file = dir.join("self.tmx").display().to_string();
    let e = load_tmx(
        &file,
        &map(
            2,
            2,
            r#"<objectgroup><object template="self.tx"/></objectgroup>"#,
        ),
    )
    .unwrap_err();
    assert_eq!(e.file(), dir.join("self.tx").display().to_string(), "{e}");
    assert_eq!(e.field(), Some("template.objects[0].template"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Loaded, or refused for something the Tiled reader did not choke on (the
/// art of a generated map has no image files).
#[track_caller]
fn past_the_tiled_reader<T: std::fmt::Debug>(r: Result<T, LevelError>) {
    if let Err(e) = r {
        let msg = e.to_string();
        assert!(
            !msg.contains("tilecount")
                && !msg.contains("Missing attribute")
                && !msg.contains("malformed"),
            "{msg}"
        );
    }
}

#[test]
fn old_tilesets_without_tilecount_are_derived_or_named() {
    let _s = serial();
    // Image size given: tilecount and columns are derived (margin 1,
    // spacing 2: (100 + 2 - 1) / 18 = 5 columns, (40 + 2 - 1) / 18 = 2 rows).
    let ts = r#"<tileset firstgid="5" name="old" tilewidth="16" tileheight="16" margin="1" spacing="2"><image source="old.png" width="100" height="40"/></tileset>"#;
    let body = format!(
        r#"{ts}<layer id="1" name="L" width="2" height="2"><data encoding="csv">0,0,0,0</data></layer>"#
    );
    past_the_tiled_reader(load_tmx("old.tmx", &map(2, 2, &body)));
    // No image size (and no such PNG to read it from): named.
    let ts = r#"<tileset firstgid="5" name="old" tilewidth="16" tileheight="16"><image source="missing.png"/></tileset>"#;
    let e = load_tmx("old.tmx", &map(2, 2, ts)).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, LevelError::Missing { .. })
            && msg.starts_with("old.tmx: map.tileset[1].tilecount")
            && msg.contains("\"old\""),
        "{msg}"
    );
    // An image collection: the number of its tiles.
    let ts = r#"<tileset firstgid="5" name="col" tilewidth="16" tileheight="16"><tile id="0"><image source="a.png" width="16" height="16"/></tile></tileset>"#;
    past_the_tiled_reader(load_tmx("col.tmx", &map(2, 2, ts)));
}

#[test]
fn the_tiled_examples_without_tilecount_get_past_the_tiled_reader() {
    let _s = serial();
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../target/level-corpus/tiled-examples"
    );
    if !Path::new(dir).is_dir() {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "{dir} is missing: run scripts/fetch-level-corpus"
        );
        eprintln!("\n*** SKIPPED: {dir} is missing (run scripts/fetch-level-corpus) ***\n");
        return;
    }
    let mut files = vec![
        format!("{dir}/sewers.tmx"),
        format!("{dir}/hexagonal-mini.tmx"),
        format!("{dir}/perspective_walls.tmx"),
    ];
    for e in std::fs::read_dir(format!("{dir}/sewer_automap")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "tmx") {
            files.push(p.display().to_string());
        }
    }
    assert!(files.len() >= 12, "{files:?}");
    for f in files {
        let (r, _) = measured(|| ledge_levels::load_file_with(&f, &LoadOptions::default()));
        if let Err(e) = r {
            let msg = e.to_string();
            assert!(
                !msg.contains("tilecount") && !msg.contains("Missing attribute"),
                "{f}: {msg}"
            );
            assert!(!matches!(e, LevelError::Limit { .. }), "{f}: {msg}");
        }
    }
}

#[test]
fn ogmo_json_depth_and_value_count_are_bounded_before_parsing() {
    let _s = serial();
    let opts = opts();
    let deep = format!("{{\"layers\": {}{}}}", "[".repeat(200), "]".repeat(200));
    let (r, _) = measured(|| ogmo::load_str("deep.json", &deep, None, &opts));
    expect_limit(r, "deep.json", "byte", "MAX_JSON_DEPTH", 128);
    // serde_json's own recursion limit is the same 128: one level under the
    // bound is parsed (and refused for its content, not its depth).
    let ok = format!("{{\"a\": {}{}}}", "[".repeat(126), "]".repeat(126));
    let r = ogmo::load_str("ok.json", &ok, None, &opts);
    assert!(
        !matches!(
            r,
            Err(LevelError::Limit { .. }) | Err(LevelError::Syntax { .. })
        ),
        "{r:?}"
    );
    let wide = format!("{{\"layers\": [{}]}}", csv(MAX_JSON_VALUES));
    let (r, peak) = measured(|| ogmo::load_str("wide.json", &wide, None, &opts));
    expect_limit(r, "wide.json", "byte", "MAX_JSON_VALUES", MAX_JSON_VALUES);
    assert!(
        peak < 1 << 20,
        "the count is checked before parsing: {peak}"
    );
}

#[test]
fn text_beyond_the_file_size_bound_is_refused() {
    let _s = serial();
    let text = format!("{}{}", map(2, 2, ""), " ".repeat(64 << 20));
    let (r, _) = measured(|| tmx::load_str("huge.tmx", &text, &opts()));
    expect_limit(
        r,
        "huge.tmx",
        "(document)",
        "MAX_FILE_BYTES",
        ledge_levels::MAX_FILE_BYTES,
    );
}

/// Loads `text` as `file`, returning the level and the extra peak heap
/// (not bounded: a level of the most cells peaks at hundreds of MiB in the
/// Tiled reader and the importer).
fn load_peak(file: &str, text: &str, o: &LoadOptions) -> (ledge_levels::LoadedLevel, usize) {
    let base = CURRENT.load(Ordering::SeqCst);
    PEAK.store(base, Ordering::SeqCst);
    let l = tmx::load_str(file, text, o).unwrap();
    (l, PEAK.load(Ordering::SeqCst).saturating_sub(base))
}

#[test]
fn a_zstd_layer_of_the_most_cells_loads_with_no_extra_peak() {
    let _s = serial();
    // 2048 x 2048 = MAX_LEVEL_CELLS cells, every tile and flip.
    let gids: Vec<u32> = (0..MAX_LEVEL_CELLS as u32)
        .map(|i| match i % 7 {
            0..=2 => 0,
            n => (n - 2) | (i % 8) << 29,
        })
        .collect();
    let mut o = opts();
    o.collision_layers = Some(vec!["L".into()]);
    let dir = temp_dir("most");
    let file = dir.join("big.tmx").display().to_string();
    let text = |enc: &str, b64: String| {
        let body = format!(
            r#"<layer id="1" name="L" width="2048" height="2048"><data encoding="base64" compression="{enc}">{b64}</data></layer>"#
        );
        with_atlas(&dir, &map(2048, 2048, &body))
    };
    let bytes = le_bytes(&gids);
    let (zlib_text, zstd_text) = (text("zlib", zlib(&bytes)), text("zstd", zstd(&bytes)));
    drop((gids, bytes));
    let (want, zlib_peak) = load_peak(&file, &zlib_text, &o);
    drop(want.art);
    let t = Instant::now();
    let (got, zstd_peak) = load_peak(&file, &zstd_text, &o);
    let secs = t.elapsed().as_secs_f64();
    eprintln!(
        "2048 x 2048 zstd layer ({} bytes of TMX): loaded in {secs:.2} s, peak heap {zstd_peak} bytes (zlib: {zlib_peak})",
        zstd_text.len()
    );
    assert!(got.level == want.level);
    // The CSV rewrite is not what the peak is made of.
    assert!(
        zstd_peak <= zlib_peak + (32 << 20),
        "{zstd_peak} vs {zlib_peak}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
