//! The orbit of the system's centre of mass (docs/equations.md §0): Keplerian, circular or elliptic.
//!
//! The controller itself only needs the orbit rate `n` (a sensed input on each step); the
//! stability analysis (Eqs. 6–19) and the simulator need the full elliptic kinematics.

use crate::real::Real;

/// Earth's gravitational parameter μ, m³/s² (IERS/WGS-84 value, docs/equations.md §0).
pub const EARTH_MU_M3PS2: f64 = 3.986_004_418e14;

/// A Keplerian orbit of the centre of mass, described by semi-major axis and eccentricity.
///
/// The true anomaly θ is measured from perigee.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit<T> {
    /// Semi-major axis `a`, m.
    pub semi_major_axis_m: T,
    /// Eccentricity `e`, in [0, 1).
    pub eccentricity: T,
    /// Gravitational parameter μ of the central body, m³/s².
    pub mu_m3ps2: T,
}

impl<T: Real> Orbit<T> {
    /// A circular Earth orbit of the given radius.
    pub fn circular(radius_m: T) -> Self {
        Self::elliptic(radius_m, T::ZERO)
    }

    /// An elliptic Earth orbit.
    pub fn elliptic(semi_major_axis_m: T, eccentricity: T) -> Self {
        Self {
            semi_major_axis_m,
            eccentricity,
            mu_m3ps2: T::from_f64(EARTH_MU_M3PS2),
        }
    }

    /// Mean motion ω = √(μ/a³), rad/s (docs/equations.md §0; the ω of Eqs. 7–13).
    pub fn mean_motion_radps(&self) -> T {
        let a = self.semi_major_axis_m;
        (self.mu_m3ps2 / (a * a * a)).sqrt()
    }

    /// `(1 − e²)^{3/2}`, the factor that scales Eqs. 9–13.
    pub fn ecc_factor(&self) -> T {
        let one_minus_e2 = T::ONE - self.eccentricity.sq();
        one_minus_e2 * one_minus_e2.sqrt()
    }

    /// Orbit radius R = a(1 − e²)/(1 + e cosθ), m.
    pub fn radius_m(&self, true_anomaly_rad: T) -> T {
        let e = self.eccentricity;
        self.semi_major_axis_m * (T::ONE - e.sq()) / (T::ONE + e * true_anomaly_rad.cos())
    }

    /// True-anomaly rate θ̇ = ω(1 + e cosθ)²/(1 − e²)^{3/2}, rad/s.
    pub fn true_anomaly_rate_radps(&self, true_anomaly_rad: T) -> T {
        let k = T::ONE + self.eccentricity * true_anomaly_rad.cos();
        self.mean_motion_radps() * k * k / self.ecc_factor()
    }

    /// True-anomaly acceleration θ̈ = −2e θ̇² sinθ/(1 + e cosθ), rad/s².
    pub fn true_anomaly_accel_radps2(&self, true_anomaly_rad: T) -> T {
        let e = self.eccentricity;
        let rate = self.true_anomaly_rate_radps(true_anomaly_rad);
        let two = T::from_f64(2.0);
        -two * e * rate.sq() * true_anomaly_rad.sin() / (T::ONE + e * true_anomaly_rad.cos())
    }

    /// Gravity-gradient coefficient μ/R³, 1/s² (equal to n² on a circular orbit).
    pub fn gravity_gradient_per_s2(&self, true_anomaly_rad: T) -> T {
        let r = self.radius_m(true_anomaly_rad);
        self.mu_m3ps2 / (r * r * r)
    }
}

/// Orbit rate of a circular orbit of the given radius, n = √(μ/R³), rad/s.
pub fn circular_rate_radps<T: Real>(radius_m: T) -> T {
    Orbit::circular(radius_m).mean_motion_radps()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's orbit: R = 7078 km (Section 6).
    const R_PAPER_M: f64 = 7_078_000.0;

    #[test]
    fn circular_rate_of_paper_orbit() {
        // n = sqrt(3.986004418e14 / 7078e3^3) = 1.060 237 e-3 rad/s (period ≈ 98.8 min).
        let n = circular_rate_radps(R_PAPER_M);
        assert!((n - 1.060_237_230_236_363_5e-3).abs() < 1e-15, "n = {n}");
        let period_min = 2.0 * core::f64::consts::PI / n / 60.0;
        assert!((period_min - 98.77).abs() < 0.02, "period {period_min} min");
    }

    #[test]
    fn circular_orbit_kinematics_are_uniform() {
        let o = Orbit::circular(R_PAPER_M);
        for &th in &[0.0, 1.0, 2.0, -2.5] {
            assert!((o.radius_m(th) - R_PAPER_M).abs() < 1e-6);
            assert!((o.true_anomaly_rate_radps(th) - o.mean_motion_radps()).abs() < 1e-15);
            assert_eq!(o.true_anomaly_accel_radps2(th), 0.0);
            assert!((o.gravity_gradient_per_s2(th) - o.mean_motion_radps().powi(2)).abs() < 1e-18);
        }
    }

    #[test]
    fn elliptic_rate_at_apsides_and_accel_is_derivative() {
        let o = Orbit::elliptic(8.0e6, 0.2);
        let w = o.mean_motion_radps();
        // Perigee: θ̇ = ω (1+e)²/(1−e²)^{3/2} = ω·1.44/0.8818163…
        let expect = w * 1.44 / (0.96_f64).powf(1.5);
        assert!((o.true_anomaly_rate_radps(0.0) - expect).abs() < 1e-15);
        // θ̈ = dθ̇/dθ · θ̇, check by central difference.
        let th = 0.7;
        let h = 1e-6;
        let d = (o.true_anomaly_rate_radps(th + h) - o.true_anomaly_rate_radps(th - h)) / (2.0 * h);
        let fd = d * o.true_anomaly_rate_radps(th);
        assert!(
            (o.true_anomaly_accel_radps2(th) - fd).abs() < 1e-6 * fd.abs(),
            "{fd}"
        );
    }
}
