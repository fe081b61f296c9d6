//! On-target tests: the library's arithmetic run on the Cortex-M4F itself (in f32, with the
//! FPU and libm as flown), in QEMU, by the defmt-test harness.
//!
//! Run with `cargo tt` (`cargo test --target thumbv7em-none-eabihf --features firmware --test
//! on_target`); the runner `scripts/qemu-run` boots the test ELF and decodes its log. Each
//! `#[test]` is one function in the `tests` module below; a failed `defmt::assert!` panics,
//! panic-probe turns that into a HardFault, and the HardFault handler (the firmware's own,
//! `tss_reel::firmware::exit`) exits QEMU with a failure, so a failing test fails the run at once.
//!
//! To add a test: add a `#[test] fn name() { … }` to `mod tests`, using `tss_reel`'s public API
//! and `defmt::assert!`. Tolerances are for f32 arithmetic.
//!
//! It needs the `firmware` feature (`required-features` in Cargo.toml; `cargo tt` passes it) and
//! the bare-metal target; the host's own tests of the same functions (in f64) are the library's
//! unit tests.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

// The firmware's runtime comes with `tss_reel` and its `firmware` feature, as in the firmware:
// the global logger (defmt over semihosting), the panic handler (panic-probe), and the
// HardFault handler that exits QEMU with a failure (`tss_reel::firmware::exit`).

/// Constants and helpers of the tests (defmt-test allows only test functions in `mod tests`).
mod support {
    use tss_reel::mass::MassModel;

    /// The paper's orbit radius, m (Section 6: R = 7078 km).
    pub const R_PAPER_M: f32 = 7_078_000.0;

    /// |a − b| ≤ rel·|b|.
    pub fn close_rel(a: f32, b: f32, rel: f32) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    /// A thin tether, ρ = 1e-3 kg/m, on the paper's satellites.
    pub fn thin_tether() -> MassModel<f32> {
        MassModel {
            tether_density_kg_per_m: 1e-3,
            ..MassModel::paper()
        }
    }
}

#[defmt_test::tests]
mod tests {
    use super::support::{close_rel, thin_tether, R_PAPER_M};
    use tss_reel::mass::MassModel;
    use tss_reel::orbit::circular_rate_radps;

    #[test]
    fn the_fpu_square_root_is_correctly_rounded() {
        // VSQRT.F32 (tss_fpu::sqrt on this target) against libm's f64 root rounded once to f32,
        // the correctly rounded one (53 ≥ 2·24 + 2): every 65 521st bit pattern from the
        // smallest subnormal to the largest finite float, and the special values.
        let mut bits = 1_u32;
        while bits < f32::MAX.to_bits() {
            let x = f32::from_bits(bits);
            let expected = libm::sqrt(f64::from(x)) as f32;
            defmt::assert_eq!(tss_fpu::sqrt(x).to_bits(), expected.to_bits());
            bits += 65_521;
        }
        defmt::assert_eq!(tss_fpu::sqrt(0.0).to_bits(), 0.0_f32.to_bits());
        defmt::assert_eq!(tss_fpu::sqrt(-0.0).to_bits(), (-0.0_f32).to_bits());
        defmt::assert_eq!(tss_fpu::sqrt(f32::INFINITY), f32::INFINITY);
        defmt::assert!(tss_fpu::sqrt(-1.0).is_nan());
        defmt::assert!(tss_fpu::sqrt(f32::NAN).is_nan());
    }

    #[test]
    fn orbit_rate_of_paper_orbit_in_f32() {
        // n = √(μ/R³) = 1.060 237 e-3 rad/s; f32 resolves ~1e-10 here.
        let n = circular_rate_radps::<f32>(R_PAPER_M);
        defmt::assert!((n - 1.060_237_2e-3).abs() < 1e-9, "n = {=f32} rad/s", n);
    }

    #[test]
    fn massless_tether_coefficients_at_30_km() {
        let c = MassModel::<f32>::paper().coefficients(30_000.0);
        defmt::assert_eq!(c.mu1, 0.0);
        defmt::assert_eq!(c.mu2, 1.0);
        defmt::assert_eq!(c.mu3, 0.0);
        defmt::assert_eq!(c.tether_kg, 0.0);
        // M* = m1 m2 / M = 1e6 / 10100 kg.
        defmt::assert!(
            close_rel(c.reduced_kg, 99.009_9, 1e-6),
            "M* = {=f32}",
            c.reduced_kg
        );
    }

    #[test]
    fn thin_tether_coefficients_at_30_km() {
        // Hand values (f64) from the library's unit test `thin_tether_at_30_km_matches_hand_values`.
        let c = thin_tether().coefficients(30_000.0);
        defmt::assert!(close_rel(c.mu3, 0.088_861_56, 1e-5), "mu3 = {=f32}", c.mu3);
        defmt::assert!(close_rel(c.mu1, 0.113_880_1, 1e-5), "mu1 = {=f32}", c.mu1);
        defmt::assert!(close_rel(c.mu2, 0.884_615_4, 1e-6), "mu2 = {=f32}", c.mu2);
        defmt::assert!(
            close_rel(c.reduced_kg, 108.690_59, 1e-6),
            "M* = {=f32}",
            c.reduced_kg
        );
        defmt::assert!(
            close_rel(c.total_kg, 10_100.0, 1e-7),
            "M = {=f32}",
            c.total_kg
        );
    }

