//! The results card, in the middle once our run is finished: our place,
//! the run's time, deaths and coins; online also where the run stands in
//! the server's records (a new record or personal best, our best time and
//! rank on the level, the level's top ten with our row picked out), or
//! that it is being saved, or why it was not recorded; then how to run
//! again.
//!
//! [`Card::new`] lays the card out without drawing (a test measures text
//! its own way, and the screenshot's description lists the lines as laid
//! out); [`draw`] draws a layout. Names come from the network: they are
//! drawn as plain text, cut to fit the card.

use ledge_shared::protocol::Standing;
use macroquad::prelude::*;

use super::hud::{crisp_text, ordinal, run_time, wrap, RunInfo, DIM, GOLD};

/// Between the window's edges and the card, pixels (the card shrinks to
/// keep it).
const EDGE: f32 = 8.0;
/// Between the card's sides and its text, pixels.
const PAD_X: f32 = 24.0;
/// Above the first line and below the last, pixels.
const PAD_Y: f32 = 12.0;
/// A line's height, in font sizes (its text sits on a baseline one font
/// size below its top).
const LEAD: f32 = 1.3;
/// A top-ten row's height, in font sizes.
const ROW_LEAD: f32 = 1.25;
/// Space before a group of lines (the records, the top ten, the hint).
const GAP: f32 = 6.0;
/// The card's inner width when it speaks of the records, so that it keeps
/// its width from "saving" to the standing, pixels (wider text widens it).
const RECORDS_WIDTH: f32 = 300.0;
/// The font size of the top ten's rows (and of their columns' measures).
const ROW_SIZE: f32 = 16.0;
/// Between the top ten's columns, pixels.
const COLUMN_GAP: f32 = 10.0;
/// What a cut name ends with.
const ELLIPSIS: &str = "...";

/// The card's panel: nearly opaque, so clouds and players behind it do not
/// show through its words.
const CARD_PANEL: Color = Color::new(0.05, 0.06, 0.1, 0.95);
/// Our row of the top ten: a faint gold band behind it.
const OUR_BAND: Color = Color::new(1.0, 0.85, 0.25, 0.16);

/// Where our finished run stands in the server's records, as far as the
/// window knows (offline there are no records: no `Records` at all).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Records<'a> {
    /// The server has not said yet: it says once the run is stored.
    Saving,
    /// Stored: where it stands.
    Recorded(&'a Standing),
    /// Not stored: why, in the server's words.
    NotRecorded(&'a str),
}

impl Records<'_> {
    /// `"saving"`, `"recorded"` or `"not_recorded"` (the screenshot's
    /// description).
    pub fn name(&self) -> &'static str {
        match self {
            Records::Saving => "saving",
            Records::Recorded(_) => "recorded",
            Records::NotRecorded(_) => "not_recorded",
        }
    }
}

/// What a line of the card says.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Says {
    /// `finished 1st`.
    Place,
    /// The run's time, large.
    Time,
    /// Deaths and coins.
    Tally,
    /// `NEW RECORD!` (`record`) or `new personal best!`.
    Headline {
        /// The level's record, not only ours.
        record: bool,
    },
    /// Our best time on the level (this run included) and our rank there.
    Best {
        /// The best time, milliseconds.
        millis: u64,
        /// 1: the level's fastest player.
        rank: u32,
    },
    /// The title over the level's top runs.
    TopTitle,
    /// One of the level's top runs.
    Top {
        /// 1: the fastest.
        place: u32,
        /// The player's name as drawn (cut to fit).
        name: String,
        /// Its best time, milliseconds.
        millis: u64,
        /// Ours: drawn picked out.
        ours: bool,
    },
    /// `saving the run...`.
    Saving,
    /// A line of `not recorded: REASON` (a long reason takes several).
    NotRecorded,
    /// How to run again.
    Again,
}

impl Says {
    /// The line's kind, one word (the screenshot's description).
    pub fn kind(&self) -> &'static str {
        match self {
            Says::Place => "place",
            Says::Time => "time",
            Says::Tally => "tally",
            Says::Headline { .. } => "headline",
            Says::Best { .. } => "best",
            Says::TopTitle => "top_title",
            Says::Top { .. } => "top",
            Says::Saving => "saving",
            Says::NotRecorded => "not_recorded",
            Says::Again => "again",
        }
    }
}

