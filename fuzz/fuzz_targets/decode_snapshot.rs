//! Snapshot datagrams: the bincode envelope, then the delta inside it
//! against a baseline with the tick it asks for (entities derived from the
//! input). Never panics; whatever decodes re-encodes exactly.
#![no_main]

use ledge_shared::protocol::snapshot::{encode_delta, StateSnapshot};
use ledge_shared::protocol::{EntityState, Message, Snapshot};
use libfuzzer_sys::fuzz_target;

/// A small valid baseline: ids and positions from the input's bytes.
fn baseline(tick: u64, data: &[u8]) -> StateSnapshot {
    let mut entities: Vec<EntityState> = data
        .iter()
        .take(32)
        .map(|&b| EntityState {
            kind: b & 3,
            flags: (b >> 2) as u32 & 1,
            ..EntityState::zero(b as u32)
        })
        .collect();
    entities.sort_unstable_by_key(|e| e.id);
    entities.dedup_by_key(|e| e.id);
    StateSnapshot { tick, entities }
}

fuzz_target!(|data: &[u8]| {
    let Ok(snapshot) = Snapshot::decode(data) else {
        return;
    };
    let again = snapshot.encode().expect("a decoded snapshot re-encodes");
    assert_eq!(
        Snapshot::decode(&again).expect("and decodes again"),
        snapshot
    );
    let base = snapshot.baseline_tick.map(|t| baseline(t, data));
    if let Ok(state) = snapshot.decode_state(base.as_ref()) {
        let mut bytes = Vec::new();
        encode_delta(base.as_ref(), &state, &mut bytes).expect("a decoded state re-encodes");
        assert_eq!(bytes, snapshot.delta, "the delta format is canonical");
    }
});
