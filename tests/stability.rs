//! Host tests of the equilibrium and stability analysis (Eqs. 6–19, 28; docs/equations.md §3–4).
//!
//! Theorem 1 and Figs. 2–3, the paper's three conclusions of §4, the closed-form roots against
//! nalgebra's eigenvalues of the full Jacobian, and the closed loop of the paper's gains.
#![cfg(not(target_os = "none"))]

use core::f64::consts::{FRAC_PI_2, PI};

use proptest::prelude::*;
use tss_reel::equilibrium::{
    depl, extent, f1, f1_derivative, f2, f2_derivative, in_plane_equilibria, max_retr, min_depl,
    normalised_rate, retr, sin_two_alpha_e, station_keeping_exists, Anomaly, ExistenceMonitor,
};
use tss_reel::mass::MassModel;
use tss_reel::orbit::Orbit;
use tss_reel::stability::{
    closed_loop_poles, equilibrium_stability, jacobian, jacobian_eigenvalues, swing_accelerations,
    Complex, FrozenCoefficients, SwingState, Verdict,
};

/// Dense sampling of θ over [−π, π] — in the tests only, to check the root finder.
const SAMPLES: usize = 200_000;

fn dense_min(e: f64, f: impl Fn(f64, f64) -> f64) -> (f64, f64) {
    let mut best = (f64::INFINITY, 0.0);
    for i in 0..=SAMPLES {
        let th = -PI + 2.0 * PI * i as f64 / SAMPLES as f64;
        let v = f(e, th);
        if v < best.0 {
            best = (v, th);
        }
    }
    best
}

// ---------------------------------------------------------------- Theorem 1, Figs. 2–3

#[test]
fn extent_is_widest_at_circular_orbit() {
    let c = extent(0.0_f64).unwrap();
    assert_eq!(c.min_depl.value, 1.5);
    assert_eq!(c.max_retr.value, -1.5);
}

#[test]
fn extent_shrinks_monotonically_and_vanishes_at_three_quarters() {
    let mut prev = f64::INFINITY;
    for i in 0..=750 {
        let e = i as f64 * 1e-3;
        let x = extent(e).unwrap();
        assert!(x.min_depl.value < prev, "not decreasing at e = {e}");
        assert_eq!(x.max_retr.value, -x.min_depl.value);
        assert!(x.min_depl.value >= -1e-12, "e = {e}");
        prev = x.min_depl.value;
    }
    assert!(extent(0.75_f64).unwrap().min_depl.value.abs() < 1e-12);
    // Beyond 0.75 no θ-independent range is left: max Retr > 0 > min Depl.
    let x = extent(0.8_f64).unwrap();
    assert!(x.min_depl.value < 0.0 && x.max_retr.value > 0.0);
}

#[test]
fn f2_is_minus_f1_of_minus_theta() {
    for i in 0..=100 {
        let e = i as f64 * 0.0099;
        for j in 0..=72 {
            let th = -PI + j as f64 * PI / 36.0;
            assert!((f2(e, th) + f1(e, -th)).abs() < 1e-15);
            assert!((retr(e, th) + depl(e, -th)).abs() < 1e-13);
            assert!((f2_derivative(e, th) - f1_derivative(e, -th)).abs() < 1e-15);
        }
    }
}

#[test]
fn extremum_is_not_at_apogee() {
    // The paper's proof evaluates at cosθ = −1; the true minimiser moves from −126.87° (e → 0)
    // to −90° (e = 0.75).
    for i in 1..=75 {
        let e = i as f64 * 0.01;
        let m = min_depl(e).unwrap();
        assert!(
            (m.anomaly_rad.abs() - PI).abs() > 0.5,
            "e = {e}: θ* = {}",
            m.anomaly_rad
        );
        assert!(m.value < depl(e, PI) - 1e-6, "e = {e}");
        assert!(m.iterations <= 12, "e = {e}: {} iterations", m.iterations);
    }
}

