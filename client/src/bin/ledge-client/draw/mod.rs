//! What the window draws, each frame, from the game's views: where it looks
//! ([`camera`]), the world and the players ([`render`], the level's own art
//! in [`art`]), how the players move between ticks ([`anim`]), particles,
//! shake and flashes ([`fx`]), the ghosts to race ([`ghost`]), the heads-up display ([`hud`]), the results
//! card once our run is finished ([`card`]), the chat ([`chat`]), the
//! server's level list and a level's download ([`levels`]), the
//! debug overlay ([`debug`]) and the collision overlay ([`overlay`]); the world's layers in their order
//! ([`scene`]), and a replay's HUD ([`replay_hud`]).
//!
//! Grouped so that the front end's layout says what it does; this module
//! only declares them.

pub mod anim;
pub mod art;
pub mod camera;
pub mod card;
pub mod chat;
pub mod debug;
pub mod fx;
pub mod ghost;
pub mod hud;
pub mod levels;
pub mod overlay;
pub mod render;
pub mod replay_hud;
pub mod scene;
