//! Whole matches over real QUIC: eight runner bots reach the goal of the
//! default level as the server sees it, and a recorded match replays
//! headlessly to the server's state hash at every tick.

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use ledge_client::bot::{RandomWalker, Runner};
use ledge_levels::{default_level, default_route};
use ledge_server::record::Change;
use ledge_shared::game::state::{kind, player_flags};
use ledge_shared::game::Game;
use ledge_shared::input::Buttons;
use ledge_shared::level::EntityKind;
use ledge_tests::e2e::{bot_options, spawn_bot, watch};
use ledge_tests::TestServer;

/// Runners in the race.
const RUNNERS: usize = 8;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn eight_runner_bots_reach_the_goal_as_the_server_sees_it() {
    let server = TestServer::start().await;
    // An observer reads the server's snapshots (its authoritative state)
    // for each runner's player and its goal flag.
    let mut observer = server.join("observer").await;
    let observer_id = observer.welcome().player_id.0;
    // The runners all start at once: they connect together and race in
    // the same world, foiling each other's plans (a walker one of them
    // stomped is still there in the others' predictions until the next
    // snapshot; a late input makes the server repeat the previous one).
    // A runner that leaves its route (falls into the walker trench) notices
    // and takes the route again.
    let (addr, fingerprint) = (server.addr, server.fingerprint);
    let bots: Vec<_> = (0..RUNNERS)
        .map(|i| {
            tokio::spawn(async move {
                let name = format!("runner-{i}");
                let session = ledge_client::connect(addr, "localhost", fingerprint, &name)
                    .await
                    .unwrap_or_else(|e| panic!("{name} is welcomed: {e}"));
                let options = ledge_client::bot::BotOptions {
                    stop_when_done: true,
                    ..bot_options(&name, Duration::from_secs(25))
                };
                spawn_bot(session, Runner::new(default_route()), options)
                    .await
                    .expect("the bot task did not panic")
            })
        })
        .collect();
    let goal = default_level()
        .entities
        .iter()
        .find(|e| matches!(e.kind, EntityKind::Goal))
        .map(|e| e.pos)
        .expect("the default level has a goal");
    let started = Instant::now();
    // Player id -> (server tick, position) when the server first showed it
    // at the goal.
    let mut won = BTreeMap::new();
    let mut furthest: BTreeMap<u32, i32> = BTreeMap::new();
    // Player id -> (tick, position in px, velocity, flags) last seen.
    let mut last = BTreeMap::new();
    let all = watch(&mut observer, Duration::from_secs(32), |state| {
        for e in state.entities.iter().filter(|e| e.kind == kind::PLAYER) {
            if e.id == observer_id {
                continue;
            }
            let f = furthest.entry(e.id).or_insert(i32::MIN);
            *f = (*f).max(e.pos.x);
            last.insert(e.id, (state.tick, e.pos / 256, e.vel, e.flags));
            if e.flags & player_flags::WON != 0 {
                won.entry(e.id).or_insert((state.tick, e.pos));
            }
        }
        won.len() == RUNNERS
    })
    .await;
    let took = started.elapsed();
    let mut reports = Vec::new();
    for bot in bots {
        let (report, runner) = bot.await.expect("the runner ran");
        eprintln!("{report}");
        reports.push((report, runner.progress()));
    }
    eprintln!(
        "{} of {RUNNERS} at the goal as the server saw it after {took:?}; {} starved ticks",
        won.len(),
        ledge_tests::starvation(&server, "room-1")
    );
    for (id, x) in &furthest {
        eprintln!(
            "player {id}: furthest x {} px, last {:?}",
            x / 256,
            last.get(id)
        );
    }
    assert!(
        all,
        "the server saw {} of {RUNNERS} runners win: {won:?}",
        won.len()
    );
    for (id, (tick, pos)) in &won {
        assert!(
            (pos.x - goal.x).abs() < 32 * 256,
            "player {id} won at tick {tick} at x = {} px, the goal is at {} px",
            pos.x / 256,
            goal.x / 256
        );
    }
    assert_eq!(reports.len(), RUNNERS);
    for (report, progress) in &reports {
        assert!(report.won, "its own snapshots show the win too: {report}");
        assert!(report.ended.is_none(), "{report}");
        // Runners may be hurt (another runner stomping the walker first
        // foils a plan) but recover and finish.
        assert!(progress.won, "{report}");
    }
    observer.close().await;
    server.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_recorded_match_replays_to_the_servers_hash_at_every_tick() {
    let server = TestServer::start_with(|c| c.record_ticks = Some(60 * 60)).await;
    let recorder = server.recorder.clone().expect("recording is on");
    // Three walkers play the whole match; a fourth joins late and leaves
    // early, and a runner crosses the level: joins, leaves, movement,
    // jumps and the moving platforms are all in the record.
    let mut bots = Vec::new();
    for i in 0..3u64 {
        let name = format!("walker-{i}");
        let session = server.join(&name).await;
        let options = bot_options(&name, Duration::from_secs(10));
        bots.push(spawn_bot(session, RandomWalker::new(i + 1), options));
    }
    let runner = server.join("runner").await;
    let runner = spawn_bot(
        runner,
        Runner::new(default_route()),
        bot_options("runner", Duration::from_secs(10)),
    );
    tokio::time::sleep(Duration::from_secs(2)).await;
    let late = server.join("late").await;
    let late = spawn_bot(
        late,
        RandomWalker::new(99),
        bot_options("late", Duration::from_secs(4)),
    );
    for bot in bots {
        let (report, _) = bot.await.unwrap();
        eprintln!("{report}");
    }
    eprintln!("{}", runner.await.unwrap().0);
    eprintln!("{}", late.await.unwrap().0);
    server.stop().await.unwrap();
    let record = recorder.snapshot();

    let joins = record
        .ticks
        .iter()
        .flat_map(|t| &t.changes)
        .filter(|c| matches!(c, Change::Join(_)))
        .count();
    let leaves = record
        .ticks
        .iter()
        .flat_map(|t| &t.changes)
        .filter(|c| matches!(c, Change::Leave(_)))
        .count();
    let pressed = record
        .ticks
        .iter()
        .flat_map(|t| &t.inputs)
        .filter(|(_, b)| *b != Buttons::NONE)
        .count();
    eprintln!(
        "recorded {} ticks from tick {} ({joins} joins, {leaves} leaves, {pressed} inputs \
         with buttons held, {} dropped)",
        record.ticks.len(),
        record.start_tick,
        record.dropped_ticks
    );
    assert!(
        record.started && !record.truncated(),
        "whole match recorded"
    );
    assert!(
        record.ticks.len() >= 500,
        "about 10 s: {}",
        record.ticks.len()
    );
    assert_eq!((joins, leaves), (5, 5), "every join and leave recorded");
    assert!(pressed > 1000, "the players pressed buttons: {pressed}");

    // Replay headlessly from the same level and configuration.
    let level = default_level();
    assert_eq!(record.level_hash, level.content_hash());
    let mut game = Game::with_config(&level, record.config).unwrap();
    assert_eq!(game.tick(), record.start_tick);
    assert_eq!(game.state_hash(), record.start_hash);
    for t in &record.ticks {
        assert_eq!(game.tick(), t.tick, "ticks are consecutive");
        for change in &t.changes {
            match *change {
                Change::Join(p) => game.add_player(p).expect("the player joins"),
                Change::Leave(p) => assert!(game.remove_player(p), "{p} was there"),
            }
        }
        game.step(&t.inputs);
        assert_eq!(
            game.state_hash(),
            t.state_hash,
            "the replay diverged from the server at tick {}",
            t.tick
        );
    }
    assert_eq!(game.players().count(), 0, "everyone left");
}
