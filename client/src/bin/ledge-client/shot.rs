//! `--screenshot PATH`: the frame as a PNG, and `PATH.json` beside it
//! describing where things are on it, so a test can check pixels:
//!
//! ```json
//! {
//!   "png": "shot.png",
//!   "tick": 150,                       // ticks of play when taken
//!   "screen": [960, 540],              // PNG size, pixels
//!   "camera": {"zoom": 2.0, "offset": [-12.0, -420.0]},
//!                                      // screen = world_px * zoom + offset
//!   "level_px": [0, 0, 1600, 480],     // x, y, w, h in world pixels
//!   "tile_px": 16,
//!   "player": {                        // null before the first snapshot
//!     "id": 1,
//!     "server_tick": 148,              // tick of the authoritative state
//!     "server_pos_units": [21504, 106496],
//!     "server_pos_px": [84.0, 416.0],  // centre of the box
//!     "server_screen": [156.0, 412.0], // that centre on the screen
//!     "size_px": [12.0, 16.0],
//!     "drawn_screen": [156.0, 412.0]   // where it was drawn (predicted)
//!   },
//!   "remotes": [                       // other players drawn, with their labels
//!     {"id": 2, "label": "bob", "drawn_screen": [60.0, 412.0], "size_px": [12.0, 16.0]}
//!   ],
//!   "ghosts": [                        // the ghosts drawn (none when hidden with G)
//!     {"kind": "record", "player": "bob", "run_tick": 212,  // "record" or "best"
//!      "pos_units": [52224, 106496], "pos_px": [204.0, 416.0], "screen": [400.0, 412.0]}
//!   ],
//!   "ghosts_shown": true,              // G: on
//!   "split": {"text": "+0.42", "faster": false, "checkpoint": 17, "against": "bob",
//!             "record": true},         // null unless a split is on screen
//!                                      // (checkpoint null: the finish's)
//!   "spectate": {                      // null unless --spectate
//!     "room": "room-1", "line": "spectating room-1 - following bob (Tab: next)",
//!     "free_camera": false,
//!     "following": {                   // null: nobody (free camera, empty room)
//!       "id": 2, "name": "bob",
//!       "drawn_px": [204.0, 416.0],    // its centre as drawn (interpolated)
//!       "drawn_screen": [400.0, 412.0],
//!       "render_tick": 1520.4,         // the game tick the others are drawn at
//!       "server_tick": 1526,           // the newest snapshot's tick
//!       "server_pos_units": [52224, 106496], "server_pos_px": [204.0, 416.0]
//!     }                                // (its centre in that snapshot)
//!   },
//!   "colors": {"sky": [r, g, b], "solid": [...], "grass": [...],
//!              "local_player": [...], "one_way": [...]},
//!   "hud": {                           // null when hidden (F2) or failed
//!     "name": "ada", "coins": 2, "coins_total": 10, "deaths": 1,
//!     "run_ticks": 412, "tick_rate": 60, "time": "0:06.86",
//!     "place": null, "results_card": false,
//!     "card": {                        // the results card; null unless drawn
//!       "panel": [330.0, 40.0, 348.0, 420.0],  // x, y, w, h
//!       "records": "recorded",         // "saving", "not_recorded"; null offline
//!       "lines": [                     // top to bottom, as drawn
//!         {"kind": "place", "text": "finished 1st", "baseline": 78.0, "size": 30.0},
//!         {"kind": "headline", "text": "new personal best!", "record": false},
//!         {"kind": "best", "text": "best 0:11.016 · #2 on this level",
//!          "millis": 11016, "time": "0:11.016", "rank": 2},
//!         {"kind": "top", "text": "1. bob 0:09.950", "place": 1, "name": "bob",
//!          "millis": 9950, "time": "0:09.950", "ours": false}, ...
//!       ]                              // kinds: place, time, tally, headline, best,
//!     },                               // top_title, top, saving, not_recorded, again
//!     "net_panel": false, "muted": false, "sound_notice": "sound off: ...",
//!     "results": [                     // the room's: everyone who finished
//!       {"place": 1, "name": "bob", "ticks": 598, "deaths": 0, "ours": false}
//!     ],
//!     "results_table": true            // drawn (someone besides us finished)
//!   },
//!   "fx": {                            // visual effects on screen
//!     "particles": 34, "shake_px": 2.5, "flash_alpha": 0.3,
//!     "recent": ["Jump", "Hurt"],      // effects started lately, oldest first
//!     "dead": true                     // our player waits to respawn
//!   },
//!   "chat": {                          // null when a failure covers the screen
//!     "lines": [                       // received lines drawn, oldest (top) first
//!       {"from": "bob", "text": "hi ada", "baseline": 460.0, "alpha": 1.0},
//!       {"from": null, "text": "muted eve (/unmute eve)", ...}  // the chat's own
//!     ],                               // names and texts as drawn (cut to fit)
//!     "typing": {"text": "say: hello_", "error": null, "baseline": 504.0},
//!                                      // null unless the chat line is open
//!     "muted": ["eve"]
//!   },
//!   "replay": {                        // null unless playing a replay (--replay)
//!     "tick": 1530,                    // the game's tick shown
//!     "start_tick": 0, "end_tick": 2400, "home": 0,  // its span; where it opened
//!     "speed": 1.0, "paused": false, "at_end": false, "run": false,
//!     "following": {"id": 2, "name": "bob"},  // null: nobody (free camera, empty game)
//!     "free_camera": false,
//!     "lines": {"clock": "replay 0:25.50 / 0:40.00   1x", "kind": "match   room-1 on Default",
//!               "follow": "following bob (Tab: next)   tick 1530", "failure": null},
//!     "end_banner": null               // ["end of replay", "Space or Home: ..."] when drawn
//!   },                                 // ("player" above is the followed player)
//!   "levels": {                        // null offline, in a replay, or before the server's list
//!     "rule": "majority",              // "off", "majority", "host"
//!     "current": 0, "next": 1,         // indexes into "list"
//!     "change_at": 5400,               // the room tick it moves on at; null: not decided
//!     "list": [{"number": 1, "id": "default", "name": "default", "votes": 0,
//!               "current": true, "next": false}, ...],
//!     "panel": {                       // the list's panel (V); null when closed
//!       "title": "levels - vote: ...", "lines": ["1. default   0 votes   < playing", ...],
//!       "more": 0, "footer": ["next level in 4 s", "1-2: vote   V: close"]
//!     },
//!     "next_line": "next: second in 4 s",  // the HUD's line; null unless decided
//!     "level_changes": 1               // the room's moves to another level seen
//!   },
//!   "downloading": {"what": "the next level", "got": 1024, "total": 4096},
//!                                      // the progress bar; null unless a level downloads
//!   "failure": {                       // null unless the session failed
//!     "message": "cannot join ...",    // as printed on stderr
//!     "font_size": 20.0,
//!     "panel": [40.0, 16.0, 400.0, 200.0],  // x, y, w, h: the text is inside
//!     "panel_color": [r, g, b],
//!     "lines": ["cannot join ...", ..., "Esc quits"]
//!   }
//! }
//! ```

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use glam::IVec2;
use macroquad::math::{Rect, Vec2};
use macroquad::texture::get_screen_data;

