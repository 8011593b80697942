//! A run as a player sees it, through the real client binary under Xvfb:
//! the moment after a death (the counter says 1, the pop is on screen),
//! the results card after a scripted run reaches the goal (its time is the
//! simulation's), and a room's results table naming another player who
//! finished (his time as the server's run record says).
//!
//! The scripts are made by playing the same simulation here first: the
//! offline client steps the default level with the script's buttons from
//! its first tick, so its game is this one, tick for tick.
//!
//! Needs `xvfb-run` (see `common::xvfb_or_skip`).

use crate::common;

use std::path::Path;
use std::time::Duration;

use common::{run_to_end, Png, TestServer};
use ledge_client::bot::{connect_and_run, BotOptions, Brain, Runner};
use ledge_client::Trust;
use ledge_levels::{default_level, default_route};
use ledge_shared::game::{Game, PlayerView};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::PlayerId;
use serde_json::Value;

/// The client must have saved its screenshot within this time.
const CLIENT_TIMEOUT: Duration = Duration::from_secs(120);

/// `buttons` (one per tick from the first) as a `--script`: runs of equal
/// buttons, one entry each.
fn script_of(buttons: &[Buttons]) -> String {
    let name = |b: Buttons| {
        let names: Vec<&str> = [
            (Buttons::LEFT, "left"),
            (Buttons::RIGHT, "right"),
            (Buttons::UP, "up"),
            (Buttons::DOWN, "down"),
            (Buttons::JUMP, "jump"),
            (Buttons::RESTART, "restart"),
        ]
        .iter()
        .filter(|(bit, _)| b.0 & bit != 0)
        .map(|&(_, n)| n)
        .collect();
        if names.is_empty() {
            "none".to_owned()
        } else {
            names.join("+")
        }
    };
    let mut out = String::new();
    let mut start = 0;
    for i in 1..=buttons.len() {
        if i == buttons.len() || buttons[i] != buttons[start] {
            out.push_str(&format!("{}..{} -> {}\n", start, i, name(buttons[start])));
            start = i;
        }
    }
    out
}

/// Plays `brain` on the default level offline as player 1 until `stop`
/// says so (at most `limit` ticks); returns the buttons of each tick and
/// the player after the last.
fn play(
    limit: u64,
    mut brain: impl FnMut(&Game, u64) -> Buttons,
    stop: impl Fn(&PlayerView) -> bool,
) -> (Vec<Buttons>, PlayerView) {
    let mut game = Game::from_level(&default_level()).expect("the default level loads");
    game.add_player(PlayerId(1)).expect("player 1 joins");
    let mut buttons = Vec::new();
    for t in 0..limit {
        let b = brain(&game, t);
        buttons.push(b);
        game.step(&[(PlayerId(1), b)]);
        let me = game.player(PlayerId(1)).expect("player 1 plays");
        if stop(&me) {
            return (buttons, me);
        }
    }
    panic!("not done within {limit} ticks");
}

