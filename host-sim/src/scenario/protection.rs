//! `[protection]`: the controller's tension- and drive-aware protection (docs/equations.md
//! §14). Off by default (the paper's controller, Table 1 unchanged); when on, its rules are the
//! controller's (`ProtectionConfig::validate`, named by scenario key in `core_rules.rs`).

use serde::{Deserialize, Serialize};

use tss_reel::controller::ProtectionConfig;

/// `[protection]`: the controller's `ProtectionConfig` (defaults:
/// `ProtectionConfig::default_for_period`, off).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ProtectionSection {
    /// Fly the protection (false: the paper's controller, bounded by the envelope alone).
    pub enabled: bool,
    /// T_min, the least tension the command keeps at the reel, N.
    pub min_tension_n: f64,
    /// T_max, the most tension the command allows at the reel, N.
    pub max_tension_n: f64,
    /// Time constant over which the load cell corrects the free-tension model, s.
    pub tension_filter_s: f64,
    /// The reel drive's first-order lag as the controller knows it, s (0: it follows the
    /// command).
    pub drive_lag_s: f64,
    /// The resolution of the encoder's measured rate as the controller knows it, m/s (one
    /// count per period). Not given: worked out from `[sensors.length]`'s encoder
    /// (2π·drum_radius_m/counts_per_rev per control period; 0 for an encoder without counts).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_resolution_mps: Option<f64>,
}

impl Default for ProtectionSection {
    fn default() -> Self {
        let p = ProtectionConfig::<f64>::default_for_period();
        Self {
            enabled: false,
            min_tension_n: p.min_tension_n,
            max_tension_n: p.max_tension_n,
            tension_filter_s: p.tension_filter_s,
            drive_lag_s: p.drive_lag_s,
            rate_resolution_mps: None,
        }
    }
}

impl ProtectionSection {
    /// The controller's protection, in its scalar type `T` (None when off);
    /// `encoder_rate_resolution_mps` is the scenario encoder's one count per period, used when
    /// `rate_resolution_mps` is not given.
    pub fn to_protection_config<T: tss_reel::Real>(
        &self,
        encoder_rate_resolution_mps: f64,
    ) -> Option<ProtectionConfig<T>> {
        let resolution = self
            .rate_resolution_mps
            .unwrap_or(encoder_rate_resolution_mps);
        self.enabled.then(|| ProtectionConfig {
            min_tension_n: T::from_f64(self.min_tension_n),
            max_tension_n: T::from_f64(self.max_tension_n),
            tension_filter_s: T::from_f64(self.tension_filter_s),
            drive_lag_s: T::from_f64(self.drive_lag_s),
            rate_resolution_mps: T::from_f64(resolution),
        })
    }
}
