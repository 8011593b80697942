//! Property tests of the wire protocol: every message round-trips, deltas
//! reproduce the exact state, and every decoder survives random and mutated
//! bytes without panicking (returning errors, never allocating from a
//! hostile length).

use glam::IVec2;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::*;
use proptest::prelude::*;
use proptest::test_runner::TestCaseResult;

const CASES: u32 = 512;
const FUZZ_CASES: u32 = 6000;

// ---------------------------------------------------------------- strategies

/// Integers that exercise varint lengths and `i32` wrap-around.
fn any_i32() -> impl Strategy<Value = i32> {
    prop_oneof![
        4 => -3000..3000i32,
        2 => -(1 << 24)..(1 << 24),
        1 => any::<i32>(),
        1 => Just(i32::MIN),
        1 => Just(i32::MAX),
    ]
}

fn any_flags() -> impl Strategy<Value = u32> {
    prop_oneof![3 => 0..16u32, 1 => any::<u32>()]
}

fn entity(id: u32) -> impl Strategy<Value = EntityState> {
    (
        prop_oneof![3 => 0..4u8, 1 => any::<u8>()],
        any_i32(),
        any_i32(),
        any_i32(),
        any_i32(),
        any_flags(),
        any_i32(),
    )
        .prop_map(move |(kind, px, py, vx, vy, flags, aux)| EntityState {
            id,
            kind,
            pos: IVec2::new(px, py),
            vel: IVec2::new(vx, vy),
            flags,
            aux,
        })
}

/// A set of ids: mostly small and dense, sometimes huge (u32::MAX included).
fn ids(max_len: usize) -> impl Strategy<Value = Vec<u32>> {
    proptest::collection::btree_set(
        prop_oneof![8 => 0..400u32, 1 => any::<u32>(), 1 => Just(u32::MAX), 1 => Just(0u32)],
        0..max_len,
    )
    .prop_map(|s| s.into_iter().collect())
}

fn snapshot_with(
    tick: impl Strategy<Value = u64>,
    max_len: usize,
) -> impl Strategy<Value = StateSnapshot> {
    (tick, ids(max_len)).prop_flat_map(|(tick, ids)| {
        let entities: Vec<_> = ids.into_iter().map(entity).collect();
        entities.prop_map(move |entities| StateSnapshot { tick, entities })
    })
}

fn any_tick() -> impl Strategy<Value = u64> {
    prop_oneof![3 => 0..100_000u64, 1 => any::<u64>()]
}

fn snapshot() -> impl Strategy<Value = StateSnapshot> {
    snapshot_with(any_tick(), 40)
}

/// What happens to one baseline entity between baseline and current.
#[derive(Debug, Clone)]
enum Fate {
    Keep,
    Remove,
    Change(EntityState),
    Nudge(i32, i32),
}

/// A baseline and a current state derived from it: kept, changed, removed
/// and added entities, and a tick at or after the baseline's.
fn pair() -> impl Strategy<Value = (StateSnapshot, StateSnapshot)> {
    (snapshot_with(0..1_000_000u64, 40), 0..300u64)
        .prop_flat_map(|(base, dt)| {
            let fates = base
                .entities
                .iter()
                .map(|e| {
                    prop_oneof![
                        3 => Just(Fate::Keep),
                        1 => Just(Fate::Remove),
                        2 => entity(e.id).prop_map(Fate::Change),
                        3 => (-600..600i32, -600..600i32).prop_map(|(x, y)| Fate::Nudge(x, y)),
                    ]
                })
                .collect::<Vec<_>>();
            (Just(base), Just(dt), fates, snapshot_with(Just(0), 12))
        })
        .prop_map(|(base, dt, fates, added)| {
            let mut cur: Vec<EntityState> = Vec::new();
            for (e, fate) in base.entities.iter().zip(fates) {
                match fate {
                    Fate::Keep => cur.push(*e),
                    Fate::Remove => {}
                    Fate::Change(n) => cur.push(n),
                    Fate::Nudge(x, y) => {
                        let mut n = *e;
                        n.pos.x = n.pos.x.wrapping_add(x);
                        n.pos.y = n.pos.y.wrapping_add(y);
                        n.vel = IVec2::new(x, y);
                        cur.push(n);
                    }
                }
            }
            for a in added.entities {
                if base.get(a.id).is_none() {
                    cur.push(a);
                }
            }
            let tick = base.tick + dt;
            let cur = StateSnapshot::capture(tick, cur, |_| true).unwrap();
            (base, cur)
        })
}

/// A valid player name: visible characters (no emoji), no space at either
/// end, often multi-byte.
fn name() -> impl Strategy<Value = String> {
    text(MAX_NAME_LEN).prop_map(|s| {
        let visible: String = s.chars().filter(|&c| c != '🙂').collect();
        match visible.trim() {
            "" => "x".to_owned(),
            t => t.to_owned(),
        }
    })
}

/// Valid text of 1..=max bytes (no control characters), often multi-byte.
fn text(max: usize) -> impl Strategy<Value = String> {
    "[a-zA-Z0-9 _.!?é漢🙂-]{1,64}".prop_map(move |s| {
        let mut out = String::new();
        for c in s.chars() {
            if out.len() + c.len_utf8() > max {
                break;
            }
            out.push(c);
        }
        if out.is_empty() {
            out.push('x');
        }
        out
    })
}

fn client_control() -> impl Strategy<Value = ClientControl> {
    prop_oneof![
        (any::<u32>(), name()).prop_map(|(version, name)| ClientControl::Hello { version, name }),
        text(MAX_CHAT_LEN).prop_map(|text| ClientControl::Chat { text }),
        any::<u64>().prop_map(|nonce| ClientControl::Ping { nonce }),
        Just(ClientControl::Leave),
    ]
}

fn envelope() -> impl Strategy<Value = Snapshot> {
    (
        pair(),
        any::<bool>(),
        proptest::option::of(any_tick()),
        any::<i16>(),
    )
        .prop_map(|((base, cur), full, last_input, timing)| {
            Snapshot::new(
                if full { None } else { Some(&base) },
                &cur,
                last_input,
                timing,
            )
            .unwrap()
        })
}

