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
    /// The deployment law flown: `"paper"` (default: the flight core's Eqs. 27–35), `"rupp"`
    /// (Rupp's tension law) or `"tracking"` (a saturated, feedback-linearised tension law);
    /// see `crate::laws` and docs/equations.md §15.
    #[serde(default)]
    pub law: LawName,
    /// `[controller.rupp]`: the gains of Rupp's tension law (`law = "rupp"`).
    #[serde(default)]
    pub rupp: RuppSection,
    /// `[controller.tracking]`: the tracking tension law's schedule, gain and tension bounds
    /// (`law = "tracking"`).
    #[serde(default)]
    pub tracking: TrackingSection,
}

fn one_m() -> f64 {
    1.0
}

/// The deployment law a scenario flies (`[controller] law`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LawName {
    /// The paper's rate law (Eqs. 27–35), the flight core `tss_reel::controller::Controller`.
    #[default]
    Paper,
    /// Rupp's tension law T = m_e Ω²[a(l − l_f) + b l̇/Ω + c l_f] (`crate::laws::rupp`).
    Rupp,
    /// The saturated, feedback-linearised tension law tracking a length-rate schedule
    /// (`crate::laws::tracking`).
    Tracking,
}

impl LawName {
    /// Every law, in the order `tss-sim compare` lists them.
    pub const ALL: [LawName; 3] = [LawName::Paper, LawName::Rupp, LawName::Tracking];

    /// The name written in scenario files and on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            LawName::Paper => "paper",
            LawName::Rupp => "rupp",
            LawName::Tracking => "tracking",
        }
    }

    /// The law named `s`, if any.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|l| l.as_str() == s)
    }

    /// `true` for the laws that command the reel's tension rather than its rate.
    pub fn commands_tension(self) -> bool {
        self != LawName::Paper
    }
}

/// `[controller.rupp]`: T = m_e Ω²[a(l − l_f) + b l̇/Ω + c l_f] (Rupp 1975), one set of gains
/// for both stages. Defaults: a = 4, b = 2, c = 3 (c = 3 makes l_f the law's equilibrium; the
/// linearised loop is stable for a > 3, b > 0: docs/equations.md §15).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RuppSection {
    /// a, the length gain (dimensionless).
    #[serde(default = "rupp_a")]
    pub length_gain: f64,
    /// b, the rate gain (dimensionless).
    #[serde(default = "rupp_b")]
    pub rate_gain: f64,
    /// c, the bias gain (dimensionless; 3 holds l_f on the local vertical).
    #[serde(default = "rupp_c")]
    pub bias_gain: f64,
}

fn rupp_a() -> f64 {
    4.0
}
fn rupp_b() -> f64 {
    2.0
}
fn rupp_c() -> f64 {
    3.0
}

impl Default for RuppSection {
    fn default() -> Self {
        Self {
            length_gain: rupp_a(),
            rate_gain: rupp_b(),
            bias_gain: rupp_c(),
        }
    }
}

/// `[controller.tracking]`: the length-rate schedule l̇_ref(l) = (v0 + kΩl)(1 − l/l_f) below
/// l_f, k_inΩ(l_f − l) above, tracked through Eq. 5a inverted about the local vertical,
/// T = m_r[3μ2Ω²l − μ1l̇²/l − l̈_ref + κΩ(l̇ − l̇_ref)], saturated in [min_tension_n,
/// max_tension_n]. Defaults: k = 0.5, k_in = 0.3, v0 = 0, κ = 2, 0.01 N, no ceiling.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackingSection {
    /// k, the schedule's exponential rate in units of the orbit rate (dimensionless).
    #[serde(default = "tracking_k")]
    pub schedule_rate: f64,
    /// k beyond l_f (winding in: retrieval, or back from an overshoot), in units of Ω.
    #[serde(default = "tracking_k_in")]
    pub retrieve_schedule_rate: f64,
    /// v0, the schedule's rate at l = 0 while deploying, m/s.
    #[serde(default)]
    pub schedule_start_rate_mps: f64,
    /// κ, the rate-error gain in units of the orbit rate: k_v = κΩ (dimensionless).
    #[serde(default = "tracking_kv")]
    pub rate_gain: f64,
    /// The tension floor (the tether must pull), N.
    #[serde(default = "tracking_min")]
    pub min_tension_n: f64,
    /// The tension ceiling, N (inf = none).
    #[serde(default = "infinity")]
    pub max_tension_n: f64,
}

fn tracking_k() -> f64 {
    0.5
}
fn tracking_k_in() -> f64 {
    0.3
}
fn tracking_kv() -> f64 {
    2.0
}
fn tracking_min() -> f64 {
    0.01
}
fn infinity() -> f64 {
    f64::INFINITY
}

impl Default for TrackingSection {
    fn default() -> Self {
        Self {
            schedule_rate: tracking_k(),
            retrieve_schedule_rate: tracking_k_in(),
            schedule_start_rate_mps: 0.0,
            rate_gain: tracking_kv(),
            min_tension_n: tracking_min(),
            max_tension_n: infinity(),
        }
    }
}

impl ControllerSection {
    /// The tension laws' gains: Rupp's a > 3, b > 0, c ≥ 0 (the linearised loop's stability);
    /// the tracking law's k > 0, v0 ≥ 0, κ > 0, 0 < T_min < T_max.
    pub(super) fn check(&self, v: &mut Validator) {
        let r = &self.rupp;
        if v.finite("controller.rupp.length_gain", r.length_gain) {
            v.check(
                r.length_gain > 3.0,
                "controller.rupp.length_gain",
                num(r.length_gain),
                "must be above 3 (the linearised loop is unstable below)",
            );
        }
        v.positive("controller.rupp.rate_gain", r.rate_gain);
        v.non_negative("controller.rupp.bias_gain", r.bias_gain);
        let t = &self.tracking;
        v.positive("controller.tracking.schedule_rate", t.schedule_rate);
        v.positive(
            "controller.tracking.retrieve_schedule_rate",
            t.retrieve_schedule_rate,
        );
        v.non_negative(
            "controller.tracking.schedule_start_rate_mps",
            t.schedule_start_rate_mps,
        );
        v.positive("controller.tracking.rate_gain", t.rate_gain);
        if v.positive("controller.tracking.min_tension_n", t.min_tension_n)
            && v.limit("controller.tracking.max_tension_n", t.max_tension_n)
        {
            v.check(
                t.max_tension_n > t.min_tension_n,
                "controller.tracking.max_tension_n",
                num(t.max_tension_n),
                "must be above controller.tracking.min_tension_n",
            );
        }
    }
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
