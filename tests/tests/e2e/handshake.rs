//! The connection handshake end to end: real server, real QUIC, loopback.

use std::time::{Duration, Instant};

use ledge_client::net::transport::dial;
use ledge_client::{connect, connect_with, handshake, ClientError, Fingerprint, JoinOptions};
use ledge_shared::protocol::ServerControl;
use ledge_shared::protocol::{
    ClientControl, CloseCode, NoticeKind, ProtocolError, RejectReason, PROTOCOL_VERSION,
};
use ledge_tests::{next_snapshot, raw_hello, TestServer, WAIT};

#[tokio::test]
async fn welcome_reports_a_running_tick_loop() {
    let server = TestServer::start().await;
    let first_start = Instant::now();
    let mut first = server.join("ada").await;
    tokio::time::sleep(Duration::from_millis(200)).await;
    let second = server.join("bob").await;
    let elapsed = first_start.elapsed();

    let (a, b) = (first.welcome().clone(), second.welcome().clone());
    assert_ne!(a.player_id, b.player_id);
    assert_eq!(a.timing.tick_rate, 60);
    assert_eq!(a.timing.snapshot_interval, 2, "30 Hz snapshots at 60 Hz");
    assert!(a.timing.input_redundancy >= 8);
    assert_eq!(a.room, "room-1");
    assert_eq!(
        (a.level_id.clone(), a.level_hash),
        (b.level_id, b.level_hash)
    );
    // The loop ran between the two joins, and not faster than 60 Hz.
    let ticks = b.server_tick - a.server_tick;
    let most = (elapsed.as_secs_f64() * 60.0).ceil() as u64 + 1;
    assert!(
        (1..=most).contains(&ticks),
        "{ticks} ticks between joins {elapsed:?} apart"
    );
    // The control stream stays usable after the welcome.
    let rtt = first.ping().await.expect("ping answered");
    assert!(rtt < Duration::from_secs(1), "{rtt:?}");

    first.close().await;
    second.close().await;
    server.stop().await.expect("clean shutdown");
}

#[tokio::test]
async fn a_wrong_fingerprint_is_refused() {
    let server = TestServer::start().await;
    let wrong = Fingerprint([0x42; 32]);
    let err = connect(server.addr, "localhost", wrong, "eve")
        .await
        .expect_err("an unpinned certificate must not be trusted");
    match err {
        ClientError::FingerprintMismatch {
            expected,
            presented,
        } => {
            assert_eq!(expected, wrong);
            assert_eq!(presented, server.fingerprint);
        }
        other => panic!("expected a fingerprint mismatch, got {other}"),
    }
    server.stop().await.expect("clean shutdown");
}

#[tokio::test]
async fn a_wrong_protocol_version_is_rejected() {
    let server = TestServer::start().await;
    for version in [PROTOCOL_VERSION + 1, PROTOCOL_VERSION - 1, 0] {
        let dialed = dial(server.addr, "localhost", server.fingerprint)
            .await
            .expect("the transport connects");
        let hello = ClientControl::Hello {
            version,
            name: "future".into(),
        };
        let err = handshake(dialed, hello)
            .await
            .expect_err("another protocol version must be rejected");
        match err {
            ClientError::Rejected(RejectReason::ProtocolVersion { server, client }) => {
                assert_eq!(server, PROTOCOL_VERSION);
                assert_eq!(client, version);
            }
            other => panic!("expected a protocol-version reject, got {other}"),
        }
    }
    // The room-choosing hello is checked the same way.
    let dialed = dial(server.addr, "localhost", server.fingerprint)
        .await
        .unwrap();
    let hello = ClientControl::HelloRoom {
        version: PROTOCOL_VERSION + 7,
        name: "future".into(),
        room: "room-1".into(),
    };
    let err = handshake(dialed, hello).await.unwrap_err();
    assert!(
        matches!(
            err,
            ClientError::Rejected(RejectReason::ProtocolVersion { .. })
        ),
        "{err}"
    );
    server.stop().await.expect("clean shutdown");
}

#[tokio::test]
async fn an_invalid_name_is_refused_by_the_client_and_rejected_by_the_server() {
    let server = TestServer::start().await;
    // The client library refuses to send it...
    let err = connect(server.addr, "localhost", server.fingerprint, "")
        .await
        .expect_err("an empty name must be refused");
    assert!(
        matches!(
            err,
            ClientError::Protocol(ProtocolError::InvalidString { .. })
        ),
        "{err}"
    );
    // ...and a hand-made hello with a bad name gets a polite reject.
    // Hello: variant 0, version, then a name with a newline in it.
    let answer = raw_hello(&server, b"a\nb").await.answer;
    assert_eq!(
        answer,
        ServerControl::Reject {
            reason: RejectReason::InvalidName
        }
    );
    server.stop().await.expect("clean shutdown");
}

#[tokio::test]
async fn a_second_hello_is_a_protocol_violation() {
    let server = TestServer::start().await;
    let mut session = server.join("ada").await;
    session
        .send_control(&ClientControl::Hello {
            version: PROTOCOL_VERSION,
            name: "again".into(),
        })
        .await
        .unwrap();
    let closed = tokio::time::timeout(WAIT, session.connection().closed())
        .await
        .expect("closed in time");
    match closed {
        quinn::ConnectionError::ApplicationClosed(close) => {
            assert_eq!(
                close.error_code,
                CloseCode::ProtocolViolation.to_u32().into()
            )
        }
        other => panic!("expected an application close, got {other}"),
    }
    server.stop().await.expect("clean shutdown");
}

#[tokio::test]
async fn shutdown_sends_a_notice_then_closes_with_a_reason() {
    let server = TestServer::start().await;
    let mut session = server.join("ada").await;
    // Joined and receiving.
    next_snapshot(&mut session, WAIT).await;
    server.stop().await.expect("clean shutdown");
    let mut notices = Vec::new();
    let err = loop {
        match session.recv().await {
            Ok(ledge_client::SessionEvent::Notice(kind)) => notices.push(kind),
            Ok(_) => {}
            Err(e) => break e,
        }
    };
    assert_eq!(notices, [NoticeKind::Shutdown]);
    assert!(
        matches!(
            err,
            ClientError::ClosedByServer {
                code: Some(CloseCode::ServerShutdown),
                ..
            }
        ),
        "{err}"
    );
}

#[tokio::test]
async fn a_new_client_during_shutdown_is_turned_away() {
    let server = TestServer::start().await;
    let session = server.join("ada").await;
    server.begin_shutdown();
    let err = connect_with(
        server.addr,
        "localhost",
        server.fingerprint,
        &JoinOptions::new("late"),
    )
    .await
    .expect_err("no joining a server that is stopping");
    assert!(
        matches!(
            err,
            ClientError::Rejected(RejectReason::ShuttingDown)
                | ClientError::ClosedByServer { .. }
                | ClientError::Connection(_)
        ),
        "{err}"
    );
    drop(session);
    server.stop().await.expect("clean shutdown");
}