fn server_control() -> impl Strategy<Value = ServerControl> {
    let welcome = (
        any::<u32>(),
        text(MAX_ID_LEN),
        text(MAX_ID_LEN),
        any::<u64>(),
        any_tick(),
        (1..=240u32, 1..=8u32, 1..=MAX_INPUT_HISTORY as u8),
        proptest::collection::vec(any::<u8>(), 0..200),
    )
        .prop_map(
            |(id, room, level_id, level_hash, server_tick, (rate, every, red), sim_config)| {
                ServerControl::Welcome(Welcome {
                    player_id: PlayerId(id),
                    room,
                    level_id,
                    level_hash,
                    server_tick,
                    timing: NetTiming {
                        tick_rate: rate,
                        snapshot_interval: every.min(rate),
                        input_redundancy: red,
                    },
                    level: LevelOffer {
                        sha256: [id as u8; 32],
                        size: server_tick % (MAX_LEVEL_BUNDLE + 1),
                    },
                    session_token: SessionToken([level_hash as u8; 16]),
                    sim_config,
                })
            },
        );
    let reason = prop_oneof![
        (any::<u32>(), any::<u32>())
            .prop_map(|(server, client)| RejectReason::ProtocolVersion { server, client }),
        Just(RejectReason::InvalidName),
        Just(RejectReason::RoomFull),
        Just(RejectReason::ShuttingDown),
        text(MAX_REASON_LEN).prop_map(|reason| RejectReason::Other { reason }),
    ];
    let notice = prop_oneof![
        Just(NoticeKind::Shutdown),
        text(MAX_REASON_LEN).prop_map(|reason| NoticeKind::Kick { reason }),
        text(MAX_REASON_LEN).prop_map(|text| NoticeKind::Info { text }),
    ];
    prop_oneof![
        welcome,
        reason.prop_map(|reason| ServerControl::Reject { reason }),
        (any::<u32>(), text(MAX_CHAT_LEN)).prop_map(|(p, text)| ServerControl::Chat {
            from: PlayerId(p),
            text
        }),
        notice.prop_map(|kind| ServerControl::Notice { kind }),
        envelope().prop_map(ServerControl::FullState),
        any::<u64>().prop_map(|nonce| ServerControl::Pong { nonce }),
        roster(40).prop_map(|players| ServerControl::Roster { players }),
        (any::<u32>(), name()).prop_map(|(id, name)| ServerControl::PlayerJoined(RosterEntry {
            id: PlayerId(id),
            name
        })),
        any::<u32>().prop_map(|id| ServerControl::PlayerLeft { id: PlayerId(id) }),
    ]
}

/// A valid roster of up to `max_len` players: ids ascending, names valid.
fn roster(max_len: usize) -> impl Strategy<Value = Vec<RosterEntry>> {
    proptest::collection::btree_map(any::<u32>(), name(), 0..max_len).prop_map(|m| {
        m.into_iter()
            .map(|(id, name)| RosterEntry {
                id: PlayerId(id),
                name,
            })
            .collect()
    })
}

fn buttons() -> impl Strategy<Value = Buttons> {
    any::<u8>().prop_map(Buttons)
}

fn input_packet() -> impl Strategy<Value = InputPacket> {
    (
        any_tick(),
        proptest::collection::vec(buttons(), 1..=MAX_INPUT_HISTORY),
        proptest::option::of(any_tick()),
        any::<bool>(),
    )
        .prop_map(|(tick, b, ack, hold)| InputPacket::new(tick, &b, ack).holding(hold))
}

/// One edit of a valid encoding.
#[derive(Debug, Clone)]
enum Mutation {
    Flip(usize, u8),
    Set(usize, u8),
    Insert(usize, u8),
    Delete(usize),
    Truncate(usize),
}

fn mutations() -> impl Strategy<Value = Vec<Mutation>> {
    proptest::collection::vec(
        prop_oneof![
            3 => (any::<usize>(), 0..8u8).prop_map(|(i, bit)| Mutation::Flip(i, 1 << bit)),
            2 => (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::Set(i, b)),
            2 => (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::Insert(i, b)),
            2 => any::<usize>().prop_map(Mutation::Delete),
            1 => any::<usize>().prop_map(Mutation::Truncate),
        ],
        1..4,
    )
}

fn mutate(mut bytes: Vec<u8>, edits: &[Mutation]) -> Vec<u8> {
    for m in edits {
        let n = bytes.len();
        match *m {
            Mutation::Flip(i, mask) if n > 0 => bytes[i % n] ^= mask,
            Mutation::Set(i, b) if n > 0 => bytes[i % n] = b,
            Mutation::Insert(i, b) => bytes.insert(i % (n + 1), b),
            Mutation::Delete(i) if n > 0 => {
                bytes.remove(i % n);
            }
            Mutation::Truncate(i) => bytes.truncate(i % (n + 1)),
            _ => {}
        }
    }
    bytes
}

/// Random bytes: short garbage, or garbage with plausible small lengths.
fn garbage() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        proptest::collection::vec(any::<u8>(), 0..64),
        proptest::collection::vec(prop_oneof![0..4u8, any::<u8>()], 0..512),
    ]
}

/// A decoded message is valid and re-encodes to something that decodes to it.
fn check_reencodes<M: Message + PartialEq + std::fmt::Debug>(m: &M) -> TestCaseResult {
    let again = m.encode().expect("a decoded message re-encodes");
    prop_assert_eq!(&M::decode(&again).expect("and decodes again"), m);
    Ok(())
}

