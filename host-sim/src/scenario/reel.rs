//! `[reel]`: the physical reel drive (`crate::reel::Reel` flies it; `convert` turns this
//! section into its parameters).

use serde::{Deserialize, Serialize};

use super::rules::Validator;

/// `[reel]`: the physical reel drive between the command and the tether. Its actual rate v
/// follows the command u as a first-order lag, dv/dt = (u − v)/lag_s, with its own rate and
/// acceleration saturation (separate from the controller's `[envelope]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReelSection {
    /// Time constant of the lag, s (0 = the rate follows the command at once).
    #[serde(default)]
    pub lag_s: f64,
    /// Largest rate the drive can reach, m/s (inf = no limit).
    #[serde(default = "infinity")]
    pub max_rate_mps: f64,
    /// Largest acceleration the drive can produce, m/s² (inf = no limit).
    #[serde(default = "infinity")]
    pub max_accel_mps2: f64,
}

impl Default for ReelSection {
    fn default() -> Self {
        Self {
            lag_s: 0.0,
            max_rate_mps: f64::INFINITY,
            max_accel_mps2: f64::INFINITY,
        }
    }
}

fn infinity() -> f64 {
    f64::INFINITY
}

impl ReelSection {
    /// A lag ≥ 0; saturations above 0 (inf = none).
    pub(super) fn check(&self, v: &mut Validator) {
        v.non_negative("reel.lag_s", self.lag_s);
        v.limit("reel.max_rate_mps", self.max_rate_mps);
        v.limit("reel.max_accel_mps2", self.max_accel_mps2);
    }
}
