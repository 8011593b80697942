//! What the game's window and the replay's window share from frame to
//! frame: the time between frames, a cap on their rate, and how long the
//! "sound off" notice stays.

use std::time::Duration;

use ledge_client::time::Instant;

/// Frames are not drawn faster than this (no vsync under Xvfb).
pub const MAX_FPS: f64 = 240.0;

/// How long "sound off: why" stays on screen, seconds from the start.
pub const SOUND_NOTICE_SECONDS: f64 = 6.0;

/// When the last frame began.
#[derive(Debug)]
pub struct FrameClock {
    last_frame: Instant,
}

impl FrameClock {
    /// A clock whose first frame begins now.
    pub fn new() -> FrameClock {
        FrameClock {
            last_frame: Instant::now(),
        }
    }

    /// The time since the last frame began; this frame begins now.
    pub fn lap(&mut self) -> Duration {
        let frame = self.last_frame.elapsed();
        self.last_frame = Instant::now();
        frame
    }

    /// Waits out the rest of the frame's time at [`MAX_FPS`] (no vsync
    /// under Xvfb or some drivers: do not spin). In a browser the page
    /// paces frames.
    pub fn pace(&self) {
        #[cfg(not(target_arch = "wasm32"))]
        {
            let spent = self.last_frame.elapsed().as_secs_f64();
            if spent < 1.0 / MAX_FPS {
                std::thread::sleep(Duration::from_secs_f64(1.0 / MAX_FPS - spent));
            }
        }
    }
}

/// "sound off: why" (`sound_off`), for the first seconds after the start
/// (`now`, seconds).
pub fn sound_notice(sound_off: Option<&str>, now: f64) -> Option<&str> {
    sound_off.filter(|_| now < SOUND_NOTICE_SECONDS)
}
