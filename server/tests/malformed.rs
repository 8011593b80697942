//! Malformed input closes the offending connection only.

use std::net::SocketAddr;
use std::time::Duration;

use ledge_client::transport::dial;
use ledge_client::{connect, Session};
use ledge_server::protocol::{CloseCode, MAX_FRAME_LEN};
use ledge_server::{Fingerprint, Server, ServerConfig};

/// Starts a server on loopback; returns its address, fingerprint and the
/// guards that keep it (and its certificate directory) alive.
async fn start() -> (
    SocketAddr,
    Fingerprint,
    ledge_server::ShutdownHandle,
    tempfile::TempDir,
) {
    let dir = tempfile::tempdir().unwrap();
    let server = Server::bind(ServerConfig {
        bind: SocketAddr::from(([127, 0, 0, 1], 0)),
        cert_dir: dir.path().to_owned(),
        ..ServerConfig::default()
    })
    .unwrap();
    let (addr, fingerprint, shutdown) = (
        server.local_addr(),
        server.fingerprint(),
        server.shutdown_handle(),
    );
    tokio::spawn(server.run());
    (addr, fingerprint, shutdown, dir)
}

/// Opens a raw connection, writes `bytes` on the control stream and returns
/// the close code the server answered with.
async fn send_raw(addr: SocketAddr, fingerprint: Fingerprint, bytes: &[u8]) -> quinn::VarInt {
    let dialed = dial(addr, "localhost", fingerprint).await.unwrap();
    let (mut send, _recv) = dialed.connection.open_bi().await.unwrap();
    send.write_all(bytes).await.unwrap();
    let closed = tokio::time::timeout(Duration::from_secs(5), dialed.connection.closed())
        .await
        .expect("server closes the connection in time");
    match closed {
        quinn::ConnectionError::ApplicationClosed(close) => close.error_code,
        other => panic!("expected an application close, got {other}"),
    }
}

async fn bystander(addr: SocketAddr, fingerprint: Fingerprint) -> Session {
    let mut session = connect(addr, "localhost", fingerprint, "bystander")
        .await
        .unwrap();
    session.ping().await.unwrap();
    session
}

#[tokio::test]
async fn an_oversized_frame_closes_only_that_connection() {
    let (addr, fingerprint, shutdown, _dir) = start().await;
    let mut other = bystander(addr, fingerprint).await;

    let header = (MAX_FRAME_LEN as u32 + 1).to_be_bytes();
    let code = send_raw(addr, fingerprint, &header).await;
    assert_eq!(code, CloseCode::ProtocolViolation.into());

    other.ping().await.expect("the other client is unaffected");
    assert!(other.connection().close_reason().is_none());
    shutdown.shutdown();
}

#[tokio::test]
async fn a_garbage_frame_closes_only_that_connection() {
    let (addr, fingerprint, shutdown, _dir) = start().await;
    let mut other = bystander(addr, fingerprint).await;

    let mut frame = 8u32.to_be_bytes().to_vec();
    frame.extend_from_slice(&[0xff; 8]);
    let code = send_raw(addr, fingerprint, &frame).await;
    assert_eq!(code, CloseCode::ProtocolViolation.into());

    other.ping().await.expect("the other client is unaffected");
    // And the server still welcomes newcomers.
    bystander(addr, fingerprint).await;
    shutdown.shutdown();
}

#[tokio::test]
async fn a_silent_client_does_not_block_others() {
    let (addr, fingerprint, shutdown, _dir) = start().await;
    // Connects but never sends a hello.
    let silent = dial(addr, "localhost", fingerprint).await.unwrap();
    let mut other = bystander(addr, fingerprint).await;
    other.ping().await.unwrap();
    assert!(silent.connection.close_reason().is_none());
    shutdown.shutdown();
}
