//! The truth model's parameters (orbit, bodies, tether, reel, environment, sensing, step), its
//! initial conditions and its errors, with their validation.

use super::environment::Environment;
use super::reel_drum::{DrumParams, FlightDrum};
use super::tether::TetherParams;
use crate::reel::Reel;
use tss_reel::orbit::Orbit;

/// The orbit the centre of mass starts on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitParams {
    /// Semi-major axis, eccentricity and μ.
    pub orbit: Orbit<f64>,
    /// True anomaly at t = 0, rad.
    pub initial_true_anomaly_rad: f64,
    /// Inclination of the orbit plane to the equator, rad (the ascending node and perigee on
    /// the inertial x axis).
    pub inclination_rad: f64,
}

/// The end bodies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyParams {
    /// Main satellite's initial mass m01 (with all the tether on the drum), kg.
    pub main_initial_kg: f64,
    /// Sub-satellite's mass m2, kg.
    pub sub_kg: f64,
    /// Main satellite's drag area times drag coefficient C_d·A, m².
    pub main_drag_area_m2: f64,
    /// Sub-satellite's C_d·A, m².
    pub sub_drag_area_m2: f64,
}

/// How the reel's rate follows the controller's command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ReelModel {
    /// l̇ = the command, at once (the paper's assumption).
    Ideal,
    /// The first-order lag with rate and acceleration limits of `crate::reel` (its `rate_mps`
    /// is the drive's rate at t = 0 and is overwritten with the initial rate).
    Lag(Reel),
    /// The drum and motor of [`reel_drum`], through its speed loop.
    Motor(DrumParams),
    /// The drum of [`reel_drum`] driven by the flight speed loop ([`FlightDrum`]) at its inner
    /// rate: the plant substeps at every inner tick, the motor's torque held over it.
    Flight(FlightParams),
}

/// The drum and the flight speed loop that drives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlightParams {
    /// The drum (its `speed_bandwidth_radps` unused: the flight loop's gains fly).
    pub drum: DrumParams,
    /// The speed loop's inner rate, Hz (≥ 100).
    pub inner_rate_hz: u32,
    /// Encoder counts per drum revolution.
    pub counts_per_rev: u32,
    /// The law's period, s (the drive's outer period).
    pub period_s: f64,
}

impl FlightParams {
    /// The drive configuration the flight loop flies ([`FlightDrum::drive_config`], with this
    /// encoder on the drum's shaft).
    pub fn drive_config(&self) -> tss_reel::reel_drive::DriveConfig {
        let mut cfg = FlightDrum::drive_config(&self.drum, self.inner_rate_hz, self.period_s);
        cfg.geometry.counts_per_motor_rev = self.counts_per_rev;
        cfg.geometry.gear_ratio = 1;
        cfg
    }
}

/// The reel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReelParams {
    /// How the reel follows the command.
    pub model: ReelModel,
    /// Hold the drum still: no tether moves at the reel, and the commands are ignored.
    pub locked: bool,
}

/// Which direction the controller's α and β describe.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sensing {
    /// The line from the main satellite to the sub-satellite (as in the rigid plant).
    Line,
    /// The tether's exit direction at the deployer (main satellite → first node).
    Exit,
}

/// Everything the truth model needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElasticParams {
    /// The orbit of the centre of mass at t = 0.
    pub orbit: OrbitParams,
    /// End bodies.
    pub bodies: BodyParams,
    /// Tether material and discretisation.
    pub tether: TetherParams,
    /// Reel mechanism.
    pub reel: ReelParams,
    /// Gravity and atmosphere.
    pub environment: Environment,
    /// What the controller's angles describe.
    pub sensing: Sensing,
    /// Largest (rate × step) of the integration (see the module doc).
    pub courant: f64,
}

/// The initial state, in the rigid plant's terms: straight, at its initial length, each segment
/// stretched to the tension that motion needs (static equilibrium, `initial.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialConditions {
    /// Paid-out length l(0), m.
    pub length_m: f64,
    /// Reel rate l̇(0), m/s (the sub-satellite moves away at this rate).
    pub rate_mps: f64,
    /// α(0), rad.
    pub alpha_rad: f64,
    /// α̇(0), rad/s.
    pub alpha_rate_radps: f64,
    /// β(0), rad.
    pub beta_rad: f64,
    /// β̇(0), rad/s.
    pub beta_rate_radps: f64,
}

/// Why a truth model cannot be built or stepped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ElasticError {
    /// A parameter is out of its range.
    #[error("elastic plant: {field} = {value} is invalid ({rule})")]
    Invalid {
        /// The parameter.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What it must satisfy.
        rule: &'static str,
    },
    /// The state stopped being finite.
    #[error("elastic plant: the state became non-finite at t = {t_s} s")]
    Diverged {
        /// Time, s.
        t_s: f64,
    },
}

pub(super) fn check(
    field: &'static str,
    value: f64,
    ok: bool,
    rule: &'static str,
) -> Result<(), ElasticError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ElasticError::Invalid { field, value, rule })
    }
}

