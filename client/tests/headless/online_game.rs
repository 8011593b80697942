//! `OnlineGame` against a real server in-process on loopback: the calls a
//! fixed-step front end makes (`wait`, `update_ticks`) and what it reads.

use crate::common;

use std::time::{Duration, Instant};

use common::TestServer;
use ledge_client::net::background::NetStatus;
use ledge_client::{Fingerprint, OnlineGame, OnlineRequest, Trust};
use ledge_shared::input::Buttons;

const WITHIN: Duration = Duration::from_secs(20);

/// Runs `check` against a real server.
fn with_server(check: impl FnOnce(&TestServer)) {
    let server = TestServer::start();
    check(&server);
    server.stop();
}

fn connect(server: &TestServer, pin: Fingerprint) -> OnlineGame {
    let request = OnlineRequest::new(&server.addr.to_string(), Trust::Pinned(pin), "ada");
    OnlineGame::connect(request).unwrap()
}

#[test]
fn a_wrong_certificate_is_untrusted_once_waited_for() {
    with_server(|server| {
        let mut online = connect(server, Fingerprint([7; 32]));
        online.wait(WITHIN);
        assert!(online.untrusted().is_some(), "{}", online.status());
        assert!(matches!(online.status(), NetStatus::Failed(_)));
        assert!(online.game().is_none());
        assert_eq!(online.update_ticks(Instant::now(), 5, |_| Buttons::NONE), 0);
    });
}

#[test]
fn a_fixed_step_loop_idles_the_wait_runs_capped_ticks_and_sees_the_server() {
    with_server(|server| {
        let mut online = connect(server, server.fingerprint);
        online.wait(WITHIN);
        assert!(online.game().is_some(), "{}", online.status());
        assert!(online.untrusted().is_none());
        // The clock runs on while, say, a window opens: those ticks
        // are run idle at the first update, not counted as played.
        std::thread::sleep(Duration::from_millis(200));
        let start = online.game().unwrap().next_tick();
        assert_eq!(online.update_ticks(Instant::now(), 1, |_| Buttons::NONE), 0);
        assert!(online.game().unwrap().next_tick() >= start + 6);

        let deadline = Instant::now() + WITHIN;
        let (mut arrivals, mut played) = (0, 0);
        loop {
            let mut asked = 0;
            let ran = online.update_ticks(Instant::now(), 1, |i| {
                assert_eq!(i, asked);
                asked += 1;
                Buttons::NONE
            });
            assert!(ran <= 1 && ran == asked, "ran {ran}, asked {asked}");
            played += ran;
            arrivals += online.take_arrivals();
            let me = online.game().unwrap().me().0;
            let seen = online.server_state().and_then(|s| s.get(me)).is_some();
            if seen && arrivals > 1 && played > 5 {
                break;
            }
            assert!(Instant::now() < deadline, "{}", online.status());
            std::thread::sleep(Duration::from_millis(20));
        }
        assert_eq!(online.take_arrivals(), 0);
        assert!(online.game().unwrap().synced());
    });
}
