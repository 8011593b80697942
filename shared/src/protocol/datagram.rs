//! Unreliable datagrams: inputs (client to server) and snapshots (server to
//! client). The choice between a datagram and the control stream for a
//! snapshot too large for one is in [`super::outgoing`].

use serde::{Deserialize, Serialize};

use super::codec::{bytes, Message};
use super::snapshot::{decode_delta, encode_delta, peek_delta, StateSnapshot};
use super::{ProtocolError, MAX_DELTA_LEN, MAX_FRAME, MAX_INPUT_DATAGRAM, MAX_INPUT_HISTORY};
use crate::input::Buttons;

/// An [`InputPacket`] as it goes on the wire: the buttons as runs of equal
/// ticks (a held button costs two bytes however long it is held) and the
/// acknowledgement relative to the newest tick (one byte when near).
#[derive(Serialize, Deserialize)]
struct InputWire {
    newest_tick: u64,
    /// `(ticks - 1, buttons)` byte pairs, newest run first.
    #[serde(with = "bytes")]
    runs: Vec<u8>,
    /// `ack_snapshot - newest_tick`, wrapping (any `u64` round-trips).
    ack: Option<i64>,
    hold: bool,
}

impl From<InputPacket> for InputWire {
    fn from(p: InputPacket) -> InputWire {
        let mut runs: Vec<u8> = Vec::new();
        for b in &p.buttons {
            match runs.len() {
                n if n >= 2 && runs[n - 1] == b.0 && runs[n - 2] < u8::MAX => runs[n - 2] += 1,
                _ => runs.extend([0, b.0]),
            }
        }
        InputWire {
            newest_tick: p.newest_tick,
            runs,
            ack: p.ack_snapshot.map(|a| a.wrapping_sub(p.newest_tick) as i64),
            hold: p.hold,
        }
    }
}

impl TryFrom<InputWire> for InputPacket {
    type Error = String;

    fn try_from(w: InputWire) -> Result<InputPacket, String> {
        if w.runs.len() % 2 != 0 {
            return Err("input runs: an odd number of bytes".into());
        }
        let mut buttons = Vec::new();
        for run in w.runs.chunks_exact(2) {
            let ticks = usize::from(run[0]) + 1;
            // Bounded before growing: never more than the history allows.
            if buttons.len() + ticks > MAX_INPUT_HISTORY {
                return Err(format!(
                    "input history: over {MAX_INPUT_HISTORY} ticks of buttons"
                ));
            }
            buttons.extend(std::iter::repeat_n(Buttons(run[1]), ticks));
        }
        Ok(InputPacket {
            newest_tick: w.newest_tick,
            buttons,
            ack_snapshot: w.ack.map(|d| w.newest_tick.wrapping_add(d as u64)),
            hold: w.hold,
        })
    }
}

/// A client's input datagram, sent every tick or two: the buttons of the
/// newest tick and of the ticks before it, so one lost datagram (or several
/// in a row, up to the redundancy) costs nothing.
///
/// A client whose buttons and world are still goes *quiet*: it sends a
/// packet with `hold` set and then only a few a second until its buttons
/// change, and the server applies the held buttons to the ticks in between.
///
/// On the wire (`InputWire`) the buttons go as runs of equal ticks and the
/// acknowledgement as an offset from `newest_tick`: 16 ticks of one held
/// button and a recent acknowledgement take about 10 bytes.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(into = "InputWire", try_from = "InputWire")]
pub struct InputPacket {
    /// The tick of `buttons[0]`.
    pub newest_tick: u64,
    /// Buttons newest first: `buttons[i]` is for tick `newest_tick - i`.
    /// 1..=[`MAX_INPUT_HISTORY`] entries, never before tick 0.
    pub buttons: Vec<Buttons>,
    /// Tick of the newest snapshot the client has decoded (its delta
    /// baseline), `None` before the first.
    pub ack_snapshot: Option<u64>,
    /// The buttons of `newest_tick` stay pressed after it until the next
    /// packet: the server applies them to the ticks it gets no input for
    /// (not counted as starved) instead of waiting for them.
    pub hold: bool,
}

impl InputPacket {
    /// A packet for `newest_tick` repeating `newest_first` (truncated to
    /// [`MAX_INPUT_HISTORY`] and to the ticks that exist).
    pub fn new(newest_tick: u64, newest_first: &[Buttons], ack_snapshot: Option<u64>) -> Self {
        let n = newest_first
            .len()
            .min(MAX_INPUT_HISTORY)
            .min(usize::try_from(newest_tick).map_or(usize::MAX, |t| t.saturating_add(1)));
        InputPacket {
            newest_tick,
            buttons: newest_first[..n].to_vec(),
            ack_snapshot,
            hold: false,
        }
    }

    /// The same packet saying whether its newest buttons are held after it
    /// ([`InputPacket::hold`]).
    pub fn holding(self, hold: bool) -> Self {
        InputPacket { hold, ..self }
    }

    /// Oldest tick carried.
    pub fn oldest_tick(&self) -> u64 {
        self.newest_tick
            .saturating_sub(self.buttons.len().saturating_sub(1) as u64)
    }

