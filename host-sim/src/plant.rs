//! The plant: what the closed loop (`crate::sim`) flies, behind one trait ([`Plant`]: observe,
//! then step one control period), and the rigid plant: the paper's equations of motion (Eq. 5,
//! docs/equations.md §2) in f64, with a rate-commanded reel, integrated by fixed-step RK4.
//!
//! The rigid plant's reel imposes l and l̇ (the commanded rate, held over each control period:
//! zero-order hold, as the firmware does), so the state integrated is (θ, l, α, α̇, β, β̇) and
//! Eq. 5a gives the tension the reel must hold. The other plant is the elastic truth model,
//! `crate::elastic`.

use crate::reel::{Reel, ReelSaturation};
use nalgebra::SVector;
use tss_reel::mass::{MassCoefficients, MassModel};
use tss_reel::orbit::Orbit;

/// Rigid plant state: θ (true anomaly), l, α, α̇, β, β̇ (rad, m, rad/s).
pub type State = SVector<f64, 6>;

/// Indices into [`State`].
pub mod ix {
    /// True anomaly θ, rad.
    pub const THETA: usize = 0;
    /// Tether length l, m.
    pub const LENGTH: usize = 1;
    /// In-plane angle α, rad.
    pub const ALPHA: usize = 2;
    /// α̇, rad/s.
    pub const ALPHA_RATE: usize = 3;
    /// Out-of-plane angle β, rad.
    pub const BETA: usize = 4;
    /// β̇, rad/s.
    pub const BETA_RATE: usize = 5;
}

/// The physical system: orbit and masses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidModel {
    /// Orbit of the centre of mass.
    pub orbit: Orbit<f64>,
    /// Masses and tether density.
    pub masses: MassModel<f64>,
}

/// What one RK4 step evaluates over and over and that does not depend on the state it is
/// evaluated at: the orbit's θ̇, θ̈ and μ/R³ on a circular orbit (uniform there: θ̇ = n,
/// θ̈ = 0, R = a), and the mass coefficients of a massless tether (ρ = 0: independent of l).
/// The values are computed by the same expressions as the general case, so a step is
/// bit-for-bit the same with or without them (see the tests).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Frozen {
    /// (θ̇, μ/R³) on a circular orbit (θ̈ = 0 there).
    circular: Option<(f64, f64)>,
    /// The mass coefficients of a massless tether.
    massless: Option<MassCoefficients<f64>>,
}

/// The terms Eqs. 5b and 5c share at one state (see [`RigidModel::terms`]).
#[derive(Clone, Copy, Debug)]
struct Terms {
    /// θ̇, rad/s.
    theta_rate: f64,
    /// θ̈, rad/s².
    theta_accel: f64,
    /// μ/R³, 1/s².
    gg: f64,
    /// θ̇ + α̇, rad/s.
    spin: f64,
    /// (2 + μ3) l̇/l, 1/s.
    stretch: f64,
}

impl Terms {
    /// Eq. 5b: α̈ = −(θ̇ + α̇)[(2 + μ3) l̇/l − 2β̇ tan β] − (3/2)(μ/R³) sin 2α − θ̈, with
    /// `beta_coupling` = 2β̇ tan β (0 in the orbit plane: `stretch − 0` is `stretch` exactly,
    /// so the in-plane shortcut is the same equation bit for bit).
    #[inline]
    fn alpha_accel(&self, alpha: f64, beta_coupling: f64) -> f64 {
        -self.spin * (self.stretch - beta_coupling)
            - 1.5 * self.gg * (2.0 * alpha).sin()
            - self.theta_accel
    }
}

impl RigidModel {
    /// The state-independent quantities of this plant (see [`Frozen`]).
    fn frozen(&self) -> Frozen {
        let circular = (self.orbit.eccentricity == 0.0).then(|| {
            // θ̇ = n(1 + e cos θ)²/(1 − e²)^{3/2} = n and R = a(1 − e²)/(1 + e cos θ) = a
            // exactly when e = 0 (the general expressions multiply and divide by 1).
            let a = self.orbit.semi_major_axis_m;
            (
                self.orbit.mean_motion_radps(),
                self.orbit.mu_m3ps2 / (a * a * a),
            )
        });
        let massless =
            (self.masses.tether_density_kg_per_m == 0.0).then(|| self.masses.coefficients(1.0));
        Frozen { circular, massless }
    }

