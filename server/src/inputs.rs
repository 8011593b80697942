//! A client's input buffer: button bits by tick, bounded, filled from
//! redundant [`InputPacket`]s and drained by the room one tick at a time.
//!
//! Only ticks in `[next_tick, next_tick + window)` are stored (a ring of
//! `window` slots), so nothing a client sends can grow it: an input for a
//! tick already simulated is *late* (counted if it was new), one too far
//! ahead is *too early* (counted). Repeats of ticks already held are the
//! normal redundancy and cost nothing.
//!
//! A packet with [`InputPacket::hold`] (a quiet client's) makes its newest
//! buttons stand for every later tick the buffer has no input for, until a
//! newer packet says otherwise: those ticks are not starved, and the
//! client's own inputs for them arriving late are not late if they agree.

use ledge_shared::input::Buttons;
use ledge_shared::protocol::{input_timing, InputPacket};

/// What one packet brought.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Received {
    /// Ticks stored for the first time.
    pub fresh: u32,
    /// Ticks never seen before that arrived after they were simulated.
    pub late: u32,
    /// Ticks too far in the future, dropped.
    pub too_early: u32,
    /// How early (+) or late (-) the packet's newest tick arrived, in ticks,
    /// relative to the next tick to simulate.
    pub timing: i16,
}

/// The inputs of one client waiting for their tick.
#[derive(Debug, Clone)]
pub struct InputBuffer {
    slots: Vec<Option<(u64, Buttons)>>,
    next_tick: u64,
    newest: Option<u64>,
    /// The newest packet's tick and buttons when it asked for them to be
    /// held.
    hold: Option<(u64, Buttons)>,
}

impl InputBuffer {
    /// An empty buffer accepting `window` ticks ahead (at least 1), starting
    /// at `next_tick`.
    pub fn new(window: usize, next_tick: u64) -> InputBuffer {
        InputBuffer {
            slots: vec![None; window.max(1)],
            next_tick,
            newest: None,
            hold: None,
        }
    }

    fn slot(&self, tick: u64) -> usize {
        (tick % self.slots.len() as u64) as usize
    }

    /// The next tick the room will take.
    pub fn next_tick(&self) -> u64 {
        self.next_tick
    }

    /// The newest tick ever received, if any.
    pub fn newest(&self) -> Option<u64> {
        self.newest
    }

    /// Stores the packet's ticks that fit the window.
    pub fn receive(&mut self, packet: &InputPacket) -> Received {
        let mut r = Received {
            timing: input_timing(packet.newest_tick, self.next_tick),
            ..Received::default()
        };
        let end = self.next_tick.saturating_add(self.slots.len() as u64);
        let seen = self.newest;
        let held = self.hold;
        for (tick, buttons) in packet.ticks() {
            if tick < self.next_tick {
                let agreed = held.is_some_and(|(t, b)| tick > t && b == buttons);
                if seen.is_none_or(|n| tick > n) && !agreed {
                    r.late += 1;
                }
            } else if tick >= end {
                r.too_early += 1;
            } else {
                let i = self.slot(tick);
                if self.slots[i].is_none_or(|(t, _)| t != tick) {
                    r.fresh += 1;
                }
                self.slots[i] = Some((tick, buttons));
            }
        }
        if seen.is_none_or(|n| packet.newest_tick >= n) {
            self.hold = packet
                .hold
                .then(|| packet.buttons.first().map(|&b| (packet.newest_tick, b)))
                .flatten();
        }
        if r.fresh > 0 || r.late > 0 {
            self.newest = Some(self.newest.map_or(packet.newest_tick, |n| {
                n.max(packet.newest_tick.min(end.saturating_sub(1)))
            }));
        }
        r
    }

