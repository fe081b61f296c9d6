//! Scenario files: the TOML description of one simulated mission.
//!
//! `scenarios/paper.toml` is the paper's Section 6 as fixed in SPEC §7. Every field has a
//! unit in its name. Loading, `--set` overrides and validation live in this module.

use serde::{Deserialize, Serialize};

/// A complete mission scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Short name, used in titles and file names.
    pub name: String,
    /// One line saying what the scenario is.
    #[serde(default)]
    pub description: String,
    /// Orbit of the system's centre of mass.
    pub orbit: OrbitSection,
    /// Satellite masses.
    pub masses: MassesSection,
    /// Tether properties.
    pub tether: TetherSection,
    /// Initial state at t = 0.
    pub initial: InitialSection,
    /// Controller gains and period.
    pub controller: ControllerSection,
    /// Stage 1: deploy, then keep.
    pub stage1: Stage1Section,
    /// Stage 2: slew, retrieve, then keep.
    pub stage2: Stage2Section,
    /// Run length and output.
    pub simulation: SimulationSection,
    /// A Monte Carlo campaign on this scenario: dispersions and pass/fail criteria
    /// (`tss-sim montecarlo`; default: none; `tss-sim run` ignores it).
    #[serde(default)]
    pub montecarlo: crate::montecarlo::MonteCarloSection,
    /// Reel limits enforced by the controller (defaults: the paper's, 15 m/s, 15 m/s², 0.5 m to
    /// 40 km, wide enough never to act in the paper's mission).
    #[serde(default)]
    pub envelope: EnvelopeSection,
    /// Sensor errors injected between the plant and the controller (default: perfect sensors).
    #[serde(default)]
    pub sensors: SensorsSection,
    /// Injected faults: dropouts, corrupted readings, length-encoder glitches (default: none).
    #[serde(default)]
    pub faults: FaultsSection,
    /// The physical reel drive: lag and its own saturation (default: ideal, the command is the
    /// reel's rate).
    #[serde(default)]
    pub reel: ReelSection,
    /// Thresholds of the controller's sensor monitor (defaults: `MonitorConfig::default_for_period`).
    #[serde(default)]
    pub monitor: MonitorSection,
    /// Faults of the processor-in-the-loop serial link (`tss-sim run --pil`; default: none).
    /// A host-linked run has no link and ignores it.
    #[serde(default)]
    pub link: LinkSection,
}

/// `[link]`: faults injected into the plant → firmware sample frames of a processor-in-the-loop
/// run (`crate::pil`). Each frame meets at most one fault, drawn with these probabilities from a
/// PCG32 stream seeded by `seed` (the same seed gives the same faults on the same ticks).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkSection {
    /// Seed of the link's fault generator.
    #[serde(default)]
    pub seed: u64,
    /// Probability that a sample frame is lost (the firmware times out: a dropout).
    #[serde(default)]
    pub drop_prob: f64,
    /// Probability that one byte of a sample frame is changed (the firmware rejects it: a
    /// dropout).
    #[serde(default)]
    pub corrupt_prob: f64,
    /// Probability that a sample frame is sent twice (the firmware discards the copy).
    #[serde(default)]
    pub duplicate_prob: f64,
    /// Probability that a sample frame is held back and sent after the next one (late: the
    /// firmware times out on its period, then discards it).
    #[serde(default)]
    pub reorder_prob: f64,
}

impl LinkSection {
    /// `true` if no fault is injected.
    pub fn is_clean(&self) -> bool {
        self.drop_prob == 0.0
            && self.corrupt_prob == 0.0
            && self.duplicate_prob == 0.0
            && self.reorder_prob == 0.0
    }
}

/// `[envelope]`: the reel's operating limits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvelopeSection {
    /// Largest reel speed, m/s.
    pub max_rate_mps: f64,
    /// Largest reel acceleration, m/s².
    pub max_accel_mps2: f64,
    /// Shortest tether (docking), m.
    pub min_length_m: f64,
    /// Longest tether (spool capacity), m.
    pub max_length_m: f64,
}

impl Default for EnvelopeSection {
    fn default() -> Self {
        Self {
            max_rate_mps: 15.0,
            max_accel_mps2: 15.0,
            min_length_m: 0.5,
            max_length_m: 40_000.0,
        }
    }
}

/// `[sensors]`: what the controller reads is the plant's truth plus these errors, applied in the
/// order bias, noise, quantisation, then a stuck window freezes the reading (SPEC: sensed
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

/// `[reel]`: the physical reel drive between the command and the tether. Its actual rate v
/// follows the command u as a first-order lag, dv/dt = (u − v)/lag_s, with its own rate and
/// acceleration saturation (separate from the controller's `[envelope]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReelSection {
    /// Time constant of the lag, s (0 = the rate follows the command at once).
    #[serde(default)]
    pub lag_s: f64,
    /// Largest rate the drive can reach, m/s (inf = no limit).
    #[serde(default = "infinity")]
    pub max_rate_mps: f64,
    /// Largest acceleration the drive can produce, m/s² (inf = no limit).
    #[serde(default = "infinity")]
    pub max_accel_mps2: f64,
}

impl Default for ReelSection {
    fn default() -> Self {
        Self {
            lag_s: 0.0,
            max_rate_mps: f64::INFINITY,
            max_accel_mps2: f64::INFINITY,
        }
    }
}

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
        }
    }
}

fn infinity() -> f64 {
    f64::INFINITY
}

/// `[orbit]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrbitSection {
    /// Semi-major axis a (the radius of a circular orbit), m.
    pub semi_major_axis_m: f64,
    /// Eccentricity e, in [0, 1).
    #[serde(default)]
    pub eccentricity: f64,
    /// True anomaly θ at t = 0, rad.
    #[serde(default)]
    pub initial_true_anomaly_rad: f64,
}

/// `[masses]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassesSection {
    /// m01, main satellite with the whole tether on the reel, kg.
    pub main_initial_kg: f64,
    /// m2, sub-satellite, kg.
    pub sub_kg: f64,
}

/// `[tether]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TetherSection {
    /// ρ, linear density, kg/m (0 = massless, the paper's run).
    #[serde(default)]
    pub density_kg_per_m: f64,
}

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
    #[serde(default = "one_f64")]
    pub keep_capture_m: f64,
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

/// `[simulation]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSection {
    /// Mission length, s.
    pub duration_s: f64,
    /// RK4 sub-steps per control period (≥ 1).
    #[serde(default = "one")]
    pub substeps: u32,
    /// Interval between rows of history.csv, s (a multiple of the control period).
    #[serde(default = "ten")]
    pub output_interval_s: f64,
}

fn one_f64() -> f64 {
    1.0
}
fn one() -> u32 {
    1
}
fn ten() -> f64 {
    10.0
}

// ---------------------------------------------------------------------------------------------
// Loading, `--set` overrides and validation.
// ---------------------------------------------------------------------------------------------

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::path::Path;
use std::sync::OnceLock;

/// Equatorial radius of the Earth (WGS-84), m: the orbit's perigee must lie above it.
pub const EARTH_EQUATORIAL_RADIUS_M: f64 = 6_378_137.0;

/// Relative tolerance when checking that one interval is a whole multiple of another
/// (e.g. the output interval of the control period): 1e-9 of the ratio.
const WHOLE_MULTIPLE_REL_TOL: f64 = 1e-9;

/// The simulator counts control ticks in a `u32`: a run may last at most this many periods.
pub const MAX_TICKS: f64 = u32::MAX as f64;