/// A line's colour, by what it means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tone {
    /// Gold: our place, a new record, our row of the top ten.
    Gold,
    /// Green: a new personal best.
    Fresh,
    /// White: the figures.
    Plain,
    /// Grey-blue: titles and hints.
    Dim,
    /// Pale red: the run was not recorded.
    Warn,
}

impl Tone {
    /// The colour drawn.
    pub fn color(self) -> Color {
        match self {
            Tone::Gold => GOLD,
            Tone::Fresh => Color::new(0.45, 1.0, 0.55, 1.0),
            Tone::Plain => WHITE,
            Tone::Dim => DIM,
            Tone::Warn => Color::new(1.0, 0.62, 0.55, 1.0),
        }
    }
}

/// One line of the card as laid out.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// What it says.
    pub says: Says,
    /// Its text as a whole (a top run's columns joined by spaces).
    pub text: String,
    /// The pieces drawn, each with the x of its left end (a top run has
    /// three columns; other lines one piece, centred).
    pub pieces: Vec<(String, f32)>,
    /// Where its text stands, y.
    pub baseline: f32,
    /// Font size, pixels.
    pub size: f32,
    /// Its colour.
    pub tone: Tone,
}

/// The results card as laid out for one window.
#[derive(Debug, Clone, PartialEq)]
pub struct Card {
    /// The panel; every line lies inside it.
    pub panel: Rect,
    /// The lines, top to bottom.
    pub lines: Vec<Line>,
    /// The band behind our row of the top ten, if we are in it.
    pub band: Option<Rect>,
    /// What it says of the records: `None` offline.
    pub records: Option<&'static str>,
}

/// A line before layout: what it says, its pieces (one: centred; three:
/// a top run's place, name and time), size, colour and the space above.
struct Spec {
    says: Says,
    pieces: Vec<String>,
    size: f32,
    tone: Tone,
    gap: f32,
}

impl Spec {
    fn new(says: Says, text: String, size: f32, tone: Tone) -> Spec {
        Spec {
            says,
            pieces: vec![text],
            size,
            tone,
            gap: 0.0,
        }
    }

    fn after_gap(self) -> Spec {
        Spec { gap: GAP, ..self }
    }

    fn height(&self) -> f32 {
        let lead = if self.pieces.len() > 1 {
            ROW_LEAD
        } else {
            LEAD
        };
        self.gap + self.size * lead
    }
}

/// `ms` milliseconds as `m:ss.mmm` (minutes grow past 59): how the records
/// tell times.
pub fn millis_time(ms: u64) -> String {
    format!("{}:{:02}.{:03}", ms / 60_000, ms / 1000 % 60, ms % 1000)
}

/// `text` cut to at most `max` wide (by `width`), ending in `...` when
/// cut; control characters (none should come: names are checked) become
/// spaces, so nothing in it can move the pen.
pub fn cut(text: &str, max: f32, width: impl Fn(&str) -> f32) -> String {
    let plain: String = text
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    if width(&plain) <= max {
        return plain;
    }
    let mut kept: Vec<char> = plain.chars().collect();
    while !kept.is_empty() {
        kept.pop();
        let shorter = format!("{}{ELLIPSIS}", kept.iter().collect::<String>().trim_end());
        if width(&shorter) <= max {
            return shorter;
        }
    }
    ELLIPSIS.to_owned()
}

/// The headline for `standing`, if it earned one.
pub fn headline(standing: &Standing) -> Option<(String, Says, Tone)> {
    if standing.new_record {
        Some((
            "NEW RECORD!".to_owned(),
            Says::Headline { record: true },
            Tone::Gold,
        ))
    } else if standing.new_personal_best {
        Some((
            "new personal best!".to_owned(),
            Says::Headline { record: false },
            Tone::Fresh,
        ))
    } else {
        None
    }
}

/// `best 0:09.016 · #2 on this level`.
pub fn best_line(standing: &Standing) -> String {
    format!(
        "best {} \u{b7} #{} on this level",
        millis_time(standing.personal_best),
        standing.rank
    )
}

/// The run's lines: place, time, deaths and coins.
fn run_lines(run: &RunInfo) -> Vec<Spec> {
    vec![
        Spec::new(
            Says::Place,
            format!("finished {}", ordinal(run.place.unwrap_or(0))),
            30.0,
            Tone::Gold,
        ),
        Spec::new(
            Says::Time,
            run_time(run.run_ticks, run.tick_rate),
            40.0,
            Tone::Plain,
        ),
        Spec::new(
            Says::Tally,
            format!(
                "deaths {}   coins {} of {}",
                run.deaths, run.coins, run.coins_total
            ),
            20.0,
            Tone::Plain,
        ),
    ]
}

