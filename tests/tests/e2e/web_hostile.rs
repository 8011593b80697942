//! The web port under hostile load (issue 36), a real server on real
//! sockets: attackers from 127.0.0.3 (on a runtime of their own, as on a
//! machine of their own), honest browsers from 127.0.0.2. Slowloris
//! connections, a `/level` flood and a request flood must not keep the
//! honest ones out; refusals are 429 with `Retry-After`; nothing is left
//! behind afterwards.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use ledge_server::web::guard::mbps_to_bytes;
use ledge_shared::protocol::{ClientControl, ServerControl, PROTOCOL_VERSION};
use ledge_tests::attack::Attack;
use ledge_tests::e2e::{assert_steady, TickProbe};
use ledge_tests::web::{connect_from, http_get_from, HttpAnswer, WebEvent, WsClient};
use ledge_tests::{metric, TestServer};
use tokio::io::{AsyncReadExt, AsyncWriteExt};

use crate::level_download::noisy_map;
use crate::web_transports::{page, web_server};

/// Where the attackers connect from.
const ATTACKER: IpAddr = IpAddr::V4(Ipv4Addr::new(127, 0, 0, 3));
/// Where the honest browsers connect from.
const HONEST: IpAddr = IpAddr::V4(Ipv4Addr::new(127, 0, 0, 2));
/// How long each honest step may take.
const WITHIN: Duration = Duration::from_secs(1);

fn web_metric(server: &TestServer, series: &str) -> f64 {
    metric(&server.metrics(), series)
}

fn refused(server: &TestServer, reason: &str) -> f64 {
    web_metric(
        server,
        &format!("ledge_web_refused_total{{reason=\"{reason}\"}}"),
    )
}

/// `GET path` from `source` within `within`, or what went wrong.
async fn get_within(
    source: IpAddr,
    addr: SocketAddr,
    path: &str,
    within: Duration,
) -> Result<HttpAnswer, String> {
    match tokio::time::timeout(within, http_get_from(Some(source), addr, path, &[])).await {
        Ok(Some(answer)) if answer.status == 200 => Ok(answer),
        Ok(Some(answer)) => Err(format!("{path}: {}", answer.head)),
        Ok(None) => Err(format!("{path}: no answer")),
        Err(_) => Err(format!("{path}: not within {within:?}")),
    }
}

/// A WebSocket session from `source` that joins `room-1` as `name` and
/// leaves, within `within`.
async fn ws_join(
    source: IpAddr,
    addr: SocketAddr,
    name: &str,
    within: Duration,
) -> Result<(), String> {
    let join = async {
        let mut ws = WsClient::connect_from(Some(source), addr)
            .await
            .map_err(|e| format!("WebSocket: {e:?}"))?;
        ws.send_control(&ClientControl::HelloRoom {
            version: PROTOCOL_VERSION,
            name: name.into(),
            room: "room-1".into(),
        })
        .await;
        loop {
            match ws.next(within).await {
                Some(WebEvent::Control(ServerControl::Welcome(_))) => break,
                Some(WebEvent::Control(_) | WebEvent::Datagram(_) | WebEvent::Level(_)) => {}
                other => return Err(format!("no Welcome: {other:?}")),
            }
        }
        ws.send_control(&ClientControl::Leave).await;
        Ok(())
    };
    tokio::time::timeout(within, join)
        .await
        .map_err(|_| format!("the WebSocket join took over {within:?}"))?
}

/// An honest visit from [`HONEST`]: the page, `/web.json`, a WebSocket
/// join; each step within [`WITHIN`]. The longest step.
async fn honest_visit(addr: SocketAddr, name: &str) -> Result<Duration, String> {
    let mut longest = Duration::ZERO;
    for path in ["/", "/web.json"] {
        let t = Instant::now();
        get_within(HONEST, addr, path, WITHIN).await?;
        longest = longest.max(t.elapsed());
    }
    let t = Instant::now();
    ws_join(HONEST, addr, name, WITHIN).await?;
    Ok(longest.max(t.elapsed()))
}

/// Raises this process's open-file limit to at least `want` if the hard
/// limit allows (a thousand attack sockets and the server's ends).
fn raise_fd_limit(want: u64) {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit/setrlimit with a valid pointer to an rlimit.
    unsafe {
        if libc::getrlimit(libc::RLIMIT_NOFILE, &mut limit) == 0 && limit.rlim_cur < want {
            limit.rlim_cur = want.min(limit.rlim_max);
            libc::setrlimit(libc::RLIMIT_NOFILE, &limit);
        }
    }
}

