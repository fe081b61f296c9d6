//! The range-rate control law (Eqs. 26–30, docs/equations.md §5): circular orbit, in-plane (β = 0).
//!
//! With δ = α − α_r, the paper's law (Eq. 27)
//!
//! ```text
//!   l̇ = [k1 δ̇ + k2 δ − 1.5 n² sin(2δ + 2α_r)] / (n + δ̇) · l/(2 + μ3)
//! ```
//!
//! turns the in-plane equation (26) into the linear δ̈ + k1 δ̇ + k2 δ = −α̈_r − (2+μ3) α̇_r l̇/l
//! (Eq. 28), and the decay blend (Eq. 29) joins it to the reel's initial rate:
//! l̇_real = l̇ + (l̇0 − l̇) e^{−cτ}.
//!
//! **Eq. 27 is implicit** when α_r depends on l: α̇_r = p·l̇_real + r (p = ∂α_r/∂l,
//! r = ∂α_r/∂t), so δ̇ contains the rate being computed. [`solve`] solves Eqs. 27 + 29 exactly
//! for y = l̇_real as the root of (docs/equations.md §5)
//!
//! ```text
//!   (y − E l̇0)(w − p y) = (1 − E) L′ (G0 − k1 p y),
//!   w = n + α̇ − r,  G0 = k1(α̇ − r) + k2 δ − 1.5 n² sin 2α,  L′ = l/(2+μ3),  E = e^{−cτ},
//! ```
//!
//! taking the physical root y = 2C/(b + √(b² − 4pC)), the one that tends to C/b as p → 0.
//!
//! **Eccentric orbits** (docs/equations.md §16). With [`LawInput::orbit`] set, n is θ̇, the
//! gravity-gradient factor 1.5n² becomes 1.5μ/R³, and the numerator also takes Eq. 5b's θ̈ and
//! the reference's explicit time acceleration ∂²α_r/∂t² (the forced libration it follows):
//!
//! ```text
//!   l̇ = [k1 δ̇ + k2 δ − 1.5(μ/R³) sin 2α − θ̈ − ∂²α_r/∂t²] / (θ̇ + δ̇) · l/(2 + μ3)
//! ```
//!
//! so that a tether on the reference's periodic libration at constant length needs l̇ = 0. With
//! `orbit: None` (a circular orbit) every operation is the paper's, bit for bit.

use crate::real::Real;

/// The gains of Eq. 27.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains<T> {
    /// k1, 1/s: the damping gain of Eq. 28 (= 2ζω0).
    pub k1_per_s: T,
    /// k2, 1/s²: the stiffness gain of Eq. 28 (= ω0²).
    pub k2_per_s2: T,
}

impl<T: Real> Gains<T> {
    /// The paper's gains (Section 6): k1 = 0.0057 s⁻¹, k2 = 9.8696e-6 s⁻²
    /// (ω0 = π·10⁻³ rad/s, ζ ≈ 0.91).
    pub fn paper() -> Self {
        Self {
            k1_per_s: T::from_f64(0.0057),
            k2_per_s2: T::from_f64(9.8696e-6),
        }
    }
}

/// The Eq. 29 blend at one instant: E = e^{−cτ} and 1 − E, each to its own relative
/// precision. Right after the blend (re)starts E ≈ 1, and 1 − E computed from a rounded E
/// would keep only a few significant bits (at τ = 1 s, c = 5·10⁻⁴ s⁻¹, a relative error of
/// 6·10⁻⁵ in f32), which the law multiplies by its large Eq. 27 value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blend<T> {
    /// E = e^{−cτ}, in [0, 1].
    pub weight: T,
    /// 1 − E, in [0, 1].
    pub complement: T,
}

impl<T: Real> Blend<T> {
    /// The blend τ after its start for the decay rate c: `neg_c_tau` = −cτ ≤ 0.
    pub fn decayed(neg_c_tau: T) -> Self {
        let (weight, complement) = neg_c_tau.exp_and_complement();
        Self { weight, complement }
    }

    /// The blend whose weight is E = 2^`log2_weight`: τ after its start for the decay rate c,
    /// `log2_weight` = −cτ·log₂e ≤ 0 (the same E as [`Blend::decayed`], with log₂e folded into
    /// the caller's constant −cΔt·log₂e; see [`crate::fastmath::exp2_and_complement`]).
    #[inline]
    pub fn from_log2(log2_weight: T) -> Self {
        let (weight, complement) = log2_weight.exp2_and_complement();
        Self { weight, complement }
    }