use crate::draw::camera::View;
use crate::draw::card::{millis_time, Card, Says};
use crate::draw::ghost::GhostSprite;
use crate::draw::hud::{BannerLayout, FAILURE_PANEL};
use crate::draw::render::{palette, PlayerSprite};
use crate::splits::Split;

/// What a screenshot records.
pub struct Shot<'a> {
    /// Ticks of play.
    pub tick: u64,
    /// The frame's camera.
    pub view: &'a View,
    /// The level's bounds, world pixels.
    pub level_px: Rect,
    /// Tile size, pixels.
    pub tile_px: i32,
    /// Our player as the server last said: `(tick, id, centre, half
    /// extents)` in units.
    pub server: Option<(u64, u32, IVec2, IVec2)>,
    /// Where our player was drawn (world px, centre).
    pub drawn: Option<Vec2>,
    /// The other players drawn.
    pub remotes: Vec<RemoteShot<'a>>,
    /// The HUD as drawn (`None` when hidden).
    pub hud: Option<HudShot<'a>>,
    /// The session's failure and its banner as drawn, if it failed.
    pub failure: Option<(&'a str, &'a BannerLayout)>,
    /// The chat as drawn (`None` when a failure covers the screen).
    pub chat: Option<ChatShot<'a>>,
    /// The visual effects on screen.
    pub fx: FxShot<'a>,
    /// The replay shown, if it is one (`--replay`).
    pub replay: Option<ReplayShot<'a>>,
    /// The ghosts drawn.
    pub ghosts: &'a [GhostSprite],
    /// Ghosts are on (their key).
    pub ghosts_shown: bool,
    /// The split on screen and its text, if any.
    pub split: Option<(&'a Split, String)>,
    /// What a spectator watched (`--spectate`).
    pub spectate: Option<SpectateShot<'a>>,
    /// The server's levels as shown (`None`: offline, a replay, or no
    /// list from the server yet).
    pub levels: Option<LevelsShot<'a>>,
    /// A level downloading, as its progress bar showed it: what, bytes so
    /// far, its size.
    pub downloading: Option<(&'a str, u64, u64)>,
}

/// The server's levels as the window showed them.
pub struct LevelsShot<'a> {
    /// The list as the server last sent it.
    pub list: &'a ledge_shared::protocol::LevelList,
    /// The list's panel as drawn (`None`: closed).
    pub panel: Option<&'a crate::draw::levels::LevelsView>,
    /// The HUD's "next: NAME in N s", when drawn.
    pub next_line: Option<&'a str>,
    /// The room's level changes seen so far.
    pub level_changes: u64,
}

/// A spectator's frame.
pub struct SpectateShot<'a> {
    /// The room watched.
    pub room: &'a str,
    /// The HUD's line.
    pub line: &'a str,
    /// The camera is free.
    pub free_camera: bool,
    /// The followed player: id, name, centre as drawn (world px).
    pub following: Option<(u32, &'a str, Vec2)>,
    /// The game tick the other players are drawn at.
    pub render_tick: f64,
    /// The followed player in the newest snapshot: its tick and centre
    /// (units).
    pub server: Option<(u64, IVec2)>,
}

/// A replay's frame.
pub struct ReplayShot<'a> {
    /// The game's tick shown.
    pub tick: u64,
    /// The game's tick where the replay starts.
    pub start_tick: u64,
    /// Where it ends.
    pub end_tick: u64,
    /// Where it opened (a run's start).
    pub home: u64,
    /// Its speed (1: as played).
    pub speed: f32,
    /// Paused by the viewer.
    pub paused: bool,
    /// At its end (or where it failed).
    pub at_end: bool,
    /// A run's replay (else a match's).
    pub run: bool,
    /// The followed player's id and name.
    pub following: Option<(u32, &'a str)>,
    /// The camera is free.
    pub free_camera: bool,
    /// The replay's HUD lines.
    pub lines: &'a crate::draw::replay_hud::ReplayLines,
    /// The end's notice (its paragraphs), when drawn.
    pub end_banner: Option<&'a [&'a str]>,
}

/// The chat when the frame was taken.
pub struct ChatShot<'a> {
    /// As laid out and drawn.
    pub view: &'a crate::draw::chat::ChatView,
    /// The players muted, by name.
    pub muted: Vec<&'a str>,
}

