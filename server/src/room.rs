//! A room: one authoritative world and its fixed-step tick loop.
//!
//! The room runs as its own task and owns its [`World`] outright; the rest
//! of the server talks to it through a [`RoomHandle`] (commands in, a
//! [`RoomStatus`] watch out), so connection tasks never lock the world.
//! The loop follows a [`TickSchedule`]: ticks run on an absolute grid, a
//! stall is caught up by a bounded number of ticks and logged.

use std::collections::BTreeMap;
use std::time::Instant;

use ledge_shared::input::Buttons;
use ledge_shared::world::World;
use tokio::sync::{mpsc, oneshot, watch};
use tokio::task::JoinHandle;
use tracing::{debug, info, warn};

use crate::clock::TickSchedule;
use crate::protocol::{PlayerId, Welcome};

/// The room's progress, published after every tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RoomStatus {
    /// Ticks simulated so far.
    pub tick: u64,
    /// The world's state hash after that tick.
    pub state_hash: u64,
    /// Players currently in the room.
    pub players: usize,
}

/// How a room runs.
#[derive(Debug, Clone, Copy)]
pub struct RoomConfig {
    /// Fixed tick rate in Hz.
    pub tick_rate: u32,
    /// Most ticks run back to back after a stall; older ones are skipped.
    pub max_catch_up: u32,
}

/// Requests to the room task.
#[derive(Debug)]
enum Command {
    Join {
        name: String,
        reply: oneshot::Sender<Welcome>,
    },
    Leave {
        player_id: PlayerId,
    },
}

/// The room task has stopped (the server is shutting down).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("the room has stopped")]
pub struct RoomClosed;

/// A cheap, cloneable way to talk to a running room. The room stops when
/// the last handle is dropped.
#[derive(Debug, Clone)]
pub struct RoomHandle {
    commands: mpsc::UnboundedSender<Command>,
    status: watch::Receiver<RoomStatus>,
}

impl RoomHandle {
    /// Adds a player; the answer carries the tick and state hash at joining.
    pub async fn join(&self, name: String) -> Result<Welcome, RoomClosed> {
        let (reply, answer) = oneshot::channel();
        self.commands
            .send(Command::Join { name, reply })
            .map_err(|_| RoomClosed)?;
        answer.await.map_err(|_| RoomClosed)
    }

    /// Removes a player (no-op if unknown or the room has stopped).
    pub fn leave(&self, player_id: PlayerId) {
        let _ = self.commands.send(Command::Leave { player_id });
    }

    /// The latest published status.
    pub fn status(&self) -> RoomStatus {
        *self.status.borrow()
    }
}

/// Starts a room owning `world` on the current tokio runtime.
pub fn spawn(world: World, config: RoomConfig) -> (RoomHandle, JoinHandle<()>) {
    let (commands, command_rx) = mpsc::unbounded_channel();
    let (status_tx, status) = watch::channel(RoomStatus {
        tick: world.tick(),
        state_hash: world.state_hash(),
        players: 0,
    });
    let room = Room {
        world,
        players: BTreeMap::new(),
        next_player: 1,
        // The warm-up room has one controller slot; players get their own
        // slots once the world supports them.
        inputs: vec![Buttons::NONE],
        tick_rate: config.tick_rate.max(1),
        max_catch_up: config.max_catch_up,
        commands: command_rx,
        status: status_tx,
    };
    let task = tokio::spawn(room.run());
    (RoomHandle { commands, status }, task)
}

/// A joined player.
#[derive(Debug)]
struct Player {
    name: String,
}

/// The room task's state.
struct Room {
    world: World,
    players: BTreeMap<PlayerId, Player>,
    next_player: u32,
    inputs: Vec<Buttons>,
    tick_rate: u32,
    max_catch_up: u32,
    commands: mpsc::UnboundedReceiver<Command>,
    status: watch::Sender<RoomStatus>,
}

impl Room {
    async fn run(mut self) {
        let mut schedule = TickSchedule::new(Instant::now(), self.tick_rate, self.max_catch_up);
        info!(tick_rate = self.tick_rate, "room started");
        loop {
            let deadline = tokio::time::Instant::from_std(schedule.next_deadline());
            tokio::select! {
                command = self.commands.recv() => match command {
                    Some(command) => self.handle(command),
                    None => break,
                },
                () = tokio::time::sleep_until(deadline) => {
                    let due = schedule.poll(Instant::now());
                    for _ in 0..due.run {
                        self.world.step(&self.inputs);
                    }
                    if due.skipped > 0 {
                        warn!(
                            caught_up = due.run,
                            skipped = due.skipped,
                            tick = self.world.tick(),
                            "tick loop fell behind; skipped ticks"
                        );
                    } else if due.run > 1 {
                        debug!(caught_up = due.run, "tick loop caught up");
                    }
                    self.publish();
                }
            }
        }
        info!(tick = self.world.tick(), "room stopped");
    }

    fn handle(&mut self, command: Command) {
        match command {
            Command::Join { name, reply } => {
                let player_id = PlayerId(self.next_player);
                self.next_player = self.next_player.wrapping_add(1);
                let welcome = Welcome {
                    player_id,
                    tick: self.world.tick(),
                    state_hash: self.world.state_hash(),
                    tick_rate: self.tick_rate,
                };
                info!(%player_id, %name, "player joined");
                self.players.insert(player_id, Player { name });
                // Publish before answering, so a joiner sees itself counted.
                self.publish();
                // The joiner may have gone while the command was queued.
                if reply.send(welcome).is_err() {
                    self.players.remove(&player_id);
                    debug!(%player_id, "joiner gone before the welcome");
                }
            }
            Command::Leave { player_id } => {
                if let Some(player) = self.players.remove(&player_id) {
                    info!(%player_id, name = %player.name, "player left");
                }
            }
        }
        self.publish();
    }

    fn publish(&self) {
        self.status.send_replace(RoomStatus {
            tick: self.world.tick(),
            state_hash: self.world.state_hash(),
            players: self.players.len(),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn config() -> RoomConfig {
        RoomConfig {
            tick_rate: 100,
            max_catch_up: 5,
        }
    }

    #[tokio::test]
    async fn ticks_advance_and_players_join_and_leave() {
        let (room, task) = spawn(ledge_shared::scene::warmup_room(), config());
        tokio::time::sleep(Duration::from_millis(100)).await;
        let first = room.join("ada".into()).await.unwrap();
        assert!(first.tick >= 1, "no tick ran in 100 ms at 100 Hz");
        assert_eq!(first.tick_rate, 100);
        let second = room.join("bob".into()).await.unwrap();
        assert_ne!(first.player_id, second.player_id);
        assert!(second.tick >= first.tick);
        assert_eq!(room.status().players, 2);
        room.leave(first.player_id);
        // A round trip through the room orders us after the leave.
        let third = room.join("cy".into()).await.unwrap();
        assert_eq!(room.status().players, 2);
        assert_ne!(third.player_id, first.player_id);
        drop(room);
        tokio::time::timeout(Duration::from_secs(1), task)
            .await
            .expect("room did not stop when its last handle dropped")
            .unwrap();
    }
}
