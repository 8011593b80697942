//! `ledge-bot`: headless bots for load and robustness testing.
//!
//! ```sh
//! ledge-bot --connect 127.0.0.1:4433 --cert-hash HEX --count 8 --brain runner --seconds 30
//! ledge-bot --connect 127.0.0.1:4433 --count 4 --brain misbehave --mode flood,stale
//! ledge-bot --connect 127.0.0.1:4433 --cert-hash HEX --count 256 --brain thin --seconds 60
//! ```
//!
//! Runs N bots in one process on one tokio runtime, each with its own QUIC
//! connection, clock, prediction and brain, and prints one line per bot at
//! the end: ticks, corrections, RTT, whether the server saw it reach the
//! goal, and the levels it played with the runs it finished on each
//! (`levels: "ID" finished N, "ID2" finished M`: a room rotating levels
//! moves its bots on, and they play on there). `--vote N` votes for the
//! level at index N of the server's list once it arrives (`vote: ...` on
//! the line says how it went). Without `--cert-hash` the certificate is trusted on first use
//! (`--known-hosts`, default in the user's configuration folder).
//!
//! `--brain thin` runs thin bots instead (`ledge_client::bot::thin`): the
//! walker's random walk, one input per tick, every snapshot decoded, but no
//! prediction. They are for load generation (`ledge-load --client thin`):
//! a predicting bot re-simulates its whole room, so a small machine cannot
//! run hundreds of them beside the server, and thin ones give the server
//! the same work for a fraction of the CPU.

#[cfg(not(target_arch = "wasm32"))]
mod cli;

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    cli::main()
}

/// Bots speak QUIC, which a browser cannot: in the package's wasm build
/// this binary does nothing, so that `cargo build --target
/// wasm32-unknown-unknown -p ledge-client` builds the package (the browser
/// front end is the `ledge-client` binary).
#[cfg(target_arch = "wasm32")]
fn main() {}