#[test]
fn root_finder_finds_the_global_extremum() {
    for i in 0..=40 {
        // e ∈ [0, 0.999], including the second branch above 0.75.
        let e = (i as f64 * 0.025).min(0.999);
        let m = min_depl(e).unwrap();
        let (v, th) = dense_min(e, depl);
        assert!(m.value <= v + 1e-12, "e = {e}: {} > sampled {v}", m.value);
        // The sampled minimum is within one sample step of θ* (F is flat at e = 0).
        if e > 0.0 {
            assert!(
                (th - m.anomaly_rad).abs() < 1e-3,
                "e = {e}: {th} vs {}",
                m.anomaly_rad
            );
        }
        assert!(f1_derivative(e, m.anomaly_rad).abs() < 1e-12, "e = {e}");
        // F1″ > 0 there: a minimum.
        let h = 1e-4;
        let curv = f1(e, m.anomaly_rad + h) - 2.0 * f1(e, m.anomaly_rad) + f1(e, m.anomaly_rad - h);
        assert!(e == 0.0 || curv > 0.0, "e = {e}");
        // Retr: the maximum, mirrored.
        let r = max_retr(e).unwrap();
        let (v, _) = dense_min(e, |e, th| -retr(e, th));
        assert!(r.value >= -v - 1e-12, "e = {e}");
        assert!(f2_derivative(e, r.anomaly_rad).abs() < 1e-12);
    }
}

#[test]
fn fig3_values_worked_by_hand() {
    // e = 0.3: θ* solves 2cosθ − 1.5 sinθ + 0.6 cos2θ = 0 in [−π, −π/2].
    let m = min_depl(0.3_f64).unwrap();
    let th = m.anomaly_rad;
    assert!((2.0 * th.cos() - 1.5 * th.sin() + 0.6 * (2.0 * th).cos()).abs() < 1e-12);
    assert!((-PI..=-FRAC_PI_2).contains(&th));
    let hand = (1.0 + 0.3 * th.cos()) * (1.5 + 0.6 * th.sin()) / 0.91_f64.powf(1.5);
    assert!((m.value - hand).abs() < 1e-14);
}

#[test]
fn extent_in_f32_matches_f64() {
    for i in 0..=75 {
        let e = i as f64 * 0.01;
        let a = min_depl(e as f32).unwrap();
        let b = min_depl(e).unwrap();
        assert!((f64::from(a.value) - b.value).abs() < 2e-6, "e = {e}");
    }
}

// ---------------------------------------------------------------- existence (Eqs. 7–15)

#[test]
fn eq7_equals_eq6_on_elliptic_orbit() {
    let orbit = Orbit::elliptic(8.0e6_f64, 0.4);
    let mass = MassModel {
        tether_density_kg_per_m: 1e-3,
        ..MassModel::paper()
    };
    for &th in &[-2.5, -1.0, 0.0, 0.7, 2.9] {
        for &rate in &[-3.0, 0.0, 1.5] {
            let c = FrozenCoefficients::from_orbit(&orbit, th, &mass, 20_000.0, rate).unwrap();
            let x = normalised_rate(c.mu3, c.length_rate_ratio_per_s, orbit.mean_motion_radps());
            let s7 = sin_two_alpha_e(0.4, th, x);
            assert!(
                (c.equilibrium_sin_two_alpha() - s7).abs() < 1e-12,
                "θ = {th}, l̇ = {rate}"
            );
        }
    }
}

#[test]
fn station_keeping_exists_everywhere_iff_e_at_most_three_quarters() {
    for &e in &[0.0, 0.3, 0.75] {
        assert!((0..=100).all(|i| station_keeping_exists(e, -PI + i as f64 * 0.0628)));
    }
    assert!(!station_keeping_exists(0.8, -FRAC_PI_2));
    let m = ExistenceMonitor::new(0.8_f64, 1e-3).unwrap();
    assert!(!m.check(Anomaly::WholeOrbit, 0.0, 0.0).unwrap().exists);
}

