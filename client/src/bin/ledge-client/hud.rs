//! The heads-up display: connection, ping, loss, fps, bandwidth,
//! corrections, coins; a net graph of the last two seconds (round-trip time
//! and snapshot arrivals); the controls.

use std::collections::VecDeque;

use ledge_client::view::NetStats;
use macroquad::prelude::*;

/// Seconds of history in the net graph.
pub const GRAPH_SECONDS: f64 = 2.0;

const FONT: f32 = 18.0;
const LINE: f32 = 20.0;
const PANEL: Color = Color::new(0.05, 0.06, 0.1, 0.62);
const DIM: Color = Color::new(0.75, 0.8, 0.9, 1.0);

/// The last seconds of network measurements.
#[derive(Debug, Default)]
pub struct NetGraph {
    /// `(time s, rtt ms)`, one per frame.
    rtt: VecDeque<(f64, f32)>,
    /// `(time s, ms since the previous arrival)`.
    arrivals: VecDeque<(f64, f32)>,
    last_arrival: Option<f64>,
}

impl NetGraph {
    /// Records this frame's round-trip time.
    pub fn rtt(&mut self, now: f64, rtt_ms: f32) {
        self.rtt.push_back((now, rtt_ms));
        self.trim(now);
    }

    /// Records a snapshot arriving at `now`.
    pub fn arrival(&mut self, now: f64) {
        let gap = self
            .last_arrival
            .map_or(0.0, |t| ((now - t) * 1000.0) as f32);
        self.last_arrival = Some(now);
        self.arrivals.push_back((now, gap));
        self.trim(now);
    }

    fn trim(&mut self, now: f64) {
        let old = now - GRAPH_SECONDS;
        while self.rtt.front().is_some_and(|&(t, _)| t < old) {
            self.rtt.pop_front();
        }
        while self.arrivals.front().is_some_and(|&(t, _)| t < old) {
            self.arrivals.pop_front();
        }
    }

    /// Draws the graph with its top-right corner at `(right, top)`.
    pub fn draw(&self, now: f64, right: f32, top: f32) {
        let (w, h) = (240.0, 84.0);
        let (x0, y0) = (right - w, top);
        draw_rectangle(x0, y0, w, h, PANEL);
        let plot = Rect::new(x0 + 6.0, y0 + 20.0, w - 12.0, h - 26.0);
        draw_rectangle_lines(
            plot.x,
            plot.y,
            plot.w,
            plot.h,
            1.0,
            Color::new(1.0, 1.0, 1.0, 0.15),
        );
        let tx = |t: f64| plot.x + plot.w * (1.0 - ((now - t) / GRAPH_SECONDS) as f32);
        // Snapshot arrivals: a bar per snapshot, as tall as the gap before
        // it (100 ms: full height), so jitter and losses stand out.
        let cyan = Color::new(0.3, 0.85, 1.0, 0.9);
        for &(t, gap) in &self.arrivals {
            let bar = (gap / 100.0).clamp(0.04, 1.0) * plot.h;
            let x = tx(t).round();
            draw_line(x, plot.bottom(), x, plot.bottom() - bar, 1.0, cyan);
        }
        // Round-trip time: a line, scaled to the largest value shown.
        let top_ms = self.rtt.iter().map(|&(_, r)| r).fold(20.0f32, f32::max) * 1.25;
        let yellow = Color::new(1.0, 0.85, 0.2, 1.0);
        let points: Vec<Vec2> = self
            .rtt
            .iter()
            .map(|&(t, r)| vec2(tx(t), plot.bottom() - (r / top_ms).min(1.0) * plot.h))
            .collect();
        for pair in points.windows(2) {
            draw_line(pair[0].x, pair[0].y, pair[1].x, pair[1].y, 1.5, yellow);
        }
        let last = self.rtt.back().map_or(0.0, |&(_, r)| r);
        draw_text(
            format!("rtt {last:.0} ms (max {:.0})", top_ms / 1.25),
            x0 + 6.0,
            y0 + 15.0,
            16.0,
            yellow,
        );
        draw_text("snapshots", x0 + w - 76.0, y0 + 15.0, 16.0, cyan);
    }
}