/// The visual effects on screen when the frame was taken.
pub struct FxShot<'a> {
    /// Particles alive.
    pub particles: usize,
    /// The screen shake's offset, screen px.
    pub shake: f32,
    /// The flash's opacity.
    pub flash: f32,
    /// The effects started lately, oldest first.
    pub recent: &'a [crate::sound::audio::Effect],
    /// Our player is dead (waiting to respawn).
    pub dead: bool,
}

/// What the HUD showed.
pub struct HudShot<'a> {
    /// The name shown.
    pub name: &'a str,
    /// Our run (`None` before we are in the game).
    pub run: Option<crate::draw::hud::RunInfo>,
    /// The network panel was shown.
    pub net_panel: bool,
    /// The muted marker was shown.
    pub muted: bool,
    /// The sound notice shown, if any.
    pub sound_notice: Option<&'a str>,
    /// The room's results (the table is drawn when someone besides us is
    /// in it).
    pub results: &'a [crate::draw::hud::ResultRow],
    /// The results card as drawn, once our run is finished.
    pub card: Option<&'a Card>,
}

/// A remote player as drawn.
pub struct RemoteShot<'a> {
    /// Its id.
    pub id: u32,
    /// The label drawn above it (its name, once known).
    pub label: &'a str,
    /// Centre of its box, world px.
    pub pos: Vec2,
    /// Size of its box, world px.
    pub size: Vec2,
}

/// The remote players drawn (`sprites`), each with its label (`labels`,
/// in the same order).
pub fn remotes<'a>(sprites: &[PlayerSprite], labels: &'a [String]) -> Vec<RemoteShot<'a>> {
    sprites
        .iter()
        .zip(labels)
        .map(|(p, label)| RemoteShot {
            id: p.id,
            label,
            pos: p.pos,
            size: p.size,
        })
        .collect()
}

/// The JSON path for screenshot `png`: `png` with `.json` appended.
pub fn json_path(png: &Path) -> PathBuf {
    let mut s = png.as_os_str().to_owned();
    s.push(".json");
    PathBuf::from(s)
}

/// Saves the current frame to `path` and the description beside it.
pub fn save(path: &Path, shot: &Shot) -> std::io::Result<()> {
    let image = get_screen_data();
    let text = path
        .to_str()
        .ok_or_else(|| std::io::Error::other("the screenshot path is not UTF-8"))?;
    image.export_png(text);
    let json = describe(shot, path, image.width, image.height);
    std::fs::write(json_path(path), json)
}

fn pair(v: Vec2) -> String {
    format!("[{:.3}, {:.3}]", v.x, v.y)
}

/// `text` as a JSON string.
fn json_string(text: &str) -> String {
    let mut s = String::from("\"");
    for c in text.chars() {
        match c {
            '"' => s.push_str("\\\""),
            '\\' => s.push_str("\\\\"),
            c if u32::from(c) < 0x20 => {
                let _ = write!(s, "\\u{:04x}", u32::from(c));
            }
            c => s.push(c),
        }
    }
    s.push('"');
    s
}

fn rgb(c: macroquad::color::Color) -> String {
    let [r, g, b] = palette::bytes(c);
    format!("[{r}, {g}, {b}]")
}

/// The JSON text (see the module documentation).
pub fn describe(shot: &Shot, png: &Path, width: u16, height: u16) -> String {
    let v = shot.view;
    let mut s = String::from("{\n");
    let name = png
        .file_name()
        .map(|n| n.to_string_lossy().replace(['"', '\\'], "_"))
        .unwrap_or_default();
    let _ = writeln!(s, "  \"png\": \"{name}\",");
    let _ = writeln!(s, "  \"tick\": {},", shot.tick);
    let _ = writeln!(s, "  \"screen\": [{width}, {height}],");
    let _ = writeln!(
        s,
        "  \"camera\": {{\"zoom\": {:.4}, \"offset\": {}}},",
        v.zoom,
        pair(v.offset)
    );
    let l = shot.level_px;
    let _ = writeln!(s, "  \"level_px\": [{}, {}, {}, {}],", l.x, l.y, l.w, l.h);
    let _ = writeln!(s, "  \"tile_px\": {},", shot.tile_px);
    describe_player(&mut s, shot);
    let remotes: Vec<String> = shot
        .remotes
        .iter()
        .map(|r| {
            format!(
                "    {{\"id\": {}, \"label\": \"{}\", \"drawn_screen\": {}, \"size_px\": {}}}",
                r.id,
                r.label.replace(['"', '\\'], "_"),
                pair(v.to_screen(r.pos)),
                pair(r.size)
            )
        })
        .collect();
    if remotes.is_empty() {
        let _ = writeln!(s, "  \"remotes\": [],");
    } else {
        let _ = writeln!(s, "  \"remotes\": [\n{}\n  ],", remotes.join(",\n"));
    }
    describe_ghosts(&mut s, shot);
    describe_spectate(&mut s, shot);
    let _ = writeln!(
        s,
        "  \"colors\": {{\"sky\": {}, \"solid\": {}, \"grass\": {}, \"local_player\": {}, \"one_way\": {}}},",
        rgb(palette::SKY),
        rgb(palette::SOLID),
        rgb(palette::GRASS),
        rgb(palette::LOCAL_PLAYER),
        rgb(palette::PLANK),
    );
    describe_hud(&mut s, shot.hud.as_ref());
    let fx = &shot.fx;
    let recent: Vec<String> = fx
        .recent
        .iter()
        .map(|e| json_string(&format!("{e:?}")))
        .collect();
    let _ = writeln!(
        s,
        "  \"fx\": {{\"particles\": {}, \"shake_px\": {:.3}, \"flash_alpha\": {:.3}, \"recent\": [{}], \"dead\": {}}},",
        fx.particles,
        fx.shake,
        fx.flash,
        recent.join(", "),
        fx.dead
    );
    describe_chat(&mut s, shot.chat.as_ref());
    describe_replay(&mut s, shot.replay.as_ref());
    describe_levels(&mut s, shot.levels.as_ref());
    match shot.downloading {
        Some((what, got, total)) => {
            let _ = writeln!(
                s,
                "  \"downloading\": {{\"what\": {}, \"got\": {got}, \"total\": {total}}},",
                json_string(what)
            );
        }
        None => {
            let _ = writeln!(s, "  \"downloading\": null,");
        }
    }
    describe_failure(&mut s, shot.failure);
    s.push_str("}\n");
    s
}

