//! `--spectate`: watching a room without a body. The library's game has
//! no player of ours ([`ledge_client::ClientGame::set_spectating`]); here
//! the camera follows one of the players ([`Follow`], Tab / Shift+Tab, F
//! for a free camera moved with WASD: [`FollowCamera`], as a replay's),
//! `--follow NAME` picks whom first, and the HUD says who is watched.

use std::collections::BTreeMap;

use ledge_client::follow::Follow;
use ledge_client::view::{FrameView, PlayerDraw};
use ledge_shared::protocol::PlayerId;
use macroquad::math::{Rect, Vec2};

use crate::input::follow::FollowCamera;

/// What the chat says when a spectator opens it.
pub const NO_CHAT: &str = "spectators cannot chat: join as a player to talk";

/// A spectator's camera (see the module documentation).
#[derive(Debug, Clone)]
pub struct Spectate {
    /// Whom the camera follows (a player not in the game: the first who
    /// is).
    follow: Follow,
    /// `--follow NAME`, until the roster names that player.
    wanted: Option<String>,
    camera: FollowCamera,
}

impl Spectate {
    /// Follows the player called `wanted` once the roster names it, the
    /// first player until then.
    pub fn new(wanted: Option<String>) -> Spectate {
        Spectate {
            // Id 0 is nobody's: the first player in the game is followed.
            follow: Follow::Player(PlayerId(0)),
            wanted,
            camera: FollowCamera::default(),
        }
    }

    /// Whom the camera follows.
    pub fn follow(&self) -> Follow {
        self.follow
    }

    /// This frame's keys (`dt` seconds long) among `players` (ascending
    /// ids, named by `names`): `--follow`'s player once named, then Tab,
    /// F and WASD.
    pub fn keys(&mut self, players: &[PlayerId], names: &BTreeMap<PlayerId, String>, dt: f32) {
        self.find_wanted(names);
        self.follow = self.camera.keys(self.follow, players, dt);
    }

    /// Follows `--follow`'s player once `names` (the roster) has it.
    fn find_wanted(&mut self, names: &BTreeMap<PlayerId, String>) {
        if let Some(wanted) = &self.wanted {
            if let Some((&id, _)) = names.iter().find(|(_, n)| *n == wanted) {
                self.follow = Follow::Player(id);
                self.wanted = None;
            }
        }
    }

    /// The player followed among `players`, if any.
    pub fn followed(&self, players: &[PlayerId]) -> Option<PlayerId> {
        self.follow.resolve(players)
    }

    /// Where the camera looks: see [`FollowCamera::focus`].
    pub fn focus(&mut self, followed: Option<Vec2>, level_px: Rect) -> Vec2 {
        self.camera.focus(self.follow, followed, level_px)
    }
}

/// `view` with the player `followed` drawn as the featured one
/// ([`FrameView::local`]: over the others, its label first), the others
/// as they were.
pub fn feature(mut view: FrameView, followed: Option<PlayerId>) -> FrameView {
    if let Some(i) = view.remotes.iter().position(|p| Some(p.id) == followed) {
        let p: PlayerDraw = view.remotes.remove(i);
        view.local = Some(p);
    }
    view
}

/// The HUD's line: `spectating room-1 - following bob (Tab: next)` (the pixel font has
/// no dash), or
/// with a free camera `spectating room-1 - free camera (WASD; F: follow)`.
pub fn line(room: &str, following: Option<&str>) -> String {
    match following {
        Some(name) => format!("spectating {room} - following {name} (Tab: next)"),
        None => format!("spectating {room} - free camera (WASD; F: follow)"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_client::view::PlayerDraw;

    #[test]
    fn the_followed_player_is_featured_and_the_line_names_it() {
        let mut view = FrameView::default();
        for id in [2, 5] {
            view.remotes
                .push(PlayerDraw::new(PlayerId(id), Vec2::ZERO, Vec2::ONE));
        }
        let shown = feature(view.clone(), Some(PlayerId(5)));
        assert_eq!(shown.local.map(|p| p.id), Some(PlayerId(5)));
        assert_eq!(shown.remotes.len(), 1);
        let none = feature(view, None);
        assert!(none.local.is_none());
        assert_eq!(none.remotes.len(), 2);
        assert_eq!(
            line("room-1", Some("bob")),
            "spectating room-1 - following bob (Tab: next)"
        );
    }

    #[test]
    fn follow_names_a_player_once_the_roster_does() {
        let mut s = Spectate::new(Some("bob".into()));
        let players = [PlayerId(2), PlayerId(5)];
        assert_eq!(s.followed(&players), Some(PlayerId(2)));
        let names = BTreeMap::from([(PlayerId(5), "bob".to_owned())]);
        s.find_wanted(&names);
        assert_eq!(s.followed(&players), Some(PlayerId(5)));
    }
}
