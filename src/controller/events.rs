//! The controller's events: what happened in a step, worth telling the ground about once, in
//! a bounded ring that keeps the newest events and counts the ones it had to drop.
//!
//! Why not `heapless::Deque`: it was tried. Its `push_back` (a full check, then an index
//! increment with wrap-around, and the write) cost about 25 instructions per event on the
//! Cortex-M4F, against about 5 for this ring's one store and one increment; the step that
//! starts stage 2 records two events and is the mission's worst step, where the deque cost
//! about 40 instructions more (`scripts/bench-target`: worst step 603 with the deque).

use super::output::{Fault, Health, Phase};

/// Capacity of the controller's event queue ([`Controller::pop_event`](super::Controller::pop_event)).
pub const EVENT_CAPACITY: usize = 16;

/// Something that happened in one step, worth telling the ground about once.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EventKind {
    /// The input health changed.
    Health {
        /// Before.
        from: Health,
        /// After.
        to: Health,
    },
    /// A fault was raised (recorded when it differs from the previous fault).
    Fault(Fault),
    /// The mission phase changed.
    Phase(Phase),
    /// The Eq. 29 blend restarted (a stage began, or the controller recovered).
    BlendRestart,
    /// This phase stopped getting closer to its keep length ([`super::Flags::NO_PROGRESS`]).
    NoProgress(Phase),
    /// The estimator gave up on its prediction after consecutive gated samples and restarted α
    /// from this sample ([`crate::estimator::Measurement::Reinitialised`]).
    EstimateRestarted,
    /// The estimator dropped its estimate (a drive it could not carry it over, a prediction
    /// that left the physical range, or a gap in the calls longer than
    /// [`super::MAX_CARRIED_PERIODS`]): the next α starts afresh.
    EstimateLost,
    /// The protection's tension bound began to restrict the command
    /// ([`super::Flags::TENSION_LIMITED`], set at this step and not at the one before).
    TensionLimited,
}

/// An event and the tick it happened at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Event {
    /// The tick.
    pub tick: u32,
    /// What happened.
    pub kind: EventKind,
}

/// The controller's event queue: a ring of [`EVENT_CAPACITY`] events in which a new event
/// overwrites the oldest unread one when the ring is full. The writer and the reader each
/// keep a free-running count (wrapping): a push is one store and one increment, with no test,
/// so a step that records events stays close to a quiet one; the reader finds any events
/// overwritten since it last read (more than [`EVENT_CAPACITY`] unread) and counts them as
/// dropped.
#[derive(Clone, Debug)]
pub(super) struct EventRing {
    buf: [Event; EVENT_CAPACITY],
    /// Events ever written (wrapping); the next is written at `written mod capacity`.
    written: u32,
    /// Events ever read or dropped (wrapping).
    read: u32,
    /// Events dropped, up to the last read.
    dropped: u32,
}

const _: () = assert!(EVENT_CAPACITY.is_power_of_two() && EVENT_CAPACITY <= u32::MAX as usize);

impl EventRing {
    const CAPACITY: u32 = EVENT_CAPACITY as u32;

    pub(super) const fn new() -> Self {
        Self {
            buf: [Event {
                tick: 0,
                kind: EventKind::BlendRestart,
            }; EVENT_CAPACITY],
            written: 0,
            read: 0,
            dropped: 0,
        }
    }

    /// Appends `e`; when the ring is full it takes the oldest unread event's slot.
    pub(super) fn push(&mut self, e: Event) {
        self.buf[self.written as usize & (EVENT_CAPACITY - 1)] = e;
        self.written = self.written.wrapping_add(1);
    }

    /// Unread events overwritten since the last read.
    fn overwritten(&self) -> u32 {
        self.written
            .wrapping_sub(self.read)
            .saturating_sub(Self::CAPACITY)
    }

    /// Takes the oldest unread event (first counting any that were overwritten).
    pub(super) fn pop(&mut self) -> Option<Event> {
        let lost = self.overwritten();
        self.dropped = self.dropped.saturating_add(lost);
        self.read = self.read.wrapping_add(lost);
        if self.read == self.written {
            return None;
        }
        let e = self.buf[self.read as usize & (EVENT_CAPACITY - 1)];
        self.read = self.read.wrapping_add(1);
        Some(e)
    }

    /// Events dropped so far, including those overwritten and not yet counted by a read.
    pub(super) fn dropped(&self) -> u32 {
        self.dropped.saturating_add(self.overwritten())
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::{Event, EventKind, EventRing, Phase, EVENT_CAPACITY};
    use std::{vec, vec::Vec};

    fn event(i: u32) -> Event {
        Event {
            tick: i,
            kind: EventKind::Phase(Phase::Deploy),
        }
    }

    fn drain(q: &mut EventRing) -> Vec<u32> {
        core::iter::from_fn(|| q.pop()).map(|e| e.tick).collect()
    }

    #[test]
    fn ring_keeps_the_newest_and_counts_the_overwritten() {
        let mut ring = EventRing::new();
        assert_eq!(ring.pop(), None);
        for i in 0..3 {
            ring.push(event(i));
        }
        assert_eq!((drain(&mut ring), ring.dropped()), (vec![0, 1, 2], 0));
        // 16 + 5 unread: the 5 oldest are overwritten, counted before and after the read.
        for i in 3..3 + EVENT_CAPACITY as u32 + 5 {
            ring.push(event(i));
        }
        assert_eq!(ring.dropped(), 5);
        let expected: Vec<u32> = (8..24).collect();
        assert_eq!(drain(&mut ring), expected);
        assert_eq!(ring.dropped(), 5);
        // A partial read, then more than a ring's worth: only the unread are lost.
        for i in 24..30 {
            ring.push(event(i));
        }
        assert_eq!(ring.pop().map(|e| e.tick), Some(24));
        for i in 30..50 {
            ring.push(event(i));
        }
        assert_eq!(ring.dropped(), 5 + 9);
        assert_eq!(drain(&mut ring), (34..50).collect::<Vec<u32>>());
    }

    #[test]
    fn ring_counters_wrap_around() {
        let mut ring = EventRing::new();
        ring.written = u32::MAX - 2;
        ring.read = u32::MAX - 2;
        for i in 0..EVENT_CAPACITY as u32 + 2 {
            ring.push(event(i));
        }
        assert_eq!(ring.written, EVENT_CAPACITY as u32 - 1);
        assert_eq!(ring.dropped(), 2);
        assert_eq!(drain(&mut ring), (2..18).collect::<Vec<u32>>());
        assert_eq!((ring.pop(), ring.dropped()), (None, 2));
    }
}