/// `value` as JSON, `null` when absent.
fn json_or_null<T: std::fmt::Display>(value: Option<T>) -> String {
    value.map_or_else(|| "null".to_owned(), |v| v.to_string())
}

/// The server's levels (`null` without a list): the list, the panel if
/// open, the HUD's line.
fn describe_levels(s: &mut String, levels: Option<&LevelsShot>) {
    let Some(l) = levels else {
        let _ = writeln!(s, "  \"levels\": null,");
        return;
    };
    let list = l.list;
    let rows: Vec<String> = list
        .levels
        .iter()
        .enumerate()
        .map(|(i, level)| {
            format!(
                "{{\"number\": {}, \"id\": {}, \"name\": {}, \"votes\": {}, \"current\": {}, \"next\": {}}}",
                i + 1,
                json_string(&level.id),
                json_string(&level.name),
                list.votes.get(i).copied().unwrap_or(0),
                i == list.current as usize,
                i == list.next as usize
            )
        })
        .collect();
    let panel = l.panel.map_or_else(
        || "null".to_owned(),
        |p| {
            let strings = |v: &mut dyn Iterator<Item = &str>| {
                v.map(json_string).collect::<Vec<_>>().join(", ")
            };
            format!(
                "{{\"title\": {}, \"lines\": [{}], \"more\": {}, \"footer\": [{}]}}",
                json_string(&p.title),
                strings(&mut p.rows.iter().map(|r| r.text.as_str())),
                p.more,
                strings(&mut p.footer.iter().map(String::as_str))
            )
        },
    );
    let _ = writeln!(s, "  \"levels\": {{");
    let _ = writeln!(s, "    \"rule\": {},", json_string(list.rule.name()));
    let _ = writeln!(
        s,
        "    \"current\": {}, \"next\": {},",
        list.current, list.next
    );
    let _ = writeln!(s, "    \"change_at\": {},", json_or_null(list.change_at));
    let _ = writeln!(s, "    \"list\": [{}],", rows.join(", "));
    let _ = writeln!(s, "    \"panel\": {panel},");
    let next = l.next_line.map_or("null".to_owned(), json_string);
    let _ = writeln!(s, "    \"next_line\": {next},");
    let _ = writeln!(s, "    \"level_changes\": {}", l.level_changes);
    let _ = writeln!(s, "  }},");
}

/// What a spectator watched (`null` unless spectating).
fn describe_spectate(s: &mut String, shot: &Shot) {
    let Some(w) = &shot.spectate else {
        let _ = writeln!(s, "  \"spectate\": null,");
        return;
    };
    let following = match w.following {
        Some((id, name, pos)) => {
            let server = match w.server {
                Some((tick, units)) => format!(
                    "\"server_tick\": {tick}, \"server_pos_units\": [{}, {}], \"server_pos_px\": {}",
                    units.x,
                    units.y,
                    pair(Vec2::new(units.x as f32, units.y as f32) / 256.0)
                ),
                None => "\"server_tick\": null, \"server_pos_units\": null, \"server_pos_px\": null".to_owned(),
            };
            format!(
                "{{\"id\": {id}, \"name\": {}, \"drawn_px\": {}, \"drawn_screen\": {}, \"render_tick\": {:.3}, {server}}}",
                json_string(name),
                pair(pos),
                pair(shot.view.to_screen(pos)),
                w.render_tick
            )
        }
        None => "null".to_owned(),
    };
    let _ = writeln!(
        s,
        "  \"spectate\": {{\"room\": {}, \"line\": {}, \"free_camera\": {}, \"following\": {following}}},",
        json_string(w.room),
        json_string(w.line),
        w.free_camera
    );
}

/// The ghosts drawn and the split shown.
fn describe_ghosts(s: &mut String, shot: &Shot) {
    let v = shot.view;
    let ghosts: Vec<String> = shot
        .ghosts
        .iter()
        .map(|g| {
            format!(
                "    {{\"kind\": \"{}\", \"player\": {}, \"run_tick\": {}, \"pos_units\": [{}, {}], \"pos_px\": {}, \"screen\": {}}}",
                if g.record { "record" } else { "best" },
                json_string(&g.player),
                g.run_tick,
                g.units.x,
                g.units.y,
                pair(g.sprite.pos),
                pair(v.to_screen(g.sprite.pos))
            )
        })
        .collect();
    if ghosts.is_empty() {
        let _ = writeln!(s, "  \"ghosts\": [],");
    } else {
        let _ = writeln!(s, "  \"ghosts\": [\n{}\n  ],", ghosts.join(",\n"));
    }
    let _ = writeln!(s, "  \"ghosts_shown\": {},", shot.ghosts_shown);
    match &shot.split {
        Some((split, text)) => {
            let _ = writeln!(
                s,
                "  \"split\": {{\"text\": {}, \"faster\": {}, \"checkpoint\": {}, \"against\": {}, \"record\": {}}},",
                json_string(text),
                split.faster(),
                split.checkpoint.map_or("null".to_owned(), |c| c.to_string()),
                json_string(&split.against),
                split.record
            );
        }
        None => {
            let _ = writeln!(s, "  \"split\": null,");
        }
    }
}

