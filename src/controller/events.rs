//! The controller's events: what happened in a step, worth telling the ground about once, in
//! a bounded queue that keeps the newest events and counts the ones it had to drop.

use heapless::Deque;

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
    /// The tension loop's mode changed (docs/equations.md §17.6): its load cell came, coasted,
    /// was lost or came back.
    TensionLoop(super::TensionLoopMode),
    /// A mode command was applied at this period boundary
    /// ([`Controller::command`](super::Controller::command)).
    Command(super::ModeCommand),
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

/// The controller's event queue: [`EVENT_CAPACITY`] events; when it is full a new event takes
/// the place of the oldest unread one, which is counted as dropped.
#[derive(Clone, Debug)]
pub(super) struct EventQueue {
    queue: Deque<Event, EVENT_CAPACITY>,
    /// Events dropped so far (saturating).
    dropped: u32,
}

impl EventQueue {
    pub(super) const fn new() -> Self {
        Self {
            queue: Deque::new(),
            dropped: 0,
        }
    }

    /// Appends `e`; when the queue is full the oldest unread event makes room for it.
    pub(super) fn push(&mut self, e: Event) {
        if let Err(e) = self.queue.push_back(e) {
            self.queue.pop_front();
            self.dropped = self.dropped.saturating_add(1);
            // Room was made above: the push cannot fail.
            let _ = self.queue.push_back(e);
        }
    }

    /// Appends the event of `kind` at `tick`, if there is one.
    pub(super) fn record(&mut self, tick: u32, kind: Option<EventKind>) {
        if let Some(kind) = kind {
            self.push(Event { tick, kind });
        }
    }

    /// Takes the oldest unread event.
    pub(super) fn pop(&mut self) -> Option<Event> {
        self.queue.pop_front()
    }

    /// Events dropped so far.
    pub(super) fn dropped(&self) -> u32 {
        self.dropped
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::{Event, EventKind, EventQueue, Phase, EVENT_CAPACITY};
    use std::{vec, vec::Vec};

    fn event(i: u32) -> Event {
        Event {
            tick: i,
            kind: EventKind::Phase(Phase::Deploy),
        }
    }

    fn drain(q: &mut EventQueue) -> Vec<u32> {
        core::iter::from_fn(|| q.pop()).map(|e| e.tick).collect()
    }

    #[test]
    fn ring_keeps_the_newest_and_counts_the_overwritten() {
        let mut ring = EventQueue::new();
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
}
