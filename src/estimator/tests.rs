//! Unit tests of the filter's parts (the closed-loop and statistical proofs are in
//! tests/estimator.rs).

use super::*;

const N: f64 = 1.060_237_230_236_363_5e-3;

fn drive(length_m: f64, rate_mps: f64) -> Drive<f64> {
    Drive {
        length_m,
        rate_mps,
        accel_mps2: 0.0,
        mu3: 0.0,
        orbit: OrbitTerms::circular(N).unwrap(),
    }
}

#[test]
fn every_invalid_parameter_is_named() {
    let ok = Config::<f64>::paper();
    assert!(Estimator::new(ok).is_ok());
    type Edit = fn(&mut Config<f64>, f64);
    let cases: [(&str, Edit); 8] = [
        ("period_s", |c, v| c.period_s = v),
        ("alpha_noise_rad", |c, v| c.alpha_noise_rad = v),
        ("alpha_quantum_rad", |c, v| c.alpha_quantum_rad = v),
        ("accel_noise_density", |c, v| c.accel_noise_density = v),
        ("disturbance_drift_density", |c, v| {
            c.disturbance_drift_density = v
        }),
        ("initial_rate_std_radps", |c, v| {
            c.initial_rate_std_radps = v
        }),
        ("initial_disturbance_std_radps2", |c, v| {
            c.initial_disturbance_std_radps2 = v
        }),
        ("gate_nis", |c, v| c.gate_nis = v),
    ];
    for (name, edit) in cases {
        for bad in [f64::NAN, f64::INFINITY, -1.0, 1e9] {
            let mut c = ok;
            edit(&mut c, bad);
            let e = Estimator::new(c).unwrap_err();
            assert_eq!(e.param, name, "{bad}");
            assert!(e.value.is_nan() == bad.is_nan());
        }
    }
    let c = Config {
        max_rejections: 0,
        ..ok
    };
    assert_eq!(Estimator::new(c).unwrap_err().param, "max_rejections");
}

#[test]
fn orbit_terms_out_of_range_are_refused_when_built() {
    let refused = |r: Result<OrbitTerms<f64>, DriveError>| r.unwrap_err().input;
    let max = MAX_ORBIT_RATE_RADPS;
    assert_eq!(
        refused(OrbitTerms::new(0.0, 0.0, N * N)),
        DriveInput::OrbitRate
    );
    assert_eq!(
        refused(OrbitTerms::new(2.0 * max, 0.0, N * N)),
        DriveInput::OrbitRate
    );
    assert_eq!(
        refused(OrbitTerms::new(f64::NAN, 0.0, N * N)),
        DriveInput::OrbitRate
    );
    assert_eq!(
        refused(OrbitTerms::new(N, f64::NAN, N * N)),
        DriveInput::OrbitAccel
    );
    assert_eq!(
        refused(OrbitTerms::new(N, 2.0 * max * max, N * N)),
        DriveInput::OrbitAccel
    );
    assert_eq!(
        refused(OrbitTerms::new(N, 0.0, -1e-6)),
        DriveInput::GravityGradient
    );
    assert_eq!(
        refused(OrbitTerms::new(N, 0.0, 0.0)),
        DriveInput::GravityGradient
    );
    assert_eq!(
        refused(OrbitTerms::new(N, 0.0, f64::NAN)),
        DriveInput::GravityGradient
    );
    for n in [0.0, -N, 1e-11, 2.0 * max, f64::NAN, f64::INFINITY] {
        assert_eq!(
            refused(OrbitTerms::circular(n)),
            DriveInput::OrbitRate,
            "{n}"
        );
    }
    // The slowest circular orbit admitted still has a positive μ/R³ in f32, and is a valid
    // general orbit.
    let slow = OrbitTerms::circular(MIN_CIRCULAR_ORBIT_RATE_RADPS as f32).unwrap();
    assert!(slow.gravity_gradient_per_s2() > 0.0);
    let t = OrbitTerms::circular(N).unwrap();
    assert_eq!(OrbitTerms::new(N, 0.0, N * N), Ok(t));
    assert_eq!(OrbitTerms::circular(max).map(|t| t.rate_radps()), Ok(max));
}

