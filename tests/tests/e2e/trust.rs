//! Trusting the server's certificate: pinned, or trust on first use with a
//! known-hosts file, over real QUIC.

use ledge_client::error::TrustError;
use ledge_client::net::trust::{connect_trusted, Trust, Trusted};
use ledge_client::{ClientError, Fingerprint, JoinOptions};
use ledge_tests::TestServer;

#[tokio::test]
async fn trust_on_first_use_stores_then_accepts_and_refuses_a_changed_certificate() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("config").join("known_hosts");
    let tofu = Trust::KnownHosts(path.clone());
    let join = JoinOptions::new("ada");
    let server = TestServer::start().await;
    let host = server.addr.to_string();
    let first = server.fingerprint;

    // First use: trusted and stored.
    let (session, trusted) = connect_trusted(&host, &tofu, &join).await.unwrap();
    assert_eq!(trusted, Trusted::FirstUse(first));
    session.close().await;
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains(&format!("{host} {first}")), "{text}");

    // Second time: the stored certificate is accepted, nothing is added.
    let (session, trusted) = connect_trusted(&host, &tofu, &join).await.unwrap();
    assert_eq!(trusted, Trusted::Known);
    session.close().await;
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text);

    // Pinned: the right fingerprint works, a wrong one is refused.
    let (session, trusted) = connect_trusted(&host, &Trust::Pinned(first), &join)
        .await
        .unwrap();
    assert_eq!(trusted, Trusted::Pinned);
    session.close().await;
    let wrong = Fingerprint([7; 32]);
    match connect_trusted(&host, &Trust::Pinned(wrong), &join).await {
        Err(ClientError::FingerprintMismatch {
            expected,
            presented,
        }) => assert_eq!((expected, presented), (wrong, first)),
        other => panic!("a wrong pin must be refused: {:?}", other.map(|(_, t)| t)),
    }

    // The server is replaced at the same address, with a new certificate.
    let addr = server.addr;
    server.stop().await.unwrap();
    let server = TestServer::start_with(|c| c.bind = addr).await;
    let second = server.fingerprint;
    assert_ne!(first, second);
    let err = match connect_trusted(&host, &tofu, &join).await {
        Err(e) => e,
        Ok((_, t)) => panic!("a changed certificate must be refused, got {t:?}"),
    };
    match &err {
        ClientError::Trust(TrustError::Changed {
            host: h,
            presented,
            stored,
            path: p,
            line,
        }) => {
            assert_eq!((h, *presented, *stored), (&host, second, first));
            assert_eq!((p, *line), (&path, 2));
        }
        other => panic!("expected a changed-certificate error, got {other:?}"),
    }
    let message = err.to_string();
    eprintln!("{message}");
    for needle in [
        "CHANGED",
        &host,
        &second.to_string(),
        &first.to_string(),
        &path.display().to_string(),
        "remove line 2",
        "--cert-hash",
    ] {
        assert!(
            message.contains(needle),
            "{needle:?} missing from: {message}"
        );
    }
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        text,
        "the stored certificate is kept"
    );

    // Doing what the message says (removing the line) trusts the new one.
    let kept: String = text
        .lines()
        .filter(|l| !l.starts_with(&host))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&path, kept).unwrap();
    let (session, trusted) = connect_trusted(&host, &tofu, &join).await.unwrap();
    assert_eq!(trusted, Trusted::FirstUse(second));
    session.close().await;
    server.stop().await.unwrap();
}
