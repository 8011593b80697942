//! Spawn spots: players joining one game stand apart, each on its own spot
//! near the spawn, free of solids and on the spawn's floor; a player
//! without a checkpoint respawns on the same spot, in any game of the level.

use crate::platformer_kit;

use glam::IVec2;
use ledge_shared::game::{spawn, Game, GameEvent, HurtCause};
use ledge_shared::level::{EntityKind, Level};
use ledge_shared::protocol::PlayerId;
use ledge_shared::tilemap::{ContactFlags, Tile, Tilemap};
use platformer_kit::{ent, level, T};

const PX: i32 = 256;

/// The centres of players `1..=n` right after they join `level`.
fn join(level: &Level, n: u32) -> (Game, Vec<IVec2>) {
    let mut game = Game::from_level(level).unwrap();
    for id in 1..=n {
        game.add_player(PlayerId(id)).unwrap();
    }
    let at = (1..=n)
        .map(|id| game.player(PlayerId(id)).unwrap().pos)
        .collect();
    (game, at)
}

/// Whether a player's box at `pos` touches no tile (solid, slope or hazard).
fn clear_of_tiles(map: &Tilemap, pos: IVec2, half: IVec2) -> bool {
    let mut out = Vec::new();
    map.box_contacts(pos, half, IVec2::ZERO, ContactFlags::default(), &mut out);
    out.is_empty()
}

fn distinct(at: &[IVec2]) -> usize {
    let mut v = at.to_vec();
    v.sort_by_key(|p| (p.x, p.y));
    v.dedup();
    v.len()
}

/// Interiors of two boxes of half extents `half` overlap.
fn overlap(a: IVec2, b: IVec2, half: IVec2) -> bool {
    (a.x - b.x).abs() < 2 * half.x && (a.y - b.y).abs() < 2 * half.y
}

#[test]
fn sixteen_players_joining_the_default_level_stand_on_sixteen_spots() {
    let lv = ledge_levels::default_level();
    let (mut game, at) = join(&lv, 16);
    let half = game.config().player.half;
    let spawn = lv
        .entities
        .iter()
        .find(|e| e.kind == EntityKind::PlayerSpawn)
        .unwrap();
    // Player 1 stands on the spawn itself, as before.
    assert_eq!(at[0].x, spawn.pos.x);
    assert_eq!(at[0].y + half.y, spawn.pos.y + spawn.size.y / 2);
    assert_eq!(distinct(&at), 16, "{at:?}");
    // All on the spawn's floor, within the spread, clear of the tiles.
    let step = 2 * half.x + spawn::GAP;
    for p in &at {
        assert_eq!(p.y, at[0].y);
        assert!((p.x - at[0].x).abs() <= spawn::SPREAD_STEPS * step, "{p}");
        assert!(clear_of_tiles(game.tilemap(), *p, half), "{p}");
    }
    // The first four stand side by side, no two overlapping.
    for i in 0..4 {
        for j in 0..i {
            assert!(!overlap(at[i], at[j], half), "{} and {}", i + 1, j + 1);
        }
    }
    // Clear of the crate and of the elevator's shaft.
    for e in &lv.entities {
        let shaft = match &e.kind {
            EntityKind::Block => Some((e.pos, e.pos)),
            EntityKind::MovingPlatform { motion, .. } => {
                let lo = motion.path.iter().fold(e.pos, |a, &b| a.min(b));
                let hi = motion.path.iter().fold(e.pos, |a, &b| a.max(b));
                Some((lo, hi))
            }
            _ => None,
        };
        if let Some((lo, hi)) = shaft {
            let h = e.size / 2;
            for p in &at {
                let apart = p.x + half.x <= lo.x - h.x
                    || hi.x + h.x <= p.x - half.x
                    || p.y + half.y <= lo.y - h.y
                    || hi.y + h.y <= p.y - half.y;
                assert!(apart, "{p} in {:?}", e.kind);
            }
        }
    }
    // They stand: a second of doing nothing moves nobody.
    for _ in 0..60 {
        game.step(&[]);
    }
    for (id, p) in (1..=16).zip(&at) {
        let v = game.player(PlayerId(id)).unwrap();
        assert!(v.grounded, "player {id}");
        assert_eq!(v.pos, *p, "player {id}");
    }
}