/// Why a scenario could not be loaded. Every message names the file and, where there is one,
/// the field (dotted path, e.g. `stage1.band_start_m`) and the value at fault.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("{file}: cannot read the scenario file")]
    Io {
        /// The scenario file, as given.
        file: String,
        /// The underlying I/O error.
        #[source]
        error: std::io::Error,
    },
    /// The file is not valid TOML.
    #[error("{file}: not valid TOML: {message}")]
    Syntax {
        /// The scenario file, as given.
        file: String,
        /// The TOML parser's message (with line and column).
        message: String,
    },
    /// A `--set` argument is not of the form `key=value`.
    #[error("{file}: --set {arg:?}: {message}")]
    BadOverride {
        /// The scenario file, as given.
        file: String,
        /// The `--set` argument as given.
        arg: String,
        /// What is wrong with it.
        message: String,
    },
    /// A key (in the file or in a `--set`) that the scenario does not have.
    #[error("{file}: {origin}unknown key `{key}` ({hint})")]
    UnknownKey {
        /// The scenario file, as given.
        file: String,
        /// `"--set k=v: "` when the key came from an override, else empty.
        origin: String,
        /// The dotted key.
        key: String,
        /// The keys that are valid at that place.
        hint: String,
    },
    /// A value of the wrong type (a string for a number, a float for an integer, …).
    #[error("{file}: {origin}{key} = {value} {message}")]
    WrongType {
        /// The scenario file, as given.
        file: String,
        /// `"--set k=v: "` when the value came from an override, else empty.
        origin: String,
        /// The dotted key.
        key: String,
        /// The offending value, as TOML.
        value: String,
        /// What was expected.
        message: String,
    },
    /// A required key is absent.
    #[error("{file}: missing key `{key}`")]
    MissingKey {
        /// The scenario file, as given.
        file: String,
        /// The dotted key.
        key: String,
    },
    /// Any other deserialization failure (the TOML library's message).
    #[error("{file}: {message}")]
    Deserialize {
        /// The scenario file, as given.
        file: String,
        /// The deserializer's message.
        message: String,
    },
    /// The scenario deserialized but makes no physical sense: one line per problem.
    #[error("{}", format_problems(file, problems))]
    Invalid {
        /// The scenario file, as given.
        file: String,
        /// Every rule that failed, in field order.
        problems: Vec<Problem>,
    },
}

/// One failed validation rule: `field = value message`.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    /// Dotted path of the field at fault, e.g. `stage1.band_start_m`.
    pub field: String,
    /// The offending value as written in messages.
    pub value: String,
    /// What is wrong, e.g. `must be below stage1.keep_length_m = 30000`.
    pub message: String,
    /// True when the value came from a `--set` override.
    pub from_override: bool,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {} {}", self.field, self.value, self.message)?;
        if self.from_override {
            write!(f, " (set by --set)")?;
        }
        Ok(())
    }
}

fn format_problems(file: &str, problems: &[Problem]) -> String {
    let lines: Vec<String> = problems.iter().map(|p| format!("{file}: {p}")).collect();
    lines.join("\n")
}

