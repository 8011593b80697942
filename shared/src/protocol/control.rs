//! Control-stream messages: one reliable, ordered QUIC stream per session,
//! each message one length-prefixed frame (see [`super::frame`]).

use std::fmt;

use serde::{Deserialize, Serialize};

use super::bounded;
use super::codec::{bytes, Message};
use super::datagram::Snapshot;
use super::rotation::{LevelList, MAX_LEVELS};
use super::{ProtocolError, MAX_FRAME, PROTOCOL_VERSION};

/// Longest player name, in bytes of UTF-8.
pub const MAX_NAME_LEN: usize = 32;
/// Longest chat line, in bytes of UTF-8.
pub const MAX_CHAT_LEN: usize = 256;
/// Longest room name or level id, in bytes of UTF-8.
pub const MAX_ID_LEN: usize = 64;
/// Longest free-text reason or notice, in bytes of UTF-8.
pub const MAX_REASON_LEN: usize = 256;
/// Longest opaque simulation-config blob in [`Welcome::sim_config`].
pub const MAX_SIM_CONFIG_LEN: usize = 4096;
/// Most players one [`ServerControl::Roster`] lists, and most names a
/// client remembers: a bound on what a hostile server can make a client
/// store. A full roster is at most about 10 KiB (checked at compile time).
pub const MAX_ROSTER: usize = 256;

/// Most runs one [`Standing::top`] lists: a level's top ten.
pub const MAX_TOP: usize = 10;

/// Most rooms one [`ServerControl::Rooms`] lists, and so most rooms a
/// server may run at once (its room cap is checked against this).
pub const MAX_ROOMS: usize = 256;

// Worst-case roster frame: variant (1) + count (3) + per entry id (5) +
// name length (1) + name (MAX_NAME_LEN).
const _: () = assert!(1 + 3 + MAX_ROSTER * (5 + 1 + MAX_NAME_LEN) <= MAX_FRAME);
// Worst-case standing: variant (1) + five numbers (10 each) + two flags +
// count (1) + per run a name (1 + MAX_NAME_LEN) and a time (10).
const _: () = assert!(1 + 52 + 1 + MAX_TOP * (1 + MAX_NAME_LEN + 10) <= MAX_FRAME);
// Worst-case room list: variant (1) + count (3) + per room two strings
// (1 + MAX_ID_LEN each) and two counts (5 each).
const _: () = assert!(1 + 3 + MAX_ROOMS * (2 * (1 + MAX_ID_LEN) + 10) <= MAX_FRAME);
// A full `LevelList` fits a frame.
const _: () = assert!(16 + MAX_LEVELS * (2 * (1 + MAX_ID_LEN) + 5) <= MAX_FRAME);

/// `text` made fit for a text field of at most `max` bytes: control
/// characters become spaces and it is cut at a character boundary (for
/// messages made from errors, which may be long or span lines).
pub fn clip_text(text: &str, max: usize) -> String {
    let mut out = String::with_capacity(text.len().min(max));
    for c in text.chars().filter(|&c| !is_hidden(c)) {
        let c = if c.is_control() { ' ' } else { c };
        if out.len() + c.len_utf8() > max {
            break;
        }
        out.push(c);
    }
    out
}

/// Checks a text field: `min..=max` bytes of UTF-8, no control characters
/// (which covers newlines, escapes and NUL).
pub fn check_text(
    field: &'static str,
    text: &str,
    min: usize,
    max: usize,
) -> Result<(), ProtocolError> {
    if text.len() < min {
        return Err(ProtocolError::InvalidString {
            field,
            problem: "empty",
        });
    }
    if text.len() > max {
        return Err(ProtocolError::InvalidString {
            field,
            problem: "too long",
        });
    }
    if text.chars().any(char::is_control) {
        return Err(ProtocolError::InvalidString {
            field,
            problem: "contains control characters",
        });
    }
    if text.chars().any(is_hidden) {
        return Err(ProtocolError::InvalidString {
            field,
            problem: "contains a direction override or an invisible character",
        });
    }
    Ok(())
}

/// Characters that change how the text around them reads without showing
/// themselves: direction marks, overrides and isolates (U+202E turns what
/// follows around, so a line could show another player something its
/// sender did not type), zero-width spaces and word joiners, invisible
/// operators, fillers that render as nothing, the byte order mark and tag
/// characters (which can carry a hidden copy of any ASCII text). No text
/// field may carry them. Joiners and variation selectors stay allowed:
/// emoji (a heart with U+FE0F, families joined by U+200D) and scripts such
/// as Persian (U+200C) need them.
pub fn is_hidden(c: char) -> bool {
    matches!(
        c,
        '\u{00AD}'
            | '\u{034F}'
            | '\u{061C}'
            | '\u{115F}'
            | '\u{1160}'
            | '\u{17B4}'
            | '\u{17B5}'
            | '\u{180E}'
            | '\u{200B}'
            | '\u{200E}'
            | '\u{200F}'
            | '\u{202A}'..='\u{202E}'
            | '\u{2060}'..='\u{206F}'
            | '\u{3164}'
            | '\u{FEFF}'
            | '\u{FFA0}'
            | '\u{FFF0}'..='\u{FFF8}'
            | '\u{E0000}'..='\u{E0FFF}'
    )
}

