//! The truth model: an elastic, 3-D, lumped-mass tether paid out by a reel mechanism, between
//! two point-mass satellites in Earth orbit (optional J2 and drag), in f64.
//!
//! This is the plant the controller was *not* designed on (the paper's rigid rod of Eq. 5 is
//! `crate::plant`): the tether stretches, bows, carries longitudinal waves and goes slack; the
//! reel has inertia, friction, a torque limit and a brake; the orbit has J2 and drag. The model
//! takes its own parameter structs ([`ElasticParams`]); a scenario converts into them.
//! `docs/truth-model.md` gives the equations, the choices and the verification figures.
//!
//! ## Bodies and frame
//! All nodes (main satellite, beads, sub-satellite; see [`tether`]) are integrated in the
//! Earth-centred inertial frame, as positions and velocities *relative to a reference point*
//! that is itself integrated as a free particle in the same gravity field (point mass + J2, no
//! drag). Each node obeys m_i r̈_i = m_i g(R + ρ_i) + (tether, drag, momentum-flux forces),
//! written as ρ̈_i = g(R + ρ_i) − g(R) + F_i/m_i: exact, and the relative coordinates (km) keep
//! 1e-12 m resolution where absolute ones (7000 km) would keep 1e-9 m.
//!
//! **Which point flies the Keplerian orbit**: at t = 0 the system's centre of mass (bodies and
//! beads) is placed on the scenario's orbit (a, e, θ0, inclination i; perigee on the ascending
//! node) with that orbit's velocity, and so is the reference point. From then on nothing is
//! constrained: the centre of mass moves as the forces make it (with J2 and drag off, and a
//! short tether, it stays on the Keplerian orbit to within the tidal coupling, ~(l/R)²).
//! The controller's orbit frame (e_r, e_θ, e_h) and its θ̇ are the centre of mass's own:
//! e_r = R_c/|R_c|, e_h ∥ R_c × V_c, θ̇ = |R_c × V_c|/|R_c|².
//!
//! ## Integration
//! Classical RK4 with the control period split into equal substeps. The substep count is
//! chosen each period from the highest rate of the current configuration: for every segment
//! √(k(1/m_a + 1/m_b)) and its damping C/L(1/m_a + 1/m_b), the drum's coupling through the reel
//! segment, the speed loop's 2ω_b. The step keeps (rate × h) ≤ `courant` (default 1: RK4 is
//! stable to 2.8 and damps a mode at ωh = 1 by 0.7 % per step; librations and the bounce mode
//! sit at ωh ≪ 0.1). Topology changes (beads entering and leaving, [`tether::feed`]) and the
//! drum's stick/slip switches happen between substeps.

pub mod environment;
mod initial;
pub mod reel_drum;
pub mod tether;

use crate::plant::{Command, ElasticObservation, Observation, Plant, SensorTruth};
use crate::reel::{Reel, ReelSaturation};
use environment::{air_velocity_mps, body_drag_n, cylinder_drag_n, Environment, Vec3};
use reel_drum::{DriveFigures, DrumParams, FlightDrum, Motion};
use tether::{Feed, Layout, TetherParams};
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

fn check(
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

/// The integrated state: the reference particle, the reel, and every node relative to the
/// reference (inertial axes). Also the shape of its time derivative.
#[derive(Clone, Debug, Default, PartialEq)]
struct State {
    /// Reference particle's position R and velocity V (inertial), m, m/s.
    r_ref: Vec3,
    v_ref: Vec3,
    /// Paid-out unstretched length l_u (the encoder's reading), m.
    paid_out_m: f64,
    /// Drum speed ω, rad/s (motor reel only).
    drum_speed_radps: f64,
    /// The speed loop's integral of the speed error, rad (motor reel only).
    drum_integral_rad: f64,
    /// Node positions ρ_i and velocities ρ̇_i relative to the reference, m, m/s.
    pos: Vec<Vec3>,
    vel: Vec<Vec3>,
}

impl State {
    /// `self = y + c·k` (same node count).
    fn set_stage(&mut self, y: &State, c: f64, k: &State) {
        self.r_ref = y.r_ref + k.r_ref * c;
        self.v_ref = y.v_ref + k.v_ref * c;
        self.paid_out_m = y.paid_out_m + k.paid_out_m * c;
        self.drum_speed_radps = y.drum_speed_radps + k.drum_speed_radps * c;
        self.drum_integral_rad = y.drum_integral_rad + k.drum_integral_rad * c;
        let n = y.pos.len();
        self.pos.resize(n, Vec3::zeros());
        self.vel.resize(n, Vec3::zeros());
        for i in 0..n {
            self.pos[i] = y.pos[i] + k.pos[i] * c;
            self.vel[i] = y.vel[i] + k.vel[i] * c;
        }
    }

    fn is_finite(&self) -> bool {
        let v = |x: &Vec3| x.iter().all(|c| c.is_finite());
        v(&self.r_ref)
            && v(&self.v_ref)
            && self.paid_out_m.is_finite()
            && self.drum_speed_radps.is_finite()
            && self.drum_integral_rad.is_finite()
            && self.pos.iter().all(v)
            && self.vel.iter().all(v)
    }
}

/// What drives the tether at the reel during one derivative evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
enum ReelDrive {
    /// l̇ imposed (ideal, lag, locked).
    Rate(f64),
    /// The drum's motor with this speed command (or tension command: [`motor_torque`]),
    /// motion and brake.
    Drum {
        drum: DrumParams,
        command_radps: f64,
        tension_n: Option<f64>,
        motion: Motion,
        brake: bool,
    },
    /// The drum under a motor torque held over the inner tick (the flight drive).
    Held {
        drum: DrumParams,
        torque_nm: f64,
        motion: Motion,
        brake: bool,
    },
}

impl ReelDrive {
    /// The reel's rate l̇ with the drum turning at `drum_speed_radps`, m/s.
    fn rate_mps(&self, drum_speed_radps: f64) -> f64 {
        match *self {
            ReelDrive::Rate(v) => v,
            ReelDrive::Drum {
                motion: Motion::Stuck,
                ..
            }
            | ReelDrive::Held {
                motion: Motion::Stuck,
                ..
            } => 0.0,
            ReelDrive::Drum { drum, .. } | ReelDrive::Held { drum, .. } => {
                drum.radius_m * drum_speed_radps
            }
        }
    }
}

/// The drum motor's torque and its speed loop's integrator rate: the speed loop's
/// ([`DrumParams::speed_loop`]) under a rate command; under a tension command T (a tension law,
/// `crate::laws`) the motor holds the tether back with −T·r (T ≥ 0: a tether only pulls) and
/// compensates its drum's friction from the drum's model: while the drum turns, the viscous and
/// Coulomb friction fed forward from its speed (so J ω̇ = r(T_reel − T) while it turns); while
/// it is stuck, the breakaway torque in the direction the tether's pull `reel_tension_n` − T
/// would turn it (the tension at the reel is measured: the load cell of the controller's
/// input). Clamped to the torque limit; the speed loop's integrator rests.
fn motor_torque(
    d: &DrumParams,
    tension_n: Option<f64>,
    reel_tension_n: f64,
    command_radps: f64,
    speed_radps: f64,
    integral_rad: f64,
) -> (f64, f64) {
    match tension_n {
        Some(t) => {
            let t = t.max(0.0);
            let friction = if speed_radps != 0.0 {
                d.viscous_nms * speed_radps + d.coulomb_nm * speed_radps.signum()
            } else {
                let pull = reel_tension_n - t;
                if pull != 0.0 {
                    d.static_nm * pull.signum()
                } else {
                    0.0
                }
            };
            let torque = -d.radius_m * t + friction;
            (torque.clamp(-d.max_torque_nm, d.max_torque_nm), 0.0)
        }
        None => d.speed_loop(command_radps, speed_radps, integral_rad),
    }
}

/// The angles of a direction in the centre of mass's orbit frame (docs/equations.md §0):
/// e_t = cosβ(cosα e_r + sinα e_θ) + sinβ e_h, and their rates in that frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Angles {
    /// α, rad.
    pub alpha_rad: f64,
    /// α̇, rad/s.
    pub alpha_rate_radps: f64,
    /// β, rad.
    pub beta_rad: f64,
    /// β̇, rad/s.
    pub beta_rate_radps: f64,
}

