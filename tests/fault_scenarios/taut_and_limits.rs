//! Keeping the tether taut and the limits: the estimator against α̇ noise, the spool end on a
//! predicted length and a lagging drive, the tension-aware protection, the law's singular
//! point, a stalled retrieval, the fault demonstration and a safe hold in the fast retrieval.

use super::*;

/// Flies `file` with `overrides` on the controller configured to fly `RateSource::Estimator`
/// (the EKF on α alone, `estimator::Config::paper()`: σ_α = 1e-4 rad): the sensed α̇ is not
/// used.
fn run_on_estimator(file: &str, overrides: &[&str]) -> History {
    use tss_reel::controller::{Controller, RateSource};
    use tss_reel::estimator;
    let sc = scenario(file, overrides);
    let mut cfg = sim::controller_config::<f32>(&sc).unwrap_or_else(|e| panic!("{e}"));
    cfg.rate_source = RateSource::Estimator(estimator::Config::paper());
    let mut ctl = Controller::new(cfg).unwrap_or_else(|e| panic!("{e}"));
    let h = sim::run_stepper(&sc, &mut ctl, &PROBE_TIMES_S, &mut |_| {})
        .unwrap_or_else(|e| panic!("{e}"));
    eprintln!("{}", render_fault_summary(&sc, &h.faults));
    h
}

/// HZ-5, O-5 closed: what flies has no α̇ sensor. The controller flies its estimator on α
/// samples with 1e-4 rad of noise (and 1 cm of length noise) under the realistic reel limits:
/// the tether stays taut after the early deployment (O-6's thin start is its own item), as on
/// the true α̇.
#[test]
fn alpha_rate_noise_of_a_microradian_per_second_keeps_the_tether_taut() {
    let h = run_on_estimator(
        REEL_LIMITS,
        &[
            "sensors.seed=1",
            "sensors.length.noise_std=0.01",
            "sensors.alpha.noise_std=1e-4",
        ],
    );
    let f = &h.faults;
    assert!(
        f.slack_episodes.iter().all(|e| e.1 <= 1_800.0),
        "{:?}",
        f.slack_episodes
    );
    assert_envelope(f, 0.0);
    assert_eq!(f.final_health, Some(Health::Nominal));
}

/// Why the rate source matters (HZ-5): the paper's idealisation, a sensed α̇ flown as is, with
/// white noise of only 1e-6 rad/s slackens the tether. The law's rate command carries
/// k1·l/((2+μ3)n)·σ_α̇ of noise (≈ 2.4 cm/s per µrad/s at 9 km), so the command jitters by the
/// full acceleration limit and the tension (≈ 2.7 N at 9 km, 99 kg × 0.1 m/s² = 9.9 N swing)
/// goes negative: 69 slack episodes, min −7.1 N at 32 535 s. The estimator's α̇̂ errs by
/// 3.6e-8 rad/s RMS, and smoothly (tests/estimator.rs).
#[test]
fn the_rate_sensor_path_with_alpha_rate_noise_of_a_microradian_per_second_slackens() {
    let h = run(
        REEL_LIMITS,
        &[
            "sensors.seed=1",
            "sensors.length.noise_std=0.01",
            "sensors.alpha.noise_std=1e-4",
            "sensors.alpha_rate.noise_std=1e-6",
        ],
    );
    let late: Vec<_> = h
        .faults
        .slack_episodes
        .iter()
        .filter(|e| e.1 > 1_800.0)
        .collect();
    eprintln!(
        "rate sensor, σ_α̇ = 1e-6 rad/s: {} slack episodes after 1 800 s",
        late.len()
    );
    assert!(late.len() >= 10, "{late:?}");
}