// ---------------------------------------------------------------- deltas

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    #[test]
    fn delta_reproduces_state_against_baseline((base, cur) in pair()) {
        let mut bytes = Vec::new();
        encode_delta(Some(&base), &cur, &mut bytes).unwrap();
        prop_assert_eq!(decode_delta(Some(&base), &bytes).unwrap(), cur);
    }

    #[test]
    fn delta_reproduces_state_without_baseline(cur in snapshot()) {
        let mut bytes = Vec::new();
        encode_delta(None, &cur, &mut bytes).unwrap();
        prop_assert_eq!(decode_delta(None, &bytes).unwrap(), cur.clone());
        // And a full state is a delta from an empty state at tick 0.
        let empty = StateSnapshot { tick: 0, entities: vec![] };
        let mut from_empty = Vec::new();
        encode_delta(Some(&empty), &cur, &mut from_empty).unwrap();
        prop_assert_eq!(decode_delta(Some(&empty), &from_empty).unwrap(), cur);
    }

    #[test]
    fn delta_of_identical_states_is_header_only(base in snapshot()) {
        let mut bytes = Vec::new();
        encode_delta(Some(&base), &base, &mut bytes).unwrap();
        // header, tick, back = 0, count = 0
        prop_assert!(bytes.len() <= 1 + 10 + 1 + 1);
        prop_assert_eq!(decode_delta(Some(&base), &bytes).unwrap(), base);
    }

    #[test]
    fn delta_with_wrong_baseline_is_refused((base, cur) in pair(), other in snapshot()) {
        let mut bytes = Vec::new();
        encode_delta(Some(&base), &cur, &mut bytes).unwrap();
        let err = decode_delta(None, &bytes).unwrap_err();
        prop_assert!(matches!(err, ProtocolError::BaselineMismatch { .. }), "{err}");
        if other.tick != base.tick {
            let err = decode_delta(Some(&other), &bytes).unwrap_err();
            prop_assert!(matches!(err, ProtocolError::BaselineMismatch { .. }), "{err}");
        }
        let mut full = Vec::new();
        encode_delta(None, &cur, &mut full).unwrap();
        prop_assert!(decode_delta(Some(&base), &full).is_err());
    }

    #[test]
    fn envelope_round_trips_and_decodes_its_state(
        (base, cur) in pair(),
        full in any::<bool>(),
        last_input in proptest::option::of(any_tick()),
        timing in any::<i16>(),
    ) {
        let baseline = if full { None } else { Some(&base) };
        let snap = Snapshot::new(baseline, &cur, last_input, timing).unwrap();
        prop_assert_eq!(snap.tick, cur.tick);
        prop_assert_eq!(snap.baseline_tick, baseline.map(|b| b.tick));
        let bytes = snap.encode().unwrap();
        let back = Snapshot::decode(&bytes).unwrap();
        prop_assert_eq!(&back, &snap);
        prop_assert_eq!(back.decode_state(baseline).unwrap(), cur);
        let wrong = if full { Some(&base) } else { None };
        let is_mismatch = matches!(back.decode_state(wrong), Err(ProtocolError::BaselineMismatch { .. }));
        prop_assert!(is_mismatch);
    }
}

// ---------------------------------------------------------------- messages

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    #[test]
    fn client_control_round_trips(m in client_control()) {
        let bytes = m.encode().unwrap();
        prop_assert_eq!(ClientControl::decode(&bytes).unwrap(), m);
    }

    #[test]
    fn server_control_round_trips(m in server_control()) {
        let bytes = m.encode().unwrap();
        prop_assert_eq!(ServerControl::decode(&bytes).unwrap(), m);
    }

    #[test]
    fn input_packet_round_trips(p in input_packet()) {
        let bytes = p.encode().unwrap();
        prop_assert!(bytes.len() <= MAX_INPUT_DATAGRAM);
        let back = InputPacket::decode(&bytes).unwrap();
        prop_assert_eq!(&back, &p);
        // Ticks, newest first, consistent with `get`.
        for (i, (tick, b)) in back.ticks().enumerate() {
            prop_assert_eq!(tick, back.newest_tick - i as u64);
            prop_assert_eq!(back.get(tick), Some(b));
        }
        if back.oldest_tick() > 0 {
            prop_assert_eq!(back.get(back.oldest_tick() - 1), None);
        }
        prop_assert_eq!(back.get(back.newest_tick.wrapping_add(1)), None);
    }

    #[test]
    fn frames_survive_any_chunking(
        msgs in proptest::collection::vec(client_control(), 0..12),
        cuts in proptest::collection::vec(1..300usize, 1..40),
    ) {
        let mut stream = Vec::new();
        for m in &msgs {
            write_frame(m, &mut stream).unwrap();
        }
        let mut dec = FrameDecoder::default();
        let mut got = Vec::new();
        let mut rest = &stream[..];
        let mut k = 0;
        while !rest.is_empty() {
            let n = cuts[k % cuts.len()].min(rest.len());
            k += 1;
            dec.push(&rest[..n]).unwrap();
            rest = &rest[n..];
            while let Some(m) = dec.pop_message::<ClientControl>() {
                got.push(m.unwrap());
            }
        }
        prop_assert_eq!(got, msgs);
        prop_assert_eq!(dec.buffered(), 0);
        prop_assert!(dec.pop().is_none());
    }

    #[test]
    fn outgoing_picks_datagram_or_control_stream(
        (base, cur) in pair(),
        max in prop_oneof![Just(None), (0..400usize).prop_map(Some)],
    ) {
        let snap = Snapshot::new(Some(&base), &cur, Some(7), -2).unwrap();
        let len = snap.encode().unwrap().len();
        match snap.clone().into_outgoing(max).unwrap() {
            Outgoing::Datagram(bytes) => {
                prop_assert!(max.is_some_and(|m| fits(len, m)));
                prop_assert_eq!(Snapshot::decode(&bytes).unwrap(), snap);
            }
            Outgoing::Control(frame) => {
                prop_assert!(!max.is_some_and(|m| fits(len, m)));
                let mut dec = FrameDecoder::default();
                dec.push(&frame).unwrap();
                let m = dec.pop_message::<ServerControl>().unwrap().unwrap();
                prop_assert_eq!(m, ServerControl::FullState(snap));
                prop_assert!(dec.pop().is_none());
            }
        }
    }
}

// ---------------------------------------------------------------- robustness

