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
use ledge_server::records::{RecordStore, RecordsTarget, TopEntry};
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
    brain: impl FnMut(&Game, u64) -> Buttons,
    stop: impl Fn(&PlayerView) -> bool,
) -> (Vec<Buttons>, PlayerView) {
    play_as(PlayerId(1), 0, limit, brain, stop)
        .unwrap_or_else(|| panic!("not done within {limit} ticks"))
}

/// [`play`] as player `id` (its spawn spot is its id's) in a game that
/// ran `before` ticks without players first; `None` if not done within
/// `limit` ticks.
fn play_as(
    id: PlayerId,
    before: u64,
    limit: u64,
    mut brain: impl FnMut(&Game, u64) -> Buttons,
    stop: impl Fn(&PlayerView) -> bool,
) -> Option<(Vec<Buttons>, PlayerView)> {
    let mut game = Game::from_level(&default_level()).expect("the default level loads");
    for _ in 0..before {
        game.step(&[]);
    }
    game.add_player(id).expect("the player joins");
    let mut buttons = Vec::new();
    for t in 0..limit {
        let b = brain(&game, t);
        buttons.push(b);
        game.step(&[(id, b)]);
        let me = game.player(id).expect("the player plays");
        if stop(&me) {
            return Some((buttons, me));
        }
    }
    None
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
    // Offline there are no records: the card tells the run alone.
    let card = &hud["card"];
    assert!(card["records"].is_null(), "{card}");
    let kinds: Vec<&str> = card["lines"]
        .as_array()
        .expect("the card's lines")
        .iter()
        .map(|l| l["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["place", "time", "tally", "again"], "{card}");
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
    assert!(hud["card"].is_null(), "{json}");
    eprintln!("bob finished in {finish} ticks: {}", hud["results"]);
}

/// Still ticks before an online script moves: by then the client's clock
/// has settled on the server's, so no input of the run comes late.
const LEAD: u64 = 60;
/// Ticks the client plays on after the finish: the server stores the run
/// and says where it stands well within them (3 s).
const AFTER_FINISH: u64 = 180;

/// A script to the goal for player `id` online: [`LEAD`] still ticks, then
/// the route runner's buttons. Checked offline to reach the goal whatever
/// the room's clock says when we join (walkers and platforms go by it);
/// returns the buttons and the player at the goal.
fn script_to_goal(id: PlayerId) -> (Vec<Buttons>, PlayerView) {
    let mut runner = Runner::new(default_route());
    let brain = |game: &Game, t: u64| {
        if t < LEAD {
            Buttons::NONE
        } else {
            runner.buttons(game, id)
        }
    };
    let (buttons, me) =
        play_as(id, 0, 60 * 60, brain, |me| me.won).expect("the runner reaches the goal");
    for before in (1..1200).step_by(53) {
        let mut replay = buttons.iter().copied();
        let later = play_as(
            id,
            before,
            buttons.len() as u64,
            |_, _| replay.next().expect("within the script"),
            |me| me.won,
        );
        let ticks = later.map(|(_, later)| later.run_ticks);
        assert_eq!(ticks, Some(me.run_ticks), "{id} joining at tick {before}");
    }
    (buttons, me)
}

/// The server's records of the one level played, from its database: the
/// top ten, fastest first.
fn stored_top(server: &TestServer) -> Vec<TopEntry> {
    let target = RecordsTarget::in_state_dir(server.cert_dir());
    server.block_on(async {
        let store = RecordStore::open(&target)
            .await
            .expect("the records database opens")
            .expect("records are on");
        let levels = store.levels().await.expect("the levels with records");
        assert_eq!(levels.len(), 1, "{levels:?}");
        let top = store.top(&levels[0].hash, 10).await.expect("the top ten");
        store.close().await;
        top
    })
}

/// `ms` as the card writes record times, `m:ss.mmm`.
fn time_ms(ms: u64) -> String {
    format!("{}:{:02}.{:03}", ms / 60_000, ms / 1000 % 60, ms % 1000)
}

/// Gold pixels (the card's gold words) on the card's `line`.
fn gold_in(img: &Png, card: &Value, line: &Value) -> usize {
    let panel: Vec<f64> = card["panel"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let (baseline, size) = (
        line["baseline"].as_f64().unwrap(),
        line["size"].as_f64().unwrap(),
    );
    let rows = (baseline - size * 0.8) as u32..baseline as u32;
    // Inside the card's gold rim.
    let across = (panel[0] + 4.0) as u32..(panel[0] + panel[2] - 4.0) as u32;
    rows.flat_map(|y| across.clone().map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let [r, g, b, _] = img.at(x, y);
            r >= 230 && (190..=235).contains(&g) && b <= 110
        })
        .count()
}

#[test]
fn a_finished_online_run_shows_where_it_stands_in_the_records() {
    let Some(xvfb) = common::xvfb_or_skip("the records card screenshot test") else {
        return;
    };
    let server = TestServer::start();
    let (addr, fingerprint) = (server.addr.to_string(), server.fingerprint);
    // First "bob", a runner bot, to the goal: his run is the level's first.
    let bob = server.runner_to_goal("bob");
    assert!(matches!(bob.standing, Some(Ok(_))), "bob's run: {bob}");
    // Then we, "ada", the next player, run the route in the window.
    let ada = PlayerId(bob.player.expect("bob joined").0 + 1);
    let (buttons, me) = script_to_goal(ada);
    let tmp = tempfile::tempdir().unwrap();
    let script = tmp.path().join("records.script");
    std::fs::write(&script, script_of(&buttons)).unwrap();
    let png = common::screenshot_dir(tmp.path()).join("records_card.png");
    let ticks = buttons.len() as u64 + AFTER_FINISH;
    let mut command =
        common::client_under_xvfb(&xvfb, env!("CARGO_BIN_EXE_ledge-client"), ticks, &png);
    command
        .args(["--connect", &addr])
        .args(["--cert-hash", &fingerprint.to_string()])
        .args(["--name", "ada"])
        .arg("--script")
        .arg(&script);
    let out = run_to_end(command, CLIENT_TIMEOUT);
    assert!(
        out.status.success(),
        "the client failed: {}; stderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let top = stored_top(&server);
    server.stop();
    let (img, json) = load(&png);
    assert_eq!(
        json["player"]["id"], ada.0,
        "the script is for {ada}: {json}"
    );
    let hud = &json["hud"];
    assert!(
        hud["place"].as_u64().is_some(),
        "ada did not finish (offline in {} ticks): {json}",
        me.run_ticks
    );
    check_records_card(&img, hud, &top);
}

/// The card of ada's finished run says what the server's records (`top`,
/// read from its database) say: our best and rank, the headline it earned,
/// the level's top runs with our row (and only ours) in gold.
fn check_records_card(img: &Png, hud: &Value, top: &[TopEntry]) {
    let card = &hud["card"];
    assert_eq!(card["records"], "recorded", "{card}");
    let lines = card["lines"].as_array().expect("the card's lines");
    let of = |kind: &str| -> Vec<&Value> { lines.iter().filter(|l| l["kind"] == kind).collect() };
    // Every run stored: bob's and ours.
    let ours = top
        .iter()
        .find(|e| e.player == "ada")
        .expect("ada's run stored");
    assert!(top.iter().any(|e| e.player == "bob"), "{top:?}");
    assert_eq!(ours.ticks, hud["run_ticks"], "{top:?}");
    let drawn: Vec<(u64, &str, u64, bool)> = of("top")
        .iter()
        .map(|l| {
            (
                l["place"].as_u64().unwrap(),
                l["name"].as_str().unwrap(),
                l["millis"].as_u64().unwrap(),
                l["ours"].as_bool().unwrap(),
            )
        })
        .collect();
    let stored: Vec<(u64, &str, u64, bool)> = top
        .iter()
        .map(|e| {
            (
                u64::from(e.place),
                e.player.as_str(),
                e.millis,
                e.player == "ada",
            )
        })
        .collect();
    assert_eq!(drawn, stored, "{card}");
    let best = of("best");
    assert_eq!(best.len(), 1, "{card}");
    assert_eq!(best[0]["millis"], ours.millis, "{card}");
    assert_eq!(best[0]["rank"], ours.place, "{card}");
    let expected = format!(
        "best {} \u{b7} #{} on this level",
        time_ms(ours.millis),
        ours.place
    );
    assert_eq!(best[0]["text"], expected.as_str(), "{card}");
    // Our first run on the level: a personal best, and the record when
    // first.
    assert_eq!(ours.runs, 1, "{top:?}");
    let headline = if ours.place == 1 {
        "NEW RECORD!"
    } else {
        "new personal best!"
    };
    let said: Vec<&Value> = of("headline").iter().map(|l| &l["text"]).collect();
    assert_eq!(said, [headline], "{card}");
    // Drawn: our row in gold, the others not.
    for line in of("top") {
        let gold = gold_in(img, card, line);
        if line["ours"] == true {
            assert!(gold >= 20, "our row has {gold} gold pixels: {line}");
        } else {
            assert_eq!(gold, 0, "another's row is gold: {line}");
        }
    }
    eprintln!("the card: {card}");
}