/// What the HUD shows.
pub struct HudInfo<'a> {
    /// Connection state, one line.
    pub status: &'a str,
    /// Network figures, when online.
    pub net: Option<&'a NetStats>,
    /// Frames per second.
    pub fps: i32,
    /// The simulation tick shown.
    pub tick: u64,
    /// Our coins.
    pub coins: u32,
    /// Whether we reached the goal.
    pub won: bool,
}

/// Draws the HUD; the net graph too when online.
pub fn draw(info: &HudInfo, graph: &NetGraph, now: f64) {
    let mut lines: Vec<(String, Color)> = vec![(info.status.to_owned(), WHITE)];
    match info.net {
        Some(n) => {
            lines.push((
                format!(
                    "fps {}   ping {:.1} ms   jitter {:.1} ms   loss {:.1}%",
                    info.fps,
                    n.rtt_ms,
                    n.jitter_ms,
                    n.loss * 100.0
                ),
                WHITE,
            ));
            lines.push((
                format!(
                    "down {:.1} kB/s   up {:.1} kB/s   {:.0} snapshots/s",
                    n.bytes_in_per_s / 1000.0,
                    n.bytes_out_per_s / 1000.0,
                    n.snapshot_hz
                ),
                DIM,
            ));
            lines.push((
                format!(
                    "corrections {} ({:.1}/s, last {:.1} px)   input margin {:.1} ticks",
                    n.corrections, n.corrections_per_s, n.last_correction_px, n.input_margin_ticks
                ),
                DIM,
            ));
        }
        None => lines.push((format!("fps {}", info.fps), WHITE)),
    }
    let mut score = format!("coins {}   tick {}", info.coins, info.tick);
    if info.won {
        score.push_str("   GOAL!");
    }
    lines.push((score, Color::new(1.0, 0.85, 0.25, 1.0)));

    let width = lines
        .iter()
        .map(|(l, _)| measure_text(l, None, FONT as u16, 1.0).width)
        .fold(0.0, f32::max);
    draw_rectangle(
        8.0,
        8.0,
        width + 16.0,
        lines.len() as f32 * LINE + 10.0,
        PANEL,
    );
    for (i, (l, c)) in lines.iter().enumerate() {
        draw_text(l, 16.0, 8.0 + 19.0 + i as f32 * LINE, FONT, *c);
    }
    if info.net.is_some() {
        graph.draw(now, screen_width() - 8.0, 8.0);
    }
    let help = "arrows/WASD move   space/Z jump   down+jump drop   F1 debug   F2 HUD   Esc quit";
    let dims = measure_text(help, None, 16, 1.0);
    let (x, y) = (screen_width() - dims.width - 14.0, screen_height() - 10.0);
    draw_rectangle(x - 6.0, y - 15.0, dims.width + 12.0, 20.0, PANEL);
    draw_text(help, x, y, 16.0, DIM);
}

/// Font sizes a banner tries, largest first, until its text fits the
/// window's height.
const BANNER_SIZES: [f32; 6] = [28.0, 24.0, 20.0, 16.0, 14.0, 12.0];
/// Between the window's edges and a banner's panel, pixels.
const BANNER_EDGE: f32 = 16.0;
/// Between a banner's panel and its text, pixels (sideways; 12 above and
/// below).
const BANNER_PAD: f32 = 16.0;
/// A failure's panel: opaque, so its text stands out whatever is behind.
pub const FAILURE_PANEL: Color = Color::new(0.45, 0.09, 0.1, 1.0);
/// Drawn over the whole scene behind a failure's banner.
const FAILURE_SHADE: Color = Color::new(0.02, 0.02, 0.04, 0.85);

/// Where a banner goes: its lines, their font size and the panel.
#[derive(Debug, Clone, PartialEq)]
pub struct BannerLayout {
    /// Font size, pixels.
    pub size: f32,
    /// The lines, each with the index of the paragraph it belongs to.
    pub lines: Vec<(usize, String)>,
    /// The panel behind them (the text lies inside, with margins).
    pub panel: Rect,
}

