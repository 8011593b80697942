//! Level rotation and votes (issue 32) over real QUIC: a server with two
//! levels (the default level and a copy of it under another name, so
//! another bundle to download) tells its players the list; a majority vote
//! moves the room to the second level, every member (a spectator too) is
//! re-welcomed on it at the room's tick, downloads it by its hash and gets
//! its snapshots; runner bots that finish the first level are moved on,
//! download the second and finish it too.

use std::path::{Path, PathBuf};
use std::time::Duration;

use ledge_client::bot::{BotOptions, Runner};
use ledge_client::net::bundle::{fetch_level, FetchOptions};
use ledge_client::net::session::{connect_with, JoinOptions, Session, SessionEvent};
use ledge_levels::default_route;
use ledge_server::config::RotationConfig;
use ledge_shared::protocol::{LevelList, VoteRule, Welcome};
use ledge_tests::e2e::{bot_options, spawn_bot};
use ledge_tests::{metric, TestServer};

/// The default level's files, and a copy of the level named `second`, in
/// `dir`: the rotation `[default, second]`.
pub fn two_levels(dir: &Path) -> Vec<PathBuf> {
    ledge_levels::write_default_copies(dir, &["default", "second"]).unwrap()
}

/// A server rotating through `two_levels`, one second of results.
pub async fn rotating_server(dir: &Path, vote: VoteRule) -> TestServer {
    let levels = two_levels(dir);
    TestServer::start_with(move |c| {
        c.levels = levels;
        c.rooms = 1;
        c.rotation = RotationConfig {
            level_time: None,
            results_time: Duration::from_secs(1),
            vote,
        };
    })
    .await
}

/// Events until `found` picks one, within `within`.
async fn until<T>(
    session: &mut Session,
    within: Duration,
    mut found: impl FnMut(SessionEvent) -> Option<T>,
) -> T {
    tokio::time::timeout(within, async {
        loop {
            let event = session.recv().await.expect("the session lasts");
            if let Some(t) = found(event) {
                return t;
            }
        }
    })
    .await
    .expect("in time")
}

async fn levels(session: &mut Session) -> LevelList {
    until(session, Duration::from_secs(5), |e| match e {
        SessionEvent::Levels(list) => Some(list),
        _ => None,
    })
    .await
}

async fn level_change(session: &mut Session) -> Welcome {
    until(session, Duration::from_secs(10), |e| match e {
        SessionEvent::LevelChange(w) => Some(w),
        _ => None,
    })
    .await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_majority_vote_moves_the_room_and_every_member_follows() {
    let dir = tempfile::tempdir().unwrap();
    let server = rotating_server(dir.path(), VoteRule::Majority).await;
    let mut ann = server.join("ann").await;
    let mut bob = server.join("bob").await;
    let spectate = JoinOptions {
        spectate: true,
        ..JoinOptions::new("eve")
    };
    let mut eve = connect_with(server.addr, "localhost", server.fingerprint, &spectate)
        .await
        .unwrap();
    let first = levels(&mut ann).await;
    let ids: Vec<&str> = first.levels.iter().map(|l| l.id.as_str()).collect();
    assert_eq!(ids, ["default", "second"]);
    assert_eq!((first.current, first.next, first.change_at), (0, 1, None));
    let _ = levels(&mut bob).await;

    // One of two is no majority: the vote only picks what comes next.
    ann.vote(1).await.unwrap();
    let counted = levels(&mut bob).await;
    assert_eq!(
        (counted.votes.clone(), counted.change_at),
        (vec![0, 1], None)
    );
    bob.vote(1).await.unwrap();
    let decided = until(&mut ann, Duration::from_secs(5), |e| match e {
        SessionEvent::Levels(l) if l.change_at.is_some() => Some(l),
        _ => None,
    })
    .await;
    let at = decided.change_at.unwrap();

    let old_offer = ann.welcome().level;
    let players = [ann.welcome().player_id, bob.welcome().player_id];
    let watcher = eve.welcome().player_id;
    for (who, session) in [("ann", &mut ann), ("bob", &mut bob), ("eve", &mut eve)] {
        let id = session.welcome().player_id;
        let w = level_change(session).await;
        assert_eq!(
            (w.player_id, w.level_id.as_str(), w.server_tick),
            (id, "second", at),
            "{who}"
        );
        assert_ne!(w.level, old_offer, "{who}: another bundle");
        assert_eq!(
            session.welcome().level,
            w.level,
            "{who}: the session's level is the new one"
        );
        // Downloaded by its hash, mid-session.
        let (bundle, fetched) = fetch_level(session, &FetchOptions::default(), |_, _| {})
            .await
            .unwrap_or_else(|e| panic!("{who} downloads the second level: {e}"));
        assert_eq!(bundle.level.name, "second");
        assert!(!fetched.embedded && !fetched.cached, "{who}: {fetched:?}");
        // Its snapshots: of the new level's ticks, players in it again.
        let mut list = None;
        let state = until(session, Duration::from_secs(5), |e| match e {
            SessionEvent::Snapshot(u) => Some(u.state),
            SessionEvent::Levels(l) => {
                list = Some(l);
                None
            }
            _ => None,
        })
        .await;
        // The list after the change, sent right after the LevelChange.
        let after = list.expect("the list after the change");
        assert_eq!(
            (after.current, after.votes.clone()),
            (1, vec![0, 0]),
            "{who}"
        );
        assert_eq!(after.next, 0, "{who}: the rotation wraps");
        assert!(
            state.tick >= at,
            "{who}: tick {} before the change at {at}",
            state.tick
        );
        for p in players {
            assert!(
                state.get(p.0).is_some(),
                "{who}: player {p} in the new level"
            );
        }
        assert!(
            state.get(watcher.0).is_none(),
            "{who}: the spectator has no body"
        );
    }
    for s in [ann, bob, eve] {
        s.close().await;
    }
    server.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn runners_that_finish_the_first_level_are_moved_on_and_finish_the_second() {
    let dir = tempfile::tempdir().unwrap();
    let server = rotating_server(dir.path(), VoteRule::Majority).await;
    let caches = [tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap()];
    let mut bots = Vec::new();
    for (name, cache) in ["ann", "bob"].into_iter().zip(&caches) {
        let session = server.join(name).await;
        let options = BotOptions {
            level_cache: Some(cache.path().to_owned()),
            ..bot_options(name, Duration::from_secs(34))
        };
        bots.push(spawn_bot(session, Runner::new(default_route()), options));
    }
    for bot in bots {
        let (report, _) = bot.await.expect("the bot task did not panic");
        let played: Vec<(&str, u32)> = report
            .levels
            .iter()
            .map(|l| (l.id.as_str(), l.finishes))
            .collect();
        assert!(
            played.len() >= 2 && played[0].0 == "default" && played[1].0 == "second",
            "{}: played {played:?}",
            report.name
        );
        assert!(
            played[0].1 >= 1 && played[1].1 >= 1,
            "{} finished each level: {played:?} ({})",
            report.name,
            report.progress
        );
        assert_eq!(report.mispredictions, 0, "{}: {report}", report.name);
    }
    let m = server.metrics();
    assert!(
        metric(&m, "ledge_level_downloads_completed_total") >= 2.0,
        "each bot downloaded the second level"
    );
    server.stop().await.unwrap();
}