#[test]
fn monitor_matches_eq9_at_theta_and_eq13_over_orbit() {
    let orbit = Orbit::elliptic(7.5e6_f64, 0.2);
    let m = ExistenceMonitor::from_orbit(&orbit).unwrap();
    let w = orbit.mean_motion_radps();
    for i in -40..=40 {
        let ratio = i as f64 * 5e-5; // l̇/l, 1/s
        let x = normalised_rate(0.05, ratio, w);
        let whole = m.check(Anomaly::WholeOrbit, 0.05, ratio).unwrap();
        let everywhere = (0..=720).all(|j| {
            let th = -PI + j as f64 * PI / 360.0;
            in_plane_equilibria(0.2, th, x).is_some()
        });
        assert_eq!(
            whole.exists,
            everywhere || whole.margin.abs() < 1e-3,
            "l̇/l = {ratio}"
        );
        let at = m.check(Anomaly::At(1.0), 0.05, ratio).unwrap();
        assert_eq!(
            at.exists,
            in_plane_equilibria(0.2, 1.0, x).is_some(),
            "l̇/l = {ratio}"
        );
    }
}

// ---------------------------------------------------------------- random valid equilibria

/// A random equilibrium: orbit, θ, masses, l, a rate that admits an equilibrium at θ, and one of
/// the two α_e branches; β_e = 0 unless told.
#[derive(Debug, Clone)]
struct Case {
    orbit: Orbit<f64>,
    theta: f64,
    mass: MassModel<f64>,
    length_m: f64,
    rate_mps: f64,
    horizontal_branch: bool,
}

impl Case {
    fn coefficients(&self) -> FrozenCoefficients<f64> {
        FrozenCoefficients::from_orbit(
            &self.orbit,
            self.theta,
            &self.mass,
            self.length_m,
            self.rate_mps,
        )
        .unwrap()
    }
    fn alpha_e(&self) -> f64 {
        let c = self.coefficients();
        let x = normalised_rate(
            c.mu3,
            c.length_rate_ratio_per_s,
            self.orbit.mean_motion_radps(),
        );
        let eq = in_plane_equilibria(self.orbit.eccentricity, self.theta, x).unwrap();
        if self.horizontal_branch {
            eq.near_horizontal_rad
        } else {
            eq.near_vertical_rad
        }
    }
}

fn case() -> impl Strategy<Value = Case> {
    (
        6.6e6..4.2e7_f64,
        0.0..0.7_f64,
        -PI..PI,
        (100.0..20_000.0_f64, 10.0..2_000.0_f64, 0.0..1e-2_f64),
        10.0..100_000.0_f64,
        -0.999..0.999_f64,
        any::<bool>(),
    )
        .prop_map(
            |(a, e, theta, (m01, m2, rho), l, frac, horizontal_branch)| {
                let orbit = Orbit::elliptic(a, e);
                // Keep the tether lighter than the main satellite.
                let rho = rho.min(0.5 * m01 / l);
                let mass = MassModel {
                    main_initial_kg: m01,
                    sub_kg: m2,
                    tether_density_kg_per_m: rho,
                };
                let mu3 = mass.coefficients(l).mu3;
                // x anywhere inside [Retr, Depl] at θ (Eq. 9).
                let (lo, hi) = (retr(e, theta), depl(e, theta));
                let x = lo + 0.5 * (frac + 1.0) * (hi - lo);
                let rate_mps = x * orbit.mean_motion_radps() * l / (2.0 + mu3);
                Case {
                    orbit,
                    theta,
                    mass,
                    length_m: l,
                    rate_mps,
                    horizontal_branch,
                }
            },
        )
}