impl BannerLayout {
    /// Lays out `paragraphs` (each starts on a new line) centred in a
    /// window of `screen` pixels: wrapped to the window's width, in the
    /// largest of [`BANNER_SIZES`] whose lines fit its height, a third of
    /// the way down when there is room. `width(text, size)` measures a
    /// line.
    pub fn new(paragraphs: &[&str], screen: Vec2, width: impl Fn(&str, f32) -> f32) -> Self {
        let max = (screen.x - 2.0 * (BANNER_EDGE + BANNER_PAD)).max(16.0);
        let room = screen.y - 2.0 * BANNER_EDGE;
        let mut layout = None;
        for size in BANNER_SIZES {
            let lines: Vec<(usize, String)> = paragraphs
                .iter()
                .enumerate()
                .flat_map(|(i, p)| {
                    wrap(p, max, |t| width(t, size))
                        .into_iter()
                        .map(move |l| (i, l))
                })
                .collect();
            let height = Self::line_height(size) * lines.len() as f32 + 24.0;
            let fits = height <= room;
            layout = Some((size, lines, height));
            if fits {
                break;
            }
        }
        let (size, lines, height) = layout.expect("BANNER_SIZES is not empty");
        let widest = lines
            .iter()
            .map(|(_, l)| width(l, size))
            .fold(0.0f32, f32::max);
        let w = widest + 2.0 * BANNER_PAD;
        let lowest = (screen.y - BANNER_EDGE - height).max(BANNER_EDGE);
        let y = (screen.y * 0.3 - size - 12.0).clamp(BANNER_EDGE, lowest);
        BannerLayout {
            size,
            lines,
            panel: Rect::new((screen.x - w) / 2.0, y, w, height),
        }
    }

    fn line_height(size: f32) -> f32 {
        size * 1.15
    }

    /// The baseline of line `i` (where `draw_text` puts it).
    pub fn baseline(&self, i: usize) -> f32 {
        self.panel.y + 12.0 + self.size * 0.85 + Self::line_height(self.size) * i as f32
    }
}

fn measure(text: &str, size: f32) -> f32 {
    measure_text(text, None, size as u16, 1.0).width
}

/// Draws `layout` on `panel`: the first paragraph white, the others dim.
fn draw_banner(layout: &BannerLayout, panel: Color) {
    let p = layout.panel;
    draw_rectangle(p.x, p.y, p.w, p.h, panel);
    for (i, (paragraph, line)) in layout.lines.iter().enumerate() {
        let x = (screen_width() - measure(line, layout.size)) / 2.0;
        let colour = if *paragraph == 0 { WHITE } else { DIM };
        draw_text(line, x, layout.baseline(i), layout.size, colour);
    }
}

/// A centred banner (connecting, waiting), wrapped to the window's width
/// so a long message is never clipped.
pub fn banner(text: &str) {
    let screen = vec2(screen_width(), screen_height());
    draw_banner(&BannerLayout::new(&[text], screen, measure), PANEL);
}

/// The end of a failed session: the scene shaded, and `message` (what
/// went wrong and what to do) on an opaque panel, wrapped to the window
/// and shrunk to fit its height, with how to quit below it. Returns the
/// layout drawn (for the screenshot's description).
pub fn failure(message: &str) -> BannerLayout {
    let screen = vec2(screen_width(), screen_height());
    draw_rectangle(0.0, 0.0, screen.x, screen.y, FAILURE_SHADE);
    let layout = BannerLayout::new(&[message, "Esc quits"], screen, measure);
    draw_banner(&layout, FAILURE_PANEL);
    layout
}

