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
//! Classical RK4 ([`integration`]) with the control period split into equal substeps. The
//! substep count is chosen each period from the highest rate of the current configuration: for
//! every segment √(k(1/m_a + 1/m_b)) and its damping C/L(1/m_a + 1/m_b), the drum's coupling
//! through the reel segment, the speed loop's closed-loop poles (a double pole at −ω_b). The
//! step keeps (rate × h) ≤ `courant` (RK4 is stable to 2.8; docs/truth-model.md states what
//! the scenarios' courant = 2 guarantees about convergence). Topology changes (beads entering
//! and leaving, [`feeding::feed`]) and the drum's stick/slip switches happen between substeps.

pub mod environment;
pub mod feeding;
mod frame;
mod initial;
mod integration;
mod params;
pub mod reel_drum;
pub mod tether;

pub use frame::Angles;
pub use params::{
    BodyParams, ElasticError, ElasticParams, FlightParams, InitialConditions, OrbitParams,
    ReelModel, ReelParams, Sensing,
};

use crate::plant::{Command, DriveFigures, ElasticObservation, Observation, Plant, SensorTruth};
use crate::reel::{Reel, ReelSaturation};
use environment::Vec3;
use feeding::{feed, Feed};
use frame::{direction_angles, orbit_frame, orbit_state, plane_basis};
use integration::{motor_torque, ReelDrive, State, Workspace};
use params::check;
use reel_drum::{DrumParams, FlightDrum, Motion};
use tether::Layout;

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
                .max(d.speed_bandwidth_radps)
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
        self.ws.resample_drag();
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
        let drives = [
            self.drive(command, t0, brake),
            self.drive(command, t0 + 0.5 * h, brake),
            self.drive(command, t0 + h, brake),
        ];
        integration::rk4_step(&self.p, &self.layout, &mut self.y, drives, h, &mut self.ws);
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
            match feed(
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

    fn take_drive_faults(&mut self) -> tss_reel::reel_drive::DriveFaults {
        self.flight
            .as_mut()
            .map_or(tss_reel::reel_drive::DriveFaults::NONE, |(f, _)| {
                f.take_faults()
            })
    }

    fn shape(&self) -> Option<Vec<[f64; 3]>> {
        Some(self.shape_orbit_frame())
    }
}
