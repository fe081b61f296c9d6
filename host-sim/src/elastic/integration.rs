//! The integration of the truth model: its state vector, the time derivative (gravity relative
//! to the reference particle, the tether's segments, drag, the momentum flux at the reel, the
//! drum and its speed loop) and the classical RK4 step over it (see the module doc of `mod.rs`).

use super::environment::{
    air_velocity_mps, altitude_m, body_drag_n, cylinder_drag_n, AirSample, Vec3,
};
use super::params::ElasticParams;
use super::reel_drum::{DrumParams, Motion};
use super::tether::Layout;

/// The integrated state: the reference particle, the reel, and every node relative to the
/// reference (inertial axes). Also the shape of its time derivative.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct State {
    /// Reference particle's position R and velocity V (inertial), m, m/s.
    pub(super) r_ref: Vec3,
    pub(super) v_ref: Vec3,
    /// Paid-out unstretched length l_u (the encoder's reading), m.
    pub(super) paid_out_m: f64,
    /// Drum speed ω, rad/s (motor reel only).
    pub(super) drum_speed_radps: f64,
    /// The speed loop's integral of the speed error, rad (motor reel only).
    pub(super) drum_integral_rad: f64,
    /// Node positions ρ_i and velocities ρ̇_i relative to the reference, m, m/s.
    pub(super) pos: Vec<Vec3>,
    pub(super) vel: Vec<Vec3>,
}

impl State {
    /// `self = y + c·k` (same node count).
    pub(super) fn set_stage(&mut self, y: &State, c: f64, k: &State) {
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

    pub(super) fn is_finite(&self) -> bool {
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
pub(super) enum ReelDrive {
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
    pub(super) fn rate_mps(&self, drum_speed_radps: f64) -> f64 {
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
pub(super) fn motor_torque(
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

/// Preallocated buffers of one RK4 step.
#[derive(Clone, Debug, Default)]
pub(super) struct Workspace {
    k: [State; 4],
    stage: State,
    /// The nodes' masses (a buffer the plant borrows between steps too).
    pub(super) masses: Vec<f64>,
    air: AirCache,
}

/// The atmosphere at the segments' midpoints (0…n − 2) and the end bodies (n − 1, n) over one
/// substep: sampled (one `exp` each) at its first stage, the later stages' densities continued
/// from those samples ([`AirSample::density_kgpm3_at`], exact to 2e-15) instead of four
/// `exp` per segment and substep.
#[derive(Clone, Debug, Default)]
struct AirCache {
    samples: Vec<AirSample>,
    /// Take new samples at this evaluation (the substep's first stage).
    resample: bool,
}

impl AirCache {
    /// The density at `r` for the sample slot `k`, kg/m³.
    #[inline]
    fn density_kgpm3(&mut self, k: usize, r: &Vec3) -> f64 {
        let h = altitude_m(r);
        if self.resample {
            self.samples[k] = AirSample::at(h);
            self.samples[k].density_kgpm3
        } else {
            self.samples[k].density_kgpm3_at(h)
        }
    }
}

/// The time derivative of `y` (see the module doc) into `dy`.
fn derivative(
    p: &ElasticParams,
    layout: &Layout,
    y: &State,
    drive: ReelDrive,
    masses: &mut Vec<f64>,
    air: &mut AirCache,
    dy: &mut State,
) {
    let t = &p.tether;
    let b = &p.bodies;
    let env = &p.environment;
    layout.masses(t, b.main_initial_kg, b.sub_kg, y.paid_out_m, masses);
    let n = masses.len();
    air.samples.resize(n + 1, AirSample::default());
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
        let u = d * (1.0 / chord);
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
            let rho_air = air.density_kgpm3(s, &mid);
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
            dy.vel[i] += body_drag_n(air.density_kgpm3(n - 1 + i.min(1), &r), cda, &v_air);
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
        *v *= 1.0 / *m;
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

/// One classical RK4 step of `h` of `y`, the reel driven by `drives` at the step's start,
/// middle and end.
pub(super) fn rk4_step(
    p: &ElasticParams,
    layout: &Layout,
    y: &mut State,
    drives: [ReelDrive; 3],
    h: f64,
    ws: &mut Workspace,
) {
    let [k1, k2, k3, k4] = &mut ws.k;
    ws.air.resample = true;
    derivative(p, layout, y, drives[0], &mut ws.masses, &mut ws.air, k1);
    ws.air.resample = false;
    ws.stage.set_stage(y, 0.5 * h, k1);
    derivative(
        p,
        layout,
        &ws.stage,
        drives[1],
        &mut ws.masses,
        &mut ws.air,
        k2,
    );
    ws.stage.set_stage(y, 0.5 * h, k2);
    derivative(
        p,
        layout,
        &ws.stage,
        drives[1],
        &mut ws.masses,
        &mut ws.air,
        k3,
    );
    ws.stage.set_stage(y, h, k3);
    derivative(
        p,
        layout,
        &ws.stage,
        drives[2],
        &mut ws.masses,
        &mut ws.air,
        k4,
    );
    let c = h / 6.0;
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
}