/// Max over the closed-form roots of the distance to the nearest unused eigenvalue, divided by
/// the largest |root|.
fn relative_mismatch<T: Into<f64> + Copy>(closed: [Complex<T>; 4], eig: [Complex<T>; 4]) -> f64 {
    let c: Vec<(f64, f64)> = closed.iter().map(|z| (z.re.into(), z.im.into())).collect();
    let mut e: Vec<(f64, f64)> = eig.iter().map(|z| (z.re.into(), z.im.into())).collect();
    let scale = c
        .iter()
        .map(|z| z.0.hypot(z.1))
        .fold(0.0, f64::max)
        .max(1e-300);
    let mut worst: f64 = 0.0;
    for z in c {
        let (i, d) = e
            .iter()
            .enumerate()
            .map(|(i, w)| (i, (z.0 - w.0).hypot(z.1 - w.1)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        e.remove(i);
        worst = worst.max(d / scale);
    }
    worst
}

fn closed_form_roots<T: tss_reel::Real>(c: &FrozenCoefficients<T>, a: T, b: T) -> [Complex<T>; 4] {
    let s = equilibrium_stability(c, a, b).unwrap();
    [
        s.in_plane.roots[0],
        s.in_plane.roots[1],
        s.out_of_plane.roots[0],
        s.out_of_plane.roots[1],
    ]
}

fn to_f32(c: &FrozenCoefficients<f64>) -> FrozenCoefficients<f32> {
    FrozenCoefficients {
        anomaly_rate_radps: c.anomaly_rate_radps as f32,
        anomaly_accel_radps2: c.anomaly_accel_radps2 as f32,
        gravity_gradient_per_s2: c.gravity_gradient_per_s2 as f32,
        length_rate_ratio_per_s: c.length_rate_ratio_per_s as f32,
        mu3: c.mu3 as f32,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, .. ProptestConfig::default() })]

    #[test]
    fn equilibrium_of_eq7_zeroes_eqs_5b_5c(case in case()) {
        let c = case.coefficients();
        let (aa, ba) = swing_accelerations(&c, &SwingState::at_rest(case.alpha_e(), 0.0)).unwrap();
        let scale = c.anomaly_rate_radps.powi(2);
        prop_assert!(aa.abs() < 1e-12 * scale, "α̈ = {aa}");
        prop_assert_eq!(ba, 0.0);
    }

    #[test]
    fn closed_form_roots_match_nalgebra_eigenvalues(case in case()) {
        let c = case.coefficients();
        let a = case.alpha_e();
        let eig = jacobian_eigenvalues(&c, &SwingState::at_rest(a, 0.0)).unwrap();
        let d = relative_mismatch(closed_form_roots(&c, a, 0.0), eig);
        prop_assert!(d < 1e-9, "f64 mismatch {d:e}");

        let c32 = to_f32(&c);
        let eig = jacobian_eigenvalues(&c32, &SwingState::at_rest(a as f32, 0.0)).unwrap();
        let d = relative_mismatch(closed_form_roots(&c32, a as f32, 0.0), eig);
        prop_assert!(d < 1e-4, "f32 mismatch {d:e}");
    }

    #[test]
    fn paper_conclusions_of_section_4(case in case(), beta_up in any::<bool>()) {
        let c = case.coefficients();
        let a = case.alpha_e();
        let b = if beta_up { FRAC_PI_2 } else { 0.0 };
        let s = equilibrium_stability(&c, a, b).unwrap();
        let (cos2a, cos2b) = ((2.0 * a).cos(), (2.0 * b).cos());
        let ratio = c.length_rate_ratio_per_s;
        // Skip the knife edges the linear analysis cannot decide.
        prop_assume!(cos2a.abs() > 1e-3 && ratio.abs() > 1e-4 * c.anomaly_rate_radps);
        if ratio < 0.0 {
            // (1) Retrieval is unstable.
            prop_assert_eq!(s.verdict, Verdict::Unstable);
        } else {
            // (2) Deployment is stable iff cos2α_e > 0 and cos2β_e > 0.
            let stable = cos2a > 0.0 && cos2b > 0.0;
            prop_assert_eq!(s.verdict == Verdict::Stable, stable, "{:?}", s);
            if !stable {
                prop_assert_eq!(s.verdict, Verdict::Unstable);
            }
        }
        // (3) Station keeping (same state, l̇ = 0) is marginal when cos2α_e, cos2β_e > 0.
        let keep = FrozenCoefficients { length_rate_ratio_per_s: 0.0, ..c };
        let s = equilibrium_stability(&keep, a, b).unwrap();
        if cos2a > 0.0 && cos2b > 0.0 {
            prop_assert_eq!(s.verdict, Verdict::Marginal);
            prop_assert!(s.in_plane.roots.iter().all(|z| z.re == 0.0 && z.im != 0.0));
            prop_assert!(s.in_plane.discriminant_per_s2 < 0.0 && s.out_of_plane.discriminant_per_s2 < 0.0);
        } else {
            prop_assert_eq!(s.verdict, Verdict::Unstable);
        }
    }

    #[test]
    fn jacobian_is_the_derivative_of_eqs_5b_5c(
        case in case(),
        alpha in -PI..PI,
        beta in -1.3..1.3_f64,
        rates in (-2.0..2.0_f64, -2.0..2.0_f64),
    ) {
        let c = case.coefficients();
        let n = c.anomaly_rate_radps;
        let x = SwingState { alpha_rad: alpha, alpha_rate_radps: rates.0 * n, beta_rad: beta, beta_rate_radps: rates.1 * n };
        let j = jacobian(&c, &x).unwrap();
        let f = |x: &SwingState<f64>| swing_accelerations(&c, x).unwrap();
        // Central differences, step 1e-6 of each coordinate's natural scale.
        let steps = [1e-6, 1e-6 * n, 1e-6, 1e-6 * n];
        for (col, h) in steps.iter().enumerate() {
            let bump = |s: f64| {
                let mut y = x;
                match col {
                    0 => y.alpha_rad += s,
                    1 => y.alpha_rate_radps += s,
                    2 => y.beta_rad += s,
                    _ => y.beta_rate_radps += s,
                }
                y
            };
            let (p, m) = (f(&bump(*h)), f(&bump(-*h)));
            let fd = [(p.0 - m.0) / (2.0 * h), (p.1 - m.1) / (2.0 * h)];
            let scale = n * n / if col % 2 == 0 { 1.0 } else { n };
            prop_assert!((j[1][col] - fd[0]).abs() < 1e-6 * scale * 30.0, "∂α̈ col {col}: {} vs {}", j[1][col], fd[0]);
            prop_assert!((j[3][col] - fd[1]).abs() < 1e-6 * scale * 30.0, "∂β̈ col {col}: {} vs {}", j[3][col], fd[1]);
        }
    }
}

