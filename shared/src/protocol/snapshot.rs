//! The replicated state model and its Quake 3 style delta encoding.
//!
//! The protocol knows nothing about the world: the server turns whatever it
//! replicates into [`EntityState`]s (a small fixed set of integer fields),
//! collects them into a [`StateSnapshot`] per tick, and encodes each
//! snapshot as a delta against the last one the client acknowledged.
//!
//! # Delta format
//!
//! Hand-written, little and canonical (see `docs/PROTOCOL.md`); varints are
//! LEB128, signed values zig-zag mapped:
//!
//! ```text
//! header   u8        bit 0: a baseline follows; bits 1..8 must be 0
//! tick     varint    the snapshot's tick
//! [back]   varint    tick - baseline tick        (only with a baseline)
//! count    varint    number of entries
//! entries  count x { id_gap varint, ctrl u8, fields... }   ids ascending
//! ```
//!
//! An entry's id is `previous id + 1 + id_gap` (the first: `id_gap`). `ctrl`
//! `0x80` removes a baseline entity; otherwise its low 7 bits say which
//! fields follow, in [`Field`] order, each a delta from the baseline entity
//! *extrapolated* to the snapshot's tick ([`extrapolate`]: its position
//! moved by its velocity times the ticks between them), or from an all-zero
//! entity when the id is new:
//!
//! * `kind`: the new byte;
//! * `pos.x`, `pos.y`, `vel.x`, `vel.y`, `aux`: zig-zag varint of the
//!   wrapping `i32` difference;
//! * `flags`: varint of the XOR with the old flags.
//!
//! Entities present in both whose state is exactly the extrapolated
//! baseline are not written at all, so an idle world, and anything moving at
//! a constant velocity (walkers between turns, running players, platforms),
//! costs nothing beyond the header. The decoder accepts only what the encoder
//! produces: a field flagged but unchanged, an unchanged entity listed, a
//! removal of an unknown id, ids out of order, non-shortest varints and
//! trailing bytes are all errors.

use glam::IVec2;
use serde::{Deserialize, Serialize};

use super::varint::{put_u32, put_u64, unzigzag32, zigzag32, Reader};
use super::{ProtocolError, MAX_ENTITIES};

/// One replicated entity at one tick: integers only, so deltas are exact.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct EntityState {
    /// Stable id, unique within a snapshot.
    pub id: u32,
    /// What the entity is (player, enemy, platform...); the world's numbering.
    pub kind: u8,
    /// Position in units.
    pub pos: IVec2,
    /// Velocity in units per tick.
    pub vel: IVec2,
    /// State bits (facing, grounded, ...); the world's numbering, except
    /// [`EntityState::CLIENT_SIMULATED`].
    pub flags: u32,
    /// One spare integer (animation frame, owner id, timer...).
    pub aux: i32,
}

impl EntityState {
    /// Flag bit reserved by convention for entities whose motion clients can
    /// simulate themselves (a platform on a fixed path): [`is_replicated`]
    /// leaves them out of snapshots.
    pub const CLIENT_SIMULATED: u32 = 1 << 31;

    /// An entity with this id and every other field zero: the baseline a new
    /// entity is delta-encoded against.
    pub const fn zero(id: u32) -> Self {
        EntityState {
            id,
            kind: 0,
            pos: IVec2::ZERO,
            vel: IVec2::ZERO,
            flags: 0,
            aux: 0,
        }
    }
}

/// The default snapshot filter: keeps every entity not flagged
/// [`EntityState::CLIENT_SIMULATED`]. Pass any other predicate to
/// [`StateSnapshot::capture`] to choose differently.
pub fn is_replicated(entity: &EntityState) -> bool {
    entity.flags & EntityState::CLIENT_SIMULATED == 0
}

/// The fields of an [`EntityState`] a delta can change, in wire order; the
/// discriminant is the field's bit in an entry's control byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum Field {
    /// [`EntityState::kind`].
    Kind = 1 << 0,
    /// `pos.x`.
    PosX = 1 << 1,
    /// `pos.y`.
    PosY = 1 << 2,
    /// `vel.x`.
    VelX = 1 << 3,
    /// `vel.y`.
    VelY = 1 << 4,
    /// [`EntityState::flags`].
    Flags = 1 << 5,
    /// [`EntityState::aux`].
    Aux = 1 << 6,
}