    /// A blend of weight E given as a number (its complement computed as 1 − E).
    pub fn from_weight(weight: T) -> Self {
        Self {
            weight,
            complement: T::ONE - weight,
        }
    }
}

/// The eccentric-orbit terms of Eqs. 27 and 30 at one instant (docs/equations.md §16.3): the
/// orbit's (§0) and those of a reference that moves with θ (§16.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitForcing<T> {
    /// 1.5 μ/R³, 1/s² (1.5 n² on a circular orbit).
    pub gradient_per_s2: T,
    /// d(1.5 μ/R³)/dt, 1/s³.
    pub gradient_rate_per_s3: T,
    /// θ̈, rad/s².
    pub orbit_accel_radps2: T,
    /// θ⃛, rad/s³.
    pub orbit_jerk_radps3: T,
    /// ∂²α_r/∂t² at fixed l, rad/s².
    pub ref_time_accel_radps2: T,
    /// ∂³α_r/∂t³ at fixed l, rad/s³.
    pub ref_time_jerk_radps3: T,
    /// ∂²α_r/∂l∂t, rad/(m·s).
    pub ref_slope_rate_rad_per_m_s: T,
    /// ∂³α_r/∂l∂t², rad/(m·s²).
    pub ref_time_accel_slope_rad_per_m_s2: T,
}

/// Everything the law needs at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LawInput<T> {
    /// Tether length l, m.
    pub length_m: T,
    /// In-plane angle α, rad.
    pub alpha_rad: T,
    /// In-plane rate α̇, rad/s.
    pub alpha_rate_radps: T,
    /// Orbit rate n (θ̇ on an eccentric orbit), rad/s.
    pub orbit_rate_radps: T,
    /// The eccentric-orbit terms (docs/equations.md §16); `None` on a circular orbit, where the
    /// law is the paper's, bit for bit.
    pub orbit: Option<OrbitForcing<T>>,
    /// α_r, rad.
    pub ref_angle_rad: T,
    /// p = ∂α_r/∂l, rad/m.
    pub ref_slope_rad_per_m: T,
    /// ∂²α_r/∂l², rad/m².
    pub ref_curvature_rad_per_m2: T,
    /// r = ∂α_r/∂t, rad/s.
    pub ref_time_rate_radps: T,
    /// μ3 at this length (Eq. 5).
    pub mu3: T,
    /// μ̇3 per unit reel rate, i.e. dμ3/dl, 1/m (so that μ̇3 = dμ3/dl · l̇).
    pub mu3_per_m: T,
    /// The Eq. 29 blend: E = e^{−cτ} and 1 − E.
    pub blend: Blend<T>,
    /// c, the Eq. 29 decay rate, 1/s.
    pub decay_rate_per_s: T,
    /// l̇0, the rate the current stage's blend started from, m/s.
    pub initial_rate_mps: T,
    /// The gains.
    pub gains: Gains<T>,
}

/// Why the law has no valid solution at this instant (docs/equations.md §5, the law's singular points).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LawFault {
    /// b ≤ 0 in the implicit solve: n + δ̇ has reached zero (the Eq. 27 denominator) or
    /// changed sign, so the command would be unbounded or the wrong root.
    SingularDenominator,
    /// b² − 4pC < 0: Eqs. 27 + 29 have no real solution for this state.
    NoRealSolution,
    /// 1 + B·p ≈ 0 in the acceleration solve: the rate solution is at a fold.
    AccelerationSingular,
    /// An intermediate value was not finite (input out of any physical range).
    NotFinite,
}