proptest! {
    #![proptest_config(ProptestConfig::with_cases(FUZZ_CASES))]

    #[test]
    fn delta_decoder_survives_mutations((base, cur) in pair(), full in any::<bool>(), edits in mutations()) {
        let baseline = if full { None } else { Some(&base) };
        let mut bytes = Vec::new();
        encode_delta(baseline, &cur, &mut bytes).unwrap();
        let bad = mutate(bytes, &edits);
        for b in [baseline, Some(&base), Some(&cur), None] {
            if let Ok(state) = decode_delta(b, &bad) {
                // The format is canonical: whatever decodes re-encodes to
                // exactly the same bytes.
                state.validate().unwrap();
                let mut again = Vec::new();
                encode_delta(b, &state, &mut again).unwrap();
                prop_assert_eq!(&again, &bad);
            }
        }
    }

    #[test]
    fn delta_decoder_survives_garbage(bytes in garbage(), base in snapshot()) {
        for b in [None, Some(&base)] {
            if let Ok(state) = decode_delta(b, &bytes) {
                let mut again = Vec::new();
                encode_delta(b, &state, &mut again).unwrap();
                prop_assert_eq!(&again, &bytes);
            }
        }
        // With the baseline the header asks for, so decoding goes deeper.
        if let Ok((_, Some(tick))) = snapshot::peek_delta(&bytes) {
            let b = StateSnapshot { tick, ..base };
            let _ = decode_delta(Some(&b), &bytes);
        }
    }

    #[test]
    fn control_decoders_survive_mutations(c in client_control(), s in server_control(), edits in mutations()) {
        let bad = mutate(c.encode().unwrap(), &edits);
        if let Ok(m) = ClientControl::decode(&bad) { check_reencodes(&m)?; }
        if let Ok(m) = ServerControl::decode(&bad) { check_reencodes(&m)?; }
        let bad = mutate(s.encode().unwrap(), &edits);
        if let Ok(m) = ServerControl::decode(&bad) {
            check_reencodes(&m)?;
            if let ServerControl::FullState(snap) = &m {
                let _ = snap.decode_state(None);
            }
        }
        if let Ok(m) = ClientControl::decode(&bad) { check_reencodes(&m)?; }
    }

    #[test]
    fn datagram_decoders_survive_mutations(p in input_packet(), snap in envelope(), edits in mutations()) {
        let bad = mutate(p.encode().unwrap(), &edits);
        if let Ok(m) = InputPacket::decode(&bad) { check_reencodes(&m)?; }
        let bad = mutate(snap.encode().unwrap(), &edits);
        if let Ok(m) = Snapshot::decode(&bad) {
            check_reencodes(&m)?;
            let _ = m.decode_state(None);
        }
    }

    #[test]
    fn every_decoder_survives_garbage(bytes in garbage()) {
        if let Ok(m) = ClientControl::decode(&bytes) { check_reencodes(&m)?; }
        if let Ok(m) = ServerControl::decode(&bytes) { check_reencodes(&m)?; }
        if let Ok(m) = InputPacket::decode(&bytes) { check_reencodes(&m)?; }
        if let Ok(m) = Snapshot::decode(&bytes) {
            check_reencodes(&m)?;
            let _ = m.decode_state(None);
        }
    }

    #[test]
    fn frame_decoder_survives_garbage_in_any_chunks(
        msgs in proptest::collection::vec(client_control(), 0..4),
        edits in mutations(),
        junk in garbage(),
        cuts in proptest::collection::vec(1..64usize, 1..8),
        small_frames in any::<bool>(),
    ) {
        let mut stream = Vec::new();
        for m in &msgs {
            write_frame(m, &mut stream).unwrap();
        }
        stream.extend_from_slice(&junk);
        let stream = mutate(stream, &edits);
        let max_frame = if small_frames { 40 } else { MAX_FRAME };
        let limit = 200;
        let mut dec = FrameDecoder::with_buffer_limit(max_frame, limit);
        let mut rest = &stream[..];
        let mut k = 0;
        let mut failed = false;
        while !rest.is_empty() {
            let n = cuts[k % cuts.len()].min(rest.len());
            k += 1;
            if let Err(e) = dec.push(&rest[..n]) {
                // Sticky: the stream is out of sync for good.
                prop_assert_eq!(dec.push(&[0]).unwrap_err(), e.clone());
                prop_assert!(matches!(e, ProtocolError::TooLarge { .. }), "{e}");
                failed = true;
                break;
            }
            rest = &rest[n..];
            prop_assert!(dec.buffered() <= limit.max(4 + max_frame));
            while let Some(payload) = dec.pop() {
                prop_assert!(payload.len() <= max_frame);
                let _ = ClientControl::decode(&payload);
            }
        }
        if !failed {
            prop_assert!(dec.error().is_none());
        }
    }
}

// ---------------------------------------------------------------- specifics

#[test]
fn oversized_frame_prefix_is_rejected_before_buffering() {
    let mut dec = FrameDecoder::default();
    let len = (MAX_FRAME as u32 + 1).to_le_bytes();
    // Two bytes of the prefix: not known yet, held.
    dec.push(&len[..2]).unwrap();
    assert_eq!(dec.buffered(), 2);
    // The rest of the prefix and some payload: rejected, nothing stored.
    let err = dec.push(&[len[2], len[3], 1, 2, 3]).unwrap_err();
    assert_eq!(
        err,
        ProtocolError::TooLarge {
            what: "frame length prefix",
            len: MAX_FRAME as u64 + 1,
            max: MAX_FRAME as u64
        }
    );
    assert_eq!(dec.buffered(), 2);
    assert!(dec.pop().is_none());
    // Sticky.
    assert_eq!(dec.push(&[]).unwrap_err(), err);

    // A 4 GiB prefix after a valid frame in the same chunk.
    let mut stream = Vec::new();
    write_frame(&ClientControl::Leave, &mut stream).unwrap();
    stream.extend_from_slice(&u32::MAX.to_le_bytes());
    let mut dec = FrameDecoder::default();
    assert!(
        matches!(dec.push(&stream), Err(ProtocolError::TooLarge { len, .. }) if len == u32::MAX as u64)
    );
    assert_eq!(dec.buffered(), 0);

    // The largest legal frame is accepted.
    let mut dec = FrameDecoder::default();
    let mut big = (MAX_FRAME as u32).to_le_bytes().to_vec();
    big.resize(4 + MAX_FRAME, 7);
    dec.push(&big).unwrap();
    assert_eq!(dec.pop().unwrap().len(), MAX_FRAME);
}

