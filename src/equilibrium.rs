//! Existence of the swing equilibria and its extent over the orbit (Eqs. 6–15, Figs. 2–3;
//! docs/equations.md §3).
//!
//! An equilibrium X_e = (α_e, β_e) of Eqs. 5b–5c with l̇/l frozen has sin2β_e = 0 and an in-plane
//! angle given by Eq. 7. It exists only while the *normalised reel rate*
//!
//! ```text
//!     x = (2 + μ3) l̇ / (ω l)
//! ```
//!
//! lies between Retr(e, θ) and Depl(e, θ) (Eqs. 9, 10). Over a whole orbit that becomes
//! max_θ Retr ≤ x ≤ min_θ Depl (Eq. 13), the curves of the paper's Fig. 3, computed here exactly
//! by a bounded, safeguarded Newton iteration on dF1/dθ = 0 (no grid search).
//!
//! For the flight software, [`ExistenceMonitor`] does the expensive part (the extent) once, at
//! configuration, and then answers "does an equilibrium exist for this commanded rate, and by how
//! much" in a handful of multiplications per control step.
//!
//! ```
//! use tss_reel::equilibrium::{extent, Anomaly, ExistenceMonitor};
//! use tss_reel::orbit::Orbit;
//!
//! // Fig. 3 at e = 0.3: 0 < x ≤ 0.96 while deploying, −0.96 ≤ x < 0 while retrieving.
//! let ext = extent(0.3_f64).unwrap();
//! assert!((ext.min_depl.value - 0.96).abs() < 1e-3);
//! assert!((ext.max_retr.value + ext.min_depl.value).abs() < 1e-15);
//!
//! // Onboard: configure once, check every step.
//! let monitor = ExistenceMonitor::from_orbit(&Orbit::circular(7_078_000.0_f32)).unwrap();
//! let c = monitor.check(Anomaly::WholeOrbit, 0.0, 2.0 / 10_000.0).unwrap(); // l̇ = 2 m/s at 10 km
//! assert!(c.exists && c.margin > 0.0);
//! ```

use core::fmt;

use crate::orbit::Orbit;
use crate::real::Real;

/// The constant term of F1 and F2 (Eq. 10): the circular-orbit bound 3/2.
const F_CONST: f64 = 1.5;
/// Coefficient of e·sinθ in F1 (Eq. 10).
const F_SIN: f64 = 2.0;
/// The eccentricity at which the whole-orbit extent vanishes: min F1 = 1.5 − 2e = 0 (docs/equations.md §3).
pub const ECCENTRICITY_LIMIT: f64 = 0.75;

/// Convergence tolerance of the extent root finder on the true anomaly θ*, rad.
///
/// The iteration stops when a step is no larger than this, or (in `f32`) when the step rounds to
/// zero. F is stationary at θ*, so the extremum's *value* is then exact to rounding.
pub const ANOMALY_TOLERANCE_RAD: f64 = 1e-12;
/// Iteration cap of the extent root finder. Bisection alone would shrink the π/2-wide bracket
/// below `f64` resolution in 53 steps; the Newton steps normally converge in 4–6.
pub const MAX_ROOT_ITERATIONS: u32 = 64;
/// θ* in the limit e → 0: the zero of 2cosθ − 1.5 sinθ in [−π, −π/2], atan(4/3) − π, rad
/// (≈ −126.87°).
pub const THETA_STAR_CIRCULAR_RAD: f64 = -2.214_297_435_588_181;

/// Why an analysis could not be done. Names the offending input where there is one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnalysisError {
    /// The named input was NaN or infinite.
    NonFinite(&'static str),
    /// The eccentricity was outside [0, 1).
    EccentricityOutOfRange,
    /// The named input must be strictly positive and was not.
    NotPositive(&'static str),
    /// The bounded root finder reached [`MAX_ROOT_ITERATIONS`] without converging.
    NotConverged,
    /// β is (within `stability::SINGULAR_COS_BETA`) ±π/2, where Eq. 5b's tanβ is singular.
    CoordinateSingularity,
    /// nalgebra's Schur (QR) iteration did not converge within its cap.
    EigenNotConverged,
}

impl fmt::Display for AnalysisError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite(name) => write!(f, "{name} must be finite"),
            Self::EccentricityOutOfRange => write!(f, "eccentricity must be in [0, 1)"),
            Self::NotPositive(name) => write!(f, "{name} must be > 0"),
            Self::NotConverged => write!(f, "extent root finder did not converge"),
            Self::CoordinateSingularity => {
                write!(f, "beta = ±90°: Eq. 5b is singular (tan beta), no Jacobian")
            }
            Self::EigenNotConverged => write!(f, "eigenvalue (Schur) iteration did not converge"),
        }
    }
}

