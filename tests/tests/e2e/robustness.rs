//! Hostile and broken clients: malformed and oversized messages, floods,
//! silence, too many connections. Each only ever affects itself.

use std::net::SocketAddr;
use std::time::{Duration, Instant};

use ledge_client::net::transport::dial;
use ledge_client::{connect, ClientError, Fingerprint, Session};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{
    write_frame, ClientControl, CloseCode, InputPacket, Message, ServerControl, MAX_FRAME,
};
use ledge_tests::{ids, metric, next_snapshot, snapshot_where, TestServer, UdpRelay, WAIT};

/// The close code the server ended `connection` with.
async fn close_code(connection: &quinn::Connection) -> u64 {
    let closed = tokio::time::timeout(WAIT, connection.closed())
        .await
        .expect("the server closes the connection in time");
    match closed {
        quinn::ConnectionError::ApplicationClosed(close) => close.error_code.into_inner(),
        other => panic!("expected an application close, got {other}"),
    }
}

/// A joined player that keeps working: answers pings, gets snapshots.
async fn assert_unaffected(session: &mut Session) {
    session
        .ping()
        .await
        .expect("the other client is unaffected");
    next_snapshot(session, WAIT).await;
    assert!(session.connection().close_reason().is_none());
}

/// Opens a raw connection, writes `bytes` on the control stream and returns
/// the close code the server answered with.
async fn send_raw(addr: SocketAddr, fingerprint: Fingerprint, bytes: &[u8]) -> u64 {
    let dialed = dial(addr, "localhost", fingerprint).await.unwrap();
    let (mut send, _recv) = dialed.connection.open_bi().await.unwrap();
    send.write_all(bytes).await.unwrap();
    close_code(&dialed.connection).await
}

#[tokio::test]
async fn an_oversized_or_garbage_first_frame_closes_only_that_connection() {
    let server = TestServer::start().await;
    let mut other = server.join("bystander").await;

    let header = (MAX_FRAME as u32 + 1).to_le_bytes();
    let code = send_raw(server.addr, server.fingerprint, &header).await;
    assert_eq!(code, u64::from(CloseCode::ProtocolViolation.to_u32()));

    let mut frame = 8u32.to_le_bytes().to_vec();
    frame.extend_from_slice(&[0xff; 8]);
    let code = send_raw(server.addr, server.fingerprint, &frame).await;
    assert_eq!(code, u64::from(CloseCode::ProtocolViolation.to_u32()));

    assert_unaffected(&mut other).await;
    // And the server still welcomes newcomers.
    server.join("newcomer").await;
    server.stop().await.unwrap();
}

#[tokio::test]
async fn an_oversized_frame_after_the_welcome_disconnects() {
    let server = TestServer::start().await;
    let mut other = server.join("bystander").await;
    let mut evil = server.join("evil").await;
    // A client frame is at most a few hundred bytes (a chat line): a 4 KiB
    // length prefix is refused from its four bytes alone.
    evil.send_raw_control(&4096u32.to_le_bytes()).await.unwrap();
    let code = close_code(evil.connection()).await;
    assert_eq!(code, u64::from(CloseCode::ProtocolViolation.to_u32()));
    assert!(metric(&server.metrics(), "ledge_kicks_total{reason=\"Malformed\"}") >= 1.0);
    assert_unaffected(&mut other).await;
    server.stop().await.unwrap();
}

#[tokio::test]
async fn malformed_control_messages_are_dropped_counted_then_disconnected() {
    // Below the control-message rate limit, so each one is decoded.
    let server = TestServer::start_with(|c| c.limits.malformed_burst = 5.0).await;
    let mut evil = server.join("evil").await;
    // Well-framed garbage: dropped and counted, the session goes on.
    let garbage = [3u8, 0, 0, 0, 0xff, 0xff, 0xff];
    evil.send_raw_control(&garbage).await.unwrap();
    evil.ping()
        .await
        .expect("one malformed message is tolerated");
    assert_eq!(
        metric(
            &server.metrics(),
            "ledge_malformed_messages_total{channel=\"Stream\"}"
        ),
        1.0
    );
    // A stream of them: disconnected.
    for _ in 0..30 {
        if evil.send_raw_control(&garbage).await.is_err() {
            break;
        }
    }
    let code = close_code(evil.connection()).await;
    assert_eq!(code, u64::from(CloseCode::ProtocolViolation.to_u32()));
    server.stop().await.unwrap();
}

