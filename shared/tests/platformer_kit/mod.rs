//! Helpers for the platformer tests: levels from ASCII art, entities by tile
//! coordinates, and a one-player driver.
#![allow(dead_code)]

use glam::IVec2;
use ledge_shared::game::{Game, GameConfig, GameEvent, PlayerView};
use ledge_shared::input::Buttons;
use ledge_shared::level::{EntityDef, EntityKind, Level, PlatformMotion};
use ledge_shared::protocol::PlayerId;
use ledge_shared::tilemap::{Slope, Tile, Tilemap};

/// One tile: 16 px.
pub const T: i32 = 16 * 256;

/// Buttons.
pub const NONE: Buttons = Buttons::NONE;
pub const LEFT: Buttons = Buttons(Buttons::LEFT);
pub const RIGHT: Buttons = Buttons(Buttons::RIGHT);
pub const JUMP: Buttons = Buttons(Buttons::JUMP);
pub const DOWN_JUMP: Buttons = Buttons(Buttons::DOWN | Buttons::JUMP);
pub const RIGHT_JUMP: Buttons = Buttons(Buttons::RIGHT | Buttons::JUMP);

/// The tile of one map character: `.` empty, `#` solid, `=` or `-` one-way,
/// `^` hazard, `/` and `\` 45 degree slopes, `a b` a 22.5 degree ramp rising
/// right (low, high), `c d` one rising left (high, low). Panics on any other
/// character, so that a typo in a map fails loudly.
pub fn tile(ch: char) -> Tile {
    match ch {
        '.' => Tile::Empty,
        '#' => Tile::Solid,
        '=' | '-' => Tile::OneWay,
        '^' => Tile::Hazard,
        '/' => Tile::Slope(Slope::Right45),
        '\\' => Tile::Slope(Slope::Left45),
        'a' => Tile::Slope(Slope::RightLow22),
        'b' => Tile::Slope(Slope::RightHigh22),
        'c' => Tile::Slope(Slope::LeftHigh22),
        'd' => Tile::Slope(Slope::LeftLow22),
        _ => panic!("unknown tile {ch:?}"),
    }
}

/// A tilemap from rows of characters ([`tile`]) with its top-left corner at
/// `origin` and tiles of `size` units.
pub fn map_at(origin: IVec2, size: i32, rows: &[&str]) -> Tilemap {
    let w = rows[0].len();
    for r in rows {
        assert_eq!(r.len(), w, "ragged map row {r:?}");
    }
    let tiles = rows.iter().flat_map(|r| r.chars().map(tile)).collect();
    Tilemap::new(origin, size, w as u32, rows.len() as u32, tiles).unwrap()
}

/// A tilemap at the origin with tiles of [`T`] from rows of characters
/// ([`tile`]).
pub fn map(rows: &[&str]) -> Tilemap {
    map_at(IVec2::ZERO, T, rows)
}

/// Centre of tile `(c, r)`.
pub fn tile_centre(c: i32, r: i32) -> IVec2 {
    IVec2::new(c * T + T / 2, r * T + T / 2)
}

/// An entity of one tile at tile `(c, r)`.
pub fn ent(kind: EntityKind, c: i32, r: i32) -> EntityDef {
    EntityDef {
        kind,
        pos: tile_centre(c, r),
        size: IVec2::splat(T),
    }
}

/// Centre of tile `(c, r)` on a map at the origin with tiles of `size`.
pub fn tile_centre_sized(size: i32, c: i32, r: i32) -> IVec2 {
    IVec2::new(c * size + size / 2, r * size + size / 2)
}

/// An entity of one tile at tile `(c, r)` on a map at the origin with tiles
/// of `size` units.
pub fn ent_sized(kind: EntityKind, size: i32, c: i32, r: i32) -> EntityDef {
    EntityDef {
        kind,
        pos: tile_centre_sized(size, c, r),
        size: IVec2::splat(size),
    }
}

/// An entity with an explicit centre and size.
pub fn ent_at(kind: EntityKind, pos: IVec2, size: IVec2) -> EntityDef {
    EntityDef { kind, pos, size }
}

/// A moving platform of `size` following `path` (centres) at `speed`.
pub fn platform(path: &[IVec2], size: IVec2, speed: i32, one_way: bool) -> EntityDef {
    EntityDef {
        kind: EntityKind::MovingPlatform {
            motion: PlatformMotion {
                path: path.to_vec(),
                speed,
                looped: false,
            },
            one_way,
        },
        pos: path[0],
        size,
    }
}

