//! A watching camera's keys, for a replay and a spectator alike: Tab
//! follows the next player (Shift+Tab the one before), F frees the camera
//! (WASD moves it) or follows a player again. Whom it follows is a
//! [`Follow`] ([`ledge_client::follow`]); this holds the free camera's
//! centre and reads the keys.

use ledge_client::follow::Follow;
use ledge_shared::protocol::PlayerId;
use macroquad::input::{is_key_down, is_key_pressed, KeyCode};
use macroquad::math::{Rect, Vec2};

/// A free camera moves this many world pixels a second (WASD).
pub const PAN_PX_PER_SECOND: f32 = 480.0;

/// Where a watching camera looks (see the module documentation).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FollowCamera {
    /// Where it looked last frame, world px (a free camera starts there).
    focus: Vec2,
    /// A free camera's centre, world px.
    free: Vec2,
}

impl FollowCamera {
    /// Reads this frame's keys (`dt` seconds long) among `players`
    /// (ascending ids); returns whom to follow now, from `follow`.
    pub fn keys(&mut self, follow: Follow, players: &[PlayerId], dt: f32) -> Follow {
        let shift = is_key_down(KeyCode::LeftShift) || is_key_down(KeyCode::RightShift);
        let mut follow = follow;
        if is_key_pressed(KeyCode::Tab) {
            follow = follow.next(players, !shift);
        }
        if is_key_pressed(KeyCode::F) {
            if follow == Follow::Free {
                follow = follow.next(players, true);
            } else {
                follow = Follow::Free;
                self.free = self.focus;
            }
        }
        if follow == Follow::Free {
            let axis = |minus: KeyCode, plus: KeyCode| {
                f32::from(u8::from(is_key_down(plus))) - f32::from(u8::from(is_key_down(minus)))
            };
            let dir = Vec2::new(axis(KeyCode::A, KeyCode::D), axis(KeyCode::W, KeyCode::S));
            self.free += dir * PAN_PX_PER_SECOND * dt;
        }
        follow
    }

    /// Where to look this frame: the free camera's centre (kept inside
    /// `level_px`), else `followed` (the followed player's centre; the
    /// level's middle without one).
    pub fn focus(&mut self, follow: Follow, followed: Option<Vec2>, level_px: Rect) -> Vec2 {
        let focus = match follow {
            Follow::Free => {
                self.free = self
                    .free
                    .clamp(level_px.point(), level_px.point() + level_px.size());
                self.free
            }
            Follow::Player(_) => followed.unwrap_or_else(|| level_px.center()),
        };
        self.focus = focus;
        focus
    }
}
