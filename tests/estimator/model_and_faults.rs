//! The filter's model and its faults: gated outliers, a lasting step in α, dropouts of any
//! length, one period against the plant, the discretisation error, eccentric orbits, a
//! constant sensor bias, any bits of input (property tests) and a quantised sensor.

use super::*;

#[test]
fn gating_rejects_injected_outliers() {
    // Every 250th sample (from 600 s) is off by 0.01 rad = 100 σ_α: each is gated, nothing
    // else is beyond the clean run's own (the χ² gate's 6e-5 false-alarm rate), and the
    // estimate is bit for bit the one of a run where those samples never arrived.
    let flight = nominal();
    let outlier = |k: usize| k >= SETTLE_TICKS && k.is_multiple_of(250);
    #[derive(Clone, Copy, PartialEq)]
    enum Fault {
        None,
        Outliers,
        Dropped,
    }
    let run = |fault: Fault| {
        let mut estimates = Vec::with_capacity(flight.len());
        let mut gated = Vec::new();
        filter::<f32>(
            Config::paper(),
            flight,
            1e-4,
            11,
            &mut |k, z| match fault {
                Fault::Outliers if outlier(k) => Some(z + 0.01),
                Fault::Dropped if outlier(k) => None,
                _ => Some(z),
            },
            &mut |k, _, o| {
                if let Measurement::Gated(i) = o.measurement {
                    gated.push((k, i.nis));
                }
                assert!(!matches!(o.measurement, Measurement::Reinitialised(_)));
                estimates.push(o.estimate.expect("estimate"));
            },
        );
        (estimates, gated)
    };
    let (_, clean_gated) = run(Fault::None);
    let (dirty, dirty_gated) = run(Fault::Outliers);
    let (dropped, _) = run(Fault::Dropped);
    let injected = (0..flight.len()).filter(|&k| outlier(k)).count();
    let caught = dirty_gated.iter().filter(|(k, _)| outlier(*k)).count();
    let others: Vec<_> = dirty_gated.iter().filter(|(k, _)| !outlier(*k)).collect();
    let least_nis = dirty_gated
        .iter()
        .filter(|(k, _)| outlier(*k))
        .map(|(_, n)| *n)
        .fold(f32::INFINITY, f32::min);
    eprintln!(
        "gating: {caught} of {injected} outliers of 100 σ rejected (least NIS {least_nis:.0}); \
         {} other samples gated ({} in the clean run)",
        others.len(),
        clean_gated.len()
    );
    assert_eq!(caught, injected);
    assert!(others.len() <= clean_gated.len() + 2, "{others:?}");
    assert!(dirty == dropped, "a gated sample is not a missing one");
}

#[test]
fn a_step_in_the_sensed_angle_restarts_alpha_after_the_gate_gives_up() {
    // A 0.05 rad jump of the sensor (a re-mounted or re-zeroed sensor) at 5 h: the filter
    // rejects it `max_rejections` times, then restarts α on it and keeps tracking.
    let flight = nominal();
    let jump_at = 18_000;
    let mut outcomes = Vec::new();
    let mut worst_rate_err_after = 0.0_f64;
    filter::<f32>(
        Config::paper(),
        flight,
        1e-4,
        13,
        &mut |k, z| Some(if k >= jump_at { z + 0.05 } else { z }),
        &mut |k, t, o| {
            if (jump_at..jump_at + 12).contains(&k) {
                outcomes.push(o.measurement);
            }
            if k >= jump_at + 1_800 && k < STAGE2_S {
                let e = o.estimate.expect("estimate");
                worst_rate_err_after = worst_rate_err_after.max(error(&e, t)[1].abs());
            }
        },
    );
    let max = Config::<f32>::paper().max_rejections as usize;
    assert!(outcomes[..max]
        .iter()
        .all(|m| matches!(m, Measurement::Gated(_))));
    assert!(matches!(outcomes[max], Measurement::Reinitialised(_)));
    assert!(matches!(outcomes[max + 1], Measurement::Accepted(_)));
    eprintln!("after a 0.05 rad sensor step: worst α̇ error from 30 min later {worst_rate_err_after:.2e} rad/s");
    assert!(worst_rate_err_after < 3e-7);
}

