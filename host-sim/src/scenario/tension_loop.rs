//! `[tension_loop]`: the controller's tension loop (docs/equations.md §17). Off by default (the
//! paper's controller, Table 1 unchanged); when on, its rules are the controller's
//! (`TensionLoopConfig::validate`, named by scenario key in `core_rules.rs`). The defaults are
//! `TensionLoopConfig::dyneema_half_mm`, the flight configuration's.

use serde::{Deserialize, Serialize};

use tss_reel::controller::TensionLoopConfig;

/// `[tension_loop]`: the controller's `TensionLoopConfig` (defaults:
/// `TensionLoopConfig::dyneema_half_mm`, off).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TensionLoopSection {
    /// Fly the tension loop (false: the paper's controller, the load cell not read by the law).
    pub enabled: bool,
    /// EA as the loop is told it, N (its gain schedule; the plant's is `tether.axial_stiffness_n`).
    pub axial_stiffness_n: f64,
    /// The damping ratio the loop gives the tether's bounce.
    pub damping_ratio: f64,
    /// The washout's time constant, s.
    pub washout_s: f64,
    /// The least mean tension the tension window keeps, N.
    pub min_tension_n: f64,
    /// The most mean tension the tension window allows, N.
    pub max_tension_n: f64,
    /// The window's elastic overshoot allowance (≥ 1).
    pub overshoot: f64,
    /// The window without a load cell, m/s².
    pub fallback_accel_mps2: f64,
    /// Control periods without a load-cell sample before it is lost.
    pub load_cell_timeout_ticks: u32,
    /// |δ| from which the attitude takes authority from the window, rad.
    pub yield_from_rad: f64,
    /// |δ| from which the law flies unshaped, rad.
    pub yield_full_rad: f64,
}

impl Default for TensionLoopSection {
    fn default() -> Self {
        let t = TensionLoopConfig::<f64>::dyneema_half_mm();
        Self {
            enabled: false,
            axial_stiffness_n: t.axial_stiffness_n,
            damping_ratio: t.damping_ratio,
            washout_s: t.washout_s,
            min_tension_n: t.min_tension_n,
            max_tension_n: t.max_tension_n,
            overshoot: t.overshoot,
            fallback_accel_mps2: t.fallback_accel_mps2,
            load_cell_timeout_ticks: t.load_cell_timeout_ticks,
            yield_from_rad: t.yield_from_rad,
            yield_full_rad: t.yield_full_rad,
        }
    }
}

impl TensionLoopSection {
    /// The controller's tension loop, in its scalar type `T` (None when off).
    pub fn to_tension_loop_config<T: tss_reel::Real>(&self) -> Option<TensionLoopConfig<T>> {
        let f = T::from_f64;
        self.enabled.then(|| TensionLoopConfig {
            axial_stiffness_n: f(self.axial_stiffness_n),
            damping_ratio: f(self.damping_ratio),
            washout_s: f(self.washout_s),
            min_tension_n: f(self.min_tension_n),
            max_tension_n: f(self.max_tension_n),
            overshoot: f(self.overshoot),
            fallback_accel_mps2: f(self.fallback_accel_mps2),
            load_cell_timeout_ticks: self.load_cell_timeout_ticks,
            yield_from_rad: f(self.yield_from_rad),
            yield_full_rad: f(self.yield_full_rad),
        })
    }
}
