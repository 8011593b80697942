//! A room's level rotation, sans-IO: which level it plays, which comes
//! next, the players' votes, and the tick at which it moves on.
//!
//! A room with one level never moves. With several, it moves to the next
//! level when
//! - everyone in it has finished (after [`RotationConfig::results_time`],
//!   so the results card shows);
//! - a vote decides ([`VoteRule::Majority`]: more than half of the players
//!   for one level; [`VoteRule::Host`]: the longest-present player, the
//!   lowest id), also after the results time;
//! - or the level's time is up ([`RotationConfig::level_time`]).
//!
//! Without a deciding vote, the next level is the most voted one (ties go
//! to the first after the current one in rotation order), else simply the
//! next in turn. The level clock does not run while the room has no
//! players, so nobody joins into a change long overdue.

use std::collections::BTreeMap;

use ledge_shared::protocol::{LevelChoice, LevelList, PlayerId, VoteRule};

use crate::config::RotationConfig;

/// What a tick decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Step {
    /// The list changed (send it to everyone).
    pub changed: bool,
    /// Move to this level now.
    pub change_to: Option<usize>,
}

/// A room's rotation.
#[derive(Debug, Clone)]
pub struct Rotation {
    choices: Vec<LevelChoice>,
    rule: VoteRule,
    level_ticks: Option<u64>,
    results_ticks: u64,
    current: usize,
    /// The tick the current level started (or the room last had players).
    started: u64,
    votes: BTreeMap<PlayerId, usize>,
    /// A decision already taken: move at this tick (to the level chosen
    /// then, or by votes then).
    decided_at: Option<u64>,
}

impl Rotation {
    /// The rotation through `choices` (at least one), by `config`'s
    /// times at `tick_rate`, playing the first level from `tick`.
    pub fn new(
        choices: Vec<LevelChoice>,
        config: &RotationConfig,
        tick_rate: u32,
        tick: u64,
    ) -> Rotation {
        let ticks = |d: std::time::Duration| (d.as_secs_f64() * f64::from(tick_rate)).ceil() as u64;
        Rotation {
            choices,
            rule: config.vote,
            level_ticks: config.level_time.map(ticks),
            results_ticks: ticks(config.results_time),
            current: 0,
            started: tick,
            votes: BTreeMap::new(),
            decided_at: None,
        }
    }

    /// Whether the room can move at all (more than one level).
    pub fn is_on(&self) -> bool {
        self.choices.len() > 1
    }

    /// The level being played.
    pub fn current(&self) -> usize {
        self.current
    }

    /// Records `player`'s vote for `level` (replacing its earlier one):
    /// `Ok(true)` when the list changed, or why the vote is refused.
    pub fn vote(&mut self, player: PlayerId, level: u32) -> Result<bool, String> {
        if !self.is_on() {
            return Err("this server plays one level: there is nothing to vote for".into());
        }
        if self.rule == VoteRule::Off {
            return Err(
                "votes are off on this server (--vote off): the levels come in turn".into(),
            );
        }
        let n = self.choices.len();
        let Some(level) = usize::try_from(level).ok().filter(|&l| l < n) else {
            return Err(format!("there is no level {}: the list has {n}", level + 1));
        };
        Ok(self.votes.insert(player, level) != Some(level))
    }

    /// `player` left: its vote goes. Whether the list changed.
    pub fn left(&mut self, player: PlayerId) -> bool {
        self.votes.remove(&player).is_some()
    }

    /// Runs the rotation for `tick`, with the room's players by id (the
    /// lowest is the host) and whether each has finished the level.
    pub fn tick(&mut self, tick: u64, players: &[(PlayerId, bool)]) -> Step {
        if !self.is_on() {
            return Step::default();
        }
        if players.is_empty() {
            // Nobody to move: the clock waits, votes and decisions go.
            let changed = self.decided_at.is_some() || !self.votes.is_empty();
            self.started = tick;
            self.votes.clear();
            self.decided_at = None;
            return Step {
                changed,
                change_to: None,
            };
        }
        let before = self.change_at();
        let all_finished = players.iter().all(|&(_, finished)| finished);
        if self.decided_at.is_none() && (all_finished || self.vote_decides(players)) {
            self.decided_at = Some(tick + self.results_ticks);
        }
        if self.change_at().is_some_and(|at| tick >= at) {
            return Step {
                changed: true,
                change_to: Some(self.next(players)),
            };
        }
        Step {
            changed: self.change_at() != before,
            change_to: None,
        }
    }