impl ElasticParams {
    /// Checks every parameter (finite, in range).
    pub fn validate(&self) -> Result<(), ElasticError> {
        let o = &self.orbit;
        let a = o.orbit.semi_major_axis_m;
        let e = o.orbit.eccentricity;
        check("orbit.semi_major_axis_m", a, a > 0.0, "> 0")?;
        check(
            "orbit.eccentricity",
            e,
            (0.0..1.0).contains(&e),
            "in [0, 1)",
        )?;
        check(
            "orbit.mu_m3ps2",
            o.orbit.mu_m3ps2,
            o.orbit.mu_m3ps2 > 0.0,
            "> 0",
        )?;
        check(
            "orbit.initial_true_anomaly_rad",
            o.initial_true_anomaly_rad,
            true,
            "finite",
        )?;
        check("orbit.inclination_rad", o.inclination_rad, true, "finite")?;
        let b = &self.bodies;
        check(
            "bodies.main_initial_kg",
            b.main_initial_kg,
            b.main_initial_kg > 0.0,
            "> 0",
        )?;
        check("bodies.sub_kg", b.sub_kg, b.sub_kg > 0.0, "> 0")?;
        check(
            "bodies.main_drag_area_m2",
            b.main_drag_area_m2,
            b.main_drag_area_m2 >= 0.0,
            ">= 0",
        )?;
        check(
            "bodies.sub_drag_area_m2",
            b.sub_drag_area_m2,
            b.sub_drag_area_m2 >= 0.0,
            ">= 0",
        )?;
        let t = &self.tether;
        check(
            "tether.density_kg_per_m",
            t.density_kg_per_m,
            t.density_kg_per_m >= 0.0,
            ">= 0",
        )?;
        check(
            "tether.axial_stiffness_n",
            t.axial_stiffness_n,
            t.axial_stiffness_n > 0.0,
            "> 0",
        )?;
        check(
            "tether.damping_ns",
            t.damping_ns,
            t.damping_ns >= 0.0,
            ">= 0",
        )?;
        check(
            "tether.diameter_m",
            t.diameter_m,
            t.diameter_m >= 0.0,
            ">= 0",
        )?;
        check(
            "tether.drag_coefficient",
            t.drag_coefficient,
            t.drag_coefficient >= 0.0,
            ">= 0",
        )?;
        check(
            "tether.segment_length_m",
            t.segment_length_m,
            t.segment_length_m > 0.0,
            "> 0",
        )?;
        check(
            "tether.min_stiffness_length_m",
            t.min_stiffness_length_m,
            t.min_stiffness_length_m > 0.0 && t.min_stiffness_length_m <= t.segment_length_m,
            "in (0, segment_length_m]",
        )?;
        match &self.reel.model {
            ReelModel::Ideal => {}
            ReelModel::Lag(r) => {
                check("reel.lag_s", r.lag_s, r.lag_s >= 0.0, ">= 0")?;
                let ok = r.max_rate_mps > 0.0 && !r.max_rate_mps.is_nan();
                check(
                    "reel.max_rate_mps",
                    if ok { 1.0 } else { r.max_rate_mps },
                    ok,
                    "> 0",
                )?;
                let ok = r.max_accel_mps2 > 0.0 && !r.max_accel_mps2.is_nan();
                check(
                    "reel.max_accel_mps2",
                    if ok { 1.0 } else { r.max_accel_mps2 },
                    ok,
                    "> 0",
                )?;
            }
            ReelModel::Flight(f) => {
                check_drum(&f.drum)?;
                let hz = f64::from(f.inner_rate_hz);
                check("reel.inner_rate_hz", hz, hz >= 100.0, ">= 100")?;
                let c = f64::from(f.counts_per_rev);
                check("reel.encoder_counts_per_rev", c, c > 0.0, "> 0")?;
                check("period_s", f.period_s, f.period_s > 0.0, "> 0")?;
                if f.drive_config().validate().is_err() {
                    return Err(ElasticError::Invalid {
                        field: "reel (flight drive configuration)",
                        value: hz,
                        rule: "a valid tss_reel::reel_drive::DriveConfig",
                    });
                }
            }
            ReelModel::Motor(d) => check_drum(d)?,
        }
        check(
            "courant",
            self.courant,
            self.courant > 0.0 && self.courant <= 2.0,
            "in (0, 2]",
        )
    }
}

/// The drum's parameters in range.
fn check_drum(d: &DrumParams) -> Result<(), ElasticError> {
    check("reel.drum_radius_m", d.radius_m, d.radius_m > 0.0, "> 0")?;
    check(
        "reel.inertia_kgm2",
        d.inertia_kgm2,
        d.inertia_kgm2 > 0.0,
        "> 0",
    )?;
    check(
        "reel.viscous_nms",
        d.viscous_nms,
        d.viscous_nms >= 0.0,
        ">= 0",
    )?;
    check("reel.coulomb_nm", d.coulomb_nm, d.coulomb_nm >= 0.0, ">= 0")?;
    check(
        "reel.static_nm",
        d.static_nm,
        d.static_nm >= d.coulomb_nm,
        ">= coulomb_nm",
    )?;
    check(
        "reel.max_torque_nm",
        d.max_torque_nm,
        d.max_torque_nm > 0.0,
        "> 0",
    )?;
    check("reel.brake_nm", d.brake_nm, d.brake_nm >= 0.0, ">= 0")?;
    let w = d.speed_bandwidth_radps;
    check("reel.speed_bandwidth_radps", w, w > 0.0, "> 0")?;
    Ok(())
}
