//! A replay's heads-up display. Top left, the followed player's panel as
//! in play (its name; coins, deaths and run time), then the replay's own:
//! the time from the replay's start and its length, the speed, paused;
//! what it is (a match, or whose run with its time and place) and whom
//! the camera follows. Top right the room's results; bottom right the
//! keys; at the end, in the middle, "end of replay" with the keys that go
//! on. The lines are made without drawing ([`ReplayLines::of`]) so that
//! the screenshot's description lists them as drawn.

use ledge_client::replay::{Follow, ReplayViewer};
use ledge_shared::replay::ReplayKind;
use macroquad::prelude::*;

use crate::draw::hud::{self, ResultRow, RunInfo, DIM, GOLD};

/// The keys, as the hint at the bottom right says them.
#[cfg(not(target_arch = "wasm32"))]
pub const KEYS_HINT: &str = "Space pause   -/+ speed   Left/Right 5 s   Home/End   Tab follow   F free camera   F2 HUD   Esc quit";
/// The keys, as the hint at the bottom right says them (a page is left by
/// closing it: no Esc).
#[cfg(target_arch = "wasm32")]
pub const KEYS_HINT: &str =
    "Space pause   -/+ speed   Left/Right 5 s   Home/End   Tab follow   F free camera   F2 HUD";

/// What the middle of the screen says at the end: that it ended, and the
/// keys that go on.
#[cfg(not(target_arch = "wasm32"))]
pub const END_TEXT: [&str; 2] = [
    "end of replay",
    "Space or Home: watch again · Left: 5 s back · Esc: quit",
];
/// What the middle of the screen says at the end (in a page: no Esc).
#[cfg(target_arch = "wasm32")]
pub const END_TEXT: [&str; 2] = [
    "end of replay",
    "Space or Home: watch again · Left: 5 s back",
];

/// Failure lines are red.
const FAILED: Color = Color::new(1.0, 0.45, 0.4, 1.0);

/// `speed` as the HUD writes it: `0.25x`, `0.5x`, `1x`, `2x`, `4x`.
pub fn speed_text(speed: f32) -> String {
    format!("{}x", (speed * 100.0).round() / 100.0)
}

/// `ticks` at `rate` a second as `m:ss.cc` (as the run timer).
pub fn time_text(ticks: u64, rate: u32) -> String {
    hud::run_time(u32::try_from(ticks).unwrap_or(u32::MAX), rate)
}

/// The replay panel's lines, as drawn.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReplayLines {
    /// `replay 0:12.50 / 3:25.75   1x   paused` (or `end`, or `seeking
    /// to 3:25.75...` while a seek is under way).
    pub clock: String,
    /// What it is: `ada's run: 0:41.23, 1st   room-1 on Default`, or
    /// `match   room-1 on Default`.
    pub kind: String,
    /// Whom the camera follows: `following ada (Tab: next)   tick 1234`.
    pub follow: String,
    /// Why it stopped playing, if it failed.
    pub failure: Option<String>,
}

impl ReplayLines {
    /// The lines for `viewer` as it stands.
    pub fn of(viewer: &ReplayViewer) -> ReplayLines {
        let rate = viewer.tick_rate();
        let seeking = viewer.seeking().map(|to| {
            let to = to.saturating_sub(viewer.start_tick());
            format!("   seeking to {}...", time_text(to, rate))
        });
        let state = if let Some(seeking) = &seeking {
            seeking.as_str()
        } else if viewer.at_end() && viewer.failure().is_none() {
            "   end"
        } else if viewer.paused() {
            "   paused"
        } else {
            ""
        };
        let clock = format!(
            "replay {} / {}   {}{state}",
            time_text(viewer.elapsed(), rate),
            time_text(viewer.total(), rate),
            speed_text(viewer.speed()),
        );
        let header = &viewer.replay().header;
        let place = format!("{} on {}", header.room, header.level_name);
        let kind = match header.kind {
            ReplayKind::Run {
                player,
                ticks,
                place: finished,
                ..
            } => format!(
                "{}'s run: {}, {}   {place}",
                viewer.name_of(player),
                time_text(ticks, rate),
                hud::ordinal(finished)
            ),
            ReplayKind::Match => format!("match   {place}"),
        };
        let who = match (viewer.follow(), viewer.followed()) {
            (Follow::Free, _) => "free camera (WASD moves it)".to_owned(),
            (_, Some(id)) => format!("following {} (Tab: next)", viewer.name_of(id)),
            (_, None) => "nobody in the game".to_owned(),
        };
        let follow = format!("{who}   tick {}", viewer.tick());
        let failure = viewer.failure().map(|e| {
            format!(
                "stopped at tick {}: {e}",
                viewer.failed_at().unwrap_or_default()
            )
        });
        ReplayLines {
            clock,
            kind,
            follow,
            failure,
        }
    }
}

/// What the replay's HUD shows.
pub struct ReplayHud<'a> {
    /// The followed player's name and run (`None`: a free camera, or
    /// nobody in the game).
    pub followed: Option<(&'a str, RunInfo)>,
    /// The replay panel.
    pub lines: &'a ReplayLines,
    /// The room's results: everyone in the game who finished.
    pub results: &'a [ResultRow],
    /// Ticks per second.
    pub tick_rate: u32,
    /// Sound muted (M).
    pub muted: bool,
    /// "sound off: why", for the first seconds.
    pub sound_notice: Option<&'a str>,
    /// At the end: say so in the middle.
    pub at_end: bool,
}

/// Draws the replay's HUD (see the module documentation).
pub fn draw(info: &ReplayHud) {
    let mut y = 8.0;
    if let Some((name, run)) = &info.followed {
        let lines = vec![
            (name.to_string(), WHITE, 22.0),
            (hud::run_line(run), GOLD, 18.0),
        ];
        y += hud::panel(&lines, 8.0, y) + 6.0;
    }
    let l = info.lines;
    let mut lines = vec![
        (l.clock.clone(), WHITE, 18.0),
        (l.kind.clone(), DIM, 14.0),
        (l.follow.clone(), DIM, 14.0),
    ];
    if let Some(failure) = &l.failure {
        lines.push((failure.clone(), FAILED, 14.0));
    }
    y += hud::panel(&lines, 8.0, y) + 6.0;
    if info.muted {
        y += hud::panel(&[("muted (M)".to_owned(), DIM, 14.0)], 8.0, y) + 6.0;
    }
    if let Some(notice) = info.sound_notice {
        hud::panel(&[(notice.to_owned(), DIM, 14.0)], 8.0, y);
    }
    if !info.results.is_empty() {
        hud::results_table(info.results, info.tick_rate, 8.0);
    }
    hud::hint(KEYS_HINT, 1.0);
    if info.at_end && l.failure.is_none() {
        hud::notice(&END_TEXT);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speeds_and_times_read_as_a_player_expects() {
        let speeds: Vec<String> = ledge_client::replay::SPEEDS
            .iter()
            .map(|&s| speed_text(s))
            .collect();
        assert_eq!(speeds, ["0.25x", "0.5x", "1x", "2x", "4x"]);
        assert_eq!(time_text(12_345, 60), "3:25.75");
        assert_eq!(time_text(0, 60), "0:00.00");
        assert_eq!(time_text(u64::MAX, 60), time_text(u64::from(u32::MAX), 60));
    }
}
