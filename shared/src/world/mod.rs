//! Bodies, colliders and the tick pipeline. (Skeleton: being built.)

use crate::input::Buttons;

/// Something that happened during a tick.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Event {}

/// The simulation state.
#[derive(Debug, Default)]
pub struct World {
    tick: u64,
    events: Vec<Event>,
}

impl World {
    /// Runs one fixed tick with one input per controller slot; returns its events.
    pub fn step(&mut self, _inputs: &[Buttons]) -> &[Event] {
        self.tick += 1;
        self.events.clear();
        &self.events
    }

    /// Ticks run so far.
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// A stable 64-bit hash of the whole simulation state.
    pub fn state_hash(&self) -> u64 {
        self.tick
    }
}