/// The law's solution at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LawOutput<T> {
    /// y = l̇_real, the blended reel-rate command (Eq. 29), m/s.
    pub rate_mps: T,
    /// The Eq. 27 value l̇ (before the blend), m/s.
    pub law_rate_mps: T,
    /// δ = α − α_r, rad.
    pub delta_rad: T,
    /// δ̇ = α̇ − α̇_r with α̇_r = p·y + r (consistent with the command), rad/s.
    pub delta_rate_radps: T,
    /// α̇_r = p·y + r, rad/s.
    pub ref_rate_radps: T,
    /// n + δ̇, the Eq. 27 denominator, rad/s.
    pub denominator_radps: T,
    /// sin 2α (= sin(2δ + 2α_r)), reused by [`acceleration`].
    pub sin_two_alpha: T,
    /// cos 2α, reused by [`acceleration`].
    pub cos_two_alpha: T,
    /// L′ = l/(2 + μ3), m, reused by [`acceleration`].
    pub reduced_length_m: T,
    /// 1.5 n² (1.5 μ/R³ on an eccentric orbit), the gravity-gradient factor of Eq. 27, 1/s²,
    /// reused by [`acceleration`].
    pub gradient_per_s2: T,
    /// N/D = l̇/L′, the Eq. 27 fraction, 1/s, reused by [`acceleration`].
    pub fraction_per_s: T,
}

/// Smallest admissible value of b relative to n: below this the Eq. 27 denominator n + δ̇ is
/// treated as singular. In the paper's run (n + δ̇)/n falls to about 0.06 in the first minutes
/// (docs/equations.md §5), so 1 % leaves a factor-six margin while bounding the command's sensitivity.
pub const MIN_DENOMINATOR_FRACTION: f64 = 0.01;

/// Solves Eqs. 27 + 29 for the reel-rate command y = l̇_real (docs/equations.md §5).
///
/// Returns a [`LawFault`] (never a non-finite number) at the law's singular points.
pub fn solve<T: Real>(x: &LawInput<T>) -> Result<LawOutput<T>, LawFault> {
    let two = T::from_f64(2.0);
    let four = T::from_f64(4.0);
    let three_halves = T::from_f64(1.5);
    let n = x.orbit_rate_radps;
    let p = x.ref_slope_rad_per_m;
    let (e, one_minus_e) = (x.blend.weight, x.blend.complement);
    let k1 = x.gains.k1_per_s;
    let l_prime = x.length_m / (two + x.mu3);
    let delta = x.alpha_rad - x.ref_angle_rad;
    // sin(2δ + 2α_r) = sin 2α.
    let (sin2a, cos2a) = (two * x.alpha_rad).sin_cos();
    // The restoring terms of Eq. 5b that the numerator cancels: 1.5n² sin 2α, and on an
    // eccentric orbit 1.5(μ/R³) sin 2α + θ̈ + ∂²α_r/∂t² (docs/equations.md §16.3).
    let (gradient, gravity) = match &x.orbit {
        None => {
            let gradient = three_halves * n * n;
            (gradient, gradient * sin2a)
        }
        Some(o) => (
            o.gradient_per_s2,
            o.gradient_per_s2 * sin2a + o.orbit_accel_radps2 + o.ref_time_accel_radps2,
        ),
    };
    let w = n + x.alpha_rate_radps - x.ref_time_rate_radps;
    let g0 =
        k1 * (x.alpha_rate_radps - x.ref_time_rate_radps) + x.gains.k2_per_s2 * delta - gravity;
    let b = w + p * (e * x.initial_rate_mps + one_minus_e * l_prime * k1);
    let c = e * x.initial_rate_mps * w + one_minus_e * l_prime * g0;
    // No finiteness test here: a NaN fails every comparison below and reaches y, and an
    // infinity in b or C makes y, α̇_r or the Eq. 27 value NaN or infinite (∞/∞, 0·∞, ∞ − ∞):
    // the one test at the end catches both (`tests/law_properties.rs` tries every input).
    if b <= T::from_f64(MIN_DENOMINATOR_FRACTION) * n.abs() {
        return Err(LawFault::SingularDenominator);
    }
    let disc = b * b - four * p * c;
    if disc < T::ZERO {
        return Err(LawFault::NoRealSolution);
    }
    let y = two * c / (b + disc.sqrt());
    let ref_rate = p * y + x.ref_time_rate_radps;
    let delta_rate = x.alpha_rate_radps - ref_rate;
    let denom = n + delta_rate;
    if denom <= T::from_f64(MIN_DENOMINATOR_FRACTION) * n.abs() {
        return Err(LawFault::SingularDenominator);
    }
    // Eq. 27 itself, evaluated with the consistent δ̇.
    let fraction = (k1 * delta_rate + x.gains.k2_per_s2 * delta - gravity) / denom;
    let law_rate = fraction * l_prime;
    if !(y + law_rate).is_finite() {
        return Err(LawFault::NotFinite);
    }
    Ok(LawOutput {
        rate_mps: y,
        law_rate_mps: law_rate,
        delta_rad: delta,
        delta_rate_radps: delta_rate,
        ref_rate_radps: ref_rate,
        denominator_radps: denom,
        sin_two_alpha: sin2a,
        cos_two_alpha: cos2a,
        reduced_length_m: l_prime,
        gradient_per_s2: gradient,
        fraction_per_s: fraction,
    })
}