#[test]
fn dropouts_grow_the_covariance_and_recover() {
    // A 10-minute dropout in each phase: the α̇ variance grows monotonically through it, the
    // truth stays within 5σ of the estimate throughout, and 20 minutes after the dropout the
    // variance is back within 5 % of a run without dropouts.
    let flight = nominal();
    let starts = [5_000, 12_000, 29_000, 33_000, 60_000];
    let len = 600;
    let missing = |k: usize| starts.iter().any(|&s| (s..s + len).contains(&k));
    let run = |drop: bool| {
        let mut var = vec![0.0_f32; flight.len()];
        let mut worst_sigmas = 0.0_f64;
        filter::<f32>(
            Config::paper(),
            flight,
            1e-4,
            17,
            &mut |k, z| (!(drop && missing(k))).then_some(z),
            &mut |k, t, o| {
                let e = o.estimate.expect("an estimate through the dropout");
                if drop && missing(k) {
                    assert_eq!(o.measurement, Measurement::Missing);
                    assert_eq!(o.prediction, Prediction::Predicted);
                }
                var[k] = e.alpha_rate_var_rad2ps2;
                if k >= SETTLE_TICKS {
                    let err = error(&e, t)[1].abs();
                    let sig = err / f64::from(e.alpha_rate_var_rad2ps2).sqrt();
                    worst_sigmas = worst_sigmas.max(sig);
                }
            },
        );
        (var, worst_sigmas)
    };
    let (clean, _) = run(false);
    let (var, worst_sigmas) = run(true);
    for &s in &starts {
        let (before, grown) = (var[s - 1], var[s + len - 1]);
        assert!(
            var[s..s + len].windows(2).all(|w| w[1] >= w[0]),
            "not monotone from {s} s"
        );
        let k = s + len + 1_200;
        eprintln!(
            "dropout {s}–{} s: σ_α̇ {:.2e} → {:.2e} rad/s; 20 min after {:.2e} (no dropout: {:.2e})",
            s + len,
            before.sqrt(),
            grown.sqrt(),
            var[k].sqrt(),
            clean[k].sqrt()
        );
        assert!(grown > 4.0 * before);
        assert!(
            (var[k] / clean[k] - 1.0).abs() < 0.05,
            "{} {}",
            var[k],
            clean[k]
        );
    }
    eprintln!("largest |α̇ error| / σ_α̇ over the mission with dropouts: {worst_sigmas:.2}");
    assert!(worst_sigmas < 5.0);
}

#[test]
fn updates_after_dropouts_of_any_length_keep_the_covariance_positive_definite() {
    // The first samples after a dropout meet P_αα far above R and α, α̇ and d strongly
    // correlated (d's growing uncertainty drives them alike): where the update's rounding is
    // most at stake. At a keep and during a deployment, after dropouts from a minute to half a
    // day, every update leaves the covariance positive definite in f32.
    let n = N as f32;
    let drives = [(30_000.0_f32, 0.0_f32), (2_000.0, 2.0)].map(|(l, v)| Drive {
        length_m: l,
        rate_mps: v,
        accel_mps2: 0.0,
        orbit: OrbitTerms::circular(n).expect("in range"),
        mu3: 0.0,
    });
    let mut strongest = 0.0_f64;
    for drive in drives {
        for dropout_s in [60, 600, 3_600, 4 * 3_600, 12 * 3_600] {
            let mut est = Estimator::<f32>::new(Config::paper()).expect("valid");
            for _ in 0..600 {
                est.step(&drive, Some(0.0));
            }
            for _ in 0..dropout_s {
                est.step(&drive, None);
            }
            let e = est.estimate().expect("estimate kept");
            let p = covariance(&e);
            strongest = strongest.max((p[0][1] / (p[0][0] * p[1][1]).sqrt()).abs());
            for _ in 0..600 {
                let e = est.step(&drive, Some(0.0)).estimate.expect("estimate kept");
                assert!(positive_definite(&e), "{dropout_s} s at {drive:?}: {e:?}");
            }
        }
    }
    eprintln!("largest |corr(α, α̇)| at a dropout's end: {strongest:.9}");
}

