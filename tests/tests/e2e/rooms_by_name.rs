//! Rooms by name over real QUIC: friends who ask for the same room name
//! meet in it (it opens on the first request), see each other, and a
//! room list taken before joining shows it; past the room cap a new name
//! is refused with what to do.

use std::time::Duration;

use ledge_client::net::transport::dial;
use ledge_client::{connect_with, list_rooms, ClientError, JoinOptions, Session};
use ledge_shared::protocol::{RejectReason, RoomInfo};
use ledge_tests::{ids, snapshot_where, TestServer};

const WITHIN: Duration = Duration::from_secs(5);

async fn join_room(server: &TestServer, name: &str, room: &str) -> Result<Session, ClientError> {
    let options = JoinOptions {
        player_name: name.into(),
        room: Some(room.into()),
        resume: None,
        spectate: false,
    };
    connect_with(server.addr, "localhost", server.fingerprint, &options).await
}

async fn rooms(server: &TestServer) -> Vec<RoomInfo> {
    let dialed = dial(server.addr, "localhost", server.fingerprint)
        .await
        .expect("dials");
    list_rooms(dialed)
        .await
        .expect("the server lists its rooms")
}

fn room<'a>(list: &'a [RoomInfo], name: &str) -> &'a RoomInfo {
    list.iter()
        .find(|r| r.name == name)
        .unwrap_or_else(|| panic!("{name} listed in {list:?}"))
}

#[tokio::test]
async fn friends_meet_in_a_named_room_listed_before_joining() {
    let server = TestServer::start_with(|c| {
        c.rooms = 1;
        c.max_rooms = 2;
    })
    .await;
    let before = rooms(&server).await;
    assert_eq!(before.len(), 1, "{before:?}");
    assert_eq!(room(&before, "room-1").players, 0);

    // Somebody elsewhere: the server's own room.
    let mut stranger = server.join("stranger").await;
    assert_eq!(stranger.welcome().room, "room-1");

    let mut ana = join_room(&server, "ana", "friends")
        .await
        .expect("ana joins");
    let mut bo = join_room(&server, "bo", "friends").await.expect("bo joins");
    assert_eq!(ana.welcome().room, "friends");
    assert_eq!(bo.welcome().room, "friends");
    let (a, b) = (ana.welcome().player_id.0, bo.welcome().player_id.0);
    // Each sees the other (and not the stranger).
    for session in [&mut ana, &mut bo] {
        let state = snapshot_where(session, WITHIN, |s| {
            ids(s).contains(&a) && ids(s).contains(&b)
        })
        .await;
        assert!(!ids(&state).contains(&stranger.welcome().player_id.0));
    }
    let state = snapshot_where(&mut stranger, WITHIN, |_| true).await;
    assert!(!ids(&state).contains(&a) && !ids(&state).contains(&b));

    let listed = rooms(&server).await;
    let names: Vec<&str> = listed.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["friends", "room-1"]);
    let friends = room(&listed, "friends");
    assert_eq!((friends.players, friends.capacity), (2, 16));
    assert_eq!(friends.level_id, ana.welcome().level_id);
    assert_eq!(room(&listed, "room-1").players, 1);

    // The cap (2 rooms) is reached: a third name is refused, saying what
    // to do; an open room still takes players.
    match join_room(&server, "cy", "others").await {
        Err(ClientError::Rejected(RejectReason::Other { reason })) => {
            assert!(reason.contains("--list-rooms"), "{reason}")
        }
        other => panic!("expected a rejection, got {:?}", other.map(|_| ())),
    }
    let cy = join_room(&server, "cy", "friends").await.expect("cy joins");
    assert_eq!(cy.welcome().room, "friends");
    assert!(server.metrics().contains("ledge_rooms 2"));
    server.stop().await.expect("clean stop");
}
