//! A lost connection's player is kept for the reconnect grace time: a
//! client cut off (a relay that drops everything) for 5 s or for 20 s
//! comes back with its session token and gets the same player, where it
//! was, with the coin and the checkpoint it had, not a new one at the
//! spawn; past the grace time it joins as new.
//! Over real QUIC, with the real server.

use std::time::{Duration, Instant};

use ledge_client::{connect_with, InputClock, JoinOptions, Session};
use ledge_shared::game::Game;
use ledge_shared::input::Buttons;
use ledge_shared::level::Level;
use ledge_shared::protocol::{PlayerId, SessionToken, StateSnapshot};
use ledge_tests::{drain, metric, snapshot_where, TestServer, UdpRelay, WAIT};

/// Joins through `addr` (the relay or the server), resuming `token`.
async fn join(
    server: &TestServer,
    addr: std::net::SocketAddr,
    resume: Option<SessionToken>,
) -> Session {
    let options = JoinOptions {
        resume,
        ..JoinOptions::new("ana")
    };
    connect_with(addr, "localhost", server.fingerprint, &options)
        .await
        .expect("welcomed")
}

/// Holds `buttons` for `hold`, then returns where the server has us.
async fn walk(session: &mut Session, buttons: u8, hold: Duration) -> (i32, i32) {
    let me = session.welcome().player_id.0;
    let clock = InputClock::new(session.welcome(), Instant::now());
    let until = Instant::now() + hold;
    while Instant::now() < until {
        let _ = session.send_input(clock.input_tick(Instant::now()), Buttons(buttons));
        drain(session, clock.until_next_tick(Instant::now())).await;
    }
    for _ in 0..30 {
        let _ = session.send_input(clock.input_tick(Instant::now()), Buttons::NONE);
        drain(session, clock.until_next_tick(Instant::now())).await;
    }
    let state = snapshot_where(session, WAIT, |s| s.get(me).is_some()).await;
    let pos = state.get(me).expect("we are in the snapshot").pos;
    (pos.x, pos.y)
}

/// Where the server has player `id` now.
async fn position(session: &mut Session, id: PlayerId) -> (i32, i32) {
    let state = snapshot_where(session, WAIT, |s| s.get(id.0).is_some()).await;
    let pos = state.get(id.0).expect("in the snapshot").pos;
    (pos.x, pos.y)
}

/// A corridor (Tiled map): the spawn, a coin and a checkpoint on the way
/// right, walls at both ends.
const CORRIDOR: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<map version="1.10" orientation="orthogonal" renderorder="right-down" width="20" height="8" tilewidth="16" tileheight="16" infinite="0" nextlayerid="2" nextobjectid="7">
 <objectgroup id="1" name="objects">
  <object id="1" type="block" x="0" y="112" width="320" height="16"/>
  <object id="2" type="block" x="0" y="0" width="16" height="112"/>
  <object id="3" type="block" x="304" y="0" width="16" height="112"/>
  <object id="4" class="spawn" x="32" y="112"><point/></object>
  <object id="5" name="coin" x="52" y="98" width="12" height="12"/>
  <object id="6" class="checkpoint" x="80" y="80" width="16" height="32"/>
 </objectgroup>
</map>
"#;

/// Coins and checkpoint of player `id` in `state`, read through a game of
/// `level` restored to it.
fn progress(level: &Level, state: &StateSnapshot, id: PlayerId) -> (u32, Option<u32>) {
    let mut game = Game::from_level(level).unwrap();
    game.restore(state).unwrap();
    let me = game.player(id).expect("the player is in the game");
    (me.coins, me.checkpoint)
}