/// Control byte of an entry that removes a baseline entity.
const REMOVED: u8 = 0x80;
/// Header bit: a baseline tick follows.
const HAS_BASELINE: u8 = 1;

/// Every replicated entity at one tick, sorted by id (ids unique), at most
/// [`MAX_ENTITIES`] of them.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct StateSnapshot {
    /// The simulation tick this state is the result of.
    pub tick: u64,
    /// The entities, strictly ascending by id.
    pub entities: Vec<EntityState>,
}

impl StateSnapshot {
    /// Whether `later` is this state with nothing changed but time: the
    /// same entities, each exactly [`extrapolate`]d by the ticks between
    /// (a still world, run timers counting, anything moving at a constant
    /// velocity). A delta from this state to `later` is empty, and a client
    /// holding this state can rebuild every tick up to `later` from it.
    pub fn extrapolates_to(&self, later: &StateSnapshot) -> bool {
        later
            .tick
            .checked_sub(self.tick)
            .is_some_and(|back| extrapolates_to(&self.entities, &later.entities, back))
    }

    /// A snapshot of the entities `keep` accepts (for example
    /// [`is_replicated`]), in any order; sorts them by id.
    ///
    /// Errors if two entities share an id or more than [`MAX_ENTITIES`]
    /// remain.
    pub fn capture(
        tick: u64,
        entities: impl IntoIterator<Item = EntityState>,
        keep: impl FnMut(&EntityState) -> bool,
    ) -> Result<Self, ProtocolError> {
        let mut entities: Vec<EntityState> = entities.into_iter().filter(keep).collect();
        entities.sort_unstable_by_key(|e| e.id);
        let snapshot = StateSnapshot { tick, entities };
        snapshot.validate()?;
        Ok(snapshot)
    }

    /// Checks the invariants: ids strictly ascending, at most
    /// [`MAX_ENTITIES`] entities.
    pub fn validate(&self) -> Result<(), ProtocolError> {
        if self.entities.len() > MAX_ENTITIES {
            return Err(ProtocolError::too_large(
                "snapshot entity count",
                self.entities.len(),
                MAX_ENTITIES,
            ));
        }
        if self.entities.windows(2).any(|w| w[0].id >= w[1].id) {
            return Err(ProtocolError::InvalidValue {
                what: "snapshot",
                detail: "entity ids are not strictly ascending (duplicate or unsorted)",
            });
        }
        Ok(())
    }

    /// The entity with this id.
    pub fn get(&self, id: u32) -> Option<&EntityState> {
        self.entities
            .binary_search_by_key(&id, |e| e.id)
            .ok()
            .map(|i| &self.entities[i])
    }
}

/// The control mask of the fields that differ between `old` and `new`.
fn changed_fields(old: &EntityState, new: &EntityState) -> u8 {
    let pairs = [
        (Field::Kind, old.kind != new.kind),
        (Field::PosX, old.pos.x != new.pos.x),
        (Field::PosY, old.pos.y != new.pos.y),
        (Field::VelX, old.vel.x != new.vel.x),
        (Field::VelY, old.vel.y != new.vel.y),
        (Field::Flags, old.flags != new.flags),
        (Field::Aux, old.aux != new.aux),
    ];
    pairs
        .iter()
        .filter(|(_, changed)| *changed)
        .fold(0, |mask, (field, _)| mask | *field as u8)
}