/// Checks a player name: 1..=[`MAX_NAME_LEN`] bytes, no control
/// characters, no space at either end, every non-ASCII character one that
/// Unicode allows in identifiers (UTS 39: no invisible, format or bidi
/// characters, no fillers such as U+3164), no square brackets and not
/// "server" or "system" (server text is shown in brackets).
pub fn check_name(name: &str) -> Result<(), ProtocolError> {
    use unicode_security::GeneralSecurityProfile;
    check_text("player name", name, 1, MAX_NAME_LEN)?;
    let bad = |problem| {
        Err(ProtocolError::InvalidString {
            field: "player name",
            problem,
        })
    };
    if name.starts_with(char::is_whitespace) || name.ends_with(char::is_whitespace) {
        return bad("starts or ends with a space");
    }
    if name
        .chars()
        .any(|c| !(c.is_ascii_graphic() || c == ' ' || c.identifier_allowed()))
    {
        return bad("contains an invisible, formatting or unusual character");
    }
    if name.contains(['[', ']']) || ["server", "system"].contains(&name_key(name).as_str()) {
        return bad("looks like server text");
    }
    Ok(())
}

/// What two player names must differ in to be told apart: the UTS 39
/// confusable skeleton of the lower-cased name, so "Bot-1", "bot-l" and
/// "bоt-1" (a Cyrillic о) are one name.
pub fn name_key(name: &str) -> String {
    let lower = name.to_lowercase();
    unicode_security::confusable_detection::skeleton(&lower)
        .collect::<String>()
        .to_lowercase()
}

/// Checks a peer's protocol version against [`PROTOCOL_VERSION`].
pub fn check_version(theirs: u32) -> Result<(), ProtocolError> {
    if theirs == PROTOCOL_VERSION {
        Ok(())
    } else {
        Err(ProtocolError::BadVersion {
            ours: PROTOCOL_VERSION,
            theirs,
        })
    }
}

/// Encodes a simulation configuration for [`Welcome::sim_config`], so the
/// client predicts with exactly the server's constants. At most
/// [`MAX_SIM_CONFIG_LEN`] bytes.
pub fn encode_sim_config<T: serde::Serialize>(config: &T) -> Result<Vec<u8>, ProtocolError> {
    let bytes = bincode::serde::encode_to_vec(
        config,
        bincode::config::standard().with_limit::<MAX_SIM_CONFIG_LEN>(),
    )
    .map_err(|e| ProtocolError::malformed("sim config", format!("cannot encode: {e}")))?;
    if bytes.len() > MAX_SIM_CONFIG_LEN {
        return Err(ProtocolError::too_large(
            "sim config",
            bytes.len(),
            MAX_SIM_CONFIG_LEN,
        ));
    }
    Ok(bytes)
}

/// Decodes a [`Welcome::sim_config`] written by [`encode_sim_config`]; no
/// trailing bytes, never panics.
pub fn decode_sim_config<T: serde::de::DeserializeOwned>(bytes: &[u8]) -> Result<T, ProtocolError> {
    if bytes.len() > MAX_SIM_CONFIG_LEN {
        return Err(ProtocolError::too_large(
            "sim config",
            bytes.len(),
            MAX_SIM_CONFIG_LEN,
        ));
    }
    let (config, used) = bincode::serde::decode_from_slice(
        bytes,
        bincode::config::standard().with_limit::<MAX_SIM_CONFIG_LEN>(),
    )
    .map_err(|e| ProtocolError::malformed("sim config", e.to_string()))?;
    if used != bytes.len() {
        return Err(ProtocolError::TrailingBytes {
            what: "sim config",
            extra: bytes.len() - used,
        });
    }
    Ok(config)
}

/// A player's id, unique within one server run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct PlayerId(pub u32);

impl fmt::Display for PlayerId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{}", self.0)
    }
}

/// One player in a room, as [`ServerControl::Roster`] and
/// [`ServerControl::PlayerJoined`] announce it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RosterEntry {
    /// The player's id (its entity id in snapshots).
    pub id: PlayerId,
    /// Its display name, checked by [`check_name`].
    pub name: String,
}

/// Checks a roster: at most [`MAX_ROSTER`] entries, ids strictly ascending
/// (so no duplicates, one canonical encoding), every name valid.
pub fn check_roster(players: &[RosterEntry]) -> Result<(), ProtocolError> {
    if players.len() > MAX_ROSTER {
        return Err(ProtocolError::too_large(
            "roster",
            players.len(),
            MAX_ROSTER,
        ));
    }
    if players.windows(2).any(|w| w[0].id >= w[1].id) {
        return Err(ProtocolError::malformed(
            "roster",
            "player ids not strictly ascending",
        ));
    }
    players.iter().try_for_each(|p| check_name(&p.name))
}