#[test]
fn invalid_drive_inputs_are_typed_and_drop_the_estimate() {
    let good = drive(9_000.0, 1.0);
    let cases = [
        (
            Drive {
                length_m: 0.0,
                ..good
            },
            DriveInput::Length,
        ),
        (
            Drive {
                rate_mps: f64::NAN,
                ..good
            },
            DriveInput::Rate,
        ),
        (
            Drive {
                accel_mps2: f64::INFINITY,
                ..good
            },
            DriveInput::Accel,
        ),
        (Drive { mu3: -3.0, ..good }, DriveInput::Mu3),
        (
            Drive {
                length_m: 1.0,
                rate_mps: 1.0,
                ..good
            },
            DriveInput::Stretch,
        ),
        (
            Drive {
                length_m: 1.0,
                rate_mps: -5.0,
                ..good
            },
            DriveInput::Stretch,
        ),
    ];
    for (d, input) in cases {
        let mut e = Estimator::new(Config::paper()).unwrap();
        e.step(&good, Some(-0.7));
        assert!(e.estimate().is_some());
        let out = e.step(&d, None);
        match out.prediction {
            Prediction::InvalidDrive(err) => assert_eq!(err.input, input, "{d:?}"),
            p => panic!("{d:?}: {p:?}"),
        }
        assert_eq!(out.estimate, None);
        // The next sample starts afresh.
        let out = e.step(&good, Some(-0.7));
        assert_eq!(out.prediction, Prediction::NoEstimate);
        assert_eq!(out.measurement, Measurement::Initialised);
    }
}

#[test]
fn at_rest_on_the_vertical_it_stays_there() {
    // α = α̇ = 0 with the reel still is an equilibrium of Eq. 5b: the estimate does not
    // move and α̇'s variance settles.
    let mut e = Estimator::new(Config::paper()).unwrap();
    let d = drive(10_000.0, 0.0);
    for _ in 0..2_000 {
        let out = e.step(&d, Some(0.0));
        assert!(!matches!(out.measurement, Measurement::Gated(_)));
    }
    let est = e.estimate().unwrap();
    assert_eq!(est.alpha_rad, 0.0);
    assert_eq!(est.alpha_rate_radps, 0.0);
    assert!(est.alpha_rate_var_rad2ps2 < 1e-14, "{est:?}");
}