/// Appends the fields of `new` that differ from `old` (same id) and returns
/// the control mask. Writes the mask placeholder first.
fn put_entity(out: &mut Vec<u8>, old: &EntityState, new: &EntityState) {
    let at = out.len();
    out.push(0);
    let mut mask = 0u8;
    if new.kind != old.kind {
        mask |= Field::Kind as u8;
        out.push(new.kind);
    }
    let signed = [
        (Field::PosX, old.pos.x, new.pos.x),
        (Field::PosY, old.pos.y, new.pos.y),
        (Field::VelX, old.vel.x, new.vel.x),
        (Field::VelY, old.vel.y, new.vel.y),
    ];
    for (field, a, b) in signed {
        if a != b {
            mask |= field as u8;
            put_u32(out, zigzag32(b.wrapping_sub(a)));
        }
    }
    if new.flags != old.flags {
        mask |= Field::Flags as u8;
        put_u32(out, new.flags ^ old.flags);
    }
    if new.aux != old.aux {
        mask |= Field::Aux as u8;
        put_u32(out, zigzag32(new.aux.wrapping_sub(old.aux)));
    }
    out[at] = mask;
}

/// Reads the fields `mask` names and applies them to `base`; every field
/// named must change.
fn get_entity(
    r: &mut Reader<'_>,
    mask: u8,
    base: &EntityState,
) -> Result<EntityState, ProtocolError> {
    let mut e = *base;
    if mask & Field::Kind as u8 != 0 {
        e.kind = r.u8()?;
    }
    let slots: [(Field, &mut i32); 4] = [
        (Field::PosX, &mut e.pos.x),
        (Field::PosY, &mut e.pos.y),
        (Field::VelX, &mut e.vel.x),
        (Field::VelY, &mut e.vel.y),
    ];
    for (field, slot) in slots {
        if mask & field as u8 != 0 {
            *slot = slot.wrapping_add(unzigzag32(r.u32()?));
        }
    }
    if mask & Field::Flags as u8 != 0 {
        e.flags ^= r.u32()?;
    }
    if mask & Field::Aux as u8 != 0 {
        e.aux = e.aux.wrapping_add(unzigzag32(r.u32()?));
    }
    // Canonical form: a flagged field that does not change was not produced
    // by the encoder.
    let changed = changed_fields(base, &e);
    if changed != mask {
        return Err(r.error("a field is flagged as changed but is not"));
    }
    Ok(e)
}

/// `base` as the baseline of a snapshot `back` ticks after it: its position
/// advanced by its velocity `back` times (wrapping `i32` arithmetic, so any
/// value is defined and encoder and decoder agree exactly); every other
/// field unchanged. An entity moving at a constant velocity extrapolates to
/// its exact state, and the delta need not mention it.
pub fn extrapolate(base: &EntityState, back: u64) -> EntityState {
    let n = back as u32 as i32;
    EntityState {
        pos: IVec2::new(
            base.pos.x.wrapping_add(base.vel.x.wrapping_mul(n)),
            base.pos.y.wrapping_add(base.vel.y.wrapping_mul(n)),
        ),
        ..*base
    }
}

/// Whether `later` is `earlier` [`extrapolate`]d by `back` ticks, entity
/// by entity (the same entities in the same order, each where its velocity
/// carried it): [`StateSnapshot::extrapolates_to`] for bare entity lists.
pub fn extrapolates_to(earlier: &[EntityState], later: &[EntityState], back: u64) -> bool {
    earlier.len() == later.len()
        && earlier
            .iter()
            .zip(later)
            .all(|(a, b)| extrapolate(a, back) == *b)
}