/// One room, as [`ServerControl::Rooms`] lists it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RoomInfo {
    /// The room's name (what `--room` takes), checked like a room name.
    pub name: String,
    /// The level it plays (a level id, same rules).
    pub level_id: String,
    /// Players in it now.
    pub players: u32,
    /// Most players it takes.
    pub capacity: u32,
}

/// Checks a room list: at most [`MAX_ROOMS`] entries, names strictly
/// ascending (one canonical encoding, no duplicates), every text valid.
pub fn check_rooms(rooms: &[RoomInfo]) -> Result<(), ProtocolError> {
    if rooms.len() > MAX_ROOMS {
        return Err(ProtocolError::too_large(
            "room list",
            rooms.len(),
            MAX_ROOMS,
        ));
    }
    if rooms.windows(2).any(|w| w[0].name >= w[1].name) {
        return Err(ProtocolError::malformed(
            "room list",
            "room names not strictly ascending",
        ));
    }
    rooms.iter().try_for_each(|r| {
        check_text("room name", &r.name, 1, MAX_ID_LEN)?;
        check_text("level id", &r.level_id, 1, MAX_ID_LEN)
    })
}

/// A roster of at most [`MAX_ROSTER`] entries, read without trusting its count.
fn roster_list<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<RosterEntry>, D::Error> {
    bounded::seq(d, MAX_ROSTER, "roster entries")
}

/// A top list of at most [`MAX_TOP`] runs, read without trusting its count.
fn top_list<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<TopRun>, D::Error> {
    bounded::seq(d, MAX_TOP, "top runs")
}

/// A room list of at most [`MAX_ROOMS`] rooms, read without trusting its count.
fn rooms_list<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<RoomInfo>, D::Error> {
    bounded::seq(d, MAX_ROOMS, "rooms")
}

/// One player's best run on a level, as [`Standing::top`] lists it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TopRun {
    /// The player's name (records go by name), checked by [`check_name`].
    pub name: String,
    /// Its best time, milliseconds.
    pub millis: u64,
}

/// Where a finished run stands in the server's records, once stored
/// ([`ServerControl::RunRecorded`]).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Standing {
    /// This run's time, milliseconds.
    pub millis: u64,
    /// The player's best time on the level, this run included.
    pub personal_best: u64,
    /// This run beat the player's earlier best (or is its first).
    pub new_personal_best: bool,
    /// This run beat every earlier run on the level.
    pub new_record: bool,
    /// The player's place among the level's players by best time (1:
    /// first).
    pub rank: u32,
    /// The level's best players, fastest first, at most [`MAX_TOP`].
    #[serde(deserialize_with = "top_list")]
    pub top: Vec<TopRun>,
}

/// Checks a standing's list: at most [`MAX_TOP`] entries, fastest first,
/// names valid.
pub fn check_standing(standing: &Standing) -> Result<(), ProtocolError> {
    if standing.top.len() > MAX_TOP {
        return Err(ProtocolError::too_large(
            "top runs",
            standing.top.len(),
            MAX_TOP,
        ));
    }
    if standing.top.windows(2).any(|w| w[0].millis > w[1].millis) {
        return Err(ProtocolError::InvalidString {
            field: "top runs",
            problem: "not fastest first",
        });
    }
    standing.top.iter().try_for_each(|t| check_name(&t.name))
}

/// Checks a [`LevelList`]: 1..=[`MAX_LEVELS`] levels with valid ids and names,
/// one vote count per level (each at most [`MAX_ROSTER`]), `current`
/// and `next` in range.
pub fn check_level_list(list: &LevelList) -> Result<(), ProtocolError> {
    let bad = |detail| ProtocolError::malformed("level list", detail);
    if list.levels.is_empty() {
        return Err(bad("no levels"));
    }
    if list.levels.len() > MAX_LEVELS {
        return Err(ProtocolError::too_large(
            "level list",
            list.levels.len(),
            MAX_LEVELS,
        ));
    }
    for level in &list.levels {
        check_text("level id", &level.id, 1, MAX_ID_LEN)?;
        check_text("level name", &level.name, 1, MAX_ID_LEN)?;
    }
    if list.votes.len() != list.levels.len() {
        return Err(bad("not one vote count per level"));
    }
    if list.votes.iter().any(|&v| v as usize > MAX_ROSTER) {
        return Err(bad("more votes than players"));
    }
    let n = list.levels.len();
    if list.current as usize >= n || list.next as usize >= n {
        return Err(bad("current or next level out of range"));
    }
    Ok(())
}

