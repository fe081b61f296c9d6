//! `[monitor]`: the thresholds of the controller's sensor monitor. Their rules are the
//! controller's (`MonitorConfig::validate`, named by scenario key in `core_rules.rs`).

use serde::{Deserialize, Serialize};

use super::rules::Validator;
use super::simulation::MAX_TICKS;

/// `[monitor]`: the controller's sensor checks and fault timing (`tss_reel`'s `MonitorConfig`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MonitorSection {
    /// Ticks without a usable sample during which the controller coasts before safe hold.
    pub coast_ticks: u32,
    /// Consecutive valid samples needed to leave safe hold.
    pub recovery_ticks: u32,
    /// Largest accepted |sensed − predicted| length, m.
    pub length_jump_m: f64,
    /// Largest accepted α jump per tick beyond α̇·Δt, rad.
    pub alpha_jump_rad: f64,
    /// Identical α readings in a row (with α̇ implying motion) that make a stuck sensor.
    pub stuck_ticks: u32,
    /// Implied motion ∫|α̇|dt over the identical readings a stuck verdict needs, rad.
    pub stuck_motion_rad: f64,
    /// Largest plausible |α̇|, rad/s.
    pub max_alpha_rate_radps: f64,
    /// Smallest plausible orbit rate, rad/s.
    pub min_orbit_rate_radps: f64,
    /// Largest plausible orbit rate, rad/s.
    pub max_orbit_rate_radps: f64,
    /// Good samples that pay back one bad one in the leaky bad-sample counter (the rate of bad
    /// samples the controller tolerates is 1 in 1 + this).
    #[serde(default = "default_good_samples_per_bad")]
    pub good_samples_per_bad: u32,
    /// Deceleration of the safe-hold ramp to rest, m/s² (the envelope's limit if lower).
    #[serde(default = "default_safe_hold_decel_mps2")]
    pub safe_hold_decel_mps2: f64,
}

fn default_good_samples_per_bad() -> u32 {
    tss_reel::controller::MonitorConfig::<f64>::default_for_period().good_samples_per_bad
}

fn default_safe_hold_decel_mps2() -> f64 {
    tss_reel::controller::MonitorConfig::<f64>::default_for_period().safe_hold_decel_mps2
}

impl Default for MonitorSection {
    fn default() -> Self {
        let m = tss_reel::controller::MonitorConfig::<f64>::default_for_period();
        Self {
            coast_ticks: m.coast_ticks,
            recovery_ticks: m.recovery_ticks,
            length_jump_m: m.length_jump_m,
            alpha_jump_rad: m.alpha_jump_rad,
            stuck_ticks: m.stuck_ticks,
            stuck_motion_rad: m.stuck_motion_rad,
            max_alpha_rate_radps: m.max_alpha_rate_radps,
            min_orbit_rate_radps: m.min_orbit_rate_radps,
            max_orbit_rate_radps: m.max_orbit_rate_radps,
            good_samples_per_bad: m.good_samples_per_bad,
            safe_hold_decel_mps2: m.safe_hold_decel_mps2,
        }
    }
}

impl MonitorSection {
    /// Tick counts within the longest run, [`MAX_TICKS`] (their other rules, ≥ 1 and the
    /// thresholds, are the controller's: `MonitorConfig::validate`).
    pub(super) fn check(&self, v: &mut Validator) {
        for (field, ticks) in [
            ("monitor.coast_ticks", self.coast_ticks),
            ("monitor.recovery_ticks", self.recovery_ticks),
            ("monitor.stuck_ticks", self.stuck_ticks),
        ] {
            v.check(
                ticks <= MAX_TICKS,
                field,
                ticks.to_string(),
                &format!("must be at most {MAX_TICKS} (the longest run, in ticks)"),
            );
        }
    }
}
