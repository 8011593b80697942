//! How the game's state packs into [`crate::protocol::EntityState`]s, and the entity kinds.

use glam::IVec2;

use crate::protocol::EntityState;

/// Ids at and above this are level entities (`ENTITY_ID_BASE + index in
/// Level::entities`); players use their [`crate::protocol::PlayerId`], which
/// must be below it.
pub const ENTITY_ID_BASE: u32 = 1 << 30;

/// Ids at and above this are run records ([`kind::RUN`]): player `p`'s is
/// `RUN_ID_BASE + p` (player ids are below [`ENTITY_ID_BASE`], so these
/// follow every player and level entity).
pub const RUN_ID_BASE: u32 = 1 << 31;

/// The kind byte of each entity type in [`crate::protocol::EntityState::kind`].
pub mod kind {
    /// A player.
    pub const PLAYER: u8 = 1;
    /// A moving platform (flagged [`crate::protocol::EntityState::CLIENT_SIMULATED`]).
    pub const PLATFORM: u8 = 2;
    /// A walker enemy.
    pub const WALKER: u8 = 3;
    /// A coin.
    pub const COIN: u8 = 4;
    /// A springboard (never replicated: no state).
    pub const SPRINGBOARD: u8 = 5;
    /// A checkpoint (never replicated).
    pub const CHECKPOINT: u8 = 6;
    /// A goal (never replicated).
    pub const GOAL: u8 = 7;
    /// A hazard volume (never replicated).
    pub const HAZARD: u8 = 8;
    /// A static block (never replicated).
    pub const BLOCK: u8 = 9;
    /// A player spawn (never replicated).
    pub const SPAWN: u8 = 10;
    /// A player's run record (id [`super::RUN_ID_BASE`] + player id): its
    /// timer, deaths and finishing order ([`super::run_flags`]).
    pub const RUN: u8 = 11;
}

/// Player flag bits ([`crate::protocol::EntityState::flags`] of a player).
pub mod player_flags {
    /// Stood on the ground at the end of the last tick.
    pub const GROUNDED: u32 = 1 << 0;
    /// Jump was held during the last tick (a press is a new hold).
    pub const JUMP_HELD: u32 = 1 << 1;
    /// Faces left.
    pub const FACING_LEFT: u32 = 1 << 2;
    /// Touched a springboard during the last tick (not re-armed yet).
    pub const ON_SPRING: u32 = 1 << 3;
    /// Reached the goal in this run (finished; cleared by a restart).
    pub const WON: u32 = 1 << 4;
    /// Dead, waiting to respawn: `aux` holds the ticks left until the
    /// respawn (at least 1) instead of the four timers, which are all zero
    /// while dead.
    pub const DEAD: u32 = 1 << 5;
    /// Restart ([`crate::input::Buttons::RESTART`]) was held during the
    /// last tick (a press is a new hold).
    pub const RESTART_HELD: u32 = 1 << 6;
    /// The respawn point: bits 16 to 30 hold 0 for the level's spawn, or one
    /// plus the checkpoint's entity index.
    pub const CHECKPOINT_SHIFT: u32 = 16;
    /// Mask of the respawn point bits (15 bits).
    pub const CHECKPOINT_MASK: u32 = 0x7fff << CHECKPOINT_SHIFT;
}

/// Run record layout ([`kind::RUN`]): `pos.x` the run's ticks (running or
/// final), `pos.y` its deaths, `vel.x` 1 while the timer runs (started, not
/// finished) and 0 otherwise, so a running timer extrapolates exactly and
/// costs nothing in a snapshot delta; `vel.y` 0; `aux` the finishing order
/// (0: not finished; see [`super::Game`]'s "Runs"); `flags` these bits.
pub mod run_flags {
    /// The timer started (the player pressed a button that plays).
    pub const STARTED: u32 = 1 << 0;
}

/// Walker flag bits.
pub mod walker_flags {
    /// Not defeated.
    pub const ALIVE: u32 = 1 << 0;
    /// Walking left.
    pub const FACING_LEFT: u32 = 1 << 1;
}

/// Coin flag bits (a collected coin's `aux` is its collector's player id).
pub mod coin_flags {
    /// Picked up.
    pub const COLLECTED: u32 = 1 << 0;
}

