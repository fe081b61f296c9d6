//! The whole scenario: one mission, section by section (each section's schema and rules in its
//! own file; `validate.rs` checks them together).

use serde::{Deserialize, Serialize};

use super::control::{ControllerSection, Stage1Section, Stage2Section};
use super::envelope::EnvelopeSection;
use super::environment::EnvironmentSection;
use super::initial::InitialSection;
use super::link::LinkSection;
use super::monitor::MonitorSection;
use super::montecarlo::MonteCarloSection;
use super::plant::PlantSection;
use super::protection::ProtectionSection;
use super::reel::ReelSection;
use super::sensors::{FaultsSection, SensorsSection};
use super::simulation::SimulationSection;
use super::system::{MassesSection, OrbitSection, TetherSection};
use super::telecommand::TelecommandSection;
use super::tension_loop::TensionLoopSection;

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
    /// `[[telecommand]]`: the on-board computer's timed mission-mode commands, sent through
    /// the unit's PUS services (default: none; only the paper's law takes them).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub telecommand: Vec<TelecommandSection>,
}