#[test]
fn a_dropout_of_days_stays_bounded_in_f32() {
    // Two days without a sample at the 30 km keep (reel still), then samples again: every
    // variance stays at or below its cap, finite, and the filter tracks again.
    let mut est = Estimator::<f32>::new(Config::paper()).expect("valid");
    let keep = Drive {
        length_m: 30_000.0,
        rate_mps: 0.0,
        accel_mps2: 0.0,
        orbit: OrbitTerms::circular(N as f32).expect("in range"),
        mu3: 0.0,
    };
    est.step(&keep, Some(0.01));
    let cfg = Config::<f32>::paper();
    for _ in 0..2 * 86_400 {
        let out = est.step(&keep, None);
        let e = out.estimate.expect("estimate kept");
        assert!(e.alpha_var_rad2 <= 1.0);
        assert!(e.alpha_rate_var_rad2ps2 <= cfg.initial_rate_std_radps.powi(2));
        assert!(e.disturbance_var_rad2ps4 <= cfg.initial_disturbance_std_radps2.powi(2));
        assert!(e.alpha_rad.is_finite() && e.alpha_rate_radps.is_finite());
        assert!(positive_definite(&e), "{e:?}");
    }
    let e = est.estimate().expect("estimate");
    eprintln!("after two days without samples: {e:?}");
    // The updates that follow start from P_αα a million times R and correlations near one,
    // where the update's rounding is most at stake: the covariance stays positive definite.
    for _ in 0..600 {
        let e = est.step(&keep, Some(0.0)).estimate.expect("estimate kept");
        assert!(positive_definite(&e), "{e:?}");
    }
    let e = est.estimate().expect("estimate");
    assert!(
        e.alpha_rad.abs() < 1e-3 && e.alpha_rate_radps.abs() < 1e-5,
        "{e:?}"
    );
}

#[test]
fn one_period_matches_the_plant() {
    // The filter's one-period prediction (Taylor series of φ₁, s at mid-period) against the
    // plant (Eq. 5b, the same model) integrated with 1 000 RK4 substeps, from states along the
    // mission: the release, early deployment, 9 km, the 30 km keep, retrieval.
    let sc = paper_scenario();
    let plant: RigidModel = sim::plant(&sc);
    let cases = [
        (1.0, 0.1, -0.61, 0.0),
        (20.0, 0.3, -1.2, -8e-4),
        (9_000.0, 1.5, -0.78, 2e-5),
        (30_000.0, 0.0, 0.05, 1e-4),
        (8_000.0, -4.0, 0.31, 3e-4),
    ];
    let mut results = Vec::new();
    for (l, v, alpha, rate) in cases {
        let mut est = Estimator::<f64>::new(Config::paper()).expect("valid");
        est.initialise(alpha, rate).expect("a state");
        let drive = Drive {
            length_m: l,
            rate_mps: v,
            accel_mps2: 0.0,
            orbit: OrbitTerms::circular(N).expect("in range"),
            mu3: 0.0,
        };
        let e = est.step(&drive, None).estimate.expect("predicted");
        let mut x = State::from([0.0, l, alpha, rate, 0.0, 0.0]);
        for _ in 0..1_000 {
            x = plant.rk4_step(&x, v, 1e-3);
        }
        let (da, dw) = (
            e.alpha_rad - x[ix::ALPHA],
            e.alpha_rate_radps - x[ix::ALPHA_RATE],
        );
        let step = (x[ix::ALPHA_RATE] - rate).abs();
        eprintln!(
            "one period at l = {l} m, l̇ = {v} m/s: α error {da:.2e} rad, α̇ error {dw:.2e} rad/s \
             (the α̇ change is {step:.2e} rad/s)"
        );
        results.push((l, da, dw, step));
    }
    for (l, da, dw, step) in results {
        // At release (l = 1 m, |s h| = 0.19) the step is good to 1e-3 of the α̇ change and to
        // 2 % of σ_α (at 20 m, to 2e-5 and 1e-4); from 100 m on, to 1e-10 rad and 1e-13 rad/s,
        // far below the estimate's own noise.
        if l < 100.0 {
            assert!(
                da.abs() < 2e-6 && dw.abs() < 1e-3 * step,
                "l = {l}: {da:e} {dw:e}"
            );
        } else {
            assert!(
                da.abs() < 1e-10 && dw.abs() < 1e-13,
                "l = {l}: {da:e} {dw:e}"
            );
        }
    }
}

