//! `[envelope]`: the reel's operating limits, which the controller enforces.

use serde::{Deserialize, Serialize};

use super::rules::{is_positive, num, Validator};

/// `[envelope]`: the reel's operating limits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvelopeSection {
    /// Largest reel speed, m/s.
    pub max_rate_mps: f64,
    /// Largest reel acceleration, m/s².
    pub max_accel_mps2: f64,
    /// Shortest tether (docking), m.
    pub min_length_m: f64,
    /// Longest tether (spool capacity), m.
    pub max_length_m: f64,
}

impl Default for EnvelopeSection {
    fn default() -> Self {
        Self {
            max_rate_mps: 15.0,
            max_accel_mps2: 15.0,
            min_length_m: 0.5,
            max_length_m: 40_000.0,
        }
    }
}

impl EnvelopeSection {
    /// Every limit finite and above 0; the shortest tether below the longest.
    pub(super) fn check(&self, v: &mut Validator) {
        v.positive("envelope.max_rate_mps", self.max_rate_mps);
        v.positive("envelope.max_accel_mps2", self.max_accel_mps2);
        let min_ok = v.positive("envelope.min_length_m", self.min_length_m);
        let max_ok = v.positive("envelope.max_length_m", self.max_length_m);
        if min_ok && max_ok {
            v.check(
                self.min_length_m < self.max_length_m,
                "envelope.max_length_m",
                num(self.max_length_m),
                &format!(
                    "must be above envelope.min_length_m = {}",
                    num(self.min_length_m)
                ),
            );
        }
    }

    /// The rate limit passed its rule (other sections' rules compare against it only then).
    pub(super) fn rate_valid(&self) -> bool {
        is_positive(self.max_rate_mps)
    }

    /// The longest length passed its own rule.
    pub(super) fn max_length_valid(&self) -> bool {
        is_positive(self.max_length_m)
    }

    /// Both lengths passed their rules: a non-empty length range to compare against.
    pub(super) fn lengths_valid(&self) -> bool {
        is_positive(self.min_length_m)
            && self.max_length_valid()
            && self.min_length_m < self.max_length_m
    }
}