#[test]
fn frame_decoder_buffer_is_bounded() {
    // Frames are legal but the reader never pops: the limit stops it.
    let mut dec = FrameDecoder::with_buffer_limit(16, 64);
    let mut frame = Vec::new();
    write_frame(&ClientControl::Ping { nonce: 1 }, &mut frame).unwrap();
    let mut pushed = 0;
    let err = loop {
        match dec.push(&frame) {
            Ok(()) => pushed += 1,
            Err(e) => break e,
        }
        assert!(pushed < 100);
    };
    assert!(
        matches!(err, ProtocolError::TooLarge { max: 64, .. }),
        "{err}"
    );
    assert!(dec.buffered() <= 64);
    // Popping between pushes never hits the limit.
    let mut dec = FrameDecoder::with_buffer_limit(16, 64);
    for _ in 0..1000 {
        dec.push(&frame).unwrap();
        assert_eq!(
            dec.pop_message::<ClientControl>().unwrap().unwrap(),
            ClientControl::Ping { nonce: 1 }
        );
    }
}

#[test]
fn hostile_lengths_inside_messages_are_errors() {
    // Chat (variant 1) claiming a 2^60-byte string: bincode varint 0xFD + u64.
    let mut bytes = vec![1u8, 0xFD];
    bytes.extend_from_slice(&(1u64 << 60).to_le_bytes());
    assert!(ClientControl::decode(&bytes).is_err());
    // Welcome sim_config claiming 1 GiB.
    let mut bytes = vec![0u8, 0, 1, b'r', 1, b'l', 0, 0, 60, 1, 8, 0xFC];
    bytes.extend_from_slice(&(1u32 << 30).to_le_bytes());
    assert!(ServerControl::decode(&bytes).is_err());
    // Input packet claiming 2^32 buttons.
    let mut bytes = vec![5u8, 0xFC];
    bytes.extend_from_slice(&u32::MAX.to_le_bytes());
    assert!(InputPacket::decode(&bytes).is_err());
    // Oversized datagrams are refused before decoding.
    let big = vec![0u8; MAX_INPUT_DATAGRAM + 1];
    assert!(matches!(
        InputPacket::decode(&big),
        Err(ProtocolError::TooLarge { .. })
    ));
    let big = vec![0u8; MAX_FRAME + 1];
    assert!(matches!(
        ServerControl::decode(&big),
        Err(ProtocolError::TooLarge { .. })
    ));
    assert!(matches!(
        Snapshot::decode(&big),
        Err(ProtocolError::TooLarge { .. })
    ));
}

#[test]
fn delta_entity_count_is_capped() {
    // A full baseline, then a delta adding one more entity (hand-made: the
    // encoder refuses to produce it).
    let base = StateSnapshot {
        tick: 10,
        entities: (0..MAX_ENTITIES as u32).map(EntityState::zero).collect(),
    };
    base.validate().unwrap();
    // header=1, tick=11, back=1, count=1, id gap=MAX_ENTITIES (0x80 0x08), ctrl=0
    let bytes = [1u8, 11, 1, 1, 0x80, 0x08, 0];
    let err = decode_delta(Some(&base), &bytes).unwrap_err();
    assert!(matches!(err, ProtocolError::TooLarge { .. }), "{err}");
    // An entry count far beyond the bytes present.
    let bytes = [0u8, 11, 0xff, 0xff, 0x03];
    assert!(decode_delta(None, &bytes).is_err());
    // Too many entities to encode.
    let too_many = StateSnapshot {
        tick: 1,
        entities: (0..=MAX_ENTITIES as u32).map(EntityState::zero).collect(),
    };
    assert!(matches!(
        encode_delta(None, &too_many, &mut Vec::new()),
        Err(ProtocolError::TooLarge { .. })
    ));
}

#[test]
fn delta_rejects_non_canonical_input() {
    let base = StateSnapshot {
        tick: 5,
        entities: vec![EntityState {
            pos: IVec2::new(3, 4),
            ..EntityState::zero(2)
        }],
    };
    let ok = |b: &[u8]| decode_delta(Some(&base), b);
    // Unchanged entity listed (mask 0).
    assert!(ok(&[1, 6, 1, 1, 2, 0]).is_err());
    // pos.x flagged with a zero delta.
    assert!(ok(&[1, 6, 1, 1, 2, 0b10, 0]).is_err());
    // pos.x + 1 is fine.
    assert_eq!(
        ok(&[1, 6, 1, 1, 2, 0b10, 2]).unwrap().entities[0].pos,
        IVec2::new(4, 4)
    );
    // Removing an unknown id.
    assert!(ok(&[1, 6, 1, 1, 3, 0x80]).is_err());
    // Unknown control bits.
    assert!(ok(&[1, 6, 1, 1, 2, 0x81]).is_err());
    // Ids out of order cannot be expressed; id overflow can.
    assert!(decode_delta(None, &[0, 6, 2, 0xff, 0xff, 0xff, 0xff, 0x0f, 0, 0, 0]).is_err());
    // Unknown header bits, trailing bytes, baseline before tick 0.
    assert!(ok(&[3, 6, 1, 0]).is_err());
    assert!(matches!(
        ok(&[1, 6, 1, 0, 0]),
        Err(ProtocolError::TrailingBytes { .. })
    ));
    assert!(decode_delta(None, &[1, 6, 7, 0]).is_err());
    // Removal works.
    assert!(ok(&[1, 6, 1, 1, 2, 0x80]).unwrap().entities.is_empty());
}