/// A level from a map and entities.
pub fn level(rows: &[&str], entities: Vec<EntityDef>) -> Level {
    Level {
        name: "test".into(),
        tilemap: map(rows),
        entities,
        player: Default::default(),
    }
}

/// A room 40 x 14 tiles (walls all round, floor top at row 13), with
/// `patches` (row, column, string) applied to the map, and entities.
pub fn room(patches: &[(usize, usize, &str)], entities: Vec<EntityDef>) -> Level {
    let mut rows = vec!["#".repeat(40)];
    for _ in 0..12 {
        rows.push(format!("#{}#", ".".repeat(38)));
    }
    rows.push("#".repeat(40));
    for &(r, c, s) in patches {
        rows[r].replace_range(c..c + s.len(), s);
    }
    let rows: Vec<&str> = rows.iter().map(|s| s.as_str()).collect();
    level(&rows, entities)
}

/// A level from a map at the origin with tiles of `size` units, and
/// entities.
pub fn level_sized(size: i32, rows: &[&str], entities: Vec<EntityDef>) -> Level {
    Level {
        name: "test".into(),
        tilemap: map_at(IVec2::ZERO, size, rows),
        entities,
        player: Default::default(),
    }
}

/// One player in a game.
pub struct Sim {
    pub game: Game,
    pub id: PlayerId,
    pub events: Vec<GameEvent>,
}

impl Sim {
    /// A game of `level` with `config` and player 1.
    pub fn with(level: &Level, config: GameConfig) -> Self {
        let mut game = Game::with_config(level, config).unwrap();
        let id = PlayerId(1);
        game.add_player(id).unwrap();
        Sim {
            game,
            id,
            events: Vec::new(),
        }
    }

    /// A game of `level` with the default configuration, its player scaled
    /// for the level (as `Game::from_level`), and player 1.
    pub fn new(level: &Level) -> Self {
        Self::with(level, GameConfig::default().for_level(level).unwrap())
    }

    /// Steps once with `b`; keeps the tick's events.
    pub fn step(&mut self, b: Buttons) -> &[GameEvent] {
        self.events = self.game.step(&[(self.id, b)]).to_vec();
        &self.events
    }

    /// Steps `n` times with `b`.
    pub fn run(&mut self, b: Buttons, n: usize) {
        for _ in 0..n {
            self.step(b);
        }
    }

    /// The player's view.
    pub fn view(&self) -> PlayerView {
        self.game.player(self.id).unwrap()
    }

    /// The player's centre.
    pub fn pos(&self) -> IVec2 {
        self.view().pos
    }

    /// The player's bottom edge.
    pub fn bottom(&self) -> i32 {
        let v = self.view();
        v.pos.y + v.half.y
    }

    /// Whether the last step raised an event matching `f`.
    pub fn saw(&self, f: impl Fn(&GameEvent) -> bool) -> bool {
        self.events.iter().any(f)
    }

    /// After a death in the last step: steps with `b` through the respawn
    /// delay, checking that the player stays dead where it died, with no
    /// event, for exactly the configured delay, then respawns at `respawn`
    /// (with a delay of 0 the respawn was in the death's tick).
    pub fn sit_out_death(&mut self, b: Buttons, respawn: IVec2) {
        let respawned = GameEvent::Respawned {
            player: self.id,
            pos: respawn,
        };
        let delay = self.game.config().player.respawn_delay_ticks;
        if delay == 0 {
            assert!(self.events.contains(&respawned), "{:?}", self.events);
        }
        let at = self.pos();
        for left in (1..=delay).rev() {
            assert_eq!(self.view().dead, Some(left), "{:?}", self.view());
            assert_eq!(self.pos(), at, "dead players do not move");
            assert_eq!(self.view().vel, IVec2::ZERO);
            self.step(b);
            if left > 1 {
                assert_eq!(self.events, vec![], "{left} ticks left");
            }
        }
        assert_eq!(self.events.last(), Some(&respawned));
        assert_eq!(self.view().dead, None);
        assert_eq!(self.pos(), respawn);
    }

    /// Steps until the player is grounded (at most `n` ticks); panics if it
    /// never is.
    pub fn land(&mut self, n: usize) {
        for _ in 0..n {
            self.step(NONE);
            if self.view().grounded {
                return;
            }
        }
        panic!("never landed: {:?}", self.view());
    }
}

/// Whether `e` is a jump of player 1.
pub fn jumped(e: &GameEvent) -> bool {
    matches!(e, GameEvent::Jumped(PlayerId(1)))
}