/// The records' lines for `records`; `me` is our name (our row of the top
/// ten is the one with it); `width(text, size)` measures (a long reason
/// is wrapped to [`RECORDS_WIDTH`]).
fn records_lines(records: Records, me: &str, width: &impl Fn(&str, f32) -> f32) -> Vec<Spec> {
    let standing = match records {
        Records::Saving => {
            let saving = "saving the run...".to_owned();
            return vec![Spec::new(Says::Saving, saving, 18.0, Tone::Dim).after_gap()];
        }
        Records::NotRecorded(reason) => {
            let text = format!("not recorded: {reason}");
            let lines = wrap(&text, RECORDS_WIDTH, |t| width(t, 16.0));
            let mut specs: Vec<Spec> = lines
                .into_iter()
                .map(|l| Spec::new(Says::NotRecorded, l, 16.0, Tone::Warn))
                .collect();
            specs[0].gap = GAP;
            return specs;
        }
        Records::Recorded(standing) => standing,
    };
    let mut specs = Vec::new();
    if let Some((text, says, tone)) = headline(standing) {
        specs.push(Spec::new(says, text, 24.0, tone));
    }
    let best = Says::Best {
        millis: standing.personal_best,
        rank: standing.rank,
    };
    specs.push(Spec::new(best, best_line(standing), 18.0, Tone::Plain));
    specs[0].gap = GAP;
    if !standing.top.is_empty() {
        let title = "fastest on this level".to_owned();
        specs.push(Spec::new(Says::TopTitle, title, 14.0, Tone::Dim).after_gap());
    }
    for (i, run) in standing.top.iter().enumerate() {
        let place = u32::try_from(i + 1).unwrap_or(u32::MAX);
        let ours = run.name == me;
        let says = Says::Top {
            place,
            name: run.name.clone(),
            millis: run.millis,
            ours,
        };
        specs.push(Spec {
            says,
            pieces: vec![
                format!("{place}."),
                run.name.clone(),
                millis_time(run.millis),
            ],
            size: ROW_SIZE,
            tone: if ours { Tone::Gold } else { Tone::Plain },
            gap: 0.0,
        });
    }
    specs
}

/// Where a top-ten row's columns go in a card whose text starts at
/// `left` and is `inner` wide at scale 1, drawn at `scale`: the place ends
/// at `place_end`, the name starts at `name_at` and may be `name_width`
/// wide, the time ends at the right edge.
struct Columns {
    left: f32,
    inner: f32,
    scale: f32,
    place_end: f32,
    name_at: f32,
    name_width: f32,
}

impl Columns {
    fn new(
        specs: &[Spec],
        (left, inner, scale): (f32, f32, f32),
        width: &impl Fn(&str, f32) -> f32,
    ) -> Columns {
        let widest = |i: usize| {
            specs
                .iter()
                .filter(|s| s.pieces.len() == 3)
                .map(|s| width(&s.pieces[i], ROW_SIZE))
                .fold(0.0f32, f32::max)
        };
        let (place_end, time) = (widest(0), widest(2));
        let name_at = place_end + COLUMN_GAP;
        Columns {
            left,
            inner,
            scale,
            place_end,
            name_at,
            name_width: (inner - name_at - COLUMN_GAP - time).max(0.0),
        }
    }

    /// A top run's pieces: its place ending in the place column, its
    /// name (cut to fit), its time ending at the right edge.
    fn pieces(
        &self,
        [place, name, time]: [String; 3],
        width: &impl Fn(&str, f32) -> f32,
    ) -> Vec<(String, f32)> {
        let at = |x: f32| self.left + x * self.scale;
        let name = cut(&name, self.name_width, |t| width(t, ROW_SIZE));
        let place_at = at(self.place_end - width(&place, ROW_SIZE));
        let time_at = at(self.inner - width(&time, ROW_SIZE));
        vec![(place, place_at), (name, at(self.name_at)), (time, time_at)]
    }

    /// The band behind a row from `top`, `height` high: across the card,
    /// half the margin either side.
    fn band(&self, top: f32, height: f32) -> Rect {
        let margin = PAD_X * self.scale / 2.0;
        Rect::new(
            self.left - margin,
            top,
            self.inner * self.scale + 2.0 * margin,
            height,
        )
    }
}

