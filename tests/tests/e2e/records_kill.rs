//! Records survive `kill -9` (issue 32): the real `ledge-server` binary,
//! its records in an SQLite file, is killed with SIGKILL again and again
//! while bots finish run after run on a short level; after each kill it is
//! started again on the same file. Every run a bot was told was recorded is
//! in the file, and no run is there twice.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Duration;

use ledge_client::bot::{BotReport, Brain};
use ledge_server::records::{RecordStore, RecordsTarget};
use ledge_shared::game::Game;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::PlayerId;
use ledge_tests::e2e::{bot_options, spawn_bot};
use ledge_tests::server_process::ServerProcess;

/// Server lifetimes (each ended by SIGKILL).
const ROUNDS: usize = 5;
/// Bots finishing runs in each.
const BOTS: usize = 3;

/// A short level (Tiled): a floor, the spawn at its left end and the goal
/// six tiles to the right, so a run takes under a second.
fn short_level(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("short.tmx");
    let floor = "1,".repeat(12);
    std::fs::write(
        &path,
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<map version="1.10" orientation="orthogonal" renderorder="right-down" width="12" height="6" tilewidth="16" tileheight="16" infinite="0" nextlayerid="3" nextobjectid="3">
 <tileset firstgid="1" name="solid" tilewidth="16" tileheight="16" tilecount="1" columns="1">
  <image source="solid.png" width="16" height="16"/>
 </tileset>
 <layer id="1" name="ground" width="12" height="6">
  <data encoding="csv">
{empty}
{empty}
{empty}
{empty}
{empty}
{floor_end}
</data>
 </layer>
 <objectgroup id="2" name="objects">
  <object id="1" name="spawn" type="spawn" x="24" y="64" width="16" height="16"/>
  <object id="2" name="goal" type="goal" x="120" y="64" width="16" height="16"/>
 </objectgroup>
</map>
"#,
            empty = "0,".repeat(12),
            floor_end = floor.trim_end_matches(','),
        ),
    )
    .unwrap();
    crate::level_download::write_png(&dir.join("solid.png"), 16, &[90; 16 * 16 * 4]);
    path
}

/// Runs right to the goal, stands there a few ticks (so the server's
/// snapshots show the finish), restarts, and again.
#[derive(Debug, Default)]
struct Shuttle {
    at_goal_since: Option<u64>,
}

impl Brain for Shuttle {
    fn name(&self) -> &'static str {
        "shuttle"
    }

    fn buttons(&mut self, game: &Game, me: PlayerId) -> Buttons {
        let won = game.player(me).is_some_and(|p| p.won);
        if !won {
            self.at_goal_since = None;
            return Buttons(Buttons::RIGHT);
        }
        let since = *self.at_goal_since.get_or_insert(game.tick());
        if game.tick() >= since + 10 {
            Buttons(Buttons::RESTART)
        } else {
            Buttons::NONE
        }
    }
}

/// The bots of one server lifetime: they play until `until` (the server
/// is killed just before), each counting the runs it was told were
/// recorded.
async fn play(server: &ServerProcess, round: usize, until: Duration) -> Vec<BotReport> {
    let mut bots = Vec::new();
    for i in 0..BOTS {
        let name = format!("k{round}-{i}");
        let session = ledge_client::connect(server.addr, "localhost", server.fingerprint, &name)
            .await
            .unwrap_or_else(|e| panic!("{name} is welcomed: {e}"));
        bots.push(spawn_bot(
            session,
            Shuttle::default(),
            bot_options(&name, until),
        ));
    }
    let mut reports = Vec::new();
    for bot in bots {
        reports.push(bot.await.expect("the bot task did not panic").0);
    }
    reports
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_run_a_player_was_told_is_recorded_survives_sigkill() {
    let dir = tempfile::tempdir().unwrap();
    let level = short_level(dir.path());
    let certs = dir.path().join("certs");
    let records = dir.path().join("records.sqlite");
    let args = [
        "--bind",
        "127.0.0.1:0",
        "--level",
        level.to_str().unwrap(),
        "--cert-dir",
        certs.to_str().unwrap(),
        "--records",
        records.to_str().unwrap(),
    ];
    let mut told: BTreeMap<String, (u32, u32)> = BTreeMap::new();
    for round in 0..ROUNDS {
        let server = ServerProcess::start(&args);
        // Killed at another moment of the runs each time, while the bots
        // still play.
        let kill_after = Duration::from_millis(2_500 + 370 * round as u64);
        let (reports, ()) = tokio::join!(
            play(&server, round, kill_after + Duration::from_millis(500)),
            async {
                tokio::time::sleep(kill_after).await;
                server.kill_now();
            }
        );
        drop(server);
        for r in reports {
            told.insert(r.name.clone(), (r.recorded, r.finishes));
        }
    }
    let store = RecordStore::open(&RecordsTarget::Sqlite(records))
        .await
        .unwrap()
        .expect("records on");
    let levels = store.levels().await.unwrap();
    assert_eq!(levels.len(), 1, "{levels:?}");
    let top = store.top(&levels[0].hash, 100).await.unwrap();
    let stored: BTreeMap<&str, u64> = top.iter().map(|e| (e.player.as_str(), e.runs)).collect();
    let (mut told_total, mut stored_total) = (0, 0);
    for (name, &(recorded, finishes)) in &told {
        let rows = stored.get(name.as_str()).copied().unwrap_or(0);
        eprintln!("{name}: {finishes} finishes, told {recorded} recorded, {rows} stored");
        assert!(
            u64::from(recorded) <= rows,
            "{name}: told {recorded} runs were recorded, {rows} stored"
        );
        assert!(
            rows <= u64::from(finishes),
            "{name}: {rows} stored of {finishes} finishes: a run stored twice"
        );
        told_total += recorded;
        stored_total += rows;
    }
    assert!(
        told_total >= (ROUNDS * BOTS) as u32,
        "runs finished: {told_total}"
    );
    eprintln!("{ROUNDS} kills: {told_total} runs told recorded, {stored_total} stored");
    store.close().await;
}