/// `Ok(x)` if `x` is finite, else [`AnalysisError::NonFinite`] naming it.
pub(crate) fn finite<T: Real>(x: T, name: &'static str) -> Result<T, AnalysisError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(AnalysisError::NonFinite(name))
    }
}

/// `Ok(e)` if `e` is a valid eccentricity, in [0, 1).
pub(crate) fn eccentricity<T: Real>(e: T) -> Result<T, AnalysisError> {
    let e = finite(e, "eccentricity")?;
    if e >= T::ZERO && e < T::ONE {
        Ok(e)
    } else {
        Err(AnalysisError::EccentricityOutOfRange)
    }
}

/// F1(θ) = 1.5 + 1.5e cosθ + 2e sinθ + 2e² sinθ cosθ = (1 + e cosθ)(1.5 + 2e sinθ) (Eq. 10).
pub fn f1<T: Real>(e: T, anomaly_rad: T) -> T {
    (T::ONE + e * anomaly_rad.cos())
        * (T::from_f64(F_CONST) + T::from_f64(F_SIN) * e * anomaly_rad.sin())
}

/// F2(θ) = −1.5 − 1.5e cosθ + 2e sinθ + 2e² sinθ cosθ = −F1(−θ) (Eq. 10).
pub fn f2<T: Real>(e: T, anomaly_rad: T) -> T {
    -f1(e, -anomaly_rad)
}

/// g(θ) = 2cosθ − 1.5 sinθ + 2e cos2θ, so that dF1/dθ = e·g(θ). Its zero in the bracket is θ*,
/// also in the limit e → 0 (where F1 is flat).
fn reduced_slope<T: Real>(e: T, anomaly_rad: T) -> T {
    let two = T::from_f64(2.0);
    let (s, c) = (anomaly_rad.sin(), anomaly_rad.cos());
    // cos2θ = c² − s², written out to need one sin and one cos.
    two * c - T::from_f64(F_CONST) * s + two * e * (c.sq() - s.sq())
}

/// dg/dθ = −2 sinθ − 1.5 cosθ − 4e sin2θ.
fn reduced_curvature<T: Real>(e: T, anomaly_rad: T) -> T {
    let two = T::from_f64(2.0);
    let (s, c) = (anomaly_rad.sin(), anomaly_rad.cos());
    -two * s - T::from_f64(F_CONST) * c - T::from_f64(8.0) * e * s * c
}

/// dF1/dθ = e(2cosθ − 1.5 sinθ + 2e cos2θ) (the derivative the paper solves for θ_r).
pub fn f1_derivative<T: Real>(e: T, anomaly_rad: T) -> T {
    e * reduced_slope(e, anomaly_rad)
}

/// dF2/dθ = F1′(−θ) (from F2(θ) = −F1(−θ)).
pub fn f2_derivative<T: Real>(e: T, anomaly_rad: T) -> T {
    f1_derivative(e, -anomaly_rad)
}

/// Depl(e, θ) = F1(θ)/(1 − e²)^{3/2}, the deployment bound of Eq. 9 (Fig. 2a).
pub fn depl<T: Real>(e: T, anomaly_rad: T) -> T {
    f1(e, anomaly_rad) / ecc_factor(e)
}

/// Retr(e, θ) = F2(θ)/(1 − e²)^{3/2}, the retrieval bound of Eq. 9 (Fig. 2b).
pub fn retr<T: Real>(e: T, anomaly_rad: T) -> T {
    f2(e, anomaly_rad) / ecc_factor(e)
}

/// (1 − e²)^{3/2}.
fn ecc_factor<T: Real>(e: T) -> T {
    let k = T::ONE - e.sq();
    k * k.sqrt()
}

