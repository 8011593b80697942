//! Control-stream messages, both directions: decoding any bytes never
//! panics, and whatever decodes is valid and re-encodes to an equal message.
#![no_main]

use ledge_shared::protocol::{ClientControl, Message, ServerControl};
use libfuzzer_sys::fuzz_target;

fn check<M: Message + PartialEq + std::fmt::Debug>(data: &[u8]) {
    if let Ok(m) = M::decode(data) {
        let again = m.encode().expect("a decoded message re-encodes");
        assert_eq!(M::decode(&again).expect("and decodes again"), m);
    }
}

fuzz_target!(|data: &[u8]| {
    check::<ClientControl>(data);
    check::<ServerControl>(data);
    if let Ok(ServerControl::FullState(snapshot)) = ServerControl::decode(data) {
        let _ = snapshot.decode_state(None);
    }
});
