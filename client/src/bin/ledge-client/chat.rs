//! The room's chat as the window keeps it, without drawing or reading
//! keys: the line being typed (opened by the chat key, T or Enter; closed
//! by Enter, which sends it, or Escape), the lines received (the newest
//! [`SHOWN`] shown, each fading after [`STAYS`] seconds) and the players
//! muted.
//!
//! A line is at most [`MAX_CHAT_LEN`] bytes (a key that would go past it
//! is refused, and the line says so); one the protocol would refuse
//! (control characters, direction overrides, invisible characters:
//! [`check_text`]) is not sent, and the line says why and stays open to be
//! mended. Such characters show in the line as `[U+XXXX]`.
//!
//! Commands, typed in the line: `/mute NAME` hides the lines of the player
//! called `NAME` (exactly, as the chat shows it) from then on, `/unmute
//! NAME` shows them again, `/mute` alone lists the players muted. The
//! chat answers in a line of its own (no sender).

use std::collections::{BTreeSet, VecDeque};

use ledge_shared::protocol::{check_text, is_hidden, MAX_CHAT_LEN};

/// Received lines shown at most, the newest.
pub const SHOWN: usize = 6;
/// Received lines kept (more than shown: the chat stays bounded).
pub const HISTORY: usize = 32;
/// Seconds a received line stays fully shown...
pub const STAYS: f64 = 10.0;
/// ...then fades out over this many seconds.
pub const FADE: f64 = 1.5;

/// A key while the line is open.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Key {
    /// A character typed.
    Char(char),
    /// Deletes the last character.
    Backspace,
    /// Sends the line (or runs its command).
    Enter,
    /// Closes the line unsent.
    Escape,
}

/// A line in the chat: a player's, or the chat's own answer.
#[derive(Debug, Clone, PartialEq)]
pub struct Said {
    /// The sender's name; `None`: the chat itself (a command's answer).
    pub from: Option<String>,
    /// What was said.
    pub text: String,
    /// When it arrived, seconds on the loop's clock.
    pub at: f64,
}

/// A line to draw, with its opacity.
#[derive(Debug, Clone, PartialEq)]
pub struct Shown<'a> {
    /// The sender's name (`None`: the chat's own answer).
    pub from: Option<&'a str>,
    /// The text, as received (the drawing makes it plain).
    pub text: &'a str,
    /// 0..=1.
    pub alpha: f32,
}

/// The line being typed.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
struct Line {
    text: String,
    /// Why the last key or Enter was refused, until the next key.
    error: Option<String>,
}

/// The chat's state.
#[derive(Debug, Default)]
pub struct Chat {
    typing: Option<Line>,
    log: VecDeque<Said>,
    muted: BTreeSet<String>,
}

impl Chat {
    /// Opens the line (empty), if not open.
    pub fn open(&mut self) {
        self.typing.get_or_insert_with(Line::default);
    }

    /// Whether a line is being typed (the game's buttons are released).
    pub fn is_open(&self) -> bool {
        self.typing.is_some()
    }

    /// The line being typed, as drawn (hidden characters spelled out),
    /// and why it was refused, if it was.
    pub fn line(&self) -> Option<(String, Option<&str>)> {
        let line = self.typing.as_ref()?;
        Some((visible(&line.text), line.error.as_deref()))
    }

    /// Handles `key` at `now`; returns a line to send, if Enter sends one
    /// (the line then closes).
    pub fn key(&mut self, key: Key, now: f64) -> Option<String> {
        let line = self.typing.as_mut()?;
        line.error = None;
        match key {
            Key::Char(c) => {
                if line.text.len() + c.len_utf8() > MAX_CHAT_LEN {
                    line.error = Some(format!("{MAX_CHAT_LEN} bytes at most"));
                } else {
                    line.text.push(c);
                }
                None
            }
            Key::Backspace => {
                line.text.pop();
                None
            }
            Key::Escape => {
                self.typing = None;
                None
            }
            Key::Enter => {
                let text = line.text.clone();
                self.enter(&text, now)
            }
        }
    }

    /// Enter on `text`: a command run, a line to send, or a refusal.
    fn enter(&mut self, text: &str, now: f64) -> Option<String> {
        if text.trim().is_empty() {
            self.typing = None;
            return None;
        }
        if let Some(command) = text.strip_prefix('/') {
            return match self.command(command, now) {
                Ok(()) => {
                    self.typing = None;
                    None
                }
                Err(e) => self.refuse(e),
            };
        }
        match refusal(text) {
            Some(why) => self.refuse(why),
            None => {
                self.typing = None;
                Some(text.to_owned())
            }
        }
    }

    /// Keeps the line open, saying `why`.
    fn refuse(&mut self, why: String) -> Option<String> {
        if let Some(line) = &mut self.typing {
            line.error = Some(why);
        }
        None
    }

    /// A line of the chat's own saying `text` (e.g. why the chat cannot
    /// be opened).
    pub fn tell(&mut self, text: &str, now: f64) {
        self.note(text.to_owned(), now);
    }

    /// Says that sending the line just closed failed, and why: a line of
    /// the chat's own.
    pub fn not_sent(&mut self, why: &str, now: f64) {
        self.note(format!("not sent: {why}"), now);
    }