/// The normalised reel rate x = (2 + μ3) l̇/(ω l) that Eqs. 9–13 bound.
///
/// `length_rate_ratio_per_s` is l̇/l, 1/s; `mean_motion_radps` is ω = √(μ/a³).
pub fn normalised_rate<T: Real>(mu3: T, length_rate_ratio_per_s: T, mean_motion_radps: T) -> T {
    (T::from_f64(2.0) + mu3) * length_rate_ratio_per_s / mean_motion_radps
}

/// sin2α_e = (2/3)[2e sinθ − x(1 − e²)^{3/2}/(1 + e cosθ)] (Eq. 7), x the normalised rate.
///
/// A value outside [−1, 1] means there is no equilibrium at this θ (Eq. 8).
pub fn sin_two_alpha_e<T: Real>(e: T, anomaly_rad: T, normalised_rate: T) -> T {
    let two = T::from_f64(2.0);
    let (s, c) = (anomaly_rad.sin(), anomaly_rad.cos());
    two / T::from_f64(3.0) * (two * e * s - normalised_rate * ecc_factor(e) / (T::ONE + e * c))
}

/// Station keeping (l̇ = 0): sin2α_e = (4/3)e sinθ (Eq. 7 with x = 0; Eq. 15 is its modulus).
pub fn station_keeping_sin_two_alpha<T: Real>(e: T, anomaly_rad: T) -> T {
    T::from_f64(4.0 / 3.0) * e * anomaly_rad.sin()
}

/// Eq. 15: a station-keeping equilibrium exists at θ iff (4/3)e|sinθ| ≤ 1; over the whole orbit
/// iff e ≤ 0.75.
pub fn station_keeping_exists<T: Real>(e: T, anomaly_rad: T) -> bool {
    station_keeping_sin_two_alpha(e, anomaly_rad).abs() <= T::ONE
}

/// Eq. 9: an equilibrium exists at θ iff Retr(e, θ) ≤ x ≤ Depl(e, θ) (false for NaN input).
pub fn exists_at<T: Real>(e: T, anomaly_rad: T, normalised_rate: T) -> bool {
    retr(e, anomaly_rad) <= normalised_rate && normalised_rate <= depl(e, anomaly_rad)
}

/// The in-plane equilibrium angles of Eq. 7 at one θ.
///
/// sin2α_e = s has two solutions for the tether line in α ∈ (−π/2, π/2] (S2 on the upper side;
/// adding π gives the same line with S2 below, with the same stability).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InPlaneEquilibria<T> {
    /// s = sin2α_e from Eq. 7.
    pub sin_two_alpha: T,
    /// α_e = ½ asin s ∈ [−π/4, π/4], within 45° of the local vertical (cos2α_e ≥ 0), rad.
    pub near_vertical_rad: T,
    /// α_e = ±π/2 − ½ asin s, beyond 45° of the vertical (cos2α_e ≤ 0), rad.
    pub near_horizontal_rad: T,
}

/// The in-plane equilibria for a normalised rate x at θ (Eq. 7), `None` if |sin2α_e| > 1 (Eq. 8)
/// or an input is not finite.
pub fn in_plane_equilibria<T: Real>(
    e: T,
    anomaly_rad: T,
    normalised_rate: T,
) -> Option<InPlaneEquilibria<T>> {
    let s = sin_two_alpha_e(e, anomaly_rad, normalised_rate);
    in_plane_equilibria_from_sin(s)
}

/// The two equilibrium angles for a given sin2α_e (`None` if |s| > 1 or s is NaN).
pub fn in_plane_equilibria_from_sin<T: Real>(sin_two_alpha: T) -> Option<InPlaneEquilibria<T>> {
    if sin_two_alpha.is_nan() || sin_two_alpha.abs() > T::ONE {
        return None;
    }
    let half = T::from_f64(0.5);
    let near_vertical = half * sin_two_alpha.asin();
    let quarter_turn = T::from_f64(core::f64::consts::FRAC_PI_2);
    let side = if sin_two_alpha < T::ZERO {
        -quarter_turn
    } else {
        quarter_turn
    };
    Some(InPlaneEquilibria {
        sin_two_alpha,
        near_vertical_rad: near_vertical,
        near_horizontal_rad: side - near_vertical,
    })
}