/// HZ-8 (YES2: running past the target). The spool ends at 30 500 m, below the paper's 31.3 km
/// overshoot, and the length sensor drops out for 200 s as the tether approaches it. The
/// controller coasts and holds on the *predicted* length: the hard limit holds strictly (the
/// envelope keeps a one-ulp guard, so the f32 rounding of the length cannot leave the tether
/// resting past it, as it did by 0.6 mm before: open item O-3, fixed in 9db0844), the
/// length-limited flag is raised, and the mission recovers afterwards.
#[test]
fn dropout_approaching_the_spool_end_holds_the_limit_on_the_predicted_length() {
    let h = run(
        PAPER,
        &[
            "envelope.max_length_m=30500",
            "simulation.duration_s=14400",
            "simulation.output_interval_s=1",
            "faults.dropout=[{ from_s = 11900, until_s = 12100 }]",
        ],
    );
    let f = &h.faults;
    assert_eq!(
        transitions(f),
        [
            (11900.0, Health::Nominal, Health::Degraded),
            (11930.0, Health::Degraded, Health::SafeHold),
            (12109.0, Health::SafeHold, Health::Nominal),
        ]
    );
    assert!(f.flags.length_limited > 0);
    let coasting_limited = h
        .samples
        .iter()
        .filter(|s| (11900.0..11930.0).contains(&s.t_s))
        .any(|s| s.flags & Flags::LENGTH_LIMITED != 0 && s.flags & Flags::SAFE_ACTION != 0);
    assert!(coasting_limited, "the coast is shaped by the length limit");
    assert!(
        f.length_range_m.1 <= 30_500.0,
        "max l {}",
        f.length_range_m.1
    );
    assert!(f.max_length_error_m.0 < 0.05, "{:?}", f.max_length_error_m);
    assert_eq!(f.final_health, Some(Health::Nominal));
    assert_envelope(f, 0.0);
}

/// HZ-8, O-2 (fixed): the spool-end limit and its braking curve acted on the command, so a drive
/// that lags ran past them: realistic reel, 2 s lag, drive limited to 0.1 m/s², spool end
/// 30 500 m, no fault at all: the tether passed the spool end by 7.2 m (1.1 m with an unlimited
/// drive) and stayed beyond it for 929 s, and the length limit overrode the acceleration limit
/// in the last periods (26 commands beyond 0.1 m/s², up to 0.35 m/s²). With the protection
/// told the drive's lag (`protection.drive_lag_s = 2`), the room to the limit is measured less
/// the drive's overrun τ|v| and the staircase brakes at a·(1 − e^{−h})/h, so the drive's peak
/// acceleration is the limit: measured, the tether stops at 30 499.997 m, no command beyond
/// 0.08 m/s² (with and without the drive's own limit).
#[test]
fn spool_end_holds_with_a_lagging_drive() {
    for drive in [&["reel.max_accel_mps2=0.1"][..], &[]] {
        let mut sets = vec![
            "envelope.max_length_m=30500",
            "simulation.duration_s=14400",
            "reel.lag_s=2",
            "protection.enabled=true",
            "protection.drive_lag_s=2",
        ];
        sets.extend_from_slice(drive);
        let h = run(REEL_LIMITS, &sets);
        let f = &h.faults;
        assert!(f.max_excursion_m <= 0.0, "{} m beyond", f.max_excursion_m);
        assert!(
            f.length_range_m.1 > 30_499.9,
            "stopped at {}",
            f.length_range_m.1
        );
        assert_envelope(f, 0.0);
    }
    // With the protection not told the drive's lag, the same drive passes the spool end (the
    // hazard itself): the simulator stops the run where the tether leaves the spool.
    let h = run(
        REEL_LIMITS,
        &[
            "envelope.max_length_m=30500",
            "simulation.duration_s=14400",
            "reel.lag_s=2",
            "reel.max_accel_mps2=0.1",
        ],
    );
    let overrun = h
        .spool_overrun
        .expect("a drive whose lag the protection does not know runs off the spool");
    assert!(overrun.length_m > overrun.spool_m, "{overrun:?}");
    assert!(
        h.faults.max_excursion_m > 0.0,
        "{}",
        h.faults.max_excursion_m
    );
}