    /// θ̇, θ̈ and μ/R³ at true anomaly θ.
    #[inline]
    fn orbit_terms(&self, f: &Frozen, theta: f64) -> (f64, f64, f64) {
        match f.circular {
            Some((theta_rate, gg)) => (theta_rate, 0.0, gg),
            None => (
                self.orbit.true_anomaly_rate_radps(theta),
                self.orbit.true_anomaly_accel_radps2(theta),
                self.orbit.gravity_gradient_per_s2(theta), // μ/R³
            ),
        }
    }

    /// The mass coefficients at length `l`.
    #[inline]
    fn mass_terms(&self, f: &Frozen, l: f64) -> MassCoefficients<f64> {
        match f.massless {
            Some(c) => c,
            None => self.masses.coefficients(l),
        }
    }

    /// The terms of Eqs. 5b and 5c at true anomaly θ and length l with the reel at l̇ =
    /// `rate_mps` and α̇ = `alpha_rate`: the orbit's θ̇, θ̈ and μ/R³, the spin θ̇ + α̇ and the
    /// stretch (2 + μ3) l̇/l.
    #[inline]
    fn terms(&self, f: &Frozen, theta: f64, l: f64, alpha_rate: f64, rate_mps: f64) -> Terms {
        let (theta_rate, theta_accel, gg) = self.orbit_terms(f, theta);
        let mu3 = self.mass_terms(f, l).mu3;
        Terms {
            theta_rate,
            theta_accel,
            gg,
            spin: theta_rate + alpha_rate,
            stretch: (2.0 + mu3) * rate_mps / l,
        }
    }

    /// Time derivative of the state with the reel running at `rate_mps` (Eqs. 5b, 5c).
    pub fn derivative(&self, x: &State, rate_mps: f64) -> State {
        self.derivative_with(&self.frozen(), x, rate_mps)
    }

    /// [`RigidModel::derivative`] with the state-independent quantities already evaluated.
    #[inline]
    fn derivative_with(&self, f: &Frozen, x: &State, rate_mps: f64) -> State {
        let (alpha, alpha_rate) = (x[ix::ALPHA], x[ix::ALPHA_RATE]);
        let (beta, beta_rate) = (x[ix::BETA], x[ix::BETA_RATE]);
        let t = self.terms(f, x[ix::THETA], x[ix::LENGTH], alpha_rate, rate_mps);
        if beta == 0.0 && beta_rate == 0.0 {
            // In the orbit plane (β = β̇ = 0, which Eq. 5c keeps): tan β = sin 2β = 0, so the
            // β terms vanish and β̈ = 0.
            let alpha_accel = t.alpha_accel(alpha, 0.0);
            return State::from([t.theta_rate, rate_mps, alpha_rate, alpha_accel, 0.0, 0.0]);
        }
        let alpha_accel = t.alpha_accel(alpha, 2.0 * beta_rate * beta.tan());
        // Eq. 5c
        let (spin, stretch, gg) = (t.spin, t.stretch, t.gg);
        let beta_accel = -stretch * beta_rate
            - 0.5 * spin * spin * (2.0 * beta).sin()
            - 1.5 * gg * alpha.cos().powi(2) * (2.0 * beta).sin();
        State::from([
            t.theta_rate,
            rate_mps,
            alpha_rate,
            alpha_accel,
            beta_rate,
            beta_accel,
        ])
    }

    /// One classical RK4 step of `h_s` seconds with the reel rate held at `rate_mps`.
    pub fn rk4_step(&self, x: &State, rate_mps: f64, h_s: f64) -> State {
        self.rk4_step_varying(x, [rate_mps; 3], h_s)
    }