#[test]
fn invalid_strings_are_rejected_both_ways() {
    // Encoders refuse.
    for name in ["", "a\nb", "\u{7}bell", &"n".repeat(MAX_NAME_LEN + 1)] {
        let m = ClientControl::Hello {
            version: PROTOCOL_VERSION,
            name: name.to_string(),
        };
        assert!(
            matches!(m.encode(), Err(ProtocolError::InvalidString { .. })),
            "{name:?}"
        );
    }
    let chat = ClientControl::Chat {
        text: "x".repeat(MAX_CHAT_LEN + 1),
    };
    assert!(chat.encode().is_err());
    // Decoders refuse what a hostile peer encodes anyway.
    let raw =
        |m: &ClientControl| bincode::serde::encode_to_vec(m, bincode::config::standard()).unwrap();
    let evil = raw(&ClientControl::Chat {
        text: "hi\u{1b}[2J".into(),
    });
    assert_eq!(
        ClientControl::decode(&evil).unwrap_err(),
        ProtocolError::InvalidString {
            field: "chat text",
            problem: "contains control characters"
        }
    );
    // A direction override would turn around what others read, and an
    // invisible character hide what a line says: refused both ways.
    for hidden in [
        "evil\u{202E}gnp.exe",
        "a\u{200B}b",
        "\u{2066}x\u{2069}",
        "tag\u{E0041}",
    ] {
        let line = ClientControl::Chat {
            text: hidden.into(),
        };
        assert!(line.encode().is_err(), "{hidden:?}");
        assert_eq!(
            ClientControl::decode(&raw(&line)).unwrap_err(),
            ProtocolError::InvalidString {
                field: "chat text",
                problem: "contains a direction override or an invisible character"
            },
            "{hidden:?}"
        );
    }
    // Emoji and scripts that need joiners and variation selectors pass.
    for fine in [
        "love \u{2764}\u{FE0F}",
        "\u{1F468}\u{200D}\u{1F469}\u{200D}\u{1F467}",
        "\u{0645}\u{06CC}\u{200C}\u{062E}\u{0648}\u{0627}\u{0645}",
    ] {
        let line = ClientControl::Chat { text: fine.into() };
        assert_eq!(
            ClientControl::decode(&line.encode().unwrap()).unwrap(),
            line,
            "{fine:?}"
        );
    }
    assert_eq!(
        ledge_shared::protocol::clip_text("a\u{202E}b\nc", 256),
        "ab c",
        "made fit: hidden characters dropped, controls spaced"
    );
    let long = raw(&ClientControl::Hello {
        version: 1,
        name: "é".repeat(17),
    });
    assert!(matches!(
        ClientControl::decode(&long),
        Err(ProtocolError::InvalidString {
            problem: "too long",
            ..
        })
    ));
    // Invalid UTF-8 is malformed.
    let mut bad_utf8 = raw(&ClientControl::Chat { text: "ab".into() });
    *bad_utf8.last_mut().unwrap() = 0xff;
    assert!(matches!(
        ClientControl::decode(&bad_utf8),
        Err(ProtocolError::Malformed { .. })
    ));
    // Trailing bytes.
    let mut trailing = ClientControl::Leave.encode().unwrap();
    trailing.push(0);
    assert!(matches!(
        ClientControl::decode(&trailing),
        Err(ProtocolError::TrailingBytes { extra: 1, .. })
    ));
}

#[test]
fn hello_of_any_version_decodes_and_version_is_checked_separately() {
    let m = ClientControl::Hello {
        version: 999,
        name: "ana".into(),
    };
    let back = ClientControl::decode(&m.encode().unwrap()).unwrap();
    let ClientControl::Hello { version, .. } = back else {
        panic!()
    };
    assert_eq!(
        check_version(version),
        Err(ProtocolError::BadVersion {
            ours: PROTOCOL_VERSION,
            theirs: 999
        })
    );
    assert_eq!(check_version(PROTOCOL_VERSION), Ok(()));
    // Hello's layout is frozen: variant 0, varint u32, string.
    assert_eq!(
        m.encode().unwrap(),
        [0, 0xFB, 0xE7, 0x03, 3, b'a', b'n', b'a']
    );
}

#[test]
fn input_packet_validation() {
    let p = InputPacket::new(3, &[Buttons(1); 20], Some(1));
    assert_eq!(p.buttons.len(), 4, "no ticks before 0");
    assert_eq!(p.oldest_tick(), 0);
    let p = InputPacket::new(1000, &[Buttons(1); 100], None);
    assert_eq!(p.buttons.len(), MAX_INPUT_HISTORY);
    let empty = InputPacket {
        newest_tick: 5,
        buttons: vec![],
        ack_snapshot: None,
        hold: false,
    };
    assert!(empty.encode().is_err());
    let before_zero = InputPacket {
        newest_tick: 1,
        buttons: vec![Buttons(0); 3],
        ack_snapshot: None,
        hold: false,
    };
    assert!(before_zero.encode().is_err());
    let raw = bincode::serde::encode_to_vec(&before_zero, bincode::config::standard()).unwrap();
    assert!(InputPacket::decode(&raw).is_err());
    assert_eq!(input_timing(105, 100), 5);
    assert_eq!(input_timing(95, 100), -5);
    assert_eq!(input_timing(u64::MAX, 0), i16::MAX);
    assert_eq!(input_timing(0, u64::MAX), i16::MIN);
}

#[test]
fn capture_filters_sorts_and_rejects_duplicates() {
    let platform = EntityState {
        flags: EntityState::CLIENT_SIMULATED | 1,
        ..EntityState::zero(1)
    };
    let s = StateSnapshot::capture(
        9,
        [EntityState::zero(7), platform, EntityState::zero(3)],
        is_replicated,
    )
    .unwrap();
    assert_eq!(s.entities.iter().map(|e| e.id).collect::<Vec<_>>(), [3, 7]);
    assert_eq!(s.get(7), Some(&EntityState::zero(7)));
    assert_eq!(s.get(1), None);
    assert!(
        StateSnapshot::capture(9, [EntityState::zero(3), EntityState::zero(3)], |_| true).is_err()
    );
    let unsorted = StateSnapshot {
        tick: 1,
        entities: vec![EntityState::zero(2), EntityState::zero(1)],
    };
    assert!(matches!(
        encode_delta(None, &unsorted, &mut Vec::new()),
        Err(ProtocolError::InvalidValue { .. })
    ));
    let newer = StateSnapshot {
        tick: 2,
        entities: vec![],
    };
    let older = StateSnapshot {
        tick: 1,
        entities: vec![],
    };
    assert!(matches!(
        encode_delta(Some(&newer), &older, &mut Vec::new()),
        Err(ProtocolError::InvalidValue { .. })
    ));
}