    /// Runs `/command` (without the slash).
    fn command(&mut self, command: &str, now: f64) -> Result<(), String> {
        let (verb, name) = command
            .split_once(' ')
            .map_or((command, ""), |(v, n)| (v, n.trim()));
        match (verb, name) {
            ("mute", "") => {
                let list = if self.muted.is_empty() {
                    "nobody muted".to_owned()
                } else {
                    let names: Vec<&str> = self.muted.iter().map(String::as_str).collect();
                    format!("muted: {}", names.join(", "))
                };
                self.note(list, now);
            }
            ("mute", name) => {
                self.muted.insert(name.to_owned());
                self.note(format!("muted {name} (/unmute {name})"), now);
            }
            ("unmute", "") => return Err("/unmute NAME".to_owned()),
            ("unmute", name) => {
                if !self.muted.remove(name) {
                    return Err(format!("{name} is not muted"));
                }
                self.note(format!("unmuted {name}"), now);
            }
            _ => return Err(format!("unknown command /{verb}: /mute NAME, /unmute NAME")),
        }
        Ok(())
    }

    /// A line of the chat's own.
    fn note(&mut self, text: String, now: f64) {
        self.push(Said {
            from: None,
            text,
            at: now,
        });
    }

    fn push(&mut self, said: Said) {
        if self.log.len() == HISTORY {
            self.log.pop_front();
        }
        self.log.push_back(said);
    }

    /// A line `text` from the player called `from`, received at `now`
    /// (dropped if `from` is muted).
    pub fn receive(&mut self, from: &str, text: &str, now: f64) {
        if self.is_muted(from) {
            return;
        }
        self.push(Said {
            from: Some(from.to_owned()),
            text: text.to_owned(),
            at: now,
        });
    }

    /// Whether the player called `name` is muted.
    pub fn is_muted(&self, name: &str) -> bool {
        self.muted.contains(name)
    }

    /// The players muted, by name.
    pub fn muted(&self) -> impl Iterator<Item = &str> {
        self.muted.iter().map(String::as_str)
    }

    /// The lines to draw at `now`, oldest first: the newest [`SHOWN`],
    /// fading after [`STAYS`] seconds (all shown fully while the line is
    /// open), the faded out left out.
    pub fn shown(&self, now: f64) -> Vec<Shown<'_>> {
        let open = self.is_open();
        let newest = self.log.len().saturating_sub(SHOWN);
        self.log
            .iter()
            .skip(newest)
            .map(|s| Shown {
                from: s.from.as_deref(),
                text: &s.text,
                alpha: if open { 1.0 } else { fade(now - s.at) },
            })
            .filter(|s| s.alpha > 0.0)
            .collect()
    }
}

/// The opacity of a line `age` seconds old.
fn fade(age: f64) -> f32 {
    (1.0 - (age - STAYS) / FADE).clamp(0.0, 1.0) as f32
}

/// Why the protocol would refuse `text` as a chat line ([`check_text`]),
/// if it would: the first character it refuses and what it is, else the
/// protocol's words.
pub fn refusal(text: &str) -> Option<String> {
    let e = check_text("chat text", text, 1, MAX_CHAT_LEN).err()?;
    let why = match text.chars().find(|&c| c.is_control() || is_hidden(c)) {
        Some(c) if c.is_control() => format!("{} is a control character", code(c)),
        Some(c) => format!(
            "{} is a direction override or an invisible character",
            code(c)
        ),
        None => e.to_string(),
    };
    Some(format!("not sent: {why}"))
}

/// `c` as `U+XXXX`.
fn code(c: char) -> String {
    format!("U+{:04X}", u32::from(c))
}