    /// The input for `tick` (the room's current tick), if it arrived or is
    /// held ([`InputPacket::hold`]); the buffer then waits for `tick + 1`.
    /// Ticks skipped over are discarded.
    pub fn take(&mut self, tick: u64) -> Option<Buttons> {
        let i = self.slot(tick);
        let found = match self.slots[i] {
            Some((t, b)) if t == tick => Some(b),
            _ => self.hold.filter(|&(t, _)| t < tick).map(|(_, b)| b),
        };
        self.slots[i] = None;
        self.next_tick = tick + 1;
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn packet(newest: u64, buttons: &[u8]) -> InputPacket {
        let b: Vec<Buttons> = buttons.iter().map(|&b| Buttons(b)).collect();
        InputPacket::new(newest, &b, None)
    }

    #[test]
    fn redundant_ticks_fill_gaps_and_are_taken_in_order() {
        let mut buf = InputBuffer::new(8, 10);
        // Ticks 12, 11, 10.
        let r = buf.receive(&packet(12, &[3, 2, 1]));
        assert_eq!((r.fresh, r.late, r.too_early, r.timing), (3, 0, 0, 2));
        // The repeat of 11 and 10 is not fresh; 13 is.
        let r = buf.receive(&packet(13, &[4, 3, 2, 1]));
        assert_eq!((r.fresh, r.late), (1, 0));
        assert_eq!(buf.take(10), Some(Buttons(1)));
        assert_eq!(buf.take(11), Some(Buttons(2)));
        assert_eq!(buf.take(12), Some(Buttons(3)));
        assert_eq!(buf.take(13), Some(Buttons(4)));
        assert_eq!(buf.take(14), None, "starved");
        assert_eq!(buf.next_tick(), 15);
    }

    #[test]
    fn late_and_early_ticks_are_dropped_and_counted() {
        let mut buf = InputBuffer::new(4, 100);
        for t in 100..105 {
            buf.take(t);
        }
        // Next tick 105; window 105..109.
        let r = buf.receive(&packet(104, &[1, 1]));
        assert_eq!((r.fresh, r.late, r.too_early), (0, 2, 0));
        assert_eq!(r.timing, -1);
        // Seen once: the same late ticks again are redundancy, not new.
        let r = buf.receive(&packet(104, &[1, 1]));
        assert_eq!(r.late, 0);
        let r = buf.receive(&packet(110, &[1, 1, 1, 1, 1, 1]));
        // 110, 109 too early; 108..105 stored.
        assert_eq!((r.fresh, r.late, r.too_early), (4, 0, 2));
        assert_eq!(buf.take(105), Some(Buttons(1)));
    }

    #[test]
    fn held_buttons_fill_the_ticks_of_a_quiet_client_until_it_speaks() {
        let mut buf = InputBuffer::new(8, 10);
        // Quiet from tick 10 on, holding 4.
        buf.receive(&packet(10, &[4, 4]).holding(true));
        assert_eq!(buf.take(10), Some(Buttons(4)));
        assert_eq!(buf.take(11), Some(Buttons(4)), "held, not starved");
        assert_eq!(buf.take(12), Some(Buttons(4)));
        // Its keepalive (newest 14) repeats ticks 10..12, already taken:
        // they agree with the hold, so they are not late; 13 and 14 are
        // fresh.
        let r = buf.receive(&packet(14, &[4, 4, 4, 4, 4]).holding(true));
        assert_eq!((r.fresh, r.late), (2, 0));
        assert_eq!(buf.take(13), Some(Buttons(4)));
        assert_eq!(buf.take(14), Some(Buttons(4)));
        assert_eq!(buf.take(15), Some(Buttons(4)));
        // A change that came too late disagrees with the hold: late. It
        // holds nothing, so the hold ends: missing ticks starve again.
        let r = buf.receive(&packet(15, &[1, 1]));
        assert_eq!((r.fresh, r.late), (0, 1), "tick 15 was held as 4");
        let r = buf.receive(&packet(17, &[1]));
        assert_eq!(r.fresh, 1);
        assert_eq!(buf.take(16), None);
        assert_eq!(buf.take(17), Some(Buttons(1)));
        assert_eq!(buf.take(18), None);
    }

    #[test]
    fn an_older_packet_arriving_late_does_not_change_the_hold() {
        let mut buf = InputBuffer::new(8, 0);
        buf.receive(&packet(4, &[2]).holding(true));
        // Reordered: an older, non-holding packet.
        buf.receive(&packet(3, &[2, 2]));
        for t in 0..4 {
            buf.take(t);
        }
        assert_eq!(buf.take(4), Some(Buttons(2)));
        assert_eq!(buf.take(5), Some(Buttons(2)), "still held");
        // An older holding packet does not start a hold either.
        let mut buf = InputBuffer::new(8, 0);
        buf.receive(&packet(4, &[2]));
        buf.receive(&packet(3, &[2]).holding(true));
        buf.take(4);
        assert_eq!(buf.take(5), None);
    }

    #[test]
    fn memory_is_bounded_whatever_the_ticks() {
        let mut buf = InputBuffer::new(16, 0);
        for t in [u64::MAX, 1 << 40, 5, 3, 0, u64::MAX / 2] {
            buf.receive(&packet(t, &[1; 64]));
        }
        assert_eq!(buf.slots.len(), 16);
        assert_eq!(buf.take(0), Some(Buttons(1)));
        // A huge tick never stored: the slot of 1 << 40 is empty or other.
        assert_eq!(buf.take(1 << 40), None);
    }

    #[test]
    fn stale_slots_from_an_older_lap_are_not_returned() {
        let mut buf = InputBuffer::new(4, 0);
        buf.receive(&packet(1, &[7, 7]));
        // Skip ahead without taking 0 and 1: tick 4 shares slot 0.
        assert_eq!(buf.take(4), None);
        assert_eq!(buf.take(5), None, "tick 1's slot is not tick 5's");
    }
}