/// An extremum over θ of Depl or Retr, with where it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extremum<T> {
    /// The extremal value (min Depl or max Retr).
    pub value: T,
    /// θ*, the true anomaly where it occurs, rad, in [−π, π].
    pub anomaly_rad: T,
    /// Newton/bisection iterations the root finder used.
    pub iterations: u32,
}

/// The whole-orbit extent of the equilibrium conditions at one eccentricity (Eq. 13, Fig. 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extent<T> {
    /// The eccentricity, in [0, 1).
    pub eccentricity: T,
    /// min_θ Depl(e, θ): deployment needs 0 < x ≤ this (Fig. 3a). ≤ 0 for e ≥ 0.75.
    pub min_depl: Extremum<T>,
    /// max_θ Retr(e, θ) = −min Depl, at θ* negated: retrieval needs this ≤ x < 0 (Fig. 3b).
    pub max_retr: Extremum<T>,
}

/// min_θ Depl(e, θ) and where it is (Fig. 3a), by a bounded safeguarded Newton iteration.
///
/// Why the bracket holds the global minimum (docs/equations.md §3): F1(θ) − F1(−θ) = 4e sinθ (1 + e cosθ), so
/// the minimum has sinθ ≤ 0; and F1(θ) − F1(−π − θ) = 2e cosθ (1.5 + 2e sinθ), so for e ≤ 0.75
/// (second factor ≥ 0) it has cosθ ≤ 0, θ* ∈ [−π, −π/2], while for e > 0.75 (min F1 < 0, second
/// factor < 0 at the minimum) cosθ ≥ 0, θ* ∈ [−π/2, 0]. On that bracket g = F1′/e goes from
/// negative to non-negative (g(−π) = 2(e − 1), g(−π/2) = 1.5 − 2e, g(0) = 2 + 2e) with a single
/// zero (checked by dense sampling in the tests for e ∈ [0, 1)). The iteration keeps the
/// bracket, takes the Newton step on g when it falls inside it and bisects otherwise, and stops
/// when a step is ≤ [`ANOMALY_TOLERANCE_RAD`] (or rounds to zero) or after
/// [`MAX_ROOT_ITERATIONS`].
///
/// At e = 0, F1 ≡ 1.5 and θ* is reported as the e → 0 limit, atan2(−4, −3) ≈ −126.87°. At
/// e = 0.75, θ* = −π/2 and the value is 0. Errors: e not finite or outside [0, 1).
pub fn min_depl<T: Real>(e: T) -> Result<Extremum<T>, AnalysisError> {
    let e = eccentricity(e)?;
    let pi = T::from_f64(core::f64::consts::PI);
    let half_pi = T::from_f64(core::f64::consts::FRAC_PI_2);
    let limit = T::from_f64(ECCENTRICITY_LIMIT);
    // Start from a straight line through the root's known values: atan(4/3) − π at e = 0, −π/2
    // at e = 0.75, and ≈ −1.38 as e → 1 (Newton then needs 3–5 steps).
    let (mut lo, mut hi, guess) = if e <= limit {
        let at_zero = T::from_f64(THETA_STAR_CIRCULAR_RAD);
        (-pi, -half_pi, at_zero + (-half_pi - at_zero) * e / limit)
    } else {
        let slope = T::from_f64(0.76);
        (-half_pi, T::ZERO, -half_pi + slope * (e - limit))
    };
    let tol = T::from_f64(ANOMALY_TOLERANCE_RAD);
    let half = T::from_f64(0.5);
    let mut x = guess;
    let mut converged = false;
    let mut iterations = 0;
    while iterations < MAX_ROOT_ITERATIONS {
        iterations += 1;
        let g = reduced_slope(e, x);
        if g == T::ZERO {
            converged = true;
            break;
        }
        // Keep g(lo) < 0 ≤ g(hi).
        if g < T::ZERO {
            lo = x;
        } else {
            hi = x;
        }
        let dg = reduced_curvature(e, x);
        let newton = x - g / dg;
        if (newton - x).abs() <= tol {
            // Converged: the Newton correction is below tolerance (NaN/∞ compare false).
            if newton >= lo && newton <= hi {
                x = newton;
            }
            converged = true;
            break;
        }
        let next = if newton > lo && newton < hi {
            newton
        } else {
            half * (lo + hi)
        };
        let step = (next - x).abs();
        x = next;
        if step <= tol || hi - lo <= tol {
            converged = true;
            break;
        }
    }
    if !converged {
        return Err(AnalysisError::NotConverged);
    }
    Ok(Extremum {
        value: depl(e, x),
        anomaly_rad: x,
        iterations,
    })
}