    /// One classical RK4 step of `h_s` seconds with a reel rate that varies over the step:
    /// `rates_mps` = its values at the start, the middle and the end of the step (each stage
    /// sees the rate at its own time, so l integrates it by Simpson's rule).
    pub fn rk4_step_varying(&self, x: &State, rates_mps: [f64; 3], h_s: f64) -> State {
        let [v0, v1, v2] = rates_mps;
        let f = self.frozen();
        if x[ix::BETA] == 0.0 && x[ix::BETA_RATE] == 0.0 {
            return self.rk4_in_plane(&f, x, rates_mps, h_s);
        }
        let k1 = self.derivative_with(&f, x, v0);
        let k2 = self.derivative_with(&f, &(x + k1 * (0.5 * h_s)), v1);
        let k3 = self.derivative_with(&f, &(x + k2 * (0.5 * h_s)), v1);
        let k4 = self.derivative_with(&f, &(x + k3 * h_s), v2);
        x + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h_s / 6.0)
    }

    /// [`RigidModel::rk4_step_varying`] from a state in the orbit plane (β = β̇ = 0, which every
    /// stage keeps: the β rows of the derivative are 0), on the four in-plane components only.
    /// Each component goes through the general step's operations in the same order, so the
    /// result is the same bit for bit (β and β̇ end at +0, as 0 + 0 does).
    fn rk4_in_plane(&self, f: &Frozen, x: &State, [v0, v1, v2]: [f64; 3], h_s: f64) -> State {
        // (θ̇, l̇, α̇, α̈) at (θ, l, α, α̇) with the reel at `v`: Eq. 5b in the plane.
        let d = |y: [f64; 4], v: f64| -> [f64; 4] {
            let t = self.terms(f, y[0], y[1], y[3], v);
            [t.theta_rate, v, y[3], t.alpha_accel(y[2], 0.0)]
        };
        let stage = |k: [f64; 4], c: f64| -> [f64; 4] {
            [
                x[0] + k[0] * c,
                x[1] + k[1] * c,
                x[2] + k[2] * c,
                x[3] + k[3] * c,
            ]
        };
        let y0 = [x[0], x[1], x[2], x[3]];
        let k1 = d(y0, v0);
        let k2 = d(stage(k1, 0.5 * h_s), v1);
        let k3 = d(stage(k2, 0.5 * h_s), v1);
        let k4 = d(stage(k3, h_s), v2);
        let c = h_s / 6.0;
        let next = |i: usize| x[i] + (k1[i] + k2[i] * 2.0 + k3[i] * 2.0 + k4[i]) * c;
        State::from([next(0), next(1), next(2), next(3), 0.0, 0.0])
    }

    /// The orbit rate θ̇ at true anomaly θ, rad/s (n on a circular orbit, without evaluating
    /// cos θ).
    pub fn orbit_rate_radps(&self, theta: f64) -> f64 {
        if self.orbit.eccentricity == 0.0 {
            self.orbit.mean_motion_radps()
        } else {
            self.orbit.true_anomaly_rate_radps(theta)
        }
    }

    /// Eq. 5a solved for l̈ under a tension T = `tension_n` held by the reel, m/s²:
    /// l̈ = −μ1 l̇²/l + μ2 l(…) − T/m_r, i.e. (T_t(l̈ = 0) − T)/m_r with T_t of
    /// [`RigidModel::tension_n`] (the same expression, so tension and acceleration agree).
    pub fn length_accel_mps2(&self, x: &State, rate_mps: f64, tension_n: f64) -> f64 {
        let m_r = self.masses.coefficients(x[ix::LENGTH]).radial_kg;
        (self.tension_n(x, rate_mps, 0.0) - tension_n) / m_r
    }

    /// One RK4 step of `h_s` seconds with the reel holding the tension `tension_n`: the state
    /// and the reel's rate l̇ = `rate_mps` integrated together (l̇ is a state here, its
    /// derivative Eq. 5a's l̈). Returns the new state and rate.
    pub fn rk4_step_tension(
        &self,
        x: &State,
        rate_mps: f64,
        tension_n: f64,
        h_s: f64,
    ) -> (State, f64) {
        let d = |y: &State, v: f64| {
            (
                self.derivative(y, v),
                self.length_accel_mps2(y, v, tension_n),
            )
        };
        let (k1, a1) = d(x, rate_mps);
        let (k2, a2) = d(&(x + k1 * (0.5 * h_s)), rate_mps + a1 * (0.5 * h_s));
        let (k3, a3) = d(&(x + k2 * (0.5 * h_s)), rate_mps + a2 * (0.5 * h_s));
        let (k4, a4) = d(&(x + k3 * h_s), rate_mps + a3 * h_s);
        (
            x + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h_s / 6.0),
            rate_mps + (a1 + 2.0 * a2 + 2.0 * a3 + a4) * (h_s / 6.0),
        )
    }

    /// Tether tension from Eq. 5a with l̇ = `rate_mps` and l̈ = `accel_mps2`, N:
    /// T_t = m_r[−l̈ − μ1 l̇²/l + μ2 l(β̇² + (θ̇+α̇)² cos²β + (μ/R³)(3cos²α cos²β − 1))].
    /// A value ≤ 0 means a slack tether.
    pub fn tension_n(&self, x: &State, rate_mps: f64, accel_mps2: f64) -> f64 {
        let f = self.frozen();
        let theta = x[ix::THETA];
        let l = x[ix::LENGTH];
        let c = self.mass_terms(&f, l);
        let (theta_rate, _, gg) = self.orbit_terms(&f, theta);
        let spin = theta_rate + x[ix::ALPHA_RATE];
        let beta = x[ix::BETA];
        let cb2 = if beta == 0.0 { 1.0 } else { beta.cos().powi(2) };
        let ca2 = x[ix::ALPHA].cos().powi(2);
        let field = x[ix::BETA_RATE].powi(2) + spin * spin * cb2 + gg * (3.0 * ca2 * cb2 - 1.0);
        c.radial_kg * (-accel_mps2 - c.mu1 * rate_mps * rate_mps / l + c.mu2 * l * field)
    }
}

