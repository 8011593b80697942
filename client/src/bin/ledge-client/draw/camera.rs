//! The camera: follows the local player smoothly, stays inside the level,
//! and maps world pixels to screen pixels. Recomputed every frame from the
//! window size, so resizing just works.
//!
//! Floats only: this is drawing, never simulation.

use macroquad::math::{Rect, Vec2};

/// World pixels visible vertically at the reference zoom (a window 540 px
/// high shows 270 world px at zoom 2).
pub const VIEW_HEIGHT_PX: f32 = 270.0;
/// At least this many world pixels are visible horizontally.
pub const MIN_VIEW_WIDTH_PX: f32 = 320.0;
/// How fast the camera closes the distance to its target (1/s): after
/// `1 / FOLLOW_RATE` seconds about 63% of the gap is gone.
pub const FOLLOW_RATE: f32 = 8.0;

/// The camera lags at most this fraction of half the view behind its
/// target.
pub const MAX_LAG: f32 = 0.4;

/// The world-to-screen transform of one frame: `screen = world * zoom +
/// offset` (pixels; y down in both).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Screen pixels per world pixel.
    pub zoom: f32,
    /// Screen position of the world origin.
    pub offset: Vec2,
    /// Screen size in pixels.
    pub screen: Vec2,
}

impl View {
    /// Screen position of world point `p` (world pixels).
    pub fn to_screen(self, p: Vec2) -> Vec2 {
        p * self.zoom + self.offset
    }

    /// World position (pixels) of screen point `s`.
    pub fn to_world(self, s: Vec2) -> Vec2 {
        (s - self.offset) / self.zoom
    }

    /// The visible part of the world, in world pixels.
    pub fn visible(self) -> Rect {
        let lo = self.to_world(Vec2::ZERO);
        let size = self.screen / self.zoom;
        Rect::new(lo.x, lo.y, size.x, size.y)
    }
}

/// The zoom for a window of `screen` pixels: about [`VIEW_HEIGHT_PX`]
/// world pixels high, at least [`MIN_VIEW_WIDTH_PX`] wide.
pub fn zoom_for(screen: Vec2) -> f32 {
    (screen.y / VIEW_HEIGHT_PX)
        .min(screen.x / MIN_VIEW_WIDTH_PX)
        .max(0.25)
}

/// A camera following a target.
#[derive(Debug, Clone)]
pub struct Camera {
    /// World pixel at the screen centre; `None` until the first frame.
    centre: Option<Vec2>,
    /// The level's player scale (1: ledge's own 12 x 16 px player): the
    /// view shows that many times the world, so a level made for a larger
    /// player looks as the default level does.
    scale: f32,
}

impl Default for Camera {
    fn default() -> Camera {
        Camera {
            centre: None,
            scale: 1.0,
        }
    }
}

impl Camera {
    /// A camera that snaps to its first target.
    pub fn new() -> Camera {
        Camera::default()
    }

    /// Follows the level's player scale from now on
    /// (`ledge_shared::level::PlayerScale::scale` / 256; values outside
    /// 1/8..=256 are held to it, a non-finite one is 1).
    pub fn set_scale(&mut self, scale: f32) {
        self.scale = if scale.is_finite() {
            scale.clamp(0.125, 256.0)
        } else {
            1.0
        };
    }

    /// Moves towards `target` (world px) for a frame of `dt` seconds, keeps
    /// the view inside `level` (world px; a level smaller than the view is
    /// centred), and returns the frame's transform for a `screen`-sized
    /// window. A target more than half a screen away (respawn, first
    /// frame) is jumped to; otherwise the camera eases towards it, never
    /// lagging more than [`MAX_LAG`] of half the view.
    pub fn update(&mut self, target: Vec2, level: Rect, screen: Vec2, dt: f32) -> View {
        let zoom = zoom_for(screen) / self.scale;
        let half_view = screen / zoom / 2.0;
        let goal = clamp_centre(target, level, half_view);
        let centre = match self.centre {
            Some(c) if (goal - c).abs().cmplt(half_view).all() => {
                let k = 1.0 - (-FOLLOW_RATE * dt.clamp(0.0, 0.25)).exp();
                let smooth = c + (goal - c) * k;
                // Never lag so far that the target leaves the middle of the
                // screen; then the level clamp again (a shrinking window
                // must not show outside the level).
                let lag = half_view * MAX_LAG;
                clamp_centre(smooth.clamp(goal - lag, goal + lag), level, half_view)
            }
            _ => goal,
        };
        self.centre = Some(centre);
        // Whole screen pixels: no shimmering edges while scrolling.
        let offset = (screen / 2.0 - centre * zoom).round();
        View {
            zoom,
            offset,
            screen,
        }
    }
}

