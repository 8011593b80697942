//! The chat on screen, bottom left: the newest lines received, each
//! `name: text` cut to fit (names gold, the chat's own answers dim), and,
//! while typing, the line being typed under them with why it was refused,
//! if it was. Laid out without drawing ([`layout`], with any text
//! measure), so the screenshot's description tells what was drawn.

use macroquad::prelude::*;

use crate::chat::{visible, Shown};
use crate::draw::hud::{crisp_text, DIM, GOLD};

/// Font size of the chat's lines.
pub const SIZE: f32 = 16.0;
/// From one line's baseline to the next.
const LINE: f32 = 20.0;
/// The lines are at most this wide (less on a narrow window).
const MAX_WIDTH: f32 = 640.0;
/// A name takes at most this much of a line.
const MAX_NAME: f32 = 160.0;
const LEFT: f32 = 8.0;
/// The typing line's baseline is this far above the bottom (clear of the
/// controls hint).
const BOTTOM: f32 = 36.0;
const PROMPT: &str = "say: ";
const PANEL: Color = Color::new(0.05, 0.06, 0.1, 0.62);
const REFUSED: Color = Color::new(1.0, 0.45, 0.4, 1.0);
const ELLIPSIS: &str = "...";

/// A received line as drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnLine {
    /// The sender's name as drawn (cut; a colon follows it); `None`: the
    /// chat's own answer.
    pub from: Option<String>,
    /// The text as drawn (plain, cut).
    pub text: String,
    /// Where the name starts, and the text.
    pub x: f32,
    pub text_x: f32,
    pub baseline: f32,
    pub alpha: f32,
}

/// The line being typed as drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnTyping {
    /// Prompt, text (its end, if it does not fit) and cursor.
    pub text: String,
    pub baseline: f32,
    /// Why it was refused, drawn above it.
    pub error: Option<String>,
    /// The panel behind it: x, y, w, h.
    pub panel: Rect,
}

/// The chat as laid out.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ChatView {
    /// Oldest first (top to bottom).
    pub lines: Vec<DrawnLine>,
    pub typing: Option<DrawnTyping>,
}

/// Lays out `shown` and the `typing` line (as [`crate::chat::Chat::line`]
/// gives it) on a `screen`, texts measured by `width` at [`SIZE`].
pub fn layout(
    shown: &[Shown],
    typing: Option<(String, Option<&str>)>,
    screen: Vec2,
    width: impl Fn(&str) -> f32,
) -> ChatView {
    let max = (screen.x - 2.0 * LEFT - 8.0).min(MAX_WIDTH);
    let bottom = screen.y - BOTTOM;
    let typing = typing.map(|(text, error)| {
        let line = format!(
            "{PROMPT}{}_",
            tail(&text, max - width(PROMPT) - width("_"), &width)
        );
        let error = error.map(|e| head(e, max, &width));
        let rows = if error.is_some() { 2.0 } else { 1.0 };
        let top = bottom - SIZE - LINE * (rows - 1.0) - 2.0;
        DrawnTyping {
            text: line,
            baseline: bottom,
            error,
            panel: Rect::new(LEFT - 4.0, top - 2.0, max + 8.0, bottom + 6.0 - top + 2.0),
        }
    });
    let above = typing.as_ref().map_or(bottom - LINE, |t| t.panel.y - 10.0);
    let count = shown.len();
    let lines = shown
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let baseline = above - LINE * (count - 1 - i) as f32;
            let from = s.from.map(|n| head(n, MAX_NAME, &width));
            let text_x = LEFT + from.as_deref().map_or(0.0, |n| width(&format!("{n}: ")));
            DrawnLine {
                text: head(&visible(s.text), max - (text_x - LEFT), &width),
                from,
                x: LEFT,
                text_x,
                baseline,
                alpha: s.alpha,
            }
        })
        .collect();
    ChatView { lines, typing }
}

/// The longest start of `text` at most `max` wide, with `...` when cut.
fn head(text: &str, max: f32, width: &impl Fn(&str) -> f32) -> String {
    let chars: Vec<char> = text.chars().collect();
    if width(text) <= max {
        return text.to_owned();
    }
    let fits = |n: usize| {
        let s: String = chars[..n].iter().collect::<String>() + ELLIPSIS;
        (width(&s) <= max).then_some(s)
    };
    longest(chars.len(), fits).unwrap_or_else(|| ELLIPSIS.to_owned())
}

