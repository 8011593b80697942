//! Eight runner bots race through the default level offline, all started
//! together, each playing on its own prediction ([`Predictor`]) of a shared
//! authoritative game that reaches it late, as over a network: inputs reach
//! the server a few ticks later and a third of them too late (the server
//! repeats the previous buttons, as on a loaded machine), snapshots reach
//! the clients a few ticks later. Every runner must reach the goal, and the
//! race is deterministic.

use std::collections::{BTreeMap, VecDeque};

use ledge_client::bot::{Brain, Runner, SplitMix64};
use ledge_client::game::predict::Predictor;
use ledge_levels::{default_level, default_route};
use ledge_shared::game::{Game, GameEvent};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{PlayerId, StateSnapshot};

/// Runners in the race.
const RUNNERS: u32 = 8;
/// How many ticks ahead of the server the clients run (their inputs reach
/// the server that late): this plus 0 to 2, by client.
const LEAD: u64 = 3;
/// Runner `k` joins `k * JOIN_EVERY` ticks after the first (connecting
/// together, a few milliseconds apart).
const JOIN_EVERY: u64 = 3;
/// Ticks the server runs before the first runner joins, by race: the
/// walkers are elsewhere when the runners get there.
const WARMUPS: [u64; 4] = [0, 128, 256, 384];
/// One input in this many reaches the server too late (a busy machine):
/// the server repeats the player's previous buttons instead, and the
/// runner's plan goes wrong.
const LATE_ONE_IN: u64 = 3;
/// How many ticks a snapshot takes to reach the clients.
const DELAY: u64 = 2;
/// Ticks between two snapshots (the server's default: 60 Hz ticks, 30 Hz
/// snapshots).
const SNAPSHOT_EVERY: u64 = 2;
/// Longest race, ticks (60 s).
const LIMIT: u64 = 60 * 60;

/// One runner bot and its prediction.
struct Client {
    me: PlayerId,
    lead: u64,
    joined: bool,
    runner: Runner,
    predictor: Predictor,
}

/// Races `RUNNERS` runners that all start at once after the server ran
/// `warmup` ticks; returns the tick each player won at and the runners.
fn race(warmup: u64) -> (BTreeMap<PlayerId, u64>, Vec<Client>) {
    let level = default_level();
    let mut server = Game::from_level(&level).expect("the default level loads");
    for _ in 0..warmup {
        server.step(&[]);
    }
    let mut clients = Vec::new();
    for k in 1..=RUNNERS {
        let me = PlayerId(k);
        clients.push(Client {
            me,
            lead: LEAD + u64::from(k % 3),
            joined: false,
            runner: Runner::new(default_route()),
            predictor: Predictor::new(&level, me, 0).expect("predictor"),
        });
    }
    // Inputs by tick, as the server receives them; snapshots in flight.
    let mut inputs: BTreeMap<u64, Vec<(PlayerId, Buttons)>> = BTreeMap::new();
    let mut last: BTreeMap<PlayerId, Buttons> = BTreeMap::new();
    let mut in_flight: VecDeque<(u64, StateSnapshot)> = VecDeque::new();
    let mut won = BTreeMap::new();
    let mut late = SplitMix64(warmup);
    while server.tick() < warmup + LIMIT && won.len() < clients.len() {
        let now = server.tick();
        for (k, c) in clients.iter_mut().enumerate() {
            if !c.joined && now >= warmup + k as u64 * JOIN_EVERY {
                server.add_player(c.me).expect("room for the runners");
                c.predictor = Predictor::new(&level, c.me, now + c.lead).expect("predictor");
                c.joined = true;
            }
        }
        while in_flight.front().is_some_and(|(at, _)| *at <= now) {
            let (_, snapshot) = in_flight.pop_front().expect("a snapshot");
            for c in &mut clients {
                if let Some(r) = c.predictor.reconcile(&snapshot) {
                    if r.mispredicted || r.correction_px > 0.0 {
                        c.runner.on_correction();
                    }
                }
            }
        }
        for c in clients.iter_mut().filter(|c| c.joined) {
            let b = if c.predictor.synced() {
                c.runner.buttons(c.predictor.game(), c.me)
            } else {
                Buttons::NONE
            };
            let tick = c.predictor.step(b);
            if late.below(LATE_ONE_IN) != 0 {
                inputs.entry(tick).or_default().push((c.me, b));
            }
        }
        // A missing input repeats the player's previous one, as the server
        // does.
        let mut applied = inputs.remove(&now).unwrap_or_default();
        for c in clients.iter().filter(|c| c.joined) {
            if !applied.iter().any(|(p, _)| *p == c.me) {
                applied.push((c.me, last.get(&c.me).copied().unwrap_or(Buttons::NONE)));
            }
        }
        applied.sort_by_key(|(p, _)| *p);
        for &(p, b) in &applied {
            last.insert(p, b);
        }
        for e in server.step(&applied) {
            if let GameEvent::Finished { player: p, .. } = e {
                won.entry(*p).or_insert(now);
            }
        }
        if server.tick() % SNAPSHOT_EVERY == 0 {
            in_flight.push_back((server.tick() + DELAY, server.snapshot()));
        }
    }
    (won, clients)
}

#[test]
fn eight_runners_started_together_on_lagged_predictions_all_reach_the_goal() {
    let mut failed = Vec::new();
    for warmup in WARMUPS {
        let (won, clients) = race(warmup);
        for c in &clients {
            eprintln!(
                "warmup {warmup}: {}: won at {:?}, {} [{:?}]",
                c.me,
                won.get(&c.me),
                Brain::progress(&c.runner),
                c.predictor.stats()
            );
        }
        eprintln!("warmup {warmup}: {} of {RUNNERS} won", won.len());
        if won.len() != clients.len() {
            failed.push((warmup, won.len()));
        }
    }
    assert!(
        failed.is_empty(),
        "(warmup, winners) of the races lost: {failed:?}"
    );
}

#[test]
fn the_race_is_deterministic() {
    let (a, _) = race(WARMUPS[1]);
    let (b, _) = race(WARMUPS[1]);
    assert_eq!(a, b);
}
