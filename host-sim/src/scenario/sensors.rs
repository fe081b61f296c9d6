//! `[sensors]` and `[faults]`: the sensors the controller reads through (their models and
//! errors) and the faults injected between the plant and the controller
//! (`crate::faults::Injector` flies them; `convert` turns these sections into its parameters).
//!
//! Every error defaults to zero: a section left out is an ideal sensor (the paper's
//! idealisation, which `scenarios/paper.toml` flies), except that the α̇ rate sensor is off
//! unless `sensors.alpha_rate.enabled = true` (no flight sensor measures α̇).
//! Realistic figures, and what each stands for, are in the README's sensor table and in
//! `scenarios/paper-montecarlo.toml`.

use serde::{Deserialize, Serialize};

use crate::sensors::{SensedQuantity, SensorErrors, Window};

use super::rules::{num, Validator};

/// `[sensors]`: what the controller reads is the plant's truth through these models (see each
/// section), then rounded to the controller's scalar type. The noise is reproducible: one
/// seeded generator per sensor (see `faults::Pcg32`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorsSection {
    /// Seed of the noise generators (the same seed gives the same run, on any machine).
    #[serde(default)]
    pub seed: u64,
    /// The reel encoder: the paid-out length and the reel's rate (units: m).
    #[serde(default)]
    pub length: EncoderSection,
    /// The swing sensor: the in-plane angle α (units: rad).
    #[serde(default)]
    pub alpha: SwingSensorSection,
    /// The optional in-plane rate sensor α̇ (units: rad/s; off by default).
    #[serde(default)]
    pub alpha_rate: RateSensorSection,
    /// The load cell at the reel: the tether's tension (units: N).
    #[serde(default)]
    pub load_cell: LoadCellSection,
}

