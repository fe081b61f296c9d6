//! Stability of the swing equilibria (Eqs. 16–19, docs/equations.md §4) and of the closed loop (Eq. 28).
//!
//! About an equilibrium (α_e, β_e) with β_e ∈ {0, ±π/2} and l̇/l frozen, Eqs. 5b–5c linearise
//! into two decoupled second-order modes (Eq. 17, without the paper's stray θ̇ — docs/equations.md §9.2):
//!
//! ```text
//!     in-plane:      λ² + (2+μ3)(l̇/l) λ + (3μ/R³) cos2α_e                    = 0
//!     out-of-plane:  λ² + (2+μ3)(l̇/l) λ + cos2β_e (θ̇² + 3μ cos²α_e / R³)     = 0
//! ```
//!
//! with roots λ = −(1+μ3/2) l̇/l ± √D (Eq. 18) and discriminants D1, D2 (Eq. 19). For any other
//! state — off equilibrium, or β not in that set — [`jacobian`] gives the full 4×4 Jacobian of
//! Eqs. 5b–5c and [`jacobian_eigenvalues`] its eigenvalues through nalgebra's Schur
//! decomposition; at the equilibria the two agree (tests: 1e-9 relative in `f64`).
//!
//! ```
//! use tss_reel::stability::{closed_loop_poles, equilibrium_stability, FrozenCoefficients, Verdict};
//!
//! // Deploying at l̇/l = 1e-4 1/s on a circular orbit with n = 1.06e-3 rad/s, massless tether,
//! // hanging at α_e = −10° in the orbit plane: both modes are damped.
//! let n = 1.06e-3_f64;
//! let c = FrozenCoefficients {
//!     anomaly_rate_radps: n,
//!     anomaly_accel_radps2: 0.0,
//!     gravity_gradient_per_s2: n * n,
//!     length_rate_ratio_per_s: 1e-4,
//!     mu3: 0.0,
//! };
//! let s = equilibrium_stability(&c, -10f64.to_radians(), 0.0).unwrap();
//! assert_eq!(s.verdict, Verdict::Stable);
//!
//! // The paper's gains (Section 6): ω0 = π·10⁻³ rad/s, ζ ≈ 0.907.
//! let cl = closed_loop_poles(0.0057_f64, 9.8696e-6).unwrap();
//! assert!((cl.natural_frequency_radps - core::f64::consts::PI * 1e-3).abs() < 1e-8);
//! assert!((cl.damping_ratio - 0.907).abs() < 1e-3);
//! ```

use nalgebra::{Matrix4, RealField, Schur};

pub use crate::equilibrium::AnalysisError;
use crate::equilibrium::{eccentricity, finite};
use crate::mass::MassModel;
use crate::orbit::Orbit;
use crate::real::Real;

/// Relative tolerance of the verdicts: a mode whose largest real part is within
/// ± this × (its largest |λ|) of zero is [`Verdict::Marginal`].
///
/// Rounding in the closed form is a few ulp of |λ| (the roots are computed without
/// cancellation), so 1e-6 is safely above `f32` noise and far below any physical damping: the
/// slowest case of interest, deploying at 0.1 m/s at 30 km, has Re λ/|λ| ≈ 2e-3.
pub const MARGINAL_RELATIVE_TOLERANCE: f64 = 1e-6;

/// |cosβ| below which Eq. 5b is treated as singular (its tanβ term): β within ≈ 0.057° of ±90°.
pub const SINGULAR_COS_BETA: f64 = 1e-3;

/// Iteration cap of nalgebra's Schur (implicit double-shift QR) iteration on the 4×4 Jacobian.
pub const MAX_SCHUR_ITERATIONS: usize = 256;

/// A complex number, for characteristic roots and eigenvalues, 1/s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Complex<T> {
    /// Real part (decay rate if negative, growth rate if positive), 1/s.
    pub re: T,
    /// Imaginary part (angular frequency of the oscillation), rad/s.
    pub im: T,
}

impl<T: Real> Complex<T> {
    /// |z|.
    pub fn norm(&self) -> T {
        (self.re.sq() + self.im.sq()).sqrt()
    }
}

/// The stability of a mode or of a set of roots.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Verdict {
    /// Every root has Re λ < −tol·|λ|max: asymptotically stable.
    Stable,
    /// The largest Re λ is within ±tol·|λ|max of zero: the linear analysis cannot decide
    /// (purely imaginary roots: station keeping).
    Marginal,
    /// Some root has Re λ > tol·|λ|max: unstable.
    Unstable,
}

