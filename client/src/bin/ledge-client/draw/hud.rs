//! The heads-up display: by default our name, coins (of the level's),
//! deaths and the run timer (the results card once finished is
//! [`super::card`]'s, and uses the formats here); behind F3
//! the network panel (connection, ping, loss, fps, bandwidth, corrections)
//! and a net graph of the last two seconds (round-trip time and snapshot
//! arrivals); the controls hint, fading after the first moves.

use std::collections::VecDeque;

use ledge_client::view::NetStats;
use macroquad::prelude::*;

/// Seconds of history in the net graph.
pub const GRAPH_SECONDS: f64 = 2.0;

const FONT: f32 = 18.0;
const PANEL: Color = Color::new(0.05, 0.06, 0.1, 0.62);
/// Titles, hints and secondary figures.
pub const DIM: Color = Color::new(0.75, 0.8, 0.9, 1.0);

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
    /// Connection state, one line (in the network panel).
    pub status: &'a str,
    /// Network figures, when online.
    pub net: Option<&'a NetStats>,
    /// Frames per second.
    pub fps: i32,
    /// The simulation tick shown.
    pub tick: u64,
    /// Our name.
    pub name: &'a str,
    /// Our run, once we are in the game.
    pub run: Option<RunInfo>,
    /// The network panel and graph (F3) are shown.
    pub show_net: bool,
    /// The controls hint's opacity, 0..=1 (it fades after the first moves).
    pub hint_alpha: f32,
    /// "sound off: why", for the first seconds after the start.
    pub sound_notice: Option<&'a str>,
    /// Sound muted (M).
    pub muted: bool,
    /// The restart key's name, for the hints.
    pub restart_key: &'a str,
    /// The room's results: everyone in the game who finished, first place
    /// first (drawn when someone besides us is in it).
    pub results: &'a [ResultRow],
    /// The split against a ghost on screen: its text (`+0.42`) and
    /// whether we were faster (green) or not (red).
    pub split: Option<(&'a str, bool)>,
    /// Spectating: the line saying whom we watch (in place of our name;
    /// the run shown is theirs).
    pub spectate: Option<&'a str>,
    /// "next: NAME in N s", once the room's move to its next level is
    /// decided.
    pub next_level: Option<&'a str>,
    /// The level list key's name, when the server sent its levels.
    pub levels_key: Option<&'a str>,
}

/// A split we were faster in.
pub const FASTER: Color = Color::new(0.35, 0.95, 0.45, 1.0);
/// A split we were slower in.
pub const SLOWER: Color = Color::new(1.0, 0.35, 0.3, 1.0);

/// One line of the room's results table.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ResultRow {
    /// 1: first.
    pub place: u32,
    /// The player's name (or `player #ID` until the roster says).
    pub name: String,
    /// The run's time, ticks.
    pub ticks: u32,
    /// Deaths in the run.
    pub deaths: u32,
    /// Our own run.
    pub ours: bool,
}

/// Whether the room's results table is worth drawing: someone besides us
/// finished (alone, the results card says it all).
pub fn shows_table(results: &[ResultRow]) -> bool {
    results.iter().any(|r| !r.ours)
}

/// Our run as the HUD shows it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunInfo {
    /// Coins picked up in this run.
    pub coins: u32,
    /// Coins in the level.
    pub coins_total: u32,
    /// Deaths in this run.
    pub deaths: u32,
    /// The run's ticks (frozen at the finish).
    pub run_ticks: u32,
    /// Simulation ticks per second.
    pub tick_rate: u32,
    /// Our place once finished.
    pub place: Option<u32>,
}

/// `ticks` at `rate` ticks a second as `m:ss.cc` (hundredths rounded
/// down; minutes grow past 59).
pub fn run_time(ticks: u32, rate: u32) -> String {
    let cs = u64::from(ticks) * 100 / u64::from(rate.max(1));
    format!("{}:{:02}.{:02}", cs / 6000, cs / 100 % 60, cs % 100)
}