/// Declares the section of a sensor that reads through the errors every such sensor shares:
/// `noise_std`, `bias`, `quantum` and a stuck window (`stuck_from_s`, `stuck_until_s`), in the
/// sensor's unit, after the sensor's own fields. Each section stays its own serde struct with
/// `deny_unknown_fields` (a shared struct `#[serde(flatten)]`ed into each would lose it), and
/// a field a file leaves out takes the section's `Default`.
macro_rules! sensor_section {
    (
        $(#[$doc:meta])*
        pub struct $name:ident in $unit:literal {
            $(
                $(#[$field_doc:meta])*
                pub $field:ident: $ty:ty = $default:expr,
            )*
        }
    ) => {
        $(#[$doc])*
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct $name {
            $(
                $(#[$field_doc])*
                pub $field: $ty,
            )*
            #[doc = concat!("Standard deviation of white Gaussian noise added every sample, ", $unit, " (0 = none).")]
            pub noise_std: f64,
            #[doc = concat!("Constant offset added to every sample, ", $unit, ".")]
            pub bias: f64,
            #[doc = concat!("Quantisation step, ", $unit, " (0 = none).")]
            pub quantum: f64,
            /// The sensor repeats the reading it gave at this time, s (inf = never).
            pub stuck_from_s: f64,
            /// … until this time, s (inf = to the end of the run).
            pub stuck_until_s: f64,
        }

        impl Default for $name {
            fn default() -> Self {
                Self {
                    $($field: $default,)*
                    noise_std: 0.0,
                    bias: 0.0,
                    quantum: 0.0,
                    stuck_from_s: f64::INFINITY,
                    stuck_until_s: f64::INFINITY,
                }
            }
        }

        impl $name {
            /// The shared errors as the simulator's sensor models take them (a stuck window
            /// from `inf`, the default, is none).
            pub fn errors(&self) -> SensorErrors {
                SensorErrors {
                    noise_std: self.noise_std,
                    bias: self.bias,
                    quantum: self.quantum,
                    stuck: (self.stuck_from_s != f64::INFINITY).then_some(Window {
                        from_s: self.stuck_from_s,
                        until_s: self.stuck_until_s,
                    }),
                }
            }

            /// Finite errors, a non-negative deviation and quantum, a stuck window that does
            /// not end before it starts; `at` is the section's key (`sensors.alpha`).
            fn check_errors(&self, at: &str, v: &mut Validator) {
                v.non_negative(&format!("{at}.noise_std"), self.noise_std);
                v.finite(&format!("{at}.bias"), self.bias);
                v.non_negative(&format!("{at}.quantum"), self.quantum);
                v.window(
                    &format!("{at}.stuck_from_s"),
                    self.stuck_from_s,
                    &format!("{at}.stuck_until_s"),
                    self.stuck_until_s,
                    true,
                );
            }
        }
    };
}

sensor_section! {
    /// `[sensors.length]`: the reel encoder. The length the drum has paid out, plus bias and
    /// noise (tether slip and stretch on the drum; the bias is the zero of the count), rounded
    /// to `quantum` and frozen in a stuck window (as any sensor below), is counted in whole
    /// encoder counts of 2π·`drum_radius_m`/`counts_per_rev` (when `counts_per_rev` > 0); the
    /// reel's rate is the count difference over the period. With `counts_per_rev = 0` and no
    /// error the encoder reads the truth, length and rate.
    pub struct EncoderSection in "m" {
        /// Encoder counts per drum revolution (0: no counting, the length is continuous).
        pub counts_per_rev: u32 = 0,
        /// Radius of the drum the tether leaves, m: one count is 2π·radius/counts_per_rev of
        /// tether (default 0.1 m: a 20 cm drum, the size of a small deployer's spool).
        pub drum_radius_m: f64 = 0.1,
    }
}

sensor_section! {
    /// `[sensors.alpha]`: the swing sensor (a deployer angle sensor or relative navigation).
    /// Each period it measures α + bias (misalignment) + noise, rounded to `quantum` (frozen in
    /// a stuck window); the controller receives the measurement of `latency_periods` periods
    /// ago, or nothing (an α dropout, `alpha_rad: None`: the estimator predicts only) with
    /// probability `dropout_prob`, in a `[[faults.alpha_dropout]]` window, and in the first
    /// `latency_periods` periods.
    pub struct SwingSensorSection in "rad" {
        /// Whole control periods between measuring α and the controller receiving it (0: the
        /// reading is of this period).
        pub latency_periods: u16 = 0,
        /// Probability that a period's α does not arrive (independent draws; 0 = never).
        pub dropout_prob: f64 = 0.0,
    }
}

sensor_section! {
    /// `[sensors.alpha_rate]`: an α̇ rate sensor, which no flight has carried: the paper's
    /// idealisation (Table 1), for comparison. Off unless `enabled`; then α̇ + bias + noise,
    /// rounded to `quantum`, frozen in a stuck window.
    pub struct RateSensorSection in "rad/s" {
        /// The sensor is fitted and read (the controller then flies on it, the paper's law as
        /// printed; without it the controller flies its estimator on α alone).
        pub enabled: bool = false,
    }
}

/// `[sensors.load_cell]`: the tension at the reel, T + bias + noise, rounded to `quantum_n`
/// and held within ±`full_scale_n` (a load cell saturates at its full scale).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadCellSection {
    /// The load cell is fitted and read (`false`: the controller gets no tension).
    #[serde(default = "yes")]
    pub enabled: bool,
    /// Standard deviation of white Gaussian noise added every sample, N (0 = none).
    #[serde(default)]
    pub noise_std_n: f64,
    /// Constant offset, N (the zero's drift).
    #[serde(default)]
    pub bias_n: f64,
    /// Quantisation step, N (0 = none; the converter's resolution).
    #[serde(default)]
    pub quantum_n: f64,
    /// The largest tension it reads, N: beyond ±full scale it reads ±full scale (inf = none).
    #[serde(default = "infinity")]
    pub full_scale_n: f64,
}

impl Default for LoadCellSection {
    fn default() -> Self {
        Self {
            enabled: true,
            noise_std_n: 0.0,
            bias_n: 0.0,
            quantum_n: 0.0,
            full_scale_n: f64::INFINITY,
        }
    }
}

fn yes() -> bool {
    true
}
/// `[faults]`: injected faults. Windows are half-open, [from_s, until_s), on the control ticks.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultsSection {
    /// `[[faults.dropout]]`: no sample arrives (the controller's `step_missing`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dropout: Vec<WindowSection>,
    /// `[[faults.alpha_dropout]]`: the sample arrives without α (`alpha_rad: None`: the swing
    /// sensor gave nothing; the estimator predicts only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub alpha_dropout: Vec<WindowSection>,
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

/// `[[faults.corrupt]]`: `sensor` reads `value` during [from_s, until_s).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CorruptSection {
    /// Which sensor.
    pub sensor: SensedQuantity,
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
    /// Finite errors, non-negative deviations and quanta, stuck windows that do not end
    /// before they start; a drum radius above 0 when the encoder counts; a probability in
    /// [0, 1]; a full scale above 0.
    pub(super) fn check(&self, v: &mut Validator) {
        let (l, a) = (&self.length, &self.alpha);
        l.check_errors("sensors.length", v);
        a.check_errors("sensors.alpha", v);
        self.alpha_rate.check_errors("sensors.alpha_rate", v);
        if l.counts_per_rev > 0 {
            v.positive("sensors.length.drum_radius_m", l.drum_radius_m);
        } else {
            v.non_negative("sensors.length.drum_radius_m", l.drum_radius_m);
        }
        v.check(
            (0.0..=1.0).contains(&a.dropout_prob),
            "sensors.alpha.dropout_prob",
            num(a.dropout_prob),
            "must be a probability, in [0, 1]",
        );
        let c = &self.load_cell;
        v.non_negative("sensors.load_cell.noise_std_n", c.noise_std_n);
        v.finite("sensors.load_cell.bias_n", c.bias_n);
        v.non_negative("sensors.load_cell.quantum_n", c.quantum_n);
        v.limit("sensors.load_cell.full_scale_n", c.full_scale_n);
    }
}

/// The most entries of each fault list (`[[faults.dropout]]`, `[[faults.alpha_dropout]]`,
/// `[[faults.corrupt]]`, `[[faults.length_glitch]]`): every control tick looks at each entry, so a run's cost grows
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
        let alpha_dropout_ok = within("alpha_dropout", self.alpha_dropout.len());
        let corrupt_ok = within("corrupt", self.corrupt.len());
        let glitch_ok = within("length_glitch", self.length_glitch.len());
        let take = |ok: bool| if ok { usize::MAX } else { 0 };
        let span = |w: &WindowSection| (w.from_s, w.until_s);
        let dropouts = self.dropout.iter().take(take(dropout_ok));
        check_windows("dropout", dropouts.map(span), v);
        let alpha_dropouts = self.alpha_dropout.iter().take(take(alpha_dropout_ok));
        check_windows("alpha_dropout", alpha_dropouts.map(span), v);
        let corrupt = self.corrupt.iter().take(take(corrupt_ok));
        check_windows("corrupt", corrupt.map(|c| (c.from_s, c.until_s)), v);
        for (i, g) in self.length_glitch.iter().take(take(glitch_ok)).enumerate() {
            v.non_negative(&format!("faults.length_glitch[{i}].at_s"), g.at_s);
            v.finite(&format!("faults.length_glitch[{i}].size_m"), g.size_m);
        }
    }
}

/// Each window of the list `faults.{list}` starts at a finite time ≥ 0 and ends after it starts.
fn check_windows(list: &str, windows: impl Iterator<Item = (f64, f64)>, v: &mut Validator) {
    for (i, (from_s, until_s)) in windows.enumerate() {
        let at = format!("faults.{list}[{i}]");
        v.window(
            &format!("{at}.from_s"),
            from_s,
            &format!("{at}.until_s"),
            until_s,
            false,
        );
    }
}
