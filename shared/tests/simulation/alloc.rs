//! No allocation per tick in steady state: a counting global allocator
//! watches many ticks of the warm-up room and of a platformer game after a
//! warm-up period.
//!
//! Only allocations made by the test's own thread while counting is on are
//! counted (the test harness's threads may allocate at any time).

use ledge_shared::scene::{run_scripted, scripted_inputs, warmup_room};
use ledge_shared::world::Event;

use crate::counting_alloc;
use counting_alloc::allocations;

#[test]
fn the_counter_counts() {
    let n = allocations(|| {
        std::hint::black_box(vec![1u8; 16]);
    });
    assert_eq!(n, 1);
}

#[test]
fn warmup_room_ticks_allocate_nothing_in_steady_state() {
    let mut world = warmup_room();
    // Warm-up: the buffers grow to the scene's needs.
    run_scripted(&mut world, 5_000);
    let mut kinds = [0u64; 3];
    let n = allocations(|| {
        for _ in 0..60_000 {
            let input = scripted_inputs(world.tick());
            for e in world.step(&[input]) {
                kinds[match e {
                    Event::Contact { .. } => 0,
                    Event::Trigger { .. } => 1,
                    Event::Squished { .. } => 2,
                    Event::SweptHit { .. } => 2,
                }] += 1;
            }
            std::hint::black_box(world.state_hash());
        }
    });
    assert_eq!(n, 0, "allocations during 60,000 steady-state ticks");
    // The run exercised contacts (restitution) and triggers, and their events.
    assert!(kinds[0] > 1_000, "contact events: {kinds:?}");
    assert!(kinds[1] > 100, "trigger events: {kinds:?}");
}

/// The platformer's steps allocate nothing in steady state either: the
/// world's tile contacts, the game's events and scratch buffers are reused.
#[test]
fn game_ticks_allocate_nothing_in_steady_state() {
    use glam::IVec2;
    use ledge_shared::game::Game;
    use ledge_shared::input::Buttons;
    use ledge_shared::level::{EntityDef, EntityKind, Level, PlatformMotion};
    use ledge_shared::protocol::PlayerId;
    use ledge_shared::tilemap::{Slope, Tile, Tilemap};

    const T: i32 = 4096;
    let rows = [
        "####################",
        "#..................#",
        "#......====........#",
        "#..................#",
        "#...../#\\....^.....#",
        "####################",
    ];
    let mut tiles = Vec::new();
    for r in rows {
        for ch in r.chars() {
            tiles.push(match ch {
                '#' => Tile::Solid,
                '=' => Tile::OneWay,
                '^' => Tile::Hazard,
                '/' => Tile::Slope(Slope::Right45),
                '\\' => Tile::Slope(Slope::Left45),
                _ => Tile::Empty,
            });
        }
    }
    let at = |c: i32, r: i32| IVec2::new(c * T + T / 2, r * T + T / 2);
    let e = |kind, pos, size| EntityDef { kind, pos, size };
    let level = Level {
        name: "alloc".into(),
        tilemap: Tilemap::new(IVec2::ZERO, T, 20, 6, tiles).unwrap(),
        entities: vec![
            e(EntityKind::PlayerSpawn, at(2, 4), IVec2::splat(T)),
            e(
                EntityKind::MovingPlatform {
                    motion: PlatformMotion {
                        path: vec![at(15, 4), at(15, 1)],
                        speed: 100,
                        looped: false,
                    },
                    one_way: false,
                },
                at(15, 4),
                IVec2::new(2 * T, T / 2),
            ),
            e(EntityKind::Walker { speed: 64 }, at(11, 4), IVec2::splat(T)),
            e(EntityKind::Coin, at(9, 4), IVec2::splat(T)),
            e(
                EntityKind::Springboard { strength: 1500 },
                at(17, 4),
                IVec2::splat(T),
            ),
            e(EntityKind::Checkpoint, at(10, 1), IVec2::splat(T)),
        ],
        player: Default::default(),
    };
    let mut game = Game::from_level(&level).unwrap();
    for id in 1..=3 {
        game.add_player(PlayerId(id)).unwrap();
    }
    let mut inputs = [(PlayerId(1), Buttons::NONE); 3];
    let mut run = |game: &mut Game, ticks: u64| {
        let mut events = 0;
        for _ in 0..ticks {
            let t = game.tick();
            for (k, slot) in inputs.iter_mut().enumerate() {
                *slot = (PlayerId(k as u32 + 1), scripted_inputs(t + 555 * k as u64));
            }
            events += game.step(&inputs).len();
            std::hint::black_box(game.state_hash());
        }
        events
    };
    run(&mut game, 5_000);
    let mut events = 0;
    let n = allocations(|| events = run(&mut game, 20_000));
    assert_eq!(n, 0, "allocations during 20,000 steady-state game ticks");
    assert!(events > 100, "{events} events");
}
