//! Level rotation and votes on the wire: the levels a room plays in turn
//! and how the next is chosen ([`LevelList`], sent as
//! [`super::ServerControl::Levels`]), a player's vote
//! ([`super::ClientControl::Vote`]); the level change itself is a new
//! [`super::Welcome`] ([`super::ServerControl::LevelChange`]).

use serde::{Deserialize, Serialize};

use super::bounded;

/// Most levels a server rotates through (and one [`LevelList`] names).
/// A full list is under 9 KiB (checked at compile time, in `control`).
pub const MAX_LEVELS: usize = 64;

/// One level of the rotation, as players choose it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct LevelChoice {
    /// The level's id (as in [`super::Welcome::level_id`]).
    pub id: String,
    /// Its name for people (1..=[`super::MAX_ID_LEN`] bytes, no control
    /// characters; the id when the level has no usable name).
    pub name: String,
}

/// How a room's players choose the next level.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum VoteRule {
    /// No votes: the levels come in turn.
    Off,
    /// More than half of the room's players voting for one level moves
    /// the room there; otherwise the most voted level is next.
    #[default]
    Majority,
    /// The host (the room's longest-present player) decides alone.
    Host,
}

impl VoteRule {
    /// The rule's name, as `--vote` takes it.
    pub fn name(self) -> &'static str {
        match self {
            VoteRule::Off => "off",
            VoteRule::Majority => "majority",
            VoteRule::Host => "host",
        }
    }
}

/// The levels a room plays, where it is, the votes and when it moves on.
/// Sent after the roster on joining and whenever any of it changes.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct LevelList {
    /// The rotation, in order: at most [`MAX_LEVELS`].
    #[serde(deserialize_with = "levels_list")]
    pub levels: Vec<LevelChoice>,
    /// The level being played (an index into `levels`).
    pub current: u32,
    /// The level that comes next unless a vote decides otherwise.
    pub next: u32,
    /// Votes for each level (as long as `levels`).
    #[serde(deserialize_with = "votes_list")]
    pub votes: Vec<u32>,
    /// How votes count.
    pub rule: VoteRule,
    /// The room tick at which it moves to `next` (everyone finished, or
    /// the level's time is up); `None`: not yet decided.
    pub change_at: Option<u64>,
}

fn levels_list<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<LevelChoice>, D::Error> {
    bounded::seq(d, MAX_LEVELS, "levels")
}

fn votes_list<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<u32>, D::Error> {
    bounded::seq(d, MAX_LEVELS, "vote counts")
}

#[cfg(test)]
mod tests {
    use super::super::{ClientControl, Message, ServerControl, MAX_ID_LEN, MAX_ROSTER};
    use super::*;

    fn list(n: usize) -> LevelList {
        LevelList {
            levels: (0..n)
                .map(|i| LevelChoice {
                    id: format!("{i:0>64}"),
                    name: "n".repeat(MAX_ID_LEN),
                })
                .collect(),
            current: 0,
            next: (n - 1) as u32,
            votes: vec![MAX_ROSTER as u32; n],
            rule: VoteRule::Host,
            change_at: Some(u64::MAX),
        }
    }

    #[test]
    fn the_largest_list_round_trips_and_one_more_level_is_refused() {
        let most = ServerControl::Levels(list(MAX_LEVELS));
        assert_eq!(
            ServerControl::decode(&most.encode().unwrap()).unwrap(),
            most
        );
        let ServerControl::Levels(mut over) = most.clone() else {
            unreachable!()
        };
        over.levels.push(over.levels[0].clone());
        over.votes.push(0);
        assert!(ServerControl::Levels(over.clone()).encode().is_err());
        // A peer that skips validation: the decoder stops at the bound.
        let bytes =
            bincode::serde::encode_to_vec(ServerControl::Levels(over), bincode::config::standard())
                .unwrap();
        assert!(ServerControl::decode(&bytes).is_err());
    }

    #[test]
    fn a_list_that_does_not_add_up_is_refused() {
        let cases: [fn(&mut LevelList); 6] = [
            |l| l.levels.clear(),
            |l| l.votes.pop().map(drop).unwrap_or(()),
            |l| l.current = 2,
            |l| l.next = 9,
            |l| l.levels[1].name = "a\u{202e}b".into(),
            |l| l.votes[0] = MAX_ROSTER as u32 + 1,
        ];
        for (i, spoil) in cases.iter().enumerate() {
            let mut l = list(2);
            spoil(&mut l);
            assert!(ServerControl::Levels(l).encode().is_err(), "case {i}");
        }
    }

    #[test]
    fn a_vote_and_a_level_change_round_trip() {
        let vote = ClientControl::Vote { level: 3 };
        assert_eq!(
            ClientControl::decode(&vote.encode().unwrap()).unwrap(),
            vote
        );
        assert_eq!(VoteRule::default().name(), "majority");
    }
}
