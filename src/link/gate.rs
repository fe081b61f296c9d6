//! The receiving side's sequence and tick checks on sample frames.

use super::messages::{LinkCounters, Sample};

/// What a [`SampleGate`] made of one valid sample frame.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Gate {
    /// The sample for the awaited tick (or a later one: the frame's tick is the authority).
    Accept(Sample),
    /// The same sequence number as the last accepted frame: a duplicate, discarded.
    Duplicate,
    /// Older than the last accepted frame (sequence or tick): late, discarded.
    OutOfOrder,
}

/// The receiving side's sequence and tick checks on sample frames, with the counts in
/// [`LinkCounters`]. A discarded frame does not use up the period: the receiver keeps waiting
/// for the right one (so a repeated frame cannot push the receiver ahead of the sender).
///
/// The sender numbers its frames from 0 and its [`End`](super::End) frame carries the number after its last
/// sample, so frames lost before the first one that arrives and after the last one are counted
/// as gaps too ([`SampleGate::close`]): the count is exact whichever frames are lost.
#[derive(Clone, Copy, Debug, Default)]
pub struct SampleGate {
    /// Sequence number and tick of the newest sample frame seen (`None`: none yet).
    last: Option<(u32, u32)>,
    /// The sequence number the sender's next new frame carries (of any kind: telecommand
    /// packets and housekeeping requests are numbered in the same sequence as the samples).
    next_seq: u32,
}

impl SampleGate {
    /// A gate that has seen nothing yet (the next frame is expected to be number 0).
    pub const fn new() -> Self {
        Self::from_seq(0)
    }

    /// A gate whose sender numbers its next frame `first_seq` (the frames before it, such as
    /// the parameter table, were of other kinds).
    pub const fn from_seq(first_seq: u32) -> Self {
        Self {
            last: None,
            next_seq: first_seq,
        }
    }

    /// Counts the frames lost before the frame `seq` as gaps, and expects the one after it.
    fn seen(&mut self, seq: u32, counters: &mut LinkCounters) {
        let gap = seq.saturating_sub(self.next_seq);
        counters.seq_gaps = counters.seq_gaps.saturating_add(gap);
        self.next_seq = self.next_seq.max(seq.saturating_add(1));
    }

    /// Judges a valid sample frame `seq`/`sample` while the receiver waits for tick `awaited`;
    /// counts duplicates, late frames and sequence gaps.
    pub fn check(
        &mut self,
        seq: u32,
        sample: Sample,
        awaited: u32,
        counters: &mut LinkCounters,
    ) -> Gate {
        if let Some((last_seq, last_tick)) = self.last {
            if seq == last_seq {
                counters.duplicates = counters.duplicates.saturating_add(1);
                return Gate::Duplicate;
            }
            if seq < last_seq || sample.tick <= last_tick {
                counters.out_of_order = counters.out_of_order.saturating_add(1);
                return Gate::OutOfOrder;
            }
        }
        // Seen, so it is no gap, whether or not it is used.
        self.seen(seq, counters);
        self.last = Some((seq, sample.tick));
        if sample.tick < awaited {
            counters.out_of_order = counters.out_of_order.saturating_add(1);
            return Gate::OutOfOrder;
        }
        counters.frames_ok = counters.frames_ok.saturating_add(1);
        Gate::Accept(sample)
    }

    /// A valid frame `seq` of another kind from the same sender (a telecommand packet, a
    /// housekeeping request): the frames lost before it are gaps.
    pub fn other(&mut self, seq: u32, counters: &mut LinkCounters) {
        self.seen(seq, counters);
    }

    /// The sender's [`End`](super::End) frame, number `end_seq`, closed the run: counts the frames lost
    /// after the last one seen (all of them if none arrived).
    pub fn close(&mut self, end_seq: u32, counters: &mut LinkCounters) {
        self.seen(end_seq, counters);
    }
}
