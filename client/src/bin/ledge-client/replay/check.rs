//! `--replay FILE --check`: the whole replay played as fast as the machine
//! goes, every state hash checked, without a window; one line says how it
//! went: `replay OK: 12,345 ticks (3:25.75 of play) in 0.41 s, 30,000
//! ticks/s`.

use std::time::{Duration, Instant};

use ledge_shared::level::Level;
use ledge_shared::replay::{Playback, Replay, ReplayError};

use crate::draw::hud::run_time;

/// A replay played to its end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Checked {
    /// Ticks played.
    pub ticks: u64,
    /// Ticks per second it was recorded at.
    pub tick_rate: u32,
    /// How long playing took.
    pub took: Duration,
}

impl Checked {
    /// The line `--check` prints.
    pub fn line(&self) -> String {
        let secs = self.took.as_secs_f64();
        let rate = if secs > 0.0 {
            (self.ticks as f64 / secs).round() as u64
        } else {
            0
        };
        format!(
            "replay OK: {} ticks ({} of play) in {secs:.2} s, {} ticks/s",
            thousands(self.ticks),
            run_time(
                u32::try_from(self.ticks).unwrap_or(u32::MAX),
                self.tick_rate
            ),
            thousands(rate)
        )
    }
}

/// Plays `replay` on `level` from its start to its end, checking every
/// hash.
pub fn check(level: &Level, replay: Replay) -> Result<Checked, ReplayError> {
    let tick_rate = u32::from(replay.header.tick_rate.max(1));
    let started = Instant::now();
    let mut playback = Playback::new(level, replay)?;
    let ticks = playback.play_to_end()?;
    Ok(Checked {
        ticks,
        tick_rate,
        took: started.elapsed(),
    })
}

/// `n` with a comma every three digits: `12,345`.
pub fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_line_says_ticks_time_of_play_and_speed() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1,000");
        assert_eq!(thousands(12_345_678), "12,345,678");
        let checked = Checked {
            ticks: 12_345,
            tick_rate: 60,
            took: Duration::from_millis(410),
        };
        assert_eq!(
            checked.line(),
            "replay OK: 12,345 ticks (3:25.75 of play) in 0.41 s, 30,110 ticks/s"
        );
    }
}