/// Messages a client sends on the control stream.
///
/// **Compatibility:** `Hello` is variant 0 and its fields never change, so a
/// server can always read a client's version and answer
/// [`RejectReason::ProtocolVersion`] instead of failing to decode.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum ClientControl {
    /// Opens the session; must be the first message, and the only `Hello`.
    Hello {
        /// The client's [`PROTOCOL_VERSION`]. Not checked by the decoder:
        /// the server checks it ([`check_version`]) and rejects politely.
        version: u32,
        /// Display name, checked by [`check_name`].
        name: String,
    },
    /// A chat line: 1..=[`MAX_CHAT_LEN`] bytes, no control characters.
    Chat {
        /// The line.
        text: String,
    },
    /// Asks for a [`ServerControl::Pong`] with the same nonce (liveness,
    /// round-trip time).
    Ping {
        /// Echoed back.
        nonce: u64,
    },
    /// The client is leaving; the server closes the connection normally.
    Leave,
    /// Like [`ClientControl::Hello`] (and instead of it, as the first
    /// message), asking to join the named room rather than the least full
    /// one. Added in protocol version 3.
    HelloRoom {
        /// The client's [`PROTOCOL_VERSION`], checked by the server.
        version: u32,
        /// Display name, checked by [`check_name`].
        name: String,
        /// The room to join: 1..=[`MAX_ID_LEN`] bytes, no control characters.
        room: String,
    },
    /// Instead of a hello, as the first message: asks for the server's
    /// rooms. The server answers [`ServerControl::Rooms`] (or a
    /// [`ServerControl::Reject`] for another version) and closes normally.
    /// Added in protocol version 5.
    ListRooms {
        /// The client's [`PROTOCOL_VERSION`], checked by the server.
        version: u32,
    },
    /// Asks for the level bundle the [`Welcome`] offered, from byte
    /// `offset` on (0, or how much a cut download already has): the server
    /// opens a unidirectional stream and writes the bundle's bytes from
    /// there to the end. Added in protocol version 5.
    GetLevel {
        /// First byte wanted; at most the bundle's size.
        offset: u64,
        /// The bundle's SHA-256 ([`LevelOffer::sha256`] of the `Welcome` or
        /// of a [`ServerControl::LevelChange`]): a server rotating levels
        /// serves any of its own (added in protocol version 11).
        sha256: [u8; 32],
    },
    /// Instead of a hello, as the first message, after a lost connection:
    /// asks for the player the [`Welcome::session_token`] names (same id,
    /// position, coins, checkpoint), which the server keeps for its
    /// reconnect grace time. An unknown or expired token joins as a new
    /// player, like [`ClientControl::HelloRoom`] (or `Hello` without a
    /// room). Added in protocol version 5.
    Resume {
        /// The client's [`PROTOCOL_VERSION`], checked by the server.
        version: u32,
        /// Display name, checked by [`check_name`] (for a new player).
        name: String,
        /// The room for a new player (`None`: any), checked like a room name.
        room: Option<String>,
        /// The token of the session to resume.
        token: SessionToken,
    },
    /// Instead of a hello, as the first message: joins a room with no
    /// body, to watch. A spectator gets the `Welcome` (its id is in no
    /// snapshot), the snapshots and the roster like a player, sends input
    /// datagrams only for their acknowledgements (their buttons move
    /// nothing), takes no player's place (rooms have a cap of their own)
    /// and is in no roster. Added in protocol version 10.
    Spectate {
        /// The client's [`PROTOCOL_VERSION`], checked by the server.
        version: u32,
        /// Display name, checked by [`check_name`].
        name: String,
        /// The room to watch (`None`: the one with the most players),
        /// checked like a room name.
        room: Option<String>,
    },
    /// A vote for the level the room plays next (an index into the
    /// [`ServerControl::Levels`] list); a later vote replaces it. Added in
    /// protocol version 11.
    Vote {
        /// The level's index in the list.
        level: u32,
    },
}

impl ClientControl {
    /// The protocol version and name of a `Hello` or `HelloRoom`, and the
    /// room asked for (`None`: any).
    pub fn as_hello(&self) -> Option<(u32, &str, Option<&str>)> {
        match self {
            ClientControl::Hello { version, name } => Some((*version, name, None)),
            ClientControl::HelloRoom {
                version,
                name,
                room,
            } => Some((*version, name, Some(room))),
            ClientControl::Resume {
                version,
                name,
                room,
                ..
            } => Some((*version, name, room.as_deref())),
            ClientControl::Spectate {
                version,
                name,
                room,
            } => Some((*version, name, room.as_deref())),
            _ => None,
        }
    }

    /// Whether this first message asks to watch ([`ClientControl::Spectate`]).
    pub fn is_spectate(&self) -> bool {
        matches!(self, ClientControl::Spectate { .. })
    }

    /// The session token of a `Resume`.
    pub fn resume_token(&self) -> Option<SessionToken> {
        match self {
            ClientControl::Resume { token, .. } => Some(*token),
            _ => None,
        }
    }
}

/// Names a player's session to the server, so a client that lost its
/// connection gets the same player back ([`ClientControl::Resume`]): 128
/// random bits, unguessable, issued in the [`Welcome`].
#[derive(Clone, Copy, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct SessionToken(pub [u8; 16]);

impl fmt::Debug for SessionToken {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // A secret: never in logs.
        f.write_str("SessionToken(..)")
    }
}