#[test]
fn the_discretisation_error_against_the_period() {
    // One prediction over periods of 1 to 10 s against the plant integrated in 1 ms RK4 steps,
    // from the early deployment (l = 100 m, l̇ = 2 m/s: |s h| = 0.04 … 0.4) and the 9 km
    // deployment (l̇ = 1.5 m/s): the error grows as h³ (the midpoint rule for s and the
    // local-linearisation step are second order).
    let sc = paper_scenario();
    let plant: RigidModel = sim::plant(&sc);
    for (l, v, alpha, rate) in [(100.0, 2.0, -0.9, -6e-4), (9_000.0, 1.5, -0.78, 2e-5)] {
        let mut previous: Option<(f64, f64, f64)> = None;
        for h in [1.0, 2.0, 5.0, 10.0] {
            let cfg = Config {
                period_s: h,
                ..Config::<f64>::paper()
            };
            let mut est = Estimator::new(cfg).expect("valid");
            est.initialise(alpha, rate).expect("a state");
            let drive = Drive {
                length_m: l,
                rate_mps: v,
                accel_mps2: 0.0,
                orbit: OrbitTerms::circular(N).expect("in range"),
                mu3: 0.0,
            };
            let e = est.step(&drive, None).estimate.expect("predicted");
            let mut x = State::from([0.0, l, alpha, rate, 0.0, 0.0]);
            let steps = (h * 1_000.0).round() as u32;
            for _ in 0..steps {
                x = plant.rk4_step(&x, v, h / f64::from(steps));
            }
            let da = (e.alpha_rad - x[ix::ALPHA]).abs();
            let dw = (e.alpha_rate_radps - x[ix::ALPHA_RATE]).abs();
            eprintln!(
                "h = {h:4} s at l = {l} m, l̇ = {v} m/s: α error {da:9.2e} rad, α̇ error {dw:9.2e} \
                 rad/s"
            );
            if h == 1.0 {
                assert!(da < 1e-7 && dw < 1e-9, "{da:e} {dw:e}");
            }
            if let Some((h0, da0, dw0)) = previous {
                // No faster than cubic growth (a margin of 2 for the series' higher terms).
                let cubic = 2.0 * (h / h0).powi(3);
                assert!(da <= cubic * da0 + 1e-12, "{da:e} after {da0:e}");
                assert!(dw <= cubic * dw0 + 1e-15, "{dw:e} after {dw0:e}");
            }
            previous = Some((h, da, dw));
        }
    }
}

#[test]
fn an_eccentric_orbit_needs_its_orbit_terms_in_the_drive() {
    // The paper's mission (stage 1) on an orbit of eccentricity 1e-3, the drive giving the
    // true θ̇, θ̈ and μ/R³: α̇̂ keeps its circular-orbit accuracy. Given the circular model's
    // terms instead (θ̈ = 0, μ/R³ = θ̇²: θ̈ up to 2e θ̇² = 2.2e-9 rad/s² left to d), its error
    // grows several times.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/paper.toml");
    let sc = Scenario::load(&path, &["orbit.eccentricity=1e-3".to_string()]).expect("loads");
    let flight = fly_scenario(&sc, 28_800.0, None);
    let circular: Vec<Tick> = flight
        .iter()
        .map(|t| Tick {
            orbit_accel_radps2: 0.0,
            gravity_gradient_per_s2: t.orbit_rate_radps * t.orbit_rate_radps,
            ..*t
        })
        .collect();
    let run = |ticks: &[Tick]| {
        let (mut sum2, mut n) = (0.0, 0.0);
        filter::<f64>(
            Config::paper(),
            ticks,
            1e-4,
            31,
            &mut |_, z| Some(z),
            &mut |k, t, o| {
                if k >= 3_600 {
                    sum2 += error(&o.estimate.expect("estimate"), t)[1].powi(2);
                    n += 1.0;
                }
            },
        );
        (sum2 / n).sqrt()
    };
    let (exact, approximate) = (run(&flight), run(&circular));
    eprintln!(
        "eccentricity 1e-3, stage 1 from 1 h: α̇ error RMS {exact:.2e} rad/s with θ̈ and μ/R³ \
         in the drive, {approximate:.2e} rad/s with the circular model's"
    );
    assert!(exact < 1e-7, "{exact:e}");
    assert!(approximate > 2.0 * exact, "{approximate:e}");
}

