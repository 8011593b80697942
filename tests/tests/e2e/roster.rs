//! The room's roster over real QUIC: each client learns who is in the
//! room by name (the newcomer gets the list after its welcome, the others
//! one join at a time), and sees a player leave; a GUI front end
//! ([`OnlineGame`]) draws remote players with their names.

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use ledge_client::{OnlineGame, OnlineRequest, Session, SessionEvent, Trust};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::PlayerId;
use ledge_tests::TestServer;

/// How long a roster change may take to reach every client.
const WITHIN: Duration = Duration::from_secs(5);

/// A client and the roster it learnt from its events.
struct Client {
    session: Session,
    who: &'static str,
    /// Folded from `PlayerJoined` / `PlayerLeft` events.
    known: BTreeMap<PlayerId, String>,
}

impl Client {
    async fn join(server: &TestServer, who: &'static str) -> Client {
        Client {
            session: server.join(who).await,
            who,
            known: BTreeMap::new(),
        }
    }

    fn id(&self) -> PlayerId {
        self.session.welcome().player_id
    }

    /// Receives events until the roster they tell is `want`; checks the
    /// session's own roster agrees and returns the roster events taken.
    async fn until_roster(&mut self, want: &BTreeMap<PlayerId, String>) -> Vec<SessionEvent> {
        let mut seen = Vec::new();
        let reached = tokio::time::timeout(WITHIN, async {
            while &self.known != want {
                let event = self.session.recv().await.expect("session stays up");
                match &event {
                    SessionEvent::PlayerJoined { id, name } => {
                        self.known.insert(*id, name.clone());
                    }
                    SessionEvent::PlayerLeft { id, .. } => {
                        self.known.remove(id);
                    }
                    _ => continue,
                }
                seen.push(event);
            }
        })
        .await;
        assert!(
            reached.is_ok(),
            "{} learnt {:?} (events {seen:?}), expected {want:?}",
            self.who,
            self.known
        );
        assert_eq!(self.session.players(), want, "{}", self.who);
        seen
    }
}

fn roster(players: &[&Client]) -> BTreeMap<PlayerId, String> {
    players
        .iter()
        .map(|c| (c.id(), c.who.to_string()))
        .collect()
}

#[tokio::test]
async fn every_client_sees_the_others_names_and_who_left() {
    let server = TestServer::start().await;
    let mut ada = Client::join(&server, "ada").await;
    let events = ada.until_roster(&roster(&[&ada])).await;
    assert_eq!(
        events,
        [SessionEvent::PlayerJoined {
            id: ada.id(),
            name: "ada".into()
        }],
        "the roster after the welcome lists ourselves"
    );

    let mut bo = Client::join(&server, "bo").await;
    let two = roster(&[&ada, &bo]);
    let events = bo.until_roster(&two).await;
    assert_eq!(events.len(), 2, "the roster lists both: {events:?}");
    let events = ada.until_roster(&two).await;
    assert_eq!(
        events,
        [SessionEvent::PlayerJoined {
            id: bo.id(),
            name: "bo".into()
        }]
    );

    // A name may be any valid UTF-8 of up to 32 bytes.
    let mut cy = Client::join(&server, "Cy 漢字 é").await;
    let three = roster(&[&ada, &bo, &cy]);
    for client in [&mut ada, &mut bo, &mut cy] {
        client.until_roster(&three).await;
    }
    assert_eq!(ada.session.player_name(cy.id()), Some("Cy 漢字 é"));

    // Bo leaves: the others see him gone, by id and name.
    let bo_id = bo.id();
    bo.session.close().await;
    let left = roster(&[&ada, &cy]);
    for client in [&mut ada, &mut cy] {
        let events = client.until_roster(&left).await;
        assert_eq!(
            events,
            [SessionEvent::PlayerLeft {
                id: bo_id,
                name: Some("bo".into())
            }],
            "{}",
            client.who
        );
        assert_eq!(client.session.player_name(bo_id), None);
    }

    // A player who joins later gets the current list, without bo.
    let mut dee = Client::join(&server, "dee").await;
    let now = roster(&[&ada, &cy, &dee]);
    dee.until_roster(&now).await;
    for client in [&mut ada, &mut cy] {
        client.until_roster(&now).await;
    }

    // A client that drops off without leaving is gone too, once the server
    // notices (here at once: its connection is closed).
    let dee_id = dee.id();
    dee.session.connection().close(0u32.into(), b"crash");
    for client in [&mut ada, &mut cy] {
        let events = client.until_roster(&left).await;
        assert_eq!(
            events,
            [SessionEvent::PlayerLeft {
                id: dee_id,
                name: Some("dee".into())
            }]
        );
    }

    ada.session.close().await;
    cy.session.close().await;
    server.stop().await.unwrap();
}

/// Runs `online` (frames of 10 ms) until `done` holds for its remote
/// players' `(id, name)`s, or panics after [`WITHIN`].
fn play_until(
    online: &mut OnlineGame,
    what: &str,
    done: impl Fn(&[(PlayerId, Option<String>)]) -> bool,
) {
    let deadline = Instant::now() + WITHIN;
    loop {
        online.update(Instant::now(), Buttons::NONE);
        let remotes: Vec<(PlayerId, Option<String>)> = online
            .view()
            .map(|v| v.remotes.iter().map(|p| (p.id, p.name.clone())).collect())
            .unwrap_or_default();
        if done(&remotes) {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "{what}: remotes drawn {remotes:?}, status {}",
            online.status()
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn a_gui_front_end_draws_remote_players_with_their_names() {
    let runtime = tokio::runtime::Runtime::new().unwrap();
    let server = runtime.block_on(TestServer::start());
    // Bo is already in the room (the roster brings his name) ...
    let bo = runtime.block_on(server.join("bo"));
    let bo_id = bo.welcome().player_id;
    let request = OnlineRequest::new(
        &server.addr.to_string(),
        Trust::Pinned(server.fingerprint),
        "ada",
    );
    let mut online = OnlineGame::connect(request).unwrap();
    play_until(&mut online, "bo drawn with his name", |r| {
        r.contains(&(bo_id, Some("bo".into())))
    });
    let me = online.game().unwrap().me();
    let names = online.game().unwrap().player_names().clone();
    assert_eq!(
        names,
        BTreeMap::from([(bo_id, "bo".to_string()), (me, "ada".to_string())])
    );
    assert_eq!(online.net().players(), names);
    assert_eq!(
        online.view().unwrap().local.unwrap().name.as_deref(),
        Some("ada")
    );

    // ... Cy joins later (a PlayerJoined brings hers).
    let cy = runtime.block_on(server.join("cy"));
    let cy_id = cy.welcome().player_id;
    play_until(&mut online, "cy drawn with her name", |r| {
        r.contains(&(cy_id, Some("cy".into())))
    });

    // Bo leaves: no longer drawn, his name forgotten.
    runtime.block_on(bo.close());
    play_until(&mut online, "bo gone", |r| {
        r.iter().all(|(id, _)| *id != bo_id) && r.iter().any(|(id, _)| *id == cy_id)
    });
    assert!(!online.game().unwrap().player_names().contains_key(&bo_id));
    drop(online);
    runtime.block_on(async {
        cy.close().await;
        server.stop().await.unwrap();
    });
}
