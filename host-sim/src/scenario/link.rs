//! `[link]`: faults of the processor-in-the-loop serial link (`tss-sim run --pil`).

use serde::{Deserialize, Serialize};

use super::rules::{num, Validator};

/// `[link]`: faults injected into the plant → firmware sample frames of a processor-in-the-loop
/// run (`crate::pil`). Each frame meets at most one fault, drawn with these probabilities from a
/// PCG32 stream seeded by `seed` (the same seed gives the same faults on the same ticks).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkSection {
    /// Seed of the link's fault generator.
    #[serde(default)]
    pub seed: u64,
    /// Probability that a sample frame is lost (the firmware times out: a dropout).
    #[serde(default)]
    pub drop_prob: f64,
    /// Probability that one byte of a sample frame is changed (the firmware rejects it: a
    /// dropout).
    #[serde(default)]
    pub corrupt_prob: f64,
    /// Probability that a sample frame is sent twice (the firmware discards the copy).
    #[serde(default)]
    pub duplicate_prob: f64,
    /// Probability that a sample frame is held back and sent after the next one (late: the
    /// firmware times out on its period, then discards it).
    #[serde(default)]
    pub reorder_prob: f64,
}

impl LinkSection {
    /// `true` if no fault is injected.
    pub fn is_clean(&self) -> bool {
        self.drop_prob == 0.0
            && self.corrupt_prob == 0.0
            && self.duplicate_prob == 0.0
            && self.reorder_prob == 0.0
    }
}

impl LinkSection {
    /// Probabilities in [0, 1] that add up to at most 1 (one fault per frame).
    pub(super) fn check(&self, v: &mut Validator) {
        let l = self;
        let mut all_ok = true;
        for (field, p) in [
            ("link.drop_prob", l.drop_prob),
            ("link.corrupt_prob", l.corrupt_prob),
            ("link.duplicate_prob", l.duplicate_prob),
            ("link.reorder_prob", l.reorder_prob),
        ] {
            all_ok &= v.check((0.0..=1.0).contains(&p), field, num(p), "must be in [0, 1]");
        }
        if all_ok {
            let sum = l.drop_prob + l.corrupt_prob + l.duplicate_prob + l.reorder_prob;
            v.check(
                sum <= 1.0,
                "link.drop_prob + link.corrupt_prob + link.duplicate_prob + link.reorder_prob",
                num(sum),
                "must be at most 1 (each frame meets at most one fault)",
            );
        }
    }
}
