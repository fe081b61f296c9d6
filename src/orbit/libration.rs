//! The forced periodic libration of a constant-length tether on an eccentric orbit
//! (docs/equations.md §16).
//!
//! With the true anomaly θ as the independent variable (′ = d/dθ), a constant length and β = 0,
//! Eq. 5b becomes the classic pitch equation of a dumbbell on an elliptic orbit:
//!
//! ```text
//!   (1 + e cosθ) α″ − 2e sinθ (α′ + 1) + 3 sinα cosα = 0
//! ```
//!
//! (θ̈ = −2eθ̇² sinθ/(1 + e cosθ) and μ/R³ = θ̇²/(1 + e cosθ), §0). It has no fixed point for
//! e > 0: the orbit forces the tether to librate. Its odd 2π-periodic solution P(θ) is the
//! station-keeping reference of an eccentric orbit: P ≈ e sinθ to first order in e. [`Libration`]
//! holds P as a sine series, P(θ) = Σ_{k=1..N} b_k sin kθ, its coefficients found once (in f64,
//! when the controller is built) by collocation and Newton's method, continued in e from the
//! circular orbit, to a residual of [`RESIDUAL_TOLERANCE`] (in the units of 3 sinα cosα).

use crate::real::Real;

/// Harmonics of the sine series (the most [`Libration::new`] keeps; trailing ones below
/// [`NEGLIGIBLE_COEFFICIENT_RAD`] are dropped).
pub const MAX_HARMONICS: usize = 24;

/// Largest eccentricity for which [`Libration::new`] looks for the periodic solution. Beyond it
/// the solution's harmonics decay too slowly for [`MAX_HARMONICS`] to meet
/// [`RESIDUAL_TOLERANCE`] (docs/equations.md §16.2).
pub const MAX_ECCENTRICITY: f64 = 0.35;

/// The largest pitch-equation residual accepted at the check points (between the collocation
/// points), dimensionless (the units of 3 sinα cosα, i.e. of α″).
pub const RESIDUAL_TOLERANCE: f64 = 1e-9;

/// A trailing coefficient below this is dropped, rad (well below an f32 ulp of α).
pub const NEGLIGIBLE_COEFFICIENT_RAD: f64 = 1e-11;

/// Newton iterations per continuation step, at most.
#[cfg(not(target_os = "none"))]
const MAX_NEWTON_ITERATIONS: u32 = 30;

/// Continuation steps in e per unit eccentricity (at least one step).
#[cfg(not(target_os = "none"))]
const STEPS_PER_UNIT_ECCENTRICITY: f64 = 40.0;

/// Why no periodic libration was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LibrationError {
    /// e is not finite or not in [0, [`MAX_ECCENTRICITY`]].
    Eccentricity,
    /// Newton's method did not converge, or the solution misses [`RESIDUAL_TOLERANCE`].
    NotConverged,
    /// A bare-metal build (`target_os = "none"`: the firmwares) leaves the solver out
    /// (docs/equations.md §16.2: their flash and stack budgets); it flies P ≡ 0.
    NotInThisBuild,
}

impl core::fmt::Display for LibrationError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Eccentricity => write!(
                f,
                "the eccentricity must be in [0, {MAX_ECCENTRICITY}] for the periodic libration"
            ),
            Self::NotConverged => write!(f, "no periodic libration found for this eccentricity"),
            Self::NotInThisBuild => write!(f, "the periodic libration is not in this build"),
        }
    }
}

/// P and its first three derivatives with respect to θ at one θ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LibrationPoint<T> {
    /// P(θ), rad.
    pub angle_rad: T,
    /// P′(θ) = dP/dθ, dimensionless.
    pub slope: T,
    /// P″(θ).
    pub curvature: T,
    /// P‴(θ).
    pub third: T,
}

/// The odd 2π-periodic solution P(θ) of the pitch equation at one eccentricity (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Libration<T> {
    eccentricity: T,
    /// b_1 … b_N, rad (b_k multiplies sin kθ); zero beyond `harmonics`.
    sine_rad: [T; MAX_HARMONICS],
    harmonics: usize,
    /// The largest residual of the pitch equation found at the check points (in f64).
    residual: f64,
}

impl<T: Real> Libration<T> {
    /// No libration (P ≡ 0), at no eccentricity in particular.
    pub const NONE: Self = Self {
        eccentricity: T::ZERO,
        sine_rad: [T::ZERO; MAX_HARMONICS],
        harmonics: 0,
        residual: 0.0,
    };