/// The verdict on a set of roots with relative tolerance `rel_tol` (see
/// [`MARGINAL_RELATIVE_TOLERANCE`]). An empty set or NaN roots are `Unstable` (fail safe).
pub fn classify<T: Real>(roots: &[Complex<T>], rel_tol: T) -> Verdict {
    let mut max_re: Option<T> = None;
    let mut scale = T::ZERO;
    for r in roots {
        if !(r.re.is_finite() && r.im.is_finite()) {
            return Verdict::Unstable;
        }
        max_re = Some(match max_re {
            Some(m) => m.max(r.re),
            None => r.re,
        });
        scale = scale.max(r.norm());
    }
    let Some(max_re) = max_re else {
        return Verdict::Unstable;
    };
    let tol = rel_tol * scale;
    if max_re > tol {
        Verdict::Unstable
    } else if max_re < -tol {
        Verdict::Stable
    } else {
        Verdict::Marginal
    }
}

/// The two roots of λ² + 2hλ + c = 0 and what they say.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeRoots<T> {
    /// λ1 = −h + √D and λ2 = −h − √D (for D < 0: +i first), 1/s.
    pub roots: [Complex<T>; 2],
    /// h, half the damping coefficient: (1 + μ3/2) l̇/l for Eq. 17, k1/2 for Eq. 28, 1/s.
    pub half_damping_per_s: T,
    /// c, the stiffness, 1/s².
    pub stiffness_per_s2: T,
    /// D = h² − c (D1 or D2 of Eq. 19), 1/s²: ≥ 0 real roots, < 0 a complex pair.
    pub discriminant_per_s2: T,
    /// The verdict with [`MARGINAL_RELATIVE_TOLERANCE`].
    pub verdict: Verdict,
}

/// Roots of λ² + 2hλ + c = 0 (Eq. 18 form), computed without cancellation: for real roots the
/// larger-magnitude one is −h − sign(h)√D and the other is c divided by it (Vieta).
pub fn quadratic_roots<T: Real>(half_damping_per_s: T, stiffness_per_s2: T) -> ModeRoots<T> {
    let h = half_damping_per_s;
    let c = stiffness_per_s2;
    let d = h.sq() - c;
    let roots = if d >= T::ZERO {
        let sq = d.sqrt();
        let big = if h >= T::ZERO { -h - sq } else { -h + sq };
        let small = if big != T::ZERO { c / big } else { T::ZERO };
        // Order: λ1 = −h + √D (the larger), λ2 = −h − √D.
        let (l1, l2) = if big >= small {
            (big, small)
        } else {
            (small, big)
        };
        [
            Complex {
                re: l1,
                im: T::ZERO,
            },
            Complex {
                re: l2,
                im: T::ZERO,
            },
        ]
    } else {
        let w = (-d).sqrt();
        [Complex { re: -h, im: w }, Complex { re: -h, im: -w }]
    };
    ModeRoots {
        roots,
        half_damping_per_s: h,
        stiffness_per_s2: c,
        discriminant_per_s2: d,
        verdict: classify(&roots, T::from_f64(MARGINAL_RELATIVE_TOLERANCE)),
    }
}

/// The coefficients of Eqs. 5b–5c that the analysis holds frozen at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrozenCoefficients<T> {
    /// θ̇, the true-anomaly rate, rad/s (n on a circular orbit).
    pub anomaly_rate_radps: T,
    /// θ̈, rad/s² (0 on a circular orbit). Shifts the equilibrium, not the linearisation.
    pub anomaly_accel_radps2: T,
    /// μ/R³, 1/s² (n² on a circular orbit).
    pub gravity_gradient_per_s2: T,
    /// l̇/l, 1/s (> 0 deploying, < 0 retrieving, 0 station keeping).
    pub length_rate_ratio_per_s: T,
    /// μ3 (docs/equations.md §1), dimensionless.
    pub mu3: T,
}