/// `text` in lines no wider than `max` (by `width`), broken between words;
/// a word wider than `max` alone is broken between characters.
pub fn wrap(text: &str, max: f32, width: impl Fn(&str) -> f32) -> Vec<String> {
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        let candidate = if line.is_empty() {
            word.to_owned()
        } else {
            format!("{line} {word}")
        };
        if width(&candidate) <= max {
            line = candidate;
            continue;
        }
        if !line.is_empty() {
            lines.push(std::mem::take(&mut line));
        }
        // The word alone: split it if it does not fit either.
        for c in word.chars() {
            let mut next = line.clone();
            next.push(c);
            if width(&next) > max && !line.is_empty() {
                lines.push(std::mem::take(&mut line));
                line.push(c);
            } else {
                line = next;
            }
        }
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::{wrap, BannerLayout};
    use macroquad::math::vec2;

    #[test]
    fn long_messages_wrap_between_words_and_never_exceed_the_width() {
        let w = |s: &str| s.chars().count() as f32;
        let text = "the server plays level \"sandbox2\" (hash 8240e92b1acea947), but the embedded default level has hash 89e9fbc2af16c009: pass the server's level file (--level)";
        let lines = wrap(text, 30.0, w);
        assert!(lines.len() > 3, "{lines:?}");
        assert!(lines.iter().all(|l| w(l) <= 30.0), "{lines:?}");
        // Nothing lost, nothing added but line breaks.
        assert_eq!(
            lines.join(" ").split_whitespace().collect::<Vec<_>>(),
            text.split_whitespace().collect::<Vec<_>>()
        );
        // A word longer than a line is split.
        let long = "x".repeat(75);
        let lines = wrap(&long, 30.0, w);
        assert_eq!(
            lines.iter().map(|l| l.len()).collect::<Vec<_>>(),
            [30, 30, 15]
        );
        assert_eq!(wrap("", 30.0, w), [""]);
        assert_eq!(wrap("short", 30.0, w), ["short"]);
    }

    /// A long failure in a small window: every line fits the width, the
    /// panel lies inside the window, and the font shrinks until the lines
    /// fit its height.
    #[test]
    fn a_banner_fits_small_windows() {
        // 0.5 px per character per pixel of font size: 14 px per
        // character at 28.
        let w = |s: &str, size: f32| s.chars().count() as f32 * size * 0.5;
        let long = "cannot play on 192.168.1.20:4433: the server plays level \"sandbox2\" (hash 8240e92b1acea947), but the embedded default level has hash 89e9fbc2af16c009: start the client with the server's level file, --level FILE (the server prints it in its join command)";
        for (screen, short_enough) in [
            (vec2(480.0, 270.0), true),
            (vec2(960.0, 540.0), true),
            (vec2(200.0, 120.0), false),
        ] {
            let layout = BannerLayout::new(&[long, "Esc quits"], screen, w);
            let p = layout.panel;
            assert!(
                p.x >= 16.0 && p.right() <= screen.x - 16.0,
                "{screen}: {p:?}"
            );
            assert!(p.y >= 16.0, "{screen}: {p:?}");
            if short_enough {
                assert!(p.bottom() <= screen.y - 16.0, "{screen}: {p:?}");
            } else {
                // Too long even at the smallest size: the top stays.
                assert_eq!(layout.size, 12.0);
            }
            for (_, line) in &layout.lines {
                assert!(w(line, layout.size) <= p.w - 32.0, "{line:?} in {p:?}");
            }
            assert_eq!(layout.lines.last().unwrap(), &(1, "Esc quits".to_owned()));
            let first = layout.baseline(0) - layout.size * 0.85;
            let last = layout.baseline(layout.lines.len() - 1) + layout.size * 0.3;
            assert!(first >= p.y && last <= p.bottom(), "{layout:?}");
        }
        // Room to spare: the largest size, a third of the way down.
        let small = BannerLayout::new(&["connecting..."], vec2(960.0, 540.0), w);
        assert_eq!(small.size, 28.0);
        assert_eq!(small.lines.len(), 1);
        assert!((small.panel.y - (540.0 * 0.3 - 28.0 - 12.0)).abs() < 0.01);
        // At 480x270 the long message needs a smaller font.
        let shrunk = BannerLayout::new(&[long], vec2(480.0, 270.0), w);
        assert!(shrunk.size < 28.0, "{shrunk:?}");
    }
}