/// Our player, as the server last said and as drawn (`null` before the
/// first snapshot).
fn describe_player(s: &mut String, shot: &Shot) {
    let v = shot.view;
    let px = |u: IVec2| Vec2::new(u.x as f32, u.y as f32) / 256.0;
    match shot.server {
        Some((tick, id, pos, half)) => {
            let p = px(pos);
            let _ = writeln!(s, "  \"player\": {{");
            let _ = writeln!(s, "    \"id\": {id},");
            let _ = writeln!(s, "    \"server_tick\": {tick},");
            let _ = writeln!(s, "    \"server_pos_units\": [{}, {}],", pos.x, pos.y);
            let _ = writeln!(s, "    \"server_pos_px\": {},", pair(p));
            let _ = writeln!(s, "    \"server_screen\": {},", pair(v.to_screen(p)));
            let _ = writeln!(s, "    \"size_px\": {},", pair(px(half * 2)));
            match shot.drawn {
                Some(d) => {
                    let _ = writeln!(s, "    \"drawn_screen\": {}", pair(v.to_screen(d)));
                }
                None => {
                    let _ = writeln!(s, "    \"drawn_screen\": null");
                }
            }
            let _ = writeln!(s, "  }},");
        }
        None => {
            let _ = writeln!(s, "  \"player\": null,");
        }
    }
}

/// The HUD as drawn (`null` when hidden).
fn describe_hud(s: &mut String, hud: Option<&HudShot>) {
    match hud {
        Some(h) => {
            let _ = writeln!(s, "  \"hud\": {{");
            let _ = writeln!(s, "    \"name\": {},", json_string(h.name));
            if let Some(r) = &h.run {
                let _ = writeln!(s, "    \"coins\": {},", r.coins);
                let _ = writeln!(s, "    \"coins_total\": {},", r.coins_total);
                let _ = writeln!(s, "    \"deaths\": {},", r.deaths);
                let _ = writeln!(s, "    \"run_ticks\": {},", r.run_ticks);
                let _ = writeln!(s, "    \"tick_rate\": {},", r.tick_rate);
                let time = crate::draw::hud::run_time(r.run_ticks, r.tick_rate);
                let _ = writeln!(s, "    \"time\": {},", json_string(&time));
                let place = r.place.map_or("null".to_owned(), |p| p.to_string());
                let _ = writeln!(s, "    \"place\": {place},");
                let _ = writeln!(s, "    \"results_card\": {},", h.card.is_some());
            }
            describe_card(s, h.card);
            let _ = writeln!(s, "    \"net_panel\": {},", h.net_panel);
            let _ = writeln!(s, "    \"muted\": {},", h.muted);
            let notice = h.sound_notice.map_or("null".to_owned(), json_string);
            let _ = writeln!(s, "    \"sound_notice\": {notice},");
            let rows: Vec<String> = h
                .results
                .iter()
                .map(|r| {
                    format!(
                        "{{\"place\": {}, \"name\": {}, \"ticks\": {}, \"deaths\": {}, \"ours\": {}}}",
                        r.place,
                        json_string(&r.name),
                        r.ticks,
                        r.deaths,
                        r.ours
                    )
                })
                .collect();
            let _ = writeln!(s, "    \"results\": [{}],", rows.join(", "));
            let _ = writeln!(
                s,
                "    \"results_table\": {}",
                crate::draw::hud::shows_table(h.results)
            );
            let _ = writeln!(s, "  }},");
        }
        None => {
            let _ = writeln!(s, "  \"hud\": null,");
        }
    }
}

/// The chat as drawn (`null` under a failure): the received lines, the
/// line being typed, who is muted.
fn describe_chat(s: &mut String, chat: Option<&ChatShot>) {
    let Some(chat) = chat else {
        let _ = writeln!(s, "  \"chat\": null,");
        return;
    };
    let lines: Vec<String> = chat
        .view
        .lines
        .iter()
        .map(|l| {
            format!(
                "      {{\"from\": {}, \"text\": {}, \"baseline\": {:.1}, \"alpha\": {:.3}}}",
                l.from.as_deref().map_or("null".to_owned(), json_string),
                json_string(&l.text),
                l.baseline,
                l.alpha
            )
        })
        .collect();
    let typing = chat.view.typing.as_ref().map_or("null".to_owned(), |t| {
        format!(
            "{{\"text\": {}, \"error\": {}, \"baseline\": {:.1}}}",
            json_string(&t.text),
            t.error.as_deref().map_or("null".to_owned(), json_string),
            t.baseline
        )
    });
    let muted: Vec<String> = chat.muted.iter().map(|m| json_string(m)).collect();
    let _ = writeln!(s, "  \"chat\": {{");
    if lines.is_empty() {
        let _ = writeln!(s, "    \"lines\": [],");
    } else {
        let _ = writeln!(s, "    \"lines\": [\n{}\n    ],", lines.join(",\n"));
    }
    let _ = writeln!(s, "    \"typing\": {typing},");
    let _ = writeln!(s, "    \"muted\": [{}]", muted.join(", "));
    let _ = writeln!(s, "  }},");
}

/// The results card as drawn (`null` when it is not): its panel, what it
/// says of the records (`null` offline) and its lines, each with its
/// kind, text, baseline and font size, and a top run's place, name (as drawn), time and whether
/// it is ours, our best's time and rank.
fn describe_card(s: &mut String, card: Option<&Card>) {
    let Some(card) = card else {
        let _ = writeln!(s, "    \"card\": null,");
        return;
    };
    let p = card.panel;
    let records = card.records.map_or("null".to_owned(), json_string);
    let lines: Vec<String> = card.lines.iter().map(describe_card_line).collect();
    let _ = writeln!(s, "    \"card\": {{");
    let _ = writeln!(
        s,
        "      \"panel\": [{:.3}, {:.3}, {:.3}, {:.3}],",
        p.x, p.y, p.w, p.h
    );
    let _ = writeln!(s, "      \"records\": {records},");
    let _ = writeln!(
        s,
        "      \"lines\": [\n        {}\n      ]",
        lines.join(",\n        ")
    );
    let _ = writeln!(s, "    }},");
}