impl<T: Real> FrozenCoefficients<T> {
    /// The coefficients at true anomaly θ of `orbit`, tether length l and rate l̇, with μ3 from
    /// `mass`. Errors name the input: non-finite values, e ∉ [0, 1), a ≤ 0, l ≤ 0, m01 ≤ 0,
    /// m2 ≤ 0, ρ < 0, or a tether heavier than the main satellite (m1 = m01 − ρl ≤ 0).
    pub fn from_orbit(
        orbit: &Orbit<T>,
        anomaly_rad: T,
        mass: &MassModel<T>,
        length_m: T,
        length_rate_mps: T,
    ) -> Result<Self, AnalysisError> {
        eccentricity(orbit.eccentricity)?;
        positive(orbit.semi_major_axis_m, "semi_major_axis_m")?;
        positive(orbit.mu_m3ps2, "mu_m3ps2")?;
        let theta = finite(anomaly_rad, "true_anomaly_rad")?;
        positive(mass.main_initial_kg, "main_initial_kg")?;
        positive(mass.sub_kg, "sub_kg")?;
        let rho = finite(mass.tether_density_kg_per_m, "tether_density_kg_per_m")?;
        if rho < T::ZERO {
            return Err(AnalysisError::NotPositive("tether_density_kg_per_m"));
        }
        let l = positive(length_m, "length_m")?;
        let rate = finite(length_rate_mps, "length_rate_mps")?;
        let coeffs = mass.coefficients(l);
        positive(coeffs.main_kg, "main_kg (m01 - rho*l)")?;
        let mu3 = finite(coeffs.mu3, "mu3")?;
        Ok(Self {
            anomaly_rate_radps: orbit.true_anomaly_rate_radps(theta),
            anomaly_accel_radps2: orbit.true_anomaly_accel_radps2(theta),
            gravity_gradient_per_s2: orbit.gravity_gradient_per_s2(theta),
            length_rate_ratio_per_s: rate / l,
            mu3,
        })
    }

    /// (2 + μ3) l̇/l, the damping coefficient of Eqs. 5b–5c and 17, 1/s.
    pub fn damping_per_s(&self) -> T {
        (T::from_f64(2.0) + self.mu3) * self.length_rate_ratio_per_s
    }

    /// sin2α_e of the in-plane equilibrium at β = 0 (Eq. 6):
    /// −(2R³/3μ)[θ̇ (2+μ3) l̇/l + θ̈]. Equal to Eq. 7 (tests); outside [−1, 1] there is none.
    pub fn equilibrium_sin_two_alpha(&self) -> T {
        let k = self.damping_per_s();
        -T::from_f64(2.0) * (self.anomaly_rate_radps * k + self.anomaly_accel_radps2)
            / (T::from_f64(3.0) * self.gravity_gradient_per_s2)
    }

    fn check(&self) -> Result<(), AnalysisError> {
        finite(self.anomaly_rate_radps, "anomaly_rate_radps")?;
        finite(self.anomaly_accel_radps2, "anomaly_accel_radps2")?;
        finite(self.gravity_gradient_per_s2, "gravity_gradient_per_s2")?;
        finite(self.length_rate_ratio_per_s, "length_rate_ratio_per_s")?;
        finite(self.mu3, "mu3")?;
        Ok(())
    }
}

fn positive<T: Real>(x: T, name: &'static str) -> Result<T, AnalysisError> {
    let x = finite(x, name)?;
    if x > T::ZERO {
        Ok(x)
    } else {
        Err(AnalysisError::NotPositive(name))
    }
}

/// D1 = [(1 + μ3/2) l̇/l]² − (3μ/R³) cos2α_e (Eq. 19), 1/s².
pub fn d1<T: Real>(c: &FrozenCoefficients<T>, alpha_e_rad: T) -> T {
    in_plane(c, alpha_e_rad).discriminant_per_s2
}

/// D2 = [(1 + μ3/2) l̇/l]² − cos2β_e (θ̇² + 3μ cos²α_e/R³) (Eq. 19), 1/s².
pub fn d2<T: Real>(c: &FrozenCoefficients<T>, alpha_e_rad: T, beta_e_rad: T) -> T {
    out_of_plane(c, alpha_e_rad, beta_e_rad).discriminant_per_s2
}

fn half_damping<T: Real>(c: &FrozenCoefficients<T>) -> T {
    (T::ONE + T::from_f64(0.5) * c.mu3) * c.length_rate_ratio_per_s
}

fn in_plane<T: Real>(c: &FrozenCoefficients<T>, alpha_e_rad: T) -> ModeRoots<T> {
    let two_alpha = T::from_f64(2.0) * alpha_e_rad;
    quadratic_roots(
        half_damping(c),
        T::from_f64(3.0) * c.gravity_gradient_per_s2 * two_alpha.cos(),
    )
}

