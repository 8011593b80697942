//! A room's match, recorded while anyone is in it: it starts at the first
//! join into an empty room, ends (and is saved) when the room empties or
//! the recording is full, and hands out each finished run cut from it.
//! Sans IO: the room turns what it returns into saves.

use ledge_shared::game::Game;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::PlayerId;
use ledge_shared::replay::{Replay, ReplayHeader, ReplayRecorder};

use super::replay_id;

/// A replay to save, and its id.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ToSave {
    /// Its id ([`replay_id`]).
    pub id: String,
    /// The replay.
    pub replay: Replay,
}

/// See the module documentation.
#[derive(Debug)]
pub struct MatchRecording {
    /// Header of every replay of the room (its kind and names are set per
    /// replay).
    template: ReplayHeader,
    /// This server's instance: match replays' keys start with it.
    instance: String,
    recorder: Option<ReplayRecorder>,
}

impl MatchRecording {
    /// Recording for the room described by `template`, on server
    /// `instance`.
    pub fn new(template: ReplayHeader, instance: String) -> MatchRecording {
        MatchRecording {
            template,
            instance,
            recorder: None,
        }
    }

    /// Whether a match is being recorded.
    pub fn recording(&self) -> bool {
        self.recorder.is_some()
    }

    /// A player is about to be added to `game`: starts recording if the
    /// room was empty (`present`: the players already in it, by id and
    /// name, for a recording started after a split).
    pub fn before_join<'a>(
        &mut self,
        game: &Game,
        present: impl Iterator<Item = (PlayerId, &'a str)>,
    ) {
        if self.recorder.is_none() {
            let mut r = ReplayRecorder::new(self.template.clone(), game);
            for (id, name) in present {
                r.name(id, name);
            }
            self.recorder = Some(r);
        }
    }

    /// Player `id`, called `name`, was added to the game.
    pub fn joined(&mut self, id: PlayerId, name: &str) {
        if let Some(r) = &mut self.recorder {
            r.join(id, name);
        }
    }

    /// Player `id` was removed from `game`; `empty`: nobody is left, so the
    /// match ends and is returned for saving.
    pub fn left(&mut self, game: &Game, id: PlayerId, empty: bool) -> Option<ToSave> {
        self.recorder.as_mut()?.leave(id);
        if empty {
            self.end(game)
        } else {
            None
        }
    }

    /// `game` was stepped with `inputs`. A full recording is returned for
    /// saving and a new one starts, naming the players `present`.
    pub fn stepped<'a>(
        &mut self,
        game: &Game,
        inputs: &[(PlayerId, Buttons)],
        present: impl Iterator<Item = (PlayerId, &'a str)>,
    ) -> Option<ToSave> {
        let r = self.recorder.as_mut()?;
        r.step(game, inputs);
        if !r.full() {
            return None;
        }
        let saved = self.end(game);
        self.before_join(game, present);
        saved
    }

    /// Ends the match: its replay, if any tick was recorded.
    pub fn end(&mut self, game: &Game) -> Option<ToSave> {
        let r = self.recorder.take()?;
        if r.ticks() == 0 {
            return None;
        }
        let key = format!(
            "{}/{}/match/{}",
            self.instance,
            self.template.room,
            r.start_tick()
        );
        Some(ToSave {
            id: replay_id(&key),
            replay: r.replay(game),
        })
    }

    /// The run `player` just finished (its records key `key`, `ticks`
    /// long, place `place`), cut from the match; `None` if it started
    /// before the recording did.
    pub fn run(
        &self,
        game: &Game,
        key: &str,
        player: PlayerId,
        ticks: u64,
        place: u32,
    ) -> Option<ToSave> {
        let r = self.recorder.as_ref()?;
        let start = game.tick().saturating_sub(ticks);
        let replay = r.run(game, player, start, ticks, place)?;
        Some(ToSave {
            id: replay_id(key),
            replay,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_levels::default_level;
    use ledge_shared::game::GameConfig;
    use ledge_shared::protocol::LevelOffer;
    use ledge_shared::replay::Playback;

    fn template() -> ReplayHeader {
        ReplayHeader::for_match(
            "room-1",
            ("default", "Default", LevelOffer::default()),
            GameConfig::default(),
            60,
        )
    }

    #[test]
    fn a_match_runs_from_the_first_join_until_the_room_empties() {
        let mut game = Game::from_level(&default_level()).unwrap();
        let mut rec = MatchRecording::new(template(), "inst".into());
        // An empty room ticks unrecorded.
        for _ in 0..100 {
            game.step(&[]);
            assert!(rec.stepped(&game, &[], std::iter::empty()).is_none());
        }
        assert!(!rec.recording());
        let a = PlayerId(1);
        rec.before_join(&game, std::iter::empty());
        game.add_player(a).unwrap();
        rec.joined(a, "alice");
        let right = [(a, Buttons(Buttons::RIGHT))];
        for _ in 0..200 {
            game.step(&right);
            rec.stepped(&game, &right, std::iter::empty());
        }
        assert!(game.remove_player(a));
        let saved = rec.left(&game, a, true).expect("the match, saved");
        assert!(!rec.recording());
        assert_eq!(saved.replay.start_tick(), 100);
        assert_eq!(saved.replay.ticks(), 200);
        assert_eq!(saved.replay.name_of(a), Some("alice"));
        let mut playing = Playback::new(&default_level(), saved.replay).unwrap();
        playing.play_to_end().unwrap();
        assert_eq!(playing.game().state_hash(), game.state_hash());
    }
}