impl Message for ClientControl {
    const WHAT: &'static str = "client control message";
    const MAX_LEN: usize = MAX_FRAME;

    fn validate(&self) -> Result<(), ProtocolError> {
        match self {
            ClientControl::Hello { name, .. } => check_name(name),
            ClientControl::HelloRoom { name, room, .. } => {
                check_name(name)?;
                check_text("room name", room, 1, MAX_ID_LEN)
            }
            ClientControl::Resume { name, room, .. }
            | ClientControl::Spectate { name, room, .. } => {
                check_name(name)?;
                room.as_deref()
                    .map_or(Ok(()), |r| check_text("room name", r, 1, MAX_ID_LEN))
            }
            ClientControl::Chat { text } => check_text("chat text", text, 1, MAX_CHAT_LEN),
            ClientControl::Ping { .. }
            | ClientControl::Leave
            | ClientControl::ListRooms { .. }
            | ClientControl::GetLevel { .. } => Ok(()),
            ClientControl::Vote { level } => {
                if *level as usize >= MAX_LEVELS {
                    return Err(ProtocolError::malformed("vote", "no such level"));
                }
                Ok(())
            }
        }
    }
}

/// Tick timing of a room, sent in [`Welcome`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct NetTiming {
    /// Simulation ticks per second (60 by default).
    pub tick_rate: u32,
    /// A snapshot is sent every this many ticks (snapshot rate =
    /// `tick_rate / snapshot_interval`).
    pub snapshot_interval: u32,
    /// How many ticks of input each [`super::InputPacket`] should repeat.
    pub input_redundancy: u8,
}

impl NetTiming {
    fn validate(&self) -> Result<(), ProtocolError> {
        let bad = |detail| ProtocolError::malformed("welcome timing", detail);
        if self.tick_rate == 0 || self.tick_rate > 1000 {
            return Err(bad("tick rate outside 1..=1000 Hz"));
        }
        if self.snapshot_interval == 0 || self.snapshot_interval > self.tick_rate {
            return Err(bad("snapshot interval outside 1..=tick rate"));
        }
        if self.input_redundancy == 0 || self.input_redundancy as usize > super::MAX_INPUT_HISTORY {
            return Err(bad("input redundancy outside 1..=MAX_INPUT_HISTORY"));
        }
        Ok(())
    }
}

/// Largest level bundle any server may offer, bytes: a client refuses a
/// bigger offer before downloading anything. (A server's own cap is
/// usually lower.)
pub const MAX_LEVEL_BUNDLE: u64 = 96 << 20;

/// The level bundle a server plays (the level and what clients draw it
/// with, as `ledge_levels::LevelBundle` encodes it): what a client needs to
/// find it in its cache or download it with [`ClientControl::GetLevel`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct LevelOffer {
    /// SHA-256 of the bundle's bytes.
    pub sha256: [u8; 32],
    /// The bundle's size in bytes. Not checked by the decoder: a client
    /// refuses more than [`MAX_LEVEL_BUNDLE`] itself, saying so.
    pub size: u64,
}

impl LevelOffer {
    /// The hash in lower-case hex (64 digits): the bundle's name in caches.
    pub fn hex(&self) -> String {
        self.sha256.iter().map(|b| format!("{b:02x}")).collect()
    }
}

/// The server's answer to an accepted `Hello`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Welcome {
    /// The id the server gave this player.
    pub player_id: PlayerId,
    /// The room joined (1..=[`MAX_ID_LEN`] bytes, no control characters).
    pub room: String,
    /// The level being played (same rules as `room`).
    pub level_id: String,
    /// Hash of the level's content, so a client can check its copy.
    pub level_hash: u64,
    /// The level bundle: its hash and size (added in protocol version 5).
    pub level: LevelOffer,
    /// Resumes this player after a lost connection
    /// ([`ClientControl::Resume`]; added in protocol version 5).
    pub session_token: SessionToken,
    /// The room's simulation tick when the player joined.
    pub server_tick: u64,
    /// Tick and snapshot rates.
    pub timing: NetTiming,
    /// The simulation configuration the client must predict with, encoded by
    /// the world (opaque here), at most [`MAX_SIM_CONFIG_LEN`] bytes.
    #[serde(with = "bytes")]
    pub sim_config: Vec<u8>,
}

impl Welcome {
    /// Checks the names, the timing and the config's size.
    fn validate(&self) -> Result<(), ProtocolError> {
        check_text("room name", &self.room, 1, MAX_ID_LEN)?;
        check_text("level id", &self.level_id, 1, MAX_ID_LEN)?;
        self.timing.validate()?;
        if self.sim_config.len() > MAX_SIM_CONFIG_LEN {
            return Err(ProtocolError::too_large(
                "welcome sim config",
                self.sim_config.len(),
                MAX_SIM_CONFIG_LEN,
            ));
        }
        Ok(())
    }
}

