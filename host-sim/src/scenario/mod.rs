//! Scenario files: the TOML description of one simulated mission.
//!
//! `scenarios/paper.toml` is the paper's Section 6 as fixed in docs/equations.md §7. Every field has a unit
//! in its name. The module is split by concern:
//!
//! - one file per group of sections, each holding the section's schema (a serde struct, its
//!   defaults) and its validation rules next to it: `system.rs` (`[orbit]`, `[masses]`,
//!   `[tether]`), `initial.rs`, `control.rs` (`[controller]`, `[stage1]`, `[stage2]`),
//!   `envelope.rs`, `monitor.rs`, `protection.rs`, `tension_loop.rs`, `simulation.rs`, `sensors.rs` (`[sensors]`, `[faults]`),
//!   `reel.rs`, `link.rs`, `montecarlo.rs`, `plant.rs` (`[plant]`), `environment.rs`;
//! - `core_rules.rs`: the flight controller's own rules, not repeated here: the f32 controller
//!   is built from the scenario and the parameter path of what it rejects is named by scenario
//!   key (this also catches values beyond f32's range);
//! - `rules.rs`: the `Validator` the rules are written with (each failed rule a [`Problem`]);
//! - `schema.rs`: every key with its type, traced from the structs (no hand-written list;
//!   [`schema()`]);
//! - `load.rs`: reading the file, checking its keys, `--set` overrides, then validation
//!   ([`Scenario::load`]);
//! - `convert.rs`: the scenario turned into the parameter types of the models it configures
//!   (the physics never reads the schema);
//! - `error.rs`: errors that name the file, the field and the value ([`ScenarioError`]);
//! - [`keys`]: `tss-sim scenario keys`, every key with its unit, default and rules, read from
//!   the schema and from validation itself.
//!
//! # Adding a section, say `[thermal]`
//! 1. A file `thermal.rs` with `pub struct ThermalSection` (`#[derive(Clone, Debug,
//!    PartialEq, Serialize, Deserialize)]`, `#[serde(deny_unknown_fields)]`, units in the field
//!    names, `#[serde(default)]` and a `Default` impl if a file may leave it out) and
//!    `fn check(&self, v: &mut Validator)` with its rules, naming fields by their dotted keys.
//! 2. Here: `mod thermal;`, `pub use thermal::ThermalSection;`, a field
//!    `pub thermal: ThermalSection` in [`Scenario`], and a line in
//!    [`Scenario::problems`] calling its `check`.
//! 3. If a model takes it, a conversion in `convert.rs` into that model's own parameter type.
//!    If it configures the flight controller, its rules are `Config::validate`'s: map the
//!    controller's parameter path to the key in `core_rules.rs` instead of repeating them.
//! 4. A count or size gets a documented bound (a `MAX_…` constant) checked in its `check`.
//!
//! The schema, `--set`, Monte Carlo dispersions, `tss-sim scenario keys` and the resolved
//! `scenario.toml` a run writes follow from the struct by themselves.

mod control;
mod convert;
mod core_rules;
mod cost;
mod envelope;
mod environment;
mod error;
mod initial;
pub mod keys;
mod link;
mod load;
mod monitor;
mod montecarlo;
mod plant;
mod protection;
mod reel;
mod rules;
mod schema;
mod sensors;
mod simulation;
mod system;
mod tension_loop;

#[cfg(test)]
mod tests;

use serde::{Deserialize, Serialize};

pub use control::{
    ControllerSection, LawName, RuppSection, Stage1Section, Stage2Section, TrackingSection,
};
pub use cost::{
    elastic_cost, ElasticCost, BYTES_PER_NODE, MAX_ELASTIC_NODES, MAX_ELASTIC_NODE_STEPS,
    MAX_SHAPE_POINTS,
};
pub use envelope::EnvelopeSection;
pub use environment::EnvironmentSection;
pub use error::{Problem, ScenarioError};
pub use initial::InitialSection;
pub use link::LinkSection;
pub use load::{read_bounded, MAX_SCENARIO_BYTES};
pub use monitor::MonitorSection;
pub(crate) use montecarlo::nominal_in;
pub use montecarlo::{
    dispersible_fields, ignored_by_models, nominal_value, CriteriaSection, DispersionSection,
    Distribution, MonteCarloSection,
};
pub use plant::{PlantModel, PlantSection, SensedDirection};
pub use protection::ProtectionSection;
pub use reel::{ReelModelName, ReelSection};
pub use schema::{schema, LeafKind, Schema};
pub use sensors::{
    CorruptSection, EncoderSection, FaultsSection, GlitchSection, LoadCellSection,
    RateSensorSection, SensorsSection, SwingSensorSection, WindowSection, MAX_FAULT_ENTRIES,
};
pub use simulation::{
    SimulationSection, MAX_HISTORY_ROWS, MAX_PLANT_STEPS, MAX_SUBSTEPS, MAX_TICKS,
};
pub use system::{
    MassesSection, OrbitSection, TetherSection, EARTH_EQUATORIAL_RADIUS_M, EARTH_HILL_RADIUS_M,
    MIN_PERIGEE_ALTITUDE_M,
};
pub use tension_loop::TensionLoopSection;