#[test]
fn transition_is_the_matrix_exponential_of_the_jacobian() {
    // With P = v vᵀ and (almost) no process noise, the predicted covariance is (Φv)(Φv)ᵀ:
    // compare Φv with a fine integration of ẋ = A x, A the Jacobian at the estimate with
    // the drive's mid-period s (κ = 3n² cos 2α̂).
    let cfg = Config {
        accel_noise_density: 0.0,
        disturbance_drift_density: 1e-14,
        ..Config::paper()
    };
    let e = Estimator::new(cfg).unwrap();
    let d = Drive {
        length_m: 1_000.0,
        rate_mps: 75.0,
        ..drive(0.0, 0.0)
    };
    let s = e.stretch(&d).unwrap();
    assert!((s - 2.0 * 75.0 / 1037.5).abs() < 1e-15);
    let alpha = 0.3_f64;
    let kappa = 3.0 * N * N * (2.0 * alpha).cos();
    let v = [1e-3, 2e-4, 1e-6];
    let t = Track {
        alpha,
        rate: 0.0,
        disturbance: 0.0,
        p: Sym3 {
            aa: v[0] * v[0],
            aw: v[0] * v[1],
            ad: v[0] * v[2],
            ww: v[1] * v[1],
            wd: v[1] * v[2],
            dd: v[2] * v[2],
        },
        rejections: 0,
        trig: None,
    };
    let p = e.predict(&t, &d).unwrap().p;
    let mut x = v;
    let steps = 100_000;
    let dt = 1.0 / f64::from(steps);
    let a = |x: [f64; 3]| [x[1], -kappa * x[0] - s * x[1] + x[2], 0.0];
    for _ in 0..steps {
        let k1 = a(x);
        let k2 = a([0, 1, 2].map(|i| x[i] + 0.5 * dt * k1[i]));
        let k3 = a([0, 1, 2].map(|i| x[i] + 0.5 * dt * k2[i]));
        let k4 = a([0, 1, 2].map(|i| x[i] + dt * k3[i]));
        x = [0, 1, 2].map(|i| x[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    // The series' first neglected term, (s h)⁵/120 ≈ 5e-7 relative on each factor Φv,
    // bounds the error (twice that on a product, and a margin).
    let tol = 4.0 * s.powi(5) / 120.0;
    let close = |got: f64, want: f64| (got - want).abs() <= tol * want.abs();
    assert!(close(p.aa, x[0] * x[0]), "{} vs {}", p.aa, x[0] * x[0]);
    assert!(close(p.aw, x[0] * x[1]), "{} vs {}", p.aw, x[0] * x[1]);
    assert!(close(p.ww, x[1] * x[1]), "{} vs {}", p.ww, x[1] * x[1]);
    assert!(close(p.wd, x[1] * x[2]), "{} vs {}", p.wd, x[1] * x[2]);
}

/// The textbook Kalman update, in f64 with nalgebra, of the state `x` with covariance `p` by
/// a sample `z` of α of variance `r` (H = (1 0 0)): K = P Hᵀ (H P Hᵀ + r)⁻¹,
/// x⁺ = x + K (z − H x), P⁺ = (I − K H) P (I − K H)ᵀ + K r Kᵀ (the Joseph form).
fn textbook_update(
    x: [f64; 3],
    p: &Sym3<f64>,
    r: f64,
    z: f64,
) -> (nalgebra::Vector3<f64>, nalgebra::Matrix3<f64>) {
    use nalgebra::{Matrix3, RowVector3, Vector3};
    let p = Matrix3::new(
        p.aa, p.aw, p.ad, //
        p.aw, p.ww, p.wd, //
        p.ad, p.wd, p.dd,
    );
    let h = RowVector3::new(1.0, 0.0, 0.0);
    let x = Vector3::from(x);
    let s = (h * p * h.transpose())[0] + r;
    let k = p * h.transpose() / s;
    let i_kh = Matrix3::identity() - k * h;
    let x_post = x + k * (z - (h * x)[0]);
    let p_post = i_kh * p * i_kh.transpose() + k * r * k.transpose();
    (x_post, p_post)
}

/// The estimator's own update (`Estimator::update_with`) of a track at `x` with covariance
/// `p`, by a sample `z` of variance `r`: the state and covariance after it.
fn estimator_update<T: Real>(x: [T; 3], p: Sym3<T>, r: T, z: T) -> ([T; 3], Sym3<T>) {
    let mut e = Estimator::<T>::new(Config::paper()).unwrap();
    e.measurement_var = r;
    e.track = Some(Track {
        alpha: x[0],
        rate: x[1],
        disturbance: x[2],
        p,
        rejections: 0,
        trig: None,
    });
    let m = e.update_with(Some(z));
    assert!(matches!(m, Measurement::Accepted(_)), "{m:?}");
    let t = e.track.unwrap();
    ([t.alpha, t.rate, t.disturbance], t.p)
}

/// A covariance's upper triangle in f64.
fn sym3_f64<T: Real>(p: &Sym3<T>) -> Sym3<f64> {
    Sym3 {
        aa: p.aa.to_f64(),
        aw: p.aw.to_f64(),
        ad: p.ad.to_f64(),
        ww: p.ww.to_f64(),
        wd: p.wd.to_f64(),
        dd: p.dd.to_f64(),
    }
}

/// `got` within `rel` of `want`, relative to `scale`.
fn near(got: f64, want: f64, rel: f64, scale: f64) -> bool {
    (got - want).abs() <= rel * scale.abs()
}

#[test]
fn the_update_is_the_textbook_kalman_update() {
    let p = Sym3 {
        aa: 1e-8,
        aw: 9.9e-12,
        ad: 1e-15,
        ww: 1e-14,
        wd: 9e-19,
        dd: 1e-22,
    };
    let (x, r) = ([-0.6, 2e-5, 1e-9], 1e-8_f64);
    // A sample one standard deviation of the innovation away (NIS 1: inside the gate).
    let z = x[0] + (p.aa + r).sqrt();
    let (gx, gp) = estimator_update(x, p, r, z);
    let (wx, wp) = textbook_update(x, &p, r, z);
    for i in 0..3 {
        assert!(
            near(gx[i], wx[i], 1e-12, wx[i]),
            "x[{i}]: {} vs {}",
            gx[i],
            wx[i]
        );
    }
    let got = [gp.aa, gp.aw, gp.ad, gp.ww, gp.wd, gp.dd];
    let want = [
        wp[(0, 0)],
        wp[(0, 1)],
        wp[(0, 2)],
        wp[(1, 1)],
        wp[(1, 2)],
        wp[(2, 2)],
    ];
    for (g, w) in got.into_iter().zip(want) {
        assert!(near(g, w, 1e-9, w), "{g} vs {w}");
    }
    // Positive: the leading minors of the textbook's posterior and ours.
    assert!(wp[(0, 0)] > 0.0 && wp[(0, 0)] * wp[(1, 1)] > wp[(0, 1)].powi(2));
    assert!(gp.aa > 0.0 && gp.aa * gp.ww - gp.aw * gp.aw > 0.0);
}

#[test]
fn the_update_keeps_the_alpha_row_accurate_after_a_dropout() {
    // P_αα at its cap, a hundred million times R: the α row of the posterior is 1e-8 of P's α
    // column. The f32 update keeps it within a few roundings of the textbook update in f64
    // (a form that subtracts P_αα K from P e₁ cancels it to nothing in f32).
    let p = Sym3::<f32> {
        aa: 1.0,
        aw: 1.5e-3,
        ad: 8e-7,
        ww: 4e-6,
        wd: 1.9e-9,
        dd: 1e-12,
    };
    let (x, r) = ([-0.5_f32, 1e-4, 0.0], 1e-8_f32);
    let z = 0.5_f32;
    let (gx, gp) = estimator_update(x, p, r, z);
    let (wx, wp) = textbook_update(x.map(f64::from), &sym3_f64(&p), f64::from(r), f64::from(z));
    let eps = 4.0 * f64::from(f32::EPSILON);
    let alpha_row = [
        (gp.aa, wp[(0, 0)]),
        (gp.aw, wp[(0, 1)]),
        (gp.ad, wp[(0, 2)]),
    ];
    for (got, want) in alpha_row {
        assert!(near(f64::from(got), want, eps, want), "{got} vs {want}");
    }
    for i in 0..3 {
        let got = f64::from(gx[i]);
        assert!(
            near(got, wx[i], eps, wx[i].abs().max(1e-7)),
            "x[{i}]: {got} vs {}",
            wx[i]
        );
    }
    // The (α̇, d) block is the Schur complement's: positive, the correlations kept below 1.
    let j = gp;
    assert!(
        j.ww > 0.0 && j.dd > 0.0 && j.ww * j.dd > j.wd * j.wd,
        "{j:?}"
    );
    assert!(j.aa * j.ww > j.aw * j.aw, "{j:?}");
}

#[test]
fn a_negative_residue_on_the_diagonal_becomes_its_magnitude() {
    // A P⁻ a rounding beyond semidefinite (Cov(α, α̇)² just above P_αα P_α̇α̇): the α̇
    // variance of the textbook update is negative, and the update keeps its magnitude, never
    // below the zero a cut would leave; the other entries are the textbook's.
    let p = Sym3 {
        aa: 1e-8,
        aw: 1.5e-11,
        ad: 1e-15,
        ww: 1e-14,
        wd: 9e-19,
        dd: 1e-22,
    };
    let (x, r) = ([0.0, 0.0, 0.0], 1e-8_f64);
    let z = 1e-4;
    let (_, j) = estimator_update(x, p, r, z);
    let (_, w) = textbook_update(x, &p, r, z);
    assert!(w[(1, 1)] < 0.0);
    assert!(
        near(j.ww, -w[(1, 1)], 1e-9, w[(1, 1)]),
        "{} vs {}",
        j.ww,
        w[(1, 1)]
    );
    assert!(near(j.aa, w[(0, 0)], 1e-12, w[(0, 0)]));
    assert!(near(j.dd, w[(2, 2)], 1e-9, w[(2, 2)]));
}

#[test]
fn caps_bound_the_covariance_and_never_raise_a_correlation() {
    let p = Sym3 {
        aa: 4.0,
        aw: 0.0199,
        ad: 1e-6,
        ww: 1e-4,
        wd: 1e-9,
        dd: 1e-10,
    };
    let caps = [1.0, 4e-6, 1e-12];
    let mut c = p;
    c.cap(&caps);
    assert_eq!((c.aa, c.ww, c.dd), (1.0, 4e-6, 1e-12));
    let corr = |a: f64, b: f64, ab: f64| (ab / (a * b).sqrt()).abs();
    assert!(corr(c.aa, c.ww, c.aw) <= corr(p.aa, p.ww, p.aw));
    assert!(corr(c.aa, c.dd, c.ad) <= corr(p.aa, p.dd, p.ad));
    assert!(corr(c.ww, c.dd, c.wd) <= corr(p.ww, p.dd, p.wd));
    // Still positive definite: leading minors of the result.
    assert!(c.aa * c.ww - c.aw * c.aw > 0.0);
    let mut c = p;
    c.cap(&[10.0, 1.0, 1.0]);
    assert_eq!(c, p);
}

#[test]
fn lent_trigonometry_is_used_only_for_the_alpha_it_was_computed_for() {
    let d32 = Drive {
        length_m: 9_000.0_f32,
        rate_mps: 1.0,
        accel_mps2: 0.0,
        mu3: 0.0,
        orbit: OrbitTerms::circular(N as f32).unwrap(),
    };
    let mut own = Estimator::new(Config::<f32>::paper()).unwrap();
    own.step(&d32, Some(-0.7));
    own.step(&d32, Some(-0.7001));
    let mut lent = own;
    let a = lent.estimate().unwrap().alpha_rad;
    // For another α: ignored.
    lent.lend_sin_cos_two_alpha(a + 1e-3, 0.5, 0.5);
    assert_eq!(lent, own);
    // For α̂: the next prediction is bit for bit the one that computes its own.
    let (s, c) = (2.0 * a).sin_cos();
    lent.lend_sin_cos_two_alpha(a, s, c);
    assert_ne!(lent, own);
    assert_eq!(
        lent.step(&d32, Some(-0.7002)),
        own.step(&d32, Some(-0.7002))
    );
}

#[test]
fn initialise_refuses_what_is_not_an_angle() {
    let mut e = Estimator::new(Config::<f32>::paper()).unwrap();
    assert_eq!(e.initialise(f32::NAN, 0.0), Err(Measurement::Invalid));
    assert_eq!(e.initialise(0.1, f32::INFINITY), Err(Measurement::Invalid));
    assert_eq!(e.estimate(), None);
    e.initialise(-0.61, 0.0).unwrap();
    let est = e.estimate().unwrap();
    assert_eq!(est.alpha_rad, -0.61);
    assert_eq!(est.alpha_var_rad2, e.measurement_var_rad2());
    assert_eq!(est.alpha_rate_var_rad2ps2, 2e-3_f32 * 2e-3);
}