fn out_of_plane<T: Real>(c: &FrozenCoefficients<T>, alpha_e_rad: T, beta_e_rad: T) -> ModeRoots<T> {
    let two = T::from_f64(2.0);
    let stiffness = (two * beta_e_rad).cos()
        * (c.anomaly_rate_radps.sq()
            + T::from_f64(3.0) * c.gravity_gradient_per_s2 * alpha_e_rad.cos().sq());
    quadratic_roots(half_damping(c), stiffness)
}

/// The linear stability of one equilibrium (Eqs. 17–19).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EquilibriumStability<T> {
    /// The in-plane (α) mode: roots λ1,2 and D1.
    pub in_plane: ModeRoots<T>,
    /// The out-of-plane (β) mode: roots λ3,4 and D2.
    pub out_of_plane: ModeRoots<T>,
    /// The worse of the two verdicts.
    pub verdict: Verdict,
}

/// The characteristic roots, D1, D2 and verdicts at the equilibrium (α_e, β_e) (Eqs. 17–19).
///
/// Valid at equilibria, where β_e ∈ {0, ±π/2} and α_e solves Eq. 7 (see
/// [`FrozenCoefficients::equilibrium_sin_two_alpha`]); the formulas are evaluated for whatever
/// angles are given. The paper's conclusions (§4) follow: retrieving (l̇ < 0) is unstable;
/// deploying is stable iff cos2α_e > 0 and cos2β_e > 0; station keeping is marginal.
/// Errors: a non-finite input, named.
pub fn equilibrium_stability<T: Real>(
    c: &FrozenCoefficients<T>,
    alpha_e_rad: T,
    beta_e_rad: T,
) -> Result<EquilibriumStability<T>, AnalysisError> {
    c.check()?;
    finite(alpha_e_rad, "alpha_e_rad")?;
    finite(beta_e_rad, "beta_e_rad")?;
    let a = in_plane(c, alpha_e_rad);
    let b = out_of_plane(c, alpha_e_rad, beta_e_rad);
    Ok(EquilibriumStability {
        in_plane: a,
        out_of_plane: b,
        verdict: a.verdict.max(b.verdict),
    })
}

/// The closed loop of the range-rate law, δ̈ + k1 δ̇ + k2 δ = 0 (Eq. 28), as a design check.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosedLoop<T> {
    /// The poles of λ² + k1 λ + k2 = 0 (h = k1/2, c = k2), and their verdict.
    pub poles: ModeRoots<T>,
    /// ω0 = √k2, rad/s.
    pub natural_frequency_radps: T,
    /// ζ = k1/(2√k2).
    pub damping_ratio: T,
}

/// Poles, natural frequency and damping ratio of Eq. 28 for gains k1 (1/s) and k2 (1/s²).
///
/// Errors: k1 not finite, k2 not finite or ≤ 0 (no oscillator, ω0 undefined).
pub fn closed_loop_poles<T: Real>(
    k1_per_s: T,
    k2_per_s2: T,
) -> Result<ClosedLoop<T>, AnalysisError> {
    let k1 = finite(k1_per_s, "k1")?;
    let k2 = positive(k2_per_s2, "k2")?;
    let w0 = k2.sqrt();
    Ok(ClosedLoop {
        poles: quadratic_roots(T::from_f64(0.5) * k1, k2),
        natural_frequency_radps: w0,
        damping_ratio: k1 / (T::from_f64(2.0) * w0),
    })
}

/// The swing state about which Eqs. 5b–5c are evaluated or linearised.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwingState<T> {
    /// α, rad.
    pub alpha_rad: T,
    /// α̇, rad/s.
    pub alpha_rate_radps: T,
    /// β, rad.
    pub beta_rad: T,
    /// β̇, rad/s.
    pub beta_rate_radps: T,
}

impl<T: Real> SwingState<T> {
    /// A state at rest relative to the orbit frame (α̇ = β̇ = 0).
    pub fn at_rest(alpha_rad: T, beta_rad: T) -> Self {
        Self {
            alpha_rad,
            alpha_rate_radps: T::ZERO,
            beta_rad,
            beta_rate_radps: T::ZERO,
        }
    }
}

