//! `[simulation]`: how long to fly, how finely to integrate, how often to write a row.
//!
//! Every size has a bound, checked when the scenario is loaded, before any work: a run costs
//! time in proportion to its plant steps (ticks × sub-steps) and memory in proportion to its
//! history rows, and each is capped well above any mission of the paper's kind (72 000 ticks,
//! 7 201 rows) and well below what would exhaust a desk machine.

use serde::{Deserialize, Serialize};

use super::rules::{num, Validator};

/// The longest run, in control periods: 10⁷ (116 days at the paper's 1 s period; the paper's
/// mission is 72 000).
pub const MAX_TICKS: u32 = 10_000_000;

/// The most RK4 sub-steps per control period.
pub const MAX_SUBSTEPS: u32 = 1_000;

/// The most plant steps of a run (ticks × sub-steps): 10⁸, about a minute of desk time.
pub const MAX_PLANT_STEPS: u64 = 100_000_000;

/// The most rows of history.csv (and of the history held in memory, about 120 bytes each):
/// 10⁶.
pub const MAX_HISTORY_ROWS: u64 = 1_000_000;

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
    /// The tether must be taut from the first tick at which the paid-out length reaches this,
    /// m (docs/equations.md §17.7): slack before it is reported, slack after it is what the run
    /// summary's "after the taut point" figures and the Monte Carlo `no_slack` criterion count.
    /// 0 (the default): from the start.
    #[serde(default)]
    pub taut_from_length_m: f64,
}

fn one() -> u32 {
    1
}
fn ten_s() -> f64 {
    10.0
}

impl SimulationSection {
    /// A duration and an output interval of whole control periods, at least one sub-step, and
    /// the run's size within [`MAX_TICKS`], [`MAX_SUBSTEPS`], [`MAX_PLANT_STEPS`] and
    /// [`MAX_HISTORY_ROWS`].
    pub(super) fn check(&self, period_s: f64, v: &mut Validator) {
        let sim = self;
        let period_ok = period_s.is_finite() && period_s > 0.0;
        // The run's length in ticks, once it is known to be a valid one.
        let mut ticks = None;
        if v.positive("simulation.duration_s", sim.duration_s) {
            v.whole_multiple_of_period("simulation.duration_s", sim.duration_s, period_s, false);
            if period_ok {
                let n = (sim.duration_s / period_s).round();
                let ok = v.check(
                    n <= f64::from(MAX_TICKS),
                    "simulation.duration_s",
                    num(sim.duration_s),
                    &format!(
                        "is {} control periods, more than the simulator's {MAX_TICKS} \
                         (simulation::MAX_TICKS)",
                        num(n)
                    ),
                );
                ticks = ok.then_some(n as u64);
            }
        }
        let substeps_ok = v.check(
            sim.substeps >= 1,
            "simulation.substeps",
            sim.substeps.to_string(),
            "must be at least 1",
        ) && v.check(
            sim.substeps <= MAX_SUBSTEPS,
            "simulation.substeps",
            sim.substeps.to_string(),
            &format!("must be at most {MAX_SUBSTEPS}"),
        );
        if let (Some(n), true) = (ticks, substeps_ok) {
            let steps = n * u64::from(sim.substeps);
            v.check(
                steps <= MAX_PLANT_STEPS,
                "simulation.substeps",
                sim.substeps.to_string(),
                &format!(
                    "makes {steps} plant steps over simulation.duration_s = {}, more than the \
                     simulator's {MAX_PLANT_STEPS}",
                    num(sim.duration_s)
                ),
            );
        }
        v.non_negative("simulation.taut_from_length_m", sim.taut_from_length_m);
        if v.positive("simulation.output_interval_s", sim.output_interval_s) {
            v.whole_multiple_of_period(
                "simulation.output_interval_s",
                sim.output_interval_s,
                period_s,
                false,
            );
            if let (Some(n), true) = (ticks, period_ok) {
                let every = ((sim.output_interval_s / period_s).round() as u64).max(1);
                // A row every `every` ticks from tick 0, and the last tick.
                let rows = n.div_ceil(every) + 1;
                v.check(
                    rows <= MAX_HISTORY_ROWS,
                    "simulation.output_interval_s",
                    num(sim.output_interval_s),
                    &format!(
                        "makes {rows} rows of history over simulation.duration_s = {}, more \
                         than the simulator's {MAX_HISTORY_ROWS}",
                        num(sim.duration_s)
                    ),
                );
            }
        }
    }
}
