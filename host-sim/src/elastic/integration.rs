//! The integration of the truth model: its state vector, the time derivative (gravity relative
//! to the reference particle, the tether's segments, drag, the momentum flux at the reel, the
//! drum and its speed loop) and the classical RK4 step over it (see the module doc of `mod.rs`),
//! written for a second-order system: a position's rate at a stage is that stage's velocity, so
//! the step needs the accelerations only (Runge–Kutta–Nyström form of the same method).

use super::environment::{air_velocity_mps, body_drag_n, cylinder_drag_n, Vec3};
use super::params::ElasticParams;
use super::reel_drum::{DrumParams, Motion};
use super::tether::Layout;

/// The integrated state: the reference particle, the reel, and every node relative to the
/// reference (inertial axes).
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

/// The time derivative of a [`State`] but for the positions' rates (the velocities).
#[derive(Clone, Debug, Default)]
pub(super) struct Rates {
    /// The reference particle's acceleration, m/s².
    accel_ref: Vec3,
    /// l̇, m/s.
    paid_out_mps: f64,
    /// ω̇, rad/s².
    drum_accel_radps2: f64,
    /// The speed loop's integrator rate, rad/s.
    drum_integral_radps: f64,
    /// Node accelerations ρ̈_i, m/s².
    accel: Vec<Vec3>,
}

impl State {
    /// `self` = a stage of the RK4 step from `y`, `tau` into it: the velocities and the
    /// first-order quantities advanced by `tau`·`k`, the positions by `tau`·(`y`'s velocities)
    /// plus `c`·(the accelerations `a`). With the stages' rates k_1…k_4, RK4 for ρ̇ = v,
    /// v̇ = a(ρ, v) is ρ_2 = ρ + (h/2)v, ρ_3 = ρ + (h/2)v + (h²/4)a_1, ρ_4 = ρ + hv + (h²/2)a_2,
    /// v_j = v + c_j h a_(j−1).
    fn set_stage(&mut self, y: &State, tau: f64, k: &Rates, c: f64, a: &Rates) {
        self.r_ref = y.r_ref + y.v_ref * tau + a.accel_ref * c;
        self.v_ref = y.v_ref + k.accel_ref * tau;
        self.paid_out_m = y.paid_out_m + k.paid_out_mps * tau;
        self.drum_speed_radps = y.drum_speed_radps + k.drum_accel_radps2 * tau;
        self.drum_integral_rad = y.drum_integral_rad + k.drum_integral_radps * tau;
        let n = y.pos.len();
        self.pos.resize(n, Vec3::zeros());
        self.vel.resize(n, Vec3::zeros());
        let (pos, vel) = (&mut self.pos[..n], &mut self.vel[..n]);
        let (y_pos, y_vel, k, a) = (&y.pos[..n], &y.vel[..n], &k.accel[..n], &a.accel[..n]);
        for i in 0..n {
            pos[i] = y_pos[i] + y_vel[i] * tau + a[i] * c;
            vel[i] = y_vel[i] + k[i] * tau;
        }
    }