/// Shared pieces of Eqs. 5b–5c at one state, after the singularity check.
struct Terms<T> {
    w: T,
    k: T,
    g: T,
    tan_b: T,
    sec2_b: T,
    sin2a: T,
    cos2a: T,
    cos_a_sq: T,
    sin2b: T,
    cos2b: T,
}

fn terms<T: Real>(c: &FrozenCoefficients<T>, x: &SwingState<T>) -> Result<Terms<T>, AnalysisError> {
    c.check()?;
    finite(x.alpha_rad, "alpha_rad")?;
    finite(x.alpha_rate_radps, "alpha_rate_radps")?;
    finite(x.beta_rad, "beta_rad")?;
    finite(x.beta_rate_radps, "beta_rate_radps")?;
    let two = T::from_f64(2.0);
    let cos_b = x.beta_rad.cos();
    if cos_b.abs() < T::from_f64(SINGULAR_COS_BETA) {
        return Err(AnalysisError::CoordinateSingularity);
    }
    let cos_a = x.alpha_rad.cos();
    Ok(Terms {
        w: c.anomaly_rate_radps + x.alpha_rate_radps,
        k: c.damping_per_s(),
        g: c.gravity_gradient_per_s2,
        tan_b: x.beta_rad.sin() / cos_b,
        sec2_b: T::ONE / cos_b.sq(),
        sin2a: (two * x.alpha_rad).sin(),
        cos2a: (two * x.alpha_rad).cos(),
        cos_a_sq: cos_a.sq(),
        sin2b: (two * x.beta_rad).sin(),
        cos2b: (two * x.beta_rad).cos(),
    })
}

/// (α̈, β̈) from Eqs. 5b and 5c, rad/s², with l̇/l and the orbit terms frozen in `c`:
///
/// α̈ = −(θ̇+α̇)[(2+μ3) l̇/l − 2β̇ tanβ] − (3μ/2R³) sin2α − θ̈,
/// β̈ = −(2+μ3)(l̇/l) β̇ − ½(θ̇+α̇)² sin2β − (3μ/2R³) cos²α sin2β.
///
/// Zero at an equilibrium. Errors: a non-finite input, or |cosβ| < [`SINGULAR_COS_BETA`].
pub fn swing_accelerations<T: Real>(
    c: &FrozenCoefficients<T>,
    x: &SwingState<T>,
) -> Result<(T, T), AnalysisError> {
    let t = terms(c, x)?;
    let two = T::from_f64(2.0);
    let half = T::from_f64(0.5);
    let three_half_g = T::from_f64(1.5) * t.g;
    let alpha_acc = -t.w * (t.k - two * x.beta_rate_radps * t.tan_b)
        - three_half_g * t.sin2a
        - c.anomaly_accel_radps2;
    let beta_acc =
        -t.k * x.beta_rate_radps - half * t.w.sq() * t.sin2b - three_half_g * t.cos_a_sq * t.sin2b;
    Ok((alpha_acc, beta_acc))
}

/// The Jacobian ∂(α̇, α̈, β̇, β̈)/∂(α, α̇, β, β̇) of Eqs. 5b–5c at any state (full partial
/// derivatives, not only at equilibria), row-major, with l̇/l, θ̇, θ̈, μ/R³ and μ3 frozen.
///
/// With w = θ̇ + α̇, k = (2+μ3) l̇/l, G = μ/R³:
///
/// ```text
///     [ 0                      1                 0                          0          ]
///     [ −3G cos2α              −(k − 2β̇ tanβ)    2wβ̇ sec²β                  2w tanβ    ]
///     [ 0                      0                 0                          1          ]
///     [ (3G/2) sin2α sin2β     −w sin2β          −cos2β (w² + 3G cos²α)     −k         ]
/// ```
///
/// Errors: a non-finite input, or |cosβ| < [`SINGULAR_COS_BETA`] (β = ±π/2 is a coordinate
/// singularity of α; the closed form of [`equilibrium_stability`] still covers it).
pub fn jacobian<T: Real>(
    c: &FrozenCoefficients<T>,
    x: &SwingState<T>,
) -> Result<[[T; 4]; 4], AnalysisError> {
    let t = terms(c, x)?;
    let (zero, one, two, three) = (T::ZERO, T::ONE, T::from_f64(2.0), T::from_f64(3.0));
    let bd = x.beta_rate_radps;
    Ok([
        [zero, one, zero, zero],
        [
            -three * t.g * t.cos2a,
            -(t.k - two * bd * t.tan_b),
            two * t.w * bd * t.sec2_b,
            two * t.w * t.tan_b,
        ],
        [zero, zero, zero, one],
        [
            T::from_f64(1.5) * t.g * t.sin2a * t.sin2b,
            -t.w * t.sin2b,
            -t.cos2b * (t.w.sq() + three * t.g * t.cos_a_sq),
            -t.k,
        ],
    ])
}