/// One line of the card, as a JSON object.
fn describe_card_line(line: &crate::draw::card::Line) -> String {
    let extra = match &line.says {
        Says::Top {
            place,
            name,
            millis,
            ours,
        } => format!(
            ", \"place\": {place}, \"name\": {}, \"millis\": {millis}, \"time\": {}, \"ours\": {ours}",
            json_string(name),
            json_string(&millis_time(*millis))
        ),
        Says::Best { millis, rank } => format!(
            ", \"millis\": {millis}, \"time\": {}, \"rank\": {rank}",
            json_string(&millis_time(*millis))
        ),
        Says::Headline { record } => format!(", \"record\": {record}"),
        _ => String::new(),
    };
    format!(
        "{{\"kind\": \"{}\", \"text\": {}, \"baseline\": {:.3}, \"size\": {:.3}{extra}}}",
        line.says.kind(),
        json_string(&line.text),
        line.baseline,
        line.size
    )
}

/// The replay's frame (`null` unless it is one).
fn describe_replay(s: &mut String, replay: Option<&ReplayShot>) {
    let Some(r) = replay else {
        let _ = writeln!(s, "  \"replay\": null,");
        return;
    };
    let following = r.following.map_or("null".to_owned(), |(id, name)| {
        format!("{{\"id\": {id}, \"name\": {}}}", json_string(name))
    });
    let l = r.lines;
    let failure = l.failure.as_deref().map_or("null".to_owned(), json_string);
    let end = r.end_banner.map_or("null".to_owned(), |paragraphs| {
        let texts: Vec<String> = paragraphs.iter().map(|p| json_string(p)).collect();
        format!("[{}]", texts.join(", "))
    });
    let _ = writeln!(s, "  \"replay\": {{");
    let _ = writeln!(s, "    \"tick\": {},", r.tick);
    let _ = writeln!(s, "    \"start_tick\": {},", r.start_tick);
    let _ = writeln!(s, "    \"end_tick\": {},", r.end_tick);
    let _ = writeln!(s, "    \"home\": {},", r.home);
    let _ = writeln!(s, "    \"speed\": {},", r.speed);
    let _ = writeln!(s, "    \"paused\": {},", r.paused);
    let _ = writeln!(s, "    \"at_end\": {},", r.at_end);
    let _ = writeln!(s, "    \"run\": {},", r.run);
    let _ = writeln!(s, "    \"following\": {following},");
    let _ = writeln!(s, "    \"free_camera\": {},", r.free_camera);
    let _ = writeln!(
        s,
        "    \"lines\": {{\"clock\": {}, \"kind\": {}, \"follow\": {}, \"failure\": {failure}}},",
        json_string(&l.clock),
        json_string(&l.kind),
        json_string(&l.follow)
    );
    let _ = writeln!(s, "    \"end_banner\": {end}");
    let _ = writeln!(s, "  }},");
}