#[tokio::test]
async fn malformed_datagrams_are_counted_then_the_sender_is_disconnected() {
    let server = TestServer::start().await;
    let mut other = server.join("bystander").await;
    let evil = server.join("evil").await;
    let connection = evil.connection().clone();

    // A few are tolerated (and counted)...
    for _ in 0..5 {
        connection
            .send_datagram_wait(vec![0xff; 40].into())
            .await
            .unwrap();
    }
    // An oversized one: over the 128-byte input limit.
    connection
        .send_datagram_wait(vec![0u8; 600].into())
        .await
        .unwrap();
    let deadline = Instant::now() + WAIT;
    while metric(
        &server.metrics(),
        "ledge_malformed_messages_total{channel=\"Datagram\"}",
    ) < 6.0
    {
        assert!(Instant::now() < deadline, "malformed datagrams not counted");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    assert!(connection.close_reason().is_none(), "a few are tolerated");
    // ...a steady stream of them is not.
    for _ in 0..40 {
        if connection
            .send_datagram_wait(vec![0xfe; 40].into())
            .await
            .is_err()
        {
            break;
        }
    }
    let code = close_code(&connection).await;
    assert_eq!(code, u64::from(CloseCode::ProtocolViolation.to_u32()));
    let text = server.metrics();
    assert!(
        metric(
            &text,
            "ledge_malformed_messages_total{channel=\"Datagram\"}"
        ) >= 20.0
    );
    assert!(metric(&text, "ledge_kicks_total{reason=\"Malformed\"}") >= 1.0);
    assert_unaffected(&mut other).await;
    server.stop().await.unwrap();
}

#[tokio::test]
async fn a_datagram_flood_is_dropped_counted_and_disconnected() {
    let server = TestServer::start().await;
    let mut other = server.join("bystander").await;
    let evil = server.join("flooder").await;
    let connection = evil.connection().clone();
    let packet = InputPacket::new(10, &[Buttons(Buttons::RIGHT); 16], None)
        .encode()
        .unwrap();
    // Valid inputs, far faster than one per tick.
    let started = Instant::now();
    let mut sent = 0;
    while started.elapsed() < Duration::from_secs(3) && connection.close_reason().is_none() {
        if connection
            .send_datagram_wait(packet.clone().into())
            .await
            .is_err()
        {
            break;
        }
        sent += 1;
        if sent % 50 == 0 {
            tokio::task::yield_now().await;
        }
    }
    let code = close_code(&connection).await;
    assert_eq!(code, u64::from(CloseCode::Kicked.to_u32()), "after {sent}");
    let text = server.metrics();
    assert!(
        metric(
            &text,
            "ledge_dropped_messages_total{reason=\"DatagramRateLimited\"}"
        ) >= 100.0,
        "{text}"
    );
    assert!(metric(&text, "ledge_kicks_total{reason=\"Flooding\"}") >= 1.0);
    assert_unaffected(&mut other).await;
    server.stop().await.unwrap();
}

#[tokio::test]
async fn a_chat_flood_is_rate_limited() {
    let server = TestServer::start().await;
    let mut other = server.join("bystander").await;
    let mut evil = server.join("chatty").await;
    for i in 0..60 {
        if evil.chat(&format!("spam {i}")).await.is_err() {
            break;
        }
    }
    let deadline = Instant::now() + WAIT;
    while metric(
        &server.metrics(),
        "ledge_dropped_messages_total{reason=\"ControlRateLimited\"}",
    ) < 30.0
    {
        assert!(Instant::now() < deadline, "chat flood not limited");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    // The bystander heard at most the burst.
    let heard = ledge_tests::drain(&mut other, Duration::from_millis(300))
        .await
        .into_iter()
        .filter(|e| matches!(e, ledge_client::SessionEvent::Chat { .. }))
        .count();
    assert!((1..=25).contains(&heard), "heard {heard} lines");
    assert_unaffected(&mut other).await;
    server.stop().await.unwrap();
}

#[tokio::test]
async fn a_silent_client_times_out_and_its_body_is_removed() {
    // No reconnect grace: the lost player goes as soon as it is lost
    // (tests/e2e/resume.rs covers keeping it).
    let server = TestServer::start_with(|c| {
        c.idle_timeout = Duration::from_millis(600);
        c.reconnect_grace = Duration::ZERO;
    })
    .await;
    let mut observer = server.join("observer").await;
    let (before, _) = next_snapshot(&mut observer, WAIT).await;
    let before = ids(&before.state);

    let relay = UdpRelay::start(server.addr).await;
    let ghost = connect(relay.addr, "localhost", server.fingerprint, "ghost")
        .await
        .expect("joins through the relay");
    let joined = ghost.welcome().server_tick;
    let with_ghost = snapshot_where(&mut observer, WAIT, |s| s.tick > joined).await;
    let body: Vec<u32> = ids(&with_ghost).difference(&before).copied().collect();
    assert!(!body.is_empty());

    // The network dies: no close, no more packets either way.
    relay.blackhole();
    let went = Instant::now();
    snapshot_where(&mut observer, WAIT, |s| {
        body.iter().all(|&id| s.get(id).is_none())
    })
    .await;
    let after = went.elapsed();
    assert!(
        after >= Duration::from_millis(400),
        "removed after {after:?}: before the idle timeout?"
    );
    assert_unaffected(&mut observer).await;
    drop(ghost);
    server.stop().await.unwrap();
}

#[tokio::test]
async fn a_client_that_never_says_hello_is_dropped_without_blocking_others() {
    let server = TestServer::start().await;
    let silent = dial(server.addr, "localhost", server.fingerprint)
        .await
        .unwrap();
    let mut other = server.join("bystander").await;
    assert_unaffected(&mut other).await;
    assert!(silent.connection.close_reason().is_none());
    server.stop().await.unwrap();
}

#[tokio::test]
async fn connections_over_the_cap_are_refused() {
    let server = TestServer::start_with(|c| c.max_connections = 2).await;
    let mut a = server.join("a").await;
    let _b = server.join("b").await;
    let err = connect(server.addr, "localhost", server.fingerprint, "c")
        .await
        .expect_err("over the cap");
    assert!(matches!(err, ClientError::Connection(_)), "{err}");
    assert!(
        err.to_string()
            .contains("the server refused the connection: it is full"),
        "{err}"
    );
    assert_eq!(
        metric(
            &server.metrics(),
            r#"ledge_connections_refused_total{reason="ServerFull"}"#
        ),
        1.0
    );
    assert_eq!(metric(&server.metrics(), "ledge_connections"), 2.0);
    assert_unaffected(&mut a).await;
    server.stop().await.unwrap();
}

#[tokio::test]
async fn a_forged_ack_is_counted_as_malformed_not_believed() {
    let server = TestServer::start().await;
    let mut forger = server.join("forger").await;
    let connection = forger.connection().clone();
    // Acknowledges a snapshot the server never sent.
    let lie = InputPacket::new(5, &[Buttons::NONE], Some(u64::MAX))
        .encode()
        .unwrap();
    connection.send_datagram(lie.into()).unwrap();
    let series = r#"ledge_malformed_messages_total{channel="Datagram"}"#;
    let deadline = Instant::now() + WAIT;
    while metric(&server.metrics(), series) < 1.0 {
        assert!(Instant::now() < deadline, "the forged ack was not counted");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    // Not believed: the client's own acks still get it deltas.
    let clock = ledge_client::InputClock::new(forger.welcome(), Instant::now());
    let mut deltas = 0;
    let until = Instant::now() + Duration::from_secs(2);
    while Instant::now() < until && deltas < 5 {
        let _ = forger.send_input(clock.input_tick(Instant::now()), Buttons::NONE);
        let (update, _) = next_snapshot(&mut forger, WAIT).await;
        deltas += usize::from(update.baseline_tick.is_some());
    }
    assert!(deltas >= 5, "only {deltas} delta snapshots after the lie");
    assert_eq!(metric(&server.metrics(), series), 1.0);
    forger.close().await;
    server.stop().await.unwrap();
}

#[tokio::test]
async fn pongs_to_a_client_that_stopped_reading_are_counted_as_that() {
    let server = TestServer::start().await;
    let mut bystander = server.join("bystander").await;
    let mut raw = ledge_tests::raw_hello(&server, b"deaf").await;
    assert!(
        matches!(raw.answer, ServerControl::Welcome(_)),
        "{:?}",
        raw.answer
    );
    // Stop reading the control stream (STOP_SENDING), then keep pinging.
    raw.recv.stop(0u32.into()).unwrap();
    let ping = |nonce| {
        let mut frame = Vec::new();
        write_frame(&ClientControl::Ping { nonce }, &mut frame).unwrap();
        frame
    };
    raw.send.write_all(&ping(0)).await.unwrap();
    tokio::time::sleep(Duration::from_millis(300)).await;
    for nonce in 1..=10 {
        raw.send.write_all(&ping(nonce)).await.unwrap();
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let series = |reason: &str| format!("ledge_dropped_messages_total{{reason=\"{reason}\"}}");
    let deadline = Instant::now() + WAIT;
    while metric(&server.metrics(), &series("ClientNotReading")) < 10.0 {
        assert!(
            Instant::now() < deadline,
            "pongs counted as not read:\n{}",
            server.metrics()
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert_eq!(metric(&server.metrics(), &series("ControlQueueFull")), 0.0);
    assert_unaffected(&mut bystander).await;
    drop(raw);
    server.stop().await.unwrap();
}
