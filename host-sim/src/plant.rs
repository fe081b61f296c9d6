//! The plant: the paper's equations of motion (Eq. 5, SPEC §2) in f64, with a rate-commanded
//! reel, integrated by fixed-step RK4.
//!
//! The reel imposes l and l̇ (the commanded rate, held over each control period: zero-order
//! hold, as the firmware does), so the state integrated is (θ, l, α, α̇, β, β̇) and Eq. 5a gives
//! the tension the reel must hold.

use nalgebra::SVector;
use tss_reel::mass::MassModel;
use tss_reel::orbit::Orbit;

/// Plant state: θ (true anomaly), l, α, α̇, β, β̇ (rad, m, rad/s).
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
pub struct Plant {
    /// Orbit of the centre of mass.
    pub orbit: Orbit<f64>,
    /// Masses and tether density.
    pub masses: MassModel<f64>,
}

impl Plant {
    /// Time derivative of the state with the reel running at `rate_mps` (Eqs. 5b, 5c).
    pub fn derivative(&self, x: &State, rate_mps: f64) -> State {
        let theta = x[ix::THETA];
        let l = x[ix::LENGTH];
        let (alpha, alpha_rate) = (x[ix::ALPHA], x[ix::ALPHA_RATE]);
        let (beta, beta_rate) = (x[ix::BETA], x[ix::BETA_RATE]);
        let theta_rate = self.orbit.true_anomaly_rate_radps(theta);
        let theta_accel = self.orbit.true_anomaly_accel_radps2(theta);
        let gg = self.orbit.gravity_gradient_per_s2(theta); // μ/R³
        let mu3 = self.masses.coefficients(l).mu3;
        let spin = theta_rate + alpha_rate;
        let stretch = (2.0 + mu3) * rate_mps / l;
        // Eq. 5b
        let alpha_accel = -spin * (stretch - 2.0 * beta_rate * beta.tan())
            - 1.5 * gg * (2.0 * alpha).sin()
            - theta_accel;
        // Eq. 5c
        let beta_accel = -stretch * beta_rate
            - 0.5 * spin * spin * (2.0 * beta).sin()
            - 1.5 * gg * alpha.cos().powi(2) * (2.0 * beta).sin();
        State::from([theta_rate, rate_mps, alpha_rate, alpha_accel, beta_rate, beta_accel])
    }

    /// One classical RK4 step of `h_s` seconds with the reel rate held at `rate_mps`.
    pub fn rk4_step(&self, x: &State, rate_mps: f64, h_s: f64) -> State {
        let k1 = self.derivative(x, rate_mps);
        let k2 = self.derivative(&(x + k1 * (0.5 * h_s)), rate_mps);
        let k3 = self.derivative(&(x + k2 * (0.5 * h_s)), rate_mps);
        let k4 = self.derivative(&(x + k3 * h_s), rate_mps);
        x + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h_s / 6.0)
    }

    /// Tether tension from Eq. 5a with l̇ = `rate_mps` and l̈ = `accel_mps2`, N:
    /// T_t = m_r[−l̈ − μ1 l̇²/l + μ2 l(β̇² + (θ̇+α̇)² cos²β + (μ/R³)(3cos²α cos²β − 1))].
    /// A value ≤ 0 means a slack tether.
    pub fn tension_n(&self, x: &State, rate_mps: f64, accel_mps2: f64) -> f64 {
        let theta = x[ix::THETA];
        let l = x[ix::LENGTH];
        let c = self.masses.coefficients(l);
        let spin = self.orbit.true_anomaly_rate_radps(theta) + x[ix::ALPHA_RATE];
        let gg = self.orbit.gravity_gradient_per_s2(theta);
        let cb2 = x[ix::BETA].cos().powi(2);
        let ca2 = x[ix::ALPHA].cos().powi(2);
        let field = x[ix::BETA_RATE].powi(2) + spin * spin * cb2 + gg * (3.0 * ca2 * cb2 - 1.0);
        c.radial_kg * (-accel_mps2 - c.mu1 * rate_mps * rate_mps / l + c.mu2 * l * field)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper_plant() -> Plant {
        Plant {
            orbit: Orbit::circular(7_078_000.0),
            masses: MassModel::paper(),
        }
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