use rules::Validator;

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
    pub montecarlo: MonteCarloSection,
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
    /// The controller's tension- and drive-aware protection (default: off, the paper's
    /// controller).
    #[serde(default)]
    pub protection: ProtectionSection,
    /// The controller's tension loop (docs/equations.md §17; default: off, the paper's
    /// controller).
    #[serde(default)]
    pub tension_loop: TensionLoopSection,
    /// Faults of the processor-in-the-loop serial link (`tss-sim run --pil`; default: none).
    /// A host-linked run has no link and ignores it.
    #[serde(default)]
    pub link: LinkSection,
    /// The plant flown: the rigid rod of Eq. 5 (default) or the elastic truth model.
    #[serde(default)]
    pub plant: PlantSection,
    /// J2, drag and inclination for the elastic plant (default: none, equatorial).
    #[serde(default)]
    pub environment: EnvironmentSection,
}

impl Scenario {
    /// Checks that the scenario makes physical sense; returns every failed rule (empty =
    /// valid): the scenario's own rules section by section, then the first rule of the flight
    /// controller's configuration (built in f32, as flown) that fails.
    pub fn problems(&self) -> Vec<Problem> {
        let mut v = Validator::default();
        let s = self;
        s.check_name(&mut v);
        s.orbit.check(&mut v);
        s.initial.check(&mut v);
        s.initial.check_within(&s.envelope, &mut v);
        s.controller.check(&mut v);
        s.stage1.check(&mut v);
        s.stage2.check(&s.stage1, s.controller.period_s, &mut v);
        s.simulation.check(s.controller.period_s, &mut v);
        s.montecarlo.check(s, &mut v);
        s.sensors.check(&mut v);
        s.faults.check(&mut v);
        s.reel.check(&mut v);
        s.reel.check_flight_drive(s.controller.period_s, &mut v);
        s.monitor.check(&mut v);
        s.link.check(&mut v);
        s.tether.check(&mut v);
        s.plant.check(s.controller.period_s, &mut v);
        s.environment.check(&mut v);
        s.check_elastic_only(&mut v);
        cost::check(s, &mut v);
        // The flight controller's own rules, last (it reports the first it finds).
        core_rules::check(s, &mut v);
        v.problems
    }

    /// The motor reel, J2 and drag exist only in the elastic plant: asking the rigid one for
    /// them is an error, not a silent no-op. On the elastic plant a tension law needs the motor
    /// reel.
    fn check_elastic_only(&self, v: &mut Validator) {
        if self.plant.model == PlantModel::Elastic {
            // A tension law drives the drum's torque: the elastic plant needs the drum.
            v.check(
                !self.controller.law.commands_tension() || self.reel.model == ReelModelName::Motor,
                "controller.law",
                format!("{:?}", self.controller.law.as_str()),
                "needs reel.model = \"motor\" on the elastic plant (a tension law drives the drum)",
            );
            return;
        }
        let needs = "needs plant.model = \"elastic\" (the rigid plant has no such model)";
        v.check(
            self.reel.model != ReelModelName::Motor,
            "reel.model",
            "\"motor\"".to_string(),
            needs,
        );
        v.check(
            self.reel.model != ReelModelName::FlightDrive,
            "reel.model",
            "\"flight_drive\"".to_string(),
            needs,
        );
        v.check(
            !self.environment.j2,
            "environment.j2",
            "true".to_string(),
            needs,
        );
        v.check(
            !self.environment.drag,
            "environment.drag",
            "true".to_string(),
            needs,
        );
        // The loop's gain is scheduled on the tether's compliance (EA): on a rod infinitely
        // stiffer than it is told it is unstable (docs/equations.md §17.3).
        v.check(
            !self.tension_loop.enabled,
            "tension_loop.enabled",
            "true".to_string(),
            "needs plant.model = \"elastic\" (the loop damps an elastic tether's bounce; on the \
             rigid rod, infinitely stiff, it is unstable: docs/equations.md §17.3)",
        );
    }

    /// `name` names the default output directory: a non-empty file name.
    fn check_name(&self, v: &mut Validator) {
        let name = &self.name;
        let ok = !name.trim().is_empty()
            && name != "."
            && name != ".."
            && !name
                .chars()
                .any(|c| c == '/' || c == '\\' || c.is_control());
        v.check(
            ok,
            "name",
            format!("{name:?}"),
            "must be a non-empty file name (no '/', '\\' or control characters, not '.' or '..')",
        );
    }
}
