//! The relay over real loopback UDP: an echo server behind it, clients in
//! front.

use std::collections::BTreeSet;
use std::net::SocketAddr;
use std::time::Duration;

use ledge_netsim::{Direction, LinkConfig, Loss, Relay, RelayConfig};
use tokio::net::UdpSocket;
use tokio::time::{timeout, Instant};

/// Echoes every datagram back to its sender; returns its address and the
/// senders it has seen.
async fn echo_server() -> (
    SocketAddr,
    tokio::sync::watch::Receiver<BTreeSet<SocketAddr>>,
) {
    let socket = UdpSocket::bind("127.0.0.1:0").await.unwrap();
    let addr = socket.local_addr().unwrap();
    let (tx, rx) = tokio::sync::watch::channel(BTreeSet::new());
    tokio::spawn(async move {
        let mut buf = vec![0u8; 2048];
        while let Ok((n, from)) = socket.recv_from(&mut buf).await {
            tx.send_modify(|seen| {
                seen.insert(from);
            });
            let _ = socket.send_to(&buf[..n], from).await;
        }
    });
    (addr, rx)
}

async fn client(relay: &Relay) -> UdpSocket {
    let socket = UdpSocket::bind("127.0.0.1:0").await.unwrap();
    socket.connect(relay.local_addr()).await.unwrap();
    socket
}

/// Sends `n` numbered datagrams `every` apart and collects the echoes that
/// come back within `wait` of the last send.
async fn ping(socket: &UdpSocket, n: u32, every: Duration, wait: Duration) -> Vec<(u32, Duration)> {
    let mut back = Vec::new();
    let mut buf = [0u8; 64];
    let start = Instant::now();
    let mut next = start;
    let mut sent = 0;
    loop {
        let deadline = if sent < n { next } else { next + wait };
        match timeout(
            deadline.saturating_duration_since(Instant::now()),
            socket.recv(&mut buf),
        )
        .await
        {
            Ok(Ok(8)) => {
                let i = u32::from_le_bytes(buf[..4].try_into().unwrap());
                let at = Duration::from_micros(u64::from(u32::from_le_bytes(
                    buf[4..8].try_into().unwrap(),
                )));
                back.push((i, start.elapsed() - at));
            }
            Ok(_) => panic!("unexpected datagram"),
            Err(_) if sent < n => {
                let at = start.elapsed().as_micros() as u32;
                let mut msg = sent.to_le_bytes().to_vec();
                msg.extend_from_slice(&at.to_le_bytes());
                socket.send(&msg).await.unwrap();
                sent += 1;
                next += every;
            }
            Err(_) => return back,
        }
    }
}

#[tokio::test]
async fn two_clients_share_a_relay_with_delay_loss_and_blackout() {
    let (server, seen) = echo_server().await;
    let link = LinkConfig::delay(Duration::from_millis(30))
        .with_jitter(Duration::from_millis(5))
        .with_loss(Loss::Bernoulli { p: 0.1 });
    let relay = Relay::start(
        "127.0.0.1:0".parse().unwrap(),
        server,
        RelayConfig::symmetric(link),
    )
    .await
    .unwrap();
    let (a, b) = (client(&relay).await, client(&relay).await);
    let every = Duration::from_millis(2);
    let wait = Duration::from_millis(300);
    let (back_a, back_b) = tokio::join!(ping(&a, 400, every, wait), ping(&b, 400, every, wait));
    // Each client has its own upstream socket: the server sees two.
    assert_eq!(seen.borrow().len(), 2);
    assert!(!seen.borrow().contains(&a.local_addr().unwrap()));
    for back in [&back_a, &back_b] {
        // Two chances of 10% loss: 81% come back.
        let rate = back.len() as f64 / 400.0;
        assert!((0.7..=0.9).contains(&rate), "{rate}");
        for (i, rtt) in back {
            assert!(
                *rtt >= Duration::from_millis(50),
                "{i} came back in {rtt:?}"
            );
        }
        // Jitter alone never reorders.
        assert!(back.windows(2).all(|w| w[0].0 < w[1].0), "reordered");
    }
    let s = relay.stats();
    eprintln!("up: {}\ndown: {}", s.up, s.down);
    assert_eq!(s.clients, 2);
    assert_eq!(s.up.received, 800);
    assert_eq!(s.up.forwarded + s.up.lost, 800);
    assert_eq!(s.down.received, s.up.forwarded);
    assert_eq!(s.down.forwarded + s.down.lost, s.down.received);
    assert_eq!(s.down.forwarded as usize, back_a.len() + back_b.len());

    // A blackout one way: nothing comes back, and it is counted.
    relay.set_link(Direction::Up, LinkConfig::PERFECT).unwrap();
    relay
        .set_link(Direction::Down, LinkConfig::PERFECT)
        .unwrap();
    relay.set_blackout(Direction::Down, true);
    // Let the flows see the new settings.
    tokio::time::sleep(Duration::from_millis(20)).await;
    assert!(ping(&a, 20, every, wait).await.is_empty());
    let s2 = relay.stats();
    assert_eq!(s2.down.blackout - s.down.blackout, 20);
    assert_eq!(s2.up.forwarded - s.up.forwarded, 20);
    // Restored: everything comes back, at once.
    relay.set_blackout(Direction::Down, false);
    tokio::time::sleep(Duration::from_millis(20)).await;
    let back = ping(&a, 50, every, wait).await;
    assert_eq!(back.len(), 50);
    assert!(back.iter().all(|(_, rtt)| *rtt < Duration::from_millis(50)));
}