/// Why the server refused a `Hello`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum RejectReason {
    /// The client speaks another protocol version.
    ProtocolVersion {
        /// The version the server speaks.
        server: u32,
        /// The version the client announced.
        client: u32,
    },
    /// The name breaks [`check_name`]'s rules.
    InvalidName,
    /// The room is full.
    RoomFull,
    /// The server is shutting down.
    ShuttingDown,
    /// Anything else, explained (at most [`MAX_REASON_LEN`] bytes).
    Other {
        /// Why.
        reason: String,
    },
}

impl fmt::Display for RejectReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RejectReason::ProtocolVersion { server, client } => write!(
                f,
                "protocol version mismatch: server speaks {server}, client {client}"
            ),
            RejectReason::InvalidName => write!(
                f,
                "invalid player name: 1 to {MAX_NAME_LEN} bytes of visible characters, no \
                 space at either end, no brackets"
            ),
            RejectReason::RoomFull => f.write_str("the room is full"),
            RejectReason::ShuttingDown => f.write_str("the server is shutting down"),
            RejectReason::Other { reason } => f.write_str(reason),
        }
    }
}

/// What a [`ServerControl::Notice`] announces.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum NoticeKind {
    /// The server is shutting down; the connection closes next.
    Shutdown,
    /// This client is being disconnected.
    Kick {
        /// Why (at most [`MAX_REASON_LEN`] bytes).
        reason: String,
    },
    /// Informational text for the player (at most [`MAX_REASON_LEN`] bytes).
    Info {
        /// The text.
        text: String,
    },
}

/// Messages the server sends on the control stream.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum ServerControl {
    /// The `Hello` was accepted.
    Welcome(Welcome),
    /// The `Hello` was refused; the server closes the connection next.
    Reject {
        /// Why.
        reason: RejectReason,
    },
    /// A chat line from a player.
    Chat {
        /// Who said it.
        from: PlayerId,
        /// The line (same rules as [`ClientControl::Chat`]).
        text: String,
    },
    /// A server announcement.
    Notice {
        /// What it announces.
        kind: NoticeKind,
    },
    /// A snapshot too large for one datagram (see [`super::Outgoing`]); it
    /// is the same [`Snapshot`] (full or delta) a datagram would carry.
    FullState(Snapshot),
    /// Answer to [`ClientControl::Ping`] with the same nonce.
    Pong {
        /// The ping's nonce.
        nonce: u64,
    },
    /// Everyone in the room (the receiver included), ascending by id, at
    /// most [`MAX_ROSTER`] ([`check_roster`]). Sent once, right after the
    /// `Welcome`; [`ServerControl::PlayerJoined`] and
    /// [`ServerControl::PlayerLeft`] keep it current. Added in protocol
    /// version 4.
    Roster {
        /// The players.
        #[serde(deserialize_with = "roster_list")]
        players: Vec<RosterEntry>,
    },
    /// A player joined the room (sent to everyone else in it). Added in
    /// protocol version 4.
    PlayerJoined(RosterEntry),
    /// A player left the room. Added in protocol version 4.
    PlayerLeft {
        /// Who left.
        id: PlayerId,
    },
    /// Answer to [`ClientControl::ListRooms`]: every room, ascending by
    /// name, at most [`MAX_ROOMS`] ([`check_rooms`]); the server closes the
    /// connection next. Added in protocol version 5.
    Rooms {
        /// The rooms.
        #[serde(deserialize_with = "rooms_list")]
        rooms: Vec<RoomInfo>,
    },
    /// The receiver's run finished and is stored in the server's records
    /// (sent only once it is: a run the server says is recorded survives
    /// the server being killed). Added in protocol version 9.
    RunRecorded(Standing),
    /// The receiver's run finished but was not stored: why (the records
    /// are off, or the database failed). Added in protocol version 9.
    RunNotRecorded {
        /// Why, for the results card.
        reason: String,
    },
    /// A run to race against, as its replay file
    /// (`ledge_shared::replay::decode`): the level's record, or the
    /// receiver's own best. Sent after the roster when the server has one.
    /// Added in protocol version 10.
    Ghost(GhostRun),
    /// The room's levels, votes and when it moves on: after the roster on
    /// joining, then whenever any of it changes. Added in protocol
    /// version 11.
    Levels(LevelList),
    /// The room moved to another level. This `Welcome` replaces the one
    /// the session began with: same player id (its `session_token` is not
    /// sent: the first one stays valid), the new level (download it as on
    /// joining, [`ClientControl::GetLevel`]), the room's tick at the change
    /// and the new simulation config. Snapshots of earlier ticks are of the
    /// old level: drop them; those of the new level come on the control
    /// stream, after this message, until one of them is acknowledged.
    /// Added in protocol version 11.
    LevelChange(Welcome),
}

/// A ghost: who ran it, in what time, and the run's replay.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct GhostRun {
    /// The level's record (`false`: the receiver's own best).
    pub record: bool,
    /// Who ran it (checked as a player name).
    pub player: String,
    /// Its time, milliseconds.
    pub millis: u64,
    /// The run's replay file, at most [`MAX_GHOST_REPLAY`] bytes.
    #[serde(with = "super::codec::bytes")]
    pub replay: Vec<u8>,
}

