//! `[controller]`, `[stage1]`, `[stage2]`: the control law's gains and period, and the two
//! stages' reference schedules (Eqs. 27–35 of the paper). Most of their rules are the
//! controller's own (`Config::validate`, named by scenario key in `core_rules.rs`); the ones
//! here are the scenario's.

use serde::{Deserialize, Serialize};

use super::rules::{is_positive, num, Validator};

/// `[controller]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSection {
    /// Control period (and zero-order-hold interval of the reel command), s.
    pub period_s: f64,
    /// k1 of Eq. 27, 1/s.
    pub k1_per_s: f64,
    /// k2 of Eq. 27, 1/s².
    pub k2_per_s2: f64,
    /// A keep phase begins when l is within this distance of its keep length, m.
    #[serde(default = "one_m")]
    pub keep_capture_m: f64,
}

fn one_m() -> f64 {
    1.0
}

/// `[stage1]`: Eq. 34.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stage1Section {
    /// c of Eq. 29 in stage 1, 1/s.
    pub decay_rate_per_s: f64,
    /// α_r while deploying (l ≤ band start), rad.
    pub deploy_angle_rad: f64,
    /// Start of the transition band (10 km in the paper), m.
    pub band_start_m: f64,
    /// Keep length, the end of the band (30 km), m.
    pub keep_length_m: f64,
    /// Slope k of α_r = k(l − keep) beyond the keep length, rad/m.
    pub keep_slope_rad_per_m: f64,
}

impl Stage1Section {
    /// A band that starts above 0 and a slope k ≥ 0 (c ≥ 0, the deployment-side angle, the
    /// band below the keep length and the keep inside the envelope are the controller's).
    pub(super) fn check(&self, v: &mut Validator) {
        let s1 = self;
        v.positive("stage1.band_start_m", s1.band_start_m);
        v.non_negative("stage1.keep_slope_rad_per_m", s1.keep_slope_rad_per_m);
    }
}

/// `[stage2]`: the slew and Eq. 35.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stage2Section {
    /// Mission time at which stage 2 begins, s (8 h in the paper).
    pub start_time_s: f64,
    /// c of Eq. 29 in stage 2, 1/s.
    pub decay_rate_per_s: f64,
    /// α_r plateau while retrieving (l ≥ band end), rad.
    pub retrieve_angle_rad: f64,
    /// Slew rate of α_r from 0 to the plateau, rad/s.
    pub slew_rate_radps: f64,
    /// Upper end of the transition band (5 km), m.
    pub band_start_m: f64,
    /// Keep length, the lower end of the band (2 km), m.
    pub keep_length_m: f64,
    /// Slope k of α_r = k(l − keep) below the keep length, rad/m.
    pub keep_slope_rad_per_m: f64,
}

impl Stage2Section {
    /// A start on a control tick, a band that starts above 0, a keep length below stage 1's
    /// (stage 2 retrieves), k ≥ 0 (c ≥ 0, the retrieval-side angle, the slew rate, the band
    /// above the keep length and the keep inside the envelope are the controller's).
    pub(super) fn check(&self, stage1: &Stage1Section, period_s: f64, v: &mut Validator) {
        let s2 = self;
        if v.non_negative("stage2.start_time_s", s2.start_time_s) {
            v.whole_multiple_of_period("stage2.start_time_s", s2.start_time_s, period_s, true);
        }
        v.positive("stage2.band_start_m", s2.band_start_m);
        if is_positive(s2.keep_length_m) && is_positive(stage1.keep_length_m) {
            v.check(
                s2.keep_length_m < stage1.keep_length_m,
                "stage2.keep_length_m",
                num(s2.keep_length_m),
                &format!(
                    "must be below stage1.keep_length_m = {} (stage 2 retrieves)",
                    num(stage1.keep_length_m)
                ),
            );
        }
        v.non_negative("stage2.keep_slope_rad_per_m", s2.keep_slope_rad_per_m);
    }
}