    /// Solves for the periodic libration at eccentricity `e` (f64 arithmetic, bounded work:
    /// ≤ 40e + 1 continuation steps of ≤ 30 Newton iterations on a 24 × 24 system).
    ///
    /// At e = 0 the solution is P ≡ 0 (no harmonics). Errors: e outside [0,
    /// [`MAX_ECCENTRICITY`]] or not finite; no convergence to [`RESIDUAL_TOLERANCE`].
    pub fn new(eccentricity: T) -> Result<Self, LibrationError> {
        let e = eccentricity.to_f64();
        if !(e.is_finite() && (0.0..=MAX_ECCENTRICITY).contains(&e)) {
            return Err(LibrationError::Eccentricity);
        }
        Self::solved(eccentricity, e)
    }

    /// A bare-metal build: no solver (see [`LibrationError::NotInThisBuild`]).
    #[cfg(target_os = "none")]
    fn solved(_eccentricity: T, _e: f64) -> Result<Self, LibrationError> {
        Err(LibrationError::NotInThisBuild)
    }

    /// [`Libration::new`] once `e` is checked.
    #[cfg(not(target_os = "none"))]
    fn solved(eccentricity: T, e: f64) -> Result<Self, LibrationError> {
        let (b, residual) = solve_f64(e)?;
        let mut harmonics = MAX_HARMONICS;
        while harmonics > 0 && b[harmonics - 1].abs() < NEGLIGIBLE_COEFFICIENT_RAD {
            harmonics -= 1;
        }
        Ok(Self {
            eccentricity,
            sine_rad: b.map(T::from_f64),
            harmonics,
            residual,
        })
    }

    /// The eccentricity.
    pub fn eccentricity(&self) -> T {
        self.eccentricity
    }

    /// b_1 … b_N, rad: P(θ) = Σ b_k sin kθ.
    pub fn coefficients(&self) -> &[T] {
        self.sine_rad.get(..self.harmonics).unwrap_or(&[])
    }

    /// The largest pitch-equation residual at the check points, at the solution (f64).
    pub fn residual(&self) -> f64 {
        self.residual
    }

    /// P, P′, P″ and P‴ at true anomaly θ (rad): one sin_cos and the angle-addition recurrence
    /// for sin kθ, cos kθ.
    pub fn eval(&self, true_anomaly_rad: T) -> LibrationPoint<T> {
        let (s1, c1) = true_anomaly_rad.sin_cos();
        self.eval_sin_cos(s1, c1)
    }

    /// [`Libration::eval`] from sinθ and cosθ.
    pub fn eval_sin_cos(&self, s1: T, c1: T) -> LibrationPoint<T> {
        let (mut s, mut c) = (s1, c1);
        let mut p = LibrationPoint {
            angle_rad: T::ZERO,
            slope: T::ZERO,
            curvature: T::ZERO,
            third: T::ZERO,
        };
        let mut k = T::ZERO;
        for &b in self.coefficients() {
            k = k + T::ONE;
            let kb = k * b;
            let k2b = k * kb;
            p.angle_rad = p.angle_rad + b * s;
            p.slope = p.slope + kb * c;
            p.curvature = p.curvature - k2b * s;
            p.third = p.third - k * k2b * c;
            (s, c) = (s * c1 + c * s1, c * c1 - s * s1);
        }
        p
    }
}

#[cfg(not(target_os = "none"))]
/// The pitch equation's residual (1 + e cosθ)P″ − 2e sinθ (P′ + 1) + 1.5 sin 2P at θ.
pub fn residual_at(e: f64, b: &[f64], theta: f64) -> f64 {
    let (mut p, mut p1, mut p2) = (0.0, 0.0, 0.0);
    for (i, &bk) in b.iter().enumerate() {
        let k = (i + 1) as f64;
        let (s, c) = libm::sincos(k * theta);
        p += bk * s;
        p1 += k * bk * c;
        p2 -= k * k * bk * s;
    }
    let (s, c) = libm::sincos(theta);
    (1.0 + e * c) * p2 - 2.0 * e * s * (p1 + 1.0) + 1.5 * libm::sin(2.0 * p)
}