/// The reel command of one control period (held over it: zero-order hold).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Command {
    /// Commanded reel rate l̇, m/s.
    pub rate_mps: f64,
    /// The acceleration the controller commanded with it, m/s² (the rigid plant's tension of
    /// Eq. 5a under the ideal reel uses it).
    pub accel_mps2: f64,
    /// A tension command instead, N (`Some`: a tension law, `crate::laws`; the rate and
    /// acceleration are then ignored). The reel holds this tension, not a rate: on the rigid
    /// plant l̈ follows from Eq. 5a ([`RigidModel::length_accel_mps2`]), on the elastic plant
    /// the drum's motor applies the torque T·r. A tether only pulls: a negative value acts as 0.
    pub tension_n: Option<f64>,
}

/// What the sensors would read without errors.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorTruth {
    /// The reel encoder's length (the paid-out length), m.
    pub length_m: f64,
    /// α of the sensed direction, rad.
    pub alpha_rad: f64,
    /// α̇ of the sensed direction, rad/s.
    pub alpha_rate_radps: f64,
    /// Orbit rate θ̇, rad/s.
    pub orbit_rate_radps: f64,
    /// True anomaly θ, rad.
    pub true_anomaly_rad: f64,
}

/// What the elastic plant adds to a recorded instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ElasticObservation {
    /// Distance between the end bodies, m.
    pub range_m: f64,
    /// Tension at the sub-satellite, N.
    pub tension_tip_n: f64,
    /// Largest lateral deviation of the tether from the line between the end bodies, m.
    pub bowing_m: f64,
    /// α the controller's sensor sees (line or exit direction), rad.
    pub alpha_sensed_rad: f64,
    /// The reel's actual rate, m/s.
    pub reel_rate_mps: f64,
    /// Number of beads.
    pub beads: usize,
    /// What the flight drive did so far (`reel.model = "flight_drive"` only).
    pub drive: Option<DriveFigures>,
}

/// What the flight drive did over the periods flown: tracking, saturation, tension, faults.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DriveFigures {
    /// Inner ticks flown with the brake released (the tracking statistics' population).
    pub released_ticks: u64,
    /// Inner ticks flown in all.
    pub ticks: u64,
    /// Σ (drum speed − reference)² over the released ticks, (m/s)².
    pub sum_sq_error: f64,
    /// Largest |drum speed − reference| over the released ticks, m/s.
    pub max_error_mps: f64,
    /// Largest |drum speed − law's command| at the end of a law period (the drive's own
    /// ramp included), m/s.
    pub max_period_end_error_mps: f64,
    /// Ticks with the duty saturated.
    pub saturated_ticks: u64,
    /// Least and largest tension at the reel the drive saw, N.
    pub tension_range_n: (f64, f64),
    /// Every drive fault seen (bits of `tss_reel::reel_drive::DriveFaults`).
    pub fault_bits: u16,
    /// The last tick's duty, −1…1 (filled by `ElasticPlant::drive_figures`).
    pub duty: f64,
}

impl DriveFigures {
    /// RMS of the tracking error over the released ticks, m/s.
    pub fn rms_error_mps(&self) -> f64 {
        if self.released_ticks == 0 {
            0.0
        } else {
            (self.sum_sq_error / self.released_ticks as f64).sqrt()
        }
    }

    /// The fraction of ticks with the duty saturated.
    pub fn saturated_fraction(&self) -> f64 {
        if self.ticks == 0 {
            0.0
        } else {
            self.saturated_ticks as f64 / self.ticks as f64
        }
    }
}