/// max_θ Retr(e, θ) and where it is (Fig. 3b): −min Depl at θ* negated, since F2(θ) = −F1(−θ).
pub fn max_retr<T: Real>(e: T) -> Result<Extremum<T>, AnalysisError> {
    let m = min_depl(e)?;
    Ok(Extremum {
        value: -m.value,
        anomaly_rad: -m.anomaly_rad,
        iterations: m.iterations,
    })
}

/// Both whole-orbit bounds of Eq. 13 at eccentricity `e` (one root-finder run).
pub fn extent<T: Real>(e: T) -> Result<Extent<T>, AnalysisError> {
    let m = min_depl(e)?;
    Ok(Extent {
        eccentricity: e,
        min_depl: m,
        max_retr: Extremum {
            value: -m.value,
            anomaly_rad: -m.anomaly_rad,
            iterations: m.iterations,
        },
    })
}

/// Where on the orbit the existence condition is checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Anomaly<T> {
    /// At this true anomaly θ, rad (Eq. 9).
    At(T),
    /// At every θ of the orbit (Eq. 13, using the precomputed extent).
    WholeOrbit,
}

/// The reel regime, by the sign of l̇ (Eqs. 11–13, 15).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Regime {
    /// l̇ > 0.
    Deploying,
    /// l̇ = 0.
    StationKeeping,
    /// l̇ < 0.
    Retrieving,
}

/// The answer of [`ExistenceMonitor::check`]: is there an equilibrium for this rate, by how much.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExistenceCheck<T> {
    /// x = (2 + μ3) l̇/(ω l), dimensionless.
    pub normalised_rate: T,
    /// Lower bound on x: Retr(e, θ), or max_θ Retr over the whole orbit.
    pub lower: T,
    /// Upper bound on x: Depl(e, θ), or min_θ Depl over the whole orbit.
    pub upper: T,
    /// Signed margin min(upper − x, x − lower), in units of x: > 0 inside, < 0 outside.
    pub margin: T,
    /// The same margin as a rate ratio l̇/l, 1/s: margin · ω/(2 + μ3).
    pub margin_per_s: T,
    /// `true` iff lower ≤ x ≤ upper (Eq. 9 or 13).
    pub exists: bool,
    /// Deploying, keeping or retrieving, from the sign of x.
    pub regime: Regime,
}

/// The onboard existence check of Eqs. 9 and 13, configured once for an orbit.
///
/// `new` runs the extent root finder once (≤ [`MAX_ROOT_ITERATIONS`] iterations, one sin and
/// one cos each); `check` with [`Anomaly::WholeOrbit`] then costs a few multiplications and
/// comparisons, and with [`Anomaly::At`] one sin and one cos more. No allocation, no panics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExistenceMonitor<T> {
    eccentricity: T,
    mean_motion_radps: T,
    extent: Extent<T>,
}

impl<T: Real> ExistenceMonitor<T> {
    /// Configures the monitor for an orbit of eccentricity `e` and mean motion ω = √(μ/a³).
    ///
    /// Errors: e not in [0, 1), ω not finite or ≤ 0.
    pub fn new(eccentricity: T, mean_motion_radps: T) -> Result<Self, AnalysisError> {
        let w = finite(mean_motion_radps, "mean_motion_radps")?;
        if w <= T::ZERO {
            return Err(AnalysisError::NotPositive("mean_motion_radps"));
        }
        Ok(Self {
            eccentricity,
            mean_motion_radps: w,
            extent: extent(eccentricity)?,
        })
    }

    /// Configures the monitor from an [`Orbit`].
    pub fn from_orbit(orbit: &Orbit<T>) -> Result<Self, AnalysisError> {
        Self::new(orbit.eccentricity, orbit.mean_motion_radps())
    }

    /// The precomputed whole-orbit extent (Fig. 3 at this e).
    pub fn extent(&self) -> &Extent<T> {
        &self.extent
    }

