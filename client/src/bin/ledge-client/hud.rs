//! The placeholder scene and the heads-up text.

use ledge_client::background::NetStatus;
use ledge_shared::input::Buttons;
use ledge_shared::world::World;
use macroquad::prelude::*;

const FONT_SIZE: f32 = 24.0;
const LINE: f32 = 28.0;

/// Draws one frame: a framed placeholder for the world, then the HUD.
pub fn draw(world: &World, buttons: Buttons, status: &NetStatus) {
    clear_background(Color::from_rgba(24, 26, 33, 255));
    let (w, h) = (screen_width(), screen_height());
    let margin = 40.0;
    draw_rectangle_lines(
        margin,
        margin * 4.0,
        w - 2.0 * margin,
        h - margin * 5.0,
        2.0,
        DARKGRAY,
    );
    let note = "warm-up room (drawing the world comes later)";
    let size = measure_text(note, None, FONT_SIZE as u16, 1.0);
    draw_text(
        note,
        (w - size.width) / 2.0,
        h / 2.0 + margin * 1.5,
        FONT_SIZE,
        GRAY,
    );

    let lines = [
        format!("tick {}", world.tick()),
        format!("state hash {:016x}", world.state_hash()),
        format!("buttons {} | {} fps", describe(buttons), get_fps()),
        status.to_string(),
    ];
    for (i, line) in lines.iter().enumerate() {
        draw_text(line, margin, margin + i as f32 * LINE, FONT_SIZE, WHITE);
    }
}

/// The held buttons as five symbols (`<>^vJ`), `.` where not held.
fn describe(buttons: Buttons) -> String {
    let names = [
        (Buttons::LEFT, '<'),
        (Buttons::RIGHT, '>'),
        (Buttons::UP, '^'),
        (Buttons::DOWN, 'v'),
        (Buttons::JUMP, 'J'),
    ];
    names
        .iter()
        .map(|&(bit, c)| if buttons.held(bit) { c } else { '.' })
        .collect()
}