    #[test]
    fn thin_tether_mu3_grows_with_length() {
        // μ3 = l (dM*/dl) / M* > 0 and increasing over the mission's range, 2 km to 30 km.
        let model = thin_tether();
        let mut previous = 0.0_f32;
        let mut length_m = 2_000.0_f32;
        while length_m <= 30_000.0 {
            let mu3 = model.coefficients(length_m).mu3;
            defmt::assert!(
                mu3.is_finite() && mu3 > previous,
                "mu3({=f32} m) = {=f32}",
                length_m,
                mu3
            );
            previous = mu3;
            length_m += 1_000.0;
        }
    }
    #[test]
    fn fast_sin_cos_matches_f64_on_the_fpu() {
        // The single-precision sin/cos the law uses, against libm's f64 on the target itself.
        let mut x = -6.5_f32;
        while x <= 6.5 {
            let (s, c) = tss_reel::fastmath::sin_cos(x);
            let xd = f64::from(x);
            let err = (f64::from(s) - libm::sin(xd))
                .abs()
                .max((f64::from(c) - libm::cos(xd)).abs());
            defmt::assert!(err < 1.5e-7, "x = {=f32}: error {=f64}", x, err);
            x += 0.0137;
        }
    }

    #[test]
    fn blend_weight_and_complement_match_f64_on_the_fpu() {
        // 2^t and 1 − 2^t of the blend (fastmath::exp2_and_complement, t = −cτ·log₂e) on its
        // fast range, and e^x and 1 − e^x (fastmath::exp_and_complement) on the decay range,
        // against libm's f64 on the target itself, each within two ulps of its own size.
        let ulps =
            |got: f32, exact: f64| (got.to_bits() as i64 - (exact as f32).to_bits() as i64).abs();
        let mut t = -126.0_f32;
        while t < 0.0 {
            let (e, c) = tss_reel::fastmath::exp2_and_complement(t);
            let td = f64::from(t);
            let exact_c = -libm::expm1(td * core::f64::consts::LN_2);
            let (ue, uc) = (ulps(e, libm::exp2(td)), ulps(c, exact_c));
            defmt::assert!(
                ue <= 2 && uc <= 2,
                "t = {=f32}: {=i64} and {=i64} ulps",
                t,
                ue,
                uc
            );
            t = if t < -1.0 { t + 0.0731 } else { t * 0.9 };
            if t > -1e-6 {
                break;
            }
        }
        let mut x = -87.0_f32;
        while x < 0.0 {
            let (e, c) = tss_reel::fastmath::exp_and_complement(x);
            let xd = f64::from(x);
            let (ue, uc) = (ulps(e, libm::exp(xd)), ulps(c, -libm::expm1(xd)));
            defmt::assert!(
                ue <= 2 && uc <= 2,
                "x = {=f32}: {=i64} and {=i64} ulps",
                x,
                ue,
                uc
            );
            // Dense near 0, where the complement would lose its digits to cancellation.
            x = if x < -1.0 { x + 0.0731 } else { x * 0.9 };
            if x > -1e-6 {
                break;
            }
        }
    }

    #[test]
    fn quintic_transition_meets_its_end_conditions_in_f32() {
        let s = tss_reel::schedule::BandSchedule::<f32>::paper_stage1();
        let lo = s.eval(10_000.0 + 1e-3);
        let hi = s.eval(30_000.0 - 1e-3);
        defmt::assert!((lo.angle_rad + core::f32::consts::FRAC_PI_4).abs() < 1e-6);
        defmt::assert!(lo.slope_rad_per_m.abs() < 1e-9);
        defmt::assert!(hi.angle_rad.abs() < 1e-6);
        defmt::assert!((hi.slope_rad_per_m - core::f32::consts::PI * 1e-5).abs() < 1e-9);
    }

    #[test]
    fn implicit_law_residual_is_zero_in_f32() {
        // Substituting the command back into Eqs. 27 + 29 gives it back (docs/equations.md §5).
        use tss_reel::law::{solve, Blend, Gains, LawInput};
        let x = LawInput {
            length_m: 15_000.0_f32,
            alpha_rad: -0.6,
            alpha_rate_radps: 1.0e-4,
            orbit_rate_radps: 1.060_237_2e-3,
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
        };
        let Ok(s) = solve(&x) else {
            defmt::panic!("no solution");
        };
        let dd = x.alpha_rate_radps - x.ref_slope_rad_per_m * s.rate_mps;
        let n = x.orbit_rate_radps;
        let u = (x.gains.k1_per_s * dd + x.gains.k2_per_s2 * s.delta_rad
            - 1.5 * n * n * libm::sinf(2.0 * x.alpha_rad))
            / (n + dd)
            * x.length_m
            / 2.0;
        let blended = u + (x.initial_rate_mps - u) * x.blend.weight;
        defmt::assert!(
            (blended - s.rate_mps).abs() <= 1e-4 * s.rate_mps.abs(),
            "y = {=f32}, Eq. 29 gives {=f32}",
            s.rate_mps,
            blended
        );
    }

    #[test]
    fn controller_never_commands_outside_the_envelope_on_garbage() {
        use tss_reel::controller::{Config, Controller, Input};
        let cfg = Config::<f32>::paper();
        let mut ctl = defmt::unwrap!(Controller::new(cfg).ok());
        let junk = [
            f32::NAN,
            f32::INFINITY,
            -f32::INFINITY,
            1e-40,
            -1.0,
            3.0e38,
            0.0,
        ];
        let mut tick = 0;
        for &a in &junk {
            for &b in &junk {
                let o = ctl.step(&Input {
                    tick,
                    length_m: a,
                    reel_rate_mps: None,
                    tension_n: None,
                    alpha_rad: Some(b),
                    alpha_rate_radps: Some(a),
                    orbit_rate_radps: b,
                    true_anomaly_rad: 0.0,
                });
                defmt::assert!(o.rate_cmd_mps.is_finite());
                defmt::assert!(o.rate_cmd_mps.abs() <= cfg.envelope.max_rate_mps);
                tick += 1;
            }
        }
    }
}
