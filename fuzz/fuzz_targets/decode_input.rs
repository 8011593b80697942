//! Input datagrams: decoding any bytes never panics; whatever decodes is
//! valid, re-encodes, and its tick accessors agree.
#![no_main]

use ledge_shared::protocol::{InputPacket, Message, MAX_INPUT_HISTORY};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(p) = InputPacket::decode(data) {
        assert!(!p.buttons.is_empty() && p.buttons.len() <= MAX_INPUT_HISTORY);
        for (tick, buttons) in p.ticks() {
            assert_eq!(p.get(tick), Some(buttons));
        }
        let again = p.encode().expect("a decoded packet re-encodes");
        assert_eq!(InputPacket::decode(&again).expect("and decodes again"), p);
    }
});
