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
        }
    }
}

impl ProtectionSection {
    /// The controller's protection, in its scalar type `T` (None when off).
    pub fn to_protection_config<T: tss_reel::Real>(&self) -> Option<ProtectionConfig<T>> {
        self.enabled.then(|| ProtectionConfig {
            min_tension_n: T::from_f64(self.min_tension_n),
            max_tension_n: T::from_f64(self.max_tension_n),
            tension_filter_s: T::from_f64(self.tension_filter_s),
            drive_lag_s: T::from_f64(self.drive_lag_s),
        })
    }
}
