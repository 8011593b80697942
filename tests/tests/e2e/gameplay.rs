//! Joining, inputs, snapshots, leaving, chat and rooms, end to end.

use std::collections::BTreeSet;
use std::time::{Duration, Instant};

use ledge_client::{connect_with, ClientError, InputClock, JoinOptions, SessionEvent};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{PlayerId, RejectReason};
use ledge_tests::{drain, ids, next_snapshot, snapshot_where, TestServer, WAIT};

#[tokio::test]
async fn the_first_snapshot_is_full_and_later_ones_are_deltas_against_acks() {
    let server = TestServer::start().await;
    let mut ada = server.join("ada").await;
    let (first, _) = next_snapshot(&mut ada, WAIT).await;
    assert_eq!(first.baseline_tick, None, "nothing acknowledged yet: full");
    assert!(
        first.state.tick >= ada.welcome().server_tick,
        "{} before the welcome's tick {}",
        first.state.tick,
        ada.welcome().server_tick
    );
    assert!(!first.state.entities.is_empty(), "our body is in it");
    assert_eq!(first.state.tick % 2, 0, "snapshots every 2 ticks");

    // Acks travel in input packets: send some, then deltas follow.
    let clock = InputClock::new(ada.welcome(), Instant::now());
    let deadline = Instant::now() + WAIT;
    let delta = loop {
        assert!(Instant::now() < deadline, "no delta snapshot in time");
        ada.send_input(clock.input_tick(Instant::now()), Buttons::NONE)
            .unwrap();
        let (update, _) = next_snapshot(&mut ada, WAIT).await;
        if update.baseline_tick.is_some() {
            break update;
        }
    };
    let baseline = delta.baseline_tick.unwrap();
    assert!(baseline < delta.state.tick);
    assert!(ada.snapshots().get(baseline).is_some());
    assert!(!delta.via_stream);
    assert!(ada.stats().full_snapshots >= 1);
    ada.close().await;
    server.stop().await.unwrap();
}

#[tokio::test]
async fn inputs_move_the_player_and_leaving_removes_the_body() {
    let server = TestServer::start().await;
    // An observer sees the mover's body appear, move and disappear.
    let mut observer = server.join("observer").await;
    let (before, _) = next_snapshot(&mut observer, WAIT).await;
    let before = ids(&before.state);

    let mut mover = server.join("mover").await;
    let joined_at = mover.welcome().server_tick;
    let with_mover = snapshot_where(&mut observer, WAIT, |s| s.tick > joined_at).await;
    let body: BTreeSet<u32> = ids(&with_mover).difference(&before).copied().collect();
    assert!(!body.is_empty(), "the mover's body appeared");
    let x_of = |s: &ledge_shared::protocol::StateSnapshot| -> i64 {
        body.iter()
            .filter_map(|&id| s.get(id))
            .map(|e| i64::from(e.pos.x))
            .sum()
    };
    let start_x = x_of(&with_mover);

    // Hold right for about 0.8 s, one input per tick.
    let clock = InputClock::new(mover.welcome(), Instant::now());
    let mut last_input_tick = None;
    let mut timings = Vec::new();
    let until = Instant::now() + Duration::from_millis(800);
    let mut latest = with_mover.clone();
    while Instant::now() < until {
        mover
            .send_input(clock.input_tick(Instant::now()), Buttons(Buttons::RIGHT))
            .unwrap();
        for event in drain(&mut mover, clock.until_next_tick(Instant::now())).await {
            if let SessionEvent::Snapshot(u) = event {
                last_input_tick = u.last_input_tick.or(last_input_tick);
                timings.push(u.input_timing);
            }
        }
        for event in drain(&mut observer, Duration::ZERO).await {
            if let SessionEvent::Snapshot(u) = event {
                latest = u.state;
            }
        }
    }
    let latest = snapshot_where(&mut observer, WAIT, |s| s.tick > latest.tick).await;
    let moved = x_of(&latest) - start_x;
    assert!(
        moved >= 4 * 256,
        "holding right for 0.8 s moved the body by {moved} units"
    );
    let applied = last_input_tick.expect("the server reported applied inputs");
    assert!(applied > joined_at, "{applied} vs join at {joined_at}");
    assert!(
        timings.iter().any(|&t| t >= 0),
        "inputs arrive in time: timings {timings:?}"
    );

    mover.close().await;
    let after = snapshot_where(&mut observer, WAIT, |s| {
        body.iter().all(|&id| s.get(id).is_none())
    })
    .await;
    assert!(ids(&after).is_subset(&ids(&latest)));
    observer.close().await;
    server.stop().await.unwrap();
}