/// TSS-1R at short length: a 40 s dropout at t = 40 s (l ≈ 5 m) puts the reel in safe hold;
/// after recovery the restarted blend winds in and brakes with more acceleration than the
/// tether's sub-milli-newton tension can carry, so it is slack for 8 minutes (measured 230–716 s,
/// min −6.3e-4 N). Deployment then resumes and reaches the 30 km keep 12 minutes late.
#[test]
fn early_safe_hold_slackens_the_short_tether_but_deployment_resumes() {
    let h = run(
        PAPER,
        &[
            "simulation.duration_s=14400",
            "faults.dropout=[{ from_s = 40, until_s = 80 }]",
        ],
    );
    let f = &h.faults;
    assert_eq!(f.safe_hold_s, 19.0);
    assert_eq!(f.slack_events, 1);
    let (from, until) = f.slack_episodes[0];
    assert!(from >= 200.0 && until <= 800.0, "slack {from}–{until} s");
    assert!(f.min_tension_n.0 > -1e-3, "{:?}", f.min_tension_n);
    let keep = h
        .samples
        .iter()
        .find(|s| s.phase == PhaseLabel::Keep1)
        .expect("keep reached");
    assert!(keep.t_s < 13_000.0, "keep at {} s", keep.t_s);
    assert_envelope(f, 0.0);
}

/// O-6 (closed by the protection): the paper's deployment has no tension margin (3.3e-5 N at
/// l ≈ 26 m, t ≈ 1051 s: the tether swings back to α ≈ −70°, where Eq. 5a's free tension
/// vanishes). With the protection (scenarios/paper-reel-limits.toml: T_min = 2 mN, on the
/// true tension at the reel) the tether keeps its margin from the first tension sample on
/// (T_min, or a quarter of 3 m_r n² l on a short tether: measured min 2.000 mN): the
/// pay-out brakes, then winds in 1.1 m while the swing passes (the bound acts on l̈, not on
/// the direction), and resumes. The cost, measured on the paper's envelope: the 30 km keep is
/// reached 230 s *earlier* (11 580 s against 11 810 s: the braking damps the swing), Table-1
/// lengths at 2 h / 4 h / 6 h of 2 461.9 / 29 661.4 / 29 999.19 m against 2 048.0 / 29 601.9 /
/// 29 999.51 m, 8 h within 3 mm of 30 km either way, the Table-1 instants (7–8 h) within
/// 3.1 cm of the unprotected run. Table 1 itself (paper.toml, no protection) is unchanged.
/// The bound starts once, in one stretch: no chatter.
#[test]
fn the_protection_keeps_the_tension_margin_from_release() {
    let h = run(
        REEL_LIMITS,
        &[
            "simulation.duration_s=28800",
            "simulation.output_interval_s=1",
        ],
    );
    let f = &h.faults;
    let released = margin_ratio_from(&h, 1.0);
    eprintln!(
        "protected: min tension {:?}, least share of the margin {released:?}",
        f.min_tension_n
    );
    assert!(released.0 >= 1.0 - 1e-3, "{released:?}");
    assert_eq!(f.slack_events, 0);
    assert_envelope(f, 0.0);
    let starts = h
        .samples
        .windows(2)
        .filter(|w| {
            w[1].flags & Flags::TENSION_LIMITED != 0 && w[0].flags & Flags::TENSION_LIMITED == 0
        })
        .count();
    assert_eq!(starts, 1, "the tension bound starts once");

    // What the margin costs, on the paper's own envelope (no reel limits).
    let keep1 = |h: &History| {
        h.samples
            .iter()
            .find(|s| s.phase == PhaseLabel::Keep1)
            .map(|s| s.t_s)
            .expect("keep reached")
    };
    let protected = run(
        PAPER,
        &["simulation.duration_s=28800", "protection.enabled=true"],
    );
    let (a, b) = (keep1(&protected), keep1(clean_stage1()));
    eprintln!("margin cost: keep at {a} s (unprotected {b} s)");
    for t in [7200.0, 14_400.0, 21_600.0, 28_800.0] {
        let (p, q) = (at(&protected, t).length_m, at(clean_stage1(), t).length_m);
        eprintln!("  t = {t} s: {p:.3} m (unprotected {q:.3} m)");
    }
    let d = probe_difference(&protected, clean_stage1());
    eprintln!("  Table 1 (7–8 h): largest difference {d:.4} m");
    assert!(d < 0.1, "{d}"); // measured 3.1 cm (the keep settles from a different approach)
    assert!(a <= b, "{a} vs {b}");
    assert!(protected.faults.min_tension_n.0 >= 2e-3 * (1.0 - 1e-3));
    let at_8h = protected.probes.iter().find(|p| p.0 == 28_800.0).unwrap();
    assert!((at_8h.1 - 30_000.0).abs() < 0.01, "{at_8h:?}");
}