    /// Checks a commanded rate ratio l̇/l (1/s) at the given μ3 against Eq. 9 (at θ) or Eq. 13
    /// (whole orbit). Errors: a non-finite input, named.
    pub fn check(
        &self,
        anomaly: Anomaly<T>,
        mu3: T,
        length_rate_ratio_per_s: T,
    ) -> Result<ExistenceCheck<T>, AnalysisError> {
        let mu3 = finite(mu3, "mu3")?;
        let ratio = finite(length_rate_ratio_per_s, "length_rate_ratio_per_s")?;
        let x = normalised_rate(mu3, ratio, self.mean_motion_radps);
        let (lower, upper) = match anomaly {
            Anomaly::WholeOrbit => (self.extent.max_retr.value, self.extent.min_depl.value),
            Anomaly::At(theta) => {
                let theta = finite(theta, "true_anomaly_rad")?;
                (
                    retr(self.eccentricity, theta),
                    depl(self.eccentricity, theta),
                )
            }
        };
        let margin = (upper - x).min(x - lower);
        let regime = if x > T::ZERO {
            Regime::Deploying
        } else if x < T::ZERO {
            Regime::Retrieving
        } else {
            Regime::StationKeeping
        };
        Ok(ExistenceCheck {
            normalised_rate: x,
            lower,
            upper,
            margin,
            margin_per_s: margin * self.mean_motion_radps / (T::from_f64(2.0) + mu3),
            exists: lower <= x && x <= upper,
            regime,
        })
    }

    /// x = (2 + μ3) l̇/(ω l) (Eq. 7's normalised rate) of a reel at length `length_m` (m)
    /// running at `length_rate_mps` (m/s), with this orbit's ω. Not finite when l = 0.
    #[inline]
    pub fn normalised_rate(&self, mu3: T, length_m: T, length_rate_mps: T) -> T {
        normalised_rate(mu3, length_rate_mps / length_m, self.mean_motion_radps)
    }

    /// [`normalised_rate`](Self::normalised_rate) (Eq. 7's x) from the reduced length
    /// L′ = l/(2 + μ3) (m) the law has already formed: x = l̇/(ω L′), l̇ in m/s, ω in rad/s.
    #[inline]
    pub fn normalised_rate_at_reduced_length(&self, reduced_length_m: T, length_rate_mps: T) -> T {
        length_rate_mps / (reduced_length_m * self.mean_motion_radps)
    }

    /// The signed whole-orbit (Eq. 13) margin of a finite normalised rate `x`:
    /// min(min Depl − x, x − max Retr), ≥ 0 exactly when an equilibrium exists over the whole
    /// orbit.
    ///
    /// The region is symmetric (max Retr = −min Depl exactly, see [`extent`]), so the margin is
    /// min Depl − |x|: bit for bit the same number (min Depl − x for x ≥ 0, x + min Depl for
    /// x < 0), without a comparison.
    #[inline]
    pub fn whole_orbit_margin_of(&self, x: T) -> T {
        self.extent.min_depl.value - x.abs()
    }