#[tokio::test]
async fn duplicates_and_reordering_reach_the_client() {
    let (server, _) = echo_server().await;
    let down = LinkConfig::delay(Duration::from_millis(5))
        .with_duplicate(0.2)
        .with_reorder(0.2, Duration::from_millis(15));
    let relay = Relay::start(
        "127.0.0.1:0".parse().unwrap(),
        server,
        RelayConfig {
            down,
            seed: 42,
            ..RelayConfig::default()
        },
    )
    .await
    .unwrap();
    let a = client(&relay).await;
    let back = ping(
        &a,
        300,
        Duration::from_millis(3),
        Duration::from_millis(200),
    )
    .await;
    let s = relay.stats();
    eprintln!("down: {}", s.down);
    assert_eq!(s.up.forwarded, 300);
    assert_eq!(back.len() as u64, 300 + s.down.duplicated);
    assert!((30..=90).contains(&s.down.duplicated), "{}", s.down);
    assert!((30..=90).contains(&s.down.reordered), "{}", s.down);
    let inversions = back.windows(2).filter(|w| w[0].0 > w[1].0).count();
    assert!(inversions >= 20, "{inversions} inversions");
}

#[tokio::test]
async fn a_bad_configuration_is_refused() {
    let bad = LinkConfig::PERFECT.with_loss(Loss::Bernoulli { p: 2.0 });
    let start = Relay::start(
        "127.0.0.1:0".parse().unwrap(),
        "127.0.0.1:9".parse().unwrap(),
        RelayConfig::symmetric(bad),
    )
    .await;
    assert!(start.is_err());
    let relay = Relay::start(
        "127.0.0.1:0".parse().unwrap(),
        "127.0.0.1:9".parse().unwrap(),
        RelayConfig::default(),
    )
    .await
    .unwrap();
    assert!(relay.set_link(Direction::Up, bad).is_err());
    assert_eq!(relay.link(Direction::Up), LinkConfig::PERFECT);
}

#[tokio::test]
async fn an_idle_client_is_forgotten_and_comes_back() {
    let (server, seen) = echo_server().await;
    let relay = Relay::start(
        "127.0.0.1:0".parse().unwrap(),
        server,
        RelayConfig {
            idle: Duration::from_millis(200),
            ..RelayConfig::default()
        },
    )
    .await
    .unwrap();
    let a = client(&relay).await;
    let every = Duration::from_millis(2);
    let wait = Duration::from_millis(100);
    assert_eq!(ping(&a, 5, every, wait).await.len(), 5);
    assert_eq!(relay.stats().clients, 1);
    tokio::time::sleep(Duration::from_millis(400)).await;
    assert_eq!(relay.stats().clients, 0, "forgotten when idle");
    // Back: a new flow, so a new upstream socket.
    assert_eq!(ping(&a, 5, every, wait).await.len(), 5);
    assert_eq!(relay.stats().clients, 1);
    assert_eq!(seen.borrow().len(), 2);
}
