//! The hand-written delta format against a fuzzer-chosen baseline: the first
//! byte says how many entities the baseline has, the next bytes give their
//! ids and fields, the rest is the delta. Never panics; whatever decodes
//! re-encodes to exactly the same bytes (the format is canonical).
#![no_main]

use ledge_shared::protocol::snapshot::{decode_delta, encode_delta, peek_delta, StateSnapshot};
use ledge_shared::protocol::EntityState;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&n, rest)) = data.split_first() else {
        return;
    };
    let n = (n as usize % 48).min(rest.len() / 4);
    let (spec, delta) = rest.split_at(n * 4);
    let mut entities: Vec<EntityState> = spec
        .chunks_exact(4)
        .map(|c| {
            let mut e = EntityState::zero(c[0] as u32 * 7);
            e.kind = c[1];
            e.pos.x = c[2] as i32 - 128;
            e.pos.y = (c[3] as i32) << 20;
            e.flags = c[3] as u32;
            e
        })
        .collect();
    entities.sort_unstable_by_key(|e| e.id);
    entities.dedup_by_key(|e| e.id);
    // The baseline tick the delta asks for, so decoding goes past the header.
    let tick = match peek_delta(delta) {
        Ok((_, Some(t))) => t,
        _ => 0,
    };
    let base = StateSnapshot { tick, entities };
    for b in [None, Some(&base)] {
        if let Ok(state) = decode_delta(b, delta) {
            state.validate().expect("decoded states are valid");
            let mut again = Vec::new();
            encode_delta(b, &state, &mut again).expect("a decoded state re-encodes");
            assert_eq!(again, delta);
        }
    }
});