    /// The room moved to `level` at `tick`: a new level clock, no votes.
    pub fn changed_to(&mut self, level: usize, tick: u64) {
        self.current = level.min(self.choices.len() - 1);
        self.started = tick;
        self.votes.clear();
        self.decided_at = None;
    }

    /// The tick the room moves on at, if known.
    pub fn change_at(&self) -> Option<u64> {
        if !self.is_on() {
            return None;
        }
        let deadline = self.level_ticks.map(|t| self.started + t);
        match (self.decided_at, deadline) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// The list as players see it (`players` as for [`Rotation::tick`]).
    pub fn list(&self, players: &[(PlayerId, bool)]) -> LevelList {
        let mut votes = vec![0u32; self.choices.len()];
        for &level in self.votes.values() {
            votes[level] += 1;
        }
        LevelList {
            levels: self.choices.clone(),
            current: self.current as u32,
            next: self.next(players) as u32,
            votes,
            rule: self.rule,
            change_at: self.change_at(),
        }
    }

    /// Whether the votes alone decide now.
    fn vote_decides(&self, players: &[(PlayerId, bool)]) -> bool {
        match self.rule {
            VoteRule::Off => false,
            VoteRule::Host => players
                .first()
                .is_some_and(|(host, _)| self.votes.contains_key(host)),
            VoteRule::Majority => {
                let in_room = |id: &PlayerId| players.iter().any(|(p, _)| p == id);
                let mut counts = vec![0usize; self.choices.len()];
                for (_, &level) in self.votes.iter().filter(|(id, _)| in_room(id)) {
                    counts[level] += 1;
                }
                counts.iter().any(|&c| 2 * c > players.len())
            }
        }
    }

    /// The level that comes next: the host's choice, else the most voted
    /// (ties: the first after the current one), else the next in turn.
    fn next(&self, players: &[(PlayerId, bool)]) -> usize {
        let n = self.choices.len();
        let in_turn = (self.current + 1) % n;
        match self.rule {
            VoteRule::Off => in_turn,
            VoteRule::Host => players
                .first()
                .and_then(|(host, _)| self.votes.get(host).copied())
                .unwrap_or(in_turn),
            VoteRule::Majority => {
                let mut counts = vec![0usize; n];
                for &level in self.votes.values() {
                    counts[level] += 1;
                }
                let order = (1..=n).map(|k| (self.current + k) % n);
                let best = order.max_by_key(|&l| {
                    (counts[l], std::cmp::Reverse((l + n - self.current - 1) % n))
                });
                best.filter(|&l| counts[l] > 0).unwrap_or(in_turn)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;

    fn rotation(levels: usize, rule: VoteRule, level_secs: Option<u64>) -> Rotation {
        let choices = (0..levels)
            .map(|i| LevelChoice {
                id: format!("l{i}"),
                name: format!("level {i}"),
            })
            .collect();
        let config = RotationConfig {
            level_time: level_secs.map(Duration::from_secs),
            results_time: Duration::from_secs(2),
            vote: rule,
        };
        Rotation::new(choices, &config, 10, 0)
    }

    fn p(ids: &[(u32, bool)]) -> Vec<(PlayerId, bool)> {
        ids.iter().map(|&(i, f)| (PlayerId(i), f)).collect()
    }

    /// Ticks from `from` until a change, or `None` within `limit` ticks.
    fn run(
        r: &mut Rotation,
        from: u64,
        limit: u64,
        players: &[(PlayerId, bool)],
    ) -> Option<(u64, usize)> {
        (from..from + limit).find_map(|t| r.tick(t, players).change_to.map(|l| (t, l)))
    }

    #[test]
    fn one_level_never_moves_and_takes_no_votes() {
        let mut r = rotation(1, VoteRule::Majority, Some(1));
        assert_eq!(run(&mut r, 0, 100, &p(&[(1, true)])), None);
        assert!(r.vote(PlayerId(1), 0).is_err());
        assert_eq!(r.change_at(), None);
    }

    #[test]
    fn everyone_finished_moves_on_after_the_results_time_in_turn() {
        let mut r = rotation(3, VoteRule::Majority, None);
        assert_eq!(run(&mut r, 0, 50, &p(&[(1, true), (2, false)])), None);
        let step = r.tick(50, &p(&[(1, true), (2, true)]));
        assert!(step.changed && step.change_to.is_none());
        assert_eq!(r.change_at(), Some(70));
        assert_eq!(
            run(&mut r, 51, 100, &p(&[(1, true), (2, true)])),
            Some((70, 1))
        );
        r.changed_to(1, 70);
        assert_eq!(r.list(&[]).current, 1);
        assert_eq!(r.list(&[]).next, 2);
        r.changed_to(2, 80);
        assert_eq!(r.list(&[]).next, 0, "the rotation wraps");
    }

    #[test]
    fn the_level_time_moves_on_unfinished_but_not_an_empty_room() {
        let mut r = rotation(2, VoteRule::Majority, Some(3));
        assert_eq!(r.change_at(), Some(30));
        // Empty from tick 0 to 99: the clock waits.
        assert_eq!(run(&mut r, 0, 100, &[]), None);
        assert_eq!(r.change_at(), Some(129));
        assert_eq!(run(&mut r, 100, 100, &p(&[(1, false)])), Some((129, 1)));
    }

    #[test]
    fn a_majority_decides_and_a_minority_only_picks_the_next() {
        let mut r = rotation(4, VoteRule::Majority, None);
        let room = p(&[(1, false), (2, false), (3, false)]);
        assert_eq!(r.vote(PlayerId(1), 3), Ok(true));
        assert_eq!(r.vote(PlayerId(1), 3), Ok(false), "the same vote again");
        assert_eq!(
            run(&mut r, 0, 100, &room),
            None,
            "one of three is no majority"
        );
        assert_eq!(r.list(&room).next, 3, "but it picks the next level");
        assert_eq!(r.list(&room).votes, vec![0, 0, 0, 1]);
        r.vote(PlayerId(2), 3).unwrap();
        assert_eq!(run(&mut r, 100, 100, &room), Some((120, 3)));
        assert!(r.vote(PlayerId(1), 4).is_err(), "no such level");
    }

    #[test]
    fn ties_go_to_the_first_after_the_current_level_and_leavers_lose_their_vote() {
        let mut r = rotation(4, VoteRule::Majority, None);
        r.changed_to(2, 0);
        let room = p(&[(1, false), (2, false), (3, false), (4, false)]);
        r.vote(PlayerId(1), 1).unwrap();
        r.vote(PlayerId(2), 0).unwrap();
        assert_eq!(r.list(&room).next, 0, "0 comes before 1 after level 2");
        assert!(r.left(PlayerId(2)));
        assert_eq!(r.list(&room).next, 1);
    }

    #[test]
    fn the_host_decides_alone() {
        let mut r = rotation(3, VoteRule::Host, None);
        let room = p(&[(4, false), (9, false)]);
        r.vote(PlayerId(9), 2).unwrap();
        assert_eq!(
            run(&mut r, 0, 50, &room),
            None,
            "a guest's vote does not decide"
        );
        assert_eq!(r.list(&room).next, 1);
        r.vote(PlayerId(4), 0).unwrap();
        assert_eq!(run(&mut r, 50, 50, &room), Some((70, 0)));
    }

    #[test]
    fn votes_off_are_refused_with_the_flag_to_change() {
        let mut r = rotation(3, VoteRule::Off, None);
        let err = r.vote(PlayerId(1), 2).unwrap_err();
        assert!(err.contains("--vote"), "{err}");
    }
}