#[test]
fn snapshot_history_keeps_newest() {
    let mut h = SnapshotHistory::new(3);
    assert!(h.is_empty());
    for t in [1, 2, 3, 4] {
        assert!(h.insert(StateSnapshot {
            tick: t,
            entities: vec![]
        }));
    }
    assert!(
        !h.insert(StateSnapshot {
            tick: 2,
            entities: vec![]
        }),
        "older: ignored"
    );
    assert_eq!(h.len(), 3);
    assert!(h.get(1).is_none());
    assert_eq!(h.get(3).unwrap().tick, 3);
    assert_eq!(h.latest().unwrap().tick, 4);
    h.forget_before(4);
    assert_eq!(h.len(), 1);
}

#[test]
fn close_codes_round_trip() {
    for code in [
        CloseCode::Normal,
        CloseCode::ProtocolViolation,
        CloseCode::Rejected,
        CloseCode::Timeout,
        CloseCode::ServerShutdown,
        CloseCode::Kicked,
    ] {
        assert_eq!(CloseCode::from_u32(code.to_u32()), Some(code));
    }
    assert_eq!(CloseCode::from_u32(99), None);
}

// ---------------------------------------------------------------- sizes

/// `n` players standing around a level (positions spread over 4000 px).
fn room(tick: u64, n: u32) -> StateSnapshot {
    let entities = (0..n)
        .map(|i| EntityState {
            id: i + 1,
            kind: (i % 4) as u8,
            pos: IVec2::new((i as i32 * 977 % 4000) * 256, (i as i32 * 131 % 1000) * 256),
            vel: IVec2::ZERO,
            flags: 1,
            aux: 0,
        })
        .collect();
    StateSnapshot { tick, entities }
}

#[test]
fn idle_and_typical_deltas_are_small() {
    // A server about an hour in: ticks need three varint bytes.
    let t0 = 216_000;
    let idle_base = room(t0, 200);
    let idle = StateSnapshot {
        tick: t0 + 3,
        ..idle_base.clone()
    };
    let mut bytes = Vec::new();
    encode_delta(Some(&idle_base), &idle, &mut bytes).unwrap();
    let idle_len = bytes.len();
    assert!(
        idle_len < 16,
        "idle delta of 200 entities is {idle_len} bytes"
    );
    let envelope = Snapshot::new(Some(&idle_base), &idle, Some(t0 + 5), 2)
        .unwrap()
        .encode()
        .unwrap();

    let mut full = Vec::new();
    encode_delta(None, &idle, &mut full).unwrap();

    // 8 players running and jumping (among 200 entities): pos and vel change.
    let base = room(t0, 200);
    let mut cur = StateSnapshot {
        tick: t0 + 3,
        ..base.clone()
    };
    for (k, e) in cur.entities.iter_mut().take(8).enumerate() {
        let k = k as i32;
        e.vel = IVec2::new(3 * 256 + k * 17, -(5 * 256) + k * 40);
        e.pos += e.vel * 3;
        if k % 3 == 0 {
            e.flags ^= 2; // became grounded
            e.aux += 1; // animation frame
        }
    }
    let mut moving = Vec::new();
    encode_delta(Some(&base), &cur, &mut moving).unwrap();
    let moving_envelope = Snapshot::new(Some(&base), &cur, Some(t0 + 5), 2)
        .unwrap()
        .encode()
        .unwrap();
    assert!(
        moving.len() < 120,
        "8 moving players: {} bytes",
        moving.len()
    );
    assert_eq!(decode_delta(Some(&base), &moving).unwrap(), cur);

    // 16 ticks of input with one change among them, the ack 3 ticks back.
    let mut ticks = [Buttons(Buttons::RIGHT); DEFAULT_INPUT_REDUNDANCY as usize];
    ticks[..5].fill(Buttons(Buttons::RIGHT | Buttons::JUMP));
    let input = InputPacket::new(t0 + 5, &ticks, Some(t0 + 2))
        .encode()
        .unwrap();
    assert!(input.len() <= 13, "input datagram: {} bytes", input.len());
    eprintln!(
        "sizes: idle delta (200 entities) {idle_len} B, idle snapshot datagram {} B; \
         8 moving players delta {} B, datagram {} B; full state of 200 entities {} B; \
         input packet ({} ticks) {} B",
        envelope.len(),
        moving.len(),
        moving_envelope.len(),
        full.len(),
        DEFAULT_INPUT_REDUNDANCY,
        input.len()
    );
    let bincode_full = bincode::serde::encode_to_vec(&idle, bincode::config::standard()).unwrap();
    let bincode_moving = bincode::serde::encode_to_vec(&cur, bincode::config::standard()).unwrap();
    eprintln!(
        "bincode of the whole state for comparison: {} B (idle), {} B (moving)",
        bincode_full.len(),
        bincode_moving.len()
    );
    // About 10 bytes per entity from scratch: too big for a 1200-byte
    // datagram, so a full 200-entity state travels on the control stream.
    assert!(full.len() < 12 * 200, "full state: {} bytes", full.len());
    let first = Snapshot::new(None, &idle, None, 0).unwrap();
    assert!(matches!(
        first.into_outgoing(Some(1200)).unwrap(),
        Outgoing::Control(_)
    ));
}