/// Most bytes of a ghost's replay in a [`ServerControl::Ghost`] (a run
/// replay of a few minutes among a few players; a larger one is not sent).
pub const MAX_GHOST_REPLAY: usize = MAX_FRAME - 1024;

impl ServerControl {
    /// The message's name, for errors and logs (never its contents, which
    /// may be large or hostile).
    pub fn kind(&self) -> &'static str {
        match self {
            ServerControl::Welcome(_) => "Welcome",
            ServerControl::Reject { .. } => "Reject",
            ServerControl::Chat { .. } => "Chat",
            ServerControl::Notice { .. } => "Notice",
            ServerControl::FullState(_) => "FullState",
            ServerControl::Pong { .. } => "Pong",
            ServerControl::Roster { .. } => "Roster",
            ServerControl::PlayerJoined(_) => "PlayerJoined",
            ServerControl::PlayerLeft { .. } => "PlayerLeft",
            ServerControl::Rooms { .. } => "Rooms",
            ServerControl::RunRecorded(_) => "RunRecorded",
            ServerControl::RunNotRecorded { .. } => "RunNotRecorded",
            ServerControl::Ghost(_) => "Ghost",
            ServerControl::Levels(_) => "Levels",
            ServerControl::LevelChange(_) => "LevelChange",
        }
    }
}

impl Message for ServerControl {
    const WHAT: &'static str = "server control message";
    const MAX_LEN: usize = MAX_FRAME;

    fn validate(&self) -> Result<(), ProtocolError> {
        match self {
            ServerControl::Welcome(w) | ServerControl::LevelChange(w) => w.validate(),
            ServerControl::Levels(list) => check_level_list(list),
            ServerControl::Reject { reason } => match reason {
                RejectReason::Other { reason } => {
                    check_text("reject reason", reason, 0, MAX_REASON_LEN)
                }
                _ => Ok(()),
            },
            ServerControl::Chat { text, .. } => check_text("chat text", text, 1, MAX_CHAT_LEN),
            ServerControl::Notice { kind } => match kind {
                NoticeKind::Shutdown => Ok(()),
                NoticeKind::Kick { reason } => check_text("kick reason", reason, 0, MAX_REASON_LEN),
                NoticeKind::Info { text } => check_text("notice text", text, 0, MAX_REASON_LEN),
            },
            ServerControl::FullState(snapshot) => snapshot.validate(),
            ServerControl::Pong { .. } | ServerControl::PlayerLeft { .. } => Ok(()),
            ServerControl::Roster { players } => check_roster(players),
            ServerControl::PlayerJoined(entry) => check_name(&entry.name),
            ServerControl::Rooms { rooms } => check_rooms(rooms),
            ServerControl::RunRecorded(standing) => check_standing(standing),
            ServerControl::RunNotRecorded { reason } => {
                check_text("not recorded reason", reason, 0, MAX_REASON_LEN)
            }
            ServerControl::Ghost(ghost) => {
                check_name(&ghost.player)?;
                if ghost.replay.len() > MAX_GHOST_REPLAY {
                    return Err(ProtocolError::too_large(
                        "ghost replay",
                        ghost.replay.len(),
                        MAX_GHOST_REPLAY,
                    ));
                }
                Ok(())
            }
        }
    }
}

/// Application close codes of a QUIC connection, so either side can tell
/// why the other hung up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum CloseCode {
    /// Normal end of a session (the client left).
    Normal = 0,
    /// The peer sent a malformed or unexpected frame or message.
    ProtocolViolation = 1,
    /// The server refused the `Hello` (a [`ServerControl::Reject`] precedes it).
    Rejected = 2,
    /// The peer did not send what was due in time.
    Timeout = 3,
    /// The server is shutting down.
    ServerShutdown = 4,
    /// The server kicked the client (a [`NoticeKind::Kick`] precedes it).
    Kicked = 5,
}

impl CloseCode {
    /// The code as sent on the wire.
    pub fn to_u32(self) -> u32 {
        self as u32
    }

