//! Spectators (issue 32) over real QUIC: a client that asks to watch gets
//! the room's roster and snapshots, sees every player move and finish,
//! has no body, takes no player's place and cannot chat.

use std::collections::BTreeMap;
use std::time::Duration;

use ledge_client::net::session::{connect_with, JoinOptions, Session, SessionEvent};
use ledge_shared::game::{kind, RUN_ID_BASE};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{NoticeKind, PlayerId};
use ledge_tests::TestServer;

use crate::records::race;

/// What a spectator saw of each player: its first and last position and
/// its finishing ticks and place (0: not finished).
#[derive(Debug, Default, Clone, Copy)]
struct Seen {
    first_x: Option<i32>,
    last_x: i32,
    finish: Option<(u32, u32)>,
}

async fn spectate(server: &TestServer, name: &str) -> Session {
    let options = JoinOptions {
        spectate: true,
        ..JoinOptions::new(name)
    };
    connect_with(server.addr, "localhost", server.fingerprint, &options)
        .await
        .expect("a spectator is welcomed")
}

/// Watches until `until` players have finished (or 40 s), acknowledging
/// each snapshot; returns what it saw, the names it was told and the
/// notices.
async fn watch(
    session: &mut Session,
    until: usize,
) -> (
    BTreeMap<PlayerId, Seen>,
    BTreeMap<PlayerId, String>,
    Vec<NoticeKind>,
) {
    let me = session.welcome().player_id;
    let (mut seen, mut names, mut notices) = (BTreeMap::new(), BTreeMap::new(), Vec::new());
    let deadline = tokio::time::Instant::now() + Duration::from_secs(40);
    while seen.values().filter(|s: &&Seen| s.finish.is_some()).count() < until {
        let event = tokio::time::timeout_at(deadline, session.recv())
            .await
            .expect("everyone finished in time")
            .expect("the session lasts");
        match event {
            SessionEvent::Snapshot(update) => {
                for e in &update.state.entities {
                    assert_ne!(e.id, me.0, "a spectator has no body");
                    if e.kind == kind::PLAYER {
                        let s: &mut Seen = seen.entry(PlayerId(e.id)).or_default();
                        s.first_x.get_or_insert(e.pos.x);
                        s.last_x = e.pos.x;
                    } else if e.kind == kind::RUN && e.aux > 0 {
                        let s = seen.entry(PlayerId(e.id - RUN_ID_BASE)).or_default();
                        s.finish = Some((e.pos.x as u32, e.aux as u32));
                    }
                }
                // Acknowledge it: its buttons move nothing.
                let tick = update.state.tick + 1;
                session.send_input(tick, Buttons(Buttons::RIGHT)).unwrap();
            }
            SessionEvent::PlayerJoined { id, name } => {
                names.insert(id, name);
            }
            SessionEvent::Notice(n) => notices.push(n),
            _ => {}
        }
    }
    (seen, names, notices)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_spectator_sees_every_player_run_and_takes_no_place() {
    // Two players' places; the spectator comes first.
    let server = TestServer::start_with(|c| c.max_players = 2).await;
    let mut spectator = spectate(&server, "sam").await;
    let me = spectator.welcome().player_id;
    spectator.chat("hello").await.unwrap();
    let watching = tokio::spawn(async move {
        let saw = watch(&mut spectator, 2).await;
        (spectator, saw)
    });
    let reports = race(&server, &["ann", "bob"]).await;
    let (spectator, (seen, names, notices)) = watching.await.unwrap();

    for r in &reports {
        let id = r.player.expect("a player id");
        assert_eq!(names.get(&id), Some(&r.name), "told who plays");
        let s = seen[&id];
        let moved = s.last_x - s.first_x.unwrap();
        assert!(moved > 100 * 256, "{} moved {moved} units", r.name);
        let (ticks, place) = s.finish.expect("seen finishing");
        assert_eq!(Some(ticks), r.finish_ticks, "{}'s time", r.name);
        assert!((1..=2).contains(&place));
    }
    assert!(!names.contains_key(&me), "a spectator is in no roster");
    assert!(
        notices.iter().any(
            |n| matches!(n, NoticeKind::Info { text } if text.contains("spectators cannot chat"))
        ),
        "{notices:?}"
    );
    spectator.close().await;
    server.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_full_room_still_takes_spectators_up_to_their_own_cap() {
    let server = TestServer::start_with(|c| {
        c.max_players = 1;
        c.max_spectators = 1;
    })
    .await;
    let ann = server.join("ann").await;
    // The player's place is taken: a second player is refused...
    let options = JoinOptions::new("bob");
    let refused = connect_with(server.addr, "localhost", server.fingerprint, &options).await;
    assert!(refused.is_err(), "a second player in a one-player room");
    // ...a spectator is not; a second spectator is, saying why.
    let sam = spectate(&server, "sam").await;
    let options = JoinOptions {
        spectate: true,
        ..JoinOptions::new("sue")
    };
    let Err(err) = connect_with(server.addr, "localhost", server.fingerprint, &options).await
    else {
        panic!("a second spectator is refused");
    };
    assert!(err.to_string().contains("spectator places"), "{err}");
    sam.close().await;
    ann.close().await;
    server.stop().await.unwrap();
}