/// Platform flag bits (besides [`crate::protocol::EntityState::CLIENT_SIMULATED`]).
pub mod platform_flags {
    /// Solid only from above.
    pub const ONE_WAY: u32 = 1 << 0;
}

/// A player's controller state besides its body's position and velocity.
///
/// Packs into a player's [`crate::protocol::EntityState`]: booleans and the respawn point in
/// `flags` ([`player_flags`]); the four timers, one byte each, in `aux`
/// (bits 0-7 coyote, 8-15 jump buffer, 16-23 jump hold, 24-31 drop-through),
/// or while dead ([`player_flags::DEAD`]) the ticks left until the respawn.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub(crate) struct PlayerState {
    pub grounded: bool,
    pub jump_held: bool,
    pub facing_left: bool,
    pub on_spring: bool,
    /// Finished this run (reached a goal).
    pub won: bool,
    pub restart_held: bool,
    /// Ticks left until the respawn; 0: alive. While dead the four timers
    /// below are zero (a death clears them, nothing sets them).
    pub dead: u16,
    /// Coyote ticks left (refilled while grounded, spent while airborne).
    pub coyote: u8,
    /// Ticks a buffered jump press stays valid.
    pub buffer: u8,
    /// Ticks of light jump gravity left.
    pub hold: u8,
    /// Ticks of drop-through left.
    pub drop: u8,
    /// 0: the level spawn; else 1 + the checkpoint's entity index.
    pub checkpoint: u16,
}

impl PlayerState {
    pub fn flags(&self) -> u32 {
        use player_flags::*;
        (self.grounded as u32 * GROUNDED)
            | (self.jump_held as u32 * JUMP_HELD)
            | (self.facing_left as u32 * FACING_LEFT)
            | (self.on_spring as u32 * ON_SPRING)
            | (self.won as u32 * WON)
            | ((self.dead > 0) as u32 * DEAD)
            | (self.restart_held as u32 * RESTART_HELD)
            | ((self.checkpoint as u32) << CHECKPOINT_SHIFT)
    }

    pub fn aux(&self) -> i32 {
        if self.dead > 0 {
            return self.dead as i32;
        }
        u32::from_le_bytes([self.coyote, self.buffer, self.hold, self.drop]) as i32
    }

    /// The state of `flags` and `aux`; `None` when a bit no state uses is
    /// set, or a dead player's countdown is not in `1..=u16::MAX`.
    pub fn unpack(flags: u32, aux: i32) -> Option<Self> {
        use player_flags::*;
        let known = GROUNDED
            | JUMP_HELD
            | FACING_LEFT
            | ON_SPRING
            | WON
            | DEAD
            | RESTART_HELD
            | CHECKPOINT_MASK;
        if flags & !known != 0 {
            return None;
        }
        let (dead, timers) = if flags & DEAD != 0 {
            let dead = u16::try_from(aux).ok().filter(|&d| d > 0)?;
            (dead, 0u32)
        } else {
            (0, aux as u32)
        };
        let [coyote, buffer, hold, drop] = timers.to_le_bytes();
        Some(Self {
            grounded: flags & GROUNDED != 0,
            jump_held: flags & JUMP_HELD != 0,
            facing_left: flags & FACING_LEFT != 0,
            on_spring: flags & ON_SPRING != 0,
            won: flags & WON != 0,
            restart_held: flags & RESTART_HELD != 0,
            dead,
            coyote,
            buffer,
            hold,
            drop,
            checkpoint: ((flags & CHECKPOINT_MASK) >> CHECKPOINT_SHIFT) as u16,
        })
    }
}

/// Largest run tick count, death count and finishing order: they stop
/// there (saturate), so each fits the non-negative `i32` it packs into.
pub(crate) const RUN_MAX: u32 = i32::MAX as u32;

/// A player's run: what [`kind::RUN`] records carry ([`run_flags`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub(crate) struct RunState {
    /// The timer started: the player pressed a button that plays.
    pub started: bool,
    /// Ticks run: counting while started and not finished.
    pub ticks: u32,
    /// Deaths in this run (not counted after finishing).
    pub deaths: u32,
    /// Finishing order in the room: 0 until finished, then one more than
    /// the largest order of the players in the game when it finished.
    pub order: u32,
}

impl RunState {
    /// The timer runs: started and not finished.
    pub fn running(&self) -> bool {
        self.started && self.order == 0
    }