impl Scenario {
    /// Reads a scenario file, applies `--set key=value` overrides (dotted keys, values parsed as
    /// TOML scalars; a bare word is a string), deserializes and validates it.
    ///
    /// ```
    /// # use tss_sim::scenario::Scenario;
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/paper.toml");
    /// let s = Scenario::load(path, &["simulation.duration_s=3600".to_string()]).unwrap();
    /// assert_eq!(s.simulation.duration_s, 3600.0);
    /// ```
    pub fn load(path: impl AsRef<Path>, overrides: &[String]) -> Result<Scenario, ScenarioError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|error| ScenarioError::Io {
            file: file.clone(),
            error,
        })?;
        Self::from_toml_str(&text, &file, overrides)
    }

    /// Like [`Scenario::load`] on text already read; `file` is the name used in messages.
    pub fn from_toml_str(
        text: &str,
        file: &str,
        overrides: &[String],
    ) -> Result<Scenario, ScenarioError> {
        let mut table: toml::Table = toml::from_str(text).map_err(|e| ScenarioError::Syntax {
            file: file.to_string(),
            message: e.to_string().trim_end().to_string(),
        })?;
        let schema = schema();
        check_table(&table, "", schema, file, "")?;
        if !overrides.is_empty() {
            // Apply overrides on top of the file *with its defaults filled in*, so that setting
            // one key of a section the file leaves to its default (e.g. `[envelope]`) keeps the
            // section's other defaults. A file that is incomplete by itself is used as it is.
            let complete = toml::Value::Table(table.clone())
                .try_into::<Scenario>()
                .ok()
                .and_then(|sc| toml::Table::try_from(sc).ok());
            if let Some(complete) = complete {
                table = complete;
            }
        }
        let mut overridden = BTreeSet::new();
        for arg in overrides {
            let key = apply_override(&mut table, arg, schema, file)?;
            overridden.insert(key);
        }
        let scenario: Scenario = toml::Value::Table(table.clone())
            .try_into()
            .map_err(|e: toml::de::Error| deserialize_error(&e, &table, schema, file))?;
        let mut problems = scenario.problems();
        if problems.is_empty() {
            return Ok(scenario);
        }
        for p in &mut problems {
            // `faults.dropout[0].from_s` came from `--set faults.dropout=[...]`.
            let element_of = |k: &String| {
                p.field
                    .strip_prefix(k.as_str())
                    .is_some_and(|r| r.starts_with('['))
            };
            p.from_override = overridden.contains(&p.field) || overridden.iter().any(element_of);
        }
        Err(ScenarioError::Invalid {
            file: file.to_string(),
            problems,
        })
    }

    /// Checks that the scenario makes physical sense; returns every failed rule (empty = valid).
    pub fn problems(&self) -> Vec<Problem> {
        let mut v = Validator::default();
        let s = self;

        // name: it names the default output directory.
        let name_ok = !s.name.trim().is_empty()
            && s.name != "."
            && s.name != ".."
            && !s
                .name
                .chars()
                .any(|c| c == '/' || c == '\\' || c.is_control());
        v.check(
            name_ok,
            "name",
            format!("{:?}", s.name),
            "must be a non-empty file name (no '/', '\\' or control characters, not '.' or '..')",
        );

        // [orbit]
        let o = &s.orbit;
        v.positive("orbit.semi_major_axis_m", o.semi_major_axis_m);
        if v.finite("orbit.eccentricity", o.eccentricity) {
            v.check(
                (0.0..1.0).contains(&o.eccentricity),
                "orbit.eccentricity",
                num(o.eccentricity),
                "must be in [0, 1)",
            );
        }
        v.finite("orbit.initial_true_anomaly_rad", o.initial_true_anomaly_rad);
        if o.semi_major_axis_m.is_finite()
            && o.semi_major_axis_m > 0.0
            && (0.0..1.0).contains(&o.eccentricity)
        {
            let perigee_m = o.semi_major_axis_m * (1.0 - o.eccentricity);
            v.check(
                perigee_m > EARTH_EQUATORIAL_RADIUS_M,
                "orbit.semi_major_axis_m",
                num(o.semi_major_axis_m),
                &format!(
                    "puts the perigee a(1 − e) = {} m (orbit.eccentricity = {}) inside the Earth \
                     (radius {EARTH_EQUATORIAL_RADIUS_M} m)",
                    num(perigee_m),
                    num(o.eccentricity)
                ),
            );
        }

        // [masses]
        v.positive("masses.main_initial_kg", s.masses.main_initial_kg);
        v.positive("masses.sub_kg", s.masses.sub_kg);

        // [initial]
        let i = &s.initial;
        v.positive("initial.length_m", i.length_m);
        v.finite("initial.length_rate_mps", i.length_rate_mps);
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

        // [controller]
        let c = &s.controller;
        v.positive("controller.period_s", c.period_s);
        v.positive("controller.k1_per_s", c.k1_per_s);
        v.positive("controller.k2_per_s2", c.k2_per_s2);
        v.positive("controller.keep_capture_m", c.keep_capture_m);

        // [envelope]: the reel's limits, which the controller enforces.
        let env = &s.envelope;
        let rate_ok = v.positive("envelope.max_rate_mps", env.max_rate_mps);
        v.positive("envelope.max_accel_mps2", env.max_accel_mps2);
        let min_ok = v.positive("envelope.min_length_m", env.min_length_m);
        let max_ok = v.positive("envelope.max_length_m", env.max_length_m);
        let env_ok = min_ok
            && max_ok
            && v.check(
                env.min_length_m < env.max_length_m,
                "envelope.max_length_m",
                num(env.max_length_m),
                &format!(
                    "must be above envelope.min_length_m = {}",
                    num(env.min_length_m)
                ),
            );
        if rate_ok && i.length_rate_mps.is_finite() {
            v.check(
                i.length_rate_mps.abs() <= env.max_rate_mps,
                "initial.length_rate_mps",
                num(i.length_rate_mps),
                &format!(
                    "must be within ±envelope.max_rate_mps = {}",
                    num(env.max_rate_mps)
                ),
            );
        }
        if env_ok && i.length_m.is_finite() && i.length_m > 0.0 {
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

        // [stage1]: Eq. 34
        let s1 = &s.stage1;
        v.non_negative("stage1.decay_rate_per_s", s1.decay_rate_per_s);
        v.angle_in_open_range(
            "stage1.deploy_angle_rad",
            s1.deploy_angle_rad,
            (-std::f64::consts::FRAC_PI_2, 0.0),
            "(−π/2, 0) (the deployment side, Eq. 33)",
        );
        let s1_band = v.positive("stage1.band_start_m", s1.band_start_m);
        let s1_keep = v.positive("stage1.keep_length_m", s1.keep_length_m);
        if s1_band && s1_keep {
            v.check(
                s1.band_start_m < s1.keep_length_m,
                "stage1.band_start_m",
                num(s1.band_start_m),
                &format!(
                    "must be below stage1.keep_length_m = {}",
                    num(s1.keep_length_m)
                ),
            );
        }
        v.non_negative("stage1.keep_slope_rad_per_m", s1.keep_slope_rad_per_m);

        // [stage2]: slew, then Eq. 35
        let s2 = &s.stage2;
        if v.non_negative("stage2.start_time_s", s2.start_time_s) {
            v.whole_multiple_of_period("stage2.start_time_s", s2.start_time_s, c.period_s, true);
        }
        v.non_negative("stage2.decay_rate_per_s", s2.decay_rate_per_s);
        v.angle_in_open_range(
            "stage2.retrieve_angle_rad",
            s2.retrieve_angle_rad,
            (0.0, std::f64::consts::FRAC_PI_2),
            "(0, π/2) (the retrieval side, Eq. 33)",
        );
        v.positive("stage2.slew_rate_radps", s2.slew_rate_radps);
        let s2_band = v.positive("stage2.band_start_m", s2.band_start_m);
        let s2_keep = v.positive("stage2.keep_length_m", s2.keep_length_m);
        if s2_band && s2_keep {
            v.check(
                s2.keep_length_m < s2.band_start_m,
                "stage2.band_start_m",
                num(s2.band_start_m),
                &format!(
                    "must be above stage2.keep_length_m = {}",
                    num(s2.keep_length_m)
                ),
            );
        }
        if s2_keep && s1_keep {
            v.check(
                s2.keep_length_m < s1.keep_length_m,
                "stage2.keep_length_m",
                num(s2.keep_length_m),
                &format!(
                    "must be below stage1.keep_length_m = {} (stage 2 retrieves)",
                    num(s1.keep_length_m)
                ),
            );
        }
        v.non_negative("stage2.keep_slope_rad_per_m", s2.keep_slope_rad_per_m);
        if env_ok {
            for (field, keep, ok) in [
                ("stage1.keep_length_m", s1.keep_length_m, s1_keep),
                ("stage2.keep_length_m", s2.keep_length_m, s2_keep),
            ] {
                if ok {
                    v.check(
                        keep > env.min_length_m && keep < env.max_length_m,
                        field,
                        num(keep),
                        &format!(
                            "must be inside the envelope (envelope.min_length_m = {}, \
                             envelope.max_length_m = {})",
                            num(env.min_length_m),
                            num(env.max_length_m)
                        ),
                    );
                }
            }
        }

        // [tether]: ρ ≥ 0 and the tether never outweighs the main satellite, even paid out to
        // the longest length the envelope allows.
        if v.non_negative("tether.density_kg_per_m", s.tether.density_kg_per_m) {
            let longest_m = env.max_length_m;
            let tether_kg = s.tether.density_kg_per_m * longest_m;
            if max_ok && s.masses.main_initial_kg.is_finite() {
                v.check(
                    tether_kg < s.masses.main_initial_kg,
                    "tether.density_kg_per_m",
                    num(s.tether.density_kg_per_m),
                    &format!(
                        "makes the tether at envelope.max_length_m = {} m weigh {} kg, not \
                         below masses.main_initial_kg = {}",
                        num(longest_m),
                        num(tether_kg),
                        num(s.masses.main_initial_kg)
                    ),
                );
            }
        }

        // [simulation]
        let sim = &s.simulation;
        if v.positive("simulation.duration_s", sim.duration_s) {
            v.whole_multiple_of_period("simulation.duration_s", sim.duration_s, c.period_s, false);
            if c.period_s.is_finite() && c.period_s > 0.0 {
                let ticks = (sim.duration_s / c.period_s).round();
                v.check(
                    ticks <= MAX_TICKS,
                    "simulation.duration_s",
                    num(sim.duration_s),
                    &format!("is {ticks} control periods, more than the simulator's {MAX_TICKS}"),
                );
            }
        }
        v.check(
            sim.substeps >= 1,
            "simulation.substeps",
            sim.substeps.to_string(),
            "must be at least 1",
        );
        if v.positive("simulation.output_interval_s", sim.output_interval_s) {
            v.whole_multiple_of_period(
                "simulation.output_interval_s",
                sim.output_interval_s,
                c.period_s,
                false,
            );
        }

        // [montecarlo]: dispersed fields that exist, complete distributions, sane criteria.
        v.problems.extend(crate::montecarlo::problems(s));

        // [sensors]: finite errors; a stuck window that does not end before it starts.
        for (name, sensor) in [
            ("sensors.length", &s.sensors.length),
            ("sensors.alpha", &s.sensors.alpha),
            ("sensors.alpha_rate", &s.sensors.alpha_rate),
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

        // [faults]: windows that start at a finite time ≥ 0 and end after they start.
        let f = &s.faults;
        for (i, w) in f.dropout.iter().enumerate() {
            let at = format!("faults.dropout[{i}]");
            v.window(
                &format!("{at}.from_s"),
                w.from_s,
                &format!("{at}.until_s"),
                w.until_s,
                false,
            );
        }
        for (i, c) in f.corrupt.iter().enumerate() {
            let at = format!("faults.corrupt[{i}]");
            v.window(
                &format!("{at}.from_s"),
                c.from_s,
                &format!("{at}.until_s"),
                c.until_s,
                false,
            );
        }
        for (i, g) in f.length_glitch.iter().enumerate() {
            v.non_negative(&format!("faults.length_glitch[{i}].at_s"), g.at_s);
            v.finite(&format!("faults.length_glitch[{i}].size_m"), g.size_m);
        }

        // [reel]: a lag ≥ 0; saturations above 0 (inf = none).
        v.non_negative("reel.lag_s", s.reel.lag_s);
        v.limit("reel.max_rate_mps", s.reel.max_rate_mps);
        v.limit("reel.max_accel_mps2", s.reel.max_accel_mps2);

        // [monitor]: the same rules as `MonitorConfig::validate`, named by scenario key.
        let m = &s.monitor;
        for (field, ticks) in [
            ("monitor.coast_ticks", m.coast_ticks),
            ("monitor.recovery_ticks", m.recovery_ticks),
            ("monitor.stuck_ticks", m.stuck_ticks),
        ] {
            v.check(ticks >= 1, field, ticks.to_string(), "must be at least 1");
        }
        v.positive("monitor.length_jump_m", m.length_jump_m);
        v.positive("monitor.alpha_jump_rad", m.alpha_jump_rad);
        v.positive("monitor.stuck_motion_rad", m.stuck_motion_rad);
        v.positive("monitor.max_alpha_rate_radps", m.max_alpha_rate_radps);
        let min_ok = v.positive("monitor.min_orbit_rate_radps", m.min_orbit_rate_radps);
        if v.positive("monitor.max_orbit_rate_radps", m.max_orbit_rate_radps) && min_ok {
            v.check(
                m.max_orbit_rate_radps > m.min_orbit_rate_radps,
                "monitor.max_orbit_rate_radps",
                num(m.max_orbit_rate_radps),
                &format!(
                    "must be above monitor.min_orbit_rate_radps = {}",
                    num(m.min_orbit_rate_radps)
                ),
            );
        }

        // [link]: probabilities in [0, 1] that add up to at most 1 (one fault per frame).
        let l = &s.link;
        let mut all_ok = true;
        for (field, p) in [
            ("link.drop_prob", l.drop_prob),
            ("link.corrupt_prob", l.corrupt_prob),
            ("link.duplicate_prob", l.duplicate_prob),
            ("link.reorder_prob", l.reorder_prob),
        ] {
            all_ok &= v.check((0.0..=1.0).contains(&p), field, num(p), "must be in [0, 1]");
        }
        if all_ok {
            let sum = l.drop_prob + l.corrupt_prob + l.duplicate_prob + l.reorder_prob;
            v.check(
                sum <= 1.0,
                "link.drop_prob + link.corrupt_prob + link.duplicate_prob + link.reorder_prob",
                num(sum),
                "must be at most 1 (each frame meets at most one fault)",
            );
        }
        v.problems
    }
}

/// `{}` of an f64 (shortest round-trip form; `40000` for 40000.0).
fn num(x: f64) -> String {
    format!("{x}")
}

#[derive(Default)]
struct Validator {
    problems: Vec<Problem>,
}

impl Validator {
    /// Records a problem unless `ok`; returns `ok`.
    fn check(&mut self, ok: bool, field: &str, value: String, message: &str) -> bool {
        if !ok {
            self.problems.push(Problem {
                field: field.to_string(),
                value,
                message: message.to_string(),
                from_override: false,
            });
        }
        ok
    }
    fn finite(&mut self, field: &str, x: f64) -> bool {
        self.check(x.is_finite(), field, num(x), "must be a finite number")
    }
    fn positive(&mut self, field: &str, x: f64) -> bool {
        self.finite(field, x) && self.check(x > 0.0, field, num(x), "must be above 0")
    }
    fn non_negative(&mut self, field: &str, x: f64) -> bool {
        self.finite(field, x) && self.check(x >= 0.0, field, num(x), "must not be negative")
    }
    /// A saturation limit: above 0, `inf` meaning none (NaN is rejected).
    fn limit(&mut self, field: &str, x: f64) -> bool {
        self.check(x > 0.0, field, num(x), "must be above 0 (inf = no limit)")
    }
    /// A window [from, until): `from` finite and ≥ 0 (or inf = never, when `never_ok`),
    /// `until` after `from` (inf = to the end of the run; equal to `from` only when both are
    /// inf).
    fn window(
        &mut self,
        from_field: &str,
        from: f64,
        until_field: &str,
        until: f64,
        never_ok: bool,
    ) {
        let from_ok = if never_ok && from == f64::INFINITY {
            true
        } else {
            self.non_negative(from_field, from)
        };
        let until_ok = self.check(
            !until.is_nan(),
            until_field,
            num(until),
            "must be a number (inf = to the end of the run)",
        );
        if from_ok && until_ok && from.is_finite() {
            self.check(
                until > from,
                until_field,
                num(until),
                &format!("must be after {from_field} = {}", num(from)),
            );
        }
    }
    fn angle_in_open_range(&mut self, field: &str, x: f64, (lo, hi): (f64, f64), range: &str) {
        if self.finite(field, x) {
            self.check(
                x > lo && x < hi,
                field,
                num(x),
                &format!("must be within {range}"),
            );
        }
    }
    /// `x` must be `k · period` for a whole k (k ≥ 1, or k ≥ 0 when `zero_ok`).
    fn whole_multiple_of_period(&mut self, field: &str, x: f64, period: f64, zero_ok: bool) {
        if !(period.is_finite() && period > 0.0) {
            return; // reported on controller.period_s
        }
        let ratio = x / period;
        let k = ratio.round();
        let whole = (ratio - k).abs() <= WHOLE_MULTIPLE_REL_TOL * ratio.abs().max(1.0);
        let ok = whole && (k >= 1.0 || (zero_ok && k == 0.0));
        let what = if zero_ok { "non-negative" } else { "positive" };
        self.check(
            ok,
            field,
            num(x),
            &format!(
                "must be a {what} whole multiple of controller.period_s = {}",
                num(period)
            ),
        );
    }
}

// ---- schema: the keys and value types of `Scenario`, traced from its Deserialize impl -------

/// The type a scenario key holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeafKind {
    /// A float (an integer is accepted and converted).
    Float,
    /// An integer within `[min, max]`.
    Integer {
        /// Smallest allowed value.
        min: i64,
        /// Largest allowed value.
        max: i64,
    },
    /// A string.
    String,
    /// A boolean.
    Bool,
    /// One of the listed strings (an enum).
    OneOf(&'static [&'static str]),
}