/// Everything observable about the truth model at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measurement {
    /// Time since the start, s.
    pub t_s: f64,
    /// Unstretched length paid out (the reel encoder), m.
    pub paid_out_m: f64,
    /// The reel's rate l̇ now, m/s.
    pub reel_rate_mps: f64,
    /// Angles of the line main satellite → sub-satellite.
    pub line: Angles,
    /// Angles of the tether's exit direction at the deployer (main satellite → first node).
    pub exit: Angles,
    /// The centre of mass's orbit rate θ̇, rad/s.
    pub orbit_rate_radps: f64,
    /// The centre of mass's true anomaly θ, rad: its angle from the initial orbit's periapsis
    /// in the initial orbit plane (J2's node regression turns the plane slowly away from it).
    pub true_anomaly_rad: f64,
    /// Tension at the reel (the reel segment), N.
    pub tension_reel_n: f64,
    /// Tension at the sub-satellite (the last segment), N.
    pub tension_tip_n: f64,
    /// Distance between the end bodies, m.
    pub range_m: f64,
    /// Largest distance of a bead from the straight line between the end bodies, m.
    pub bowing_m: f64,
    /// Number of beads.
    pub beads: usize,
    /// The drum is held by static friction (motor reel).
    pub drum_stuck: bool,
}

impl Measurement {
    /// The angles the controller senses under `sensing`.
    pub fn sensed(&self, sensing: Sensing) -> Angles {
        match sensing {
            Sensing::Line => self.line,
            Sensing::Exit => self.exit,
        }
    }
}

/// Counts of the feeding rule's actions since the start.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FeedCounts {
    /// Beads inserted at the reel.
    pub inserted: u64,
    /// Beads removed at the reel.
    pub removed: u64,
}

/// Preallocated buffers of one RK4 step.
#[derive(Clone, Debug, Default)]
struct Workspace {
    k: [State; 4],
    stage: State,
    masses: Vec<f64>,
}

/// The reel's state between periods, by model.
#[derive(Clone, Copy, Debug, PartialEq)]
enum ReelState {
    /// Held still (`reel.locked`), whatever the model.
    Locked,
    /// The rate is the command.
    Ideal,
    /// The lag drive, with its rate now.
    Lag(Reel),
    /// The drum and its stick/slip state (its speed and integral are integrated in [`State`]).
    Motor {
        /// Its parameters.
        drum: DrumParams,
        /// Stuck or slipping.
        motion: Motion,
    },
    /// The drum under the flight speed loop ([`FlightDrum`], kept in the plant): the torque
    /// and brake of the current inner tick.
    Flight {
        /// Its parameters.
        drum: DrumParams,
        /// Stuck or slipping.
        motion: Motion,
        /// Motor torque held over the tick, N·m.
        torque_nm: f64,
        /// The spring brake engaged.
        brake: bool,
    },
}

/// The truth model, stepped one control period at a time.
#[derive(Clone, Debug)]
pub struct ElasticPlant {
    p: ElasticParams,
    layout: Layout,
    y: State,
    /// The reel's own state.
    reel: ReelState,
    /// The reel's rate at the end of the last period, m/s.
    reel_rate_mps: f64,
    t_s: f64,
    feeds: FeedCounts,
    substeps_last: u32,
    /// The control period the reel's saturation flags are judged over (the last one stepped;
    /// 1 s before the first), s.
    period_hint_s: f64,
    /// The tension command of the current period (a tension law drives the drum's torque),
    /// N; `None` under a rate command.
    tension_cmd_n: Option<f64>,
    /// The acceleration the law commanded with the current period's rate (Eq. 30), m/s²
    /// (the flight drive's ramp feeds it forward).
    accel_cmd_mps2: f64,
    /// The flight speed loop (flight reel only) and the paid-out length its encoder counts
    /// from, m.
    flight: Option<(Box<FlightDrum>, f64)>,
    ws: Workspace,
}