/// One instant of a plant, as the loop records it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Observation {
    /// What the sensors see (before their errors).
    pub sensors: SensorTruth,
    /// Paid-out length at the reel, m.
    pub length_m: f64,
    /// α of the line main satellite → sub-satellite, rad (truth).
    pub alpha_rad: f64,
    /// α̇ of that line, rad/s.
    pub alpha_rate_radps: f64,
    /// β of that line, rad.
    pub beta_rad: f64,
    /// Tension at the reel, N.
    pub tension_n: f64,
    /// Which reel limits act on the command of this period.
    pub reel: ReelSaturation,
    /// The elastic plant's extra quantities (`None` for the rigid plant).
    pub elastic: Option<ElasticObservation>,
}

/// A plant the closed loop can fly: observed at the start of each control period (with the
/// command about to be held, for the quantities that depend on it), then stepped over it.
pub trait Plant {
    /// The plant now, under `command` for the period starting now.
    fn observe(&self, command: &Command) -> Observation;
    /// Advances one control period of `period_s` with `command` held.
    fn step(&mut self, command: &Command, period_s: f64);
    /// `false` once the state stopped being finite (a physically impossible run).
    fn is_finite(&self) -> bool;
    /// The tether's shape (node positions relative to the main satellite in the orbit frame
    /// e_r, e_θ, e_h, m), if the plant has one beyond a straight line.
    fn shape(&self) -> Option<Vec<[f64; 3]>> {
        None
    }
    /// The faults the reel's flight speed loop reported since the last call (the union of its
    /// inner ticks'; none for a plant without one), for the outer controller's health.
    fn take_drive_faults(&mut self) -> tss_reel::reel_drive::DriveFaults {
        tss_reel::reel_drive::DriveFaults::NONE
    }
}

/// The rigid plant flying: Eq. 5's state, its reel drive (ideal, or lagging and saturating),
/// the RK4 substeps per period, and whether the reel is locked.
#[derive(Clone, Debug)]
pub struct RigidPlant {
    /// The equations.
    pub model: RigidModel,
    /// The state.
    pub x: State,
    /// The reel drive.
    pub reel: Reel,
    /// RK4 substeps per control period (≥ 1).
    pub substeps: u32,
    /// Reel locked: l̇ = 0 whatever the command.
    pub locked: bool,
    /// The control period the reel's saturation flags are judged over, s.
    pub period_s: f64,
}

impl RigidPlant {
    /// The command the reel applies (zero while locked).
    fn applied(&self, command: &Command) -> Command {
        if self.locked {
            Command::default()
        } else {
            *command
        }
    }
}

impl Plant for RigidPlant {
    fn observe(&self, command: &Command) -> Observation {
        let x = &self.x;
        let c = self.applied(command);
        // The tension of Eq. 5a at the start of the period: with the ideal reel l̈ is the
        // commanded acceleration; with a real drive, its actual rate and acceleration.
        let (tension_n, reel) = if let Some(t) = c.tension_n {
            // A tension-commanded reel holds the commanded tension (≥ 0: a tether only pulls).
            (t.max(0.0), ReelSaturation::default())
        } else if self.reel.is_ideal() {
            let t = self.model.tension_n(x, c.rate_mps, c.accel_mps2);
            (t, ReelSaturation::default())
        } else {
            let rate = c.rate_mps;
            let (v, a) = (
                self.reel.rate_after(rate, 0.0),
                self.reel.accel_after(rate, 0.0),
            );
            let t = self.model.tension_n(x, v, a);
            (t, self.reel.saturation(rate, self.period_s))
        };
        Observation {
            sensors: SensorTruth {
                length_m: x[ix::LENGTH],
                alpha_rad: x[ix::ALPHA],
                alpha_rate_radps: x[ix::ALPHA_RATE],
                orbit_rate_radps: self.model.orbit_rate_radps(x[ix::THETA]),
                true_anomaly_rad: x[ix::THETA].rem_euclid(std::f64::consts::TAU),
            },
            length_m: x[ix::LENGTH],
            alpha_rad: x[ix::ALPHA],
            alpha_rate_radps: x[ix::ALPHA_RATE],
            beta_rad: x[ix::BETA],
            tension_n,
            reel,
            elastic: None,
        }
    }