/// Waits up to `within` for `done`, polling.
async fn eventually(within: Duration, mut done: impl FnMut() -> bool) -> bool {
    let deadline = Instant::now() + within;
    while !done() {
        if Instant::now() >= deadline {
            return false;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    true
}

/// `count` slowloris connections from [`ATTACKER`]: each sends a request
/// head a line a second, never ending it, and reconnects half a second
/// after the server drops it.
fn slowloris(attack: &mut Attack, addr: SocketAddr, count: usize) {
    for _ in 0..count {
        let (stop, opened, failed) = (
            attack.stop.clone(),
            attack.opened.clone(),
            attack.failed.clone(),
        );
        attack.spawn(async move {
            while !stop.load(Ordering::SeqCst) {
                let Ok(mut stream) = connect_from(Some(ATTACKER), addr).await else {
                    failed.fetch_add(1, Ordering::Relaxed);
                    tokio::time::sleep(Duration::from_millis(500)).await;
                    continue;
                };
                opened.fetch_add(1, Ordering::Relaxed);
                let mut line: &[u8] = b"GET / HTTP/1.1\r\n";
                while !stop.load(Ordering::SeqCst) && stream.write_all(line).await.is_ok() {
                    line = b"X-Slow: 1\r\n";
                    tokio::time::sleep(Duration::from_secs(1)).await;
                }
                tokio::time::sleep(Duration::from_millis(500)).await;
            }
        });
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_thousand_slowloris_connections_do_not_keep_honest_browsers_out() {
    raise_fd_limit(8192);
    let root = page();
    let server = web_server(root.path(), |_| {}).await;
    let addr = server.web_addr.unwrap();
    // Warm up (the first join loads what it loads), then count the tasks.
    honest_visit(addr, "warm-up")
        .await
        .expect("a visit before the attack");
    tokio::time::sleep(Duration::from_millis(500)).await;
    let tasks = tokio::runtime::Handle::current()
        .metrics()
        .num_alive_tasks();

    let mut attack = Attack::new();
    slowloris(&mut attack, addr, 1000);
    let end = Instant::now() + Duration::from_secs(20);
    tokio::time::sleep(Duration::from_secs(2)).await;
    let (mut visits, mut longest, mut failures) = (0, Duration::ZERO, Vec::new());
    while Instant::now() < end {
        let next = Instant::now() + Duration::from_millis(500);
        match honest_visit(addr, &format!("honest-{visits}")).await {
            Ok(t) => longest = longest.max(t),
            Err(e) => failures.push(e),
        }
        visits += 1;
        tokio::time::sleep_until(next.into()).await;
    }
    let open_during = web_metric(&server, "ledge_web_connections");
    let (opened, failed) = attack.stop().await;
    eprintln!(
        "{visits} honest visits, the longest step {longest:?}; the attack opened {opened} \
         connections ({failed} failed), {open_during} open at its end; refused: {}",
        refused(&server, "Connections")
    );
    assert!(failures.is_empty(), "honest visits failed: {failures:?}");
    assert!(visits >= 30, "{visits} visits");
    assert!(opened > 1000, "the attack ran: {opened}");
    assert!(
        refused(&server, "Connections") > 0.0,
        "the attacker's connections past its cap were refused"
    );
    assert!(open_during <= 16.0 + 16.0, "{open_during} connections open");

    // Nothing left: connections, tracked addresses, tasks, series.
    let clean = eventually(Duration::from_secs(10), || {
        web_metric(&server, "ledge_web_connections") == 0.0
            && web_metric(&server, "ledge_web_addresses") == 0.0
    })
    .await;
    assert!(clean, "{}", server.metrics());
    let settled = eventually(Duration::from_secs(10), || {
        tokio::runtime::Handle::current()
            .metrics()
            .num_alive_tasks()
            <= tasks
    })
    .await;
    assert!(settled, "tasks left over");
    assert!(
        !server.metrics().contains("127.0.0"),
        "no series per address"
    );
    server.stop().await.unwrap();
}

/// Bytes of `/level` bodies an attacker read, and how many requests were
/// refused.
#[derive(Default)]
struct Flood {
    bytes: AtomicU64,
    refused: AtomicU64,
}

/// `count` tasks from [`ATTACKER`] downloading `/level` over and over,
/// retrying refusals after 100 ms (not honouring `Retry-After`).
fn level_flood(attack: &mut Attack, addr: SocketAddr, count: usize, flood: &Arc<Flood>) {
    for _ in 0..count {
        let (stop, flood) = (attack.stop.clone(), flood.clone());
        attack.spawn(async move {
            while !stop.load(Ordering::SeqCst) {
                let Ok(mut stream) = connect_from(Some(ATTACKER), addr).await else {
                    tokio::time::sleep(Duration::from_millis(100)).await;
                    continue;
                };
                let request = b"GET /level HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n";
                if stream.write_all(request).await.is_err() {
                    continue;
                }
                let mut head = Vec::new();
                let mut buf = vec![0u8; 64 * 1024];
                let mut ok = None;
                while !stop.load(Ordering::SeqCst) {
                    let n = match stream.read(&mut buf).await {
                        Ok(0) | Err(_) => break,
                        Ok(n) => n,
                    };
                    match ok {
                        Some(true) => {
                            flood.bytes.fetch_add(n as u64, Ordering::Relaxed);
                        }
                        Some(false) => {}
                        None => {
                            head.extend_from_slice(&buf[..n]);
                            if let Some(end) = head.windows(4).position(|w| w == b"\r\n\r\n") {
                                let status_ok = head.starts_with(b"HTTP/1.1 200");
                                ok = Some(status_ok);
                                if status_ok {
                                    let body = (head.len() - end - 4) as u64;
                                    flood.bytes.fetch_add(body, Ordering::Relaxed);
                                } else {
                                    flood.refused.fetch_add(1, Ordering::Relaxed);
                                }
                            }
                        }
                    }
                }
                if ok != Some(true) {
                    tokio::time::sleep(Duration::from_millis(100)).await;
                }
            }
        });
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_level_flood_is_held_to_its_budget_while_an_honest_browser_downloads_and_joins() {
    let dir = tempfile::tempdir().unwrap();
    // 4 MiB of noise in the tileset: a multi-megabyte bundle.
    let map = noisy_map(dir.path(), 1024);
    let root = page();
    let (uplink_mbps, address_mbps) = (80.0, 16.0);
    let server = web_server(root.path(), move |c| {
        c.levels = vec![map.clone()];
        let web = c.web.as_mut().expect("the web port");
        web.limits.uplink_bytes_per_second = mbps_to_bytes(uplink_mbps);
        web.limits.address_bytes_per_second = mbps_to_bytes(address_mbps);
    })
    .await;
    let addr = server.web_addr.unwrap();
    let size = server.level_offer.size;
    assert!(size > 4_000_000, "a multi-megabyte bundle: {size}");
    let rate = mbps_to_bytes(address_mbps);

    let ticks_before = TickProbe::read(&server, "room-1");
    let flood = Arc::new(Flood::default());
    let mut attack = Attack::new();
    level_flood(&mut attack, addr, 8, &flood);
    // Measure the attacker after its first second, for six seconds.
    tokio::time::sleep(Duration::from_secs(1)).await;
    let (t0, b0) = (Instant::now(), flood.bytes.load(Ordering::SeqCst));
    // Meanwhile an honest browser downloads the level and joins.
    tokio::time::sleep(Duration::from_millis(500)).await;
    let started = Instant::now();
    let expected = Duration::from_secs_f64(size as f64 / rate);
    let level = get_within(HONEST, addr, "/level", expected * 2)
        .await
        .expect("the honest download");
    let took = started.elapsed();
    assert_eq!(
        ledge_levels::bundle::sha256(&level.body),
        server.level_offer.sha256,
        "the honest browser got the whole bundle"
    );
    ws_join(HONEST, addr, "honest", WITHIN)
        .await
        .expect("the honest browser joins");
    let remaining = Duration::from_secs(6).saturating_sub(t0.elapsed());
    tokio::time::sleep(remaining).await;
    let (secs, bytes) = (
        t0.elapsed().as_secs_f64(),
        flood.bytes.load(Ordering::SeqCst) - b0,
    );
    let ticks_after = TickProbe::read(&server, "room-1");
    attack.stop().await;
    let attacker_rate = bytes as f64 / secs;
    eprintln!(
        "the attacker read {:.2} MB/s (its budget {:.2} MB/s), {} refusals; the honest \
         download of {size} bytes took {took:?} (at the address rate {expected:?})",
        attacker_rate / 1e6,
        rate / 1e6,
        flood.refused.load(Ordering::SeqCst),
    );
    assert!(
        (attacker_rate / rate - 1.0).abs() <= 0.10,
        "the attacker got {attacker_rate:.0} B/s, its budget is {rate:.0} B/s"
    );
    assert!(
        took.as_secs_f64() <= expected.as_secs_f64() * 1.15 + 0.3,
        "the honest download took {took:?}, {expected:?} at full speed"
    );
    assert!(
        flood.refused.load(Ordering::SeqCst) > 0,
        "refused past 4 at once"
    );
    assert!(refused(&server, "Downloads") > 0.0);
    let served = web_metric(
        &server,
        "ledge_web_download_bytes_total{class=\"Loopback\"}",
    );
    assert!(served >= (bytes + size) as f64, "{served} bytes counted");
    assert_steady(
        "during the level flood",
        ticks_before.rate_until(&ticks_after),
        60.0,
    );
    server.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_request_flood_gets_429_with_retry_after_and_a_patient_client_is_served() {
    let root = page();
    let server = web_server(root.path(), |_| {}).await;
    let addr = server.web_addr.unwrap();
    let (mut ok, mut limited, mut retry_after) = (0, 0, 0u64);
    let started = Instant::now();
    for _ in 0..200 {
        let answer = http_get_from(Some(ATTACKER), addr, "/web.json", &[])
            .await
            .expect("an answer, not a silent drop");
        match answer.status {
            200 => ok += 1,
            429 => {
                limited += 1;
                let after: u64 = answer
                    .header("retry-after")
                    .and_then(|v| v.parse().ok())
                    .expect("a Retry-After in seconds");
                assert!(after >= 1);
                retry_after = after;
                assert!(String::from_utf8_lossy(&answer.body).contains("too many requests"));
            }
            other => panic!("status {other}: {}", answer.head),
        }
    }
    let secs = started.elapsed().as_secs_f64();
    eprintln!("{ok} answered, {limited} refused in {secs:.2} s; Retry-After {retry_after}");
    // The burst of 60 and 20 a second after it.
    assert!(
        ok >= 60 && f64::from(ok) <= 60.0 + 20.0 * secs + 1.0,
        "{ok} in {secs} s"
    );
    assert!(limited > 0);
    assert!(refused(&server, "Requests") >= f64::from(limited));
    // Another address is served meanwhile.
    get_within(HONEST, addr, "/web.json", WITHIN).await.unwrap();
    // The attacker's address, honouring Retry-After, is served again.
    tokio::time::sleep(Duration::from_secs(retry_after)).await;
    get_within(ATTACKER, addr, "/web.json", WITHIN)
        .await
        .expect("served after waiting as told");
    server.stop().await.unwrap();
}

/// Sends `request` raw on a fresh connection from [`HONEST`] and reads
/// until the server closes it or `within` passes: the text, and whether it
/// closed.
async fn raw(addr: SocketAddr, request: &[u8], within: Duration) -> (String, bool) {
    let mut stream = connect_from(Some(HONEST), addr).await.unwrap();
    stream.write_all(request).await.unwrap();
    let mut answer = Vec::new();
    let closed = tokio::time::timeout(within, stream.read_to_end(&mut answer))
        .await
        .is_ok();
    (String::from_utf8_lossy(&answer).into_owned(), closed)
}

#[tokio::test]
async fn reloads_revalidate_bodies_are_refused_and_idle_connections_close() {
    let root = page();
    let server = web_server(root.path(), |_| {}).await;
    let addr = server.web_addr.unwrap();
    // Entity tags: the page and the level answer 304 to a reload.
    for path in ["/", "/app.js", "/level"] {
        let first = http_get_from(Some(HONEST), addr, path, &[]).await.unwrap();
        assert_eq!(first.status, 200, "{path}");
        let tag = first.header("etag").expect("an entity tag").to_owned();
        assert_eq!(first.header("cache-control"), Some("no-cache"));
        let again = http_get_from(Some(HONEST), addr, path, &[("If-None-Match", &tag)])
            .await
            .unwrap();
        assert_eq!(again.status, 304, "{path}: {}", again.head);
        assert!(again.body.is_empty());
        let other = http_get_from(Some(HONEST), addr, path, &[("If-None-Match", "\"x\"")])
            .await
            .unwrap();
        assert_eq!(other.status, 200, "{path}: another version is sent");
    }
    let level = http_get_from(Some(HONEST), addr, "/level", &[])
        .await
        .unwrap();
    assert_eq!(
        level.header("etag"),
        Some(format!("\"{}\"", server.level_offer.hex()).as_str())
    );
    // A body is refused, saying so.
    let post = b"GET / HTTP/1.1\r\nHost: x\r\nContent-Length: 5\r\n\r\nhello";
    let (text, closed) = raw(addr, post, Duration::from_secs(3)).await;
    assert!(text.starts_with("HTTP/1.1 413"), "{text}");
    assert!(closed, "the connection closes after a refused body");
    // An idle keep-alive connection is closed after the header deadline.
    let started = Instant::now();
    let keep = b"GET /web.json HTTP/1.1\r\nHost: x\r\n\r\n";
    let (text, closed) = raw(addr, keep, Duration::from_secs(10)).await;
    assert!(text.starts_with("HTTP/1.1 200"), "{text}");
    assert!(closed, "the idle connection was closed");
    let idle = started.elapsed();
    assert!(
        idle >= ledge_server::web::HEADER_TIMEOUT - Duration::from_millis(100)
            && idle < ledge_server::web::HEADER_TIMEOUT + Duration::from_secs(2),
        "closed after {idle:?}"
    );
    server.stop().await.unwrap();
}
