//! `ledge-client`: the macroquad front end.
//!
//! Runs the warm-up room locally at a fixed 60 Hz (arrow keys or WASD,
//! space to jump) and shows the tick and state hash. With `--connect` it
//! also joins a server on a background network thread (macroquad owns the
//! main thread) and shows the welcome. Drawing the world comes later.

mod hud;
mod keys;

use clap::Parser;
use ledge_client::background::{ConnectRequest, NetStatus, NetThread};
use ledge_client::timestep::FixedStep;
use ledge_client::Fingerprint;
use macroquad::prelude::*;
use std::time::Duration;

/// Local simulation rate in Hz (the server's default).
const TICK_RATE: u32 = 60;
/// Most ticks simulated per rendered frame before the backlog is dropped.
const MAX_STEPS_PER_FRAME: u32 = 8;

/// ledge: a networked 2D platformer.
#[derive(Debug, Parser)]
#[command(version)]
struct Cli {
    /// Server to join, as HOST:PORT (without it, play locally).
    #[arg(long, value_name = "HOST:PORT", requires = "cert_hash")]
    connect: Option<String>,
    /// SHA-256 fingerprint of the server certificate (the server prints it).
    #[arg(long, value_name = "HEX", requires = "connect")]
    cert_hash: Option<Fingerprint>,
    /// Player name shown to others.
    #[arg(long, default_value = "player")]
    name: String,
}

fn main() -> anyhow::Result<()> {
    // Parse before opening the window, so `--help` and errors need no display.
    let cli = Cli::parse();
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "info".into()),
        )
        .init();

    let (net, status) = match (cli.connect, cli.cert_hash) {
        (Some(server), Some(cert_fingerprint)) => {
            let request = ConnectRequest {
                server: server.clone(),
                cert_fingerprint,
                player_name: cli.name,
            };
            let net = NetThread::spawn(request)
                .map_err(|e| anyhow::anyhow!("starting the network thread: {e}"))?;
            (Some(net), NetStatus::Connecting(server))
        }
        _ => (None, NetStatus::Offline),
    };

    let conf = macroquad::window::Conf {
        window_title: "ledge".to_owned(),
        window_width: 960,
        window_height: 540,
        ..Default::default()
    };
    // What `#[macroquad::main]` expands to, called directly so the command
    // line is parsed before a window exists.
    macroquad::Window::from_config(conf, game(net, status));
    Ok(())
}

async fn game(net: Option<NetThread>, mut status: NetStatus) {
    let mut world = ledge_shared::scene::warmup_room();
    let mut clock = FixedStep::new(TICK_RATE, MAX_STEPS_PER_FRAME);
    loop {
        if is_key_pressed(KeyCode::Escape) {
            break;
        }
        let buttons = keys::held_buttons();
        let frame = Duration::from_secs_f32(get_frame_time().max(0.0));
        for _ in 0..clock.advance(frame) {
            world.step(&[buttons]);
        }
        if let Some(net) = &net {
            while let Some(event) = net.try_recv() {
                status.apply(event);
            }
        }
        hud::draw(&world, buttons, &status);
        next_frame().await;
    }
    // Leaves the server (if connected) before the window closes.
    drop(net);
}