    fn step(&mut self, command: &Command, period_s: f64) {
        let rate = self.applied(command).rate_mps;
        let h = period_s / f64::from(self.substeps);
        if let Some(t) = self.applied(command).tension_n {
            // Tension-commanded: the reel's rate is a state (kept in `reel.rate_mps`), driven
            // by Eq. 5a under the held tension; the drive's lag and limits do not apply.
            let mut v = self.reel.rate_mps;
            for _ in 0..self.substeps {
                (self.x, v) = self.model.rk4_step_tension(&self.x, v, t.max(0.0), h);
            }
            self.reel.rate_mps = v;
        } else if self.reel.is_ideal() {
            for _ in 0..self.substeps {
                self.x = self.model.rk4_step(&self.x, rate, h);
            }
        } else {
            for k in 0..self.substeps {
                self.x = rk4_with_reel(&self.model, &self.x, &self.reel, rate, f64::from(k) * h, h);
            }
            self.reel.advance(rate, period_s);
        }
    }

    fn is_finite(&self) -> bool {
        self.x.iter().all(|v| v.is_finite()) && self.reel.rate_mps.is_finite()
    }
}

/// One RK4 step of `h_s` seconds starting `t0_s` into the period, with the reel's rate v(t)
/// under the held command (`reel` is the drive at the start of the period): each stage sees
/// the rate at its own time, so l integrates v(t) (Simpson's rule) and Eq. 5b sees l̇ = v(t).
fn rk4_with_reel(
    model: &RigidModel,
    x: &State,
    reel: &Reel,
    command_mps: f64,
    t0_s: f64,
    h_s: f64,
) -> State {
    let v = |t: f64| reel.rate_after(command_mps, t);
    let (v0, v1, v2) = (v(t0_s), v(t0_s + 0.5 * h_s), v(t0_s + h_s));
    model.rk4_step_varying(x, [v0, v1, v2], h_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper_plant() -> RigidModel {
        RigidModel {
            orbit: Orbit::circular(7_078_000.0),
            masses: MassModel::paper(),
        }
    }

    /// Eqs. 5b–5c as written, with every term evaluated (the reference for the shortcuts).
    fn reference_derivative(p: &RigidModel, x: &State, rate_mps: f64) -> State {
        let (theta, l, alpha, alpha_rate, beta, beta_rate) = (x[0], x[1], x[2], x[3], x[4], x[5]);
        let theta_rate = p.orbit.true_anomaly_rate_radps(theta);
        let theta_accel = p.orbit.true_anomaly_accel_radps2(theta);
        let gg = p.orbit.gravity_gradient_per_s2(theta);
        let mu3 = p.masses.coefficients(l).mu3;
        let spin = theta_rate + alpha_rate;
        let stretch = (2.0 + mu3) * rate_mps / l;
        let alpha_accel = -spin * (stretch - 2.0 * beta_rate * beta.tan())
            - 1.5 * gg * (2.0 * alpha).sin()
            - theta_accel;
        let beta_accel = -stretch * beta_rate
            - 0.5 * spin * spin * (2.0 * beta).sin()
            - 1.5 * gg * alpha.cos().powi(2) * (2.0 * beta).sin();
        State::from([
            theta_rate,
            rate_mps,
            alpha_rate,
            alpha_accel,
            beta_rate,
            beta_accel,
        ])
    }

    /// Eq. 5a as written (the reference for the shortcuts).
    fn reference_tension(p: &RigidModel, x: &State, rate: f64, accel: f64) -> f64 {
        let (theta, l) = (x[ix::THETA], x[ix::LENGTH]);
        let c = p.masses.coefficients(l);
        let spin = p.orbit.true_anomaly_rate_radps(theta) + x[ix::ALPHA_RATE];
        let gg = p.orbit.gravity_gradient_per_s2(theta);
        let (cb2, ca2) = (x[ix::BETA].cos().powi(2), x[ix::ALPHA].cos().powi(2));
        let field = x[ix::BETA_RATE].powi(2) + spin * spin * cb2 + gg * (3.0 * ca2 * cb2 - 1.0);
        c.radial_kg * (-accel - c.mu1 * rate * rate / l + c.mu2 * l * field)
    }

    /// The shortcuts of [`Frozen`] (circular orbit, massless tether) and of the in-plane state
    /// give the equations' results bit for bit.
    #[test]
    fn shortcuts_are_bit_identical_to_the_equations() {
        for (ecc, rho) in [(0.0, 0.0), (0.0, 1e-3), (0.01, 0.0), (0.01, 1e-3)] {
            let p = RigidModel {
                orbit: Orbit::elliptic(7_078_000.0, ecc),
                masses: MassModel {
                    tether_density_kg_per_m: rho,
                    ..MassModel::paper()
                },
            };
            let f = p.frozen();
            assert_eq!(f.circular.is_some(), ecc == 0.0);
            assert_eq!(f.massless.is_some(), rho == 0.0);
            for (i, beta, beta_rate) in [
                (0_u32, 0.0, 0.0),
                (1, 0.0, 1e-4),
                (2, 0.03, 0.0),
                (3, -0.2, -1e-4),
            ] {
                let th = 1.3 + 17.0 * f64::from(i);
                let x = State::from([th, 12_345.6, -0.61, 2e-3, beta, beta_rate]);
                for rate in [0.0, 3.2, -7.5] {
                    let fast = p.derivative(&x, rate);
                    let slow = reference_derivative(&p, &x, rate);
                    // Equal as numbers: in the plane the equations give β̈ = −0.0 where the
                    // shortcut gives +0.0, which no sum of the step can tell apart (0 + −0 = 0).
                    for k in 0..6 {
                        assert!(
                            fast[k] == slow[k],
                            "{ecc} {rho} {x} {k}: {} {}",
                            fast[k],
                            slow[k]
                        );
                    }
                    let step = p.rk4_step(&x, rate, 1.0);
                    let h = 1.0;
                    let k1 = slow;
                    let k2 = reference_derivative(&p, &(x + k1 * (0.5 * h)), rate);
                    let k3 = reference_derivative(&p, &(x + k2 * (0.5 * h)), rate);
                    let k4 = reference_derivative(&p, &(x + k3 * h), rate);
                    let expect = x + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
                    for k in 0..6 {
                        assert_eq!(
                            step[k].to_bits(),
                            expect[k].to_bits(),
                            "{ecc} {rho} {x} {k}"
                        );
                    }
                    let varying = p.rk4_step_varying(&x, [rate, 0.5 * rate, 0.25], 1.0);
                    let k1 = reference_derivative(&p, &x, rate);
                    let k2 = reference_derivative(&p, &(x + k1 * 0.5), 0.5 * rate);
                    let k3 = reference_derivative(&p, &(x + k2 * 0.5), 0.5 * rate);
                    let k4 = reference_derivative(&p, &(x + k3), 0.25);
                    let expect = x + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (1.0 / 6.0);
                    for k in 0..6 {
                        assert_eq!(
                            varying[k].to_bits(),
                            expect[k].to_bits(),
                            "{ecc} {rho} {x} {k}"
                        );
                    }
                    assert_eq!(
                        p.orbit_rate_radps(th).to_bits(),
                        p.orbit.true_anomaly_rate_radps(th).to_bits()
                    );
                    let t = p.tension_n(&x, rate, 0.01);
                    let expect = reference_tension(&p, &x, rate, 0.01);
                    assert_eq!(t.to_bits(), expect.to_bits(), "{ecc} {rho} {x}");
                }
            }
        }
    }

    /// Eq. 5a solved for l̈ inverts Eq. 5a's tension, and a reel holding the hanging tether's
    /// tension keeps it hanging at rest (the tension-commanded mode of the tension laws).
    #[test]
    fn a_tension_commanded_reel_is_eq_5a_solved_for_the_acceleration() {
        let rho = MassModel {
            tether_density_kg_per_m: 1e-3,
            ..MassModel::paper()
        };
        for masses in [MassModel::paper(), rho] {
            let p = RigidModel {
                orbit: Orbit::circular(7_078_000.0),
                masses,
            };
            let x = State::from([0.3, 12_000.0, -0.4, 2e-4, 0.0, 0.0]);
            for (v, a) in [(2.0, 0.01), (-3.0, -0.002), (0.0, 0.0)] {
                let t = p.tension_n(&x, v, a);
                let back = p.length_accel_mps2(&x, v, t);
                assert!((back - a).abs() < 1e-12, "{v} {a}: {back}");
            }
            let hanging = State::from([0.0, 30_000.0, 0.0, 0.0, 0.0, 0.0]);
            let t = p.tension_n(&hanging, 0.0, 0.0);
            let (mut y, mut v) = (hanging, 0.0);
            for _ in 0..1000 {
                (y, v) = p.rk4_step_tension(&y, v, t, 1.0);
            }
            assert!((y[ix::LENGTH] - 30_000.0).abs() < 1e-6, "{}", y[ix::LENGTH]);
            assert!(v.abs() < 1e-9 && y[ix::ALPHA].abs() < 1e-12);
            // Less tension: the gravity gradient pays tether out.
            let (mut y, mut v) = (hanging, 0.0);
            for _ in 0..100 {
                (y, v) = p.rk4_step_tension(&y, v, 0.9 * t, 1.0);
            }
            assert!(v > 0.0 && y[ix::LENGTH] > 30_000.0);
        }
    }

    /// Energy under a tension-commanded reel: on a circular orbit with a massless tether, in the
    /// orbit plane, Eqs. 5a–5b conserve H = ½m_r(l̇² + l²α̇²) − (3/2)m_r n² l² cos²α but for the
    /// tension's power: dH/dt = −T l̇. With T held over each period the work is T·Δl exactly,
    /// so H(t) − H(0) + Σ T_k Δl_k vanishes to the integrator's error, whatever T does.
    #[test]
    fn a_tension_commanded_reel_does_exactly_the_work_the_energy_loses() {
        let p = paper_plant();
        let n = p.orbit.mean_motion_radps();
        let m_r = p.masses.coefficients(1.0).radial_kg;
        let energy = |x: &State, v: f64| {
            let (l, a, w) = (x[ix::LENGTH], x[ix::ALPHA], x[ix::ALPHA_RATE]);
            0.5 * m_r * (v * v + l * l * w * w) - 1.5 * m_r * n * n * l * l * a.cos().powi(2)
        };
        let (mut x, mut v) = (State::from([0.0, 2_000.0, -0.3, 1e-4, 0.0, 0.0]), 1.5);
        let h0 = energy(&x, v);
        let mut work = 0.0;
        let mut scale: f64 = h0.abs();
        for k in 0..20_000 {
            // A tension that pays out, brakes and winds in over the run.
            let t = 3.0 * m_r * n * n * x[ix::LENGTH] * (1.0 + 0.5 * (f64::from(k) * 1e-3).sin());
            let l0 = x[ix::LENGTH];
            for _ in 0..4 {
                (x, v) = p.rk4_step_tension(&x, v, t, 0.25);
            }
            work += t * (x[ix::LENGTH] - l0);
            scale = scale.max(work.abs());
        }
        let residual = energy(&x, v) - h0 + work;
        assert!(residual.abs() < 1e-9 * scale, "{residual} of {scale}");
        assert!(work.abs() > 1.0, "the tension did work: {work}");
    }

    #[test]
    fn local_vertical_at_rest_is_an_equilibrium() {
        let p = paper_plant();
        let x = State::from([0.0, 30_000.0, 0.0, 0.0, 0.0, 0.0]);
        let d = p.derivative(&x, 0.0);
        assert_eq!(d[ix::ALPHA_RATE], 0.0);
        assert_eq!(d[ix::BETA_RATE], 0.0);
        // Tension of a hanging 30 km tether: m_r · l · 3n² (massless tether, α = β = 0).
        let n2 = p.orbit.gravity_gradient_per_s2(0.0);
        let t = p.tension_n(&x, 0.0, 0.0);
        let expect = 1e6 / 10_100.0 * 30_000.0 * 3.0 * n2;
        assert!((t - expect).abs() < 1e-9 * expect, "{t} vs {expect}");
    }

    #[test]
    fn small_swing_at_fixed_length_has_the_libration_frequency() {
        // In-plane libration at fixed length: ω = √3 n. Integrate one period and come back.
        let p = paper_plant();
        let n = p.orbit.mean_motion_radps();
        let period = 2.0 * core::f64::consts::PI / (3f64.sqrt() * n);
        let steps = 20_000;
        let h = period / f64::from(steps);
        let mut x = State::from([0.0, 10_000.0, 1e-4, 0.0, 0.0, 0.0]);
        for _ in 0..steps {
            x = p.rk4_step(&x, 0.0, h);
        }
        assert!((x[ix::ALPHA] - 1e-4).abs() < 1e-9, "{}", x[ix::ALPHA]);
        assert!(x[ix::ALPHA_RATE].abs() < 1e-10);
    }

    #[test]
    fn out_of_plane_libration_frequency_is_2n() {
        let p = paper_plant();
        let n = p.orbit.mean_motion_radps();
        let period = 2.0 * core::f64::consts::PI / (2.0 * n);
        let steps = 20_000;
        let h = period / f64::from(steps);
        let mut x = State::from([0.0, 10_000.0, 0.0, 0.0, 1e-4, 0.0]);
        for _ in 0..steps {
            x = p.rk4_step(&x, 0.0, h);
        }
        assert!((x[ix::BETA] - 1e-4).abs() < 1e-9, "{}", x[ix::BETA]);
    }
}
