//! The streaming frame decoder fed in chunks: the first byte picks the chunk
//! size and the frame limit. Never panics, never holds more than its limit,
//! never returns a frame over the frame limit.
#![no_main]

use ledge_shared::protocol::{ClientControl, FrameDecoder, Message, ProtocolError, ServerControl};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&knobs, stream)) = data.split_first() else {
        return;
    };
    let chunk = (knobs & 0x1f) as usize + 1;
    let max_frame = if knobs & 0x20 != 0 {
        64
    } else {
        ledge_shared::protocol::MAX_FRAME
    };
    let limit = 256;
    let mut dec = FrameDecoder::with_buffer_limit(max_frame, limit);
    for piece in stream.chunks(chunk) {
        if let Err(e) = dec.push(piece) {
            assert!(matches!(e, ProtocolError::TooLarge { .. }));
            assert_eq!(dec.push(&[]), Err(e), "errors are sticky");
            return;
        }
        assert!(dec.buffered() <= limit.max(4 + max_frame));
        while let Some(payload) = dec.pop() {
            assert!(payload.len() <= max_frame);
            let _ = ClientControl::decode(&payload);
            let _ = ServerControl::decode(&payload);
        }
    }
});
