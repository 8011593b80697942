//! What a player can do about each reason a replay does not read or play
//! ([`ReplayError`]), to follow the reason in every message.

use ledge_shared::replay::ReplayError;

/// What to do about `e`.
pub fn advice(e: &ReplayError) -> &'static str {
    match e {
        ReplayError::NotAReplay => {
            "give a replay file saved from a ledge server, or its URL (http://HOST:PORT/replays/ID)"
        }
        // Its message says it: update ledge.
        ReplayError::NewerFormat { .. } => "this version cannot read it",
        ReplayError::Truncated { .. }
        | ReplayError::TrailingBytes { .. }
        | ReplayError::Checksum { .. } => {
            "the file was cut short or changed since the server saved it: download it again"
        }
        ReplayError::TooLarge { .. } | ReplayError::Invalid(_) => {
            "it is not a replay this version of ledge wrote: download it again, or watch it \
             with the server's version of ledge"
        }
        ReplayError::Unplayable { .. } => {
            "its level or its content is not what it was recorded with: download it again"
        }
        ReplayError::Diverged { .. } => {
            "watch it with the version of ledge the server that recorded it runs (what comes \
             before that tick still plays)"
        }
    }
}
