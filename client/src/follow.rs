//! Whom a watching camera follows ([`Follow`]) among the players in a
//! game, and Tab's cycling through them: shared by the replay viewer
//! ([`crate::replay::ReplayViewer`]) and a spectator's window.

use ledge_shared::protocol::PlayerId;

/// Whom the camera follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Follow {
    /// This player (while in the game; else the first player who is).
    Player(PlayerId),
    /// Nobody: the front end moves the camera itself.
    Free,
}

impl Follow {
    /// The player followed among `players` (ascending ids): the one asked
    /// for while it is there, else the first; `None` with a free camera or
    /// nobody there.
    pub fn resolve(self, players: &[PlayerId]) -> Option<PlayerId> {
        let Follow::Player(id) = self else {
            return None;
        };
        if players.contains(&id) {
            Some(id)
        } else {
            players.first().copied()
        }
    }

    /// Follows the next of `players` (ascending ids) after the one
    /// followed now (`forward`; else the one before), wrapping around; a
    /// free camera goes to the first (or last). Unchanged with nobody
    /// there.
    pub fn next(self, players: &[PlayerId], forward: bool) -> Follow {
        let next = match self.resolve(players) {
            Some(now) if forward => players.iter().find(|&&p| p > now).or(players.first()),
            Some(now) => players.iter().rev().find(|&&p| p < now).or(players.last()),
            None if forward => players.first(),
            None => players.last(),
        };
        next.map_or(self, |&id| Follow::Player(id))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tab_cycles_through_the_players_and_a_gone_one_falls_back_to_the_first() {
        let players = [PlayerId(2), PlayerId(5), PlayerId(9)];
        let f = Follow::Player(PlayerId(5));
        assert_eq!(f.resolve(&players), Some(PlayerId(5)));
        assert_eq!(f.next(&players, true), Follow::Player(PlayerId(9)));
        assert_eq!(f.next(&players, false), Follow::Player(PlayerId(2)));
        let last = Follow::Player(PlayerId(9));
        assert_eq!(last.next(&players, true), Follow::Player(PlayerId(2)));
        let gone = Follow::Player(PlayerId(7));
        assert_eq!(gone.resolve(&players), Some(PlayerId(2)));
        assert_eq!(Follow::Free.resolve(&players), None);
        assert_eq!(
            Follow::Free.next(&players, true),
            Follow::Player(PlayerId(2))
        );
        assert_eq!(
            Follow::Free.next(&players, false),
            Follow::Player(PlayerId(9))
        );
        assert_eq!(Follow::Free.next(&[], true), Follow::Free);
        assert_eq!(gone.resolve(&[]), None);
    }
}
