//! The controller's events: what happened in a step, worth telling the ground about once, in
//! a bounded queue that keeps the first events of a burst and counts the ones it had to drop.

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

/// The controller's event queue: [`EVENT_CAPACITY`] events. When it is full, a new event is
/// dropped and counted, and the unread ones are kept: in a burst the first events tell the cause
/// (the fault, the health change it led to) and the later ones its consequences, so a reader
/// that fell behind still learns what started it (first-fault retention), and the count tells
/// it that more happened.
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

    /// Appends `e`, or counts it as dropped when the queue is full.
    pub(super) fn push(&mut self, e: Event) {
        if self.queue.push_back(e).is_err() {
            self.dropped = self.dropped.saturating_add(1);
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
    fn a_full_queue_keeps_the_first_events_and_counts_the_dropped() {
        let mut q = EventQueue::new();
        assert_eq!(q.pop(), None);
        for i in 0..3 {
            q.push(event(i));
        }
        assert_eq!((drain(&mut q), q.dropped()), (vec![0, 1, 2], 0));
        // 16 + 5 unread: the 5 newest are dropped, counted before and after the read.
        for i in 3..3 + EVENT_CAPACITY as u32 + 5 {
            q.push(event(i));
        }
        assert_eq!(q.dropped(), 5);
        let expected: Vec<u32> = (3..19).collect();
        assert_eq!(drain(&mut q), expected);
        assert_eq!(q.dropped(), 5);
        // A partial read makes room for as many: only what finds no room is lost.
        for i in 24..40 {
            q.push(event(i));
        }
        assert_eq!(q.pop().map(|e| e.tick), Some(24));
        for i in 40..50 {
            q.push(event(i));
        }
        assert_eq!(q.dropped(), 5 + 9);
        assert_eq!(drain(&mut q), (25..41).collect::<Vec<u32>>());
    }
}
