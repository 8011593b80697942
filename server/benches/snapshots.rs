//! Snapshot bandwidth and encode time per client, full vs delta.
//!
//! `cargo bench -p ledge-server --bench snapshots` prints a Markdown table
//! (the one in docs/PERFORMANCE.md, "Snapshots"). Each scenario runs 10 s
//! of a 60 Hz room sending 30 Hz snapshots to 8 clients through the
//! server's own [`RoomSnapshots`] (capture, per-client delta against the
//! client's ack, envelope encoding). Client `i` acknowledges the snapshot
//! sent `2 + i % 4` snapshots earlier (round trips of 67 to 167 ms), so
//! deltas span several snapshots and clients rarely share a baseline.
//!
//! Scenarios:
//! * idle: 8 players standing still and 200 entities at rest (half of them
//!   platforms, flagged `CLIENT_SIMULATED`);
//! * busy: 8 players running and jumping, 100 platforms on paths (flagged
//!   `CLIENT_SIMULATED` as the game does: never sent) and 100 walkers;
//! * busy, all sent: the same 200 moving entities, all replicated
//!   (platforms not flagged): the worst case;
//! * game: the real `Game` on the embedded default level with 8 players
//!   holding scripted inputs.
//!
//! The synthetic entities are `EntityState`s moved by a few lines here
//! (platforms ping-pong along x at constant speed, walkers walk and turn
//! around every few seconds, players run and jump under gravity).

use std::hint::black_box;
use std::time::{Duration, Instant};

use glam::IVec2;
use ledge_server::snapshots::RoomSnapshots;
use ledge_shared::game::Game;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{EntityState, Message, PlayerId, Snapshot};

const TICK_RATE: u64 = 60;
const INTERVAL: u64 = 2;
const CLIENTS: usize = 8;
const SECONDS: u64 = 10;
/// The usual QUIC datagram limit on a 1280+ byte path.
const DATAGRAM: usize = 1200;
/// Per-datagram overhead on the wire: QUIC short header (1 + 8-byte CID +
/// 1..4 packet number), DATAGRAM frame header (~3), AEAD tag (16), UDP (8)
/// and IPv4 (20) headers: about 58 bytes.
const WIRE_OVERHEAD: usize = 58;

const PLAYER: u8 = 1;
const PLATFORM: u8 = 2;
const WALKER: u8 = 3;
const BASE: u32 = 1 << 30;

/// A synthetic room.
struct Synthetic {
    entities: Vec<EntityState>,
    moving: bool,
}

impl Synthetic {
    fn new(moving: bool, flag_platforms: bool) -> Synthetic {
        let mut entities = Vec::new();
        for p in 0..CLIENTS as u32 {
            entities.push(EntityState {
                id: p + 1,
                kind: PLAYER,
                pos: IVec2::new(4096 * (10 + 7 * p as i32), 4096 * 40),
                flags: 1,
                ..EntityState::zero(p + 1)
            });
        }
        for i in 0..200u32 {
            let platform = i % 2 == 0;
            let speed = if !moving {
                0
            } else if platform {
                64 + (i as i32 % 5) * 32
            } else {
                96 + (i as i32 % 3) * 32
            };
            let flags = if platform {
                if flag_platforms {
                    EntityState::CLIENT_SIMULATED
                } else {
                    0
                }
            } else {
                1 // alive
            };
            entities.push(EntityState {
                id: BASE + i,
                kind: if platform { PLATFORM } else { WALKER },
                pos: IVec2::new(
                    4096 * (20 + (i as i32 * 37) % 900),
                    4096 * (5 + (i as i32 * 13) % 60),
                ),
                vel: IVec2::new(speed, 0),
                flags,
                aux: 0,
            });
        }
        Synthetic { entities, moving }
    }