    pub(super) fn is_finite(&self) -> bool {
        let v = |x: &Vec3| x.x.is_finite() && x.y.is_finite() && x.z.is_finite();
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
    k: [Rates; 4],
    stage: State,
    /// The nodes' masses (a buffer the plant borrows between steps too).
    pub(super) masses: Vec<f64>,
    drag: HeldDrag,
}

impl Workspace {
    /// A control period starts: the drag is evaluated again at the next step.
    pub(super) fn resample_drag(&mut self) {
        self.drag.stale = true;
    }
}

/// The drag on every node over one control period, N: evaluated at the period's start (the
/// atmosphere sampled there, one `exp` per segment and body) and held over its substeps, or
/// again after a bead entered or left. Drag is a slow external force — at 700 km about 1e-6 N
/// per segment against tensions of 0.1–20 N, changing on the orbit's and the librations' time
/// scales (its rate relative to itself ~1e-3 /s), and damping the tether's modes at ~1e-9 /s —
/// so holding it over a period changes the answers far below the step's own error
/// (docs/truth-model.md §1 "Integration").
#[derive(Clone, Debug, Default)]
struct HeldDrag {
    force_n: Vec<Vec3>,
    /// Evaluate the drag at the next evaluation (a period starts).
    stale: bool,
}

/// The drag on every node at `y`, N: half of each segment's cross-flow drag (at its midpoint,
/// the air co-rotating) on either end, and the end bodies' own.
fn drag_n(p: &ElasticParams, y: &State, force_n: &mut Vec<Vec3>) {
    let t = &p.tether;
    let b = &p.bodies;
    let env = &p.environment;
    let n = y.pos.len();
    force_n.clear();
    force_n.resize(n, Vec3::zeros());
    let cd_d = t.drag_coefficient * t.diameter_m;
    if cd_d > 0.0 {
        for s in 0..n - 1 {
            let d = y.pos[s + 1] - y.pos[s];
            let chord = d.norm();
            if chord == 0.0 {
                continue;
            }
            let u = d * (1.0 / chord);
            let mid = y.r_ref + (y.pos[s] + y.pos[s + 1]) * 0.5;
            let v_air = y.v_ref + (y.vel[s] + y.vel[s + 1]) * 0.5 - air_velocity_mps(&mid);
            let f = cylinder_drag_n(env.air_density_kgpm3(&mid), cd_d * chord, &u, &v_air) * 0.5;
            force_n[s] += f;
            force_n[s + 1] += f;
        }
    }
    for (i, cda) in [(0, b.main_drag_area_m2), (n - 1, b.sub_drag_area_m2)] {
        let r = y.r_ref + y.pos[i];
        let v_air = y.v_ref + y.vel[i] - air_velocity_mps(&r);
        force_n[i] += body_drag_n(env.air_density_kgpm3(&r), cda, &v_air);
    }
}

/// The time derivative of `y` (see the module doc) into `dy` (the positions' rates are the
/// velocities).
fn derivative(
    p: &ElasticParams,
    layout: &Layout,
    y: &State,
    drive: ReelDrive,
    masses: &mut Vec<f64>,
    drag: &mut HeldDrag,
    dy: &mut Rates,
) {
    let t = &p.tether;
    let b = &p.bodies;
    let env = &p.environment;
    layout.masses(t, b.main_initial_kg, b.sub_kg, y.paid_out_m, masses);
    let n = masses.len();
    dy.accel.resize(n, Vec3::zeros());
    let reel_rate = drive.rate_mps(y.drum_speed_radps);
    let g_ref = env.gravity(&y.r_ref);
    dy.accel_ref = g_ref;
    dy.paid_out_mps = reel_rate;
    // Forces: gravity relative to the reference particle's (exact), then the tether, drag and
    // the momentum flux of the paid-out tether; divided by the masses at the end.
    let (pos, vel, accel) = (&y.pos[..n], &y.vel[..n], &mut dy.accel[..n]);
    for ((a, p), m) in accel.iter_mut().zip(pos).zip(masses.iter()) {
        *a = env.gravity_relative(&y.r_ref, &g_ref, p) * *m;
    }
    // Segment s − 1 pulls node s − 1 towards node s and node s back.
    let mut tension_reel = 0.0;
    for s in 1..n {
        let d = pos[s] - pos[s - 1];
        let chord = d.norm();
        if chord == 0.0 {
            continue;
        }
        let u = d * (1.0 / chord);
        let chord_rate = (vel[s] - vel[s - 1]).dot(&u);
        let tension = if s == 1 {
            tension_reel = t.tension_n(
                chord,
                chord_rate,
                layout.reel_segment_m(t, y.paid_out_m),
                reel_rate,
            );
            tension_reel
        } else {
            t.tension_n(chord, chord_rate, t.segment_length_m, 0.0)
        };
        let f = u * tension;
        accel[s - 1] += f;
        accel[s] -= f;
    }
    if env.drag {
        if drag.stale || drag.force_n.len() != n {
            drag_n(p, y, &mut drag.force_n);
            drag.stale = false;
        }
        for (v, f) in dy.accel.iter_mut().zip(&drag.force_n) {
            *v += f;
        }
    }
    // Paying out, ½ρl̇ kg/s of tether joins node 1 at node 0's velocity (winding in, it leaves
    // node 1 for node 0 at node 1's velocity): the receiver's momentum changes by
    // q·(v_donor − v_receiver), the donor's velocity not at all.
    let q = 0.5 * t.density_kg_per_m * reel_rate;
    if q > 0.0 {
        dy.accel[1] += (y.vel[0] - y.vel[1]) * q;
    } else if q < 0.0 {
        dy.accel[0] += (y.vel[1] - y.vel[0]) * (-q);
    }
    for (v, m) in dy.accel.iter_mut().zip(masses.iter()) {
        *v *= 1.0 / *m;
    }
    (dy.drum_accel_radps2, dy.drum_integral_radps) = match drive {
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
    let (masses, drag, stage) = (&mut ws.masses, &mut ws.drag, &mut ws.stage);
    derivative(p, layout, y, drives[0], masses, drag, k1);
    stage.set_stage(y, 0.5 * h, k1, 0.0, k1);
    derivative(p, layout, stage, drives[1], masses, drag, k2);
    stage.set_stage(y, 0.5 * h, k2, 0.25 * h * h, k1);
    derivative(p, layout, stage, drives[1], masses, drag, k3);
    stage.set_stage(y, h, k3, 0.5 * h * h, k2);
    derivative(p, layout, stage, drives[2], masses, drag, k4);
    // ρ ← ρ + hv + (h²/6)(a_1 + a_2 + a_3), v ← v + (h/6)(a_1 + 2a_2 + 2a_3 + a_4).
    let c = h / 6.0;
    let c_pos = h * c;
    let comb = |a: f64, b: f64, d: f64, e: f64| (a + 2.0 * b + 2.0 * d + e) * c;
    y.r_ref += y.v_ref * h + (k1.accel_ref + k2.accel_ref + k3.accel_ref) * c_pos;
    y.v_ref += (k1.accel_ref + (k2.accel_ref + k3.accel_ref) * 2.0 + k4.accel_ref) * c;
    y.paid_out_m += comb(
        k1.paid_out_mps,
        k2.paid_out_mps,
        k3.paid_out_mps,
        k4.paid_out_mps,
    );
    y.drum_speed_radps += comb(
        k1.drum_accel_radps2,
        k2.drum_accel_radps2,
        k3.drum_accel_radps2,
        k4.drum_accel_radps2,
    );
    y.drum_integral_rad += comb(
        k1.drum_integral_radps,
        k2.drum_integral_radps,
        k3.drum_integral_radps,
        k4.drum_integral_radps,
    );
    for i in 0..y.pos.len() {
        let (a1, a2, a3, a4) = (k1.accel[i], k2.accel[i], k3.accel[i], k4.accel[i]);
        y.pos[i] += y.vel[i] * h + (a1 + a2 + a3) * c_pos;
        y.vel[i] += (a1 + (a2 + a3) * 2.0 + a4) * c;
    }
}
