//! Scripted input (`--script FILE|INLINE`): which buttons are held at which
//! tick, for tests, demos and screenshots.
//!
//! A script is a list of entries separated by newlines or `;`, each
//! `TICKS -> BUTTONS` (or `TICKS: BUTTONS`):
//!
//! * `TICKS` counts simulated ticks from the start of play (the first tick
//!   after joining, or the first offline tick), starting at 0: `N` (one
//!   tick), `N-M` (inclusive) or `N..M` (`M` excluded);
//! * `BUTTONS` is a list of `left`, `right`, `up`, `down`, `jump` (or
//!   `l r u d j`), `restart` joined by `+`, `,` or spaces; `none` or `-` for nothing.
//!
//! Ticks no entry covers hold nothing; where entries overlap, their buttons
//! combine. `#` starts a comment.
//!
//! ```text
//! 0-59 -> right          # run right for a second
//! 30..34 -> jump         # jumping on the way
//! 120 -> down+jump       # drop through a one-way ledge
//! 130 -> say made it     # a chat line
//! 140 -> levels          # the level list's key (V): opens or closes it
//! 150 -> vote 2          # the number key 2 (votes for level 2 while the list is open)
//! ```

use ledge_shared::input::Buttons;

/// One entry: ticks `start..end` hold `buttons`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Entry {
    start: u64,
    end: u64,
    buttons: u8,
}

/// A key the script presses (not a button: a window's own key).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Press {
    /// The level list's key.
    Levels,
    /// A number key, 1 to 9.
    Number(u32),
}

/// A parsed script.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Script {
    entries: Vec<Entry>,
    /// `(tick, text)`: chat lines typed.
    says: Vec<(u64, String)>,
    /// `(tick, key)`: the window's keys pressed.
    presses: Vec<(u64, Press)>,
}

/// An entry that is not buttons held.
enum Action {
    Say(String),
    Press(Press),
}

impl Script {
    /// Reads `arg`: the file at that path if there is one, else the text
    /// itself.
    pub fn load(arg: &str) -> Result<Script, String> {
        let path = std::path::Path::new(arg);
        if path.is_file() {
            let text = std::fs::read_to_string(path)
                .map_err(|e| format!("reading script {}: {e}", path.display()))?;
            Script::parse(&text).map_err(|e| format!("{}: {e}", path.display()))
        } else {
            Script::parse(arg).map_err(|e| format!("inline script: {e}"))
        }
    }

    /// Parses script text (see the module documentation).
    pub fn parse(text: &str) -> Result<Script, String> {
        let mut entries = Vec::new();
        let mut says = Vec::new();
        let mut presses = Vec::new();
        for (n, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("");
            for part in line.split(';') {
                let part = part.trim();
                if part.is_empty() {
                    continue;
                }
                let at = |e| format!("line {}: {e}", n + 1);
                match parse_action(part).map_err(at)? {
                    Some((tick, Action::Say(text))) => says.push((tick, text)),
                    Some((tick, Action::Press(key))) => presses.push((tick, key)),
                    None => entries.push(parse_entry(part).map_err(at)?),
                }
            }
        }
        Ok(Script {
            entries,
            says,
            presses,
        })
    }

    /// The window's keys pressed at ticks `ticks`, in order.
    pub fn pressed(&self, ticks: std::ops::Range<u64>) -> impl Iterator<Item = Press> + '_ {
        self.presses
            .iter()
            .filter(move |(t, _)| ticks.contains(t))
            .map(|&(_, key)| key)
    }

    /// The chat lines typed at ticks `ticks`, in order.
    pub fn said(&self, ticks: std::ops::Range<u64>) -> impl Iterator<Item = &str> {
        self.says
            .iter()
            .filter(move |(t, _)| ticks.contains(t))
            .map(|(_, text)| text.as_str())
    }

    /// The buttons held at `tick`.
    pub fn at(&self, tick: u64) -> Buttons {
        let bits = self
            .entries
            .iter()
            .filter(|e| (e.start..e.end).contains(&tick))
            .fold(0, |acc, e| acc | e.buttons);
        Buttons(bits)
    }
}

fn parse_entry(part: &str) -> Result<Entry, String> {
    let (ticks, buttons) = part
        .split_once("->")
        .or_else(|| part.split_once(':'))
        .ok_or_else(|| format!("{part:?}: expected `TICKS -> BUTTONS`"))?;
    let (start, end) = parse_ticks(ticks.trim())?;
    let buttons = parse_buttons(buttons.trim())?;
    Ok(Entry {
        start,
        end,
        buttons,
    })
}

