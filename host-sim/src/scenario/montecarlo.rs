//! `[montecarlo]`: a campaign on this scenario (`tss-sim montecarlo`): the dispersed inputs and
//! the pass/fail criteria of one run. `tss-sim run` ignores it. The campaign itself (drawing,
//! flying, judging) is `crate::montecarlo`; this is only its schema and rules.

use serde::{Deserialize, Serialize};

use super::rules::{num, Validator};

/// `[montecarlo]`: what a campaign on this scenario disperses and what every run must achieve.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloSection {
    /// `[[montecarlo.dispersion]]`: the dispersed inputs, drawn in this order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dispersion: Vec<DispersionSection>,
    /// `[montecarlo.criteria]`: the pass/fail criteria of one run.
    #[serde(default)]
    pub criteria: CriteriaSection,
}

/// The shape of a dispersion.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Distribution {
    /// Gaussian: `std` (required), `mean` (default: the nominal value, or 0 when relative).
    Normal,
    /// Uniform on [`min`, `max`].
    Uniform,
}

impl Distribution {
    /// The name as written in scenario files.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Normal => "normal",
            Self::Uniform => "uniform",
        }
    }
}

/// `[[montecarlo.dispersion]]`: one dispersed scenario field.
///
/// Absolute (`relative = false`): the draw is the value (a normal's mean defaults to the
/// nominal value). Relative: the draw x is a fraction of the nominal value, value =
/// nominal × (1 + x) (a normal's mean defaults to 0).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DispersionSection {
    /// The dotted scenario key of a number field, as `--set` takes it, e.g. `initial.delta_rad`.
    pub field: String,
    /// `normal` or `uniform`.
    pub distribution: Distribution,
    /// Normal: the mean (default: the nominal value; 0 when relative).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean: Option<f64>,
    /// Normal: the standard deviation (≥ 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
    /// Uniform: the lower end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    /// Uniform: the upper end (≥ min).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
    /// The parameters are fractions of the nominal value: value = nominal × (1 + draw).
    #[serde(default)]
    pub relative: bool,
}

/// `[montecarlo.criteria]`: what one run must achieve to pass. A criterion left at its default
/// (inf, −inf or false) is not checked; a run that did not complete fails.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CriteriaSection {
    /// Largest allowed max |l − stage1.keep_length_m| over [keep1_from_s, keep1_until_s], m
    /// (station keeping; the paper claims 0.1 m over 7–8 h).
    #[serde(default = "infinity")]
    pub max_keep1_error_m: f64,
    /// Start of the station-keeping window, s (default 7 h, the paper's Table 1).
    #[serde(default = "keep1_from_s")]
    pub keep1_from_s: f64,
    /// End of the station-keeping window, s (default 8 h).
    #[serde(default = "keep1_until_s")]
    pub keep1_until_s: f64,
    /// Latest allowed time to reach the stage-1 keep length (within 0.5 m), s.
    #[serde(default = "infinity")]
    pub max_time_to_keep1_s: f64,
    /// Largest allowed stage-1 overshoot above the keep length, m.
    #[serde(default = "infinity")]
    pub max_overshoot_m: f64,
    /// Smallest allowed tether tension over the run, N (−inf = not checked).
    #[serde(default = "neg_infinity")]
    pub min_tension_n: f64,
    /// The tether must never go slack (tension ≤ 0).
    #[serde(default)]
    pub no_slack: bool,
    /// Largest allowed |final length − stage2.keep_length_m|, m.
    #[serde(default = "infinity")]
    pub max_final_error_m: f64,
    /// The controller must never enter safe hold.
    #[serde(default)]
    pub no_safe_hold: bool,
}

impl Default for CriteriaSection {
    fn default() -> Self {
        Self {
            max_keep1_error_m: f64::INFINITY,
            keep1_from_s: keep1_from_s(),
            keep1_until_s: keep1_until_s(),
            max_time_to_keep1_s: f64::INFINITY,
            max_overshoot_m: f64::INFINITY,
            min_tension_n: f64::NEG_INFINITY,
            no_slack: false,
            max_final_error_m: f64::INFINITY,
            no_safe_hold: false,
        }
    }
}

fn infinity() -> f64 {
    f64::INFINITY
}
fn neg_infinity() -> f64 {
    f64::NEG_INFINITY
}
/// 7 h: the first stage-1 instant of the paper's Table 1.
fn keep1_from_s() -> f64 {
    25_200.0
}
/// 8 h: the last stage-1 instant of the paper's Table 1 (stage 2 starts).
fn keep1_until_s() -> f64 {
    28_800.0
}