/// O-6: the disturbances that slacken an unprotected start leave the protected one taut. A 1° α
/// bias (unprotected, slack 866–1284 s; the biased model is corrected by the load cell over
/// τ_f, measured min 1.77 mN, 88 % of the margin) and a 2 s reel lag (unprotected, slack
/// 983–1268 s; measured min 2.0 mN from the first tension sample on).
#[test]
fn the_protected_start_does_not_slacken_under_bias_or_lag() {
    let bias = format!("sensors.alpha.bias={}", 1f64.to_radians());
    let h = run(
        PAPER,
        &[
            &bias,
            "protection.enabled=true",
            "simulation.duration_s=14400",
            "simulation.output_interval_s=1",
        ],
    );
    let share = margin_ratio_from(&h, 1.0);
    eprintln!(
        "bias: min tension {:?}, least share of the margin {share:?}",
        h.faults.min_tension_n
    );
    assert_eq!(h.faults.slack_events, 0, "{:?}", h.faults.slack_episodes);
    assert!(share.0 > 0.8, "{share:?}");
    let h = run(
        REEL_LIMITS,
        &[
            "reel.lag_s=2",
            "reel.max_accel_mps2=0.1",
            "protection.drive_lag_s=2",
            "simulation.duration_s=14400",
            "simulation.output_interval_s=1",
        ],
    );
    let released = margin_ratio_from(&h, 1.0);
    eprintln!("lag: least share of the margin from release {released:?}");
    assert_eq!(h.faults.slack_events, 0, "{:?}", h.faults.slack_episodes);
    assert!(released.0 > 1.0 - 1e-3, "{released:?}");
}

/// The safe hold ramps at a rate the tether carries: the early safe hold (l ≈ 5 m) that
/// slackened the short tether for 8 minutes (above) keeps it taut when the tension bound
/// applies to the hold and to the restarted blend: at l ≈ 5–10 m the margin is a quarter of
/// 3 m_r n² l (0.4–0.8 mN), the free tension the tether has there; a fixed 2 mN wound the
/// tether in for 1 600 s against the law until it swung through the vertical (a law fault and
/// a second safe hold). Measured: min 0.46 mN at 858 s, at least 99 % of the margin after
/// the dropout, the keep reached at 12 430 s (unprotected: 12 min late as well).
#[test]
fn the_protected_early_safe_hold_keeps_the_short_tether_taut() {
    let h = run(
        PAPER,
        &[
            "simulation.duration_s=14400",
            "simulation.output_interval_s=1",
            "protection.enabled=true",
            "faults.dropout=[{ from_s = 40, until_s = 80 }]",
        ],
    );
    let f = &h.faults;
    assert!(f.safe_hold_s > 0.0);
    assert_eq!(f.slack_events, 0, "{:?}", f.slack_episodes);
    assert_eq!(f.safe_hold_s, 19.0, "one safe hold");
    let after = margin_ratio_from(&h, 80.0);
    eprintln!(
        "early hold: min tension {:?}, least share of the margin after the dropout {after:?}",
        f.min_tension_n
    );
    assert!(after.0 >= 0.99, "{after:?}");
    let keep = h
        .samples
        .iter()
        .find(|s| s.phase == PhaseLabel::Keep1)
        .expect("keep reached");
    assert!(keep.t_s < 13_000.0, "keep at {} s", keep.t_s);
}