/// A `TICKS -> say TEXT`, `TICKS -> levels` or `TICKS -> vote N` entry
/// as its first tick and what it does; `None` if the entry is buttons.
fn parse_action(part: &str) -> Result<Option<(u64, Action)>, String> {
    let Some((ticks, rest)) = part.split_once("->").or_else(|| part.split_once(':')) else {
        return Ok(None);
    };
    let rest = rest.trim();
    let action = if let Some(text) = rest.strip_prefix("say ") {
        Action::Say(text.trim().to_owned())
    } else if rest == "levels" {
        Action::Press(Press::Levels)
    } else if let Some(n) = rest.strip_prefix("vote ") {
        match n.trim().parse::<u32>() {
            Ok(n @ 1..=9) => Action::Press(Press::Number(n)),
            _ => return Err(format!("vote {n:?}: a level number from 1 to 9")),
        }
    } else {
        return Ok(None);
    };
    let (start, _) = parse_ticks(ticks.trim())?;
    Ok(Some((start, action)))
}

fn parse_ticks(s: &str) -> Result<(u64, u64), String> {
    let num = |t: &str| {
        t.trim()
            .parse::<u64>()
            .map_err(|_| format!("{t:?} is not a tick number"))
    };
    let (start, end) = if let Some((a, b)) = s.split_once("..") {
        (num(a)?, num(b)?)
    } else if let Some((a, b)) = s.split_once('-') {
        (num(a)?, num(b)?.saturating_add(1))
    } else {
        let t = num(s)?;
        (t, t.saturating_add(1))
    };
    if end <= start {
        return Err(format!("empty tick range {s:?}"));
    }
    Ok((start, end))
}

fn parse_buttons(s: &str) -> Result<u8, String> {
    let mut bits = 0;
    for word in s.split(['+', ',', ' ', '\t']).filter(|w| !w.is_empty()) {
        bits |= match word.to_ascii_lowercase().as_str() {
            "left" | "l" => Buttons::LEFT,
            "right" | "r" => Buttons::RIGHT,
            "up" | "u" => Buttons::UP,
            "down" | "d" => Buttons::DOWN,
            "jump" | "j" => Buttons::JUMP,
            "restart" => Buttons::RESTART,
            "none" | "-" => 0,
            other => {
                return Err(format!(
                    "unknown button {other:?} (left, right, up, down, jump, restart, none)"
                ))
            }
        };
    }
    Ok(bits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_ranges_buttons_and_comments() {
        let s = Script::parse(
            "0-59 -> right   # run\n30..34: jump; 120 -> down+jump\n\n200..210 -> L,J\n300 -> none",
        )
        .unwrap();
        assert_eq!(s.at(0), Buttons(Buttons::RIGHT));
        assert_eq!(s.at(59), Buttons(Buttons::RIGHT));
        assert_eq!(s.at(60), Buttons::NONE);
        assert_eq!(s.at(31), Buttons(Buttons::RIGHT | Buttons::JUMP));
        assert_eq!(s.at(34), Buttons(Buttons::RIGHT));
        assert_eq!(s.at(120), Buttons(Buttons::DOWN | Buttons::JUMP));
        assert_eq!(s.at(205), Buttons(Buttons::LEFT | Buttons::JUMP));
        assert_eq!(s.at(300), Buttons::NONE);
    }

    #[test]
    fn errors_name_the_line() {
        let e = Script::parse("0-5 -> right\n7 -> fly").unwrap_err();
        assert!(e.contains("line 2") && e.contains("fly"), "{e}");
        assert!(Script::parse("9-3 -> right").is_err());
        assert!(Script::parse("right").is_err());
    }

    #[test]
    fn say_entries_type_chat_lines() {
        let s =
            Script::parse("0-9 -> right; 30 -> say hello bob: gg!\n40..50 -> say  two ").unwrap();
        assert_eq!(s.at(5), Buttons(Buttons::RIGHT));
        assert_eq!(s.at(30), Buttons::NONE, "saying presses nothing");
        assert_eq!(s.said(0..31).collect::<Vec<_>>(), ["hello bob: gg!"]);
        assert_eq!(s.said(31..60).collect::<Vec<_>>(), ["two"]);
        assert_eq!(s.said(41..60).count(), 0, "once, at the first tick");
    }

    #[test]
    fn levels_and_vote_entries_press_the_window_keys() {
        let s = Script::parse("10 -> levels; 20 -> vote 2\n30..40 -> levels").unwrap();
        assert_eq!(s.at(10), Buttons::NONE, "pressing holds no button");
        assert_eq!(s.pressed(0..11).collect::<Vec<_>>(), [Press::Levels]);
        assert_eq!(
            s.pressed(11..100).collect::<Vec<_>>(),
            [Press::Number(2), Press::Levels]
        );
        assert!(Script::parse("5 -> vote 0").is_err());
        assert!(Script::parse("5 -> vote ten").is_err());
    }

    #[test]
    fn inline_when_no_such_file() {
        let s = Script::load("0..2 -> jump").unwrap();
        assert_eq!(s.at(1), Buttons(Buttons::JUMP));
    }
}