impl Line {
    fn new(says: Says, pieces: Vec<(String, f32)>, baseline: f32, size: f32, tone: Tone) -> Line {
        let text = pieces
            .iter()
            .map(|(t, _)| t.as_str())
            .collect::<Vec<_>>()
            .join(" ");
        Line {
            says,
            text,
            pieces,
            baseline,
            size,
            tone,
        }
    }
}

impl Card {
    /// Lays out the card for our finished `run` in a window of `screen`
    /// pixels: `records` says where it stands (`None` offline: nothing of
    /// records), `me` is our name, `restart_key` the key that runs again,
    /// `width(text, size)` measures a line. Centred across, a third of the
    /// way down when there is room; shrunk as a whole when the window is
    /// too small for it.
    pub fn new(
        run: &RunInfo,
        restart_key: &str,
        records: Option<Records>,
        me: &str,
        screen: Vec2,
        width: impl Fn(&str, f32) -> f32,
    ) -> Card {
        let mut specs = run_lines(run);
        if let Some(records) = records {
            specs.extend(records_lines(records, me, &width));
        }
        let again = format!("{restart_key}: run again");
        specs.push(Spec::new(Says::Again, again, 18.0, Tone::Dim).after_gap());
        let widest = specs
            .iter()
            .filter(|s| s.pieces.len() == 1)
            .map(|s| width(&s.pieces[0], s.size))
            .fold(0.0f32, f32::max);
        let inner = if records.is_some() {
            widest.max(RECORDS_WIDTH)
        } else {
            widest
        };
        let (w, h) = (
            inner + 2.0 * PAD_X,
            specs.iter().map(Spec::height).sum::<f32>() + 2.0 * PAD_Y,
        );
        // Shrunk as a whole (text widths grow with the font size).
        let scale = ((screen.x - 2.0 * EDGE) / w)
            .min((screen.y - 2.0 * EDGE) / h)
            .clamp(0.05, 1.0);
        let (w, h) = (w * scale, h * scale);
        let x = (screen.x - w) / 2.0;
        let y = ((screen.y - h) * 0.3).max(EDGE.min((screen.y - h) / 2.0));
        let mut card = Card {
            panel: Rect::new(x, y, w, h),
            lines: Vec::new(),
            band: None,
            records: records.map(|r| r.name()),
        };
        card.place(specs, inner, scale, &width);
        card
    }

    /// Places `specs` (laid out at scale 1, `inner` wide) in the panel,
    /// scaled by `scale`: a line's text one font size below its top,
    /// centred, or in the top ten's columns.
    fn place(
        &mut self,
        specs: Vec<Spec>,
        inner: f32,
        scale: f32,
        width: &impl Fn(&str, f32) -> f32,
    ) {
        let left = self.panel.x + PAD_X * scale;
        let columns = Columns::new(&specs, (left, inner, scale), width);
        let centre = self.panel.center().x;
        let mut top = self.panel.y + PAD_Y * scale;
        for spec in specs {
            top += spec.gap * scale;
            let (size, height) = (spec.size * scale, (spec.height() - spec.gap) * scale);
            let mut says = spec.says;
            let pieces = match <[String; 3]>::try_from(spec.pieces) {
                Ok(row) => {
                    let pieces = columns.pieces(row, width);
                    if let Says::Top { name, ours, .. } = &mut says {
                        name.clone_from(&pieces[1].0);
                        if *ours {
                            self.band = Some(columns.band(top, height));
                        }
                    }
                    pieces
                }
                Err(one) => one
                    .into_iter()
                    .map(|t| {
                        let x = centre - width(&t, spec.size) * scale / 2.0;
                        (t, x)
                    })
                    .collect(),
            };
            self.lines
                .push(Line::new(says, pieces, top + size, size, spec.tone));
            top += height;
        }
    }
}

