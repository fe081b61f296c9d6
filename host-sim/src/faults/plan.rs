//! What is injected between the plant and the controller: the fault model's parameters
//! (a scenario's `[sensors]` and `[faults]`), which the fault `Injector` applies.

use crate::sensors::{
    EncoderModel, LoadCellModel, SensedQuantity, SensorErrors, SwingSensorModel, Window,
};

/// A reading replaced by a fixed value (NaN, inf, anything) during a window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corruption {
    /// Which quantity.
    pub sensor: SensedQuantity,
    /// When.
    pub window: Window,
    /// The reading, in the quantity's unit.
    pub value: f64,
}

/// A one-tick error of the length encoder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Glitch {
    /// When, s (the tick at or after it).
    pub at_s: f64,
    /// Size of the error, m.
    pub size_m: f64,
}

/// Everything injected between the plant and the controller: the parameters of an
/// [`Injector`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InjectionPlan {
    /// Seed of the noise generators (one stream per sensor).
    pub seed: u64,
    /// The reel encoder (length and rate).
    pub length: EncoderModel,
    /// The swing sensor (α): errors, latency, α dropouts.
    pub alpha: SwingSensorModel,
    /// The α̇ sensor is fitted.
    pub alpha_rate_enabled: bool,
    /// The α̇ sensor's errors.
    pub alpha_rate: SensorErrors,
    /// The load cell.
    pub load_cell: LoadCellModel,
    /// Windows without a sample (the controller's `step_missing`).
    pub dropout: Vec<Window>,
    /// Corrupted readings.
    pub corrupt: Vec<Corruption>,
    /// Length-encoder glitches.
    pub length_glitch: Vec<Glitch>,
}

impl InjectionPlan {
    /// `true` if nothing is injected: the controller reads the truth (rounded to its type),
    /// α̇ included.
    pub fn is_transparent(&self) -> bool {
        self.length.is_perfect()
            && self.alpha.is_perfect()
            && self.alpha_rate_enabled
            && self.alpha_rate.is_perfect()
            && self.load_cell.is_perfect()
            && self.dropout.is_empty()
            && self.corrupt.is_empty()
            && self.length_glitch.is_empty()
    }
}
