//! `ledge-server`: host a ledge game.
//!
//! Prints the certificate fingerprint clients must pin, then runs until
//! Ctrl-C or SIGTERM and shuts down gracefully. Options: `--help`, and
//! `docs/SERVER.md`.
//!
//! Exit codes: 0 stopped by Ctrl-C or SIGTERM; 1 could not start (the
//! reason on stderr, prefixed `ledge-server: `, with what to change, e.g.
//! `--bind` when the port is in use) or failed while running; 2 a
//! command-line error.

use std::io::{IsTerminal, Write};
use std::process::ExitCode;

use anyhow::Context;
use clap::{CommandFactory, FromArgMatches};
use ledge_server::config::Cli;
use ledge_server::Server;
use tracing_subscriber::EnvFilter;
/// The exit codes, for `--help`.
const EXIT_CODES: &str = "Exit codes:
  0  stopped by Ctrl-C or SIGTERM
  1  could not start (the reason and what to change are printed on stderr,
     prefixed \"ledge-server: \"; a port in use: choose another with --bind),
     or failed while running
  2  a command-line error";

#[tokio::main]
async fn main() -> ExitCode {
    match run().await {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(std::io::stderr().lock(), "ledge-server: {}", told(&e));
            ExitCode::FAILURE
        }
    }
}

/// An error and its causes on one line, each cause once: most of our
/// errors already say their cause (`cannot bind ...: {source}`), which
/// anyhow's `{:#}` would repeat.
fn told(error: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in error.chain() {
        let cause = cause.to_string();
        if text.contains(&cause) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&cause);
    }
    text
}

async fn run() -> anyhow::Result<()> {
    let matches = Cli::command().after_help(EXIT_CODES).get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    // Logs on stderr, coloured only on a terminal; stdout carries the
    // join instructions. A log line that cannot be written (stderr closed:
    // `ledge-server 2>&1 | head -1`) is dropped: reporting it would
    // `eprintln!` to the same closed stderr, which panics, and a panicking
    // signal task would leave the server deaf to Ctrl-C and SIGTERM.
    tracing_subscriber::fmt()
        .with_env_filter(EnvFilter::try_from_default_env().unwrap_or_else(|_| "info".into()))
        .with_writer(std::io::stderr)
        .with_ansi(std::io::stderr().is_terminal())
        .log_internal_errors(false)
        .init();
    let config = cli.resolve().context("reading the configuration")?;

    let server = Server::bind(config.clone()).with_context(|| {
        format!(
            "starting the server on {} with certificates in {}",
            config.bind,
            config.cert_dir.display()
        )
    })?;
    // Signals first: whoever reads the join instructions may stop the
    // server at once.
    let signals = ShutdownSignals::install().context("installing signal handlers")?;
    let fingerprint = server.fingerprint();
    let port = server.local_addr().port();
    say(format_args!(
        "ledge server listening on {}",
        server.local_addr()
    ));
    if let Some(addr) = server.metrics_addr() {
        say(format_args!("metrics at http://{addr}/metrics"));
    }
    say(format_args!(
        "certificate SHA-256 fingerprint: {fingerprint}"
    ));
    // Players need the same level file (and its settings) until clients
    // download it from the server.
    let level = config
        .level
        .as_ref()
        .map(|p| format!(" --level {}", p.display()))
        .unwrap_or_default();
    say(format_args!(
        "connect with: cargo run --release -p ledge-client -- \
         --connect 127.0.0.1:{port} --cert-hash {fingerprint}{level} --name YOUR_NAME"
    ));

    let shutdown = server.shutdown_handle();
    tokio::spawn(async move {
        let signal = signals.recv().await;
        tracing::info!("{signal} received");
        shutdown.shutdown();
    });
    server.run().await.context("running the server")
}

/// A line on stdout. Unlike `println!`, a closed stdout (`ledge-server |
/// head -1`) is no reason to panic: the server keeps running and still
/// stops on Ctrl-C and SIGTERM.
fn say(line: std::fmt::Arguments<'_>) {
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "{line}").and_then(|()| out.flush());
}

/// Ctrl-C and, on Unix, SIGTERM.
struct ShutdownSignals {
    /// SIGINT, registered at once: `tokio::signal::ctrl_c()` registers only
    /// when first polled, and a Ctrl-C before that killed the process.
    #[cfg(unix)]
    int: tokio::signal::unix::Signal,
    #[cfg(unix)]
    term: tokio::signal::unix::Signal,
}

impl ShutdownSignals {
    /// Registers the handlers now, so a failure stops the start-up.
    fn install() -> std::io::Result<ShutdownSignals> {
        #[cfg(unix)]
        use tokio::signal::unix::{signal, SignalKind};
        Ok(ShutdownSignals {
            #[cfg(unix)]
            int: signal(SignalKind::interrupt())?,
            #[cfg(unix)]
            term: signal(SignalKind::terminate())?,
        })
    }

    /// Resolves on the first signal, naming it.
    async fn recv(mut self) -> &'static str {
        #[cfg(unix)]
        {
            tokio::select! {
                _ = self.int.recv() => "Ctrl-C",
                _ = self.term.recv() => "SIGTERM",
            }
        }
        #[cfg(not(unix))]
        {
            let _ = &mut self;
            Self::ctrl_c().await
        }
    }

    #[cfg(not(unix))]
    async fn ctrl_c() -> &'static str {
        match tokio::signal::ctrl_c().await {
            Ok(()) => "Ctrl-C",
            Err(e) => {
                tracing::error!("cannot listen for Ctrl-C: {e}");
                std::future::pending().await
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_error_says_each_cause_once() {
        let io = std::io::Error::from(std::io::ErrorKind::AddrInUse);
        let inner = anyhow::Error::new(io).context("cannot bind 0.0.0.0:1: address in use");
        let e = inner.context("starting the server");
        assert_eq!(
            told(&e),
            "starting the server: cannot bind 0.0.0.0:1: address in use"
        );
        let plain = anyhow::anyhow!("a").context("b");
        assert_eq!(told(&plain), "b: a");
    }
}