impl LeafKind {
    fn describe(self) -> String {
        match self {
            LeafKind::Float => "must be a number".to_string(),
            LeafKind::Integer { min, max } => format!("must be an integer in [{min}, {max}]"),
            LeafKind::String => "must be a string".to_string(),
            LeafKind::Bool => "must be true or false".to_string(),
            LeafKind::OneOf(names) => format!("must be one of {}", names.join(", ")),
        }
    }

    /// Does `value` fit? (Integers fit floats.)
    fn accepts(self, value: &toml::Value) -> bool {
        match (self, value) {
            (LeafKind::Float, toml::Value::Float(_) | toml::Value::Integer(_)) => true,
            (LeafKind::Integer { min, max }, toml::Value::Integer(i)) => (min..=max).contains(i),
            (LeafKind::String, toml::Value::String(_)) => true,
            (LeafKind::Bool, toml::Value::Boolean(_)) => true,
            (LeafKind::OneOf(names), toml::Value::String(s)) => names.contains(&s.as_str()),
            _ => false,
        }
    }
}

/// Every key of a scenario file: dotted leaf keys with their types, and the section tables.
#[derive(Debug, Default)]
pub struct Schema {
    /// Dotted key → value type, e.g. `stage1.band_start_m` → `Float`.
    pub leaves: BTreeMap<String, LeafKind>,
    /// Dotted keys of the sections (tables), e.g. `stage1`.
    pub tables: BTreeSet<String>,
    /// Dotted keys of the arrays of tables, e.g. `faults.dropout` (`[[faults.dropout]]`); the
    /// keys of one element are in `leaves` under the array's key, e.g. `faults.dropout.from_s`.
    pub arrays: BTreeSet<String>,
}

impl Schema {
    /// The array of tables that `key` is a field of an element of, if any.
    pub fn array_of(&self, key: &str) -> Option<&str> {
        self.arrays
            .iter()
            .find(|a| {
                key.strip_prefix(a.as_str())
                    .is_some_and(|r| r.starts_with('.'))
            })
            .map(String::as_str)
    }

    /// The keys directly under `prefix` ("" for the top level), comma-separated.
    fn keys_under(&self, prefix: &str) -> String {
        let under = |k: &&String| match prefix {
            "" => !k.contains('.'),
            p => k
                .strip_prefix(p)
                .and_then(|rest| rest.strip_prefix('.'))
                .is_some_and(|rest| !rest.contains('.')),
        };
        let mut keys: Vec<&String> = self.leaves.keys().filter(under).collect();
        keys.extend(self.tables.iter().filter(under));
        keys.sort();
        keys.iter()
            .map(|k| k.rsplit('.').next().unwrap_or(k))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The scenario's key schema (traced once from `Scenario`'s `Deserialize` impl, so it follows
/// the structs automatically).
pub fn schema() -> &'static Schema {
    static SCHEMA: OnceLock<Schema> = OnceLock::new();
    SCHEMA.get_or_init(|| {
        let mut schema = Schema::default();
        let tracer = Tracer {
            path: String::new(),
            out: &mut schema,
        };
        // The tracer feeds every field a placeholder, so this cannot fail for plain structs of
        // numbers, strings, bools, options and unit enums; anything else is a programming error.
        if let Err(e) = <Scenario as Deserialize>::deserialize(tracer) {
            panic!("scenario schema tracing failed: {e}");
        }
        schema
    })
}

struct Tracer<'a> {
    path: String,
    out: &'a mut Schema,
}

type TraceError = serde::de::value::Error;

impl Tracer<'_> {
    fn leaf(self, kind: LeafKind) {
        self.out.leaves.insert(self.path, kind);
    }
    fn int(self, min: i64, max: i64) {
        self.leaf(LeafKind::Integer { min, max });
    }
}

impl<'de> serde::Deserializer<'de> for Tracer<'_> {
    type Error = TraceError;

    fn deserialize_any<V: serde::de::Visitor<'de>>(self, _: V) -> Result<V::Value, TraceError> {
        Err(serde::de::Error::custom(format!(
            "unsupported field type at `{}`",
            self.path
        )))
    }
    fn deserialize_f64<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.leaf(LeafKind::Float);
        v.visit_f64(0.0)
    }
    fn deserialize_f32<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.leaf(LeafKind::Float);
        v.visit_f32(0.0)
    }
    fn deserialize_u8<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(0, u8::MAX.into());
        v.visit_u8(1)
    }
    fn deserialize_u16<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(0, u16::MAX.into());
        v.visit_u16(1)
    }
    fn deserialize_u32<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(0, u32::MAX.into());
        v.visit_u32(1)
    }
    fn deserialize_u64<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(0, i64::MAX);
        v.visit_u64(1)
    }
    fn deserialize_i8<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(i8::MIN.into(), i8::MAX.into());
        v.visit_i8(1)
    }
    fn deserialize_i16<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(i16::MIN.into(), i16::MAX.into());
        v.visit_i16(1)
    }
    fn deserialize_i32<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(i32::MIN.into(), i32::MAX.into());
        v.visit_i32(1)
    }
    fn deserialize_i64<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(i64::MIN, i64::MAX);
        v.visit_i64(1)
    }
    fn deserialize_bool<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.leaf(LeafKind::Bool);
        v.visit_bool(false)
    }
    fn deserialize_str<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.leaf(LeafKind::String);
        v.visit_str("")
    }
    fn deserialize_string<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.leaf(LeafKind::String);
        v.visit_string(String::new())
    }
    fn deserialize_option<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        v.visit_some(self)
    }
    fn deserialize_struct<V: serde::de::Visitor<'de>>(
        self,
        _name: &'static str,
        fields: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, TraceError> {
        if !self.path.is_empty() {
            self.out.tables.insert(self.path.clone());
        }
        v.visit_map(TraceFields {
            path: self.path,
            fields,
            next: 0,
            out: self.out,
        })
    }
    fn deserialize_seq<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        // An array of tables: trace one element at the array's own path.
        self.out.arrays.insert(self.path.clone());
        v.visit_seq(TraceSeq {
            path: self.path,
            done: false,
            out: self.out,
        })
    }
    fn deserialize_enum<V: serde::de::Visitor<'de>>(
        self,
        _name: &'static str,
        variants: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, TraceError> {
        use serde::de::IntoDeserializer;
        self.leaf(LeafKind::OneOf(variants));
        let first: &'static str = variants.first().copied().unwrap_or("");
        v.visit_enum(first.into_deserializer())
    }

    serde::forward_to_deserialize_any! {
        i128 u128 char bytes byte_buf unit unit_struct newtype_struct tuple
        tuple_struct map identifier ignored_any
    }
}