impl ElasticPlant {
    /// A tether straight along (α, β) at its initial length, pre-stretched to static
    /// equilibrium (`initial.rs`), with the centre of mass on the orbit (see the module doc),
    /// the reel running at the initial rate.
    pub fn new(p: ElasticParams, init: InitialConditions) -> Result<Self, ElasticError> {
        p.validate()?;
        check(
            "initial.length_m",
            init.length_m,
            init.length_m > 0.0,
            "> 0",
        )?;
        check("initial.rate_mps", init.rate_mps, true, "finite")?;
        check("initial.alpha_rad", init.alpha_rad, true, "finite")?;
        check(
            "initial.alpha_rate_radps",
            init.alpha_rate_radps,
            true,
            "finite",
        )?;
        check("initial.beta_rad", init.beta_rad, true, "finite")?;
        check(
            "initial.beta_rate_radps",
            init.beta_rate_radps,
            true,
            "finite",
        )?;
        let (r_c, v_c) = orbit_state(&p.orbit, &p.environment);
        let (e_r, e_th, e_h) = orbit_frame(&r_c, &v_c);
        let theta_rate = r_c.cross(&v_c).norm() / r_c.norm_squared();
        let (sa, ca) = init.alpha_rad.sin_cos();
        let (sb, cb) = init.beta_rad.sin_cos();
        let e_t = (e_r * ca + e_th * sa) * cb + e_h * sb;
        let e_t_rate = (e_th * ca - e_r * sa) * (init.alpha_rate_radps * cb)
            + ((e_r * ca + e_th * sa) * (-sb) + e_h * cb) * init.beta_rate_radps;

        let layout = Layout::initial(&p.tether, init.length_m);
        let mut masses = Vec::new();
        let b = &p.bodies;
        layout.masses(
            &p.tether,
            b.main_initial_kg,
            b.sub_kg,
            init.length_m,
            &mut masses,
        );
        let locked = p.reel.locked;
        let rate = if locked { 0.0 } else { init.rate_mps };
        let start = initial::equilibrium(
            &p.tether,
            &p.environment,
            &layout,
            &masses,
            init.length_m,
            init.rate_mps,
            rate,
            &r_c,
            &initial::Line {
                direction: e_t,
                direction_rate: e_t_rate,
                frame_rate: e_h * theta_rate,
            },
        );
        let (pos, vel) = (start.pos, start.vel);

        let (mut speed, mut integral) = (0.0, 0.0);
        let mut reel = match p.reel.model {
            _ if locked => ReelState::Locked,
            ReelModel::Ideal => ReelState::Ideal,
            ReelModel::Lag(mut r) => {
                r.rate_mps = rate.clamp(-r.max_rate_mps, r.max_rate_mps);
                ReelState::Lag(r)
            }
            ReelModel::Motor(drum) => {
                speed = rate / drum.radius_m;
                // The loop starts holding that speed against the friction and the tension.
                let motion = if speed == 0.0 {
                    Motion::Stuck
                } else {
                    let hold = drum.viscous_nms * speed + drum.coulomb_nm * speed.signum()
                        - drum.radius_m * start.reel_tension_n;
                    integral = hold / drum.ki();
                    Motion::Slipping(speed.signum())
                };
                ReelState::Motor { drum, motion }
            }
            // The flight drive starts braked at rest here; spun up below.
            ReelModel::Flight(f) => ReelState::Flight {
                drum: f.drum,
                motion: Motion::Stuck,
                torque_nm: 0.0,
                brake: true,
            },
        };
        let flight = match p.reel.model {
            ReelModel::Flight(f) if !locked => {
                let mut drum = FlightDrum::new(f.drum, f.drive_config()).map_err(|_| {
                    ElasticError::Invalid {
                        field: "reel (flight drive configuration)",
                        value: f64::from(f.inner_rate_hz),
                        rule: "a valid tss_reel::reel_drive::DriveConfig",
                    }
                })?;
                // The reel pays out at l̇(0) when the mission starts, as the motor reel does
                // (`FlightDrum::spin_up`: the drive's own brake release and ramp, before t = 0).
                // The encoder's origin is where the spin-up started, so that its count goes
                // on from the spin-up's.
                let travel_m = drum.spin_up(rate);
                let (drum_radps, motion) = drum.drum_state();
                speed = drum_radps;
                if let ReelState::Flight {
                    motion: m,
                    brake: b,
                    ..
                } = &mut reel
                {
                    *m = motion;
                    *b = !drum.speed_loop().brake().brake_released();
                }
                Some((Box::new(drum), init.length_m - travel_m))
            }
            _ => None,
        };
        let y = State {
            r_ref: r_c,
            v_ref: v_c,
            paid_out_m: init.length_m,
            drum_speed_radps: speed,
            drum_integral_rad: integral,
            pos,
            vel,
        };
        let reel_rate_mps = match (&reel, &flight) {
            (ReelState::Lag(r), _) => r.rate_mps,
            (ReelState::Flight { drum, .. }, Some(_)) => drum.radius_m * speed,
            (ReelState::Flight { .. }, None) => 0.0,
            _ => rate,
        };
        Ok(Self {
            p,
            layout,
            y,
            reel,
            reel_rate_mps,
            t_s: 0.0,
            feeds: FeedCounts::default(),
            substeps_last: 0,
            period_hint_s: 1.0,
            tension_cmd_n: None,
            accel_cmd_mps2: 0.0,
            flight,
            ws: Workspace::default(),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &ElasticParams {
        &self.p
    }

    /// Time since the start, s.
    pub fn time_s(&self) -> f64 {
        self.t_s
    }

    /// The feeding rule's actions so far.
    pub fn feeds(&self) -> FeedCounts {
        self.feeds
    }

    /// The substeps the last period took.
    pub fn substeps_last(&self) -> u32 {
        self.substeps_last
    }

    /// Unstretched length paid out (the encoder), m.
    pub fn paid_out_m(&self) -> f64 {
        self.y.paid_out_m
    }

    /// Every node's mass, kg (main satellite, beads, sub-satellite).
    pub fn masses(&self) -> Vec<f64> {
        let mut m = Vec::new();
        self.node_masses(&mut m);
        m
    }

    fn node_masses(&self, m: &mut Vec<f64>) {
        let b = &self.p.bodies;
        self.layout.masses(
            &self.p.tether,
            b.main_initial_kg,
            b.sub_kg,
            self.y.paid_out_m,
            m,
        );
    }

    /// Total linear momentum of the nodes relative to the reference particle's motion,
    /// Σ m_i ρ̇_i, kg·m/s (the reference particle's own momentum M·V is left out).
    pub fn relative_momentum(&self) -> Vec3 {
        self.masses()
            .iter()
            .zip(&self.y.vel)
            .map(|(m, v)| v * *m)
            .sum()
    }

    /// Positions of the nodes relative to the main satellite, in the centre of mass's orbit
    /// frame (e_r, e_θ, e_h), m: the tether's shape.
    pub fn shape_orbit_frame(&self) -> Vec<[f64; 3]> {
        let (rc, vc, _) = self.centre_of_mass();
        let (e_r, e_th, e_h) = orbit_frame(&rc, &vc);
        let p0 = self.y.pos[0];
        self.y
            .pos
            .iter()
            .map(|p| {
                let d = p - p0;
                [d.dot(&e_r), d.dot(&e_th), d.dot(&e_h)]
            })
            .collect()
    }

    /// The centre of mass's absolute (Earth-centred inertial) position and velocity, m, m/s.
    pub fn centre_of_mass_state(&self) -> (Vec3, Vec3) {
        let (r, v, _) = self.centre_of_mass();
        (r, v)
    }

    /// The centre of mass's absolute position and velocity and the total mass.
    fn centre_of_mass(&self) -> (Vec3, Vec3, f64) {
        let m = self.masses();
        let total: f64 = m.iter().sum();
        let p: Vec3 = m.iter().zip(&self.y.pos).map(|(m, p)| p * *m).sum();
        let v: Vec3 = m.iter().zip(&self.y.vel).map(|(m, v)| v * *m).sum();
        (self.y.r_ref + p / total, self.y.v_ref + v / total, total)
    }

    /// The Jacobi integral of the relative motion on a circular orbit, J: with the frame
    /// rotating at n = √(μ/a³) about the orbit normal and centred on the circular orbit's point
    /// R0(t) (the reference orbit of the initial conditions),
    /// J = Σ m_i(½|v_i,rot|² + ΔU(ρ'_i)) + Σ elastic energy, with
    /// ΔU = −μ(1/r − 1/a) − n² a x' − ½n²(x'² + y'²) (the constant at ρ' = 0 dropped).
    /// Conserved with the reel locked, damping, drag and J2 off, on a circular orbit; it is
    /// E − n·H_z of the inertial frame less a constant, computed without the cancellation of
    /// the 10¹¹ J orbital terms.
    pub fn jacobi_integral_j(&self) -> f64 {
        let o = &self.p.orbit;
        let a = o.orbit.semi_major_axis_m;
        let mu = o.orbit.mu_m3ps2;
        let n = (mu / (a * a * a)).sqrt();
        let (p_hat, q_hat) = plane_basis(o.inclination_rad);
        let h_hat = p_hat.cross(&q_hat);
        let phi = o.initial_true_anomaly_rad + n * self.t_s;
        let x_hat = p_hat * phi.cos() + q_hat * phi.sin();
        let y_hat = h_hat.cross(&x_hat);
        let r0 = x_hat * a;
        let v0 = h_hat.cross(&r0) * n;
        let masses = self.masses();
        let mut j = 0.0;
        for (i, m) in masses.iter().enumerate() {
            let rho = (self.y.r_ref - r0) + self.y.pos[i];
            let v_rot = (self.y.v_ref - v0) + self.y.vel[i] - h_hat.cross(&rho) * n;
            let (x, y) = (rho.dot(&x_hat), rho.dot(&y_hat));
            let rho2 = rho.norm_squared();
            let r = (a * a + 2.0 * a * x + rho2).sqrt();
            let du = mu * (2.0 * a * x + rho2) / (a * r * (r + a))
                - n * n * a * x
                - 0.5 * n * n * (x * x + y * y);
            j += m * (0.5 * v_rot.norm_squared() + du);
        }
        for s in 0..self.layout.nodes() - 1 {
            let chord = (self.y.pos[s + 1] - self.y.pos[s]).norm();
            let l = self.layout.segment_m(&self.p.tether, self.y.paid_out_m, s);
            j += self.p.tether.elastic_energy_j(chord, l);
        }
        j
    }

    /// Observes the model now (see [`Measurement`]).
    pub fn measure(&self) -> Measurement {
        let (rc, vc, _) = self.centre_of_mass();
        let (e_r, e_th, e_h) = orbit_frame(&rc, &vc);
        let h = rc.cross(&vc);
        let omega = h / rc.norm_squared();
        let y = &self.y;
        let last = y.pos.len() - 1;
        let angles = |j: usize| {
            let d = y.pos[j] - y.pos[0];
            let d_rate = (y.vel[j] - y.vel[0]) - omega.cross(&d);
            direction_angles(&d, &d_rate, &e_r, &e_th, &e_h)
        };
        let tension = |s: usize| {
            let d = y.pos[s + 1] - y.pos[s];
            let chord = d.norm();
            let rate = if chord > 0.0 {
                (y.vel[s + 1] - y.vel[s]).dot(&d) / chord
            } else {
                0.0
            };
            let l = self.layout.segment_m(&self.p.tether, y.paid_out_m, s);
            let l_rate = if s == 0 { self.reel_rate_mps } else { 0.0 };
            self.p.tether.tension_n(chord, rate, l, l_rate)
        };
        let line = y.pos[last] - y.pos[0];
        let range = line.norm();
        let u = line / range;
        let bowing = (1..last)
            .map(|i| {
                let d = y.pos[i] - y.pos[0];
                (d - u * u.dot(&d)).norm()
            })
            .fold(0.0, f64::max);
        Measurement {
            t_s: self.t_s,
            paid_out_m: y.paid_out_m,
            reel_rate_mps: self.reel_rate_mps,
            line: angles(last),
            exit: angles(1),
            orbit_rate_radps: h.norm() / rc.norm_squared(),
            true_anomaly_rad: {
                let (p_hat, q_hat) = plane_basis(self.p.orbit.inclination_rad);
                rc.dot(&q_hat).atan2(rc.dot(&p_hat))
            },
            tension_reel_n: tension(0),
            tension_tip_n: tension(last - 1),
            range_m: range,
            bowing_m: bowing,
            beads: self.layout.beads,
            drum_stuck: matches!(
                self.reel,
                ReelState::Motor {
                    motion: Motion::Stuck,
                    ..
                } | ReelState::Flight {
                    motion: Motion::Stuck,
                    ..
                }
            ),
        }
    }

    /// The highest rate (rad/s or 1/s) of the current configuration that the step must resolve.
    fn fastest_rate(&mut self) -> f64 {
        let mut m = std::mem::take(&mut self.ws.masses);
        self.node_masses(&mut m);
        let t = &self.p.tether;
        let mut fastest: f64 = 0.0;
        let drum = self.drum();
        for s in 0..m.len() - 1 {
            let l = self.layout.segment_m(t, self.y.paid_out_m, s);
            let mut inv_mass = 1.0 / m[s] + 1.0 / m[s + 1];
            if let (0, Some(d)) = (s, drum) {
                inv_mass += d.radius_m * d.radius_m / d.inertia_kgm2;
            }
            let k = t.stiffness_npm(l);
            fastest = fastest
                .max((k * inv_mass).sqrt())
                .max(t.damping_ns / l.max(t.min_stiffness_length_m) * inv_mass);
        }
        if let Some(d) = drum {
            fastest = fastest
                .max(2.0 * d.speed_bandwidth_radps)
                .max(d.viscous_nms / d.inertia_kgm2);
        }
        self.ws.masses = m;
        fastest
    }

    /// Advances one control period of `period_s` with the reel commanded at `command_mps`
    /// (held over the period; ignored while the reel is locked).
    pub fn step(&mut self, command_mps: f64, period_s: f64) -> Result<(), ElasticError> {
        check("command_mps", command_mps, true, "finite")?;
        check("period_s", period_s, period_s > 0.0, "> 0")?;
        let command = match self.reel {
            ReelState::Locked => 0.0,
            _ => command_mps,
        };
        if self.flight.is_some() {
            self.step_flight(command, period_s)?;
            self.t_s += period_s;
            self.reel_rate_mps = self
                .drum()
                .map_or(0.0, |d| d.radius_m * self.y.drum_speed_radps);
            return Ok(());
        }
        let n = (period_s * self.fastest_rate() / self.p.courant)
            .ceil()
            .max(1.0);
        let n = if n > f64::from(u32::MAX) {
            u32::MAX
        } else {
            n as u32
        };
        self.substeps_last = n;
        let h = period_s / f64::from(n);
        for k in 0..n {
            self.substep(command, f64::from(k) * h, h);
            if !self.y.is_finite() {
                return Err(ElasticError::Diverged {
                    t_s: self.t_s + f64::from(k) * h,
                });
            }
        }
        self.t_s += period_s;
        self.reel_rate_mps = match &mut self.reel {
            ReelState::Locked => 0.0,
            ReelState::Ideal => command,
            ReelState::Lag(r) => {
                r.advance(command, period_s);
                r.rate_mps
            }
            ReelState::Motor { drum, .. } | ReelState::Flight { drum, .. } => {
                drum.radius_m * self.y.drum_speed_radps
            }
        };
        Ok(())
    }

    /// One law period of the flight drive: the law's `command` reaches the speed loop, which
    /// then runs at its inner rate, each tick reading the encoder (the paid-out length turned
    /// into drum counts) and the tension at the reel, its torque held over the tick while the
    /// plant integrates.
    fn step_flight(&mut self, command: f64, period_s: f64) -> Result<(), ElasticError> {
        let Some((mut flight, start_m)) = self.flight.take() else {
            return Ok(());
        };
        let result = self.fly_period(&mut flight, start_m, command, period_s);
        self.flight = Some((flight, start_m));
        result
    }

    fn fly_period(
        &mut self,
        flight: &mut FlightDrum,
        start_m: f64,
        command: f64,
        period_s: f64,
    ) -> Result<(), ElasticError> {
        let Some(d) = self.drum() else {
            return Ok(());
        };
        let hz = f64::from(flight.speed_loop().config().inner_rate_hz);
        let ticks = (period_s * hz).round().max(1.0) as u32;
        let dt = period_s / f64::from(ticks);
        flight.begin_period(
            tss_reel::reel_drive::RateCommand {
                rate_mps: command as f32,
                accel_mps2: self.accel_cmd_mps2 as f32,
                safe_hold: false,
            },
            self.reel_tension_n(&d),
        );
        let mut substeps = 0;
        for tick in 0..ticks {
            let angle_rad = (self.y.paid_out_m - start_m) / d.radius_m;
            let (torque_nm, brake) = flight.start_tick(angle_rad, self.reel_tension_n(&d));
            if let ReelState::Flight {
                torque_nm: t,
                brake: b,
                ..
            } = &mut self.reel
            {
                (*t, *b) = (torque_nm, brake);
            }
            let n = (dt * self.fastest_rate() / self.p.courant).ceil().max(1.0) as u32;
            substeps += n;
            let h = dt / f64::from(n);
            for k in 0..n {
                self.substep(command, f64::from(tick) * dt + f64::from(k) * h, h);
                if !self.y.is_finite() {
                    return Err(ElasticError::Diverged {
                        t_s: self.t_s + f64::from(tick) * dt + f64::from(k) * h,
                    });
                }
            }
            flight.end_tick(d.radius_m * self.y.drum_speed_radps);
        }
        flight.end_period(command, d.radius_m * self.y.drum_speed_radps);
        self.substeps_last = substeps;
        Ok(())
    }

    /// What the flight drive did so far (flight reel only).
    pub fn drive_figures(&self) -> Option<DriveFigures> {
        self.flight.as_ref().map(|(f, _)| {
            let mut figures = *f.figures();
            figures.duty = f.duty();
            figures
        })
    }

    /// The reel's drive at `t_in_period_s` into the period under `command`.
    fn drive(&self, command: f64, t_in_period_s: f64, brake: bool) -> ReelDrive {
        match self.reel {
            ReelState::Locked => ReelDrive::Rate(0.0),
            ReelState::Ideal => ReelDrive::Rate(command),
            ReelState::Lag(r) => ReelDrive::Rate(r.rate_after(command, t_in_period_s)),
            ReelState::Motor { drum, motion } => ReelDrive::Drum {
                drum,
                command_radps: command / drum.radius_m,
                tension_n: self.tension_cmd_n,
                motion,
                brake,
            },
            ReelState::Flight {
                drum,
                motion,
                torque_nm,
                brake,
            } => ReelDrive::Held {
                drum,
                torque_nm,
                motion,
                brake,
            },
        }
    }

    /// The drum's parameters, if a motor reel is turning (not locked).
    fn drum(&self) -> Option<DrumParams> {
        match self.reel {
            ReelState::Motor { drum, .. } | ReelState::Flight { drum, .. } => Some(drum),
            _ => None,
        }
    }

    /// Sets the drum's stick/slip state (motor reel).
    fn set_motion(&mut self, to: Motion) {
        if let ReelState::Motor { motion, .. } | ReelState::Flight { motion, .. } = &mut self.reel {
            *motion = to;
        }
    }

    /// The drum's stick/slip state (stuck for every other reel).
    fn motion(&self) -> Motion {
        match self.reel {
            ReelState::Motor { motion, .. } | ReelState::Flight { motion, .. } => motion,
            _ => Motion::Stuck,
        }
    }

    /// One RK4 substep of `h` starting `t0` into the period, then the drum's stick/slip
    /// switch and the feeding rule.
    fn substep(&mut self, command: f64, t0: f64, h: f64) {
        // The brake holds a zero rate command; a tension law commands the motor, never the brake.
        let brake = match self.reel {
            ReelState::Flight { brake, .. } => brake,
            _ => command == 0.0 && self.tension_cmd_n.is_none(),
        };
        let motor = self.drum();
        if let Some(d) = motor {
            let drive = self.drum_drive_nm(&d, command);
            let motion = d.motion_for_step(self.motion(), drive, self.y.drum_speed_radps, brake);
            self.set_motion(motion);
        }
        let speed_start = self.y.drum_speed_radps;
        let mut ws = std::mem::take(&mut self.ws);
        let drives = [
            self.drive(command, t0, brake),
            self.drive(command, t0 + 0.5 * h, brake),
            self.drive(command, t0 + h, brake),
        ];
        let [k1, k2, k3, k4] = &mut ws.k;
        derivative(
            &self.p,
            &self.layout,
            &self.y,
            drives[0],
            &mut ws.masses,
            k1,
        );
        ws.stage.set_stage(&self.y, 0.5 * h, k1);
        derivative(
            &self.p,
            &self.layout,
            &ws.stage,
            drives[1],
            &mut ws.masses,
            k2,
        );
        ws.stage.set_stage(&self.y, 0.5 * h, k2);
        derivative(
            &self.p,
            &self.layout,
            &ws.stage,
            drives[1],
            &mut ws.masses,
            k3,
        );
        ws.stage.set_stage(&self.y, h, k3);
        derivative(
            &self.p,
            &self.layout,
            &ws.stage,
            drives[2],
            &mut ws.masses,
            k4,
        );
        let c = h / 6.0;
        let y = &mut self.y;
        let comb = |a: f64, b: f64, d: f64, e: f64| (a + 2.0 * b + 2.0 * d + e) * c;
        y.r_ref += (k1.r_ref + k2.r_ref * 2.0 + k3.r_ref * 2.0 + k4.r_ref) * c;
        y.v_ref += (k1.v_ref + k2.v_ref * 2.0 + k3.v_ref * 2.0 + k4.v_ref) * c;
        y.paid_out_m += comb(k1.paid_out_m, k2.paid_out_m, k3.paid_out_m, k4.paid_out_m);
        y.drum_speed_radps += comb(
            k1.drum_speed_radps,
            k2.drum_speed_radps,
            k3.drum_speed_radps,
            k4.drum_speed_radps,
        );
        y.drum_integral_rad += comb(
            k1.drum_integral_rad,
            k2.drum_integral_rad,
            k3.drum_integral_rad,
            k4.drum_integral_rad,
        );
        for i in 0..y.pos.len() {
            y.pos[i] += (k1.pos[i] + k2.pos[i] * 2.0 + k3.pos[i] * 2.0 + k4.pos[i]) * c;
            y.vel[i] += (k1.vel[i] + k2.vel[i] * 2.0 + k3.vel[i] * 2.0 + k4.vel[i]) * c;
        }
        self.ws = ws;
        if let Some(d) = motor {
            let drive = self.drum_drive_nm(&d, command);
            let (motion, speed) = d.after_step(
                self.motion(),
                speed_start,
                self.y.drum_speed_radps,
                drive,
                brake,
            );
            self.set_motion(motion);
            self.y.drum_speed_radps = speed;
        }
        let rate = self
            .drive(command, t0 + h, brake)
            .rate_mps(self.y.drum_speed_radps);
        self.feed(rate);
    }

    /// τ_m + r T_reel at the current state, N·m.
    fn drum_drive_nm(&self, d: &DrumParams, command: f64) -> f64 {
        let tension = self.reel_tension_n(d);
        if let ReelState::Flight { torque_nm, .. } = self.reel {
            return torque_nm + d.radius_m * tension;
        }
        let y = &self.y;
        let (torque, _) = motor_torque(
            d,
            self.tension_cmd_n,
            tension,
            command / d.radius_m,
            y.drum_speed_radps,
            y.drum_integral_rad,
        );
        torque + d.radius_m * tension
    }

    /// The tension of the reel segment at the current state, N.
    fn reel_tension_n(&self, d: &DrumParams) -> f64 {
        let y = &self.y;
        let dvec = y.pos[1] - y.pos[0];
        let chord = dvec.norm();
        let rate = if chord > 0.0 {
            (y.vel[1] - y.vel[0]).dot(&dvec) / chord
        } else {
            0.0
        };
        let l = self.layout.reel_segment_m(&self.p.tether, y.paid_out_m);
        self.p
            .tether
            .tension_n(chord, rate, l, d.radius_m * y.drum_speed_radps)
    }

    /// Applies the feeding rule until the reel segment is inside its band.
    /// The reel pays out at `reel_rate_mps` (the material's rate at the reel).
    fn feed(&mut self, reel_rate_mps: f64) {
        let mut m = std::mem::take(&mut self.ws.masses);
        loop {
            self.node_masses(&mut m);
            match tether::feed(
                &self.p.tether,
                &mut self.layout,
                self.y.paid_out_m,
                reel_rate_mps,
                &m,
                &mut self.y.pos,
                &mut self.y.vel,
            ) {
                Feed::Nothing => break,
                Feed::Inserted => self.feeds.inserted += 1,
                Feed::Removed => self.feeds.removed += 1,
            }
        }
        self.ws.masses = m;
    }
}

/// The time derivative of `y` (see the module doc) into `dy`.
fn derivative(
    p: &ElasticParams,
    layout: &Layout,
    y: &State,
    drive: ReelDrive,
    masses: &mut Vec<f64>,
    dy: &mut State,
) {
    let t = &p.tether;
    let b = &p.bodies;
    let env = &p.environment;
    layout.masses(t, b.main_initial_kg, b.sub_kg, y.paid_out_m, masses);
    let n = masses.len();
    dy.pos.resize(n, Vec3::zeros());
    dy.vel.resize(n, Vec3::zeros());
    let reel_rate = drive.rate_mps(y.drum_speed_radps);
    dy.r_ref = y.v_ref;
    let g_ref = env.gravity(&y.r_ref);
    dy.v_ref = g_ref;
    dy.paid_out_m = reel_rate;
    // Forces: gravity relative to the reference particle's (exact), then the tether, drag and
    // the momentum flux of the paid-out tether; divided by the masses at the end.
    for (i, m) in masses.iter().enumerate() {
        dy.pos[i] = y.vel[i];
        dy.vel[i] = env.gravity_relative(&y.r_ref, &g_ref, &y.pos[i]) * *m;
    }
    let mut tension_reel = 0.0;
    let cd_d = t.drag_coefficient * t.diameter_m;
    for s in 0..n - 1 {
        let d = y.pos[s + 1] - y.pos[s];
        let chord = d.norm();
        if chord == 0.0 {
            continue;
        }
        let u = d / chord;
        let chord_rate = (y.vel[s + 1] - y.vel[s]).dot(&u);
        let (l, l_rate) = if s == 0 {
            (layout.reel_segment_m(t, y.paid_out_m), reel_rate)
        } else {
            (t.segment_length_m, 0.0)
        };
        let tension = t.tension_n(chord, chord_rate, l, l_rate);
        if s == 0 {
            tension_reel = tension;
        }
        let f = u * tension;
        dy.vel[s] += f;
        dy.vel[s + 1] -= f;
        if env.drag && cd_d > 0.0 {
            let mid = y.r_ref + (y.pos[s] + y.pos[s + 1]) * 0.5;
            let rho_air = env.air_density_kgpm3(&mid);
            let v_air = y.v_ref + (y.vel[s] + y.vel[s + 1]) * 0.5 - air_velocity_mps(&mid);
            let f = cylinder_drag_n(rho_air, cd_d * chord, &u, &v_air) * 0.5;
            dy.vel[s] += f;
            dy.vel[s + 1] += f;
        }
    }
    if env.drag {
        for (i, cda) in [(0, b.main_drag_area_m2), (n - 1, b.sub_drag_area_m2)] {
            let r = y.r_ref + y.pos[i];
            let v_air = y.v_ref + y.vel[i] - air_velocity_mps(&r);
            dy.vel[i] += body_drag_n(env.air_density_kgpm3(&r), cda, &v_air);
        }
    }
    // Paying out, ½ρl̇ kg/s of tether joins node 1 at node 0's velocity (winding in, it leaves
    // node 1 for node 0 at node 1's velocity): the receiver's momentum changes by
    // q·(v_donor − v_receiver), the donor's velocity not at all.
    let q = 0.5 * t.density_kg_per_m * reel_rate;
    if q > 0.0 {
        dy.vel[1] += (y.vel[0] - y.vel[1]) * q;
    } else if q < 0.0 {
        dy.vel[0] += (y.vel[1] - y.vel[0]) * (-q);
    }
    for (v, m) in dy.vel.iter_mut().zip(masses.iter()) {
        *v /= *m;
    }
    (dy.drum_speed_radps, dy.drum_integral_rad) = match drive {
        ReelDrive::Rate(_) => (0.0, 0.0),
        ReelDrive::Drum {
            drum: d,
            command_radps,
            tension_n,
            motion,
            brake,
        } => {
            let (torque, integral_rate) = motor_torque(
                &d,
                tension_n,
                tension_reel,
                command_radps,
                y.drum_speed_radps,
                y.drum_integral_rad,
            );
            let drive = torque + d.radius_m * tension_reel;
            let accel = d.accel_radps2(motion, drive, y.drum_speed_radps, brake);
            (accel, integral_rate)
        }
        ReelDrive::Held {
            drum: d,
            torque_nm,
            motion,
            brake,
        } => {
            let drive = torque_nm + d.radius_m * tension_reel;
            (
                d.accel_radps2(motion, drive, y.drum_speed_radps, brake),
                0.0,
            )
        }
    };
}

/// The in-plane basis of an orbit of inclination `i` with the node and perigee on x:
/// p̂ = x̂, q̂ = (0, cos i, sin i).
fn plane_basis(inclination_rad: f64) -> (Vec3, Vec3) {
    let (si, ci) = inclination_rad.sin_cos();
    (Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, ci, si))
}

/// Position and velocity on the orbit at its initial true anomaly: Keplerian, except that a
/// circular orbit (e = 0) with J2 on starts at the circular speed of the oblate field, so that
/// it stays circular as the scenario says. At the Keplerian speed √(μ/a) the J2 field's extra
/// pull, (3/2) J2 (R_e/a)² of the point mass's on the equator, would make it an orbit of
/// e ≈ 1.3e-3 at 700 km (a ±9 km radius swing once an orbit), which forces a libration of the
/// same order (docs/equations.md §16) that a controller told e = 0 cannot know: the 30 km keep
/// moved by ±20 m. The speed balances the orbit-averaged radial gravity,
/// v² = (μ/a) (1 + (3/2) J2 (R_e/a)² (1 − (3/2) sin² i)): exact on the equator (the radial
/// J2 pull is then constant round the circle), first order in J2 on an inclined orbit, whose
/// radial pull varies with latitude.
fn orbit_state(o: &OrbitParams, env: &Environment) -> (Vec3, Vec3) {
    let (p_hat, q_hat) = plane_basis(o.inclination_rad);
    let a = o.orbit.semi_major_axis_m;
    let e = o.orbit.eccentricity;
    let semi_latus = a * (1.0 - e * e);
    let (s, c) = o.initial_true_anomaly_rad.sin_cos();
    let r = semi_latus / (1.0 + e * c);
    let oblate = if env.j2 && e == 0.0 {
        let re_a = environment::EARTH_EQUATORIAL_RADIUS_M / a;
        let si = o.inclination_rad.sin();
        1.0 + 1.5 * environment::EARTH_J2 * re_a * re_a * (1.0 - 1.5 * si * si)
    } else {
        1.0
    };
    let v = (o.orbit.mu_m3ps2 / semi_latus * oblate).sqrt();
    (
        (p_hat * c + q_hat * s) * r,
        (p_hat * (-s) + q_hat * (e + c)) * v,
    )
}

/// The orbit frame (e_r, e_θ, e_h) of a body at `r` moving at `v` (docs/equations.md §0).
fn orbit_frame(r: &Vec3, v: &Vec3) -> (Vec3, Vec3, Vec3) {
    let e_r = r.normalize();
    let e_h = r.cross(v).normalize();
    (e_r, e_h.cross(&e_r), e_h)
}

/// α, β of the direction `d` and their rates from `d_rate` (its derivative in the rotating
/// orbit frame), with e_t = d/|d| = cosβ(cosα e_r + sinα e_θ) + sinβ e_h.
fn direction_angles(d: &Vec3, d_rate: &Vec3, e_r: &Vec3, e_th: &Vec3, e_h: &Vec3) -> Angles {
    let (x, y, z) = (d.dot(e_r), d.dot(e_th), d.dot(e_h));
    let (xd, yd, zd) = (d_rate.dot(e_r), d_rate.dot(e_th), d_rate.dot(e_h));
    let rho2 = x * x + y * y;
    let norm = d.norm();
    let s = z / norm;
    let s_rate = (zd - s * (d.dot(d_rate) / norm)) / norm;
    Angles {
        alpha_rad: y.atan2(x),
        alpha_rate_radps: (x * yd - y * xd) / rho2,
        beta_rad: s.asin(),
        beta_rate_radps: s_rate / (1.0 - s * s).sqrt(),
    }
}

impl ElasticPlant {
    /// `false` once the state stopped being finite.
    pub fn is_finite(&self) -> bool {
        self.y.is_finite()
    }

    /// Which reel limits act on `command_mps` over the next `period_s`: the lag drive's own
    /// (rate, acceleration), or the motor's torque limit (reported as an acceleration limit).
    pub fn reel_saturation(&self, command_mps: f64, period_s: f64) -> ReelSaturation {
        match self.reel {
            ReelState::Lag(r) => r.saturation(command_mps, period_s),
            ReelState::Motor { drum: d, .. } => {
                let error = command_mps / d.radius_m - self.y.drum_speed_radps;
                let demand = d.kp() * error + d.ki() * self.y.drum_integral_rad;
                ReelSaturation {
                    rate: false,
                    accel: demand.abs() > d.max_torque_nm,
                }
            }
            ReelState::Flight { .. } => ReelSaturation {
                rate: false,
                accel: self
                    .flight
                    .as_ref()
                    .is_some_and(|(f, _)| f.speed_loop().output().saturated),
            },
            _ => ReelSaturation::default(),
        }
    }
}

impl ElasticPlant {
    /// Which limits act on a tension command `tension_n`: the motor's torque limit (reported as
    /// an acceleration limit) when T·r exceeds it; no rate limit.
    pub fn tension_saturation(&self, tension_n: f64) -> ReelSaturation {
        match self.reel {
            ReelState::Motor { drum: d, .. } => ReelSaturation {
                rate: false,
                accel: d.radius_m * tension_n.max(0.0) > d.max_torque_nm,
            },
            _ => ReelSaturation::default(),
        }
    }
}

impl Plant for ElasticPlant {
    fn observe(&self, command: &Command) -> Observation {
        let m = self.measure();
        let sensed = m.sensed(self.p.sensing);
        let period = self.period_hint_s;
        Observation {
            sensors: SensorTruth {
                length_m: m.paid_out_m,
                alpha_rad: sensed.alpha_rad,
                alpha_rate_radps: sensed.alpha_rate_radps,
                orbit_rate_radps: m.orbit_rate_radps,
                true_anomaly_rad: m.true_anomaly_rad,
            },
            length_m: m.paid_out_m,
            alpha_rad: m.line.alpha_rad,
            alpha_rate_radps: m.line.alpha_rate_radps,
            beta_rad: m.line.beta_rad,
            tension_n: m.tension_reel_n,
            reel: match command.tension_n {
                Some(t) => self.tension_saturation(t),
                None => self.reel_saturation(command.rate_mps, period),
            },
            elastic: Some(ElasticObservation {
                range_m: m.range_m,
                tension_tip_n: m.tension_tip_n,
                bowing_m: m.bowing_m,
                alpha_sensed_rad: sensed.alpha_rad,
                reel_rate_mps: m.reel_rate_mps,
                beads: m.beads,
                drive: self.drive_figures(),
            }),
        }
    }

    fn step(&mut self, command: &Command, period_s: f64) {
        self.period_hint_s = period_s;
        self.tension_cmd_n = command.tension_n;
        self.accel_cmd_mps2 = command.accel_mps2;
        // A non-finite state ends the period early; `is_finite` reports it to the loop.
        let _ = ElasticPlant::step(self, command.rate_mps, period_s);
    }

    fn is_finite(&self) -> bool {
        ElasticPlant::is_finite(self)
    }

    fn shape(&self) -> Option<Vec<[f64; 3]>> {
        Some(self.shape_orbit_frame())
    }
}