    fn step(&mut self, tick: u64) -> Vec<EntityState> {
        if self.moving {
            for e in &mut self.entities {
                match e.kind {
                    PLAYER => {
                        let i = e.id as u64;
                        // Run, turning every 3 s; jump every ~1.5 s.
                        let dir = if (tick / 180 + i) % 2 == 0 { 1 } else { -1 };
                        e.vel.x = dir * 512;
                        let phase = (tick + i * 11) % 90;
                        if phase == 0 {
                            e.vel.y = -2048;
                        } else if phase < 40 {
                            e.vel.y += 102; // gravity
                        } else {
                            e.vel.y = 0;
                        }
                        let grounded = e.vel.y == 0;
                        e.flags = grounded as u32 | ((dir < 0) as u32) << 2;
                        e.aux = if grounded { 6 } else { 0 };
                        e.pos += e.vel;
                    }
                    PLATFORM => {
                        // Ping-pong: reverse every 4 s.
                        let period = 240 + (e.id as u64 % 7) * 20;
                        if tick % period == 0 {
                            e.vel.x = -e.vel.x;
                        }
                        e.pos += e.vel;
                    }
                    _ => {
                        // Walkers turn around every few seconds.
                        let period = 150 + (e.id as u64 % 11) * 30;
                        if tick % period == 0 {
                            e.vel.x = -e.vel.x;
                            e.flags ^= 2; // facing left
                        }
                        e.pos += e.vel;
                    }
                }
            }
        }
        self.entities.clone()
    }
}

/// The real game on the default level, 8 players with scripted inputs.
struct RealGame {
    game: Game,
    inputs: Vec<(PlayerId, Buttons)>,
}

impl RealGame {
    fn new() -> RealGame {
        let level = ledge_levels::default_level();
        let mut game = Game::from_level(&level).expect("the default level plays");
        for p in 1..=CLIENTS as u32 {
            game.add_player(PlayerId(p)).unwrap();
        }
        RealGame {
            game,
            inputs: Vec::new(),
        }
    }

    fn step(&mut self, tick: u64) -> Vec<EntityState> {
        self.inputs.clear();
        for p in 1..=CLIENTS as u64 {
            let dir = if (tick / 150 + p) % 2 == 0 {
                Buttons::RIGHT
            } else {
                Buttons::LEFT
            };
            let jump = if (tick + p * 13) % 70 < 12 {
                Buttons::JUMP
            } else {
                0
            };
            self.inputs.push((PlayerId(p as u32), Buttons(dir | jump)));
        }
        self.game.step(&self.inputs);
        self.game.snapshot().entities
    }
}

/// A scenario: the replicated entities after each tick.
type World = Box<dyn FnMut(u64) -> Vec<EntityState>>;

#[derive(Default)]
struct Row {
    replicated: usize,
    delta_bytes: usize,
    /// Delta bytes after the first second (every client acking by then).
    steady_bytes: usize,
    delta_datagrams: usize,
    delta_max: usize,
    delta_on_stream: usize,
    full_bytes: usize,
    full_on_stream: usize,
    capture: Duration,
    delta_encode: Duration,
    full_encode: Duration,
    snapshots: usize,
}