/// A run as the HUD's second line says it: `coins 2/13   deaths 1   0:06.86`.
pub fn run_line(run: &RunInfo) -> String {
    format!(
        "coins {}/{}   deaths {}   {}",
        run.coins,
        run.coins_total,
        run.deaths,
        run_time(run.run_ticks, run.tick_rate)
    )
}

/// `1st`, `2nd`, `3rd`, `4th`, ... `11th`, `21st`.
pub fn ordinal(n: u32) -> String {
    let suffix = match (n % 10, n % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{n}{suffix}")
}

/// Our figures, our place, our row.
pub const GOLD: Color = Color::new(1.0, 0.85, 0.25, 1.0);

/// Draws `text` with its baseline at `y`, every character on a whole
/// pixel: the font is a pixel font, and a character drawn between pixels
/// (one line's characters advance by fractions of a pixel) comes out
/// smeared, at 960x540 the figure after `deaths` looked half hidden.
pub fn crisp_text(text: &str, x: f32, y: f32, size: f32, color: Color) {
    let y = y.round();
    let mut pen = x;
    let mut buf = [0u8; 4];
    for c in text.chars() {
        let glyph: &str = c.encode_utf8(&mut buf);
        pen += draw_text(glyph, pen.round(), y, size, color).width;
    }
}

/// A panel of `lines` (text, colour, font size) with its top-left corner
/// at `(x, y)`; returns its height.
pub fn panel(lines: &[(String, Color, f32)], x: f32, y: f32) -> f32 {
    let width = lines
        .iter()
        .map(|(l, _, size)| measure_text(l, None, *size as u16, 1.0).width)
        .fold(0.0, f32::max);
    let height: f32 = lines.iter().map(|(_, _, size)| size + 2.0).sum::<f32>() + 10.0;
    draw_rectangle(x, y, width + 16.0, height, PANEL);
    let mut baseline = y + 5.0;
    for (l, c, size) in lines {
        baseline += size + 2.0;
        crisp_text(l, x + 8.0, baseline - size * 0.22, *size, *c);
    }
    height
}

/// The top-left panel's lines: our name (or whom we watch), our run,
/// when the room moves on, the keys.
fn corner_lines(info: &HudInfo) -> Vec<(String, Color, f32)> {
    let mut lines: Vec<(String, Color, f32)> = match info.spectate {
        Some(line) => vec![(line.to_owned(), WHITE, FONT)],
        None => vec![(info.name.to_owned(), WHITE, 22.0)],
    };
    if let Some(run) = &info.run {
        lines.push((run_line(run), GOLD, FONT));
    }
    if let Some(next) = info.next_level {
        lines.push((next.to_owned(), WHITE, FONT));
    }
    let mut keys = match info.spectate {
        Some(_) => "Tab/Shift+Tab: next player   F: free camera (WASD)".to_owned(),
        None => format!("restart: {}", info.restart_key),
    };
    if let Some(key) = info.levels_key {
        keys.push_str(&format!("   levels: {key}"));
    }
    lines.push((keys, DIM, 14.0));
    lines
}

/// Draws the HUD: our name, coins, deaths and run timer; the network
/// panel and graph when `show_net`; the room's results table; the
/// controls hint; sound notices.
pub fn draw(info: &HudInfo, graph: &NetGraph, now: f64) {
    let mut y = 8.0 + panel(&corner_lines(info), 8.0, 8.0) + 6.0;
    if let Some((text, faster)) = info.split {
        let colour = if faster { FASTER } else { SLOWER };
        y += panel(&[(text.to_owned(), colour, 28.0)], 8.0, y) + 6.0;
    }
    if info.muted {
        y += panel(&[("muted (M)".to_owned(), DIM, 14.0)], 8.0, y) + 6.0;
    }
    if let Some(notice) = info.sound_notice {
        y += panel(&[(notice.to_owned(), DIM, 14.0)], 8.0, y) + 6.0;
    }
    if info.show_net {
        let mut net: Vec<(String, Color, f32)> = vec![(info.status.to_owned(), WHITE, FONT)];
        match info.net {
            Some(n) => {
                net.push((
                    format!(
                        "fps {}   ping {:.1} ms   jitter {:.1} ms   loss {:.1}%",
                        info.fps,
                        n.rtt_ms,
                        n.jitter_ms,
                        n.loss * 100.0
                    ),
                    WHITE,
                    FONT,
                ));
                net.push((
                    format!(
                        "down {:.1} kB/s   up {:.1} kB/s   {:.0} snapshots/s{}",
                        n.bytes_in_per_s / 1000.0,
                        n.bytes_out_per_s / 1000.0,
                        n.snapshot_hz,
                        if n.quiet {
                            " (quiet: nothing moves)"
                        } else {
                            ""
                        }
                    ),
                    DIM,
                    FONT,
                ));
                net.push((
                    format!(
                        "corrections {} ({:.1}/s, last {:.1} px)   input margin {:.1} ticks",
                        n.corrections,
                        n.corrections_per_s,
                        n.last_correction_px,
                        n.input_margin_ticks
                    ),
                    DIM,
                    FONT,
                ));
            }
            None => net.push((format!("fps {}", info.fps), WHITE, FONT)),
        }
        net.push((format!("tick {}", info.tick), DIM, FONT));
        panel(&net, 8.0, y);
        if info.net.is_some() {
            graph.draw(now, screen_width() - 8.0, 8.0);
        }
    }
    let rate = info.run.map_or(60, |r| r.tick_rate);
    if shows_table(info.results) {
        // Top right, under the net graph when it is shown.
        let top = if info.show_net && info.net.is_some() {
            100.0
        } else {
            8.0
        };
        results_table(info.results, rate, top);
    }
    if info.hint_alpha > 0.0 {
        // A page has no quit key: its tab is closed.
        let quit = if cfg!(target_arch = "wasm32") {
            ""
        } else {
            "   Esc quit"
        };
        let help = format!(
            "arrows/WASD move   space/Z jump   down+jump drop   {} restart   T chat   M sound   F3 net   F2 HUD{quit}",
            info.restart_key
        );
        hint(&help, info.hint_alpha);
    }
}

/// The keys' hint, bottom right, at opacity `alpha` (0..=1).
pub fn hint(help: &str, alpha: f32) {
    let dims = measure_text(help, None, 16, 1.0);
    let (x, y) = (screen_width() - dims.width - 14.0, screen_height() - 10.0);
    let a = alpha.clamp(0.0, 1.0);
    draw_rectangle(
        x - 6.0,
        y - 15.0,
        dims.width + 12.0,
        20.0,
        Color {
            a: PANEL.a * a,
            ..PANEL
        },
    );
    crisp_text(help, x, y, 16.0, Color { a, ..DIM });
}

/// Rows of the results table drawn at most (the rest: "... and N more").
pub const TABLE_ROWS: usize = 10;

/// The room's results, top right: place, name, time, deaths; ours in gold.
pub fn results_table(rows: &[ResultRow], rate: u32, top: f32) {
    let mut lines: Vec<(String, Color, f32)> = vec![("finished".to_owned(), DIM, 14.0)];
    for r in rows.iter().take(TABLE_ROWS) {
        lines.push((
            format!(
                "{:>4}  {}  {}  {} {}",
                ordinal(r.place),
                run_time(r.ticks, rate),
                r.name,
                r.deaths,
                if r.deaths == 1 { "death" } else { "deaths" }
            ),
            if r.ours { GOLD } else { WHITE },
            16.0,
        ));
    }
    if rows.len() > TABLE_ROWS {
        lines.push((
            format!("... and {} more", rows.len() - TABLE_ROWS),
            DIM,
            14.0,
        ));
    }
    let width = lines
        .iter()
        .map(|(l, _, size)| measure_text(l, None, *size as u16, 1.0).width)
        .fold(0.0, f32::max);
    panel(&lines, screen_width() - width - 24.0, top);
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

/// How wide `text` is drawn at font size `size`, pixels.
pub fn measure(text: &str, size: f32) -> f32 {
    measure_text(text, None, size as u16, 1.0).width
}

/// Draws `layout` on `panel`: the first paragraph white, the others dim.
fn draw_banner(layout: &BannerLayout, panel: Color) {
    let p = layout.panel;
    draw_rectangle(p.x, p.y, p.w, p.h, panel);
    for (i, (paragraph, line)) in layout.lines.iter().enumerate() {
        let x = (screen_width() - measure(line, layout.size)) / 2.0;
        let colour = if *paragraph == 0 { WHITE } else { DIM };
        crisp_text(line, x, layout.baseline(i), layout.size, colour);
    }
}

/// A centred banner (connecting, waiting), wrapped to the window's width
/// so a long message is never clipped.
pub fn banner(text: &str) {
    let screen = vec2(screen_width(), screen_height());
    draw_banner(&BannerLayout::new(&[text], screen, measure), PANEL);
}

/// Between the bottom of the window and a notice's panel, pixels: room
/// for the keys' hint.
const NOTICE_BOTTOM: f32 = 40.0;

/// A notice of `paragraphs` (the first white, the others dim) on a panel
/// centred near the bottom of the window, above the keys' hint (the
/// middle is where the camera's player is); returns its layout.
pub fn notice(paragraphs: &[&str]) -> BannerLayout {
    let screen = vec2(screen_width(), screen_height());
    let mut layout = BannerLayout::new(paragraphs, screen, measure);
    layout.panel.y = (screen.y - NOTICE_BOTTOM - layout.panel.h).max(BANNER_EDGE);
    draw_banner(&layout, PANEL);
    layout
}

/// The end of a failed session: the scene shaded, and `message` (what
/// went wrong and what to do) on an opaque panel, wrapped to the window
/// and shrunk to fit its height, with how to quit below it. Returns the
/// layout drawn (for the screenshot's description).
pub fn failure(message: &str) -> BannerLayout {
    let screen = vec2(screen_width(), screen_height());
    draw_rectangle(0.0, 0.0, screen.x, screen.y, FAILURE_SHADE);
    let quit = if cfg!(target_arch = "wasm32") {
        "reload the page to try again"
    } else {
        "Esc quits"
    };
    let layout = BannerLayout::new(&[message, quit], screen, measure);
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
    use super::{ordinal, run_time, wrap, BannerLayout};
    use macroquad::math::vec2;

    #[test]
    fn run_times_are_minutes_seconds_hundredths() {
        assert_eq!(run_time(0, 60), "0:00.00");
        assert_eq!(run_time(1, 60), "0:00.01");
        assert_eq!(run_time(59, 60), "0:00.98");
        assert_eq!(run_time(60, 60), "0:01.00");
        assert_eq!(run_time(604, 60), "0:10.06");
        assert_eq!(run_time(60 * 60 + 30, 60), "1:00.50");
        assert_eq!(run_time(60 * 60 * 75, 60), "75:00.00");
        assert_eq!(run_time(3, 30), "0:00.10");
        assert_eq!(
            run_time(u32::MAX, 0),
            run_time(u32::MAX, 1),
            "no division by 0"
        );
    }

    #[test]
    fn places_read_as_ordinals() {
        let got: Vec<String> = [1, 2, 3, 4, 11, 12, 13, 21, 22, 101, 111]
            .into_iter()
            .map(ordinal)
            .collect();
        assert_eq!(
            got,
            [
                "1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "22nd", "101st",
                "111th"
            ]
        );
    }

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