#[test]
fn off_equilibrium_eigenvalues_have_the_right_trace() {
    // Off equilibrium (β ≠ 0, β̇ ≠ 0) the modes couple; the eigenvalues still sum to the trace,
    // −(k − 2β̇ tanβ) − k.
    let n = 1.06e-3;
    let c = FrozenCoefficients {
        anomaly_rate_radps: n,
        anomaly_accel_radps2: 0.0,
        gravity_gradient_per_s2: n * n,
        length_rate_ratio_per_s: 2e-4,
        mu3: 0.1,
    };
    let x = SwingState {
        alpha_rad: -0.3,
        alpha_rate_radps: 0.2 * n,
        beta_rad: 0.4,
        beta_rate_radps: 0.3 * n,
    };
    let ev = jacobian_eigenvalues(&c, &x).unwrap();
    let k = 2.1 * 2e-4;
    let trace = -(k - 2.0 * 0.3 * n * 0.4_f64.tan()) - k;
    let sum: f64 = ev.iter().map(|z| z.re).sum();
    assert!((sum - trace).abs() < 1e-12 * n, "{sum} vs {trace}");
    assert!(ev.iter().map(|z| z.im).sum::<f64>().abs() < 1e-12 * n);
}

// ---------------------------------------------------------------- §4 conclusions, worked cases

