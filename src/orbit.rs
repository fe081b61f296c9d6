//! The orbit of the system's centre of mass (docs/equations.md §0): Keplerian, circular or elliptic.
//!
//! The controller itself only needs the orbit rate `n` (a sensed input on each step); the
//! stability analysis (Eqs. 6–19) and the simulator need the full elliptic kinematics.

use crate::real::Real;

pub mod libration;

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

/// The orbit's kinematics at one true anomaly, everything an eccentric-orbit step needs
/// (docs/equations.md §0, §16.4), from one sin_cos of θ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitAt<T> {
    /// θ̇, rad/s.
    pub rate_radps: T,
    /// θ̈ = θ̇² h, h = −2e sinθ/(1 + e cosθ), rad/s².
    pub accel_radps2: T,
    /// θ⃛ = θ̇³ (2h² + h′), h′ = −2e(cosθ + e)/(1 + e cosθ)², rad/s³.
    pub jerk_radps3: T,
    /// μ/R³ = θ̇²/(1 + e cosθ), 1/s².
    pub gravity_gradient_per_s2: T,
    /// d(μ/R³)/dt = 1.5 h θ̇ μ/R³, 1/s³.
    pub gravity_gradient_rate_per_s3: T,
}

/// An [`Orbit`] with its constants worked out once (in f64, rounded once), for evaluation at
/// every step: [`PreparedOrbit::at`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedOrbit<T> {
    eccentricity: T,
    /// ω/(1 − e²)^{3/2}, rad/s: θ̇ = this · (1 + e cosθ)².
    rate_scale_radps: T,
}

impl<T: Real> Orbit<T> {
    /// The orbit ready for [`PreparedOrbit::at`].
    pub fn prepare(&self) -> PreparedOrbit<T> {
        let e = self.eccentricity.to_f64();
        let a = self.semi_major_axis_m.to_f64();
        let w = libm::sqrt(self.mu_m3ps2.to_f64() / (a * a * a));
        let k = 1.0 - e * e;
        PreparedOrbit {
            eccentricity: self.eccentricity,
            rate_scale_radps: T::from_f64(w / (k * libm::sqrt(k))),
        }
    }
}

impl<T: Real> PreparedOrbit<T> {
    /// θ̇, θ̈, θ⃛, μ/R³ and its rate at true anomaly θ (rad).
    pub fn at(&self, true_anomaly_rad: T) -> OrbitAt<T> {
        let (s, c) = true_anomaly_rad.sin_cos();
        self.at_sin_cos(s, c)
    }

    /// [`PreparedOrbit::at`] from sinθ and cosθ.
    pub fn at_sin_cos(&self, sin_theta: T, cos_theta: T) -> OrbitAt<T> {
        let e = self.eccentricity;
        let two = T::from_f64(2.0);
        let k = T::ONE + e * cos_theta;
        let rate = self.rate_scale_radps * k * k;
        let h = -two * e * sin_theta / k;
        let h_slope = -two * e * (cos_theta + e) / (k * k);
        let rate2 = rate * rate;
        let gg = rate2 / k;
        OrbitAt {
            rate_radps: rate,
            accel_radps2: rate2 * h,
            jerk_radps3: rate2 * rate * (two * h * h + h_slope),
            gravity_gradient_per_s2: gg,
            gravity_gradient_rate_per_s3: T::from_f64(1.5) * h * rate * gg,
        }
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

    #[test]
    fn prepared_orbit_matches_the_elliptic_kinematics_and_its_derivatives() {
        let o = Orbit::elliptic(10.0e6, 0.3);
        let p = o.prepare();
        for &th in &[0.0, 0.7, 2.0, 3.1, -1.2] {
            let s = p.at(th);
            let rel = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1e-30);
            assert!(rel(s.rate_radps, o.true_anomaly_rate_radps(th)));
            assert!(rel(s.accel_radps2, o.true_anomaly_accel_radps2(th)));
            assert!(rel(
                s.gravity_gradient_per_s2,
                o.gravity_gradient_per_s2(th)
            ));
            // θ⃛ and d(μ/R³)/dt: d/dθ by central difference, times θ̇.
            let h = 1e-5;
            let (m, q) = (p.at(th - h), p.at(th + h));
            let jerk = (q.accel_radps2 - m.accel_radps2) / (2.0 * h) * s.rate_radps;
            let gg_rate =
                (q.gravity_gradient_per_s2 - m.gravity_gradient_per_s2) / (2.0 * h) * s.rate_radps;
            assert!(
                (s.jerk_radps3 - jerk).abs() < 1e-8 * jerk.abs().max(1e-12),
                "{th}"
            );
            assert!(
                (s.gravity_gradient_rate_per_s3 - gg_rate).abs() < 1e-8 * gg_rate.abs().max(1e-18),
                "{th}"
            );
        }
    }
}
