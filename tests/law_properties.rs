//! Properties of the implicit range-rate law (docs/equations.md §5) on random states, in f64.
//!
//! - Residual: the command y substituted back into Eqs. 27 + 29 (with α̇_r = p·y + r inside
//!   δ̇) gives y again.
//! - Closed-loop identity (Eq. 28): with the blend finished (E = 0), Eq. 26 under the law
//!   becomes δ̈ + k1 δ̇ + k2 δ = −α̈_r − (2+μ3) α̇_r l̇/l.
//! - The physical root is the one that tends to the explicit law as p → 0 (linearly).
//! - A non-finite or absurd input gives a fault, never a number that is not finite (in f64 and
//!   in the flight build's f32).

use proptest::prelude::*;
use tss_reel::law::{acceleration, explicit_eq27, solve, Blend, Gains, LawInput};

const N: f64 = 1.060_237_230_236_363_5e-3;

prop_compose! {
    fn state()(
        length_m in 1.0f64..40_000.0,
        alpha_rad in -1.3f64..1.3,
        alpha_rate in -2e-3f64..2e-3,
        ref_angle_rad in -0.8f64..0.8,
        slope in -1e-4f64..1e-4,
        curvature in -1e-8f64..1e-8,
        ref_time_rate in -7e-4f64..7e-4,
        mu3 in 0.0f64..0.2,
        blend in 0.0f64..1.0,
        initial_rate in -3.0f64..3.0,
    ) -> LawInput<f64> {
        LawInput {
            length_m,
            alpha_rad,
            alpha_rate_radps: alpha_rate,
            orbit_rate_radps: N,
            orbit: None,
            ref_angle_rad,
            ref_slope_rad_per_m: slope,
            ref_curvature_rad_per_m2: curvature,
            ref_time_rate_radps: ref_time_rate,
            mu3,
            mu3_per_m: 0.0,
            blend: Blend::from_weight(blend),
            decay_rate_per_s: 1e-3,
            initial_rate_mps: initial_rate,
            gains: Gains::paper(),
        }
    }
}

/// Eq. 27 with a given δ̇: the law's documented explicit form, the oracle of the implicit
/// solve.
fn eq27(x: &LawInput<f64>, delta_rate: f64) -> f64 {
    explicit_eq27(x, delta_rate)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 20_000, max_global_rejects: 200_000, ..ProptestConfig::default() })]

    #[test]
    fn command_solves_eqs_27_and_29(x in state()) {
        // States at the law's singular points are faults, not numbers (tested elsewhere).
        if let Ok(s) = solve(&x) {
            let dd = x.alpha_rate_radps - (x.ref_slope_rad_per_m * s.rate_mps + x.ref_time_rate_radps);
            let u = eq27(&x, dd);
            let blended = u + (x.initial_rate_mps - u) * x.blend.weight;
            let scale = s.rate_mps.abs().max(u.abs()).max(1e-3);
            prop_assert!((blended - s.rate_mps).abs() <= 1e-9 * scale, "y = {}, Eqs. 27+29 give {blended}", s.rate_mps);
            prop_assert!((s.law_rate_mps - u).abs() <= 1e-9 * scale);
        }
    }

    #[test]
    fn closed_loop_identity_eq28(x in state()) {
        let x = LawInput { blend: Blend::from_weight(0.0), ..x };
        if let Ok(s) = solve(&x) {
            let (n, y, l) = (x.orbit_rate_radps, s.rate_mps, x.length_m);
            // Eq. 26's left side with α̈ from Eq. 5b (circular, β = 0), α̈_r taken as 0.
            let alpha_ddot = -(n + x.alpha_rate_radps) * (2.0 + x.mu3) * y / l
                - 1.5 * n * n * (2.0 * x.alpha_rad).sin();
            let lhs = alpha_ddot + x.gains.k1_per_s * s.delta_rate_radps + x.gains.k2_per_s2 * s.delta_rad;
            let rhs = -(2.0 + x.mu3) * s.ref_rate_radps * y / l;
            let scale = (x.gains.k2_per_s2 * s.delta_rad).abs() + (n * n) + rhs.abs();
            prop_assert!((lhs - rhs).abs() <= 1e-9 * scale, "{lhs} vs {rhs}");
        }
    }

    #[test]
    fn physical_root_tends_to_the_explicit_law(x in state()) {
        // The physical root y(p) → C/b (the explicit law) as p → 0, linearly; the other root
        // of the quadratic diverges like 1/p. Dividing p by 10 must divide |y(p) − y(0)| by
        // about 10 (checked as: by at least 5). Away from the singular denominator
        // (w = n + α̇ − r ≥ 0.2 n, commands within 50 m/s): near it the command is arbitrarily
        // sensitive to p (dy/dp ∝ y²/w), which the controller treats as a fault.
        let w = x.orbit_rate_radps + x.alpha_rate_radps - x.ref_time_rate_radps;
        prop_assume!(w >= 0.2 * x.orbit_rate_radps);
        let y = |scale: f64| solve(&LawInput { ref_slope_rad_per_m: x.ref_slope_rad_per_m * scale, ..x }).map(|s| s.rate_mps);
        if let (Ok(y0), Ok(y1), Ok(y2)) = (y(0.0), y(1e-3), y(1e-4)) {
            prop_assume!(y0.abs() <= 50.0);
            let (d1, d2) = ((y1 - y0).abs(), (y2 - y0).abs());
            prop_assert!(d2 <= 0.2 * d1 + 1e-12 * y0.abs().max(1.0), "y(0) = {y0}, y(p/1e3) = {y1}, y(p/1e4) = {y2}");
        }
    }

    #[test]
    fn non_finite_or_huge_inputs_give_a_fault_not_a_number(
        x in state(),
        field in 0usize..14,
        bad in prop::sample::select(vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300, 1e30, -1e30]),
    ) {
        let x = with_field(x, field, bad);
        check_finite(&x);
        check_finite(&to_f32(&x));
    }
}

