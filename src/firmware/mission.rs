//! What the firmware does on each control tick: the mission body.
//!
//! **This is the module to replace** when the real controller lands (replaying a recorded
//! stretch of the mission through `tss_reel`'s step function). The contract with the main loop
//! in `main.rs`, which does not change:
//! - [`CONTROL_PERIOD_MS`]: the control period; one SysTick interrupt per period;
//! - [`MAX_TICKS`]: a hard bound on the run (a mission still running then is a failure);
//! - [`Mission::new`] once, then [`Mission::step`] once per tick with the tick index
//!   `0, 1, 2, …`, returning [`Flow::Continue`], [`Flow::Finished`] or [`Flow::Failed`].
//!
//! What is logged at `info` is checked against `expected/firmware.log` by
//! `scripts/firmware-log`; after an intended change, bless the new log with
//! `scripts/firmware-log --bless` and review its diff.
//!
//! For now (placeholder until the controller lands) the mission exercises what the library has:
//! the orbit rate of the paper's orbit, and the mass coefficients of Eq. 5 along a deployment
//! from 2 km to 30 km, one kilometre per tick.

use tss_reel::mass::MassModel;
use tss_reel::orbit::circular_rate_radps;

/// Control period, ms: 1 s, the period of the paper's scenario (scenarios/paper.toml, SPEC §7).
pub const CONTROL_PERIOD_MS: u32 = 1_000;

// The period must be one SysTick can produce.
const _: () = assert!(super::clock::reload_for(CONTROL_PERIOD_MS).is_some());

/// Hard bound on the number of ticks of one run.
pub const MAX_TICKS: u32 = 1_000;

/// Orbit radius of the paper's Section 6, m (R = 7078 km).
const ORBIT_RADIUS_M: f32 = 7_078_000.0;

/// A thin tether's linear density, kg/m, so that μ1 and μ3 are not trivially zero.
const TETHER_DENSITY_KG_PER_M: f32 = 1e-3;

/// Shortest tether length of the walk, m (the paper's retrieval target, 2 km).
const FIRST_LENGTH_M: u32 = 2_000;

/// Longest tether length of the walk, m (the paper's deployed length, 30 km).
const LAST_LENGTH_M: u32 = 30_000;

/// Length added on each tick, m.
const LENGTH_STEP_M: u32 = 1_000;

/// What the main loop does after a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum Flow {
    /// Wait for the next tick and step again.
    Continue,
    /// The mission is over: exit with success.
    Finished,
    /// Something is wrong (it has been logged): exit with failure.
    Failed,
}

/// The mission's state between ticks.
pub struct Mission {
    /// Orbit rate n of the circular orbit, rad/s.
    orbit_rate_radps: f32,
    /// Masses of the main satellite, sub-satellite and tether.
    masses: MassModel<f32>,
}

impl Mission {
    /// Sets the mission up (called once, before the first tick).
    pub fn new() -> Self {
        Self {
            orbit_rate_radps: circular_rate_radps::<f32>(ORBIT_RADIUS_M),
            masses: MassModel {
                tether_density_kg_per_m: TETHER_DENSITY_KG_PER_M,
                ..MassModel::paper()
            },
        }
    }

    /// One control step at tick `tick` (0 for the first).
    pub fn step(&mut self, tick: u32) -> Flow {
        if tick == 0 {
            defmt::info!(
                "orbit R = {=f32} m: n = {=f32} rad/s",
                ORBIT_RADIUS_M,
                self.orbit_rate_radps
            );
            if !self.orbit_rate_radps.is_finite() {
                defmt::error!("orbit rate is not finite");
                return Flow::Failed;
            }
        }

        let length_m = FIRST_LENGTH_M.saturating_add(tick.saturating_mul(LENGTH_STEP_M));
        // Lengths up to 30 km are exact in f32 (< 2^24).
        let c = self.masses.coefficients(length_m as f32);
        defmt::info!(
            "tick {=u32}: l = {=u32} m: mu1 = {=f32}, mu2 = {=f32}, mu3 = {=f32}, M* = {=f32} kg",
            tick,
            length_m,
            c.mu1,
            c.mu2,
            c.mu3,
            c.reduced_kg
        );
        let all_finite = [c.mu1, c.mu2, c.mu3, c.reduced_kg]
            .iter()
            .all(|x| x.is_finite());
        if !all_finite {
            defmt::error!("mass coefficients are not finite at l = {=u32} m", length_m);
            return Flow::Failed;
        }

        if length_m >= LAST_LENGTH_M {
            Flow::Finished
        } else {
            Flow::Continue
        }
    }
}