    /// Decodes a wire code; `None` for codes this version does not know.
    pub fn from_u32(code: u32) -> Option<CloseCode> {
        Some(match code {
            0 => CloseCode::Normal,
            1 => CloseCode::ProtocolViolation,
            2 => CloseCode::Rejected,
            3 => CloseCode::Timeout,
            4 => CloseCode::ServerShutdown,
            5 => CloseCode::Kicked,
            _ => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hello_room_round_trips_and_is_checked() {
        let m = ClientControl::HelloRoom {
            version: PROTOCOL_VERSION,
            name: "ana".into(),
            room: "room-2".into(),
        };
        let back = ClientControl::decode(&m.encode().unwrap()).unwrap();
        assert_eq!(back, m);
        assert_eq!(
            back.as_hello(),
            Some((PROTOCOL_VERSION, "ana", Some("room-2")))
        );
        // Appended after the existing variants: their encodings are unchanged.
        assert_eq!(m.encode().unwrap()[0], 4);
        let hello = ClientControl::Hello {
            version: 7,
            name: "bo".into(),
        };
        assert_eq!(hello.as_hello(), Some((7, "bo", None)));
        assert_eq!(ClientControl::Leave.as_hello(), None);
        for room in ["", "a\nb"] {
            let bad = ClientControl::HelloRoom {
                version: PROTOCOL_VERSION,
                name: "ana".into(),
                room: room.into(),
            };
            assert!(bad.encode().is_err(), "{room:?}");
        }
        let long = ClientControl::HelloRoom {
            version: PROTOCOL_VERSION,
            name: "ana".into(),
            room: "r".repeat(MAX_ID_LEN + 1),
        };
        assert!(long.encode().is_err());
    }

    fn room(name: &str) -> RoomInfo {
        RoomInfo {
            name: name.into(),
            level_id: "default".into(),
            players: 2,
            capacity: 16,
        }
    }

    #[test]
    fn room_lists_round_trip_and_are_bounded() {
        let ask = ClientControl::ListRooms {
            version: PROTOCOL_VERSION,
        };
        assert_eq!(ClientControl::decode(&ask.encode().unwrap()).unwrap(), ask);
        assert_eq!(ask.as_hello(), None);
        let list = ServerControl::Rooms {
            rooms: vec![room("friends"), room("room-1")],
        };
        assert_eq!(
            ServerControl::decode(&list.encode().unwrap()).unwrap(),
            list
        );
        // Out of order, duplicated or badly named: refused.
        for rooms in [
            vec![room("room-1"), room("friends")],
            vec![room("a"), room("a")],
            vec![room("")],
            vec![room("a\u{7}")],
        ] {
            let bad = ServerControl::Rooms { rooms };
            assert!(bad.encode().is_err(), "{bad:?}");
        }
        // The most rooms fit one frame; one more is refused while decoding,
        // however the count claims.
        let most: Vec<RoomInfo> = (0..MAX_ROOMS)
            .map(|i| RoomInfo {
                name: format!("{i:0>64}"),
                level_id: "l".repeat(MAX_ID_LEN),
                players: u32::MAX,
                capacity: u32::MAX,
            })
            .collect();
        let full = ServerControl::Rooms { rooms: most };
        let bytes = full.encode().unwrap();
        assert!(bytes.len() <= MAX_FRAME);
        assert_eq!(ServerControl::decode(&bytes).unwrap(), full);
        let mut over = full.clone();
        if let ServerControl::Rooms { rooms } = &mut over {
            rooms.push(room(&"z".repeat(MAX_ID_LEN)));
        }
        let over = bincode::serde::encode_to_vec(&over, bincode::config::standard()).unwrap();
        let err = ServerControl::decode(&over).unwrap_err().to_string();
        assert!(err.contains("more than 256 rooms"), "{err}");
    }

    #[test]
    fn new_first_messages_keep_their_variant_numbers_and_resume_hides_its_token() {
        let list = ClientControl::ListRooms { version: 5 };
        let get = ClientControl::GetLevel {
            offset: 3,
            sha256: [7; 32],
        };
        let resume = ClientControl::Resume {
            version: PROTOCOL_VERSION,
            name: "ana".into(),
            room: Some("friends".into()),
            token: SessionToken([7; 16]),
        };
        assert_eq!(list.encode().unwrap()[0], 5);
        assert_eq!(get.encode().unwrap()[0], 6);
        assert_eq!(resume.encode().unwrap()[0], 7);
        assert_eq!(
            ClientControl::decode(&resume.encode().unwrap()).unwrap(),
            resume
        );
        assert_eq!(
            resume.as_hello(),
            Some((PROTOCOL_VERSION, "ana", Some("friends")))
        );
        assert_eq!(resume.resume_token(), Some(SessionToken([7; 16])));
        assert!(!format!("{resume:?}").contains("7, 7"), "{resume:?}");
        let bad = ClientControl::Resume {
            version: PROTOCOL_VERSION,
            name: String::new(),
            room: None,
            token: SessionToken::default(),
        };
        assert!(bad.encode().is_err());
    }

    #[test]
    fn names_are_visible_and_told_apart_beyond_case_and_look_alikes() {
        for ok in ["ana", "bot-1", "Zoë", "дима", "李", "a b", "<ana>"] {
            assert!(check_name(ok).is_ok(), "{ok:?}");
        }
        for bad in [
            "bot\u{200B}1",
            "\u{202E}ana",
            "\u{FEFF}ana",
            "\u{3164}",
            " ",
            " ana",
            "ana ",
            "[server]",
            "Server",
            "ana\u{1F600}",
        ] {
            assert!(check_name(bad).is_err(), "{bad:?}");
        }
        assert_eq!(name_key("Bot-1"), name_key("bot-l"));
        assert_eq!(name_key("bot-1"), name_key("b\u{043E}t-1"));
        assert_ne!(name_key("bot-1"), name_key("bot-2"));
    }
}