/// Plays, is cut off for `cut`, comes back with the token: the same
/// player, where it was, with its coin and checkpoint.
async fn cut_and_resume(cut: Duration) {
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("corridor.tmx");
    std::fs::write(&map, CORRIDOR).unwrap();
    let level = ledge_levels::load_level(&map, None).unwrap().level;
    let server = TestServer::start_with(|c| c.levels = vec![map.clone()]).await;
    let relay = UdpRelay::start(server.addr).await;
    let mut ana = join(&server, relay.addr, None).await;
    let id = ana.welcome().player_id;
    let token = ana.welcome().session_token;
    let spawn = position(&mut ana, id).await;
    let walked = walk(&mut ana, Buttons::RIGHT, Duration::from_millis(800)).await;
    assert!(
        walked.0 > spawn.0 + 4 * 256,
        "walked from {spawn:?} to {walked:?}"
    );
    let state = snapshot_where(&mut ana, WAIT, |s| s.get(id.0).is_some()).await;
    let (coins, checkpoint) = progress(&level, &state, id);
    assert_eq!(coins, 1, "picked the coin on the way");
    assert!(checkpoint.is_some(), "touched the checkpoint on the way");

    // The link dies; the client gives up on the connection.
    relay.blackhole();
    tokio::time::sleep(cut).await;
    drop(ana);

    let mut back = join(&server, server.addr, Some(token)).await;
    assert_eq!(back.welcome().player_id, id, "the same player");
    assert_eq!(back.welcome().session_token, token);
    let state = snapshot_where(&mut back, WAIT, |s| s.get(id.0).is_some()).await;
    let now = state.get(id.0).map(|e| (e.pos.x, e.pos.y)).unwrap();
    assert_eq!(now, walked, "kept where it was (spawn was {spawn:?})");
    assert_eq!(
        progress(&level, &state, id),
        (coins, checkpoint),
        "kept its coin and checkpoint"
    );
    // One member: no second player for the same client.
    let m = server.metrics();
    assert_eq!(metric(&m, "ledge_sessions_resumed_total"), 1.0);
    assert_eq!(metric(&m, r#"ledge_players{room="room-1"}"#), 1.0);
    // It plays on.
    let further = walk(&mut back, Buttons::LEFT, Duration::from_millis(300)).await;
    assert!(further.0 < walked.0, "{walked:?} -> {further:?}");
    back.close().await;
    server.stop().await.expect("clean stop");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_player_cut_off_for_5_s_comes_back() {
    // The server has not noticed yet (its idle timeout is 10 s): the
    // resume takes the player over from the dead connection.
    cut_and_resume(Duration::from_secs(5)).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_player_cut_off_for_20_s_comes_back() {
    // The server noticed after its idle timeout (10 s) and kept the player
    // still.
    cut_and_resume(Duration::from_secs(20)).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn after_the_grace_time_a_player_joins_as_new() {
    let server = TestServer::start_with(|c| {
        c.idle_timeout = Duration::from_secs(1);
        c.reconnect_grace = Duration::from_secs(2);
    })
    .await;
    let relay = UdpRelay::start(server.addr).await;
    let mut ana = join(&server, relay.addr, None).await;
    let id = ana.welcome().player_id;
    let token = ana.welcome().session_token;
    walk(&mut ana, Buttons::RIGHT, Duration::from_millis(300)).await;
    relay.blackhole();
    // Lost after the idle timeout, gone after the grace time.
    let gone = Instant::now() + Duration::from_secs(8);
    while metric(&server.metrics(), "ledge_sessions_expired_total") < 1.0 {
        assert!(Instant::now() < gone, "the lost player was never removed");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    drop(ana);
    let mut again = join(&server, server.addr, Some(token)).await;
    let new_id = again.welcome().player_id;
    assert_ne!(new_id, id, "a new player");
    assert_ne!(again.welcome().session_token, token, "with a new token");
    let state = snapshot_where(&mut again, WAIT, |s| s.get(new_id.0).is_some()).await;
    assert!(state.get(id.0).is_none(), "the old body left the room");
    let m = server.metrics();
    assert_eq!(metric(&m, "ledge_sessions_resumed_total"), 0.0);
    assert_eq!(metric(&m, r#"ledge_players{room="room-1"}"#), 1.0);
    again.close().await;
    server.stop().await.expect("clean stop");
}