fn run(mut world: impl FnMut(u64) -> Vec<EntityState>) -> Row {
    let mut snaps = RoomSnapshots::new(64);
    let mut sent: Vec<u64> = Vec::new();
    let mut row = Row::default();
    for tick in 1..=TICK_RATE * SECONDS {
        let entities = world(tick);
        if tick % INTERVAL != 0 {
            continue;
        }
        let t = Instant::now();
        let latest = snaps.capture(tick, entities).unwrap();
        row.capture += t.elapsed();
        row.replicated = latest.entities.len();
        let latest = latest.clone();
        for client in 0..CLIENTS {
            let lag = 2 + client % 4;
            let ack = sent.len().checked_sub(lag).map(|i| sent[i]);
            let t = Instant::now();
            let previous = sent.last().copied();
            let snapshot = snaps.encode_for(ack, previous, Some(tick - 1), 2).unwrap();
            let bytes = black_box(snapshot.encode().unwrap());
            row.delta_encode += t.elapsed();
            row.delta_bytes += bytes.len();
            if tick > TICK_RATE {
                row.steady_bytes += bytes.len();
            }
            row.delta_max = row.delta_max.max(bytes.len());
            if bytes.len() > DATAGRAM {
                row.delta_on_stream += 1;
            } else {
                row.delta_datagrams += 1;
            }
            // The same snapshot in full, encoded for this client alone.
            let t = Instant::now();
            let full = Snapshot::new(None, &latest, Some(tick - 1), 2).unwrap();
            let bytes = black_box(full.encode().unwrap());
            row.full_encode += t.elapsed();
            row.full_bytes += bytes.len();
            if bytes.len() > DATAGRAM {
                row.full_on_stream += 1;
            }
        }
        sent.push(tick);
        row.snapshots += 1;
    }
    row
}

fn main() {
    // `cargo test --benches` runs this too: keep that quick.
    if std::env::args().any(|a| a == "--test") {
        let row = run(|t| Synthetic::new(true, true).step(t));
        assert!(row.snapshots > 0);
        return;
    }
    println!(
        "{} s at {TICK_RATE} Hz, snapshots every {INTERVAL} ticks ({} Hz), {CLIENTS} clients \
         acking 2-5 snapshots late; bytes are snapshot datagram payloads (on the wire add \
         ~{WIRE_OVERHEAD} B per datagram of QUIC/UDP/IPv4 headers: {} B/s at {} Hz)\n",
        SECONDS,
        TICK_RATE / INTERVAL,
        WIRE_OVERHEAD * (TICK_RATE / INTERVAL) as usize,
        TICK_RATE / INTERVAL
    );
    println!(
        "| scenario | replicated entities | delta B/s per client (steady, after 1 s) | delta mean / max B | full B/s per client | full mean B (sent on stream) | encode per client per snapshot: delta / full | capture per snapshot |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let mut idle = Synthetic::new(false, true);
    let mut busy = Synthetic::new(true, true);
    let mut busy_all = Synthetic::new(true, false);
    let mut game = RealGame::new();
    let scenarios: [(&str, World); 4] = [
        (
            "idle: 8 players + 200 entities at rest (100 platforms client-simulated)",
            Box::new(move |t| idle.step(t)),
        ),
        (
            "busy: 8 players + 100 platforms (client-simulated) + 100 walkers",
            Box::new(move |t| busy.step(t)),
        ),
        (
            "busy, all sent: 8 players + 200 moving entities replicated",
            Box::new(move |t| busy_all.step(t)),
        ),
        (
            "game: default level, 8 players running and jumping",
            Box::new(move |t| game.step(t)),
        ),
    ];
    for (name, world) in scenarios {
        let row = run(world);
        let per_client = |bytes: usize| bytes as f64 / CLIENTS as f64 / SECONDS as f64;
        let sends = (row.snapshots * CLIENTS) as f64;
        let us = |d: Duration| d.as_secs_f64() * 1e6 / sends;
        println!(
            "| {name} | {} | {:.0} ({:.0}) | {:.0} / {} | {:.0} | {:.0} ({}%) | {:.1} µs / {:.1} µs | {:.1} µs |",
            row.replicated,
            per_client(row.delta_bytes),
            row.steady_bytes as f64 / CLIENTS as f64 / (SECONDS - 1) as f64,
            row.delta_bytes as f64 / sends,
            row.delta_max,
            per_client(row.full_bytes),
            row.full_bytes as f64 / sends,
            (row.full_on_stream as f64 * 100.0 / sends).round(),
            us(row.delta_encode),
            us(row.full_encode),
            row.capture.as_secs_f64() * 1e6 / row.snapshots as f64,
        );
        debug_assert_eq!(row.delta_datagrams + row.delta_on_stream, sends as usize);
    }
}