/// `x` with its field number `field` (in declaration order; the blend weight sets both E and
/// 1 − E) replaced by `v`.
fn with_field(mut x: LawInput<f64>, field: usize, v: f64) -> LawInput<f64> {
    match field {
        0 => x.length_m = v,
        1 => x.alpha_rad = v,
        2 => x.alpha_rate_radps = v,
        3 => x.orbit_rate_radps = v,
        4 => x.ref_angle_rad = v,
        5 => x.ref_slope_rad_per_m = v,
        6 => x.ref_curvature_rad_per_m2 = v,
        7 => x.ref_time_rate_radps = v,
        8 => x.mu3 = v,
        9 => x.mu3_per_m = v,
        10 => x.blend = Blend::from_weight(v),
        11 => x.decay_rate_per_s = v,
        12 => x.initial_rate_mps = v,
        _ => x.gains.k1_per_s = v,
    }
    x
}

fn to_f32(x: &LawInput<f64>) -> LawInput<f32> {
    let f = |v: f64| v as f32;
    LawInput {
        length_m: f(x.length_m),
        alpha_rad: f(x.alpha_rad),
        alpha_rate_radps: f(x.alpha_rate_radps),
        orbit_rate_radps: f(x.orbit_rate_radps),
        orbit: None,
        ref_angle_rad: f(x.ref_angle_rad),
        ref_slope_rad_per_m: f(x.ref_slope_rad_per_m),
        ref_curvature_rad_per_m2: f(x.ref_curvature_rad_per_m2),
        ref_time_rate_radps: f(x.ref_time_rate_radps),
        mu3: f(x.mu3),
        mu3_per_m: f(x.mu3_per_m),
        blend: Blend {
            weight: f(x.blend.weight),
            complement: f(x.blend.complement),
        },
        decay_rate_per_s: f(x.decay_rate_per_s),
        initial_rate_mps: f(x.initial_rate_mps),
        gains: Gains {
            k1_per_s: f(x.gains.k1_per_s),
            k2_per_s2: f(x.gains.k2_per_s2),
        },
    }
}

/// Every number the law and the acceleration return as `Ok` at `x` is finite.
fn check_finite<T: tss_reel::real::Real + core::fmt::Debug>(x: &LawInput<T>) {
    let Ok(s) = solve(x) else { return };
    let all = [
        s.rate_mps,
        s.law_rate_mps,
        s.delta_rad,
        s.delta_rate_radps,
        s.ref_rate_radps,
        s.denominator_radps,
    ];
    assert!(all.iter().all(|v| v.is_finite()), "{x:?} gave {s:?}");
    if let Ok(a) = acceleration(x, &s) {
        assert!(a.is_finite(), "{x:?} gave the acceleration {a:?}");
    }
}
