//! Scenario files: the TOML description of one simulated mission.
//!
//! `scenarios/paper.toml` is the paper's Section 6 as fixed in docs/equations.md §7. Every field has a unit
//! in its name. The module is split by concern:
//!
//! - `mission.rs`: the whole scenario ([`Scenario`]), one field per section;
//! - one file per group of sections, each holding the section's schema (a serde struct, its
//!   defaults) and its validation rules next to it: `system.rs` (`[orbit]`, `[masses]`,
//!   `[tether]`), `initial.rs`, `control.rs` (`[controller]`, `[stage1]`, `[stage2]`),
//!   `envelope.rs`, `monitor.rs`, `protection.rs`, `tension_loop.rs`, `simulation.rs`, `sensors.rs` (`[sensors]`, `[faults]`),
//!   `reel.rs`, `link.rs`, `montecarlo.rs`, `plant.rs` (`[plant]`), `environment.rs`;
//! - `validate.rs`: the sections' rules called together, and the rules between sections
//!   ([`Scenario::problems`]);
//! - `dispersible.rs`: the number fields a Monte Carlo campaign may disperse, their nominal
//!   values, and `[montecarlo]` checked against them;
//! - `cost.rs`: what an elastic run will cost, refused beyond a stated bound;
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
//! 2. Here: `mod thermal;` and `pub use thermal::ThermalSection;`; a field
//!    `pub thermal: ThermalSection` in [`Scenario`] (`mission.rs`), and a line in
//!    [`Scenario::problems`] (`validate.rs`) calling its `check`.
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
mod dispersible;
mod envelope;
mod environment;
mod error;
mod initial;
pub mod keys;
mod link;
mod load;
mod mission;
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
mod telecommand;
mod tension_loop;
mod validate;

#[cfg(test)]
mod tests;

pub use control::{
    ControllerSection, LawName, RuppSection, Stage1Section, Stage2Section, TrackingSection,
};
pub use cost::{
    elastic_cost, ElasticCost, BYTES_PER_NODE, MAX_ELASTIC_NODES, MAX_ELASTIC_NODE_STEPS,
    MAX_SHAPE_POINTS,
};
pub(crate) use dispersible::nominal_in;
pub use dispersible::{dispersible_fields, ignored_by_models, nominal_value};
pub use envelope::EnvelopeSection;
pub use environment::EnvironmentSection;
pub use error::{Problem, ScenarioError};
pub use initial::InitialSection;
pub use link::LinkSection;
pub use load::{read_bounded, MAX_SCENARIO_BYTES};
pub use mission::Scenario;
pub use monitor::MonitorSection;
pub use montecarlo::{CriteriaSection, DispersionSection, Distribution, MonteCarloSection};
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
pub use telecommand::{CommandName, TelecommandSection, MAX_TELECOMMANDS};
pub use tension_loop::TensionLoopSection;
