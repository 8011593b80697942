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

/// A centred banner (connecting, disconnected, won), wrapped to the
/// window's width so a long message is never clipped.
pub fn banner(text: &str) {
    let size = 28.0;
    let max = (screen_width() - 64.0).max(64.0);
    let lines = wrap(text, max, |t| measure_text(t, None, size as u16, 1.0).width);
    let line_h = size * 1.15;
    let widest = lines
        .iter()
        .map(|l| measure_text(l, None, size as u16, 1.0).width)
        .fold(0.0f32, f32::max);
    let top = screen_height() * 0.3 - size;
    draw_rectangle(
        (screen_width() - widest) / 2.0 - 16.0,
        top - 12.0,
        widest + 32.0,
        line_h * lines.len() as f32 + 24.0,
        PANEL,
    );
    for (i, line) in lines.iter().enumerate() {
        let w = measure_text(line, None, size as u16, 1.0).width;
        let y = top + size * 0.85 + line_h * i as f32;
        draw_text(line, (screen_width() - w) / 2.0, y, size, WHITE);
    }
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
    use super::wrap;

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
}