/// Collocation on θ_j = πj/(N + 1), j = 1 … N (the solution is odd: sin kθ vanishes at 0 and
/// π), continued from e = 0 in equal steps, Newton at each step. Returns b and the largest
/// residual on a check grid between the collocation points.
#[cfg(not(target_os = "none"))]
fn solve_f64(e: f64) -> Result<([f64; MAX_HARMONICS], f64), LibrationError> {
    const N: usize = MAX_HARMONICS;
    let mut b = [0.0; N];
    if e == 0.0 {
        return Ok((b, 0.0));
    }
    let steps = libm::ceil(e * STEPS_PER_UNIT_ECCENTRICITY).max(1.0) as u32;
    let nodes: [f64; N] =
        core::array::from_fn(|j| core::f64::consts::PI * (j + 1) as f64 / (N + 1) as f64);
    for step in 1..=steps {
        let ei = e * f64::from(step) / f64::from(steps);
        let mut converged = false;
        for _ in 0..MAX_NEWTON_ITERATIONS {
            // J Δb = −R at the nodes.
            let mut jac = [[0.0; N]; N];
            let mut rhs = [0.0; N];
            for (j, &th) in nodes.iter().enumerate() {
                let (s, c) = libm::sincos(th);
                let mut sk = [0.0; N];
                let mut ck = [0.0; N];
                let mut p = 0.0;
                for k in 0..N {
                    let (sn, cs) = libm::sincos((k + 1) as f64 * th);
                    sk[k] = sn;
                    ck[k] = cs;
                    p += b[k] * sn;
                }
                rhs[j] = -residual_at(ei, &b, th);
                let stiff = 3.0 * libm::cos(2.0 * p);
                for k in 0..N {
                    let kf = (k + 1) as f64;
                    jac[j][k] = -(1.0 + ei * c) * kf * kf * sk[k] - 2.0 * ei * s * kf * ck[k]
                        + stiff * sk[k];
                }
            }
            let delta = gauss_solve(jac, rhs).ok_or(LibrationError::NotConverged)?;
            let mut step_size: f64 = 0.0;
            for k in 0..N {
                b[k] += delta[k];
                step_size = step_size.max(delta[k].abs());
            }
            if !step_size.is_finite() {
                return Err(LibrationError::NotConverged);
            }
            if step_size < 1e-14 {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(LibrationError::NotConverged);
        }
    }
    // Check between the nodes (and beyond them, on (π, 2π), by oddness the same).
    let mut worst: f64 = 0.0;
    for j in 0..=4 * (N + 1) {
        let th = core::f64::consts::PI * j as f64 / (4 * (N + 1)) as f64;
        worst = worst.max(residual_at(e, &b, th).abs());
    }
    if worst.is_finite() && worst <= RESIDUAL_TOLERANCE {
        Ok((b, worst))
    } else {
        Err(LibrationError::NotConverged)
    }
}

#[cfg(not(target_os = "none"))]
/// Gaussian elimination with partial pivoting; `None` if the matrix is singular.
fn gauss_solve<const N: usize>(mut a: [[f64; N]; N], mut r: [f64; N]) -> Option<[f64; N]> {
    for col in 0..N {
        let mut pivot = col;
        for row in col + 1..N {
            if a[row][col].abs() > a[pivot][col].abs() {
                pivot = row;
            }
        }
        if a[pivot][col] == 0.0 || a[pivot][col].is_nan() {
            return None;
        }
        a.swap(col, pivot);
        r.swap(col, pivot);
        let (top, rest) = a.split_at_mut(col + 1);
        let pivot_row = top.last()?;
        for (i, row) in rest.iter_mut().enumerate() {
            let f = row[col] / pivot_row[col];
            for (x, p) in row.iter_mut().zip(pivot_row).skip(col) {
                *x -= f * p;
            }
            r[col + 1 + i] -= f * r[col];
        }
    }
    let mut x = [0.0; N];
    for row in (0..N).rev() {
        let mut acc = r[row];
        for k in row + 1..N {
            acc -= a[row][k] * x[k];
        }
        x[row] = acc / a[row][row];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circular_orbit_has_no_libration() {
        let l = Libration::<f64>::new(0.0).unwrap();
        assert!(l.coefficients().is_empty());
        assert_eq!(l.eval(1.0).angle_rad, 0.0);
    }

    #[test]
    fn solves_up_to_the_limit_and_refuses_beyond_it() {
        for i in 0..=35 {
            let e = f64::from(i) / 100.0;
            let l = Libration::<f64>::new(e).unwrap_or_else(|err| panic!("e = {e}: {err}"));
            assert!(l.residual() <= RESIDUAL_TOLERANCE, "e = {e}");
        }
        for e in [0.36, 0.75, -0.1, f64::NAN, f64::INFINITY] {
            assert!(Libration::<f64>::new(e).is_err(), "e = {e}");
        }
    }

    /// The pitch equation as a first-order system in θ: (α, α′).
    fn pitch(e: f64, th: f64, y: [f64; 2]) -> [f64; 2] {
        let (s, c) = th.sin_cos();
        [
            y[1],
            (2.0 * e * s * (y[1] + 1.0) - 1.5 * (2.0 * y[0]).sin()) / (1.0 + e * c),
        ]
    }

    /// Integrates the pitch equation (RK4 in θ, 4000 steps an orbit) for `orbits` orbits from
    /// (α, α′) at θ0 and returns the largest |α − reference(θ)| on the way.
    fn deviation(
        e: f64,
        th0: f64,
        y0: [f64; 2],
        orbits: u32,
        reference: impl Fn(f64) -> f64,
    ) -> f64 {
        let steps = 4000 * orbits;
        let h = 2.0 * core::f64::consts::PI / 4000.0;
        let (mut th, mut y) = (th0, y0);
        let mut worst: f64 = 0.0;
        for _ in 0..steps {
            let k1 = pitch(e, th, y);
            let k2 = pitch(
                e,
                th + h / 2.0,
                [y[0] + h / 2.0 * k1[0], y[1] + h / 2.0 * k1[1]],
            );
            let k3 = pitch(
                e,
                th + h / 2.0,
                [y[0] + h / 2.0 * k2[0], y[1] + h / 2.0 * k2[1]],
            );
            let k4 = pitch(e, th + h, [y[0] + h * k3[0], y[1] + h * k3[1]]);
            for i in 0..2 {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            th += h;
            worst = worst.max((y[0] - reference(th)).abs());
        }
        worst
    }

    #[test]
    fn the_plant_started_on_the_series_stays_on_it_for_an_orbit() {
        // Eq. 5b at constant length, integrated from the reference's own initial condition
        // (α = P(θ0), α′ = P′(θ0)): it follows P to the integrator's and the series' accuracy.
        for (e, tol) in [(0.01, 1e-10), (0.1, 1e-9), (0.2, 1e-8), (0.3, 1e-7)] {
            let l = Libration::<f64>::new(e).unwrap();
            for th0 in [0.0, 1.0, 2.5] {
                let p = l.eval(th0);
                let d = deviation(e, th0, [p.angle_rad, p.slope], 1, |th| l.eval(th).angle_rad);
                assert!(d < tol, "e = {e}, θ0 = {th0}: {d:e}");
            }
        }
    }

    #[test]
    fn the_first_order_libration_errs_as_e_squared() {
        // P ≈ e sinθ to first order (e sinθ solves α″ + 3α = 2e sinθ): started there, the plant
        // leaves it by O(e²); halving e quarters the deviation.
        let dev = |e: f64| deviation(e, 0.0, [0.0, e], 1, |th| e * th.sin());
        let (d1, d2, d3) = (dev(0.04), dev(0.02), dev(0.01));
        for (a, b) in [(d1, d2), (d2, d3)] {
            let ratio = a / b;
            assert!((3.6..4.4).contains(&ratio), "ratio {ratio} ({a:e} / {b:e})");
        }
    }

    #[test]
    fn its_derivatives_are_those_of_the_series() {
        let l = Libration::<f64>::new(0.3).unwrap();
        let h = 1e-5;
        for th in [0.3, 1.7, 4.0] {
            let (m, c, p) = (l.eval(th - h), l.eval(th), l.eval(th + h));
            let d = |a: f64, b: f64| (b - a) / (2.0 * h);
            assert!((c.slope - d(m.angle_rad, p.angle_rad)).abs() < 1e-8);
            assert!((c.curvature - d(m.slope, p.slope)).abs() < 1e-8);
            assert!((c.third - d(m.curvature, p.curvature)).abs() < 1e-7);
        }
    }

    #[test]
    fn it_tends_to_zero_with_e_linearly() {
        // e → 0: P/e → sinθ (the circular reference is the limit).
        for e in [1e-3, 1e-5, 1e-7] {
            let l = Libration::<f64>::new(e).unwrap();
            let b = l.coefficients();
            assert!((b[0] / e - 1.0).abs() < e, "e = {e}: b1 = {}", b[0]);
            assert!(b.iter().skip(1).all(|x| x.abs() <= 1.5 * e * e));
        }
    }

    #[test]
    fn f32_series_matches_f64() {
        let (a, b) = (
            Libration::<f32>::new(0.3).unwrap(),
            Libration::<f64>::new(0.3).unwrap(),
        );
        for i in 0..64 {
            let th = f64::from(i) * 0.1;
            let (x, y) = (a.eval(th as f32), b.eval(th));
            assert!((f64::from(x.angle_rad) - y.angle_rad).abs() < 2e-6, "{th}");
            assert!((f64::from(x.curvature) - y.curvature).abs() < 2e-5, "{th}");
        }
    }
}