impl DispersionSection {
    /// Finite parameters, those of its distribution and no others, std ≥ 0, min ≤ max, and a
    /// nominal value it can be centred on or scale (`at`: `montecarlo.dispersion[i]`).
    pub(super) fn check(&self, at: &str, nominal: Option<f64>, v: &mut Validator) {
        let d = self;
        let params = [
            ("mean", d.mean),
            ("std", d.std),
            ("min", d.min),
            ("max", d.max),
        ];
        for (name, value) in params {
            if let Some(x) = value {
                v.finite(&format!("{at}.{name}"), x);
            }
        }
        let (wanted, unused): (&[&str], &[&str]) = match d.distribution {
            Distribution::Normal => (&["std"], &["min", "max"]),
            Distribution::Uniform => (&["min", "max"], &["mean", "std"]),
        };
        let get = |name: &str| params.iter().find(|p| p.0 == name).and_then(|p| p.1);
        let distribution = d.distribution.as_str();
        for name in wanted {
            v.check(
                get(name).is_some(),
                &format!("{at}.{name}"),
                "(missing)".to_string(),
                &format!("is required by distribution = \"{distribution}\""),
            );
        }
        for name in unused {
            if let Some(x) = get(name) {
                v.check(
                    false,
                    &format!("{at}.{name}"),
                    num(x),
                    &format!(
                        "is not used by distribution = \"{distribution}\" (it takes {})",
                        wanted.join(" and ")
                    ),
                );
            }
        }
        if let Some(s) = d.std {
            v.check(
                s.is_nan() || s >= 0.0, // NaN is reported as not finite
                &format!("{at}.std"),
                num(s),
                "must not be negative",
            );
        }
        if let (Some(lo), Some(hi)) = (d.min, d.max) {
            v.check(
                lo.is_nan() || hi.is_nan() || lo <= hi,
                &format!("{at}.max"),
                num(hi),
                &format!("must not be below {at}.min = {}", num(lo)),
            );
        }
        let needs_nominal =
            d.relative || (d.distribution == Distribution::Normal && d.mean.is_none());
        match nominal {
            Some(x) if needs_nominal && !x.is_finite() => {
                v.check(
                    false,
                    &format!("{at}.field"),
                    format!("{:?}", d.field),
                    &format!(
                        "has the nominal value {}, which a {} dispersion cannot be centred on \
                         (give a mean, or min and max)",
                        num(x),
                        if d.relative { "relative" } else { "normal" }
                    ),
                );
            }
            Some(x) if d.relative && x == 0.0 => {
                v.check(
                    false,
                    &format!("{at}.relative"),
                    "true".to_string(),
                    &format!(
                        "cannot scale {} = 0 (a relative dispersion multiplies the nominal \
                         value; use an absolute one)",
                        d.field
                    ),
                );
            }
            _ => {}
        }
    }
}

impl CriteriaSection {
    /// Error bounds ≥ 0 (inf = not checked), a tension bound that is a number, a window that
    /// starts at a finite time ≥ 0 and does not end before it starts.
    pub(super) fn check(&self, v: &mut Validator) {
        let c = self;
        for (field, x) in [
            ("montecarlo.criteria.max_keep1_error_m", c.max_keep1_error_m),
            (
                "montecarlo.criteria.max_time_to_keep1_s",
                c.max_time_to_keep1_s,
            ),
            ("montecarlo.criteria.max_overshoot_m", c.max_overshoot_m),
            ("montecarlo.criteria.max_final_error_m", c.max_final_error_m),
        ] {
            v.check(
                x >= 0.0,
                field,
                num(x),
                "must not be negative (inf = not checked)",
            );
        }
        v.check(
            !c.min_tension_n.is_nan() && c.min_tension_n != f64::INFINITY,
            "montecarlo.criteria.min_tension_n",
            num(c.min_tension_n),
            "must be a number (-inf = not checked)",
        );
        let from_ok = v.check(
            c.keep1_from_s.is_finite() && c.keep1_from_s >= 0.0,
            "montecarlo.criteria.keep1_from_s",
            num(c.keep1_from_s),
            "must be a finite time ≥ 0",
        );
        if from_ok {
            v.check(
                c.keep1_until_s >= c.keep1_from_s,
                "montecarlo.criteria.keep1_until_s",
                num(c.keep1_until_s),
                &format!(
                    "must not be before montecarlo.criteria.keep1_from_s = {}",
                    num(c.keep1_from_s)
                ),
            );
        }
    }
}