/// The eigenvalues of [`jacobian`] at any state, by nalgebra's Schur decomposition, 1/s.
///
/// Before the decomposition the matrix is balanced, J′ = S⁻¹ D J D⁻¹ with D = diag(1, 1/s, 1, 1/s)
/// and s the largest rate scale in J (√|stiffness| or |damping|), so that all entries are O(1);
/// the eigenvalues are s·eig(J′). Generic over `f32` and `f64`. Order: as the QR iteration
/// deflates them (match them to other roots by nearest distance).
///
/// Errors: those of [`jacobian`], or the QR iteration not converging within
/// [`MAX_SCHUR_ITERATIONS`].
pub fn jacobian_eigenvalues<T: Real + RealField>(
    c: &FrozenCoefficients<T>,
    x: &SwingState<T>,
) -> Result<[Complex<T>; 4], AnalysisError> {
    let j = jacobian(c, x)?;
    // Rate scale s: entries of the rate rows (1, 3) in the angle columns (0, 2) are 1/s², in the
    // rate columns (1, 3) 1/s.
    let mut s = T::ZERO;
    for row in [&j[1], &j[3]] {
        for (col, v) in row.iter().enumerate() {
            let v = Real::abs(*v);
            let rate = if col % 2 == 0 { Real::sqrt(v) } else { v };
            s = Real::max(s, rate);
        }
    }
    if s <= T::ZERO || !Real::is_finite(s) {
        s = T::ONE;
    }
    // J′_ij = J_ij · s^(p_j − p_i − 1), p = 0 for angles, 1 for rates.
    let inv_s = T::ONE / s;
    let inv_s2 = inv_s * inv_s;
    let scale = |row: usize, col: usize, v: T| -> T {
        match (row % 2, col % 2) {
            (0, 1) => v,         // p_j − p_i − 1 = 0
            (0, _) => v * inv_s, // −1
            (_, 1) => v * inv_s, // −1
            _ => v * inv_s2,     // −2
        }
    };
    let mut b = j;
    for (r, row) in b.iter_mut().enumerate() {
        for (col, v) in row.iter_mut().enumerate() {
            *v = scale(r, col, *v);
        }
    }
    let m = Matrix4::new(
        b[0][0], b[0][1], b[0][2], b[0][3], //
        b[1][0], b[1][1], b[1][2], b[1][3], //
        b[2][0], b[2][1], b[2][2], b[2][3], //
        b[3][0], b[3][1], b[3][2], b[3][3],
    );
    let schur = Schur::try_new(m, machine_epsilon::<T>(), MAX_SCHUR_ITERATIONS)
        .ok_or(AnalysisError::EigenNotConverged)?;
    let ev = schur.complex_eigenvalues();
    let out = |z: &nalgebra::Complex<T>| Complex {
        re: z.re * s,
        im: z.im * s,
    };
    let mut roots = [Complex {
        re: T::ZERO,
        im: T::ZERO,
    }; 4];
    for (dst, z) in roots.iter_mut().zip(ev.iter()) {
        *dst = out(z);
    }
    Ok(roots)
}

