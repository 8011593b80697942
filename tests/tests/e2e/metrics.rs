//! The Prometheus endpoint serves the server's counters over HTTP.

use std::net::SocketAddr;
use std::time::{Duration, Instant};

use ledge_client::InputClock;
use ledge_shared::input::Buttons;
use ledge_tests::{metric, next_snapshot, scrape, TestServer, WAIT};

#[tokio::test]
async fn the_metrics_endpoint_serves_the_counters() {
    let server = TestServer::start_with(|c| {
        c.metrics_bind = Some(SocketAddr::from(([127, 0, 0, 1], 0)));
    })
    .await;
    let addr = server.metrics_addr.expect("metrics endpoint bound");
    let mut ada = server.join("ada").await;
    let id = ada.welcome().player_id.0;
    // Send inputs for a while (with a gap, to starve the buffer) and
    // receive snapshots.
    let clock = InputClock::new(ada.welcome(), Instant::now());
    for i in 0..30 {
        if !(10..20).contains(&i) {
            ada.send_input(clock.input_tick(Instant::now()), Buttons(Buttons::LEFT))
                .unwrap();
        }
        tokio::time::sleep(Duration::from_millis(16)).await;
    }
    next_snapshot(&mut ada, WAIT).await;
    // One malformed datagram.
    ada.connection()
        .send_datagram(vec![0xee; 9].into())
        .unwrap();
    tokio::time::sleep(Duration::from_millis(100)).await;

    let (status, text) = scrape(addr).await;
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert!(text.ends_with("# EOF\n"), "OpenMetrics text");
    for series in [
        "ledge_players{room=\"room-1\"}",
        "ledge_connections",
        "ledge_tick_duration_seconds_count{room=\"room-1\"}",
        &format!("ledge_client_bytes_in_total{{client=\"{id}\"}}"),
        &format!("ledge_client_bytes_out_total{{client=\"{id}\"}}"),
        "ledge_bytes_out_total{channel=\"Datagram\"}",
        "ledge_snapshot_bytes_count{kind=\"Full\",channel=\"Datagram\"}",
        "ledge_input_starvation_total{room=\"room-1\"}",
        "ledge_malformed_messages_total{channel=\"Datagram\"}",
    ] {
        assert!(
            metric(&text, series) >= 1.0,
            "{series} missing or zero in\n{text}"
        );
    }
    assert!(text.contains("ledge_missed_ticks_total{room=\"room-1\"}"));
    let (status, _) = {
        let mut stream = tokio::net::TcpStream::connect(addr).await.unwrap();
        use tokio::io::{AsyncReadExt, AsyncWriteExt};
        stream
            .write_all(b"GET /nope HTTP/1.1\r\n\r\n")
            .await
            .unwrap();
        let mut response = String::new();
        stream.read_to_string(&mut response).await.unwrap();
        let status = response.lines().next().unwrap().to_owned();
        (status, response)
    };
    assert_eq!(status, "HTTP/1.1 404 Not Found");

    // A departed player's series go away (a bounded label set).
    ada.close().await;
    let deadline = Instant::now() + WAIT;
    loop {
        let (_, text) = scrape(addr).await;
        if !text.contains(&format!("client=\"{id}\"")) {
            assert_eq!(metric(&text, "ledge_players{room=\"room-1\"}"), 0.0);
            break;
        }
        assert!(Instant::now() < deadline, "client series not removed");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    server.stop().await.unwrap();
}