    /// One tick of the timer (while it runs).
    pub fn tick(&mut self) {
        if self.running() {
            self.ticks = (self.ticks + 1).min(RUN_MAX);
        }
    }

    /// Player `id`'s run record.
    pub fn to_entity(self, id: u32) -> EntityState {
        EntityState {
            id: RUN_ID_BASE + id,
            kind: kind::RUN,
            pos: IVec2::new(self.ticks as i32, self.deaths as i32),
            vel: IVec2::new(self.running() as i32, 0),
            flags: self.started as u32 * run_flags::STARTED,
            aux: self.order as i32,
        }
    }

    /// The run of a record; `Err` names what is not a record
    /// [`RunState::to_entity`] makes (negative counts, unknown flags, a
    /// timer not started with ticks, a velocity that does not match).
    pub fn from_entity(e: &EntityState) -> Result<Self, &'static str> {
        if e.flags & !run_flags::STARTED != 0 {
            return Err("unknown run flag bits");
        }
        if e.pos.x < 0 || e.pos.y < 0 || e.aux < 0 {
            return Err("a negative tick count, death count or order");
        }
        let run = RunState {
            started: e.flags & run_flags::STARTED != 0,
            ticks: e.pos.x as u32,
            deaths: e.pos.y as u32,
            order: e.aux as u32,
        };
        if !run.started && run.ticks != 0 {
            return Err("ticks counted before the timer started");
        }
        if e.vel != IVec2::new(run.running() as i32, 0) {
            return Err("the velocity does not say whether the timer runs");
        }
        Ok(run)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn player_state_round_trips() {
        let s = PlayerState {
            grounded: true,
            jump_held: false,
            facing_left: true,
            on_spring: true,
            won: false,
            restart_held: true,
            dead: 0,
            coyote: 3,
            buffer: 254,
            hold: 17,
            drop: 9,
            checkpoint: 0x7fff,
        };
        assert_eq!(PlayerState::unpack(s.flags(), s.aux()), Some(s));
        assert_eq!(s.flags() & EntityState::CLIENT_SIMULATED, 0);
        assert_eq!(PlayerState::unpack(1 << 9, 0), None);
        // Dead: the countdown in aux, the timers zero.
        let d = PlayerState {
            dead: 1200,
            won: true,
            coyote: 0,
            buffer: 0,
            hold: 0,
            drop: 0,
            ..s
        };
        assert_eq!(d.aux(), 1200);
        assert_ne!(d.flags() & player_flags::DEAD, 0);
        assert_eq!(PlayerState::unpack(d.flags(), d.aux()), Some(d));
        for bad in [0, -1, 65536] {
            assert_eq!(PlayerState::unpack(d.flags(), bad), None, "{bad}");
        }
    }

    #[test]
    fn run_records_round_trip_and_are_strict() {
        let runs = [
            RunState::default(),
            RunState {
                started: true,
                ticks: 0,
                deaths: 0,
                order: 0,
            },
            RunState {
                started: true,
                ticks: 1234,
                deaths: 7,
                order: 0,
            },
            RunState {
                started: true,
                ticks: RUN_MAX,
                deaths: RUN_MAX,
                order: RUN_MAX,
            },
            RunState {
                started: false,
                ticks: 0,
                deaths: 3,
                order: 2,
            },
        ];
        for r in runs {
            let e = r.to_entity(5);
            assert_eq!(e.id, RUN_ID_BASE + 5);
            assert_eq!(e.kind, kind::RUN);
            assert_eq!(e.vel.x, r.running() as i32);
            assert_eq!(RunState::from_entity(&e), Ok(r));
        }
        let good = runs[2].to_entity(5);
        let bad: [fn(&mut EntityState); 6] = [
            |e| e.flags |= 2,
            |e| e.pos.x = -1,
            |e| e.pos.y = -1,
            |e| e.aux = -1,
            |e| e.vel.x = 0,
            |e| e.vel.y = 1,
        ];
        for f in bad {
            let mut e = good;
            f(&mut e);
            assert!(RunState::from_entity(&e).is_err(), "{e:?}");
        }
        let mut e = RunState::default().to_entity(5);
        e.pos.x = 3;
        assert!(RunState::from_entity(&e).is_err(), "ticks before the start");
        // The timer stops at the bound.
        let mut r = runs[3];
        r.order = 0;
        r.tick();
        assert_eq!(r.ticks, RUN_MAX);
    }
}
