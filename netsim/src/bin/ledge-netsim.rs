//! `ledge-netsim`: a UDP link conditioner between clients and a server.
//!
//! ```text
//! ledge-netsim --listen 127.0.0.1:4434 --server 127.0.0.1:4433 \
//!     --latency-ms 75 --jitter-ms 25 --loss 0.05 --down-burst-loss 0.02
//! ```
//!
//! Clients connect to `--listen` instead of the server. The impairment
//! options apply to both directions; `--up-*` (client to server) and
//! `--down-*` (server to client) override them for one direction.

use std::net::SocketAddr;
use std::time::Duration;

use anyhow::Context;
use clap::{Args, Parser};
use ledge_netsim::{Direction, LinkConfig, Loss, Relay, RelayConfig};
use tracing_subscriber::EnvFilter;

/// A UDP relay that delays, jitters, loses, duplicates and reorders
/// datagrams between clients and a server.
#[derive(Debug, Parser)]
#[command(version)]
struct Cli {
    /// Where clients send (instead of the server).
    #[arg(long)]
    listen: SocketAddr,
    /// The server.
    #[arg(long)]
    server: SocketAddr,
    /// Seed of the random draws (the same seed, the same fates).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Packets in flight per client and direction, at most.
    #[arg(long, default_value_t = 4096)]
    queue: usize,
    /// Clients served at once, at most.
    #[arg(long, default_value_t = 256)]
    max_clients: usize,
    /// Seconds between counter reports (0: never).
    #[arg(long, default_value_t = 5.0)]
    stats_every_s: f64,
    #[command(flatten)]
    both: Both,
    #[command(flatten)]
    up: Up,
    #[command(flatten)]
    down: Down,
}

/// One direction's options, each `None` when not given.
#[derive(Debug, Clone, Copy, Default)]
struct Impairment {
    latency_ms: Option<f64>,
    jitter_ms: Option<f64>,
    loss: Option<f64>,
    burst_loss: Option<f64>,
    burst_len: Option<f64>,
    dup: Option<f64>,
    reorder: Option<f64>,
    reorder_ms: Option<f64>,
}

impl Impairment {
    /// `self`, with `over`'s options where given.
    fn overridden_by(self, over: Impairment) -> Impairment {
        Impairment {
            latency_ms: over.latency_ms.or(self.latency_ms),
            jitter_ms: over.jitter_ms.or(self.jitter_ms),
            loss: over.loss.or(self.loss),
            burst_loss: over.burst_loss.or(self.burst_loss),
            burst_len: over.burst_len.or(self.burst_len),
            dup: over.dup.or(self.dup),
            reorder: over.reorder.or(self.reorder),
            reorder_ms: over.reorder_ms.or(self.reorder_ms),
        }
    }

    fn link(self) -> anyhow::Result<LinkConfig> {
        let ms = |name: &str, v: Option<f64>| -> anyhow::Result<Duration> {
            Duration::try_from_secs_f64(v.unwrap_or(0.0) / 1000.0)
                .with_context(|| format!("{name} must be a non-negative number of milliseconds"))
        };
        let loss = match (self.loss, self.burst_loss) {
            (Some(_), Some(_)) => {
                anyhow::bail!("--loss and --burst-loss exclude each other (for one direction)")
            }
            (Some(p), None) => Loss::Bernoulli { p },
            (None, Some(rate)) => Loss::bursts(rate, self.burst_len.unwrap_or(3.0)),
            (None, None) => Loss::None,
        };
        let config = LinkConfig {
            latency: ms("latency", self.latency_ms)?,
            jitter: ms("jitter", self.jitter_ms)?,
            loss,
            duplicate: self.dup.unwrap_or(0.0),
            reorder: self.reorder.unwrap_or(0.0),
            reorder_delay: ms("reorder delay", self.reorder_ms.or(Some(20.0)))?,
        };
        config.validate()?;
        Ok(config)
    }
}

/// Both directions.
#[derive(Debug, Args)]
struct Both {
    /// One-way delay, milliseconds.
    #[arg(long)]
    latency_ms: Option<f64>,
    /// One-way jitter, milliseconds: delays are uniform in latency ± jitter
    /// (jitter alone never reorders).
    #[arg(long)]
    jitter_ms: Option<f64>,
    /// Random loss probability, 0..1.
    #[arg(long)]
    loss: Option<f64>,
    /// Burst loss (Gilbert-Elliott): long-run loss probability, 0..1.
    #[arg(long)]
    burst_loss: Option<f64>,
    /// Mean burst length, packets [default: 3].
    #[arg(long)]
    burst_len: Option<f64>,
    /// Duplication probability, 0..1.
    #[arg(long)]
    dup: Option<f64>,
    /// Reordering probability, 0..1: a packet is held back by --reorder-ms.
    #[arg(long)]
    reorder: Option<f64>,
    /// How long a reordered packet is held back, milliseconds [default: 20].
    #[arg(long)]
    reorder_ms: Option<f64>,
}

/// Client to server only.
#[derive(Debug, Args)]
struct Up {
    /// --latency-ms, client to server only.
    #[arg(long)]
    up_latency_ms: Option<f64>,
    /// --jitter-ms, client to server only.
    #[arg(long)]
    up_jitter_ms: Option<f64>,
    /// --loss, client to server only.
    #[arg(long)]
    up_loss: Option<f64>,
    /// --burst-loss, client to server only.
    #[arg(long)]
    up_burst_loss: Option<f64>,
    /// --burst-len, client to server only.
    #[arg(long)]
    up_burst_len: Option<f64>,
    /// --dup, client to server only.
    #[arg(long)]
    up_dup: Option<f64>,
    /// --reorder, client to server only.
    #[arg(long)]
    up_reorder: Option<f64>,
    /// --reorder-ms, client to server only.
    #[arg(long)]
    up_reorder_ms: Option<f64>,
}

