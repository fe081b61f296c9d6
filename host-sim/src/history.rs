//! The simulated mission's time history: one [`Sample`] per output interval.
//!
//! This is the contract between the closed-loop simulation (`sim`) and everything that reports
//! on it (CSV, figures, Table 1, summary).

use tss_reel::controller::Flags;

/// Mission phase as reported by the controller, in the order they occur.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PhaseLabel {
    /// Stage 1: paying out toward the stage-1 keep length.
    Deploy,
    /// Stage 1: holding at the stage-1 keep length (30 km in the paper).
    Keep1,
    /// Stage 2: α_r slewing from 0 to its plateau.
    Slew,
    /// Stage 2: winding in toward the stage-2 keep length.
    Retrieve,
    /// Stage 2: holding at the stage-2 keep length (2 km in the paper).
    Keep2,
}

impl PhaseLabel {
    /// The label written in `history.csv`'s `phase` column.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Deploy => "deploy",
            Self::Keep1 => "keep1",
            Self::Slew => "slew",
            Self::Retrieve => "retrieve",
            Self::Keep2 => "keep2",
        }
    }
}

/// One recorded instant of the closed-loop mission (plant state in f64, controller outputs
/// widened from f32).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Mission time, s (computed from the integer tick count).
    pub t_s: f64,
    /// Tether length l, m (plant truth).
    pub length_m: f64,
    /// Reel rate l̇ applied over the period that starts at this instant, m/s (the command).
    pub length_rate_mps: f64,
    /// In-plane angle α, rad (plant truth).
    pub alpha_rad: f64,
    /// In-plane angle rate α̇, rad/s (plant truth).
    pub alpha_rate_radps: f64,
    /// Reference angle α_r, rad (controller).
    pub alpha_ref_rad: f64,
    /// δ = α − α_r, rad (controller).
    pub delta_rad: f64,
    /// δ̇ = α̇ − α̇_r, rad/s (controller, consistent with the command).
    pub delta_rate_radps: f64,
    /// Out-of-plane angle β, rad (plant truth).
    pub beta_rad: f64,
    /// Tether tension T_t from Eq. 5a with l̈ = the commanded reel acceleration, N.
    pub tension_n: f64,
    /// Commanded reel acceleration, m/s² (Eq. 30, sign corrected).
    pub length_accel_mps2: f64,
    /// The Eq. 27 value l̇ (before the Eq. 29 blend), m/s.
    pub law_rate_mps: f64,
    /// Blend weight e^{−cτ} of Eq. 29 (1 at a stage start, → 0).
    pub blend_weight: f64,
    /// Mission phase.
    pub phase: PhaseLabel,
    /// Controller status flags: the bits of `tss_reel::controller::Flags` ([`FLAG_NAMES`]
    /// names them; [`flag_names`] writes them as text).
    pub flags: u32,
}

/// The result of a closed-loop run.
#[derive(Clone, Debug, Default)]
pub struct History {
    /// Samples at the output interval, starting at t = 0 and including the final instant.
    pub samples: Vec<Sample>,
    /// Length at every Table-1 instant requested by the caller of `sim::run` (t_s, length_m), in order,
    /// taken at the exact control tick (not interpolated).
    pub probes: Vec<(f64, f64)>,
    /// Faults, health, tension and envelope over every control tick of the run (see
    /// `faults::FaultSummary`; all zero for a history not made by `sim::run`).
    pub faults: crate::faults::FaultSummary,
    /// The elastic plant's extra quantities, one per sample (empty for the rigid plant).
    pub elastic: Vec<crate::plant::ElasticObservation>,
    /// The tether's shape every `plant.shape_interval_s` and at the end (elastic plant):
    /// (t_s, node positions relative to the main satellite in the orbit frame e_r, e_θ, e_h, m).
    pub shapes: Vec<(f64, Vec<[f64; 3]>)>,
    /// The tether ran off the end of its spool, and the run stopped there (`None`: it did not).
    pub spool_overrun: Option<SpoolOverrun>,
    /// The unit's telemetry packets (CCSDS/PUS, as sent; `crate::obc`): every verification
    /// report and event, and the housekeeping of the ticks that have a sample (empty when the
    /// controller in the loop has no PUS services).
    pub telemetry: Vec<Vec<u8>>,
}

/// The tether paid out beyond the spool it is wound on (`envelope.max_length_m`): a reel has
/// no more to give, so the run stops at that tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpoolOverrun {
    /// When, s.
    pub t_s: f64,
    /// The paid-out length, m.
    pub length_m: f64,
    /// The spool's length, m.
    pub spool_m: f64,
}

/// The controller's flag bits (`tss_reel::controller::Flags`, the `flags` column of
/// `history.csv`) and their names, in bit order.
pub const FLAG_NAMES: [(u32, &str); 15] = [
    (Flags::RATE_SATURATED, "rate-saturated"),
    (Flags::ACCEL_SATURATED, "accel-saturated"),
    (Flags::LENGTH_LIMITED, "length-limited"),
    (Flags::SAFE_ACTION, "safe-action"),
    (Flags::BLEND_RESTART, "blend-restart"),
    (Flags::SLEWING, "slewing"),
    (Flags::HEALTH_CHANGED, "health-changed"),
    (Flags::NO_EQUILIBRIUM, "no-equilibrium"),
    (Flags::NO_PROGRESS, "no-progress"),
    (Flags::TENSION_LIMITED, "tension-limited"),
    (Flags::PHASE_CHANGED, "phase-changed"),
    (Flags::TENSION_SHAPED, "tension-shaped"),
    (Flags::LOAD_CELL_LOST, "load-cell-lost"),
    (Flags::HELD, "held"),
    (Flags::ABORTED, "aborted"),
];

/// The names of the bits set in `flags`, joined by `|` (e.g. `slewing|no-equilibrium`;
/// `none` for 0; an unknown bit as its hexadecimal value).
pub fn flag_names(flags: u32) -> String {
    if flags == 0 {
        return "none".to_string();
    }
    let mut names: Vec<String> = FLAG_NAMES
        .iter()
        .filter(|(bit, _)| flags & bit != 0)
        .map(|(_, name)| (*name).to_string())
        .collect();
    let known = FLAG_NAMES.iter().fold(0, |m, (bit, _)| m | bit);
    if flags & !known != 0 {
        names.push(format!("{:#x}", flags & !known));
    }
    names.join("|")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_flag_has_one_bit_and_a_name() {
        let mut all = 0;
        for (bit, name) in FLAG_NAMES {
            assert_eq!(bit.count_ones(), 1, "{name}");
            assert_eq!(all & bit, 0, "{name} shares a bit");
            all |= bit;
            assert_eq!(flag_names(bit), name);
        }
        assert_eq!(flag_names(0), "none");
        assert_eq!(
            flag_names(Flags::SLEWING | Flags::NO_EQUILIBRIUM),
            "slewing|no-equilibrium"
        );
        assert_eq!(flag_names(1 << 31), "0x80000000");
    }
}