struct TraceSeq<'a> {
    path: String,
    done: bool,
    out: &'a mut Schema,
}

impl<'de> serde::de::SeqAccess<'de> for TraceSeq<'_> {
    type Error = TraceError;

    fn next_element_seed<S: serde::de::DeserializeSeed<'de>>(
        &mut self,
        seed: S,
    ) -> Result<Option<S::Value>, TraceError> {
        if self.done {
            return Ok(None);
        }
        self.done = true;
        seed.deserialize(Tracer {
            path: self.path.clone(),
            out: &mut *self.out,
        })
        .map(Some)
    }
}

struct TraceFields<'a> {
    path: String,
    fields: &'static [&'static str],
    next: usize,
    out: &'a mut Schema,
}

impl<'de> serde::de::MapAccess<'de> for TraceFields<'_> {
    type Error = TraceError;

    fn next_key_seed<K: serde::de::DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, TraceError> {
        use serde::de::IntoDeserializer;
        match self.fields.get(self.next) {
            Some(&field) => seed.deserialize(field.into_deserializer()).map(Some),
            None => Ok(None),
        }
    }

    fn next_value_seed<V: serde::de::DeserializeSeed<'de>>(
        &mut self,
        seed: V,
    ) -> Result<V::Value, TraceError> {
        let field = self.fields.get(self.next).copied().unwrap_or("");
        self.next += 1;
        let path = if self.path.is_empty() {
            field.to_string()
        } else {
            format!("{}.{field}", self.path)
        };
        seed.deserialize(Tracer {
            path,
            out: &mut *self.out,
        })
    }
}

// ---- checking the file's table and applying overrides ----------------------------------------