#[tokio::test]
async fn chat_is_relayed_to_the_room() {
    let server = TestServer::start().await;
    let mut ada = server.join("ada").await;
    let mut bob = server.join("bob").await;
    ada.chat("hello, bob").await.unwrap();
    let ada_id = ada.welcome().player_id;
    for session in [&mut ada, &mut bob] {
        let heard = tokio::time::timeout(WAIT, async {
            loop {
                if let SessionEvent::Chat { from, text } = session.recv().await.unwrap() {
                    return (from, text);
                }
            }
        })
        .await
        .expect("the chat line arrives");
        assert_eq!(heard, (ada_id, "hello, bob".to_owned()));
    }
    // A line with a direction override is refused before it leaves; sent
    // anyway (raw), the server drops it and nobody hears it.
    let evil = "look at this \u{202E}gnp.exe";
    let refused = ada.chat(evil).await.unwrap_err();
    assert!(
        refused.to_string().contains("direction override"),
        "{refused}"
    );
    // `ClientControl::Chat` is variant 1; a string is its length (one
    // byte below 251) and its bytes (docs/PROTOCOL.md, "Encodings").
    let mut raw = vec![1u8, evil.len() as u8];
    raw.extend_from_slice(evil.as_bytes());
    let mut frame = (raw.len() as u32).to_le_bytes().to_vec();
    frame.extend_from_slice(&raw);
    ada.send_raw_control(&frame).await.unwrap();
    ada.chat("still here").await.unwrap();
    let next = tokio::time::timeout(WAIT, async {
        loop {
            if let SessionEvent::Chat { text, .. } = bob.recv().await.unwrap() {
                return text;
            }
        }
    })
    .await
    .expect("the next line arrives");
    assert_eq!(next, "still here", "the hidden line was not relayed");
    ada.close().await;
    bob.close().await;
    server.stop().await.unwrap();
}

#[tokio::test]
async fn players_fill_the_least_full_room_or_the_named_one() {
    let server = TestServer::start_with(|c| {
        c.rooms = 2;
        c.max_rooms = 2;
        c.max_players = 2;
    })
    .await;
    let (addr, fingerprint) = (server.addr, server.fingerprint);
    let join = |name: &str, room: Option<&str>| {
        let options = JoinOptions {
            player_name: name.to_owned(),
            room: room.map(str::to_owned),
            resume: None,
            spectate: false,
        };
        async move { connect_with(addr, "localhost", fingerprint, &options).await }
    };
    let a = join("a", None).await.unwrap();
    let b = join("b", None).await.unwrap();
    assert_ne!(a.welcome().room, b.welcome().room, "spread over both rooms");
    let c = join("c", Some("room-2")).await.unwrap();
    assert_eq!(c.welcome().room, "room-2");
    // room-2 is full now; a named join is refused, an unnamed one goes to room-1.
    let err = join("d", Some("room-2")).await.unwrap_err();
    assert!(
        matches!(err, ClientError::Rejected(RejectReason::RoomFull)),
        "{err}"
    );
    let d = join("d", None).await.unwrap();
    assert_eq!(d.welcome().room, "room-1");
    let err = join("e", None).await.unwrap_err();
    assert!(
        matches!(err, ClientError::Rejected(RejectReason::RoomFull)),
        "{err}"
    );
    // Both rooms (the cap) are open: a new name is refused, saying why.
    let err = join("f", Some("nowhere")).await.unwrap_err();
    assert!(
        matches!(&err, ClientError::Rejected(RejectReason::Other { reason })
            if reason.contains("--list-rooms")),
        "{err}"
    );
    // Ids are unique across rooms.
    let ids: BTreeSet<PlayerId> = [&a, &b, &c, &d]
        .iter()
        .map(|s| s.welcome().player_id)
        .collect();
    assert_eq!(ids.len(), 4);
    // A place frees up when a player leaves.
    c.close().await;
    let deadline = Instant::now() + WAIT;
    let e = loop {
        match join("e", Some("room-2")).await {
            Ok(e) => break e,
            Err(_) if Instant::now() < deadline => {
                tokio::time::sleep(Duration::from_millis(50)).await
            }
            Err(err) => panic!("room-2 still full after a leave: {err}"),
        }
    };
    assert_eq!(e.welcome().room, "room-2");
    server.stop().await.unwrap();
}