/// Server to client only.
#[derive(Debug, Args)]
struct Down {
    /// --latency-ms, server to client only.
    #[arg(long)]
    down_latency_ms: Option<f64>,
    /// --jitter-ms, server to client only.
    #[arg(long)]
    down_jitter_ms: Option<f64>,
    /// --loss, server to client only.
    #[arg(long)]
    down_loss: Option<f64>,
    /// --burst-loss, server to client only.
    #[arg(long)]
    down_burst_loss: Option<f64>,
    /// --burst-len, server to client only.
    #[arg(long)]
    down_burst_len: Option<f64>,
    /// --dup, server to client only.
    #[arg(long)]
    down_dup: Option<f64>,
    /// --reorder, server to client only.
    #[arg(long)]
    down_reorder: Option<f64>,
    /// --reorder-ms, server to client only.
    #[arg(long)]
    down_reorder_ms: Option<f64>,
}

impl Cli {
    fn links(&self) -> anyhow::Result<(LinkConfig, LinkConfig)> {
        let b = &self.both;
        let both = Impairment {
            latency_ms: b.latency_ms,
            jitter_ms: b.jitter_ms,
            loss: b.loss,
            burst_loss: b.burst_loss,
            burst_len: b.burst_len,
            dup: b.dup,
            reorder: b.reorder,
            reorder_ms: b.reorder_ms,
        };
        let u = &self.up;
        let up = Impairment {
            latency_ms: u.up_latency_ms,
            jitter_ms: u.up_jitter_ms,
            loss: u.up_loss,
            burst_loss: u.up_burst_loss,
            burst_len: u.up_burst_len,
            dup: u.up_dup,
            reorder: u.up_reorder,
            reorder_ms: u.up_reorder_ms,
        };
        let d = &self.down;
        let down = Impairment {
            latency_ms: d.down_latency_ms,
            jitter_ms: d.down_jitter_ms,
            loss: d.down_loss,
            burst_loss: d.down_burst_loss,
            burst_len: d.down_burst_len,
            dup: d.down_dup,
            reorder: d.down_reorder,
            reorder_ms: d.down_reorder_ms,
        };
        // A direction's --*-loss replaces the shared --burst-loss and the
        // other way round: only one loss model per direction.
        let one_loss = |base: Impairment, over: Impairment| {
            let mut base = base;
            if over.loss.is_some() || over.burst_loss.is_some() {
                base.loss = None;
                base.burst_loss = None;
            }
            base.overridden_by(over)
        };
        let up = one_loss(both, up).link().context("client to server")?;
        let down = one_loss(both, down).link().context("server to client")?;
        Ok((up, down))
    }
}

#[tokio::main]
async fn main() -> anyhow::Result<()> {
    tracing_subscriber::fmt()
        .with_env_filter(
            EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new("info")),
        )
        .init();
    let cli = Cli::parse();
    let (up, down) = cli.links()?;
    let relay = Relay::start(
        cli.listen,
        cli.server,
        RelayConfig {
            up,
            down,
            seed: cli.seed,
            queue: cli.queue,
            max_clients: cli.max_clients,
            ..RelayConfig::default()
        },
    )
    .await
    .with_context(|| format!("cannot listen on {}", cli.listen))?;
    tracing::info!(listen = %relay.local_addr(), server = %cli.server, "relaying");
    tracing::info!("client to server: {up:?}");
    tracing::info!("server to client: {down:?}");
    let every = Duration::try_from_secs_f64(cli.stats_every_s)
        .context("--stats-every-s must be a non-negative number")?;
    let report = |relay: &Relay| {
        let s = relay.stats();
        tracing::info!(
            clients = s.clients,
            "up: {} | down: {}",
            s.direction(Direction::Up),
            s.direction(Direction::Down)
        );
    };
    if every.is_zero() {
        tokio::signal::ctrl_c().await?;
    } else {
        let mut ticker = tokio::time::interval(every);
        ticker.tick().await;
        loop {
            tokio::select! {
                _ = ticker.tick() => report(&relay),
                r = tokio::signal::ctrl_c() => { r?; break; }
            }
        }
    }
    report(&relay);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn links(args: &[&str]) -> anyhow::Result<(LinkConfig, LinkConfig)> {
        let mut all = vec![
            "ledge-netsim",
            "--listen",
            "127.0.0.1:0",
            "--server",
            "127.0.0.1:1",
        ];
        all.extend_from_slice(args);
        Cli::try_parse_from(all)?.links()
    }

    #[test]
    fn shared_options_apply_both_ways_and_overrides_one_way() {
        let (up, down) = links(&[
            "--latency-ms",
            "75",
            "--jitter-ms",
            "25",
            "--loss",
            "0.05",
            "--down-burst-loss",
            "0.1",
            "--down-burst-len",
            "4",
            "--up-latency-ms",
            "10",
        ])
        .unwrap();
        assert_eq!(up.latency, Duration::from_millis(10));
        assert_eq!(down.latency, Duration::from_millis(75));
        assert_eq!(up.jitter, Duration::from_millis(25));
        assert_eq!(down.jitter, Duration::from_millis(25));
        assert_eq!(up.loss, Loss::Bernoulli { p: 0.05 });
        assert_eq!(down.loss, Loss::bursts(0.1, 4.0));
    }

    #[test]
    fn bad_values_are_refused() {
        assert!(links(&["--loss", "1.5"]).is_err());
        assert!(links(&["--latency-ms", "-1"]).is_err());
        assert!(links(&["--loss", "0.1", "--burst-loss", "0.1"]).is_err());
    }
}