/// The machine epsilon of `T` (`f32::EPSILON` or `f64::EPSILON`): 1 + 2⁻²⁴ rounds to 1 in `f32`.
fn machine_epsilon<T: Real>() -> T {
    let eps32 = T::from_f64(f64::from(f32::EPSILON));
    if T::ONE + T::from_f64(0.5) * eps32 == T::ONE {
        eps32
    } else {
        T::from_f64(f64::EPSILON)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circular(n: f64, ratio: f64, mu3: f64) -> FrozenCoefficients<f64> {
        FrozenCoefficients {
            anomaly_rate_radps: n,
            anomaly_accel_radps2: 0.0,
            gravity_gradient_per_s2: n * n,
            length_rate_ratio_per_s: ratio,
            mu3,
        }
    }

    #[test]
    fn hand_worked_roots() {
        // n = 1e-3, l̇/l = 1e-3, μ3 = 0, α_e = β_e = 0: in-plane λ² + 2e-3 λ + 3e-6 = 0 →
        // h = 1e-3, D1 = 1e-6 − 3e-6 = −2e-6, λ = −1e-3 ± i·1.414 213 56e-3.
        // Out-of-plane λ² + 2e-3 λ + 4e-6 = 0 → D2 = −3e-6, λ = −1e-3 ± i·1.732 050 81e-3.
        let s = equilibrium_stability(&circular(1e-3, 1e-3, 0.0), 0.0, 0.0).unwrap();
        assert!((s.in_plane.discriminant_per_s2 + 2e-6).abs() < 1e-20);
        assert!((s.out_of_plane.discriminant_per_s2 + 3e-6).abs() < 1e-20);
        assert!((s.in_plane.roots[0].re + 1e-3).abs() < 1e-18);
        assert!((s.in_plane.roots[0].im - 1.414_213_562_373_095e-3).abs() < 1e-15);
        assert!((s.out_of_plane.roots[1].im + 1.732_050_807_568_877e-3).abs() < 1e-15);
        assert_eq!(s.verdict, Verdict::Stable);
        // d1/d2 agree with the struct.
        let c = circular(1e-3, 1e-3, 0.0);
        assert_eq!(d1(&c, 0.0), s.in_plane.discriminant_per_s2);
        assert_eq!(d2(&c, 0.0, 0.0), s.out_of_plane.discriminant_per_s2);
        // Real roots without cancellation: λ² + 2λ + 1e-12 = 0 → λ = −1 ± √(1 − 1e-12), i.e.
        // −5.000 000 000 001 25e-13 (the naive formula loses 4 digits here) and −2.
        let r = quadratic_roots(1.0_f64, 1e-12);
        assert!(
            (r.roots[0].re / -5.000_000_000_001_25e-13 - 1.0).abs() < 1e-15,
            "{:?}",
            r.roots
        );
        assert!((r.roots[1].re + 2.0).abs() < 1e-12);
        // μ3 enters as (1 + μ3/2): μ3 = 0.2, l̇/l = 1e-3 → h = 1.1e-3.
        let s = equilibrium_stability(&circular(1e-3, 1e-3, 0.2), 0.0, 0.0).unwrap();
        assert!((s.in_plane.half_damping_per_s - 1.1e-3).abs() < 1e-18);
    }

    #[test]
    fn paper_closed_loop() {
        let cl = closed_loop_poles(0.0057_f64, 9.8696e-6).unwrap();
        assert!((cl.natural_frequency_radps / (core::f64::consts::PI * 1e-3) - 1.0).abs() < 1e-4);
        assert!(
            (cl.damping_ratio - 0.907_174).abs() < 1e-5,
            "{}",
            cl.damping_ratio
        );
        // Poles −2.85e-3 ± i √(9.8696e-6 − 8.1225e-6) = −2.85e-3 ± i 1.321 780e-3.
        assert!((cl.poles.roots[0].re + 2.85e-3).abs() < 1e-15);
        assert!((cl.poles.roots[0].im - 1.747_1e-6_f64.sqrt()).abs() < 1e-12);
        assert_eq!(cl.poles.verdict, Verdict::Stable);
        assert_eq!(
            closed_loop_poles(0.0_f64, 0.0),
            Err(AnalysisError::NotPositive("k2"))
        );
    }

    #[test]
    fn classify_edges() {
        let z = Complex {
            re: 0.0_f64,
            im: 0.0,
        };
        assert_eq!(classify(&[z, z], 1e-6), Verdict::Marginal);
        assert_eq!(classify::<f64>(&[], 1e-6), Verdict::Unstable);
        assert_eq!(
            classify(
                &[Complex {
                    re: f64::NAN,
                    im: 0.0
                }],
                1e-6
            ),
            Verdict::Unstable
        );
    }

    #[test]
    fn beta_singularity_is_reported() {
        let c = circular(1e-3, 0.0, 0.0);
        let x = SwingState::at_rest(0.0, core::f64::consts::FRAC_PI_2);
        assert_eq!(jacobian(&c, &x), Err(AnalysisError::CoordinateSingularity));
        // The closed form still answers: the out-of-plane mode is a saddle there.
        let s = equilibrium_stability(&c, 0.0, core::f64::consts::FRAC_PI_2).unwrap();
        assert_eq!(s.out_of_plane.verdict, Verdict::Unstable);
    }
}