/// The session's failure and its panel (`null` unless it failed).
fn describe_failure(s: &mut String, failure: Option<(&str, &BannerLayout)>) {
    match failure {
        Some((message, layout)) => {
            let p = layout.panel;
            let lines: Vec<String> = layout.lines.iter().map(|(_, l)| json_string(l)).collect();
            let _ = writeln!(s, "  \"failure\": {{");
            let _ = writeln!(s, "    \"message\": {},", json_string(message));
            let _ = writeln!(s, "    \"font_size\": {:.1},", layout.size);
            let _ = writeln!(
                s,
                "    \"panel\": [{:.3}, {:.3}, {:.3}, {:.3}],",
                p.x, p.y, p.w, p.h
            );
            let _ = writeln!(s, "    \"panel_color\": {},", rgb(FAILURE_PANEL));
            let _ = writeln!(s, "    \"lines\": [{}]", lines.join(", "));
            let _ = writeln!(s, "  }}");
        }
        None => {
            let _ = writeln!(s, "  \"failure\": null");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shot of nothing (no player, HUD, chat, effects...) in `view`:
    /// each test sets what it looks at.
    fn blank(view: &View) -> Shot<'_> {
        Shot {
            tick: 0,
            view,
            level_px: Rect::new(0.0, 0.0, 1.0, 1.0),
            tile_px: 16,
            server: None,
            drawn: None,
            remotes: Vec::new(),
            hud: None,
            failure: None,
            chat: None,
            fx: FxShot {
                particles: 0,
                shake: 0.0,
                flash: 0.0,
                recent: &[],
                dead: false,
            },
            replay: None,
            ghosts: &[],
            ghosts_shown: true,
            split: None,
            spectate: None,
            levels: None,
            downloading: None,
        }
    }

    #[test]
    fn json_lists_the_chat_lines_drawn() {
        use crate::chat::Shown;
        use crate::draw::chat::layout;
        let view = View {
            zoom: 2.0,
            offset: Vec2::ZERO,
            screen: Vec2::new(960.0, 540.0),
        };
        let shown = [
            Shown {
                from: Some("bob \"b\""),
                text: "hi ada",
                alpha: 0.5,
            },
            Shown {
                from: None,
                text: "muted eve (/unmute eve)",
                alpha: 1.0,
            },
        ];
        let chat = layout(
            &shown,
            Some(("gg".to_owned(), Some("not sent: why"))),
            Vec2::new(960.0, 540.0),
            |t| t.len() as f32 * 8.0,
        );
        let shot = Shot {
            tick: 1,
            level_px: Rect::new(0.0, 0.0, 100.0, 100.0),
            chat: Some(ChatShot {
                view: &chat,
                muted: vec!["eve"],
            }),
            ..blank(&view)
        };
        let json = describe(&shot, Path::new("c.png"), 960, 540);
        let parsed: serde_json::Value = serde_json::from_str(&json).expect(&json);
        let c = &parsed["chat"];
        assert_eq!(c["lines"][0]["from"], "bob \"b\"");
        assert_eq!(c["lines"][0]["text"], "hi ada");
        assert_eq!(c["lines"][0]["alpha"], 0.5);
        assert!(c["lines"][1]["from"].is_null());
        assert_eq!(c["typing"]["text"], "say: gg_");
        assert_eq!(c["typing"]["error"], "not sent: why");
        assert_eq!(c["muted"][0], "eve");
    }

    #[test]
    fn json_names_the_player_on_screen() {
        let view = View {
            zoom: 2.0,
            offset: Vec2::new(-10.0, -20.0),
            screen: Vec2::new(960.0, 540.0),
        };
        let shot = Shot {
            tick: 7,
            level_px: Rect::new(0.0, 0.0, 1600.0, 480.0),
            server: Some((
                5,
                3,
                IVec2::new(256 * 100, 256 * 50),
                IVec2::new(1536, 2048),
            )),
            drawn: Some(Vec2::new(100.0, 50.0)),
            remotes: vec![RemoteShot {
                id: 4,
                label: "bo \"b\"",
                pos: Vec2::new(10.0, 20.0),
                size: Vec2::new(12.0, 16.0),
            }],
            hud: Some(HudShot {
                name: "ada \"x\"",
                run: Some(crate::draw::hud::RunInfo {
                    coins: 2,
                    coins_total: 10,
                    deaths: 1,
                    run_ticks: 604,
                    tick_rate: 60,
                    place: None,
                }),
                net_panel: false,
                muted: true,
                sound_notice: None,
                results: &[
                    crate::draw::hud::ResultRow {
                        place: 1,
                        name: "bo".into(),
                        ticks: 600,
                        deaths: 0,
                        ours: false,
                    },
                    crate::draw::hud::ResultRow {
                        place: 2,
                        name: "ada \"x\"".into(),
                        ticks: 604,
                        deaths: 1,
                        ours: true,
                    },
                ],
                card: None,
            }),
            fx: FxShot {
                particles: 12,
                shake: 1.5,
                flash: 0.25,
                recent: &[crate::sound::audio::Effect::Hurt],
                dead: true,
            },
            ..blank(&view)
        };
        let json = describe(&shot, Path::new("/tmp/a.png"), 960, 540);
        let parsed: serde_json::Value = serde_json::from_str(&json).expect("JSON");
        assert_eq!(parsed["fx"]["particles"], 12);
        assert_eq!(parsed["fx"]["recent"][0], "Hurt");
        assert_eq!(parsed["fx"]["dead"], true);
        assert_eq!(parsed["fx"]["flash_alpha"], 0.25);
        let hud = &parsed["hud"];
        assert_eq!(hud["name"], "ada \"x\"");
        assert_eq!(hud["coins"], 2);
        assert_eq!(hud["coins_total"], 10);
        assert_eq!(hud["deaths"], 1);
        assert_eq!(hud["run_ticks"], 604);
        assert_eq!(hud["time"], "0:10.06");
        assert!(hud["place"].is_null());
        assert_eq!(hud["net_panel"], false);
        assert_eq!(hud["muted"], true);
        assert!(hud["sound_notice"].is_null());
        assert_eq!(hud["results"][1]["name"], "ada \"x\"");
        assert_eq!(hud["results"][0]["ticks"], 600);
        assert_eq!(hud["results_table"], true);
        assert!(
            json.contains("\"server_screen\": [190.000, 80.000]"),
            "{json}"
        );
        assert!(json.contains("\"size_px\": [12.000, 16.000]"), "{json}");
        assert!(json.contains("\"png\": \"a.png\""), "{json}");
        assert!(
            json.contains(
                "{\"id\": 4, \"label\": \"bo _b_\", \"drawn_screen\": [10.000, 20.000], \
                 \"size_px\": [12.000, 16.000]}"
            ),
            "{json}"
        );
        assert_eq!(
            json_path(Path::new("x/s.png")),
            PathBuf::from("x/s.png.json")
        );
    }

    #[test]
    fn json_tells_the_failure_as_printed() {
        let view = View {
            zoom: 1.0,
            offset: Vec2::ZERO,
            screen: Vec2::new(480.0, 270.0),
        };
        let message = "the server plays level \"a\\b\"\tnow";
        let layout = BannerLayout {
            size: 20.0,
            lines: vec![(0, message.to_owned()), (1, "Esc quits".to_owned())],
            panel: Rect::new(40.0, 16.0, 400.0, 80.5),
        };
        let shot = Shot {
            failure: Some((message, &layout)),
            ..blank(&view)
        };
        let json: serde_json::Value =
            serde_json::from_str(&describe(&shot, Path::new("f.png"), 480, 270)).expect("JSON");
        let failure = &json["failure"];
        assert_eq!(failure["message"], message);
        assert_eq!(failure["lines"][1], "Esc quits");
        assert_eq!(failure["panel"][3], 80.5);
        assert_eq!(failure["font_size"], 20.0);
        let none = Shot {
            failure: None,
            chat: None,
            ..shot
        };
        let json: serde_json::Value =
            serde_json::from_str(&describe(&none, Path::new("f.png"), 480, 270)).expect("JSON");
        assert!(json["failure"].is_null());
    }

    /// The level list: each level with its votes and marks, the panel's
    /// lines when open, the HUD's line, a download's progress.
    #[test]
    fn json_tells_the_levels_the_panel_and_a_download() {
        use ledge_shared::protocol::{LevelChoice, LevelList, VoteRule};
        let view = View {
            zoom: 1.0,
            offset: Vec2::ZERO,
            screen: Vec2::new(480.0, 270.0),
        };
        let list = LevelList {
            levels: ["default", "se\"cond"]
                .map(|n| LevelChoice {
                    id: n.into(),
                    name: n.into(),
                })
                .to_vec(),
            current: 0,
            next: 1,
            votes: vec![0, 2],
            rule: VoteRule::Majority,
            change_at: Some(900),
        };
        let panel = crate::draw::levels::view(&list, Some(std::time::Duration::from_secs(4)));
        let shot = Shot {
            levels: Some(LevelsShot {
                list: &list,
                panel: Some(&panel),
                next_line: Some("next: second in 4 s"),
                level_changes: 2,
            }),
            downloading: Some(("the next level", 1024, 4096)),
            ..blank(&view)
        };
        let json: serde_json::Value =
            serde_json::from_str(&describe(&shot, Path::new("l.png"), 480, 270)).expect("JSON");
        let levels = &json["levels"];
        assert_eq!(levels["rule"], "majority");
        assert_eq!(levels["change_at"], 900);
        assert_eq!(levels["list"][1]["name"], "se\"cond");
        assert_eq!(levels["list"][1]["votes"], 2);
        assert_eq!(levels["list"][1]["next"], true);
        assert_eq!(levels["list"][0]["current"], true);
        assert_eq!(
            levels["panel"]["lines"][0],
            "1. default   0 votes   < playing"
        );
        assert_eq!(levels["panel"]["footer"][0], "next level in 4 s");
        assert_eq!(levels["next_line"], "next: second in 4 s");
        assert_eq!(levels["level_changes"], 2);
        assert_eq!(json["downloading"]["got"], 1024);
        assert_eq!(json["downloading"]["what"], "the next level");
        let closed = Shot {
            levels: Some(LevelsShot {
                list: &list,
                panel: None,
                next_line: None,
                level_changes: 0,
            }),
            downloading: None,
            ..blank(&view)
        };
        let json: serde_json::Value =
            serde_json::from_str(&describe(&closed, Path::new("l.png"), 480, 270)).expect("JSON");
        assert!(json["levels"]["panel"].is_null());
        assert!(json["levels"]["next_line"].is_null());
        assert!(json["downloading"].is_null());
        let json: serde_json::Value =
            serde_json::from_str(&describe(&blank(&view), Path::new("l.png"), 480, 270))
                .expect("JSON");
        assert!(json["levels"].is_null());
    }

    /// The card's lines as laid out: kinds, texts, the top runs' names and
    /// times, our row, our best and rank; `null` without a card.
    #[test]
    fn json_tells_what_the_card_says_of_the_records() {
        use crate::draw::card::Records;
        use crate::draw::hud::RunInfo;
        use ledge_shared::protocol::{Standing, TopRun};
        let view = View {
            zoom: 1.0,
            offset: Vec2::ZERO,
            screen: Vec2::new(960.0, 540.0),
        };
        let run = RunInfo {
            coins: 1,
            coins_total: 13,
            deaths: 2,
            run_ticks: 661,
            tick_rate: 60,
            place: Some(1),
        };
        let standing = Standing {
            millis: 11_016,
            personal_best: 11_016,
            new_personal_best: true,
            new_record: false,
            rank: 2,
            top: vec![
                TopRun {
                    name: "bo \"b\"".into(),
                    millis: 9_950,
                },
                TopRun {
                    name: "ada".into(),
                    millis: 11_016,
                },
            ],
        };
        let width = |t: &str, size: f32| t.chars().count() as f32 * size * 0.5;
        let card = Card::new(
            &run,
            "R",
            Some(Records::Recorded(&standing)),
            "ada",
            view.screen,
            width,
        );
        let hud = |card| HudShot {
            name: "ada",
            run: Some(run),
            net_panel: false,
            muted: false,
            sound_notice: None,
            results: &[],
            card,
        };
        let shot = |hud| Shot {
            hud: Some(hud),
            ..blank(&view)
        };
        let json = describe(&shot(hud(Some(&card))), Path::new("c.png"), 960, 540);
        let json: serde_json::Value = serde_json::from_str(&json).expect("JSON");
        let c = &json["hud"]["card"];
        assert_eq!(json["hud"]["results_card"], true);
        assert_eq!(c["records"], "recorded");
        assert_eq!(c["panel"][2], card.panel.w);
        let kinds: Vec<&str> = c["lines"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| l["kind"].as_str().unwrap())
            .collect();
        assert_eq!(
            kinds,
            [
                "place",
                "time",
                "tally",
                "headline",
                "best",
                "top_title",
                "top",
                "top",
                "again"
            ]
        );
        let lines = &c["lines"];
        assert_eq!(lines[3]["text"], "new personal best!");
        assert_eq!(lines[3]["record"], false);
        assert_eq!(lines[4]["millis"], 11_016);
        assert_eq!(lines[4]["time"], "0:11.016");
        assert_eq!(lines[4]["rank"], 2);
        assert_eq!(lines[6]["name"], "bo \"b\"");
        assert_eq!(lines[6]["time"], "0:09.950");
        assert_eq!(lines[6]["ours"], false);
        assert_eq!(lines[7]["place"], 2);
        assert_eq!(lines[7]["ours"], true);
        let baseline = lines[7]["baseline"].as_f64().unwrap();
        assert!((baseline - f64::from(card.lines[7].baseline)).abs() < 0.001);
        let json = describe(&shot(hud(None)), Path::new("c.png"), 960, 540);
        let json: serde_json::Value = serde_json::from_str(&json).expect("JSON");
        assert!(json["hud"]["card"].is_null());
        assert_eq!(json["hud"]["results_card"], false);
    }
}