#[test]
fn a_constant_sensor_bias_leaves_the_rate_unbiased() {
    // A 1e-3 rad α bias: α̂ reads α + b (unobservable from α alone, see the module docs), while
    // d̂ absorbs the stiffness mismatch and α̇̂ keeps its accuracy. The same filter without its
    // disturbance state (d's drift and prior at their floors) lets the bias into α̇̂.
    let flight = nominal();
    let bias = 1e-3_f32;
    let run = |cfg: Config<f32>| {
        let (mut rate_sum, mut rate_sum2, mut alpha_sum, mut n) = (0.0, 0.0, 0.0, 0.0);
        filter::<f32>(
            cfg,
            flight,
            1e-4,
            19,
            &mut |_, z| Some(z + bias),
            &mut |k, t, o| {
                if (3_600..STAGE2_S).contains(&k) {
                    let err = error(&o.estimate.expect("estimate"), t);
                    alpha_sum += err[0];
                    rate_sum += err[1];
                    rate_sum2 += err[1] * err[1];
                    n += 1.0;
                }
            },
        );
        (alpha_sum / n, rate_sum / n, (rate_sum2 / n).sqrt())
    };
    let (alpha_mean, rate_mean, rate_rms) = run(Config::paper());
    let (_, rate_mean_without, rate_rms_without) = run(Config {
        disturbance_drift_density: 1e-14,
        initial_disturbance_std_radps2: 1e-12,
        ..Config::paper()
    });
    eprintln!(
        "α bias 1e-3 rad, stage 1 from 1 h: mean α̂ − α {alpha_mean:.3e} rad; α̇ error mean \
         {rate_mean:.2e}, RMS {rate_rms:.2e} rad/s; without d: mean {rate_mean_without:.2e}, \
         RMS {rate_rms_without:.2e} rad/s"
    );
    assert!((alpha_mean - 1e-3).abs() < 1e-4);
    assert!(rate_rms < 1e-7 && rate_mean.abs() < 2e-8);
    assert!(rate_rms_without > 2.0 * rate_rms);
}

/// Any f32 at all, by bit pattern (NaN with any payload, ±∞, subnormals, ±0, huge values).
fn any_bits() -> impl Strategy<Value = f32> {
    any::<u32>().prop_map(f32::from_bits)
}

/// Half the time any bit pattern, half the time a value in a plausible range.
fn field(lo: f32, hi: f32) -> impl Strategy<Value = f32> {
    prop_oneof![any_bits(), lo..hi]
}

