//! `[sensors]` and `[faults]`: the errors and faults injected between the plant and the
//! controller (`crate::faults::Injector` flies them; `convert` turns these sections into its
//! parameters).

use serde::{Deserialize, Serialize};

use super::rules::Validator;

/// `[sensors]`: what the controller reads is the plant's truth plus these errors, applied in the
/// order bias, noise, quantisation, then a stuck window freezes the reading (then the sensed
/// values are rounded to the controller's scalar type last). The noise is reproducible: one
/// seeded generator per sensor (see `faults::Pcg32`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorsSection {
    /// Seed of the noise generators (the same seed gives the same run, on any machine).
    #[serde(default)]
    pub seed: u64,
    /// The length encoder (units: m).
    #[serde(default)]
    pub length: SensorSection,
    /// The in-plane angle sensor α (units: rad).
    #[serde(default)]
    pub alpha: SensorSection,
    /// The in-plane rate sensor α̇ (units: rad/s).
    #[serde(default)]
    pub alpha_rate: SensorSection,
}

/// `[sensors.length]`, `[sensors.alpha]`, `[sensors.alpha_rate]`: one sensor's errors, in the
/// sensor's own unit (m, rad, rad/s).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSection {
    /// Standard deviation of white Gaussian noise added every sample (0 = none).
    #[serde(default)]
    pub noise_std: f64,
    /// Constant offset added to every sample.
    #[serde(default)]
    pub bias: f64,
    /// Quantisation step: the reading is rounded to a multiple of it (0 = none).
    #[serde(default)]
    pub quantum: f64,
    /// The sensor repeats the reading it gave at this time, s (inf = never).
    #[serde(default = "infinity")]
    pub stuck_from_s: f64,
    /// … until this time, s (inf = to the end of the run).
    #[serde(default = "infinity")]
    pub stuck_until_s: f64,
}

impl Default for SensorSection {
    fn default() -> Self {
        Self {
            noise_std: 0.0,
            bias: 0.0,
            quantum: 0.0,
            stuck_from_s: f64::INFINITY,
            stuck_until_s: f64::INFINITY,
        }
    }
}

/// `[faults]`: injected faults. Windows are half-open, [from_s, until_s), on the control ticks.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultsSection {
    /// `[[faults.dropout]]`: no sample arrives (the controller's `step_missing`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dropout: Vec<WindowSection>,
    /// `[[faults.corrupt]]`: one sensor reads a fixed value (NaN, inf, anything).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub corrupt: Vec<CorruptSection>,
    /// `[[faults.length_glitch]]`: the length encoder is off by `size_m` for one tick.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub length_glitch: Vec<GlitchSection>,
}

/// A time window [from_s, until_s).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindowSection {
    /// Start, s.
    pub from_s: f64,
    /// End (excluded), s; inf = to the end of the run.
    pub until_s: f64,
}

/// The sensors a `[[faults.corrupt]]` entry can hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SensorName {
    /// The length encoder.
    Length,
    /// The α sensor.
    Alpha,
    /// The α̇ sensor.
    AlphaRate,
    /// The orbit-rate source.
    OrbitRate,
}

impl SensorName {
    /// The name as written in scenario files.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Length => "length",
            Self::Alpha => "alpha",
            Self::AlphaRate => "alpha_rate",
            Self::OrbitRate => "orbit_rate",
        }
    }
}

/// `[[faults.corrupt]]`: `sensor` reads `value` during [from_s, until_s).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CorruptSection {
    /// Which sensor.
    pub sensor: SensorName,
    /// Start, s.
    pub from_s: f64,
    /// End (excluded), s; inf = to the end of the run.
    pub until_s: f64,
    /// The reading, in the sensor's unit; `nan`, `inf` and `-inf` are allowed (that is the
    /// point).
    pub value: f64,
}

/// `[[faults.length_glitch]]`: the length reading of the tick at `at_s` is off by `size_m`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GlitchSection {
    /// When, s (the tick at or after it).
    pub at_s: f64,
    /// Size of the error, m.
    pub size_m: f64,
}

fn infinity() -> f64 {
    f64::INFINITY
}

impl SensorsSection {
    /// Finite errors; a stuck window that does not end before it starts.
    pub(super) fn check(&self, v: &mut Validator) {
        for (name, sensor) in [
            ("sensors.length", &self.length),
            ("sensors.alpha", &self.alpha),
            ("sensors.alpha_rate", &self.alpha_rate),
        ] {
            v.non_negative(&format!("{name}.noise_std"), sensor.noise_std);
            v.finite(&format!("{name}.bias"), sensor.bias);
            v.non_negative(&format!("{name}.quantum"), sensor.quantum);
            v.window(
                &format!("{name}.stuck_from_s"),
                sensor.stuck_from_s,
                &format!("{name}.stuck_until_s"),
                sensor.stuck_until_s,
                true,
            );
        }
    }
}

/// The most entries of each fault list (`[[faults.dropout]]`, `[[faults.corrupt]]`,
/// `[[faults.length_glitch]]`): every control tick looks at each entry, so a run's cost grows
/// with their number.
pub const MAX_FAULT_ENTRIES: usize = 1_000;

impl FaultsSection {
    /// At most [`MAX_FAULT_ENTRIES`] per list; windows that start at a finite time ≥ 0 and end
    /// after they start; finite glitches. A list beyond the bound is reported as a whole.
    pub(super) fn check(&self, v: &mut Validator) {
        let mut within = |list: &str, len: usize| {
            v.check(
                len <= MAX_FAULT_ENTRIES,
                &format!("faults.{list}"),
                format!("[{len} entries]"),
                &format!("has more entries than the simulator's {MAX_FAULT_ENTRIES}"),
            )
        };
        let dropout_ok = within("dropout", self.dropout.len());
        let corrupt_ok = within("corrupt", self.corrupt.len());
        let glitch_ok = within("length_glitch", self.length_glitch.len());
        let take = |ok: bool| if ok { usize::MAX } else { 0 };
        for (i, w) in self.dropout.iter().take(take(dropout_ok)).enumerate() {
            let at = format!("faults.dropout[{i}]");
            v.window(
                &format!("{at}.from_s"),
                w.from_s,
                &format!("{at}.until_s"),
                w.until_s,
                false,
            );
        }
        for (i, c) in self.corrupt.iter().take(take(corrupt_ok)).enumerate() {
            let at = format!("faults.corrupt[{i}]");
            v.window(
                &format!("{at}.from_s"),
                c.from_s,
                &format!("{at}.until_s"),
                c.until_s,
                false,
            );
        }
        for (i, g) in self.length_glitch.iter().take(take(glitch_ok)).enumerate() {
            v.non_negative(&format!("faults.length_glitch[{i}].at_s"), g.at_s);
            v.finite(&format!("faults.length_glitch[{i}].size_m"), g.size_m);
        }
    }
}
