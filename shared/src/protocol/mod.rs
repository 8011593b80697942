//! The wire protocol: versioned message types, their encodings, and
//! delta-compressed snapshots. Pure (sans-IO): bytes in, values out, no
//! sockets or clocks, and no panic on any input.
//!
//! A session is one QUIC connection with
//!
//! * one reliable bidirectional **control stream** of length-prefixed frames
//!   ([`write_frame`], [`FrameDecoder`]) carrying [`ClientControl`] and
//!   [`ServerControl`] (hello / welcome, chat, notices, pings, and snapshots
//!   too large for a datagram);
//! * unreliable **datagrams**: [`InputPacket`] from client to server every
//!   tick (repeating the last ticks' buttons) and [`Snapshot`] from server to
//!   client every few ticks, each delta-encoded ([`encode_delta`]) against the
//!   newest snapshot the client acknowledged.
//!
//! Messages and envelopes use bincode 2 through serde with a size limit
//! ([`Message`]); the entity state inside a snapshot uses a smaller
//! hand-written varint format ([`snapshot`]). `docs/PROTOCOL.md` documents
//! the wire format byte by byte.

mod bounded;
mod codec;
mod control;
mod datagram;
mod error;
mod fingerprint;
mod frame;
mod outgoing;
mod rotation;
pub mod snapshot;
mod varint;
pub mod web;

pub use codec::Message;
pub use control::{
    check_level_list, check_name, check_rooms, check_roster, check_standing, check_text,
    check_version, clip_text, decode_sim_config, encode_sim_config, is_hidden, name_key,
    ClientControl, CloseCode, GhostRun, LevelOffer, NetTiming, NoticeKind, PlayerId, RejectReason,
    RoomInfo, RosterEntry, ServerControl, SessionToken, Standing, TopRun, Welcome, MAX_CHAT_LEN,
    MAX_GHOST_REPLAY, MAX_ID_LEN, MAX_LEVEL_BUNDLE, MAX_NAME_LEN, MAX_REASON_LEN, MAX_ROOMS,
    MAX_ROSTER, MAX_SIM_CONFIG_LEN, MAX_TOP,
};
pub use datagram::{input_timing, InputPacket, Snapshot};
pub use error::ProtocolError;
pub use fingerprint::{Fingerprint, ParseFingerprintError};
pub use frame::{write_frame, FrameDecoder, FRAME_HEADER};
pub use outgoing::{fits, Outgoing};
pub use rotation::{LevelChoice, LevelList, VoteRule, MAX_LEVELS};
pub use snapshot::{
    decode_delta, encode_delta, extrapolate, extrapolates_to, is_replicated, EntityState,
    SnapshotHistory, StateSnapshot,
};

/// Version of this protocol, sent in [`ClientControl::Hello`]; the server
/// rejects any other. Bump it on every change of any encoding.
///
/// 3: `ClientControl::HelloRoom`; deltas against baseline entities
/// extrapolated by their velocity ([`snapshot::extrapolate`]).
/// 4: the room's roster: `ServerControl::Roster`, `PlayerJoined`,
/// `PlayerLeft` (players' names).
/// 5: rooms by name: `ClientControl::ListRooms`, `ServerControl::Rooms`;
/// level download: `Welcome::level`, `ClientControl::GetLevel`; resuming a
/// lost session: `Welcome::session_token`, `ClientControl::Resume`.
/// 6: runs (`game::state`): a run record per player in snapshots
/// (`kind::RUN`, id `RUN_ID_BASE` + player id), the player flags `DEAD`
/// (its `aux` then the respawn countdown) and `RESTART_HELD`, the input bit
/// `Buttons::RESTART`, and `PlayerConfig::respawn_delay_ticks` in
/// `Welcome::sim_config`.
/// 7: input datagrams carry their buttons as runs of equal ticks and the
/// acknowledgement as an offset from the newest tick (`InputPacket`'s wire
/// form); clients send one every other tick at 60 Hz.
/// 8: idle clients and rooms go quiet: `InputPacket::hold` (the server
/// applies held buttons to the ticks a quiet client sends none for) and
/// `Snapshot::since_previous` (the server sends no snapshot that would
/// change nothing for a client that sent nothing).
/// 9: records: `ServerControl::RunRecorded` (where a finished run stands,
/// sent once it is stored) and `ServerControl::RunNotRecorded`.
/// 10: spectators (`ClientControl::Spectate`) and ghosts (`ServerControl::Ghost`).
/// 11: level rotation and votes: `ServerControl::Levels`,
/// `ServerControl::LevelChange`, `ClientControl::Vote`, and
/// `ClientControl::GetLevel::sha256` (which of the server's levels).
/// 12: the level bundle's `Level` carries the level's player scale
/// (`Level::player`) and turned triggers (`EntityKind::Turned`).
pub const PROTOCOL_VERSION: u32 = 12;

/// ALPN identifier for the TLS handshake, so a ledge endpoint never talks to
/// an unrelated QUIC peer. It names the application, not the version:
/// versions are compared in `Hello`, so a mismatch gets a readable
/// [`RejectReason::ProtocolVersion`] instead of a failed handshake.
pub const ALPN: &[u8] = b"ledge";

/// Largest control-stream frame payload either side sends or accepts.
pub const MAX_FRAME: usize = 64 * 1024;

/// Most entities a [`StateSnapshot`] may hold. With it, even the worst-case
/// delta fits one control frame (checked at compile time).
pub const MAX_ENTITIES: usize = 1024;

/// Largest encoded snapshot delta, in bytes.
pub const MAX_DELTA_LEN: usize = MAX_FRAME - 64;

/// Most ticks of buttons one [`InputPacket`] may carry.
pub const MAX_INPUT_HISTORY: usize = 64;

/// Ticks of buttons a client repeats in each [`InputPacket`] by default
/// (16 ticks: a quarter second of loss at 60 Hz costs nothing).
pub const DEFAULT_INPUT_REDUNDANCY: u8 = 16;

/// Largest accepted input datagram, in bytes (the largest valid
/// [`InputPacket`], 64 ticks of buttons changing every tick, is 149).
pub const MAX_INPUT_DATAGRAM: usize = 160;

// Worst case of a delta: header (1 + 10 + 10) + count (5) + removing every
// baseline entity (id 5 + ctrl 1) + every current entity in full (id 5 +
// ctrl 1 + kind 1 + five 5-byte varints + flags 5).
const _: () = assert!(1 + 10 + 10 + 5 + MAX_ENTITIES * 6 + MAX_ENTITIES * 37 <= MAX_DELTA_LEN);