/// One period's input: the drive and the sample (or a dropout).
fn period() -> impl Strategy<Value = (Drive<f32>, Option<f32>)> {
    let orbit = (
        field(1.0e-3, 1.2e-3),
        prop_oneof![Just(0.0_f32), field(-3e-9, 3e-9)],
        field(1.0e-6, 1.5e-6),
    );
    (
        field(0.5, 40_000.0),
        field(-15.0, 15.0),
        prop_oneof![Just(0.0_f32), field(-1.0, 1.0)],
        orbit,
        prop_oneof![Just(0.0_f32), field(-0.1, 0.1)],
        proptest::option::weighted(0.9, field(-1.6, 1.6)),
    )
        .prop_map(|(length_m, rate_mps, accel_mps2, orbit, mu3, z)| {
            // Orbit terms out of range cannot be built ([`OrbitTerms`]'s own tests).
            let orbit = OrbitTerms::new(orbit.0, orbit.1, orbit.2)
                .unwrap_or_else(|_| OrbitTerms::circular(1.06e-3).expect("in range"));
            let drive = Drive {
                length_m,
                rate_mps,
                accel_mps2,
                mu3,
                orbit,
            };
            (drive, z)
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// Whatever the drive and the samples, every output is typed and every estimate finite,
    /// with variances in [0, cap] and a rate inside the admitted range.
    #[test]
    fn any_input_gives_a_typed_rejection_or_a_finite_estimate(
        periods in proptest::collection::vec(period(), 1..120)
    ) {
        let cfg = Config::<f32>::paper();
        let mut est = Estimator::new(cfg).expect("valid");
        let caps = [
            1.0,
            cfg.initial_rate_std_radps * cfg.initial_rate_std_radps,
            cfg.initial_disturbance_std_radps2 * cfg.initial_disturbance_std_radps2,
        ];
        for (drive, z) in &periods {
            let out = est.step(drive, *z);
            match (out.prediction, out.estimate) {
                (Prediction::InvalidDrive(_) | Prediction::Diverged | Prediction::NoEstimate, _)
                | (Prediction::Predicted, Some(_)) => {}
                (p, e) => prop_assert!(false, "{p:?} with {e:?}"),
            }
            if let Measurement::Accepted(i) | Measurement::Gated(i) | Measurement::Reinitialised(i) =
                out.measurement
            {
                prop_assert!(i.nis.is_finite() && i.nis >= 0.0 && i.variance_rad2 > 0.0, "{i:?}");
            }
            if let Some(e) = out.estimate {
                let values = [
                    e.alpha_rad, e.alpha_rate_radps, e.disturbance_radps2,
                    e.alpha_rate_cov_rad2ps, e.alpha_disturbance_cov_rad2ps2,
                    e.rate_disturbance_cov_rad2ps3,
                ];
                prop_assert!(values.iter().all(|v| v.is_finite()), "{e:?}");
                prop_assert!(e.alpha_rate_radps.abs() <= 1.0, "{e:?}");
                let vars = [e.alpha_var_rad2, e.alpha_rate_var_rad2ps2, e.disturbance_var_rad2ps4];
                for (v, cap) in vars.iter().zip(&caps) {
                    prop_assert!(*v >= 0.0 && *v <= *cap, "{e:?}");
                }
                prop_assert!(positive_definite(&e), "{e:?}");
            }
        }
    }

    /// Any configuration is either refused with the name of a parameter or makes a filter.
    #[test]
    fn any_configuration_is_named_or_valid(
        values in proptest::collection::vec(field(0.0, 1.0), 8),
        max_rejections in any::<u16>(),
    ) {
        let cfg = Config {
            period_s: values[0],
            alpha_noise_rad: values[1],
            alpha_quantum_rad: values[2],
            accel_noise_density: values[3],
            disturbance_drift_density: values[4],
            initial_rate_std_radps: values[5],
            initial_disturbance_std_radps2: values[6],
            gate_nis: values[7],
            max_rejections,
        };
        match Estimator::new(cfg) {
            Ok(mut est) => {
                let orbit = OrbitTerms::circular(1.06e-3).expect("in range");
                let d = Drive { length_m: 9_000.0, rate_mps: 1.0, accel_mps2: 0.0, mu3: 0.0,
                                orbit };
                for _ in 0..10 {
                    let out = est.step(&d, Some(-0.78));
                    let e = out.estimate.expect("estimate");
                    prop_assert!(e.alpha_rate_radps.is_finite() && e.alpha_var_rad2 >= 0.0);
                }
            }
            Err(e) => {
                let inside = e.value >= e.min && e.value <= e.max;
                prop_assert!(!e.param.is_empty() && !inside, "{e:?}");
            }
        }
    }
}

#[test]
fn a_quantised_sensor_is_covered_by_its_quantum() {
    // A sensor quantised to 2e-4 rad on top of its 1e-4 rad noise (which dithers it): with
    // the quantum configured (R = σ² + q²/12), the NIS still averages 1 and α̇ keeps its
    // accuracy; without it, the NIS shows the mistuning.
    let flight = nominal();
    let quantum = 2e-4_f64;
    let run = |configured: bool| {
        let cfg = Config {
            alpha_quantum_rad: if configured { quantum } else { 0.0 },
            ..Config::<f64>::paper()
        };
        let (mut nis, mut rate2, mut n) = (0.0, 0.0, 0.0);
        filter::<f64>(
            cfg,
            flight,
            1e-4,
            23,
            &mut |_, z| Some((z / quantum).round() * quantum),
            &mut |k, t, o| {
                if k >= SETTLE_TICKS {
                    if let Measurement::Accepted(i) | Measurement::Gated(i) = o.measurement {
                        nis += i.nis;
                    }
                    rate2 += error(&o.estimate.expect("estimate"), t)[1].powi(2);
                    n += 1.0;
                }
            },
        );
        (nis / n, (rate2 / n).sqrt())
    };
    let (with, rate_rms) = run(true);
    let (without, _) = run(false);
    eprintln!(
        "quantum 2e-4 rad: mean NIS {with:.3} configured, {without:.3} not; α̇ error RMS \
         {rate_rms:.2e} rad/s"
    );
    assert!((with - 1.0).abs() < 0.05, "{with}");
    assert!(without > 1.2, "{without}");
    assert!(rate_rms < 1e-7);
}
