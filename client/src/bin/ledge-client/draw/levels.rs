//! The server's levels: the list panel its key (V) opens, where the number
//! keys vote ([`LevelsView`], laid out without drawing so the screenshot's
//! description and the tests read the same lines); the HUD's line saying
//! when the room moves on ([`next_line`]); and the progress bar of a
//! level downloading ([`progress`]).

use std::time::Duration;

use ledge_shared::protocol::{LevelList, VoteRule};
use macroquad::prelude::*;

use super::hud::{crisp_text, measure, panel, DIM, GOLD};

/// Rows the panel lists at most (the rest: "... and N more"); the number
/// keys vote for the first nine.
pub const MAX_ROWS: usize = 16;
/// Levels the number keys 1-9 can vote for.
pub const VOTE_KEYS: usize = 9;

/// One level of the list, as the panel shows it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LevelRow {
    /// Its number on the panel (1: the first; its number key).
    pub number: usize,
    /// Its name.
    pub name: String,
    /// Votes for it.
    pub votes: u32,
    /// Being played.
    pub current: bool,
    /// Comes next.
    pub next: bool,
    /// The line drawn.
    pub text: String,
}

/// The level list panel, laid out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LevelsView {
    /// How votes count.
    pub rule: VoteRule,
    /// The title line (the rule in words).
    pub title: String,
    /// The levels shown, in rotation order.
    pub rows: Vec<LevelRow>,
    /// Levels not shown (beyond [`MAX_ROWS`]).
    pub more: usize,
    /// The footer lines: when the room moves on, the keys.
    pub footer: Vec<String>,
}

/// What `rule` means, in a few words.
pub fn rule_words(rule: VoteRule) -> &'static str {
    match rule {
        VoteRule::Off => "no votes: the levels come in turn",
        VoteRule::Majority => "vote: more than half of the players moves the room",
        VoteRule::Host => "vote: the host (longest in the room) decides",
    }
}

/// "in 12 s" (rounded up: 0.2 s left is "in 1 s").
fn in_seconds(left: Duration) -> String {
    format!("in {} s", left.as_secs_f64().ceil() as u64)
}

/// The panel for `list`; `next_in`: how long until the room moves on, when
/// decided.
pub fn view(list: &LevelList, next_in: Option<Duration>) -> LevelsView {
    let rows = list
        .levels
        .iter()
        .zip(list.votes.iter().chain(std::iter::repeat(&0)))
        .enumerate()
        .take(MAX_ROWS)
        .map(|(i, (level, &votes))| {
            let current = i == list.current as usize;
            let next = i == list.next as usize && !current;
            let mark = match (current, next) {
                (true, _) => "   < playing",
                (_, true) => "   < next",
                _ => "",
            };
            let noun = if votes == 1 { "vote" } else { "votes" };
            LevelRow {
                number: i + 1,
                name: level.name.clone(),
                votes,
                current,
                next,
                text: format!("{}. {}   {votes} {noun}{mark}", i + 1, level.name),
            }
        })
        .collect();
    let mut footer = Vec::new();
    if let Some(left) = next_in {
        footer.push(format!("next level {}", in_seconds(left)));
    }
    let keys = match (list.rule, list.levels.len()) {
        (VoteRule::Off, _) => "V: close".to_owned(),
        (_, n) if n > VOTE_KEYS => {
            format!("1-{VOTE_KEYS}: vote (the first {VOTE_KEYS})   V: close")
        }
        (_, n) => format!("1-{n}: vote   V: close"),
    };
    footer.push(keys);
    LevelsView {
        rule: list.rule,
        title: format!("levels - {}", rule_words(list.rule)),
        rows,
        more: list.levels.len().saturating_sub(MAX_ROWS),
        footer,
    }
}

/// The HUD's line when the room's move is decided: "next: NAME in N s".
pub fn next_line(list: &LevelList, next_in: Option<Duration>) -> Option<String> {
    let left = next_in.filter(|_| list.change_at.is_some())?;
    let name = &list.levels.get(list.next as usize)?.name;
    Some(format!("next: {name} {}", in_seconds(left)))
}

/// The panel's lines: text, colour, font size.
fn lines(v: &LevelsView) -> Vec<(String, Color, f32)> {
    let mut lines = vec![(v.title.clone(), DIM, 14.0)];
    for row in &v.rows {
        let colour = if row.current {
            GOLD
        } else if row.next {
            WHITE
        } else {
            DIM
        };
        lines.push((row.text.clone(), colour, 18.0));
    }
    if v.more > 0 {
        lines.push((format!("... and {} more", v.more), DIM, 14.0));
    }
    lines.extend(v.footer.iter().map(|f| (f.clone(), DIM, 14.0)));
    lines
}