/// One step of the merge of baseline and current ids.
enum Entry<'a> {
    Removed(u32),
    /// The extrapolated baseline entity and the current one.
    Changed(EntityState, &'a EntityState),
    Added(&'a EntityState),
}

/// Walks baseline and current in id order, yielding what the delta must say
/// (baseline entities extrapolated `back` ticks).
fn diff<'a>(
    base: &'a [EntityState],
    cur: &'a [EntityState],
    back: u64,
    mut f: impl FnMut(Entry<'a>),
) {
    let (mut i, mut j) = (0, 0);
    loop {
        match (base.get(i), cur.get(j)) {
            (None, None) => break,
            (Some(b), Some(c)) if b.id == c.id => {
                let predicted = extrapolate(b, back);
                if predicted != *c {
                    f(Entry::Changed(predicted, c));
                }
                i += 1;
                j += 1;
            }
            (Some(b), Some(c)) if b.id < c.id => {
                f(Entry::Removed(b.id));
                i += 1;
            }
            (Some(b), None) => {
                f(Entry::Removed(b.id));
                i += 1;
            }
            (_, Some(c)) => {
                f(Entry::Added(c));
                j += 1;
            }
        }
    }
}

/// Appends `current` encoded as a delta against `baseline` (`None`: a full
/// snapshot, decodable with no prior state) to `out`.
///
/// Errors, writing nothing, if either snapshot breaks its invariants
/// ([`StateSnapshot::validate`]) or the baseline is newer than `current`.
pub fn encode_delta(
    baseline: Option<&StateSnapshot>,
    current: &StateSnapshot,
    out: &mut Vec<u8>,
) -> Result<(), ProtocolError> {
    current.validate()?;
    let base: &[EntityState] = match baseline {
        Some(b) => {
            b.validate()?;
            if b.tick > current.tick {
                return Err(ProtocolError::InvalidValue {
                    what: "snapshot delta",
                    detail: "the baseline is newer than the snapshot",
                });
            }
            &b.entities
        }
        None => &[],
    };
    out.push(if baseline.is_some() { HAS_BASELINE } else { 0 });
    put_u64(out, current.tick);
    if let Some(b) = baseline {
        put_u64(out, current.tick - b.tick);
    }
    let back = baseline.map_or(0, |b| current.tick - b.tick);
    let mut count = 0u32;
    diff(base, &current.entities, back, |_| count += 1);
    put_u32(out, count);
    // Ids start at 0, so the "previous id" before the first is -1.
    let mut next_id = 0u64;
    let mut gap = |out: &mut Vec<u8>, id: u32| {
        put_u32(out, (id as u64 - next_id) as u32);
        next_id = id as u64 + 1;
    };
    diff(base, &current.entities, back, |entry| match entry {
        Entry::Removed(id) => {
            gap(out, id);
            out.push(REMOVED);
        }
        Entry::Changed(b, c) => {
            gap(out, c.id);
            put_entity(out, &b, c);
        }
        Entry::Added(c) => {
            gap(out, c.id);
            put_entity(out, &EntityState::zero(c.id), c);
        }
    });
    Ok(())
}

/// The baseline tick a delta was encoded against (`None` for a full
/// snapshot) and its tick, read from the header only.
pub fn peek_delta(bytes: &[u8]) -> Result<(u64, Option<u64>), ProtocolError> {
    let mut r = Reader::new(bytes, "snapshot delta");
    read_header(&mut r)
}

fn read_header(r: &mut Reader<'_>) -> Result<(u64, Option<u64>), ProtocolError> {
    let header = r.u8()?;
    if header & !HAS_BASELINE != 0 {
        return Err(r.error("unknown header bits"));
    }
    let tick = r.u64()?;
    let baseline = if header & HAS_BASELINE != 0 {
        let back = r.u64()?;
        Some(
            tick.checked_sub(back)
                .ok_or_else(|| r.error("baseline tick before tick 0"))?,
        )
    } else {
        None
    };
    Ok((tick, baseline))
}

/// Decodes a delta made by [`encode_delta`] against the same `baseline`,
/// reproducing the encoded snapshot exactly.
///
/// Never panics and allocates at most [`MAX_ENTITIES`] entities, whatever
/// the bytes. Errors with [`ProtocolError::BaselineMismatch`] if `baseline`
/// is not the one the delta was encoded against (by tick), and with
/// [`ProtocolError::Malformed`] (or another variant) on any invalid input.
pub fn decode_delta(
    baseline: Option<&StateSnapshot>,
    bytes: &[u8],
) -> Result<StateSnapshot, ProtocolError> {
    let mut r = Reader::new(bytes, "snapshot delta");
    let (tick, needed) = read_header(&mut r)?;
    let given = baseline.map(|b| b.tick);
    if needed != given {
        return Err(ProtocolError::BaselineMismatch { needed, given });
    }
    let base: &[EntityState] = match baseline {
        Some(b) => {
            b.validate()?;
            &b.entities
        }
        None => &[],
    };
    // Ticks the baseline entities are extrapolated by.
    let back = needed.map_or(0, |b| tick - b);
    let count = r.u32()? as usize;
    // Every entry takes at least two bytes, and there can be no more entries
    // than removals of baseline entities plus current entities.
    let max_entries = base.len() + MAX_ENTITIES;
    if count > max_entries {
        return Err(ProtocolError::too_large(
            "snapshot delta entry count",
            count,
            max_entries,
        ));
    }
    if count > r.remaining() / 2 {
        return Err(r.error("entry count exceeds the bytes left"));
    }
    let mut out = Vec::with_capacity((base.len() + count).min(MAX_ENTITIES));
    let mut i = 0; // next baseline entity not yet copied
    let mut next_id = 0u64; // smallest id the next entry may have
    for _ in 0..count {
        let id = next_id + r.u32()? as u64;
        let id: u32 = id
            .try_into()
            .map_err(|_| r.error("entity id overflows u32"))?;
        next_id = id as u64 + 1;
        // Unlisted baseline entities before this id carry over, extrapolated.
        while i < base.len() && base[i].id < id {
            out.push(extrapolate(&base[i], back));
            i += 1;
        }
        let old = match base.get(i) {
            Some(b) if b.id == id => {
                i += 1;
                Some(extrapolate(b, back))
            }
            _ => None,
        };
        let ctrl = r.u8()?;
        match (ctrl, old) {
            (REMOVED, Some(_)) => {}
            (REMOVED, None) => return Err(r.error("removes an entity the baseline lacks")),
            (m, _) if m & REMOVED != 0 => return Err(r.error("unknown control bits")),
            (0, Some(_)) => return Err(r.error("lists an unchanged entity")),
            (mask, old) => {
                let zero = EntityState::zero(id);
                out.push(get_entity(&mut r, mask, old.as_ref().unwrap_or(&zero))?);
            }
        }
        if out.len() > MAX_ENTITIES {
            return Err(ProtocolError::too_large(
                "snapshot entity count",
                out.len(),
                MAX_ENTITIES,
            ));
        }
    }
    out.extend(base[i..].iter().map(|b| extrapolate(b, back)));
    if out.len() > MAX_ENTITIES {
        return Err(ProtocolError::too_large(
            "snapshot entity count",
            out.len(),
            MAX_ENTITIES,
        ));
    }
    r.finish()?;
    Ok(StateSnapshot {
        tick,
        entities: out,
    })
}

/// The last few snapshots by tick: the server's record of what it sent (to
/// find the baseline a client acknowledged), or a client's record of what
/// it received (to decode deltas against).
#[derive(Debug, Clone)]
pub struct SnapshotHistory {
    ring: std::collections::VecDeque<StateSnapshot>,
    capacity: usize,
}

impl SnapshotHistory {
    /// An empty history keeping the newest `capacity` snapshots (at least 1).
    pub fn new(capacity: usize) -> Self {
        let capacity = capacity.max(1);
        SnapshotHistory {
            ring: std::collections::VecDeque::with_capacity(capacity),
            capacity,
        }
    }

    /// Stores `snapshot` if it is newer than every stored one (dropping the
    /// oldest when full); returns whether it was stored. Older or duplicate
    /// ticks (reordered datagrams) are ignored.
    pub fn insert(&mut self, snapshot: StateSnapshot) -> bool {
        if self.latest().is_some_and(|l| l.tick >= snapshot.tick) {
            return false;
        }
        if self.ring.len() == self.capacity {
            self.ring.pop_front();
        }
        self.ring.push_back(snapshot);
        true
    }

    /// The stored snapshot of `tick`.
    pub fn get(&self, tick: u64) -> Option<&StateSnapshot> {
        self.ring
            .binary_search_by_key(&tick, |s| s.tick)
            .ok()
            .map(|i| &self.ring[i])
    }

    /// The newest stored snapshot.
    pub fn latest(&self) -> Option<&StateSnapshot> {
        self.ring.back()
    }

    /// Drops every snapshot older than `tick` (for example once the server
    /// has moved its baselines past them).
    pub fn forget_before(&mut self, tick: u64) {
        while self.ring.front().is_some_and(|s| s.tick < tick) {
            self.ring.pop_front();
        }
    }

    /// Number of stored snapshots.
    pub fn len(&self) -> usize {
        self.ring.len()
    }

    /// Whether nothing is stored.
    pub fn is_empty(&self) -> bool {
        self.ring.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn walker(id: u32, x: i32, vx: i32) -> EntityState {
        EntityState {
            kind: 3,
            pos: IVec2::new(x, 4096),
            vel: IVec2::new(vx, 0),
            flags: 1,
            ..EntityState::zero(id)
        }
    }

    #[test]
    fn constant_velocity_costs_nothing_and_changes_are_exact() {
        let base = StateSnapshot {
            tick: 100,
            entities: vec![walker(1, 1000, 128), walker(2, 5000, -96)],
        };
        // Six ticks later both kept walking: header only.
        let cur = StateSnapshot {
            tick: 106,
            entities: vec![
                walker(1, 1000 + 6 * 128, 128),
                walker(2, 5000 - 6 * 96, -96),
            ],
        };
        let mut bytes = Vec::new();
        encode_delta(Some(&base), &cur, &mut bytes).unwrap();
        assert_eq!(bytes, [0x01, 106, 6, 0], "header and a zero count");
        assert_eq!(decode_delta(Some(&base), &bytes).unwrap(), cur);
        // Walker 2 turned around two ticks ago: only it is listed, with its
        // velocity and the position error of the extrapolation.
        let turned = StateSnapshot {
            tick: 106,
            entities: vec![walker(1, 1000 + 6 * 128, 128), walker(2, 5000 - 2 * 96, 96)],
        };
        bytes.clear();
        encode_delta(Some(&base), &turned, &mut bytes).unwrap();
        assert_eq!(&bytes[..4], [0x01, 106, 6, 1]);
        assert_eq!(decode_delta(Some(&base), &bytes).unwrap(), turned);
        // Extrapolation wraps instead of overflowing, identically both ways.
        let fast = StateSnapshot {
            tick: u64::MAX,
            entities: vec![walker(7, i32::MAX, i32::MAX)],
        };
        let far = StateSnapshot {
            tick: 3,
            entities: vec![walker(7, i32::MIN, i32::MAX)],
        };
        let mut bytes = Vec::new();
        encode_delta(Some(&far), &fast, &mut bytes).unwrap();
        assert_eq!(decode_delta(Some(&far), &bytes).unwrap(), fast);
        assert_eq!(extrapolate(&walker(1, 10, 3), 0), walker(1, 10, 3));
    }

    #[test]
    fn a_state_extrapolates_to_a_later_one_exactly_when_the_delta_is_empty() {
        let base = StateSnapshot {
            tick: 100,
            entities: vec![walker(1, 1000, 128), walker(2, 5000, 0)],
        };
        let later = |tick: u64, entities| StateSnapshot { tick, entities };
        let empty_delta = |cur: &StateSnapshot| {
            let mut bytes = Vec::new();
            encode_delta(Some(&base), cur, &mut bytes).unwrap();
            bytes.len() == 4
        };
        let moved_on = later(
            106,
            vec![walker(1, 1000 + 6 * 128, 128), walker(2, 5000, 0)],
        );
        assert!(base.extrapolates_to(&moved_on) && empty_delta(&moved_on));
        assert!(base.extrapolates_to(&base), "itself");
        let turned = later(
            106,
            vec![walker(1, 1000 + 6 * 128, -128), walker(2, 5000, 0)],
        );
        assert!(!base.extrapolates_to(&turned) && !empty_delta(&turned));
        let gone = later(106, vec![walker(1, 1000 + 6 * 128, 128)]);
        assert!(!base.extrapolates_to(&gone));
        let renamed = later(
            106,
            vec![walker(1, 1000 + 6 * 128, 128), walker(3, 5000, 0)],
        );
        assert!(!base.extrapolates_to(&renamed));
        assert!(!moved_on.extrapolates_to(&base), "not backwards in time");
    }
}
