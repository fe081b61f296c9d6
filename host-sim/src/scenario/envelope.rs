//! `[envelope]`: the reel's operating limits, which the controller enforces. Their rules are
//! the controller's (`core_rules.rs`).

use serde::{Deserialize, Serialize};

use super::rules::is_positive;

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
    /// Both lengths passed their rules: a non-empty length range to compare against.
    pub(super) fn lengths_valid(&self) -> bool {
        is_positive(self.min_length_m)
            && is_positive(self.max_length_m)
            && self.min_length_m < self.max_length_m
    }
}
