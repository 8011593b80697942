//! Runs `ledge-sim tradeoff --quick` and checks the CSV and the plot: a row
//! per setting, sane values, and the behaviour each knob promises.

use std::collections::BTreeMap;
use std::process::Command;

use ledge_sim::report::CSV_COLUMNS;
use ledge_sim::settings;

const SHOTS: u64 = 4000;

/// One CSV row by column name.
struct Row(BTreeMap<String, String>);

impl Row {
    fn s(&self, col: &str) -> &str {
        self.0
            .get(col)
            .unwrap_or_else(|| panic!("no column {col}"))
            .as_str()
    }
    fn f(&self, col: &str) -> f64 {
        self.s(col)
            .parse()
            .unwrap_or_else(|e| panic!("{col} = {:?}: {e}", self.s(col)))
    }
    fn u(&self, col: &str) -> u64 {
        self.s(col)
            .parse()
            .unwrap_or_else(|e| panic!("{col} = {:?}: {e}", self.s(col)))
    }
}

/// The columns that measure what the simulation did (not what it cost).
const ACCURACY: [&str; 23] = [
    "shots",
    "tunnels",
    "slow_shots",
    "slow_tunnels",
    "tiny_shots",
    "tiny_tunnels",
    "max_penetration_units",
    "mean_max_penetration_units",
    "seam_crossings",
    "seam_loss_tiles_units",
    "seam_loss_boxes_units",
    "stack_boxes",
    "stack_squishes",
    "pile_squishes",
    "false_squishes",
    "drift_samples",
    "drift_mean_units",
    "drift_max_units",
    "tunnel_rate",
    "game_seam_crossings_tiles",
    "game_seam_loss_tiles_units",
    "game_seam_crossings_blocks",
    "game_seam_loss_blocks_units",
];

#[test]
fn quick_tradeoff_writes_a_sane_row_per_setting() {
    let dir = tempfile::tempdir().expect("temp dir");
    let csv = dir.path().join("tradeoff.csv");
    let svg = dir.path().join("tradeoff.svg");
    let out = Command::new(env!("CARGO_BIN_EXE_ledge-sim"))
        .args([
            "tradeoff",
            "--quick",
            "--shots",
            &SHOTS.to_string(),
            "--csv",
        ])
        .arg(&csv)
        .arg("--plot")
        .arg(&svg)
        .output()
        .expect("ledge-sim runs");
    assert!(
        out.status.success(),
        "ledge-sim failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8(out.stdout).expect("utf-8 table");

    // One CSV row per setting, in order, with every column.
    let text = std::fs::read_to_string(&csv).expect("csv written");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    assert_eq!(header, CSV_COLUMNS);
    let rows: Vec<Row> = lines
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            assert_eq!(cells.len(), header.len(), "{l}");
            Row(header
                .iter()
                .zip(cells)
                .map(|(h, c)| (h.to_string(), c.to_string()))
                .collect())
        })
        .collect();
    let all = settings::all();
    let names: Vec<&str> = rows.iter().map(|r| r.s("setting")).collect();
    let expected: Vec<&str> = all.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, expected);
    let by = |name: &str| {
        rows.iter()
            .find(|r| r.s("setting") == name)
            .unwrap_or_else(|| panic!("no row {name}"))
    };
    for name in &names {
        assert!(
            table.contains(&format!("| {name} |")),
            "{name} missing from the table"
        );
    }

    // Sane values everywhere.
    for r in &rows {
        let name = r.s("setting");
        assert_eq!(r.u("shots"), SHOTS, "{name}");
        assert_eq!(r.u("tiny_shots"), SHOTS / 4, "{name}");
        assert!(r.u("tunnels") <= r.u("shots"), "{name}");
        assert!(r.u("slow_tunnels") <= r.u("slow_shots"), "{name}");
        assert!(r.u("slow_shots") > 0 && r.u("slow_shots") < SHOTS, "{name}");
        assert!((0.0..=1.0).contains(&r.f("tunnel_rate")), "{name}");
        assert!(r.f("world_ns_per_tick") > 0.0, "{name}");
        assert!(r.f("game_ns_per_tick") > 0.0, "{name}");
        assert!(r.f("pile_ns_per_tick") > 0.0, "{name}");
        assert!(r.u("seam_crossings") > 0, "{name}");
        assert!(r.u("game_seam_crossings_tiles") > 0, "{name}");
        assert!(r.u("game_seam_crossings_blocks") > 0, "{name}");
        assert!(r.u("stack_boxes") > 0, "{name}");
        assert!(r.u("drift_samples") > 0, "{name}");
        assert!(r.f("drift_mean_units") <= r.f("drift_max_units"), "{name}");
        assert!(
            r.f("mean_max_penetration_units") <= r.f("max_penetration_units"),
            "{name}"
        );
        assert_eq!(
            r.u("false_squishes"),
            r.u("stack_squishes") + r.u("pile_squishes"),
            "{name}"
        );
    }

    // Knobs that never change results change no accuracy figure; nor does
    // `sweep=off` in scenes without marked bodies (the default `flagged`
    // sweeps only marked bodies).
    let base = by("baseline");
    for name in [
        "broad=brute",
        "broad=strips32px",
        "broad=strips128px",
        "broad=strips64px/x8",
        "pipeline=general",
        "threads=2",
        "sweep=off",
        "preset:balanced",
    ] {
        for col in ACCURACY {
            assert_eq!(by(name).s(col), base.s(col), "{name}: {col}");
        }
    }
    // Predicting with the authority's own configuration never drifts; with
    // another player shape it does.
    assert_eq!(base.u("drift_max_units"), 0);
    assert!(by("player=box+feet+head").u("drift_max_units") > 0);
    // Without sweeps, shots faster than about their half size per tick
    // tunnel: most of them up to 64 px per tick, a few at game speeds.
    assert!(base.u("tunnels") > SHOTS / 4, "{}", base.u("tunnels"));
    assert!(base.u("slow_tunnels") > 0);

    // More substeps never tunnel more (their positions nest), and 8 tunnel
    // far less than 1.
    let mut last = base.u("tunnels");
    for n in [2, 4, 8] {
        let t = by(&format!("substeps={n}")).u("tunnels");
        assert!(t <= last, "substeps={n}: {t} > {last}");
        last = t;
    }
    assert!(last * 4 < base.u("tunnels"), "substeps=8: {last}");
    // The swept modes: nothing game-sized tunnels; the 1 px threshold stops
    // the tiny shots too.
    for name in [
        "sweep=flagged+marked",
        "sweep=auto",
        "sweep=auto1px",
        "preset:exact",
    ] {
        assert_eq!(by(name).u("tunnels"), 0, "{name}");
    }
    assert_eq!(by("sweep=auto1px").u("tiny_tunnels"), 0);
    // Marked shots are swept whatever their speed: none tunnels, tiny or not,
    // and nothing else changes.
    let marked = by("sweep=flagged+marked");
    assert_eq!(marked.u("tiny_tunnels"), 0);
    for col in &ACCURACY[6..18] {
        assert_eq!(marked.s(col), base.s(col), "sweep=flagged+marked: {col}");
    }
    // More restitution passes never squish more than one.
    assert!(by("iterations=16").u("false_squishes") <= by("iterations=1").u("false_squishes"));

    // The plot is an SVG with the presets labelled.
    let plot = std::fs::read_to_string(&svg).expect("svg written");
    assert!(plot.starts_with("<svg"), "{}", &plot[..plot.len().min(80)]);
    for label in ["fast", "balanced", "exact"] {
        assert!(plot.lines().any(|l| l.trim() == label), "{label}");
    }
}
