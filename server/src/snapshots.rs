//! A room's snapshots: the history of what it captured (the baselines its
//! clients acknowledge) and per-client encoding against each client's ack.
//!
//! Pure (no I/O): the room task and the snapshot benchmark use the same
//! code. Clients that acknowledged the same snapshot share one encoded
//! delta: encoding costs one delta per distinct baseline, not per client.

use ledge_shared::protocol::{
    encode_delta, is_replicated, EntityState, ProtocolError, Snapshot, SnapshotHistory,
    StateSnapshot,
};

/// Default number of snapshots kept as baselines (about 2 s at 30 Hz).
pub const DEFAULT_HISTORY: usize = 64;

/// The snapshots of one room.
#[derive(Debug)]
pub struct RoomSnapshots {
    history: SnapshotHistory,
    /// Deltas of the newest snapshot already encoded, by baseline tick.
    cache: Vec<(Option<u64>, Vec<u8>)>,
}

impl RoomSnapshots {
    /// Keeps the newest `history` snapshots as baselines.
    pub fn new(history: usize) -> RoomSnapshots {
        RoomSnapshots {
            history: SnapshotHistory::new(history),
            cache: Vec::new(),
        }
    }

    /// Captures the replicated entities of `tick` (leaving out those flagged
    /// [`EntityState::CLIENT_SIMULATED`]) as the newest snapshot.
    pub fn capture(
        &mut self,
        tick: u64,
        entities: impl IntoIterator<Item = EntityState>,
    ) -> Result<&StateSnapshot, ProtocolError> {
        let state = StateSnapshot::capture(tick, entities, is_replicated)?;
        if !self.history.insert(state) {
            return Err(ProtocolError::InvalidValue {
                what: "snapshot",
                detail: "tick not newer than the previous snapshot",
            });
        }
        self.cache.clear();
        Ok(self.history.latest().expect("just inserted"))
    }

    /// The newest snapshot.
    pub fn latest(&self) -> Option<&StateSnapshot> {
        self.history.latest()
    }

    /// Whether nothing but time changed from the snapshot of `tick` to the
    /// newest ([`StateSnapshot::extrapolates_to`]; false when that one is
    /// no longer kept, or none was taken): a client holding it would learn
    /// nothing from the newest.
    pub fn unchanged_since(&self, tick: u64) -> bool {
        match (self.history.latest(), self.history.get(tick)) {
            (Some(now), Some(then)) => then.extrapolates_to(now),
            _ => false,
        }
    }

    /// The newest snapshot encoded for a client that acknowledged `ack`:
    /// a delta against it when it is still in the history (and not newer
    /// than the snapshot), else a full snapshot. `previous` is the tick of
    /// the last snapshot sent to that client ([`Snapshot::since_previous`]).
    pub fn encode_for(
        &mut self,
        ack: Option<u64>,
        previous: Option<u64>,
        last_input_tick: Option<u64>,
        input_timing: i16,
    ) -> Result<Snapshot, ProtocolError> {
        let current = self.history.latest().ok_or(ProtocolError::InvalidValue {
            what: "snapshot",
            detail: "nothing captured yet",
        })?;
        let baseline = ack
            .filter(|&a| a <= current.tick)
            .and_then(|a| self.history.get(a));
        let baseline_tick = baseline.map(|b| b.tick);
        let delta = match self.cache.iter().find(|(t, _)| *t == baseline_tick) {
            Some((_, delta)) => delta.clone(),
            None => {
                let mut delta = Vec::new();
                encode_delta(baseline, current, &mut delta)?;
                self.cache.push((baseline_tick, delta.clone()));
                delta
            }
        };
        Ok(Snapshot {
            tick: current.tick,
            baseline_tick,
            last_input_tick,
            input_timing,
            since_previous: previous
                .filter(|&p| p < current.tick)
                .map_or(0, |p| u32::try_from(current.tick - p).unwrap_or(u32::MAX)),
            delta,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::IVec2;

    fn entities(tick: u64) -> Vec<EntityState> {
        (0..10u32)
            .map(|id| EntityState {
                pos: IVec2::new(id as i32 * 1000 + tick as i32 * (id as i32 % 3), 0),
                flags: if id == 9 {
                    EntityState::CLIENT_SIMULATED
                } else {
                    0
                },
                ..EntityState::zero(id)
            })
            .collect()
    }

    #[test]
    fn deltas_against_acks_and_full_without() {
        let mut s = RoomSnapshots::new(4);
        s.capture(2, entities(2)).unwrap();
        let full = s.encode_for(None, None, None, 0).unwrap();
        assert_eq!(full.baseline_tick, None);
        let state = full.decode_state(None).unwrap();
        assert_eq!(state.entities.len(), 9, "client-simulated entity left out");

        s.capture(4, entities(4)).unwrap();
        let delta = s.encode_for(Some(2), Some(2), Some(3), -1).unwrap();
        assert_eq!(delta.baseline_tick, Some(2));
        assert_eq!((delta.last_input_tick, delta.input_timing), (Some(3), -1));
        assert_eq!((delta.since_previous, delta.previous_tick()), (2, Some(2)));
        assert_eq!(
            delta.decode_state(Some(&state)).unwrap(),
            *s.latest().unwrap()
        );
        assert!(delta.delta.len() < full.delta.len());
        // A shared baseline is encoded once, the envelope is per client.
        let again = s.encode_for(Some(2), None, None, 5).unwrap();
        assert_eq!(again.delta, delta.delta);

        // Unknown or future acks: full.
        assert_eq!(
            s.encode_for(Some(3), None, None, 0).unwrap().baseline_tick,
            None
        );
        assert_eq!(
            s.encode_for(Some(99), None, None, 0).unwrap().baseline_tick,
            None
        );
        // Acks older than the history: full.
        for t in [6, 8, 10, 12] {
            s.capture(t, entities(t)).unwrap();
        }
        assert_eq!(
            s.encode_for(Some(2), None, None, 0).unwrap().baseline_tick,
            None
        );
        assert_eq!(
            s.encode_for(Some(6), None, None, 0).unwrap().baseline_tick,
            Some(6)
        );
        assert!(s.capture(12, entities(12)).is_err(), "same tick twice");
    }

    #[test]
    fn unchanged_compares_the_entities_of_a_kept_snapshot() {
        let mut s = RoomSnapshots::new(3);
        assert!(!s.unchanged_since(0), "nothing captured");
        s.capture(1, entities(0)).unwrap();
        s.capture(2, entities(0)).unwrap();
        assert!(s.unchanged_since(1));
        assert!(s.unchanged_since(2), "itself");
        s.capture(3, entities(3)).unwrap();
        assert!(!s.unchanged_since(2), "entities moved");
        s.capture(4, entities(3)).unwrap();
        assert!(s.unchanged_since(3));
        let mut runner = entities(0);
        runner[1].vel.x = 5;
        s.capture(5, runner.clone()).unwrap();
        runner[1].pos.x += 10;
        s.capture(7, runner).unwrap();
        assert!(s.unchanged_since(5), "moved on at its velocity");
        assert!(!s.unchanged_since(1), "no longer kept");
        assert!(!s.unchanged_since(9), "never taken");
    }
}
