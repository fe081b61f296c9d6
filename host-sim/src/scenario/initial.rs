//! `[initial]`: the state at t = 0.

use serde::{Deserialize, Serialize};

use super::envelope::EnvelopeSection;
use super::rules::{num, Validator};

/// `[initial]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSection {
    /// l(0), m.
    pub length_m: f64,
    /// l̇0 = l̇_real(0), the reel's initial rate, m/s.
    pub length_rate_mps: f64,
    /// δ(0) = α(0) − α_r(0), rad.
    pub delta_rad: f64,
    /// δ̇(0), rad/s.
    #[serde(default)]
    pub delta_rate_radps: f64,
    /// β(0), rad.
    #[serde(default)]
    pub beta_rad: f64,
    /// β̇(0), rad/s.
    #[serde(default)]
    pub beta_rate_radps: f64,
}

impl InitialSection {
    /// Every value finite, l(0) > 0, |β(0)| < π/2 (l̇0 is the controller's: finite, within the
    /// envelope's rate).
    pub(super) fn check(&self, v: &mut Validator) {
        let i = self;
        v.positive("initial.length_m", i.length_m);
        v.finite("initial.delta_rad", i.delta_rad);
        v.finite("initial.delta_rate_radps", i.delta_rate_radps);
        if v.finite("initial.beta_rad", i.beta_rad) {
            v.check(
                i.beta_rad.abs() < std::f64::consts::FRAC_PI_2,
                "initial.beta_rad",
                num(i.beta_rad),
                "must be within (−π/2, π/2)",
            );
        }
        v.finite("initial.beta_rate_radps", i.beta_rate_radps);
    }

    /// The initial length inside the envelope (when the envelope itself is valid).
    pub(super) fn check_within(&self, env: &EnvelopeSection, v: &mut Validator) {
        let i = self;
        if env.lengths_valid() && i.length_m.is_finite() && i.length_m > 0.0 {
            v.check(
                (env.min_length_m..=env.max_length_m).contains(&i.length_m),
                "initial.length_m",
                num(i.length_m),
                &format!(
                    "must be within [envelope.min_length_m, envelope.max_length_m] = [{}, {}]",
                    num(env.min_length_m),
                    num(env.max_length_m)
                ),
            );
        }
    }
}