/// Eq. 27 evaluated explicitly for a given δ̇ (rad/s), in the paper's form (with the
/// eccentric-orbit terms of docs/equations.md §16.3 when [`LawInput::orbit`] is set):
///
/// ```text
///   l̇ = [k1 δ̇ + k2 δ − 1.5 n² sin(2δ + 2α_r)] / (n + δ̇) · l/(2 + μ3),   δ = α − α_r.
/// ```
///
/// Not used by the controller (see [`solve`]): it is the oracle the implicit solve is tested
/// against. With δ̇ = α̇ − (p·y + r) for [`solve`]'s command y, Eq. 29 on this value gives y
/// back: y = l̇ + (l̇0 − l̇)·E.
///
/// ```
/// use tss_reel::law::{explicit_eq27, solve, Blend, Gains, LawInput};
///
/// let x = LawInput::<f64> {
///     length_m: 15_000.0,
///     alpha_rad: -0.6,
///     alpha_rate_radps: 1.0e-4,
///     orbit_rate_radps: 1.06e-3,
///     orbit: None,
///     ref_angle_rad: -0.55,
///     ref_slope_rad_per_m: 6.0e-5,
///     ref_curvature_rad_per_m2: 3.0e-9,
///     ref_time_rate_radps: 0.0,
///     mu3: 0.0,
///     mu3_per_m: 0.0,
///     blend: Blend::from_weight(0.2),
///     decay_rate_per_s: 1e-3,
///     initial_rate_mps: 0.1,
///     gains: Gains::paper(),
/// };
/// let y = solve(&x).unwrap().rate_mps;
/// let l_dot = explicit_eq27(&x, x.alpha_rate_radps - x.ref_slope_rad_per_m * y);
/// assert!((l_dot + (x.initial_rate_mps - l_dot) * x.blend.weight - y).abs() < 1e-12);
/// ```
pub fn explicit_eq27<T: Real>(x: &LawInput<T>, delta_rate_radps: T) -> T {
    let two = T::from_f64(2.0);
    let delta = x.alpha_rad - x.ref_angle_rad;
    let n = x.orbit_rate_radps;
    let sin2a = (two * delta + two * x.ref_angle_rad).sin();
    let restoring = match &x.orbit {
        None => T::from_f64(1.5) * n * n * sin2a,
        Some(o) => o.gradient_per_s2 * sin2a + o.orbit_accel_radps2 + o.ref_time_accel_radps2,
    };
    (x.gains.k1_per_s * delta_rate_radps + x.gains.k2_per_s2 * delta - restoring)
        / (n + delta_rate_radps)
        * x.length_m
        / (two + x.mu3)
}