/// Runs the client offline with `script` for `ticks` ticks as "ada", and
/// returns its screenshot and the screenshot's description.
fn client_offline(script: &str, ticks: usize, name: &str) -> Option<(Png, Value)> {
    let xvfb = common::xvfb_or_skip("the run screenshot tests")?;
    let tmp = tempfile::tempdir().unwrap();
    let dir = common::screenshot_dir(tmp.path());
    let script_path = tmp.path().join(format!("{name}.script"));
    std::fs::write(&script_path, script).unwrap();
    let png = dir.join(format!("{name}.png"));
    let mut command = common::client_under_xvfb(
        &xvfb,
        env!("CARGO_BIN_EXE_ledge-client"),
        ticks as u64,
        &png,
    );
    command
        .args(["--name", "ada"])
        .arg("--script")
        .arg(&script_path);
    let out = run_to_end(command, CLIENT_TIMEOUT);
    assert!(
        out.status.success(),
        "the client failed: {}; stderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    Some(load(&png))
}

fn load(png: &Path) -> (Png, Value) {
    let mut json = png.as_os_str().to_owned();
    json.push(".json");
    let text = std::fs::read_to_string(&json).expect("the screenshot's JSON");
    (
        Png::load(png),
        serde_json::from_str(&text).expect("valid JSON"),
    )
}

/// The JSON's `recent` effects contain `effect`.
fn started(json: &Value, effect: &str) -> bool {
    json["fx"]["recent"]
        .as_array()
        .expect("fx.recent")
        .iter()
        .any(|e| e == effect)
}

/// `ticks` at 60 a second as the HUD writes it.
fn time_60(ticks: u32) -> String {
    let cs = u64::from(ticks) * 100 / 60;
    format!("{}:{:02}.{:02}", cs / 6000, cs / 100 % 60, cs % 100)
}

/// Ticks after the death the picture is taken: the flash has faded, the
/// pieces are still flying, the respawn (24 ticks) is still to come.
const AFTER_DEATH: usize = 14;

#[test]
fn the_moment_after_a_death_shows_the_pop_and_the_counter_says_one() {
    // Run right, jumping 8 ticks of every 20, until something kills us.
    let hop = |t: u64| Buttons(Buttons::RIGHT | if t % 20 < 8 { Buttons::JUMP } else { 0 });
    let (mut buttons, me) = play(900, |_, t| hop(t), |me| me.deaths > 0);
    let died = buttons.len();
    let delay = usize::from(me.dead.expect("dead after dying"));
    assert!(AFTER_DEATH < delay, "respawned before the picture");
    for t in died..died + AFTER_DEATH {
        buttons.push(hop(t as u64));
    }
    let Some((img, json)) = client_offline(&script_of(&buttons), died + AFTER_DEATH, "death")
    else {
        return;
    };
    let hud = &json["hud"];
    assert_eq!(hud["deaths"], 1, "{json}");
    assert_eq!(json["fx"]["dead"], true, "{json}");
    assert!(started(&json, "Hurt"), "{json}");
    assert!(
        json["fx"]["particles"].as_u64().unwrap() >= 20,
        "{}",
        json["fx"]
    );
    // The body stays where it died until it respawns.
    let (sx, sy) = common::pair(&json["player"]["server_pos_px"]);
    let death = (me.pos.x as f64 / 256.0, me.pos.y as f64 / 256.0);
    assert!(
        (sx - death.0).abs() < 1.0 && (sy - death.1).abs() < 1.0,
        "({sx}, {sy}) vs {death:?}"
    );
    // Pieces of our colour flew out of the body: count them around it,
    // outside its box.
    let zoom = json["camera"]["zoom"].as_f64().unwrap();
    let (cx, cy) = common::pair(&json["player"]["drawn_screen"]);
    let (w, h) = common::pair(&json["player"]["size_px"]);
    let ours = {
        let c = json["colors"]["local_player"].as_array().unwrap();
        [0, 1, 2].map(|i| c[i].as_u64().unwrap() as i32)
    };
    let reach = 60.0 * zoom;
    let mut pieces = 0;
    for y in (cy - reach).max(0.0) as u32..((cy + reach) as u32).min(img.height) {
        for x in (cx - reach).max(0.0) as u32..((cx + reach) as u32).min(img.width) {
            let (dx, dy) = ((x as f64 - cx).abs(), (y as f64 - cy).abs());
            if dx <= (w / 2.0 + 2.0) * zoom && dy <= (h / 2.0 + 2.0) * zoom {
                continue;
            }
            let [r, g, b, _] = img.at(x, y);
            let near = [r, g, b]
                .iter()
                .zip(ours)
                .all(|(&v, o)| (i32::from(v) - o).abs() <= 40);
            pieces += usize::from(near);
        }
    }
    assert!(
        pieces >= 40,
        "only {pieces} pixels of our colour around the body"
    );
    eprintln!(
        "death at tick {died}: {pieces} pixels of pieces, fx {}",
        json["fx"]
    );
}

#[test]
fn a_run_to_the_goal_ends_on_the_results_card_with_the_simulations_time() {
    let mut runner = Runner::new(default_route());
    let (mut buttons, me) = play(
        60 * 60,
        |game, _| runner.buttons(game, PlayerId(1)),
        |me| me.won,
    );
    let finished = buttons.len();
    buttons.extend(std::iter::repeat_n(Buttons::NONE, 30));
    let Some((img, json)) = client_offline(&script_of(&buttons), finished + 30, "finish") else {
        return;
    };
    let hud = &json["hud"];
    assert_eq!(hud["place"], 1, "{json}");
    assert_eq!(hud["results_card"], true, "{json}");
    assert_eq!(hud["run_ticks"], me.run_ticks, "{json}");
    assert_eq!(hud["time"], time_60(me.run_ticks), "{json}");
    assert_eq!(hud["deaths"], me.deaths, "{json}");
    assert_eq!(hud["coins"], me.coins, "{json}");
    assert!(started(&json, "Goal"), "{json}");
    // Alone: the card says it all, no table.
    assert_eq!(hud["results_table"], false, "{json}");
    assert_eq!(hud["results"].as_array().unwrap().len(), 1, "{json}");
    assert_eq!(hud["results"][0]["ours"], true, "{json}");
    // The card: a dark panel across the middle column in the upper half,
    // with gold words on it.
    let mid = img.width / 2;
    let dark = (0..img.height / 2)
        .filter(|&y| {
            let [r, g, b, _] = img.at(mid, y);
            u32::from(r) + u32::from(g) + u32::from(b) < 160
        })
        .count();
    assert!(
        dark >= 80,
        "no results card in the middle ({dark} dark pixels)"
    );
    let gold = (0..img.height / 2)
        .flat_map(|y| (mid - 100..mid + 100).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let [r, g, b, _] = img.at(x, y);
            r >= 230 && (190..=235).contains(&g) && b <= 110
        })
        .count();
    assert!(gold >= 30, "no gold words on the card ({gold} pixels)");
    eprintln!("finished in {} ticks: {}", me.run_ticks, json["hud"]);
}