    /// The signed whole-orbit (Eq. 13) margin of [`check_rate`](Self::check_rate) alone:
    /// [`whole_orbit_margin_of`](Self::whole_orbit_margin_of) the
    /// [`normalised_rate`](Self::normalised_rate). `None` when l ≤ 0 or x is not finite (where
    /// `check_rate` returns an error).
    #[inline]
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(l > 0)` is meant: it is true for NaN.
    pub fn whole_orbit_margin(&self, mu3: T, length_m: T, length_rate_mps: T) -> Option<T> {
        if !(length_m > T::ZERO) {
            return None;
        }
        let x = self.normalised_rate(mu3, length_m, length_rate_mps);
        if !x.is_finite() {
            return None;
        }
        Some(self.whole_orbit_margin_of(x))
    }

    /// [`check`](Self::check) from the reel's length l (m, > 0) and rate l̇ (m/s).
    pub fn check_rate(
        &self,
        anomaly: Anomaly<T>,
        mu3: T,
        length_m: T,
        length_rate_mps: T,
    ) -> Result<ExistenceCheck<T>, AnalysisError> {
        let l = finite(length_m, "length_m")?;
        if l <= T::ZERO {
            return Err(AnalysisError::NotPositive("length_m"));
        }
        let rate = finite(length_rate_mps, "length_rate_mps")?;
        self.check(anomaly, mu3, rate / l)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::{FRAC_PI_2, PI};

    #[test]
    fn f1_factorised_equals_paper_expanded_form() {
        for &e in &[0.0, 0.1, 0.5, 0.74] {
            for i in 0..=36 {
                let th = -PI + i as f64 * PI / 18.0;
                let (s, c) = (th.sin(), th.cos());
                let paper1 = 1.5 + 1.5 * e * c + 2.0 * e * s + 2.0 * e * e * s * c;
                let paper2 = -1.5 - 1.5 * e * c + 2.0 * e * s + 2.0 * e * e * s * c;
                assert!((f1(e, th) - paper1).abs() < 1e-14);
                assert!((f2(e, th) - paper2).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn hand_worked_values() {
        // e = 0.5, θ = π/2: F1 = (1 + 0)(1.5 + 1) = 2.5; (1 − 0.25)^{3/2} = 0.649 519 052 8;
        // Depl = 3.849 001 795; F2 = −F1(−π/2) = −(1.5 − 1) = −0.5, Retr = −0.769 800 359.
        assert!((f1(0.5, FRAC_PI_2) - 2.5).abs() < 1e-15);
        assert!((depl(0.5, FRAC_PI_2) - 3.849_001_794_597_505).abs() < 1e-12);
        assert!((retr(0.5, FRAC_PI_2) + 0.769_800_358_919_501).abs() < 1e-12);
        // dF1/dθ at θ = 0, e = 0.5: e(2 + 2e) = 0.5·3 = 1.5.
        assert!((f1_derivative(0.5, 0.0) - 1.5).abs() < 1e-15);
        // Eq. 7, e = 0.2, θ = π/2, x = 0.5: (2/3)[0.4 − 0.5·0.96^{1.5}] = −0.046 868 020.
        let s = sin_two_alpha_e(0.2, FRAC_PI_2, 0.5);
        assert!((s - (2.0 / 3.0) * (0.4 - 0.5 * 0.96_f64.powf(1.5))).abs() < 1e-15);
        assert!((s + 0.046_868_020_409_580_08).abs() < 1e-12, "{s}");
        // Circular, x = 0.75: sin2α_e = −0.5 → α_e = −15° or −75°.
        let eq = in_plane_equilibria(0.0, 1.0, 0.75).unwrap();
        assert!((eq.near_vertical_rad + 15f64.to_radians()).abs() < 1e-14);
        assert!((eq.near_horizontal_rad + 75f64.to_radians()).abs() < 1e-14);
        // Eq. 15: e = 0.6, θ = −π/2 → sin2α_e = −0.8.
        assert!((station_keeping_sin_two_alpha(0.6, -FRAC_PI_2) + 0.8).abs() < 1e-15);
        assert!(station_keeping_exists(0.75, FRAC_PI_2));
        assert!(!station_keeping_exists(0.76, FRAC_PI_2));
        // Normalised rate: μ3 = 0, l̇/l = 1e-4 1/s, ω = 1e-3 → 0.2.
        assert!((normalised_rate(0.0, 1e-4, 1e-3) - 0.2).abs() < 1e-15);
    }

    #[test]
    fn extent_at_circular_and_limit_eccentricity() {
        let c = extent(0.0_f64).unwrap();
        assert_eq!(c.min_depl.value, 1.5);
        assert_eq!(c.max_retr.value, -1.5);
        assert!((c.min_depl.anomaly_rad - (-4.0_f64).atan2(-3.0)).abs() < 1e-12);
        let l = extent(0.75_f64).unwrap();
        assert!(l.min_depl.value.abs() < 1e-12, "{:?}", l);
        assert!((l.min_depl.anomaly_rad + FRAC_PI_2).abs() < 1e-6);
        assert!(extent(0.8_f64).unwrap().min_depl.value < 0.0);
    }

    #[test]
    fn extent_rejects_bad_eccentricity() {
        assert_eq!(
            min_depl(1.0_f64),
            Err(AnalysisError::EccentricityOutOfRange)
        );
        assert_eq!(
            min_depl(-0.1_f64),
            Err(AnalysisError::EccentricityOutOfRange)
        );
        assert_eq!(
            min_depl(f64::NAN),
            Err(AnalysisError::NonFinite("eccentricity"))
        );
    }

    #[test]
    fn monitor_whole_orbit_and_at_anomaly() {
        let m = ExistenceMonitor::new(0.0_f64, 1e-3).unwrap();
        // l̇/l = 5e-4 → x = 1.0 < 1.5: margin 0.5, i.e. 0.5·1e-3/2 = 2.5e-4 1/s.
        let c = m.check(Anomaly::WholeOrbit, 0.0, 5e-4).unwrap();
        assert!(c.exists && c.regime == Regime::Deploying);
        assert!((c.margin - 0.5).abs() < 1e-12 && (c.margin_per_s - 2.5e-4).abs() < 1e-15);
        // l̇/l = −1e-3 → x = −2 < −1.5: no equilibrium, margin −0.5.
        let c = m.check(Anomaly::WholeOrbit, 0.0, -1e-3).unwrap();
        assert!(!c.exists && c.regime == Regime::Retrieving);
        assert!((c.margin + 0.5).abs() < 1e-12);
        // Elliptic, at a θ: same as exists_at.
        let m = ExistenceMonitor::new(0.3_f64, 1e-3).unwrap();
        let c = m.check(Anomaly::At(2.0), 0.1, 4e-4).unwrap();
        assert_eq!(c.exists, exists_at(0.3, 2.0, 2.1 * 0.4));
        assert_eq!(
            m.check(Anomaly::WholeOrbit, f64::NAN, 0.0),
            Err(AnalysisError::NonFinite("mu3"))
        );
        assert_eq!(
            m.check_rate(Anomaly::WholeOrbit, 0.0, 0.0, 1.0),
            Err(AnalysisError::NotPositive("length_m"))
        );
        assert_eq!(
            ExistenceMonitor::new(0.1, 0.0),
            Err(AnalysisError::NotPositive("mean_motion_radps"))
        );
    }

    #[test]
    fn f32_extent_matches_f64() {
        for &e in &[0.0, 0.1, 0.3, 0.6, 0.7, 0.75, 0.9] {
            let a = min_depl(e as f32).unwrap();
            let b = min_depl(e).unwrap();
            assert!((a.value as f64 - b.value).abs() < 1e-5, "e = {e}");
            assert!(
                (a.anomaly_rad as f64 - b.anomaly_rad).abs() < 1e-3,
                "e = {e}"
            );
        }
    }

    #[test]
    fn whole_orbit_margin_is_check_rates_margin() {
        let m = ExistenceMonitor::new(0.3_f64, 1.06e-3).unwrap();
        for &(mu3, l, rate) in &[
            (0.0, 1.0, 0.1),
            (0.0, 30_000.0, 0.0),
            (0.05, 12_000.0, 3.0),
            (0.0, 2_000.0, -1.5),
            (0.02, 5.0, -12.0),
            (0.0, 1e-3, 15.0),
        ] {
            let c = m
                .check_rate(Anomaly::WholeOrbit, mu3, l, rate)
                .expect("valid input");
            let margin = m.whole_orbit_margin(mu3, l, rate).expect("valid input");
            assert_eq!(margin, c.margin, "l = {l}, rate = {rate}");
            assert_eq!(margin >= 0.0, c.exists, "l = {l}, rate = {rate}");
        }
        for &(l, rate) in &[
            (0.0, 1.0),
            (-1.0, 1.0),
            (f64::NAN, 1.0),
            (1.0, f64::INFINITY),
        ] {
            assert!(m.whole_orbit_margin(0.0, l, rate).is_none());
            assert!(m.check_rate(Anomaly::WholeOrbit, 0.0, l, rate).is_err());
        }
    }

    #[test]
    fn normalised_rate_from_the_reduced_length_is_eq_7s() {
        let m = ExistenceMonitor::new(0.0_f64, 1.06e-3).unwrap();
        for &(mu3, l, rate) in &[(0.0, 1.0, 0.1), (0.05, 12_000.0, 3.0), (0.2, 5.0, -12.0)] {
            let x = m.normalised_rate(mu3, l, rate);
            let from_reduced = m.normalised_rate_at_reduced_length(l / (2.0 + mu3), rate);
            assert!(
                (from_reduced - x).abs() <= 4.0 * f64::EPSILON * x.abs(),
                "{x} vs {from_reduced}"
            );
        }
    }
}