fn join_key(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

fn hint_for(schema: &Schema, prefix: &str) -> String {
    if prefix.is_empty() {
        format!("top-level keys: {}", schema.keys_under(""))
    } else if schema.tables.contains(prefix) {
        format!("keys in [{prefix}]: {}", schema.keys_under(prefix))
    } else {
        format!("top-level keys: {}", schema.keys_under(""))
    }
}

/// Checks every key of `table` (at dotted `prefix`) against the schema: unknown keys and values
/// of the wrong type are errors.
fn check_table(
    table: &toml::Table,
    prefix: &str,
    schema: &Schema,
    file: &str,
    origin: &str,
) -> Result<(), ScenarioError> {
    for (key, value) in table {
        let full = join_key(prefix, key);
        if schema.arrays.contains(&full) {
            check_array(value, &full, schema, file, origin)?;
        } else if let Some(kind) = schema.leaves.get(&full) {
            if !kind.accepts(value) {
                return Err(ScenarioError::WrongType {
                    file: file.to_string(),
                    origin: origin.to_string(),
                    key: full,
                    value: value.to_string(),
                    message: kind.describe(),
                });
            }
        } else if schema.tables.contains(&full) {
            match value {
                toml::Value::Table(sub) => check_table(sub, &full, schema, file, origin)?,
                other => {
                    return Err(ScenarioError::WrongType {
                        file: file.to_string(),
                        origin: origin.to_string(),
                        key: full.clone(),
                        value: other.to_string(),
                        message: format!("must be a table ([{full}])"),
                    })
                }
            }
        } else {
            return Err(ScenarioError::UnknownKey {
                file: file.to_string(),
                origin: origin.to_string(),
                key: full,
                hint: hint_for(schema, prefix),
            });
        }
    }
    Ok(())
}

/// Checks an array of tables (`[[key]]`): every element is a table of the element's keys.
fn check_array(
    value: &toml::Value,
    key: &str,
    schema: &Schema,
    file: &str,
    origin: &str,
) -> Result<(), ScenarioError> {
    let wrong = || ScenarioError::WrongType {
        file: file.to_string(),
        origin: origin.to_string(),
        key: key.to_string(),
        value: value.to_string(),
        message: format!(
            "must be an array of tables ([[{key}]], or inline [{{ {} }}, ...])",
            schema.keys_under(key)
        ),
    };
    let toml::Value::Array(items) = value else {
        return Err(wrong());
    };
    for item in items {
        match item {
            toml::Value::Table(t) => check_table(t, key, schema, file, origin)?,
            _ => return Err(wrong()),
        }
    }
    Ok(())
}

/// Parses the value of a `--set`: a TOML scalar (integer, float, bool, quoted string), or else the
/// raw text as a string.
fn parse_override_value(raw: &str) -> toml::Value {
    let raw = raw.trim();
    if let Ok(mut t) = toml::from_str::<toml::Table>(&format!("v = {raw}")) {
        if t.len() == 1 {
            if let Some(v) = t.remove("v") {
                return v;
            }
        }
    }
    toml::Value::String(raw.to_string())
}

/// Applies one `key=value` override to `table`; returns the dotted key.
fn apply_override(
    table: &mut toml::Table,
    arg: &str,
    schema: &Schema,
    file: &str,
) -> Result<String, ScenarioError> {
    let bad = |message: &str| ScenarioError::BadOverride {
        file: file.to_string(),
        arg: arg.to_string(),
        message: message.to_string(),
    };
    let (key, raw) = arg
        .split_once('=')
        .ok_or_else(|| bad("expected key=value, e.g. tether.density_kg_per_m=1e-3"))?;
    let key = key.trim();
    if key.is_empty() || key.split('.').any(|part| part.trim().is_empty()) {
        return Err(bad(
            "the key must be a dotted path such as stage2.start_time_s",
        ));
    }
    let origin = format!("--set {arg}: ");
    if let Some(array) = schema.array_of(key) {
        return Err(bad(&format!(
            "`{array}` is an array of tables; set it whole, e.g. \
             {array}=[{{ {} }}]",
            schema.keys_under(array)
        )));
    }
    if schema.arrays.contains(key) {
        let value = parse_override_value(raw);
        check_array(&value, key, schema, file, &origin)?;
        insert_dotted(table, key, value).map_err(|m| bad(&m))?;
        return Ok(key.to_string());
    }
    let Some(&kind) = schema.leaves.get(key) else {
        let prefix = key.rsplit_once('.').map_or("", |(p, _)| p);
        let hint = if schema.tables.contains(key) {
            format!(
                "`{key}` is a section; set one of its keys: {}",
                schema.keys_under(key)
            )
        } else {
            hint_for(schema, prefix)
        };
        return Err(ScenarioError::UnknownKey {
            file: file.to_string(),
            origin,
            key: key.to_string(),
            hint,
        });
    };
    let mut value = parse_override_value(raw);
    value = match (kind, value) {
        // A string field takes the text as written, whatever it looks like.
        (LeafKind::String, toml::Value::String(s)) => toml::Value::String(s),
        (LeafKind::String, _) => toml::Value::String(raw.trim().to_string()),
        // An integer given for a float field is that float.
        (LeafKind::Float, toml::Value::Integer(i)) => toml::Value::Float(i as f64),
        (_, v) => v,
    };
    if !kind.accepts(&value) {
        return Err(ScenarioError::WrongType {
            file: file.to_string(),
            origin,
            key: key.to_string(),
            value: value.to_string(),
            message: kind.describe(),
        });
    }
    insert_dotted(table, key, value).map_err(|m| bad(&m))?;
    Ok(key.to_string())
}

/// Sets dotted `key` of `table` to `value`, creating sections as needed.
fn insert_dotted(table: &mut toml::Table, key: &str, value: toml::Value) -> Result<(), String> {
    let parts: Vec<&str> = key.split('.').collect();
    let (last, sections) = parts.split_last().ok_or("empty key")?;
    let mut cursor = table;
    let mut walked = String::new();
    for part in sections {
        walked = join_key(&walked, part);
        let entry = cursor
            .entry(part.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        cursor = match entry {
            toml::Value::Table(t) => t,
            _ => return Err(format!("`{walked}` in the file is not a table")),
        };
    }
    cursor.insert(last.to_string(), value);
    Ok(())
}

/// Turns a deserialization error of the (already schema-checked) table into a clear message;
/// in practice a missing required key.
fn deserialize_error(
    e: &toml::de::Error,
    table: &toml::Table,
    schema: &Schema,
    file: &str,
) -> ScenarioError {
    let message = e.message();
    if let Some(field) = message
        .strip_prefix("missing field `")
        .and_then(|rest| rest.split('`').next())
    {
        let absent = |k: &String| {
            k.rsplit('.').next() == Some(field) && lookup(table, k).is_none() && {
                // The enclosing section is present (or is the top level); otherwise the section
                // itself is what is missing.
                k.rsplit_once('.')
                    .is_none_or(|(parent, _)| lookup(table, parent).is_some())
            }
        };
        let candidate = schema
            .leaves
            .keys()
            .chain(schema.tables.iter())
            .find(|k| absent(k));
        if let Some(key) = candidate {
            return ScenarioError::MissingKey {
                file: file.to_string(),
                key: key.clone(),
            };
        }
    }
    ScenarioError::Deserialize {
        file: file.to_string(),
        message: e.to_string().trim_end().replace('\n', " "),
    }
}

fn lookup<'t>(table: &'t toml::Table, dotted: &str) -> Option<&'t toml::Value> {
    let mut parts = dotted.split('.');
    let mut value = table.get(parts.next()?)?;
    for part in parts {
        value = value.as_table()?.get(part)?;
    }
    Some(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A complete scenario (the paper's, with every section written out) for the rule tests.
    const BASE: &str = r#"
name = "base"
description = "test scenario"
[orbit]
semi_major_axis_m = 7_078_000.0
eccentricity = 0.0
initial_true_anomaly_rad = 0.0
[masses]
main_initial_kg = 10_000.0
sub_kg = 100.0
[tether]
density_kg_per_m = 0.0
[initial]
length_m = 1.0
length_rate_mps = 0.1
delta_rad = 0.17453292519943295
delta_rate_radps = 0.0
beta_rad = 0.0
beta_rate_radps = 0.0
[controller]
period_s = 1.0
k1_per_s = 0.0057
k2_per_s2 = 9.8696e-6
keep_capture_m = 1.0
[stage1]
decay_rate_per_s = 1.0e-3
deploy_angle_rad = -0.7853981633974483
band_start_m = 10_000.0
keep_length_m = 30_000.0
keep_slope_rad_per_m = 3.141592653589793e-5
[stage2]
start_time_s = 28_800.0
decay_rate_per_s = 5.0e-4
retrieve_angle_rad = 0.3141592653589793
slew_rate_radps = 6.2932e-4
band_start_m = 5_000.0
keep_length_m = 2_000.0
keep_slope_rad_per_m = 1.5707963267948966e-4
[simulation]
duration_s = 72_000.0
substeps = 1
output_interval_s = 10.0
[envelope]
max_rate_mps = 10.0
max_accel_mps2 = 0.05
min_length_m = 0.5
max_length_m = 40_000.0
"#;
    const FILE: &str = "scenarios/x.toml";

    fn load(sets: &[&str]) -> Result<Scenario, ScenarioError> {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        Scenario::from_toml_str(BASE, FILE, &sets)
    }

    fn err(sets: &[&str]) -> String {
        match load(sets) {
            Ok(_) => panic!("{sets:?} was accepted"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn the_base_and_every_shipped_scenario_load() {
        let s = load(&[]).unwrap();
        assert_eq!(s.name, "base");
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios");
        let mut n = 0;
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                Scenario::load(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
                n += 1;
            }
        }
        assert!(n >= 1);
    }

    #[test]
    fn schema_lists_every_key() {
        let s = schema();
        for key in [
            "name",
            "description",
            "orbit.semi_major_axis_m",
            "tether.density_kg_per_m",
            "stage2.start_time_s",
            "simulation.output_interval_s",
            "envelope.max_length_m",
        ] {
            assert!(s.leaves.contains_key(key), "{key}");
        }
        assert_eq!(
            s.leaves.get("simulation.substeps"),
            Some(&LeafKind::Integer {
                min: 0,
                max: u32::MAX.into()
            })
        );
        assert!(s.tables.contains("stage1"));
        // Every leaf of a serialized scenario is in the schema and vice versa.
        let value = toml::Value::try_from(load(&[]).unwrap()).unwrap();
        let mut found = BTreeSet::new();
        fn walk(v: &toml::Value, prefix: &str, out: &mut BTreeSet<String>) {
            if let toml::Value::Table(t) = v {
                for (k, v) in t {
                    let full = join_key(prefix, k);
                    if v.is_table() {
                        walk(v, &full, out);
                    } else {
                        out.insert(full);
                    }
                }
            }
        }
        walk(&value, "", &mut found);
        // The base has no faults, so no element of an array of tables is serialized.
        let expected: BTreeSet<String> = s
            .leaves
            .keys()
            .filter(|k| s.array_of(k).is_none())
            .cloned()
            .collect();
        assert_eq!(found, expected);
        for array in ["faults.dropout", "faults.corrupt", "faults.length_glitch"] {
            assert!(s.arrays.contains(array), "{array}");
        }
        assert_eq!(
            s.leaves.get("faults.dropout.until_s"),
            Some(&LeafKind::Float)
        );
        assert_eq!(
            s.leaves.get("faults.corrupt.sensor"),
            Some(&LeafKind::OneOf(&[
                "length",
                "alpha",
                "alpha_rate",
                "orbit_rate"
            ]))
        );
    }

    #[test]
    fn fault_sections_default_to_a_perfect_system() {
        let s = load(&[]).unwrap();
        assert_eq!(s.sensors, SensorsSection::default());
        assert!(s.faults.dropout.is_empty() && s.faults.corrupt.is_empty());
        assert_eq!(s.reel.lag_s, 0.0);
        assert_eq!(s.reel.max_rate_mps, f64::INFINITY);
        assert_eq!(s.monitor, MonitorSection::default());
        assert_eq!(s.monitor.coast_ticks, 30);
        assert_eq!(s.monitor.length_jump_m, 20.0);
    }

    #[test]
    fn fault_injection_from_the_file_and_from_overrides() {
        let text = format!(
            "{BASE}\n[sensors]\nseed = 7\n[sensors.alpha]\nnoise_std = 1e-4\n\
             [[faults.dropout]]\nfrom_s = 600\nuntil_s = 660.0\n\
             [[faults.corrupt]]\nsensor = \"alpha_rate\"\nfrom_s = 10.0\nuntil_s = 11.0\nvalue = nan\n"
        );
        let sets = [
            "faults.length_glitch=[{ at_s = 100, size_m = 100.0 }]".to_string(),
            "reel.lag_s=2".to_string(),
            "sensors.length.stuck_from_s=50".to_string(),
        ];
        let s = Scenario::from_toml_str(&text, FILE, &sets).unwrap();
        assert_eq!(s.sensors.seed, 7);
        assert_eq!(s.sensors.alpha.noise_std, 1e-4);
        assert_eq!(
            s.faults.dropout,
            [WindowSection {
                from_s: 600.0,
                until_s: 660.0
            }]
        );
        assert_eq!(s.faults.corrupt[0].sensor, SensorName::AlphaRate);
        assert!(s.faults.corrupt[0].value.is_nan());
        assert_eq!(
            s.faults.length_glitch,
            [GlitchSection {
                at_s: 100.0,
                size_m: 100.0
            }]
        );
        assert_eq!(s.reel.lag_s, 2.0);
        assert_eq!(s.sensors.length.stuck_from_s, 50.0);
        assert_eq!(s.sensors.length.stuck_until_s, f64::INFINITY);
        // The resolved scenario (as `run` writes it) reads back the same.
        let again = toml::to_string_pretty(&s).unwrap();
        let back = Scenario::from_toml_str(&again, FILE, &[]).unwrap();
        assert_eq!(back.faults.dropout, s.faults.dropout);
        assert_eq!(back.reel, s.reel);
    }

    #[test]
    fn fault_keys_are_checked_like_every_other_key() {
        let e = err(&["faults.dropout.from_s=3"]);
        assert!(
            e.contains("array of tables") && e.contains("from_s, until_s"),
            "{e}"
        );
        let e = err(&["faults.dropout=3"]);
        assert!(
            e.contains("faults.dropout = 3 must be an array of tables"),
            "{e}"
        );
        let e = err(&["faults.dropout=[{ from_s = 1, until = 2 }]"]);
        assert!(e.contains("unknown key `faults.dropout.until`"), "{e}");
        let e =
            err(&["faults.corrupt=[{ sensor = \"beta\", from_s = 1, until_s = 2, value = 0 }]"]);
        assert!(
            e.contains("must be one of length, alpha, alpha_rate, orbit_rate"),
            "{e}"
        );
        let e = err(&["sensors.alpha.noise=1"]);
        assert!(
            e.contains("unknown key `sensors.alpha.noise`") && e.contains("noise_std"),
            "{e}"
        );
        let text = format!("{BASE}\n[faults.dropout]\nfrom_s = 1\nuntil_s = 2\n");
        let e = Scenario::from_toml_str(&text, FILE, &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("faults.dropout = ") && e.contains("array of tables"),
            "{e}"
        );
    }

    #[test]
    fn overrides_take_floats_integers_strings_and_apply_in_order() {
        let s = load(&[
            "tether.density_kg_per_m=1e-3",
            "stage2.start_time_s=30000",
            "simulation.duration_s=3600",
            "name=foo",
            "description=\"quoted text\"",
            "simulation.substeps=4",
            "controller.k1_per_s = 0.006",
            "controller.k1_per_s=0.007",
        ])
        .unwrap();
        assert_eq!(s.tether.density_kg_per_m, 1e-3);
        assert_eq!(s.stage2.start_time_s, 30_000.0);
        assert_eq!(s.simulation.duration_s, 3600.0);
        assert_eq!(s.name, "foo");
        assert_eq!(s.description, "quoted text");
        assert_eq!(s.simulation.substeps, 4);
        assert_eq!(s.controller.k1_per_s, 0.007);
        // A string field takes any text, even one that looks like a number.
        assert_eq!(load(&["name=42"]).unwrap().name, "42");
    }

    #[test]
    fn an_integer_in_the_file_is_accepted_for_a_float_field() {
        let text = BASE.replace("duration_s = 72_000.0", "duration_s = 7200");
        let s = Scenario::from_toml_str(&text, FILE, &[]).unwrap();
        assert_eq!(s.simulation.duration_s, 7200.0);
    }

    #[test]
    fn an_override_can_set_a_key_the_file_leaves_to_its_default() {
        let text = BASE.replace("eccentricity = 0.0\n", "");
        let sets = ["orbit.eccentricity=0.01".to_string()];
        let s = Scenario::from_toml_str(&text, FILE, &sets).unwrap();
        assert_eq!(s.orbit.eccentricity, 0.01);
    }

    #[test]
    fn an_override_into_a_defaulted_section_keeps_its_other_defaults() {
        let start = BASE.find("[envelope]").unwrap();
        let text = &BASE[..start];
        let sets = ["envelope.max_rate_mps=100".to_string()];
        let s = Scenario::from_toml_str(text, FILE, &sets).unwrap();
        assert_eq!(s.envelope.max_rate_mps, 100.0);
        assert_eq!(
            s.envelope.max_accel_mps2,
            EnvelopeSection::default().max_accel_mps2
        );
    }

    #[test]
    fn malformed_overrides_are_errors_naming_the_argument() {
        let e = err(&["stage1.band_start_m"]);
        assert!(
            e.starts_with(FILE) && e.contains("stage1.band_start_m") && e.contains("key=value"),
            "{e}"
        );
        let e = err(&["=3"]);
        assert!(e.contains("dotted path"), "{e}");
        let e = err(&["stage1..band_start_m=3"]);
        assert!(e.contains("dotted path"), "{e}");
    }

    #[test]
    fn unknown_override_keys_are_errors_naming_the_key() {
        let e = err(&["stage1.band_start=3"]);
        assert!(
            e.starts_with(&format!(
                "{FILE}: --set stage1.band_start=3: unknown key `stage1.band_start`"
            )),
            "{e}"
        );
        assert!(
            e.contains("band_start_m"),
            "the hint lists the valid keys: {e}"
        );
        let e = err(&["nosuch.key=1"]);
        assert!(
            e.contains("unknown key `nosuch.key`") && e.contains("top-level keys"),
            "{e}"
        );
        let e = err(&["stage1=1"]);
        assert!(
            e.contains("unknown key `stage1`") && e.contains("is a section"),
            "{e}"
        );
    }

    #[test]
    fn override_values_of_the_wrong_type_are_errors_naming_key_and_value() {
        let e = err(&["simulation.substeps=1.5"]);
        assert!(e.contains(&format!("{FILE}: --set simulation.substeps=1.5: simulation.substeps = 1.5 must be an integer")), "{e}");
        let e = err(&["simulation.substeps=-1"]);
        assert!(
            e.contains("simulation.substeps = -1 must be an integer in [0, 4294967295]"),
            "{e}"
        );
        let e = err(&["simulation.duration_s=abc"]);
        assert!(
            e.contains("simulation.duration_s = \"abc\" must be a number"),
            "{e}"
        );
        let e = err(&["simulation.duration_s=true"]);
        assert!(
            e.contains("simulation.duration_s = true must be a number"),
            "{e}"
        );
    }

    #[test]
    fn file_errors_name_the_file_and_key() {
        let unknown = BASE.replace("[stage1]\n", "[stage1]\nbnad_start_m = 1.0\n");
        let e = Scenario::from_toml_str(&unknown, FILE, &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(&format!("{FILE}: unknown key `stage1.bnad_start_m`")),
            "{e}"
        );
        let wrong = BASE.replace("substeps = 1", "substeps = \"one\"");
        let e = Scenario::from_toml_str(&wrong, FILE, &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!(
                "{FILE}: simulation.substeps = \"one\" must be an integer"
            )),
            "{e}"
        );
        let missing = BASE.replace("k1_per_s = 0.0057\n", "");
        let e = Scenario::from_toml_str(&missing, FILE, &[])
            .unwrap_err()
            .to_string();
        assert_eq!(e, format!("{FILE}: missing key `controller.k1_per_s`"));
        let no_section = BASE.replace("[masses]\nmain_initial_kg = 10_000.0\nsub_kg = 100.0\n", "");
        let e = Scenario::from_toml_str(&no_section, FILE, &[])
            .unwrap_err()
            .to_string();
        assert_eq!(e, format!("{FILE}: missing key `masses`"));
        let e = Scenario::from_toml_str("name = ", FILE, &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(&format!("{FILE}: not valid TOML")) && e.contains("line 1"),
            "{e}"
        );
        let e = Scenario::load("/nonexistent/dir/x.toml", &[]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "/nonexistent/dir/x.toml: cannot read the scenario file"
        );
    }

    /// Every validation rule: the override that breaks it, the field and value named, and a
    /// piece of the message.
    #[test]
    fn every_rule_names_file_field_and_value() {
        let cases: &[(&[&str], &str, &str, &str)] = &[
            (&["name=a/b"], "name", "\"a/b\"", "file name"),
            (&["name=.."], "name", "\"..\"", "file name"),
            (&["orbit.semi_major_axis_m=-1"], "orbit.semi_major_axis_m", "-1", "must be above 0"),
            (&["orbit.semi_major_axis_m=6000000"], "orbit.semi_major_axis_m", "6000000", "inside the Earth"),
            (&["orbit.eccentricity=0.2"], "orbit.semi_major_axis_m", "7078000", "inside the Earth"),
            (&["orbit.eccentricity=1"], "orbit.eccentricity", "1", "must be in [0, 1)"),
            (&["orbit.eccentricity=-0.1"], "orbit.eccentricity", "-0.1", "must be in [0, 1)"),
            (&["orbit.initial_true_anomaly_rad=nan"], "orbit.initial_true_anomaly_rad", "NaN", "finite"),
            (&["masses.main_initial_kg=0"], "masses.main_initial_kg", "0", "must be above 0"),
            (&["masses.sub_kg=-5"], "masses.sub_kg", "-5", "must be above 0"),
            (&["masses.sub_kg=inf"], "masses.sub_kg", "inf", "finite"),
            (&["initial.length_m=0"], "initial.length_m", "0", "must be above 0"),
            (&["initial.length_m=0.25"], "initial.length_m", "0.25", "within [envelope.min_length_m, envelope.max_length_m] = [0.5, 40000]"),
            (&["initial.length_rate_mps=inf"], "initial.length_rate_mps", "inf", "finite"),
            (&["initial.length_rate_mps=-11"], "initial.length_rate_mps", "-11", "±envelope.max_rate_mps = 10"),
            (&["initial.delta_rad=nan"], "initial.delta_rad", "NaN", "finite"),
            (&["initial.delta_rate_radps=-inf"], "initial.delta_rate_radps", "-inf", "finite"),
            (&["initial.beta_rad=2"], "initial.beta_rad", "2", "(−π/2, π/2)"),
            (&["initial.beta_rate_radps=nan"], "initial.beta_rate_radps", "NaN", "finite"),
            (&["controller.period_s=0"], "controller.period_s", "0", "must be above 0"),
            (&["controller.k1_per_s=0"], "controller.k1_per_s", "0", "must be above 0"),
            (&["controller.k2_per_s2=-1e-6"], "controller.k2_per_s2", "-0.000001", "must be above 0"),
            (&["controller.keep_capture_m=0"], "controller.keep_capture_m", "0", "must be above 0"),
            (&["envelope.max_rate_mps=0"], "envelope.max_rate_mps", "0", "must be above 0"),
            (&["envelope.max_accel_mps2=-1"], "envelope.max_accel_mps2", "-1", "must be above 0"),
            (&["envelope.min_length_m=0"], "envelope.min_length_m", "0", "must be above 0"),
            (&["envelope.max_length_m=0.4"], "envelope.max_length_m", "0.4", "must be above envelope.min_length_m = 0.5"),
            (&["stage1.decay_rate_per_s=-1e-3"], "stage1.decay_rate_per_s", "-0.001", "must not be negative"),
            (&["stage1.deploy_angle_rad=0.1"], "stage1.deploy_angle_rad", "0.1", "(−π/2, 0)"),
            (&["stage1.deploy_angle_rad=-1.6"], "stage1.deploy_angle_rad", "-1.6", "(−π/2, 0)"),
            (&["stage1.band_start_m=40000"], "stage1.band_start_m", "40000", "must be below stage1.keep_length_m = 30000"),
            (&["stage1.band_start_m=0"], "stage1.band_start_m", "0", "must be above 0"),
            (&["stage1.keep_length_m=45000"], "stage1.keep_length_m", "45000", "inside the envelope"),
            (&["stage1.keep_slope_rad_per_m=-1e-5"], "stage1.keep_slope_rad_per_m", "-0.00001", "must not be negative"),
            (&["stage2.start_time_s=-1"], "stage2.start_time_s", "-1", "must not be negative"),
            (&["stage2.start_time_s=0.5"], "stage2.start_time_s", "0.5", "whole multiple of controller.period_s = 1"),
            (&["stage2.decay_rate_per_s=-1"], "stage2.decay_rate_per_s", "-1", "must not be negative"),
            (&["stage2.retrieve_angle_rad=-0.3"], "stage2.retrieve_angle_rad", "-0.3", "(0, π/2)"),
            (&["stage2.slew_rate_radps=0"], "stage2.slew_rate_radps", "0", "must be above 0"),
            (&["stage2.band_start_m=1000"], "stage2.band_start_m", "1000", "must be above stage2.keep_length_m = 2000"),
            (&["stage2.keep_length_m=31000", "stage2.band_start_m=32000"], "stage2.keep_length_m", "31000", "must be below stage1.keep_length_m = 30000"),
            (&["stage2.keep_length_m=0.5"], "stage2.keep_length_m", "0.5", "inside the envelope"),
            (&["stage2.keep_slope_rad_per_m=-1"], "stage2.keep_slope_rad_per_m", "-1", "must not be negative"),
            (&["tether.density_kg_per_m=-1e-3"], "tether.density_kg_per_m", "-0.001", "must not be negative"),
            (&["tether.density_kg_per_m=0.25"], "tether.density_kg_per_m", "0.25", "envelope.max_length_m = 40000 m weigh 10000 kg, not below masses.main_initial_kg = 10000"),
            (&["simulation.duration_s=0"], "simulation.duration_s", "0", "must be above 0"),
            (&["simulation.duration_s=600.5"], "simulation.duration_s", "600.5", "whole multiple of controller.period_s"),
            (&["simulation.duration_s=1e10"], "simulation.duration_s", "10000000000", "more than the simulator's"),
            (&["simulation.substeps=0"], "simulation.substeps", "0", "must be at least 1"),
            (&["simulation.output_interval_s=0"], "simulation.output_interval_s", "0", "must be above 0"),
            (&["simulation.output_interval_s=2.5"], "simulation.output_interval_s", "2.5", "positive whole multiple of controller.period_s = 1"),
            (&["sensors.length.noise_std=-1"], "sensors.length.noise_std", "-1", "must not be negative"),
            (&["sensors.alpha.bias=nan"], "sensors.alpha.bias", "NaN", "finite"),
            (&["sensors.alpha_rate.quantum=-1e-6"], "sensors.alpha_rate.quantum", "-0.000001", "must not be negative"),
            (&["sensors.alpha.stuck_from_s=-5"], "sensors.alpha.stuck_from_s", "-5", "must not be negative"),
            (&["sensors.alpha.stuck_from_s=50", "sensors.alpha.stuck_until_s=40"], "sensors.alpha.stuck_until_s", "40", "must be after sensors.alpha.stuck_from_s = 50"),
            (&["faults.dropout=[{ from_s = 100, until_s = 100 }]"], "faults.dropout[0].until_s", "100", "must be after faults.dropout[0].from_s = 100"),
            (&["faults.dropout=[{ from_s = inf, until_s = inf }]"], "faults.dropout[0].from_s", "inf", "finite"),
            (&["faults.corrupt=[{ sensor = \"alpha\", from_s = 5, until_s = nan, value = 0 }]"], "faults.corrupt[0].until_s", "NaN", "must be a number"),
            (&["faults.length_glitch=[{ at_s = -1, size_m = 100 }]"], "faults.length_glitch[0].at_s", "-1", "must not be negative"),
            (&["faults.length_glitch=[{ at_s = 1, size_m = inf }]"], "faults.length_glitch[0].size_m", "inf", "finite"),
            (&["reel.lag_s=-1"], "reel.lag_s", "-1", "must not be negative"),
            (&["reel.max_rate_mps=0"], "reel.max_rate_mps", "0", "must be above 0 (inf = no limit)"),
            (&["reel.max_accel_mps2=nan"], "reel.max_accel_mps2", "NaN", "must be above 0"),
            (&["monitor.coast_ticks=0"], "monitor.coast_ticks", "0", "must be at least 1"),
            (&["monitor.length_jump_m=0"], "monitor.length_jump_m", "0", "must be above 0"),
            (&["monitor.max_orbit_rate_radps=-1"], "monitor.max_orbit_rate_radps", "-1", "must be above 0"),
            (&["monitor.max_orbit_rate_radps=1e-6"], "monitor.max_orbit_rate_radps", "0.000001", "must be above monitor.min_orbit_rate_radps = 0.00001"),
        ];
        for (sets, field, value, message) in cases {
            let e = err(sets);
            let head = format!("{FILE}: {field} = {value} ");
            let line = e
                .lines()
                .find(|l| l.starts_with(&head))
                .unwrap_or_else(|| panic!("{sets:?}: no line starting {head:?} in:\n{e}"));
            assert!(
                line.contains(message),
                "{sets:?}: {line:?} lacks {message:?}"
            );
            let base = field.split('[').next().unwrap_or(field);
            if sets.iter().any(|s| s.starts_with(&format!("{base}="))) {
                assert!(line.ends_with("(set by --set)"), "{line}");
            }
        }
    }

    #[test]
    fn all_problems_are_reported_at_once() {
        let e = load(&["masses.sub_kg=0", "controller.k1_per_s=0"]).unwrap_err();
        match e {
            ScenarioError::Invalid { problems, .. } => {
                let fields: Vec<&str> = problems.iter().map(|p| p.field.as_str()).collect();
                assert_eq!(fields, ["masses.sub_kg", "controller.k1_per_s"]);
            }
            other => panic!("{other}"),
        }
    }

    #[test]
    fn the_paper_scenario_is_valid_and_its_rules_hold_in_the_example_from_the_brief() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/paper.toml");
        let e = Scenario::load(path, &["stage1.band_start_m=40000".to_string()])
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            format!(
                "{path}: stage1.band_start_m = 40000 must be below stage1.keep_length_m = 30000 \
                 (set by --set)"
            )
        );
    }
}