/// Draws `card` as laid out: the panel with a gold rim, our row's band,
/// the lines (on whole pixels: the font is a pixel font).
pub fn draw(card: &Card) {
    let p = card.panel;
    draw_rectangle(p.x, p.y, p.w, p.h, CARD_PANEL);
    draw_rectangle_lines(p.x, p.y, p.w, p.h, 2.0, GOLD);
    if let Some(b) = card.band {
        draw_rectangle(b.x, b.y, b.w, b.h, OUR_BAND);
    }
    for line in &card.lines {
        for (text, x) in &line.pieces {
            crisp_text(text, *x, line.baseline, line.size, line.tone.color());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_shared::protocol::TopRun;

    /// A monospaced font: half the font size per character.
    fn width(text: &str, size: f32) -> f32 {
        text.chars().count() as f32 * size * 0.5
    }

    fn run() -> RunInfo {
        RunInfo {
            coins: 4,
            coins_total: 13,
            deaths: 0,
            run_ticks: 661,
            tick_rate: 60,
            place: Some(1),
        }
    }

    /// A standing of ours ("ada", second) among `names` (fastest first,
    /// a second apart from 9 s).
    fn standing(names: &[&str]) -> Standing {
        Standing {
            millis: 11_016,
            personal_best: 10_016,
            new_personal_best: false,
            new_record: false,
            rank: 2,
            top: names
                .iter()
                .enumerate()
                .map(|(i, n)| TopRun {
                    name: (*n).to_owned(),
                    millis: 9_016 + 1000 * i as u64,
                })
                .collect(),
        }
    }

    fn card(records: Option<Records>, screen: Vec2) -> Card {
        Card::new(&run(), "R", records, "ada", screen, width)
    }

    fn kinds(card: &Card) -> Vec<&'static str> {
        card.lines.iter().map(|l| l.says.kind()).collect()
    }

    fn text_of<'a>(card: &'a Card, kind: &str) -> Vec<&'a str> {
        card.lines
            .iter()
            .filter(|l| l.says.kind() == kind)
            .map(|l| l.text.as_str())
            .collect()
    }

    const SCREEN: Vec2 = Vec2::new(960.0, 540.0);

    #[test]
    fn record_times_are_minutes_seconds_milliseconds() {
        assert_eq!(millis_time(0), "0:00.000");
        assert_eq!(millis_time(9_016), "0:09.016");
        assert_eq!(millis_time(59_999), "0:59.999");
        assert_eq!(millis_time(60_000), "1:00.000");
        assert_eq!(millis_time(75 * 60_000 + 1_005), "75:01.005");
    }

    #[test]
    fn long_names_are_cut_and_nothing_moves_the_pen() {
        let w = |t: &str| t.chars().count() as f32;
        assert_eq!(cut("bob", 10.0, w), "bob");
        assert_eq!(cut("abcdefghijklmnop", 10.0, w), "abcdefg...");
        assert_eq!(cut("abcdef ghijklmnop", 10.0, w), "abcdef...");
        assert_eq!(cut("a\tb\u{1b}[2J", 10.0, w), "a b [2J");
        assert_eq!(cut("anything", 2.0, w), "...");
        assert!(w(&cut(&"x".repeat(32), 12.0, w)) <= 12.0);
    }

    /// Offline: the run alone, as before the records.
    #[test]
    fn offline_the_card_tells_the_run_only() {
        let card = card(None, SCREEN);
        assert_eq!(kinds(&card), ["place", "time", "tally", "again"]);
        assert_eq!(card.records, None);
        assert_eq!(text_of(&card, "place"), ["finished 1st"]);
        assert_eq!(text_of(&card, "time"), ["0:11.01"]);
        assert_eq!(text_of(&card, "tally"), ["deaths 0   coins 4 of 13"]);
        assert_eq!(text_of(&card, "again"), ["R: run again"]);
        assert_eq!(card.band, None);
    }

    #[test]
    fn while_saving_and_when_not_recorded_the_card_says_so() {
        let saving = card(Some(Records::Saving), SCREEN);
        assert_eq!(
            kinds(&saving),
            ["place", "time", "tally", "saving", "again"]
        );
        assert_eq!(text_of(&saving, "saving"), ["saving the run..."]);
        assert_eq!(saving.records, Some("saving"));
        let refused = card(Some(Records::NotRecorded("the records are off")), SCREEN);
        assert_eq!(
            text_of(&refused, "not_recorded"),
            ["not recorded: the records are off"]
        );
        assert_eq!(refused.records, Some("not_recorded"));
        // A long reason wraps inside the card, every word kept.
        let long = "cannot reach the records database at postgres://db.example/records: \
                    connection refused; the server plays on without records";
        let refused = card(Some(Records::NotRecorded(long)), SCREEN);
        let lines = text_of(&refused, "not_recorded");
        assert!(lines.len() > 1, "{lines:?}");
        assert_eq!(
            lines.join(" ").split_whitespace().collect::<Vec<_>>(),
            format!("not recorded: {long}")
                .split_whitespace()
                .collect::<Vec<_>>()
        );
        // Saving or not, the card keeps its width.
        assert_eq!(saving.panel.w, refused.panel.w);
    }

    #[test]
    fn a_standing_shows_the_headline_our_best_and_rank_and_the_top_runs() {
        let plain = standing(&["bob", "ada", "cy"]);
        let card = card(Some(Records::Recorded(&plain)), SCREEN);
        assert_eq!(
            kinds(&card),
            [
                "place",
                "time",
                "tally",
                "best",
                "top_title",
                "top",
                "top",
                "top",
                "again"
            ]
        );
        assert_eq!(card.records, Some("recorded"));
        assert_eq!(
            text_of(&card, "best"),
            ["best 0:10.016 \u{b7} #2 on this level"]
        );
        assert_eq!(
            text_of(&card, "top"),
            ["1. bob 0:09.016", "2. ada 0:10.016", "3. cy 0:11.016"]
        );
        // Our row, and only ours, picked out: gold, on the band.
        let tops: Vec<&Line> = card
            .lines
            .iter()
            .filter(|l| l.says.kind() == "top")
            .collect();
        let ours: Vec<bool> = tops
            .iter()
            .map(|l| matches!(l.says, Says::Top { ours: true, .. }))
            .collect();
        assert_eq!(ours, [false, true, false]);
        assert_eq!(
            tops.iter().map(|l| l.tone).collect::<Vec<_>>(),
            [Tone::Plain, Tone::Gold, Tone::Plain]
        );
        let band = card.band.expect("a band behind our row");
        assert!(band.contains(vec2(band.center().x, tops[1].baseline - 4.0)));
        assert!(!band.contains(vec2(band.center().x, tops[0].baseline - 4.0)));
        // A new personal best, a new record.
        let best = Standing {
            new_personal_best: true,
            ..plain.clone()
        };
        let best = self::card(Some(Records::Recorded(&best)), SCREEN);
        assert_eq!(text_of(&best, "headline"), ["new personal best!"]);
        let record = Standing {
            new_personal_best: true,
            new_record: true,
            rank: 1,
            ..plain
        };
        let record = self::card(Some(Records::Recorded(&record)), SCREEN);
        assert_eq!(text_of(&record, "headline"), ["NEW RECORD!"]);
        assert_eq!(record.lines[3].tone, Tone::Gold);
    }

    /// A full top ten of the longest names: every line inside the card,
    /// the card inside a 960x540 window at full size; in a small window
    /// the whole card shrinks.
    #[test]
    fn a_full_top_ten_fits_the_card_and_the_card_the_window() {
        let long = ["W".repeat(32), "ada".to_owned()];
        let names: Vec<&str> = (0..10)
            .map(|i| long[usize::from(i == 3)].as_str())
            .collect();
        let full = standing(&names);
        for screen in [SCREEN, vec2(1280.0, 720.0), vec2(480.0, 270.0)] {
            let card = card(Some(Records::Recorded(&full)), screen);
            let p = card.panel;
            assert!(
                p.x >= EDGE - 0.01 && p.right() <= screen.x - EDGE + 0.01,
                "{screen}: {p:?}"
            );
            assert!(
                p.y >= EDGE - 0.01 && p.bottom() <= screen.y - EDGE + 0.01,
                "{screen}: {p:?}"
            );
            assert_eq!(text_of(&card, "top").len(), 10);
            let mut last = p.y;
            for line in &card.lines {
                for (text, x) in &line.pieces {
                    let right = x + width(text, line.size);
                    assert!(
                        *x >= p.x + 8.0 && right <= p.right() - 8.0,
                        "{screen}: {text:?} at {x}..{right} outside {p:?}"
                    );
                }
                // Below the line before, its top inside the panel.
                assert!(line.baseline - line.size * 0.8 >= last, "{line:?}");
                assert!(line.baseline + line.size * 0.2 <= p.bottom(), "{line:?}");
                last = line.baseline;
            }
            let cut_names = card
                .lines
                .iter()
                .filter(|l| matches!(&l.says, Says::Top { name, .. } if name.ends_with(ELLIPSIS)));
            assert_eq!(cut_names.count(), 9, "{screen}");
            assert_eq!(
                card.lines
                    .iter()
                    .filter(
                        |l| matches!(&l.says, Says::Top { ours: true, name, .. } if name == "ada")
                    )
                    .count(),
                1
            );
            let full_size = screen.y >= 540.0;
            let row = card.lines.iter().find(|l| l.says.kind() == "top").unwrap();
            assert_eq!(row.size == ROW_SIZE, full_size, "{screen}: {}", row.size);
        }
    }
}