/// HZ-8, core: approaching the spool end under the realistic envelope (0.1 m/s²). The
/// continuous braking curve v ≤ √(2ad), sampled once a period, asked for more deceleration than
/// the limit in the last 34 periods (up to 0.181 m/s², open item O-1); the discrete staircase
/// curve of `src/envelope.rs` stops at the limit within 0.1 m/s².
#[test]
fn braking_to_the_spool_end_respects_the_acceleration_limit() {
    let h = run(
        REEL_LIMITS,
        &["envelope.max_length_m=30500", "simulation.duration_s=14400"],
    );
    assert_envelope(&h.faults, 0.0);
}

/// The fault summary's text names what was injected and what was raised.
#[test]
fn the_fault_summary_text_reports_faults_and_slack() {
    let sc = scenario(
        PAPER,
        &[
            "simulation.duration_s=600",
            "faults.dropout=[{ from_s = 40, until_s = 80 }]",
        ],
    );
    let h = sim::run(&sc, &[], &mut |_| {}).unwrap();
    let text = render_fault_summary(&sc, &h.faults);
    for needle in [
        "dropout (no sample) 40–80 s",
        "sensor Missing",
        "nominal → degraded",
        "degraded → safe hold",
        "safe hold 19 s",
        // (The safe hold ramps at its own 0.01 m/s²: slack from 226 s.)
        "slack (T ≤ 0): 1 events, 375 s",
        "slack episodes: 226–601 s",
    ] {
        assert!(text.contains(needle), "{needle:?} not in:\n{text}");
    }
}

/// HZ-9 (SEDS-1: a large swing). The sub-satellite is released swinging backward at
/// δ̇(0) = −1.2e-3 rad/s, faster than the orbit rate (n ≈ 1.06e-3 rad/s), so Eq. 27's
/// denominator n + δ̇ is negative: the law reports SingularDenominator, the reel coasts on
/// l̇0 (Degraded, 29 s, below the 30 s coast), the law takes over as the swing slows, and the
/// deployment reaches its keep (measured: 3.307 h, 104 s later than nominal). The command is
/// flagged NO_EQUILIBRIUM while outside the Eq. 13 region.
#[test]
fn large_initial_swing_hits_the_law_singularity_coasts_and_recovers() {
    let h = run(
        REEL_LIMITS,
        &[
            "initial.delta_rate_radps=-1.2e-3",
            "simulation.duration_s=14400",
        ],
    );
    let f = &h.faults;
    let singular = Fault::Law(tss_reel::law::LawFault::SingularDenominator);
    let t = f.tally(singular).expect("SingularDenominator raised");
    assert_eq!((t.first_s, t.ticks), (0.0, 29));
    assert_eq!(
        transitions(f),
        [
            (0.0, Health::Nominal, Health::Degraded),
            (29.0, Health::Degraded, Health::Nominal),
        ]
    );
    assert_eq!(f.safe_hold_s, 0.0);
    assert!(at(&h, 0.0).flags & Flags::NO_EQUILIBRIUM != 0);
    let keep = h
        .samples
        .iter()
        .find(|s| s.phase == PhaseLabel::Keep1)
        .expect("keep reached");
    assert!(keep.t_s < 12_500.0, "keep at {} s", keep.t_s);
    assert_envelope(f, 0.0);
}

/// `scenarios/faults-demo.toml` (the shipped demonstration): every injected fault is raised
/// with its own type, each is coasted through or held and recovered from, and the mission
/// still ends at the 2 km keep inside the envelope.
#[test]
fn the_fault_demo_raises_every_fault_and_still_completes_the_mission() {
    let h = run("scenarios/faults-demo.toml", &[]);
    let f = &h.faults;
    for s in [
        Sensor::AlphaStuck,
        Sensor::Alpha,
        Sensor::Missing,
        Sensor::LengthJump,
        Sensor::OrbitRate,
    ] {
        assert!(
            f.raised(Fault::Sensor(s)),
            "{s:?} not raised: {:?}",
            f.faults
        );
    }
    assert_eq!(f.faults.len(), 5, "{:?}", f.faults);
    assert_eq!(ticks_of(f, Fault::Sensor(Sensor::Missing)), 80);
    assert_eq!(f.final_health, Some(Health::Nominal));
    assert!(f.safe_hold_s > 0.0);
    assert_envelope(f, 0.0);
    let last = h.samples.last().unwrap();
    assert_eq!(last.phase, PhaseLabel::Keep2);
    assert!(
        (last.length_m - 2000.0).abs() < 0.1,
        "final l {}",
        last.length_m
    );
}

