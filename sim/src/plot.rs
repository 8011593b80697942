//! The SVG plot: cost (busy world, µs per tick, log scale) against each
//! accuracy metric, one panel per metric, one colour per knob, presets
//! labelled. Settings costing more than [`OFF_SCALE`] times the cheapest
//! (brute force) would squeeze every other point into a corner: they are
//! left out and named under the legend.

use std::path::Path;

use anyhow::Result;
use plotters::prelude::*;

use crate::tradeoff::{Metrics, Row};

/// Colours of the knobs, in order of first appearance.
const COLOURS: [RGBColor; 10] = [
    RGBColor(0, 0, 0),
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(214, 39, 40),
    RGBColor(127, 127, 127),
    RGBColor(23, 190, 207),
];

/// Settings costing more than this many times the cheapest are not drawn.
pub const OFF_SCALE: f64 = 30.0;

/// One panel: title, y axis label, value.
type Panel = (&'static str, &'static str, fn(&Metrics) -> f64);

const PANELS: [Panel; 5] = [
    ("Tunnelling at 1 px walls", "% of shots", |m| {
        100.0 * m.thin_walls.rate()
    }),
    ("Deepest overlap after a tick", "px", |m| {
        m.penetration.max as f64 / 256.0
    }),
    ("Motion lost at floor seams", "units per seam", |m| {
        m.seams.per_seam()
    }),
    ("False squishes (stacks + pile)", "events", |m| {
        m.false_squishes() as f64
    }),
    ("Prediction drift vs default", "mean px", |m| {
        m.drift.mean / 256.0
    }),
];

/// Draws the plot of `rows` to `path` (SVG).
pub fn write_svg(all: &[Row], path: &Path) -> Result<()> {
    anyhow::ensure!(!all.is_empty(), "nothing to plot");
    let cost = |r: &Row| r.metrics.world_ns / 1000.0;
    let cheapest = all.iter().map(cost).fold(f64::MAX, f64::min);
    let (rows, off): (Vec<&Row>, Vec<&Row>) =
        all.iter().partition(|r| cost(r) <= OFF_SCALE * cheapest);
    let rows = &rows[..];
    let (lo, hi) = rows
        .iter()
        .map(|r| cost(r))
        .fold((f64::MAX, 0f64), |(lo, hi), x| (lo.min(x), hi.max(x)));
    let (xmin, xmax) = ((lo * 0.8).max(1e-3), hi.max(lo * 1.01) * 1.25);
    let mut knobs: Vec<&str> = Vec::new();
    for r in all {
        if !knobs.contains(&r.setting.knob) {
            knobs.push(r.setting.knob);
        }
    }
    let colour = |knob: &str| {
        let i = knobs.iter().position(|k| *k == knob).unwrap_or(0);
        COLOURS[i % COLOURS.len()]
    };

    let root = SVGBackend::new(path, (1500, 900)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(
        "ledge-sim tradeoff: cost (busy world, µs per tick) against accuracy",
        ("sans-serif", 22),
    )?;
    let areas = root.split_evenly((2, 3));
    for (area, (title, unit, value)) in areas.iter().zip(PANELS) {
        let top = rows.iter().map(|r| value(&r.metrics)).fold(0f64, f64::max);
        let top = if top > 0.0 { top * 1.2 } else { 1.0 };
        let mut chart = ChartBuilder::on(area)
            .caption(title, ("sans-serif", 17))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d((xmin..xmax).log_scale(), 0f64..top)?;
        chart
            .configure_mesh()
            .x_desc("µs per tick (log)")
            .y_desc(unit)
            .x_labels(8)
            .y_labels(6)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .light_line_style(RGBColor(240, 240, 240))
            .bold_line_style(RGBColor(210, 210, 210))
            .draw()?;
        for knob in &knobs {
            let c = colour(knob);
            chart.draw_series(
                rows.iter()
                    .filter(|r| r.setting.knob == *knob)
                    .map(|r| Circle::new((cost(r), value(&r.metrics)), 4, c.filled())),
            )?;
        }
        chart.draw_series(rows.iter().filter(|r| r.setting.is_preset()).map(|r| {
            let label = r.setting.name.trim_start_matches("preset:").to_owned();
            // Fast and balanced often sit together: one label above, one below.
            let dy = if label == "balanced" { 4 } else { -18 };
            EmptyElement::at((cost(r), value(&r.metrics)))
                + Text::new(label, (6, dy), ("sans-serif", 14).into_font())
        }))?;
    }
    let legend = &areas[5];
    legend.draw(&Text::new(
        "knob moved from the default",
        (30, 30),
        ("sans-serif", 17).into_font(),
    ))?;
    for (i, knob) in knobs.iter().enumerate() {
        let y = 70 + 28 * i as i32;
        legend.draw(&Circle::new((40, y), 6, colour(knob).filled()))?;
        legend.draw(&Text::new(
            knob.to_string(),
            (56, y - 8),
            ("sans-serif", 16).into_font(),
        ))?;
    }
    let mut y = 90 + 28 * knobs.len() as i32;
    for r in off {
        legend.draw(&Text::new(
            format!(
                "not drawn (off scale): {} at {:.0} µs per tick",
                r.setting.name,
                cost(r)
            ),
            (30, y),
            ("sans-serif", 15).into_font(),
        ))?;
        y += 24;
    }
    root.present()?;
    Ok(())
}