/// Whether boxes of centres `a`, `b` and half extents `ha`, `hb` overlap.
fn boxes_overlap(a: IVec2, ha: IVec2, b: IVec2, hb: IVec2) -> bool {
    (a.x - b.x).abs() < ha.x + hb.x && (a.y - b.y).abs() < ha.y + hb.y
}

#[test]
fn spots_avoid_hazards_blocks_platform_paths_and_pits() {
    // The spawn stands at col 5 on the floor (row 5's top). Left of it a
    // hazard tile at head height (col 4) and a platform riding up and down
    // col 3; right of it a pit (col 6) and a block on the floor (col 8).
    let rows = [
        "############",
        "#..........#",
        "#..........#",
        "#..........#",
        "#...^......#",
        "######.#####",
        "######.#####",
        "############",
    ];
    let platform_half = IVec2::new(T / 4, T / 8);
    let path = [
        platformer_kit::tile_centre(3, 1),
        platformer_kit::tile_centre(3, 4),
    ];
    let entities = vec![
        ent(EntityKind::PlayerSpawn, 5, 4),
        ent(EntityKind::Block, 8, 4),
        platformer_kit::platform(&path, platform_half * 2, PX, false),
    ];
    let lv = level(&rows, entities);
    let (mut game, at) = join(&lv, 32);
    let half = game.config().player.half;
    let spots = distinct(&at);
    assert!(spots >= 4, "{at:?}");
    // The platform's whole path: one box from its top to its bottom.
    let shaft = IVec2::new(path[0].x, (path[0].y + path[1].y) / 2);
    let shaft_half = IVec2::new(
        platform_half.x,
        (path[1].y - path[0].y) / 2 + platform_half.y,
    );
    let block = platformer_kit::tile_centre(8, 4);
    for p in &at {
        // On the spawn's floor, the foot over solid ground (not the pit),
        assert_eq!(p.y + half.y, 5 * T, "{p}");
        assert_eq!(game.tilemap().tile(IVec2::new(p.x / T, 5)), Tile::Solid);
        // clear of the tiles (the hazard included), the block and the
        // platform's path.
        assert!(clear_of_tiles(game.tilemap(), *p, half), "{p}");
        assert!(!boxes_overlap(*p, half, block, IVec2::splat(T / 2)), "{p}");
        assert!(!boxes_overlap(*p, half, shaft, shaft_half), "{p}");
    }
    // Ids beyond the spots take them again, in turn.
    assert_eq!(at[0], at[spots]);
    assert_eq!(distinct(&at[..spots]), spots);
    // Everyone stands where they appeared.
    for _ in 0..30 {
        game.step(&[]);
    }
    for (id, p) in (1..=32).zip(&at) {
        assert_eq!(game.player(PlayerId(id)).unwrap().pos, *p, "{id} stands");
    }
}

#[test]
fn a_player_without_a_checkpoint_respawns_on_its_own_spot_in_any_game() {
    let lv = ledge_levels::default_level();
    let (game, at) = join(&lv, 5);
    // Player 4 falls out of the level, in a fresh game restored from a
    // snapshot (as a predicting client does).
    let mut fallen = game.snapshot();
    let e = fallen.entities.iter_mut().find(|e| e.id == 4).unwrap();
    e.pos.y = 1 << 28;
    let mut other = Game::from_level(&lv).unwrap();
    other.restore(&fallen).unwrap();
    let events = other.step(&[]).to_vec();
    assert!(
        events.contains(&GameEvent::Died {
            player: PlayerId(4),
            cause: HurtCause::Fell
        }),
        "{events:?}"
    );
    // Dead for the respawn delay, then back on its own spot.
    let delay = other.config().player.respawn_delay_ticks;
    let mut events = events;
    for _ in 0..delay {
        events = other.step(&[]).to_vec();
    }
    assert!(
        events.contains(&GameEvent::Respawned {
            player: PlayerId(4),
            pos: at[3]
        }),
        "{events:?}"
    );
    assert_eq!(other.player(PlayerId(4)).unwrap().pos, at[3]);
}