    /// `(tick, buttons)` pairs, newest first.
    pub fn ticks(&self) -> impl Iterator<Item = (u64, Buttons)> + '_ {
        self.buttons
            .iter()
            .enumerate()
            .map_while(|(i, b)| Some((self.newest_tick.checked_sub(i as u64)?, *b)))
    }

    /// The buttons carried for `tick`, if any.
    pub fn get(&self, tick: u64) -> Option<Buttons> {
        let back = self.newest_tick.checked_sub(tick)?;
        self.buttons.get(usize::try_from(back).ok()?).copied()
    }
}

impl Message for InputPacket {
    const WHAT: &'static str = "input packet";
    const MAX_LEN: usize = MAX_INPUT_DATAGRAM;

    fn validate(&self) -> Result<(), ProtocolError> {
        let n = self.buttons.len();
        if n == 0 {
            return Err(ProtocolError::malformed(Self::WHAT, "no buttons"));
        }
        if n > MAX_INPUT_HISTORY {
            return Err(ProtocolError::too_large(
                "input history",
                n,
                MAX_INPUT_HISTORY,
            ));
        }
        if (n - 1) as u64 > self.newest_tick {
            return Err(ProtocolError::malformed(
                Self::WHAT,
                "buttons for ticks before 0",
            ));
        }
        Ok(())
    }
}

/// How early (positive) or late (negative), in ticks, an input for
/// `input_tick` arrived when the server was about to simulate `server_tick`
/// (saturating): the value of [`Snapshot::input_timing`]. Clients steer
/// their clock to keep it slightly positive.
pub fn input_timing(input_tick: u64, server_tick: u64) -> i16 {
    let d = input_tick as i128 - server_tick as i128;
    d.clamp(i16::MIN as i128, i16::MAX as i128) as i16
}

/// A snapshot for one client: a delta-encoded [`StateSnapshot`] and that
/// client's input bookkeeping. Sent as a datagram, or inside
/// [`ServerControl::FullState`](super::ServerControl::FullState) when it does not fit one.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Snapshot {
    /// The tick of the state.
    pub tick: u64,
    /// The state the delta is against (a snapshot the client acknowledged);
    /// `None`: a full snapshot.
    pub baseline_tick: Option<u64>,
    /// Newest tick of this client's input the server has applied, `None`
    /// before the first: the client replays its inputs after it.
    pub last_input_tick: Option<u64>,
    /// How early (+) or late (-), in ticks, this client's inputs arrive
    /// (see [`input_timing`]).
    pub input_timing: i16,
    /// Ticks since the previous snapshot the server sent this client (0:
    /// this is the first). More than the snapshot interval: the snapshots
    /// between were not sent because nothing changed, so the state of the
    /// previous one held until `tick` less one interval. Lets the client
    /// tell a skipped snapshot from a lost one (its loss figure) and hold
    /// remote players still where they were still.
    pub since_previous: u32,
    /// The state, encoded by [`encode_delta`] (at most [`MAX_DELTA_LEN`]).
    #[serde(with = "bytes")]
    pub delta: Vec<u8>,
}

impl Snapshot {
    /// Encodes `current` against `baseline` (`None`: full).
    pub fn new(
        baseline: Option<&StateSnapshot>,
        current: &StateSnapshot,
        last_input_tick: Option<u64>,
        input_timing: i16,
    ) -> Result<Self, ProtocolError> {
        let mut delta = Vec::new();
        encode_delta(baseline, current, &mut delta)?;
        if delta.len() > MAX_DELTA_LEN {
            return Err(ProtocolError::too_large(
                "snapshot delta",
                delta.len(),
                MAX_DELTA_LEN,
            ));
        }
        Ok(Snapshot {
            tick: current.tick,
            baseline_tick: baseline.map(|b| b.tick),
            last_input_tick,
            input_timing,
            since_previous: 0,
            delta,
        })
    }

    /// The tick of the previous snapshot sent to this client
    /// ([`Snapshot::since_previous`]), `None` for the first.
    pub fn previous_tick(&self) -> Option<u64> {
        match self.since_previous {
            0 => None,
            gap => self.tick.checked_sub(u64::from(gap)),
        }
    }

    /// Decodes the state against `baseline`, which must be the snapshot of
    /// [`Snapshot::baseline_tick`] (else [`ProtocolError::BaselineMismatch`]).
    pub fn decode_state(
        &self,
        baseline: Option<&StateSnapshot>,
    ) -> Result<StateSnapshot, ProtocolError> {
        let given = baseline.map(|b| b.tick);
        if given != self.baseline_tick {
            return Err(ProtocolError::BaselineMismatch {
                needed: self.baseline_tick,
                given,
            });
        }
        let state = decode_delta(baseline, &self.delta)?;
        if state.tick != self.tick {
            return Err(ProtocolError::malformed(
                Self::WHAT,
                "delta tick differs from the envelope's",
            ));
        }
        Ok(state)
    }
}

impl Message for Snapshot {
    const WHAT: &'static str = "snapshot";
    // Also carried in a control frame, with a one-byte variant tag.
    const MAX_LEN: usize = MAX_FRAME - 1;

    fn validate(&self) -> Result<(), ProtocolError> {
        if self.delta.len() > MAX_DELTA_LEN {
            return Err(ProtocolError::too_large(
                "snapshot delta",
                self.delta.len(),
                MAX_DELTA_LEN,
            ));
        }
        if peek_delta(&self.delta)? != (self.tick, self.baseline_tick) {
            return Err(ProtocolError::malformed(
                Self::WHAT,
                "delta header disagrees with the envelope's ticks",
            ));
        }
        Ok(())
    }
}
