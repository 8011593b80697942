//! What can be played: [`Effect`], named by the game events the window maps
//! to sounds. Its own module so that the synthesizer and the player both
//! read it without importing each other.

/// A sound effect.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Effect {
    /// A player jumped (a short rising blip).
    Jump,
    /// A player landed after a fall (a short low thud).
    Land,
    /// A coin was picked up (two high notes).
    Coin,
    /// A walker was stomped (a descending square).
    Stomp,
    /// A player was hurt or crushed: in ledge every hurt is a death (a noisy
    /// descending burst).
    Hurt,
    /// A player was put back at its checkpoint (a soft rising shimmer).
    Respawn,
    /// A new checkpoint was reached (three rising notes).
    Checkpoint,
    /// A springboard launched a player (a fast upward slide with vibrato).
    Spring,
    /// The goal was reached (a short fanfare).
    Goal,
}

impl Effect {
    /// Every effect, in declaration order.
    pub const ALL: [Effect; 9] = [
        Effect::Jump,
        Effect::Land,
        Effect::Coin,
        Effect::Stomp,
        Effect::Hurt,
        Effect::Respawn,
        Effect::Checkpoint,
        Effect::Spring,
        Effect::Goal,
    ];

    /// Position in [`Effect::ALL`].
    pub const fn index(self) -> usize {
        self as usize
    }

    /// A short lowercase name (logs, settings).
    pub const fn name(self) -> &'static str {
        match self {
            Effect::Jump => "jump",
            Effect::Land => "land",
            Effect::Coin => "coin",
            Effect::Stomp => "stomp",
            Effect::Hurt => "hurt",
            Effect::Respawn => "respawn",
            Effect::Checkpoint => "checkpoint",
            Effect::Spring => "spring",
            Effect::Goal => "goal",
        }
    }
}
