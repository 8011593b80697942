//! The connection handshake end to end: real server, real QUIC, loopback.

use std::time::{Duration, Instant};

use ledge_client::transport::dial;
use ledge_client::{connect, handshake, ClientError, Fingerprint};
use ledge_server::protocol::{CloseCode, Hello, RejectReason, PROTOCOL_VERSION};
use ledge_tests::TestServer;

#[tokio::test]
async fn welcome_reports_a_running_tick_loop() {
    let server = TestServer::start().await;
    let first_start = Instant::now();
    let mut first = connect(server.addr, "localhost", server.fingerprint, "ada")
        .await
        .expect("first client is welcomed");
    tokio::time::sleep(Duration::from_millis(200)).await;
    let second = connect(server.addr, "localhost", server.fingerprint, "bob")
        .await
        .expect("second client is welcomed");
    let elapsed = first_start.elapsed();

    let (a, b) = (first.welcome().clone(), second.welcome().clone());
    assert_ne!(a.player_id, b.player_id);
    assert_eq!(a.tick_rate, 60);
    // The loop ran between the two joins, and not faster than 60 Hz.
    let ticks = b.tick - a.tick;
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
    let dialed = dial(server.addr, "localhost", server.fingerprint)
        .await
        .expect("the transport connects");
    let hello = Hello {
        protocol_version: PROTOCOL_VERSION + 1,
        name: "future".into(),
    };
    let err = handshake(dialed, hello)
        .await
        .expect_err("another protocol version must be rejected");
    match err {
        ClientError::Rejected(RejectReason::ProtocolVersion { server, client }) => {
            assert_eq!(server, PROTOCOL_VERSION);
            assert_eq!(client, PROTOCOL_VERSION + 1);
        }
        other => panic!("expected a protocol-version reject, got {other}"),
    }
    server.stop().await.expect("clean shutdown");
}

#[tokio::test]
async fn an_invalid_name_is_rejected() {
    let server = TestServer::start().await;
    let err = connect(server.addr, "localhost", server.fingerprint, "")
        .await
        .expect_err("an empty name must be rejected");
    assert!(
        matches!(err, ClientError::Rejected(RejectReason::InvalidName)),
        "{err}"
    );
    server.stop().await.expect("clean shutdown");
}

#[tokio::test]
async fn shutdown_closes_sessions_with_a_reason() {
    let server = TestServer::start().await;
    let mut session = connect(server.addr, "localhost", server.fingerprint, "ada")
        .await
        .expect("welcomed");
    server.stop().await.expect("clean shutdown");
    let err = session.ping().await.expect_err("server is gone");
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
