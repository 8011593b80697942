//! `ledge-server`: host a ledge game.
//!
//! Prints the certificate fingerprint clients must pin and a join command
//! for each address it can be reached on (every network interface when
//! bound to all of them, loopback for this machine), then runs until
//! Ctrl-C or SIGTERM and shuts down gracefully. Options: `--help`, and
//! `docs/SERVER.md`.
//!
//! Exit codes: 0 stopped by Ctrl-C or SIGTERM; 1 could not start (the
//! reason on stderr, prefixed `ledge-server: `, with what to change, e.g.
//! `--bind` when the port is in use) or failed while running; 2 a
//! command-line error.

use std::io::{IsTerminal, Write};
use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr};
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

fn main() -> ExitCode {
    match start() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(std::io::stderr().lock(), "ledge-server: {}", told(&e));
            ExitCode::FAILURE
        }
    }
}

/// Reads the command line and the configuration, then runs the server on
/// a runtime of `threads` threads (one: a current-thread runtime, every
/// task on the main thread).
fn start() -> anyhow::Result<()> {
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
    let mut builder = match config.threads {
        Some(1) => tokio::runtime::Builder::new_current_thread(),
        _ => tokio::runtime::Builder::new_multi_thread(),
    };
    if let Some(n) = config.threads.filter(|&n| n > 1) {
        builder.worker_threads(n);
    }
    let runtime = builder
        .enable_all()
        .build()
        .context("starting the async runtime")?;
    runtime.block_on(run(config))
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

async fn run(config: ledge_server::config::ServerConfig) -> anyhow::Result<()> {
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
    let bound = server.local_addr();
    say(format_args!(
        "ledge server listening on {}",
        server.local_addr()
    ));
    if let Some(addr) = server.metrics_addr() {
        say(format_args!("metrics at http://{addr}/metrics"));
    }
    let interfaces = if bound.ip().is_unspecified()
        || server.web_addr().is_some_and(|a| a.ip().is_unspecified())
    {
        match if_addrs::get_if_addrs() {
            Ok(list) => list
                .into_iter()
                .filter(|i| i.oper_status != if_addrs::IfOperStatus::Down)
                .map(|i| (i.name.clone(), i.ip()))
                .collect(),
            Err(e) => {
                tracing::warn!("cannot list the network interfaces: {e}");
                Vec::new()
            }
        }
    } else {
        Vec::new()
    };
    if let Some(addr) = server.web_addr() {
        for join in join_addresses(addr, &interfaces) {
            say(format_args!(
                "{}: http://{}/",
                join.who_browser(),
                join.addr
            ));
        }
        let webtransport = match server.webtransport_addr() {
            Some(wt) => format!("WebTransport on UDP port {}", wt.port()),
            None => "no WebTransport".to_owned(),
        };
        say(format_args!(
            "(browsers: add ?room=NAME&name=YOUR_NAME; they connect by WebSocket at /ws or \
             {webtransport})"
        ));
    }
    say(format_args!(
        "certificate SHA-256 fingerprint: {fingerprint}"
    ));
    // Players need nothing but the address: clients download the level.
    let joins = join_addresses(bound, &interfaces);
    for join in &joins {
        say(format_args!(
            "{}: cargo run --release -p ledge-client -- \
             --connect {} --cert-hash {fingerprint} --name YOUR_NAME",
            join.who(),
            join.addr
        ));
    }
    if bound.ip().is_unspecified() && joins.iter().all(|j| j.interface.is_none()) {
        say(format_args!(
            "(no network interface found: players on other machines can join once this \
             one is on a network, at its address and port {})",
            bound.port()
        ));
    }

    // Last, where a host looks: what the level's warnings come to.
    say(format_args!("{}", server.levels().warnings_line()));

    let shutdown = server.shutdown_handle();
    tokio::spawn(async move {
        let signal = signals.recv().await;
        tracing::info!("{signal} received");
        shutdown.shutdown();
    });
    server.run().await.context("running the server")
}

/// An address players can join at.
#[derive(Debug, Clone, PartialEq, Eq)]
struct JoinAddress {
    /// The address to pass to `--connect`.
    addr: SocketAddr,
    /// The network interface it belongs to; `None`: loopback, for players
    /// on this machine (or the one address the server is bound to).
    interface: Option<String>,
}

impl JoinAddress {
    /// Whom the address is for, as the join line starts.
    fn who(&self) -> String {
        match &self.interface {
            None if self.addr.ip().is_loopback() => "join from this machine".to_owned(),
            None => "join from this machine or your network".to_owned(),
            Some(name) => format!("join from your network ({name})"),
        }
    }

    /// Whom the address is for, as a browser's line starts.
    fn who_browser(&self) -> String {
        match &self.interface {
            None if self.addr.ip().is_loopback() => "play in a browser on this machine".to_owned(),
            None => "play in a browser on this machine or your network".to_owned(),
            Some(name) => format!("play in a browser from your network ({name})"),
        }
    }
}

/// The addresses a server bound to `bound` can be joined at, given the
/// machine's interface addresses (`(interface name, address)`): bound to a
/// specific address, just that one; bound to all IPv4 interfaces
/// (`0.0.0.0`), loopback first (for this machine), then every other IPv4
/// address; bound to `[::]`, the same with IPv6 addresses too (IPv6
/// link-local addresses are left out: they need an interface scope to
/// be dialled). Duplicates are dropped.
fn join_addresses(bound: SocketAddr, interfaces: &[(String, IpAddr)]) -> Vec<JoinAddress> {
    let port = bound.port();
    let at = |ip: IpAddr, interface: Option<&String>| JoinAddress {
        addr: SocketAddr::new(ip, port),
        interface: interface.cloned(),
    };
    if !bound.ip().is_unspecified() {
        return vec![at(bound.ip(), None)];
    }
    let v6 = bound.is_ipv6();
    let loopback = if v6 {
        IpAddr::V6(Ipv6Addr::LOCALHOST)
    } else {
        IpAddr::V4(Ipv4Addr::LOCALHOST)
    };
    let mut joins = vec![at(loopback, None)];
    for (name, ip) in interfaces {
        let usable = match ip {
            IpAddr::V4(ip) => !ip.is_loopback() && !ip.is_unspecified(),
            IpAddr::V6(ip) => {
                v6 && !ip.is_loopback()
                    && !ip.is_unspecified()
                    // fe80::/10
                    && (ip.segments()[0] & 0xffc0) != 0xfe80
            }
        };
        if usable && joins.iter().all(|j| j.addr.ip() != *ip) {
            joins.push(at(*ip, Some(name)));
        }
    }
    joins
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

    fn ifaces(list: &[(&str, &str)]) -> Vec<(String, IpAddr)> {
        list.iter()
            .map(|(n, ip)| (n.to_string(), ip.parse().unwrap()))
            .collect()
    }

    fn addrs(joins: &[JoinAddress]) -> Vec<String> {
        joins.iter().map(|j| j.addr.to_string()).collect()
    }

    const MACHINE: &[(&str, &str)] = &[
        ("lo", "127.0.0.1"),
        ("eth0", "192.168.1.20"),
        ("wlan0", "10.0.0.7"),
        ("lo", "::1"),
        ("eth0", "fe80::1c2:3ff:fe4:5"),
        ("eth0", "2001:db8::20"),
        // Listed twice (two interfaces on one address): said once.
        ("br0", "192.168.1.20"),
    ];

    #[test]
    fn all_ipv4_interfaces_loopback_first_then_each_network_address() {
        let joins = join_addresses("0.0.0.0:4433".parse().unwrap(), &ifaces(MACHINE));
        assert_eq!(
            addrs(&joins),
            ["127.0.0.1:4433", "192.168.1.20:4433", "10.0.0.7:4433"]
        );
        assert_eq!(joins[0].who(), "join from this machine");
        assert_eq!(joins[1].who(), "join from your network (eth0)");
        assert_eq!(joins[2].who(), "join from your network (wlan0)");
    }

    #[test]
    fn all_interfaces_of_both_families_add_routable_ipv6_addresses() {
        let joins = join_addresses("[::]:5001".parse().unwrap(), &ifaces(MACHINE));
        assert_eq!(
            addrs(&joins),
            [
                "[::1]:5001",
                "192.168.1.20:5001",
                "10.0.0.7:5001",
                "[2001:db8::20]:5001"
            ]
        );
        assert_eq!(joins[0].who(), "join from this machine");
        assert_eq!(joins[3].who(), "join from your network (eth0)");
    }

    #[test]
    fn a_specific_address_is_the_only_one() {
        for (bound, who) in [
            (
                "192.168.1.20:4433",
                "join from this machine or your network",
            ),
            ("127.0.0.1:4433", "join from this machine"),
            ("[::1]:4433", "join from this machine"),
        ] {
            let joins = join_addresses(bound.parse().unwrap(), &ifaces(MACHINE));
            assert_eq!(addrs(&joins), [bound]);
            assert_eq!(joins[0].who(), who);
        }
    }

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

    #[test]
    fn without_network_interfaces_only_loopback() {
        let joins = join_addresses(
            "0.0.0.0:4433".parse().unwrap(),
            &ifaces(&[("lo", "127.0.0.1")]),
        );
        assert_eq!(addrs(&joins), ["127.0.0.1:4433"]);
        assert!(joins[0].interface.is_none());
    }
}
