//! What a frame of a replay shows: the replay's game as a [`FrameView`],
//! every player and entity blended between where it stood before the last
//! tick ([`Before`]) and where it stands now, as
//! [`crate::game::ClientGame::view`] blends the predicted game; the
//! followed player is the view's `local`, the others its `remotes`, named
//! as the replay's header names them.

use glam::IVec2;
use ledge_shared::game::{Game, PlayerView};
use ledge_shared::protocol::PlayerId;

use crate::game::wall_side;
use crate::view::{blend, px2, EntityDraw, Facing, FrameView, PlayerDraw, Vec2};

/// Where the players and entities stood before the last tick (units): the
/// start of the blend.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Before {
    players: Vec<(PlayerId, IVec2)>,
    entities: Vec<IVec2>,
}

impl Before {
    /// Where everything in `game` stands now.
    pub fn of(game: &Game) -> Before {
        let mut before = Before::default();
        before.take(game);
        before
    }

    /// Notes where everything in `game` stands now (before its next step),
    /// reusing the buffers.
    pub fn take(&mut self, game: &Game) {
        self.players.clear();
        self.players.extend(game.players());
        self.entities.clear();
        self.entities.extend(game.entities().map(|e| e.pos));
    }

    fn player(&self, id: PlayerId) -> Option<IVec2> {
        let i = self.players.binary_search_by_key(&id, |p| p.0).ok()?;
        Some(self.players[i].1)
    }
}

/// A player of the replay to draw.
fn player_draw(p: &PlayerView, pos: Vec2, rate: f32, name: Option<String>) -> PlayerDraw {
    let mut draw = PlayerDraw::new(p.id, pos, px2(p.half * 2));
    draw.name = name;
    draw.vel = px2(p.vel) * rate;
    draw.facing = Facing::from_left(p.facing_left);
    draw.grounded = p.grounded;
    draw.won = p.won;
    draw.dead = p.dead.is_some();
    draw.wall = wall_side(p.sides, p.grounded);
    draw
}

/// The frame of `game` at `alpha` (0..=1) between `before` and now:
/// `follow` (if in the game) as `local`, the others as `remotes`
/// (ascending ids), each named by `name`; `rate`: ticks per second (for
/// velocities in pixels per second).
pub fn frame_view(
    game: &Game,
    before: &Before,
    alpha: f32,
    follow: Option<PlayerId>,
    rate: u32,
    name: impl Fn(PlayerId) -> Option<String>,
) -> FrameView {
    let alpha = alpha.clamp(0.0, 1.0);
    let rate = rate as f32;
    let mut view = FrameView::default();
    for p in game.player_views() {
        let pos = blend(before.player(p.id), p.pos, alpha);
        let draw = player_draw(&p, pos, rate, name(p.id));
        if Some(p.id) == follow {
            view.local = Some(draw);
        } else {
            view.remotes.push(draw);
        }
    }
    view.entities = game
        .entities()
        .enumerate()
        .map(|(i, e)| EntityDraw::of(&e, blend(before.entities.get(i).copied(), e.pos, alpha)))
        .collect();
    view.tick = game.tick();
    view.alpha = alpha;
    view.remote_tick = game.tick() as f64;
    view
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_shared::input::Buttons;

    fn game_with(ids: &[u32]) -> Game {
        let mut game = Game::from_level(&ledge_levels::default_level()).unwrap();
        for &id in ids {
            game.add_player(PlayerId(id)).unwrap();
        }
        game
    }

    #[test]
    fn the_followed_player_is_local_and_the_others_remote_with_their_names() {
        let game = game_with(&[1, 2, 3]);
        let view = frame_view(
            &game,
            &Before::of(&game),
            1.0,
            Some(PlayerId(2)),
            60,
            |id| (id.0 != 3).then(|| format!("p{}", id.0)),
        );
        let local = view.local.expect("the followed player");
        assert_eq!(local.id, PlayerId(2));
        assert_eq!(local.name.as_deref(), Some("p2"));
        let remotes: Vec<_> = view
            .remotes
            .iter()
            .map(|p| (p.id, p.name.clone()))
            .collect();
        assert_eq!(
            remotes,
            vec![(PlayerId(1), Some("p1".into())), (PlayerId(3), None)]
        );
        assert_eq!(view.entities.len(), game.entities().count());
        assert_eq!(view.tick, game.tick());
        // Following nobody (a free camera): everyone is a remote.
        let free = frame_view(&game, &Before::of(&game), 1.0, None, 60, |_| None);
        assert!(free.local.is_none());
        assert_eq!(free.remotes.len(), 3);
    }

    #[test]
    fn positions_blend_from_before_the_tick_to_now() {
        let mut game = game_with(&[1]);
        for _ in 0..5 {
            game.step(&[(PlayerId(1), Buttons(Buttons::RIGHT))]);
        }
        let before = Before::of(&game);
        let from = game.player(PlayerId(1)).unwrap().pos;
        game.step(&[(PlayerId(1), Buttons(Buttons::RIGHT))]);
        let to = game.player(PlayerId(1)).unwrap().pos;
        assert_ne!(from, to);
        let at = |alpha| {
            frame_view(&game, &before, alpha, Some(PlayerId(1)), 60, |_| None)
                .local
                .unwrap()
                .pos
        };
        assert_eq!(at(0.0), px2(from));
        assert_eq!(at(1.0), px2(to));
        assert_eq!(at(0.5), px2(from).lerp(px2(to), 0.5));
        // A player who was not there before is drawn where it is.
        game.add_player(PlayerId(2)).unwrap();
        let view = frame_view(&game, &before, 0.0, Some(PlayerId(1)), 60, |_| None);
        let p2 = game.player(PlayerId(2)).unwrap().pos;
        assert_eq!(view.remotes[0].pos, px2(p2));
    }
}
