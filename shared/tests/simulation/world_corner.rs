//! Corners and seams between two separate solids: a wall and a door.
//!
//! * Corner: a wall on the right and a door above, flush against it; the
//!   square moves diagonally into both and must end against both, pushed out
//!   of each along its own axis, exactly, never through the wall and never
//!   pushed back down out of the door (and the three mirror images).
//! * Seam: a wall below and a door above, both on the right, one flush column;
//!   the square slides along it across the seam and must only ever be pushed
//!   sideways (and mirrored on the left, in both directions).

use glam::IVec2;
use ledge_shared::fixed::px;
use ledge_shared::input::Buttons;
use ledge_shared::scene::{
    tag, wall_and_door, CORNER_DOOR_Y, CORNER_WALL_X, MOVER, PLAYER_HALF, TILE,
};
use ledge_shared::shape::Aabb;
use ledge_shared::world::{BodyDesc, BodyId, ColliderDesc, Controller, Event, Mover, World};

const H: i32 = PLAYER_HALF;

/// A solid box of half size `half` centred at `centre`, on a static body.
fn wall(w: &mut World, centre: IVec2, half: IVec2, t: u16) {
    let b = w.add_body(BodyDesc::fixed(centre)).unwrap();
    w.add_collider(b, ColliderDesc::solid(Aabb::new(half).unwrap()).tagged(t))
        .unwrap();
}

fn square(w: &mut World, pos: IVec2) -> BodyId {
    let b = w.add_body(BodyDesc::dynamic(pos)).unwrap();
    w.add_collider(
        b,
        ColliderDesc::solid(Aabb::new(IVec2::splat(H)).unwrap()).tagged(tag::PLAYER),
    )
    .unwrap();
    w.add_controller(Controller::Mover(Mover {
        body: b,
        config: MOVER,
    }))
    .unwrap();
    b
}

fn key_x(s: i32) -> u8 {
    if s > 0 {
        Buttons::RIGHT
    } else {
        Buttons::LEFT
    }
}

fn key_y(s: i32) -> u8 {
    if s > 0 {
        Buttons::DOWN
    } else {
        Buttons::UP
    }
}

/// The wall-and-door corner mirrored by `f` (each component +1 or -1) about
/// the origin: with `f = (1, 1)` it is [`wall_and_door`]'s geometry. The
/// square starts `start` away (before mirroring) from its resting place.
fn corner(f: IVec2, start: IVec2) -> (World, BodyId) {
    let mut w = World::default();
    // Same boxes as scene::wall_and_door, mirrored.
    wall(
        &mut w,
        f * IVec2::new(CORNER_WALL_X + TILE / 2, 10 * TILE),
        IVec2::new(TILE / 2, 10 * TILE),
        tag::WALL,
    );
    wall(
        &mut w,
        f * IVec2::new(CORNER_WALL_X - 3 * TILE, CORNER_DOOR_Y - TILE / 2),
        IVec2::new(3 * TILE, TILE / 2),
        tag::DOOR,
    );
    let rest = IVec2::new(CORNER_WALL_X - H, CORNER_DOOR_Y + H);
    let b = square(&mut w, f * (rest + start));
    (w, b)
}

/// Drives the square of `w` diagonally into the corner (towards `-start`
/// direction, mirrored by `f`) and checks every tick.
fn run_corner(mut w: World, b: BodyId, f: IVec2, ctx: &str) {
    // Mirrored "right" and "up".
    let keys = Buttons(key_x(f.x) | key_y(-f.y));
    let rest = f * IVec2::new(CORNER_WALL_X - H, CORNER_DOOR_Y + H);
    let mut saw = (false, false);
    for t in 0..120 {
        let before = w.body(b).unwrap().pos();
        let events = w.step(&[keys]).to_vec();
        let pos = w.body(b).unwrap().pos();
        let d = pos - before;
        // Never through the wall or into the door...
        assert!(
            f.x * pos.x <= f.x * rest.x,
            "{ctx} tick {t}: through the wall at {pos}"
        );
        assert!(
            f.y * pos.y >= f.y * rest.y,
            "{ctx} tick {t}: into the door at {pos}"
        );
        // ...and never pushed back the way it came (no needless push down out
        // of the door, no push away from the wall).
        assert!(f.x * d.x >= 0, "{ctx} tick {t}: pushed back along x by {d}");
        assert!(f.y * d.y <= 0, "{ctx} tick {t}: pushed back along y by {d}");
        assert!(
            !events.iter().any(|e| matches!(e, Event::Squished { .. })),
            "{ctx} tick {t}: squished"
        );
        for e in &events {
            if let Event::Contact { other_tag, .. } = e {
                saw.0 |= *other_tag == tag::WALL;
                saw.1 |= *other_tag == tag::DOOR;
            }
        }
    }
    let body = w.body(b).unwrap();
    assert_eq!(body.pos(), rest, "{ctx}: final position");
    assert_eq!(
        saw,
        (true, true),
        "{ctx}: contact events with the wall and the door"
    );
}