/// `text` with control, direction-override and invisible characters
/// spelled out as `[U+XXXX]`, so the line shows what it holds.
pub fn visible(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_control() || is_hidden(c) {
                format!("[{}]", code(c))
            } else {
                c.to_string()
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn typed(chat: &mut Chat, text: &str) {
        for c in text.chars() {
            assert_eq!(chat.key(Key::Char(c), 0.0), None);
        }
    }

    #[test]
    fn typing_backspace_enter_sends_and_closes() {
        let mut chat = Chat::default();
        assert!(!chat.is_open());
        assert_eq!(chat.key(Key::Char('x'), 0.0), None, "closed: ignored");
        chat.open();
        typed(&mut chat, "hellp");
        chat.key(Key::Backspace, 0.0);
        typed(&mut chat, "o bob");
        assert_eq!(chat.line(), Some(("hello bob".to_owned(), None)));
        assert_eq!(chat.key(Key::Enter, 0.0).as_deref(), Some("hello bob"));
        assert!(!chat.is_open());
        // Escape closes unsent; an empty line sends nothing.
        chat.open();
        typed(&mut chat, "never mind");
        assert_eq!(chat.key(Key::Escape, 0.0), None);
        assert!(!chat.is_open());
        chat.open();
        typed(&mut chat, "   ");
        assert_eq!(chat.key(Key::Enter, 0.0), None);
        assert!(!chat.is_open());
        // Backspace on an empty line does nothing; reopening keeps nothing.
        chat.open();
        chat.key(Key::Backspace, 0.0);
        assert_eq!(chat.line(), Some((String::new(), None)));
    }

    #[test]
    fn the_line_stops_at_the_protocols_limit() {
        let mut chat = Chat::default();
        chat.open();
        typed(&mut chat, &"a".repeat(MAX_CHAT_LEN - 1));
        // A two-byte character would go past 256 bytes: refused, said.
        chat.key(Key::Char('é'), 0.0);
        let (line, error) = chat.line().unwrap();
        assert_eq!(line.len(), MAX_CHAT_LEN - 1);
        assert_eq!(error, Some("256 bytes at most"));
        chat.key(Key::Char('b'), 0.0);
        assert_eq!(chat.line().unwrap().1, None, "the next key clears it");
        chat.key(Key::Char('c'), 0.0);
        let sent = chat.key(Key::Enter, 0.0).expect("sent");
        assert_eq!(sent.len(), MAX_CHAT_LEN);
        assert!(refusal(&sent).is_none());
    }

    #[test]
    fn hidden_and_control_characters_are_refused_with_the_reason() {
        for (bad, name) in [
            ('\u{202E}', "U+202E"),
            ('\u{200B}', "U+200B"),
            ('\u{2066}', "U+2066"),
            ('\t', "U+0009"),
        ] {
            let mut chat = Chat::default();
            chat.open();
            typed(&mut chat, &format!("evil {bad}txt"));
            assert_eq!(chat.key(Key::Enter, 0.0), None, "{name} sent");
            let (line, error) = chat.line().expect("kept open to mend");
            assert_eq!(line, format!("evil [{name}]txt"));
            let error = error.expect("says why");
            assert!(
                error.contains(name) && error.contains("not sent"),
                "{error}"
            );
            // Mended, it goes.
            for _ in 0..4 {
                chat.key(Key::Backspace, 0.0);
            }
            assert_eq!(chat.key(Key::Enter, 0.0).as_deref(), Some("evil "));
        }
        assert!(refusal("plain words, ünïcödé and emoji 🙂").is_none());
    }

    #[test]
    fn muted_players_lines_are_not_shown() {
        let mut chat = Chat::default();
        chat.receive("bob", "one", 0.0);
        chat.open();
        typed(&mut chat, "/mute bob");
        assert_eq!(chat.key(Key::Enter, 1.0), None, "a command is not sent");
        assert!(chat.is_muted("bob") && !chat.is_muted("Bob"));
        chat.receive("bob", "two", 2.0);
        chat.receive("eve", "three", 2.0);
        let texts = |chat: &Chat| -> Vec<String> {
            chat.shown(3.0).iter().map(|s| s.text.to_owned()).collect()
        };
        assert_eq!(texts(&chat), ["one", "muted bob (/unmute bob)", "three"]);
        chat.open();
        typed(&mut chat, "/mute");
        chat.key(Key::Enter, 3.0);
        assert_eq!(chat.muted().collect::<Vec<_>>(), ["bob"]);
        assert_eq!(texts(&chat).last().unwrap(), "muted: bob");
        chat.open();
        typed(&mut chat, "/unmute bob");
        chat.key(Key::Enter, 3.0);
        chat.receive("bob", "four", 3.0);
        assert_eq!(texts(&chat).last().unwrap(), "four");
        // A wrong command keeps the line open and says so.
        chat.open();
        typed(&mut chat, "/unmute bob");
        chat.key(Key::Enter, 3.0);
        assert_eq!(chat.line().unwrap().1, Some("bob is not muted"));
        chat.key(Key::Escape, 3.0);
        chat.open();
        typed(&mut chat, "/kick bob");
        chat.key(Key::Enter, 3.0);
        assert!(chat
            .line()
            .unwrap()
            .1
            .unwrap()
            .contains("unknown command /kick"));
    }

    #[test]
    fn the_newest_lines_show_then_fade_and_history_is_bounded() {
        let mut chat = Chat::default();
        for i in 0..100 {
            chat.receive("bob", &format!("line {i}"), f64::from(i));
        }
        assert_eq!(chat.log.len(), HISTORY);
        // At 100 s the newest six (94..=99) are under 10 s old, one fading.
        let shown = chat.shown(100.0);
        let texts: Vec<&str> = shown.iter().map(|s| s.text).collect();
        assert_eq!(
            texts,
            ["line 94", "line 95", "line 96", "line 97", "line 98", "line 99"]
        );
        assert!(shown.iter().all(|s| s.alpha == 1.0));
        let later = chat.shown(104.75);
        assert_eq!(later.len(), 6);
        assert!((later[0].alpha - 0.5).abs() < 1e-6, "{later:?}");
        assert!(chat.shown(120.0).is_empty(), "all faded");
        // While typing, the newest show fully again.
        chat.open();
        assert_eq!(chat.shown(120.0).len(), SHOWN);
        assert!(chat.shown(120.0).iter().all(|s| s.alpha == 1.0));
        assert_eq!(chat.shown(120.0)[0].from, Some("bob"));
    }
}
