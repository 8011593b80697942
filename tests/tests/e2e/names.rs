//! Names tell players apart: one name per room, whatever the case or
//! look-alike letters, and no invisible or formatting characters; a
//! refused name gets a reason.

use ledge_client::ClientError;
use ledge_shared::protocol::{RejectReason, ServerControl};
use ledge_tests::{TestServer, WAIT};

/// The server's answer to a hand-made hello with `name` (past the
/// client's own checks).
async fn raw_hello(server: &TestServer, name: &str) -> ServerControl {
    ledge_tests::raw_hello(server, name.as_bytes()).await.answer
}

#[tokio::test]
async fn names_are_unique_per_room_and_visible() {
    let server = TestServer::start().await;
    let bot = server.join("bot-1").await;
    for twin in ["bot-1", "BOT-1", "bot-l", "b\u{043E}t-1"] {
        match server_join(&server, twin).await {
            Err(ClientError::Rejected(RejectReason::Other { reason })) => {
                assert!(
                    reason.contains("is taken") && reason.contains("--name"),
                    "{reason}"
                )
            }
            other => panic!("{twin:?}: expected a refusal, got {other:?}"),
        }
    }
    // Invisible or formatting characters, sent by a client that does not
    // check: refused as an invalid name.
    for hidden in ["bot\u{200B}1", "\u{202E}ana", "\u{3164}", " "] {
        assert_eq!(
            raw_hello(&server, hidden).await,
            ServerControl::Reject {
                reason: RejectReason::InvalidName
            },
            "{hidden:?}"
        );
    }
    // Another name is fine; a freed name can be taken again.
    let other = server.join("bot-2").await;
    bot.close().await;
    let deadline = std::time::Instant::now() + WAIT;
    let again = loop {
        match server_join(&server, "bot-1").await {
            Ok(s) => break s,
            Err(e) => assert!(std::time::Instant::now() < deadline, "{e}"),
        }
        tokio::time::sleep(std::time::Duration::from_millis(50)).await;
    };
    again.close().await;
    other.close().await;
    server.stop().await.unwrap();
}

async fn server_join(
    server: &TestServer,
    name: &str,
) -> Result<ledge_client::Session, ClientError> {
    ledge_client::connect(server.addr, "localhost", server.fingerprint, name).await
}