/// The commanded reel acceleration ÿ = d(l̇_real)/dt, the time derivative of Eq. 29 with
/// Eq. 27 inside it (Eq. 30, with the sign of its `[(1−e^{−cτ}) l̇_real + c l e^{−cτ}] l̇/l`
/// term corrected, docs/equations.md §9.3).
///
/// δ̈ comes from the in-plane dynamics (Eq. 26 / 5b, circular orbit, β = 0) with l̇ = y, and
/// α̈_r = (∂²α_r/∂l²) y² + p ÿ, which makes the result implicit again but linear in ÿ:
/// ÿ = A / (1 + B p).
pub fn acceleration<T: Real>(x: &LawInput<T>, s: &LawOutput<T>) -> Result<T, LawFault> {
    let two = T::from_f64(2.0);
    let n = x.orbit_rate_radps;
    let (e, one_minus_e) = (x.blend.weight, x.blend.complement);
    let y = s.rate_mps;
    let u = s.law_rate_mps;
    let l = x.length_m;
    let l_prime = s.reduced_length_m;
    let d = s.denominator_radps;
    let mu3_dot = x.mu3_per_m * y;
    // Eq. 5b (circular, β = 0) with l̇ = y: (2 + μ3) y/l = y/L′.
    let alpha_accel = -(n + x.alpha_rate_radps) * y / l_prime - s.gradient_per_s2 * s.sin_two_alpha;
    // u̇ = (L′/D)[(k1 − N/D) δ̈ + k2 δ̇ − 3n² α̇ cos2α] + u (y/l − μ̇3/(2+μ3)).
    let k_eff = x.gains.k1_per_s - s.fraction_per_s;
    let b_coef = one_minus_e * l_prime / d * k_eff;
    let mut numerator_rate = x.gains.k2_per_s2 * s.delta_rate_radps
        - two * s.gradient_per_s2 * x.alpha_rate_radps * s.cos_two_alpha;
    // δ̈ without its p ÿ part: α̈ − q y² (and on an eccentric orbit − 2 (∂²α_r/∂l∂t) y − ∂²α_r/∂t²).
    let mut delta_accel = alpha_accel - x.ref_curvature_rad_per_m2 * y * y;
    if let Some(o) = &x.orbit {
        // docs/equations.md §16.5: Eq. 5b's θ̈ in α̈; Ṅ's −d(1.5μ/R³)/dt sin 2α − θ⃛ − d(∂²α_r/∂t²)/dt;
        // Ḋ's θ̈ (D = θ̇ + δ̇), which enters u̇ as −(N/D) θ̈.
        delta_accel = delta_accel
            - o.orbit_accel_radps2
            - two * o.ref_slope_rate_rad_per_m_s * y
            - o.ref_time_accel_radps2;
        numerator_rate = numerator_rate
            - o.gradient_rate_per_s3 * s.sin_two_alpha
            - o.orbit_jerk_radps3
            - o.ref_time_jerk_radps3
            - o.ref_time_accel_slope_rad_per_m_s2 * y
            - s.fraction_per_s * o.orbit_accel_radps2;
    }
    let rest = l_prime / d * numerator_rate + u * (y / l - mu3_dot / (two + x.mu3));
    let a = x.decay_rate_per_s * e * (u - x.initial_rate_mps)
        + one_minus_e * rest
        + b_coef * delta_accel;
    let fold = T::ONE + b_coef * x.ref_slope_rad_per_m;
    if fold.abs() < T::from_f64(1e-3) {
        return Err(LawFault::AccelerationSingular);
    }
    let accel = a / fold;
    if accel.is_finite() {
        Ok(accel)
    } else {
        Err(LawFault::NotFinite)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const N: f64 = 1.060_237_230_236_363_5e-3;

    fn base_input() -> LawInput<f64> {
        base()
    }

    fn base() -> LawInput<f64> {
        LawInput {
            length_m: 15_000.0,
            alpha_rad: -0.6,
            alpha_rate_radps: 1.0e-4,
            orbit_rate_radps: N,
            orbit: None,
            ref_angle_rad: -0.55,
            ref_slope_rad_per_m: 6.0e-5,
            ref_curvature_rad_per_m2: 3.0e-9,
            ref_time_rate_radps: 0.0,
            mu3: 0.0,
            mu3_per_m: 0.0,
            blend: Blend::from_weight(0.2),
            decay_rate_per_s: 1e-3,
            initial_rate_mps: 0.1,
            gains: Gains::paper(),
        }
    }

    /// Eq. 27 evaluated directly, for a given δ̇ (the shared oracle).
    fn eq27(x: &LawInput<f64>, delta_rate: f64) -> f64 {
        explicit_eq27(x, delta_rate)
    }

    #[test]
    fn implicit_solution_has_zero_residual() {
        let x = base();
        let s = solve(&x).unwrap();
        // Substituting y back: δ̇ = α̇ − (p y + r), then Eq. 29 must return y.
        let dd = x.alpha_rate_radps - (x.ref_slope_rad_per_m * s.rate_mps + x.ref_time_rate_radps);
        let blended = eq27(&x, dd) + (x.initial_rate_mps - eq27(&x, dd)) * x.blend.weight;
        assert!((blended - s.rate_mps).abs() < 1e-12 * s.rate_mps.abs().max(1.0));
        assert!((s.law_rate_mps - eq27(&x, dd)).abs() < 1e-12);
    }

    #[test]
    fn without_slope_it_is_the_explicit_law() {
        let x = LawInput {
            ref_slope_rad_per_m: 0.0,
            ..base()
        };
        let s = solve(&x).unwrap();
        let dd = x.alpha_rate_radps;
        let u = eq27(&x, dd);
        let expect = u + (x.initial_rate_mps - u) * x.blend.weight;
        assert!((s.rate_mps - expect).abs() < 1e-14);
    }

    #[test]
    fn at_stage_start_the_command_is_the_initial_rate() {
        let x = LawInput {
            blend: Blend::from_weight(1.0),
            ..base()
        };
        let s = solve(&x).unwrap();
        assert!((s.rate_mps - 0.1).abs() < 1e-15);
    }

    #[test]
    fn hand_value_on_the_deploy_plateau() {
        // p = 0, E = 0, μ3 = 0, δ̇ = α̇: l̇ = [k1 α̇ + k2 δ − 1.5 n² sin 2α] / (n + α̇) · l/2.
        let x = LawInput {
            length_m: 2_000.0,
            alpha_rad: -0.7,
            alpha_rate_radps: 0.0,
            ref_angle_rad: -core::f64::consts::FRAC_PI_4,
            ref_slope_rad_per_m: 0.0,
            ref_curvature_rad_per_m2: 0.0,
            blend: Blend::from_weight(0.0),
            ..base()
        };
        let s = solve(&x).unwrap();
        let delta = -0.7 + core::f64::consts::FRAC_PI_4;
        let expect = (9.8696e-6 * delta - 1.5 * N * N * (-1.4_f64).sin()) / N * 1_000.0;
        assert!(
            (s.rate_mps - expect).abs() < 1e-12,
            "{} vs {expect}",
            s.rate_mps
        );
        assert!(expect > 0.0, "deploying on the −45° side");
    }

    #[test]
    fn closed_loop_identity_eq28() {
        // With E = 0, substituting l̇ from Eq. 27 into Eq. 26 gives
        // δ̈ + k1 δ̇ + k2 δ = −α̈_r − (2+μ3) α̇_r l̇/l  (Eq. 28).
        let x = LawInput {
            blend: Blend::from_weight(0.0),
            mu3: 0.07,
            ref_time_rate_radps: 2e-5,
            ..base()
        };
        let s = solve(&x).unwrap();
        let (n, y, l) = (x.orbit_rate_radps, s.rate_mps, x.length_m);
        let alpha_ddot = -(n + x.alpha_rate_radps) * (2.0 + x.mu3) * y / l
            - 1.5 * n * n * (2.0 * x.alpha_rad).sin();
        // Eq. 26 rearranged: δ̈ = α̈ − α̈_r; the identity holds for any α̈_r, take α̈_r = 0.
        let lhs =
            alpha_ddot + x.gains.k1_per_s * s.delta_rate_radps + x.gains.k2_per_s2 * s.delta_rad;
        let rhs = -(2.0 + x.mu3) * s.ref_rate_radps * y / l;
        assert!((lhs - rhs).abs() < 1e-15, "{lhs} vs {rhs}");
    }

    #[test]
    fn acceleration_is_the_time_derivative_of_the_command() {
        // Advance the state along the model with l̇ = y, ref following the schedule-like
        // linearisation α_r(l + dl) ≈ α_r + p dl + ½ q dl², and difference the command.
        let x0 = LawInput {
            mu3: 0.05,
            mu3_per_m: 2.0e-6,
            ..base()
        };
        let s0 = solve(&x0).unwrap();
        let a0 = acceleration(&x0, &s0).unwrap();
        let n = x0.orbit_rate_radps;
        let dt = 1e-3;
        let step = |h: f64| {
            let y = s0.rate_mps;
            let dl = y * h;
            let alpha_ddot = -(n + x0.alpha_rate_radps) * (2.0 + x0.mu3) * y / x0.length_m
                - 1.5 * n * n * (2.0 * x0.alpha_rad).sin();
            let x = LawInput {
                length_m: x0.length_m + dl,
                alpha_rad: x0.alpha_rad + x0.alpha_rate_radps * h,
                alpha_rate_radps: x0.alpha_rate_radps + alpha_ddot * h,
                ref_angle_rad: x0.ref_angle_rad
                    + x0.ref_slope_rad_per_m * dl
                    + 0.5 * x0.ref_curvature_rad_per_m2 * dl * dl,
                ref_slope_rad_per_m: x0.ref_slope_rad_per_m + x0.ref_curvature_rad_per_m2 * dl,
                mu3: x0.mu3 + x0.mu3_per_m * dl,
                blend: Blend::from_weight(x0.blend.weight * (-x0.decay_rate_per_s * h).exp()),
                ..x0
            };
            solve(&x).unwrap().rate_mps
        };
        let fd = (step(dt) - step(-dt)) / (2.0 * dt);
        assert!((a0 - fd).abs() < 1e-6 * fd.abs() + 1e-12, "{a0} vs {fd}");
    }

    /// A state on an eccentric orbit (e = 0.2) `h` seconds after a start state, moved along
    /// Eq. 5b with l̇ = the start state's command (to first order: central differences cancel
    /// the second-order terms), its reference and orbit terms worked out from the stage-1 band
    /// (or the stage-2 slew) and the orbit.
    fn eccentric_state(h: f64, slewing: bool) -> LawInput<f64> {
        use crate::orbit::Orbit;
        use crate::schedule::{BandSchedule, LibratingReference, Reference};
        let orbit = Orbit::elliptic(7.8e6, 0.2);
        let prepared = orbit.prepare();
        let librating = LibratingReference::new(&orbit).unwrap();
        let band = BandSchedule::<f64>::paper_stage1().prepare();
        let (theta0, l0, alpha0, alpha_rate0, tau0) = (1.1, 24_000.0, -0.3, 2.0e-4, 200.0);
        let state = |theta: f64, l: f64, alpha: f64, alpha_rate: f64, tau: f64, e: f64| {
            let base = if slewing {
                band.eval_slewed(6.2932e-4, tau, l)
            } else {
                Reference {
                    angle: band.eval(l),
                    time_rate_radps: 0.0,
                    slewing: false,
                    orbit: None,
                }
            };
            let r = librating.eval(base, theta);
            LawInput {
                length_m: l,
                alpha_rad: alpha,
                alpha_rate_radps: alpha_rate,
                orbit_rate_radps: prepared.at(theta).rate_radps,
                orbit: r.orbit,
                ref_angle_rad: r.angle.angle_rad,
                ref_slope_rad_per_m: r.angle.slope_rad_per_m,
                ref_curvature_rad_per_m2: r.angle.curvature_rad_per_m2,
                ref_time_rate_radps: r.time_rate_radps,
                mu3: 0.05,
                mu3_per_m: 0.0,
                blend: Blend::from_weight(e),
                decay_rate_per_s: 1e-3,
                initial_rate_mps: 0.1,
                gains: Gains::paper(),
            }
        };
        let x0 = state(theta0, l0, alpha0, alpha_rate0, tau0, 0.3);
        let y0 = solve(&x0).unwrap().rate_mps;
        let o0 = prepared.at(theta0);
        let alpha_ddot = -(o0.rate_radps + alpha_rate0) * y0 / (l0 / 2.05)
            - 1.5 * o0.gravity_gradient_per_s2 * (2.0 * alpha0).sin()
            - o0.accel_radps2;
        state(
            theta0 + o0.rate_radps * h,
            l0 + y0 * h,
            alpha0 + alpha_rate0 * h,
            alpha_rate0 + alpha_ddot * h,
            tau0 + h,
            0.3 * (-1e-3 * h).exp(),
        )
    }

    #[test]
    fn eccentric_acceleration_is_the_time_derivative_of_the_command() {
        // Eq. 30 on an eccentric orbit (docs/equations.md §16.5), on the band and in the slew:
        // ÿ against a central difference of the command along the motion.
        for slewing in [false, true] {
            let x0 = eccentric_state(0.0, slewing);
            let a0 = acceleration(&x0, &solve(&x0).unwrap()).unwrap();
            let dt = 1e-2;
            let y = |h: f64| solve(&eccentric_state(h, slewing)).unwrap().rate_mps;
            let fd = (y(dt) - y(-dt)) / (2.0 * dt);
            assert!(
                (a0 - fd).abs() < 1e-6 * fd.abs() + 1e-12,
                "slewing {slewing}: {a0} vs {fd}"
            );
        }
    }

    #[test]
    fn on_the_libration_at_the_keep_the_command_is_zero() {
        // At the stage-1 keep (α_r = 0), a tether on the periodic libration (α = P(θ),
        // α̇ = θ̇ P′) at rest needs no reel motion: y = 0 at every θ, the residual at rounding.
        use crate::orbit::Orbit;
        use crate::schedule::{BandSchedule, LibratingReference, Reference};
        for e in [0.1, 0.3] {
            let mut fought: f64 = 0.0;
            let orbit = Orbit::elliptic(10.0e6, e);
            let prepared = orbit.prepare();
            let librating = LibratingReference::new(&orbit).unwrap();
            let band = BandSchedule::<f64>::paper_stage1().prepare();
            for theta in [0.0, 0.5, 2.0, 3.0, 4.5] {
                let base = Reference {
                    angle: band.eval(30_000.0),
                    time_rate_radps: 0.0,
                    slewing: false,
                    orbit: None,
                };
                let r = librating.eval(base, theta);
                let p = librating.libration().eval(theta);
                let rate = prepared.at(theta).rate_radps;
                let x = LawInput {
                    length_m: 30_000.0,
                    alpha_rad: p.angle_rad,
                    alpha_rate_radps: rate * p.slope,
                    orbit_rate_radps: rate,
                    orbit: r.orbit,
                    ref_angle_rad: r.angle.angle_rad,
                    ref_slope_rad_per_m: r.angle.slope_rad_per_m,
                    ref_curvature_rad_per_m2: r.angle.curvature_rad_per_m2,
                    ref_time_rate_radps: r.time_rate_radps,
                    blend: Blend::from_weight(0.0),
                    mu3: 0.0,
                    ..base_input()
                };
                let s = solve(&x).unwrap();
                // (The series' residual, ≤ 1e-9 in α″, times L′θ̇: ≲ 1e-8 m/s.)
                assert!(
                    s.rate_mps.abs() < 1e-7,
                    "e = {e}, θ = {theta}: {}",
                    s.rate_mps
                );
                // Today's law (no orbit terms, α_r = 0) fights the libration with the reel.
                let circular = LawInput {
                    orbit: None,
                    ref_angle_rad: 0.0,
                    ref_time_rate_radps: 0.0,
                    ..x
                };
                // (or has no solution: a singular denominator counts as fighting.)
                let y = solve(&circular).map_or(f64::INFINITY, |s| s.rate_mps.abs());
                fought = fought.max(y);
            }
            assert!(fought > 0.5, "e = {e}: {fought} m/s");
        }
    }

    #[test]
    fn an_unknown_true_anomaly_is_a_fault_not_a_number() {
        // θ not finite on an eccentric orbit: the reference carries NaN orbit terms and the law
        // faults (the controller's safe action), whatever the rest of the state.
        use crate::schedule::{LibratingReference, Reference};
        let base = Reference {
            angle: crate::schedule::RefAngle {
                angle_rad: -0.55,
                slope_rad_per_m: 6.0e-5,
                curvature_rad_per_m2: 3.0e-9,
            },
            time_rate_radps: 0.0,
            slewing: false,
            orbit: None,
        };
        let r = LibratingReference::without_anomaly(base);
        assert_eq!(r.angle, base.angle);
        let x = LawInput {
            orbit: r.orbit,
            ..base_input()
        };
        assert_eq!(solve(&x), Err(LawFault::NotFinite));
    }

    #[test]
    fn singular_denominator_is_a_fault_not_a_number() {
        // On a plateau (p = 0) the denominator n + δ̇ = n + α̇ vanishes at α̇ = −n.
        let x = LawInput {
            alpha_rate_radps: -N,
            ref_slope_rad_per_m: 0.0,
            ..base()
        };
        assert_eq!(solve(&x), Err(LawFault::SingularDenominator));
        let x = LawInput {
            alpha_rate_radps: -1.5 * N,
            ref_slope_rad_per_m: 0.0,
            ..base()
        };
        assert_eq!(solve(&x), Err(LawFault::SingularDenominator));
        let x = LawInput {
            alpha_rate_radps: f64::NAN,
            ..base()
        };
        assert_eq!(solve(&x), Err(LawFault::NotFinite));
    }
}
