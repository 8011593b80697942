//! How the game's state packs into [`crate::protocol::EntityState`]s, and the entity kinds.

/// Ids at and above this are level entities (`ENTITY_ID_BASE + index in
/// Level::entities`); players use their [`crate::protocol::PlayerId`], which
/// must be below it.
pub const ENTITY_ID_BASE: u32 = 1 << 30;

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
    /// Reached the goal.
    pub const WON: u32 = 1 << 4;
    /// The respawn point: bits 16 to 30 hold 0 for the level's spawn, or one
    /// plus the checkpoint's entity index.
    pub const CHECKPOINT_SHIFT: u32 = 16;
    /// Mask of the respawn point bits (15 bits).
    pub const CHECKPOINT_MASK: u32 = 0x7fff << CHECKPOINT_SHIFT;
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
/// (bits 0-7 coyote, 8-15 jump buffer, 16-23 jump hold, 24-31 drop-through).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub(crate) struct PlayerState {
    pub grounded: bool,
    pub jump_held: bool,
    pub facing_left: bool,
    pub on_spring: bool,
    pub won: bool,
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
            | ((self.checkpoint as u32) << CHECKPOINT_SHIFT)
    }

    pub fn aux(&self) -> i32 {
        u32::from_le_bytes([self.coyote, self.buffer, self.hold, self.drop]) as i32
    }

    /// The state of `flags` and `aux`; `None` when a bit no state uses is set.
    pub fn unpack(flags: u32, aux: i32) -> Option<Self> {
        use player_flags::*;
        let known = GROUNDED | JUMP_HELD | FACING_LEFT | ON_SPRING | WON | CHECKPOINT_MASK;
        if flags & !known != 0 {
            return None;
        }
        let [coyote, buffer, hold, drop] = (aux as u32).to_le_bytes();
        Some(Self {
            grounded: flags & GROUNDED != 0,
            jump_held: flags & JUMP_HELD != 0,
            facing_left: flags & FACING_LEFT != 0,
            on_spring: flags & ON_SPRING != 0,
            won: flags & WON != 0,
            coyote,
            buffer,
            hold,
            drop,
            checkpoint: ((flags & CHECKPOINT_MASK) >> CHECKPOINT_SHIFT) as u16,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::EntityState;

    #[test]
    fn player_state_round_trips() {
        let s = PlayerState {
            grounded: true,
            jump_held: false,
            facing_left: true,
            on_spring: true,
            won: false,
            coyote: 3,
            buffer: 254,
            hold: 17,
            drop: 9,
            checkpoint: 0x7fff,
        };
        assert_eq!(PlayerState::unpack(s.flags(), s.aux()), Some(s));
        assert_eq!(s.flags() & EntityState::CLIENT_SIMULATED, 0);
        assert_eq!(PlayerState::unpack(1 << 9, 0), None);
    }
}