/// `target` moved so that a view of `half_view` around it stays in `level`;
/// on an axis where the level is smaller than the view, the level's centre.
fn clamp_centre(target: Vec2, level: Rect, half_view: Vec2) -> Vec2 {
    let axis = |t: f32, lo: f32, size: f32, half: f32| {
        if size <= 2.0 * half {
            lo + size / 2.0
        } else {
            t.clamp(lo + half, lo + size - half)
        }
    };
    Vec2::new(
        axis(target.x, level.x, level.w, half_view.x),
        axis(target.y, level.y, level.h, half_view.y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const LEVEL: Rect = Rect {
        x: 0.0,
        y: 0.0,
        w: 1600.0,
        h: 480.0,
    };
    const SCREEN: Vec2 = Vec2::new(960.0, 540.0);

    #[test]
    fn snaps_first_then_follows_smoothly() {
        let mut cam = Camera::new();
        let v = cam.update(Vec2::new(800.0, 240.0), LEVEL, SCREEN, 1.0 / 60.0);
        assert_eq!(v.zoom, 2.0);
        assert_eq!(v.to_screen(Vec2::new(800.0, 240.0)), SCREEN / 2.0);
        let v = cam.update(Vec2::new(820.0, 240.0), LEVEL, SCREEN, 1.0 / 60.0);
        let x = v.to_screen(Vec2::new(820.0, 240.0)).x;
        assert!(x > 480.0 && x < 480.0 + 40.0, "lags behind: {x}");
        for _ in 0..240 {
            cam.update(Vec2::new(820.0, 240.0), LEVEL, SCREEN, 1.0 / 60.0);
        }
        let v = cam.update(Vec2::new(820.0, 240.0), LEVEL, SCREEN, 1.0 / 60.0);
        assert_eq!(v.to_screen(Vec2::new(820.0, 240.0)), SCREEN / 2.0);
    }

    #[test]
    fn never_lags_far_behind() {
        let mut cam = Camera::new();
        cam.update(Vec2::new(700.0, 240.0), LEVEL, SCREEN, 1.0 / 60.0);
        // 200 px to the left: smoothed, but at most MAX_LAG of the half view.
        let v = cam.update(Vec2::new(500.0, 240.0), LEVEL, SCREEN, 1.0 / 60.0);
        let x = v.to_screen(Vec2::new(500.0, 240.0)).x;
        let lag = (480.0 - x) / v.zoom;
        assert!(lag > 0.0 && lag <= 240.0 * MAX_LAG + 0.5, "lag {lag}");
        // A whole view away: jumped to.
        let v = cam.update(Vec2::new(1200.0, 240.0), LEVEL, SCREEN, 1.0 / 60.0);
        assert_eq!(v.to_screen(Vec2::new(1200.0, 240.0)).x, 480.0);
    }

    #[test]
    fn stays_inside_the_level() {
        let mut cam = Camera::new();
        let v = cam.update(Vec2::new(10.0, 470.0), LEVEL, SCREEN, 0.0);
        let seen = v.visible();
        assert_eq!((seen.x, seen.bottom()), (0.0, 480.0));
        let v = cam.update(Vec2::new(1590.0, 10.0), LEVEL, SCREEN, 0.0);
        let seen = v.visible();
        assert_eq!((seen.right(), seen.y), (1600.0, 0.0));
    }

    #[test]
    fn a_small_level_is_centred_and_resizing_recomputes() {
        let small = Rect::new(0.0, 0.0, 200.0, 100.0);
        let mut cam = Camera::new();
        let v = cam.update(Vec2::new(0.0, 0.0), small, SCREEN, 0.0);
        assert_eq!(v.to_screen(Vec2::new(100.0, 50.0)), SCREEN / 2.0);
        let big = Vec2::new(1920.0, 1080.0);
        let v = cam.update(Vec2::new(0.0, 0.0), small, big, 0.0);
        assert_eq!(v.zoom, 4.0);
        assert_eq!(v.to_screen(Vec2::new(100.0, 50.0)), big / 2.0);
    }

    #[test]
    fn a_level_for_a_larger_player_is_seen_from_further_away() {
        let big = Rect::new(0.0, 0.0, 16000.0, 4800.0);
        let mut plain = Camera::new();
        let mut scaled = Camera::new();
        scaled.set_scale(10.0);
        let a = plain.update(Vec2::new(800.0, 240.0), LEVEL, SCREEN, 0.0);
        let b = scaled.update(Vec2::new(8000.0, 2400.0), big, SCREEN, 0.0);
        assert_eq!(b.zoom * 10.0, a.zoom);
        // The same view of a level ten times as large.
        assert_eq!(b.visible().w, a.visible().w * 10.0);
        scaled.set_scale(f32::NAN);
        let c = scaled.update(Vec2::new(8000.0, 2400.0), big, SCREEN, 0.0);
        assert_eq!(c.zoom, a.zoom);
    }
}
