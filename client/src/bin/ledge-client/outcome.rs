//! How a run ends for the player: lines told outside the window
//! ([`tell`]), a failure that sets the exit code ([`fail`]), and the exit
//! codes themselves. Everything else may tell the player something (the
//! entry points, the game loop, the page's glue), so this sits at the
//! bottom and uses nothing of the front end.

use std::sync::atomic::{AtomicI32, Ordering};

/// Exit code when the session failed (or the game could not start).
pub const EXIT_FAILED: i32 = 1;

/// Exit code when not joined within `--join-timeout` (clap's usage errors
/// exit with 2 too).
pub const EXIT_JOIN_TIMEOUT: i32 = 2;

/// Exit code when `--replay`'s file cannot be read, or is not a replay
/// ledge can read (missing, damaged, cut short, newer, not served).
pub const EXIT_UNREADABLE: i32 = 2;

/// Exit code when the server's certificate is refused.
pub const EXIT_UNTRUSTED: i32 = 3;

/// The process exit code, set by the game loop (macroquad's loop owns the
/// main thread until it ends).
pub static EXIT_CODE: AtomicI32 = AtomicI32::new(0);

/// A line for the player outside the window: on stderr natively, prefixed
/// `ledge-client: ` (a closed stderr is no reason to panic); in the
/// browser's console.
pub fn tell(message: &str) {
    #[cfg(not(target_arch = "wasm32"))]
    {
        use std::io::Write;
        let _ = writeln!(std::io::stderr().lock(), "ledge-client: {message}");
    }
    #[cfg(target_arch = "wasm32")]
    macroquad::logging::error!("ledge-client: {}", message);
}

/// Fails the run: message on stderr, exit code `code` (the first failure's
/// code is kept).
pub fn fail(code: i32, message: &str) {
    tell(message);
    let _ = EXIT_CODE.compare_exchange(0, code, Ordering::Relaxed, Ordering::Relaxed);
}