/// Draws the panel across the middle of the window, a little above it
/// (clear of the HUD's corner and of the chat below).
pub fn draw(v: &LevelsView) {
    let lines = lines(v);
    let width = lines
        .iter()
        .map(|(l, _, size)| measure(l, *size))
        .fold(0.0, f32::max)
        + 16.0;
    // As `panel` makes it.
    let height: f32 = lines.iter().map(|(_, _, size)| size + 2.0).sum::<f32>() + 10.0;
    let x = ((screen_width() - width) / 2.0).max(8.0);
    let y = ((screen_height() - height) * 0.4).max(8.0);
    panel(&lines, x, y);
}

/// "downloading the next level: 120 of 480 KiB".
pub fn progress_text(what: &str, got: u64, total: u64) -> String {
    format!(
        "downloading {what}: {} of {} KiB",
        got / 1024,
        total.div_ceil(1024)
    )
}

/// The part of a download done, 0..=1 (an empty one is done).
pub fn fraction(got: u64, total: u64) -> f32 {
    if total == 0 {
        1.0
    } else {
        (got.min(total) as f64 / total as f64) as f32
    }
}

/// A download's progress near the bottom of the window: `text` above a
/// bar filled to `got` of `total`.
pub fn progress(text: &str, got: u64, total: u64) {
    let (w, h) = (320.0f32.min(screen_width() - 32.0), 10.0);
    let x = (screen_width() - w) / 2.0;
    let y = screen_height() - 90.0;
    let text_w = measure(text, 16.0);
    let panel_w = w.max(text_w) + 24.0;
    draw_rectangle(
        (screen_width() - panel_w) / 2.0,
        y - 26.0,
        panel_w,
        48.0,
        Color::new(0.05, 0.06, 0.1, 0.8),
    );
    crisp_text(text, (screen_width() - text_w) / 2.0, y - 8.0, 16.0, WHITE);
    draw_rectangle_lines(x, y, w, h, 1.0, DIM);
    draw_rectangle(
        x + 1.0,
        y + 1.0,
        (w - 2.0) * fraction(got, total),
        h - 2.0,
        GOLD,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_shared::protocol::LevelChoice;

    fn list(n: usize, rule: VoteRule) -> LevelList {
        LevelList {
            levels: (0..n)
                .map(|i| LevelChoice {
                    id: format!("l{i}"),
                    name: format!("Level {i}"),
                })
                .collect(),
            current: 0,
            next: 1,
            votes: (0..n as u32).map(|i| i % 3).collect(),
            rule,
            change_at: None,
        }
    }

    #[test]
    fn the_panel_numbers_the_levels_marks_the_current_and_next_and_says_the_rule() {
        let v = view(&list(3, VoteRule::Majority), None);
        let texts: Vec<&str> = v.rows.iter().map(|r| r.text.as_str()).collect();
        assert_eq!(
            texts,
            [
                "1. Level 0   0 votes   < playing",
                "2. Level 1   1 vote   < next",
                "3. Level 2   2 votes",
            ]
        );
        assert!(v.title.contains("more than half"), "{}", v.title);
        assert_eq!(v.footer, ["1-3: vote   V: close"]);
        assert_eq!(v.more, 0);

        let v = view(&list(40, VoteRule::Host), Some(Duration::from_millis(4200)));
        assert_eq!(v.rows.len(), MAX_ROWS);
        assert_eq!(v.more, 40 - MAX_ROWS);
        assert_eq!(
            v.footer,
            ["next level in 5 s", "1-9: vote (the first 9)   V: close"]
        );
        let off = view(&list(2, VoteRule::Off), None);
        assert_eq!(off.footer, ["V: close"]);
    }

    #[test]
    fn the_hud_says_what_comes_next_once_it_is_decided() {
        let mut l = list(2, VoteRule::Majority);
        assert_eq!(next_line(&l, Some(Duration::from_secs(3))), None);
        l.change_at = Some(900);
        assert_eq!(
            next_line(&l, Some(Duration::from_millis(2500))).as_deref(),
            Some("next: Level 1 in 3 s")
        );
        assert_eq!(next_line(&l, None), None);
        assert_eq!(fraction(50, 200), 0.25);
        assert_eq!(fraction(9, 0), 1.0);
        assert_eq!(fraction(300, 200), 1.0);
        assert_eq!(
            progress_text("the next level", 2048, 4097),
            "downloading the next level: 2 of 5 KiB"
        );
    }
}