/// The longest end of `text` at most `max` wide, with `...` before it
/// when cut (the end of a long line being typed is where the cursor is).
fn tail(text: &str, max: f32, width: &impl Fn(&str) -> f32) -> String {
    let chars: Vec<char> = text.chars().collect();
    if width(text) <= max {
        return text.to_owned();
    }
    let fits = |n: usize| {
        let s = String::from(ELLIPSIS) + &chars[chars.len() - n..].iter().collect::<String>();
        (width(&s) <= max).then_some(s)
    };
    longest(chars.len(), fits).unwrap_or_else(|| ELLIPSIS.to_owned())
}

/// The result of `fits` for the largest `n` in `0..total` it accepts
/// (searched by halves: the wider the text, the more it takes).
fn longest(total: usize, fits: impl Fn(usize) -> Option<String>) -> Option<String> {
    let (mut lo, mut hi) = (0, total);
    let mut best = None;
    while lo < hi {
        let mid = (lo + hi) / 2;
        match fits(mid) {
            Some(s) => {
                best = Some(s);
                lo = mid + 1;
            }
            None => hi = mid,
        }
    }
    best.or_else(|| fits(0))
}

/// Draws `view`.
pub fn draw(view: &ChatView) {
    for line in &view.lines {
        let a = line.alpha;
        let w = line.text_x - line.x + measure_text(&line.text, None, SIZE as u16, 1.0).width;
        draw_rectangle(
            line.x - 4.0,
            line.baseline - SIZE + 2.0,
            w + 8.0,
            LINE,
            Color {
                a: PANEL.a * a,
                ..PANEL
            },
        );
        let text_colour = match line.from {
            Some(ref name) => {
                let name = format!("{name}:");
                crisp_text(&name, line.x, line.baseline, SIZE, Color { a, ..GOLD });
                WHITE
            }
            None => DIM,
        };
        crisp_text(
            &line.text,
            line.text_x,
            line.baseline,
            SIZE,
            Color { a, ..text_colour },
        );
    }
    if let Some(t) = &view.typing {
        let p = t.panel;
        draw_rectangle(p.x, p.y, p.w, p.h, Color { a: 0.85, ..PANEL });
        if let Some(error) = &t.error {
            crisp_text(error, LEFT, t.baseline - LINE, SIZE, REFUSED);
        }
        crisp_text(&t.text, LEFT, t.baseline, SIZE, WHITE);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every character 8 px wide.
    fn width(s: &str) -> f32 {
        s.chars().count() as f32 * 8.0
    }

    #[test]
    fn lines_are_cut_to_fit_and_stack_above_the_typing_line() {
        let long = "x".repeat(300);
        let shown = [
            Shown {
                from: Some("bob"),
                text: "hi",
                alpha: 1.0,
            },
            Shown {
                from: Some(&long),
                text: &long,
                alpha: 0.5,
            },
            Shown {
                from: None,
                text: "muted eve",
                alpha: 1.0,
            },
        ];
        let screen = vec2(480.0, 270.0);
        let view = layout(&shown, None, screen, width);
        assert_eq!(view.lines.len(), 3);
        assert_eq!(view.lines[0].from.as_deref(), Some("bob"));
        assert_eq!(view.lines[0].text_x, LEFT + width("bob: "));
        assert_eq!(view.lines[0].text, "hi");
        let cut = &view.lines[1];
        let name = cut.from.as_deref().unwrap();
        assert!(name.ends_with("...") && width(name) <= MAX_NAME, "{name}");
        assert!(cut.text.ends_with("..."));
        assert!(cut.text_x + width(&cut.text) <= screen.x - LEFT, "{cut:?}");
        assert_eq!(view.lines[2].from, None);
        // Oldest at the top, the newest just above the bottom.
        assert!(view.lines[0].baseline < view.lines[1].baseline);
        assert_eq!(view.lines[2].baseline, screen.y - BOTTOM - LINE);
        assert!(view.typing.is_none());

        // Typing: the line's end shows, the refusal above it, the
        // received lines above both.
        let typed = format!("{long}END");
        let view = layout(&shown, Some((typed, Some("not sent: why"))), screen, width);
        let t = view.typing.as_ref().unwrap();
        assert!(
            t.text.starts_with("say: ...") && t.text.ends_with("END_"),
            "{}",
            t.text
        );
        assert!(LEFT + width(&t.text) <= screen.x - LEFT);
        assert_eq!(t.error.as_deref(), Some("not sent: why"));
        assert!(view.lines[2].baseline < t.panel.y + SIZE, "{view:?}");
    }
}