/// HZ-13 (a mission that stops progressing). α reads 5° high: the biased equilibrium of
/// stage 2 lies short of the 2 km keep, so retrieval settles at ≈ 2 364 m and would stay in
/// Retrieve for ever without a word. The core reports it (report only, see
/// `Flags::NO_PROGRESS`): the flag and a `NoProgress(Retrieve)` event once the phase has not
/// come 1 m (the keep capture) closer for 5 × 1/c = 10 000 s.
#[test]
fn alpha_bias_of_five_degrees_stalls_retrieval_and_is_reported() {
    let bias = 5f64.to_radians();
    let h = run(PAPER, &[&format!("sensors.alpha.bias={bias}")]);
    let last = h.samples.last().unwrap();
    eprintln!(
        "5° bias: final l = {:.1} m, phase {:?}",
        last.length_m, last.phase
    );
    assert_eq!(last.phase, PhaseLabel::Retrieve);
    assert!((last.length_m - 2_364.0).abs() < 10.0, "{}", last.length_m);
    let stalled: Vec<&Sample> = h
        .samples
        .iter()
        .filter(|s| s.flags & Flags::NO_PROGRESS != 0)
        .collect();
    let first = stalled.first().expect("the stall is reported");
    eprintln!("5° bias: stall reported from {} s", first.t_s);
    assert_eq!(first.phase, PhaseLabel::Retrieve);
    assert!(
        first.t_s > 40_000.0 && first.t_s < 72_000.0,
        "{}",
        first.t_s
    );
    // From then on every sample says so, and the reel still follows the law (no safe action).
    assert!(h
        .samples
        .iter()
        .filter(|s| s.t_s >= first.t_s)
        .all(|s| s.flags & Flags::NO_PROGRESS != 0 && s.flags & Flags::SAFE_ACTION == 0));
    assert!(h.faults.faults.is_empty(), "{:?}", h.faults.faults);
}

/// The clean paper mission never reports a stall: its phases approach their keeps by more
/// than the capture distance within every window.
#[test]
fn the_paper_mission_never_stalls() {
    let h = run(PAPER, &[]);
    assert!(h.samples.iter().all(|s| s.flags & Flags::NO_PROGRESS == 0));
}

/// The safe hold ramps at its own 0.01 m/s², whatever the envelope: at the paper's 15 m/s² the
/// ramp would stop a fast wind-in in one tick, a one-tick tension spike of −300 to −626 N. A
/// 60 s dropout during the fast retrieval (t = 30 000 s).
#[test]
fn safe_hold_during_fast_retrieval_ramps_gently() {
    let h = run(
        PAPER,
        &[
            "simulation.duration_s=31000",
            "faults.dropout=[{ from_s = 30000, until_s = 30060 }]",
        ],
    );
    let f = &h.faults;
    let hold: Vec<&Sample> = h
        .samples
        .iter()
        .filter(|s| (30_000.0..=30_100.0).contains(&s.t_s))
        .collect();
    let min_t = hold
        .iter()
        .map(|s| s.tension_n)
        .fold(f64::INFINITY, f64::min);
    let max_a = hold
        .iter()
        .map(|s| s.length_accel_mps2.abs())
        .fold(0.0, f64::max);
    eprintln!(
        "retrieval hold: rate at 30 000 s {:.3} m/s, min tension {min_t:.3} N, max |l̈| {max_a:.4} m/s²",
        hold[0].length_rate_mps
    );
    assert!(hold[0].length_rate_mps < -1.0, "winding in fast");
    assert!(f.safe_hold_s > 0.0);
    assert!(max_a <= 0.01 * (1.0 + 1e-4), "{max_a}"); // (f32 rounding of a 4 m/s rate)
    assert!(min_t > 0.0, "{min_t} N");
}