#[test]
fn a_room_shows_who_finished_with_the_servers_time() {
    let Some(xvfb) = common::xvfb_or_skip("the room results screenshot test") else {
        return;
    };
    let server = TestServer::start();
    let tmp = tempfile::tempdir().unwrap();
    let dir = common::screenshot_dir(tmp.path());
    let png = dir.join("room_results.png");
    let addr = server.addr.to_string();
    let fingerprint = server.fingerprint;
    // We stand still while "bob", a runner bot, races to the goal; the
    // picture is taken 18 s after we joined, while bob is still in the
    // room.
    let bob = std::thread::scope(|scope| {
        let client = scope.spawn(|| {
            let mut command =
                common::client_under_xvfb(&xvfb, env!("CARGO_BIN_EXE_ledge-client"), 1080, &png);
            command
                .args(["--connect", &addr])
                .args(["--cert-hash", &fingerprint.to_string()])
                .args(["--name", "ada"]);
            run_to_end(command, CLIENT_TIMEOUT)
        });
        let mut runner = Runner::new(default_route());
        let options = BotOptions::new("bob", Duration::from_secs(26));
        let report = server.block_on(connect_and_run(
            &addr,
            &Trust::Pinned(fingerprint),
            &mut runner as &mut dyn Brain,
            &options,
        ));
        let out = client.join().unwrap();
        assert!(
            out.status.success(),
            "the client failed: {}; stderr:\n{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
        report
    });
    server.stop();
    let finish = bob
        .finish_ticks
        .unwrap_or_else(|| panic!("bob did not finish: {bob}"));
    let (img, json) = load(&png);
    let hud = &json["hud"];
    assert_eq!(hud["results_table"], true, "{json}");
    // Drawn top right: a panel darker than the sky there.
    let sky = json["colors"]["sky"].as_array().unwrap();
    let sky: u64 = sky.iter().map(|v| v.as_u64().unwrap()).sum();
    let [r, g, b, _] = img.at(img.width - 30, 14);
    assert!(
        u64::from(r) + u64::from(g) + u64::from(b) < sky / 2,
        "no table top right: {:?}",
        [r, g, b]
    );
    let rows = hud["results"].as_array().unwrap();
    assert_eq!(rows.len(), 1, "{json}");
    assert_eq!(rows[0]["name"], "bob", "{json}");
    assert_eq!(rows[0]["place"], 1, "{json}");
    assert_eq!(rows[0]["ours"], false, "{json}");
    assert_eq!(rows[0]["ticks"], finish, "{json}");
    // We did not finish: no card of ours.
    assert!(hud["place"].is_null(), "{json}");
    eprintln!("bob finished in {finish} ticks: {}", hud["results"]);
}