#[test]
fn paper_orbit_deployment_retrieval_and_keeping() {
    // R = 7078 km, massless tether, 10 km, ±2 m/s and 0.
    let orbit = Orbit::circular(7_078_000.0_f64);
    let mass = MassModel::paper();
    for (rate, expect) in [
        (2.0, Verdict::Stable),
        (-2.0, Verdict::Unstable),
        (0.0, Verdict::Marginal),
    ] {
        let c = FrozenCoefficients::from_orbit(&orbit, 0.0, &mass, 10_000.0, rate).unwrap();
        let a = in_plane_equilibria(
            0.0,
            0.0,
            normalised_rate(0.0, rate / 1e4, c.anomaly_rate_radps),
        )
        .unwrap()
        .near_vertical_rad;
        let s = equilibrium_stability(&c, a, 0.0).unwrap();
        assert_eq!(s.verdict, expect, "l̇ = {rate}");
    }
    // Hand value: l̇ = 2 m/s at 10 km: x = 2·2e-4/n = 0.377 273; sin2α_e = −(2/3)x = −0.251 515.
    let n = orbit.mean_motion_radps();
    let x = normalised_rate(0.0, 2e-4, n);
    assert!((x - 0.4e-3 / 1.060_237_230_236_363_5e-3).abs() < 1e-12);
    assert!((sin_two_alpha_e(0.0, 0.0, x) + 2.0 / 3.0 * x).abs() < 1e-15);
}

#[test]
fn paper_gains_closed_loop() {
    let cl = closed_loop_poles(0.0057_f64, 9.8696e-6).unwrap();
    assert!((cl.natural_frequency_radps / (PI * 1e-3) - 1.0).abs() < 1e-4);
    assert!((cl.damping_ratio - 0.907).abs() < 5e-4);
    assert_eq!(cl.poles.verdict, Verdict::Stable);
    let cl32 = closed_loop_poles(0.0057_f32, 9.8696e-6).unwrap();
    assert!((f64::from(cl32.damping_ratio) - cl.damping_ratio).abs() < 1e-6);
}

#[test]
fn worst_root_mismatch_over_a_deterministic_sweep() {
    // The same comparison as the proptest over a fixed grid, reporting the worst case
    // (`cargo test --test stability -- --nocapture`).
    let (mut worst64, mut worst32) = (0.0_f64, 0.0_f64);
    let mass = MassModel {
        tether_density_kg_per_m: 2e-3,
        ..MassModel::paper()
    };
    for &e in &[0.0, 0.2, 0.5, 0.7] {
        let orbit = Orbit::elliptic(7.0e6, e);
        for i in 0..12 {
            let theta = -PI + i as f64 * PI / 6.0;
            for j in 1..20 {
                let frac = j as f64 / 20.0;
                let x = retr(e, theta) + frac * (depl(e, theta) - retr(e, theta));
                let l = 15_000.0;
                let mu3 = mass.coefficients(l).mu3;
                let rate = x * orbit.mean_motion_radps() * l / (2.0 + mu3);
                let c = FrozenCoefficients::from_orbit(&orbit, theta, &mass, l, rate).unwrap();
                let eq = in_plane_equilibria(e, theta, x).unwrap();
                for a in [eq.near_vertical_rad, eq.near_horizontal_rad] {
                    let eig = jacobian_eigenvalues(&c, &SwingState::at_rest(a, 0.0)).unwrap();
                    worst64 = worst64.max(relative_mismatch(closed_form_roots(&c, a, 0.0), eig));
                    let c32 = to_f32(&c);
                    let eig =
                        jacobian_eigenvalues(&c32, &SwingState::at_rest(a as f32, 0.0)).unwrap();
                    worst32 = worst32.max(relative_mismatch(
                        closed_form_roots(&c32, a as f32, 0.0),
                        eig,
                    ));
                }
            }
        }
    }
    println!(
        "closed form vs nalgebra: worst relative mismatch f64 {worst64:.2e}, f32 {worst32:.2e}"
    );
    assert!(worst64 < 1e-9 && worst32 < 1e-4);
}