/// The worked example of docs/PROTOCOL.md, byte for byte.
#[test]
fn documented_example_bytes() {
    let base = StateSnapshot {
        tick: 100,
        entities: vec![
            EntityState {
                pos: IVec2::new(256, 0),
                ..EntityState::zero(5)
            },
            EntityState::zero(7),
        ],
    };
    let cur = StateSnapshot {
        tick: 103,
        entities: vec![
            EntityState {
                pos: IVec2::new(512, 0),
                vel: IVec2::new(256, 0),
                ..EntityState::zero(5)
            },
            EntityState {
                kind: 2,
                ..EntityState::zero(9)
            },
        ],
    };
    let mut bytes = Vec::new();
    encode_delta(Some(&base), &cur, &mut bytes).unwrap();
    assert_eq!(
        bytes,
        [
            0x01, 0x67, 0x03, 0x03, 0x05, 0x0A, 0x80, 0x04, 0x80, 0x04, 0x01, 0x80, 0x01, 0x01,
            0x02
        ]
    );
    assert_eq!(decode_delta(Some(&base), &bytes).unwrap(), cur);
    let input = InputPacket::new(300, &[Buttons(Buttons::JUMP), Buttons(0)], Some(297));
    assert_eq!(
        input.encode().unwrap(),
        [0xFB, 0x2C, 0x01, 0x04, 0x00, 0x10, 0x00, 0x00, 0x01, 0x05, 0x00]
    );
    assert_eq!(
        input.holding(true).encode().unwrap(),
        [0xFB, 0x2C, 0x01, 0x04, 0x00, 0x10, 0x00, 0x00, 0x01, 0x05, 0x01]
    );
}

#[test]
fn the_game_config_round_trips_through_the_welcome_blob() {
    use ledge_shared::game::GameConfig;
    use ledge_shared::protocol::{decode_sim_config, encode_sim_config, MAX_SIM_CONFIG_LEN};
    let mut config = GameConfig::default();
    config.player.gravity += 3;
    let bytes = encode_sim_config(&config).unwrap();
    assert!(bytes.len() <= MAX_SIM_CONFIG_LEN);
    assert_eq!(decode_sim_config::<GameConfig>(&bytes).unwrap(), config);
    // Trailing, truncated and oversized blobs are errors, not panics.
    let mut long = bytes.clone();
    long.push(0);
    assert!(decode_sim_config::<GameConfig>(&long).is_err());
    assert!(decode_sim_config::<GameConfig>(&bytes[..bytes.len() - 1]).is_err());
    assert!(decode_sim_config::<GameConfig>(&vec![0xff; MAX_SIM_CONFIG_LEN + 1]).is_err());
}

/// A roster entry named `name` for id `id`.
fn entry(id: u32, name: &str) -> RosterEntry {
    RosterEntry {
        id: PlayerId(id),
        name: name.into(),
    }
}

#[test]
fn roster_messages_round_trip_after_the_older_variants() {
    let full = ServerControl::Roster {
        players: (0..MAX_ROSTER as u32)
            .map(|i| entry(i * 7, &"n".repeat(MAX_NAME_LEN)))
            .collect(),
    };
    let bytes = full.encode().unwrap();
    assert!(bytes.len() <= MAX_FRAME, "{}", bytes.len());
    assert_eq!(ServerControl::decode(&bytes).unwrap(), full);
    // Appended after Pong (variant 5): the older encodings are unchanged.
    let small = ServerControl::Roster {
        players: vec![entry(1, "ana"), entry(300, "bo")],
    };
    assert_eq!(
        small.encode().unwrap(),
        [6, 2, 1, 3, b'a', b'n', b'a', 0xFB, 0x2C, 0x01, 2, b'b', b'o']
    );
    let joined = ServerControl::PlayerJoined(entry(2, "cy"));
    assert_eq!(joined.encode().unwrap(), [7, 2, 2, b'c', b'y']);
    let left = ServerControl::PlayerLeft { id: PlayerId(2) };
    assert_eq!(left.encode().unwrap(), [8, 2]);
    assert_eq!(ServerControl::Pong { nonce: 1 }.encode().unwrap(), [5, 1]);
    for m in [
        small,
        joined,
        left,
        ServerControl::Roster { players: vec![] },
    ] {
        assert_eq!(ServerControl::decode(&m.encode().unwrap()).unwrap(), m);
    }
    assert!(check_roster(&[entry(1, "a"), entry(2, "b")]).is_ok());
}

#[test]
fn bad_rosters_are_refused_both_ways() {
    let raw = |m: &ServerControl| {
        bincode::serde::encode_to_vec(m, bincode::config::standard().with_limit::<MAX_FRAME>())
            .unwrap()
    };
    let cases = [
        (
            "too many",
            (0..=MAX_ROSTER as u32).map(|i| entry(i, "x")).collect(),
        ),
        ("duplicate id", vec![entry(1, "a"), entry(1, "b")]),
        ("descending ids", vec![entry(2, "a"), entry(1, "b")]),
        ("empty name", vec![entry(1, "")]),
        ("control character", vec![entry(1, "a\u{1b}[2J")]),
        ("long name", vec![entry(1, &"n".repeat(MAX_NAME_LEN + 1))]),
    ];
    for (what, players) in cases {
        assert!(check_roster(&players).is_err(), "{what}");
        let m = ServerControl::Roster { players };
        assert!(m.encode().is_err(), "{what}: the encoder refuses");
        assert!(
            ServerControl::decode(&raw(&m)).is_err(),
            "{what}: the decoder refuses"
        );
    }
    let bad_join = ServerControl::PlayerJoined(entry(3, "a\nb"));
    assert!(bad_join.encode().is_err());
    assert!(matches!(
        ServerControl::decode(&raw(&bad_join)),
        Err(ProtocolError::InvalidString { .. })
    ));
    // A hostile count: 2^60 entries claimed, none present. The decoder
    // fails on the bytes, having allocated nothing for the claim.
    let mut bytes = vec![6u8, 0xFD];
    bytes.extend_from_slice(&(1u64 << 60).to_le_bytes());
    assert!(ServerControl::decode(&bytes).is_err());
    // More than MAX_ROSTER entries present: refused while reading, before
    // the rest is decoded.
    let too_many = ServerControl::Roster {
        players: (0..=MAX_ROSTER as u32).map(|i| entry(i, "x")).collect(),
    };
    let err = ServerControl::decode(&raw(&too_many)).unwrap_err();
    assert!(
        err.to_string()
            .contains(&format!("more than {MAX_ROSTER} roster entries")),
        "{err}"
    );
    // Truncated anywhere: an error, never a panic.
    let good = ServerControl::Roster {
        players: vec![entry(1, "ana"), entry(2, "bo")],
    }
    .encode()
    .unwrap();
    for end in 0..good.len() {
        assert!(ServerControl::decode(&good[..end]).is_err(), "{end}");
    }
}