#[test]
fn the_scene_corner_ends_against_wall_and_door() {
    let w = wall_and_door();
    let b = w.controllers()[0].body();
    // The scene's own square, from its own start (equidistant: it reaches the
    // wall and the door in the same tick).
    let start = w.body(b).unwrap().pos();
    assert_eq!(CORNER_WALL_X - H - start.x, start.y - (CORNER_DOOR_Y + H));
    run_corner(w, b, IVec2::ONE, "scene");
}

#[test]
fn corner_at_every_subpixel_offset_and_mirror() {
    for f in [
        IVec2::new(1, 1),
        IVec2::new(-1, 1),
        IVec2::new(1, -1),
        IVec2::new(-1, -1),
    ] {
        for o in 0..256 {
            // Equidistant (both contacts in the same tick), and skewed.
            for (ox, oy) in [(o, o), (o, (o * 7 + 13) % 256), ((o * 11) % 256, o)] {
                let start = IVec2::new(-px(20) - ox, px(20) + oy);
                let (w, b) = corner(f, start);
                run_corner(w, b, f, &format!("mirror {f} offset ({ox}, {oy})"));
            }
        }
    }
}

/// A wall (`tag::WALL`) and a door (`tag::DOOR`) forming one flush column on
/// side `fx` (+1 right, -1 left) of the square, the seam at `y = 0`, the wall
/// below and the door above.
fn seam(fx: i32, start: IVec2) -> (World, BodyId) {
    let mut w = World::default();
    let face = 10 * TILE;
    wall(
        &mut w,
        IVec2::new(fx * (face + TILE / 2), 6 * TILE),
        IVec2::new(TILE / 2, 6 * TILE),
        tag::WALL,
    );
    wall(
        &mut w,
        IVec2::new(fx * (face + TILE / 2), -6 * TILE),
        IVec2::new(TILE / 2, 6 * TILE),
        tag::DOOR,
    );
    let b = square(&mut w, IVec2::new(fx * (face - H) - fx * start.x, start.y));
    (w, b)
}

#[test]
fn crossing_the_wall_door_seam_pushes_sideways_only() {
    let face = 10 * TILE;
    let max = MOVER.max_speed;
    for fx in [1, -1] {
        for dy in [-1, 1] {
            // Every subpixel offset, and beyond: every phase of the crossing
            // (how deep the square enters the next box on the crossing tick
            // takes every value in 1..=max).
            for o in 0..max.max(256) {
                // Start 4 tiles before the seam, a few subpixels off the wall.
                let start = IVec2::new(o % 64, -dy * 4 * TILE + dy * o);
                let (mut w, b) = seam(fx, start);
                w.set_velocity(b, IVec2::new(0, dy * max)).unwrap();
                let keys = Buttons(key_x(fx) | key_y(dy));
                let line = fx * (face - H);
                let mut touching = false;
                let mut crossed = false;
                for t in 0..40 {
                    let before = w.body(b).unwrap().pos();
                    let events = w.step(&[keys]).to_vec();
                    let body = w.body(b).unwrap();
                    let ctx = format!("side {fx} dir {dy} offset {o} tick {t}");
                    assert_eq!(
                        body.pos().y - before.y,
                        dy * max,
                        "{ctx}: pushed along the column"
                    );
                    assert_eq!(body.vel().y, dy * max, "{ctx}: slowed along the column");
                    assert!(fx * body.pos().x <= fx * line, "{ctx}: inside the column");
                    assert!(
                        !events.iter().any(|e| matches!(e, Event::Squished { .. })),
                        "{ctx}"
                    );
                    if touching {
                        assert_eq!(body.pos().x, line, "{ctx}: pushed off the column");
                    }
                    touching |= body.pos().x == line;
                    crossed |= body.pos().y * dy > H;
                }
                assert!(
                    touching && crossed,
                    "side {fx} dir {dy} offset {o}: never slid across the seam"
                );
            }
        }
    }
}
