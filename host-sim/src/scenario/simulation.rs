//! `[simulation]`: how long to fly, how finely to integrate, how often to write a row.

use serde::{Deserialize, Serialize};

use super::rules::{num, Validator};

/// The simulator counts control ticks in a `u32`: a run may last at most this many periods.
pub const MAX_TICKS: f64 = u32::MAX as f64;

/// `[simulation]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSection {
    /// Mission length, s.
    pub duration_s: f64,
    /// RK4 sub-steps per control period (≥ 1).
    #[serde(default = "one")]
    pub substeps: u32,
    /// Interval between rows of history.csv, s (a multiple of the control period).
    #[serde(default = "ten_s")]
    pub output_interval_s: f64,
}

fn one() -> u32 {
    1
}
fn ten_s() -> f64 {
    10.0
}

impl SimulationSection {
    /// A duration and an output interval of whole control periods, at least one sub-step.
    pub(super) fn check(&self, period_s: f64, v: &mut Validator) {
        let sim = self;
        if v.positive("simulation.duration_s", sim.duration_s) {
            v.whole_multiple_of_period("simulation.duration_s", sim.duration_s, period_s, false);
            if period_s.is_finite() && period_s > 0.0 {
                let ticks = (sim.duration_s / period_s).round();
                v.check(
                    ticks <= MAX_TICKS,
                    "simulation.duration_s",
                    num(sim.duration_s),
                    &format!("is {ticks} control periods, more than the simulator's {MAX_TICKS}"),
                );
            }
        }
        v.check(
            sim.substeps >= 1,
            "simulation.substeps",
            sim.substeps.to_string(),
            "must be at least 1",
        );
        if v.positive("simulation.output_interval_s", sim.output_interval_s) {
            v.whole_multiple_of_period(
                "simulation.output_interval_s",
                sim.output_interval_s,
                period_s,
                false,
            );
        }
    }
}
