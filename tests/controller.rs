//! Behaviour of the controller's step API: parameter validation, the fault state machine
//! (Nominal → Degraded → SafeHold → Nominal), the sensor checks and the sequencer.

use tss_reel::controller::{
    Config, Controller, Fault, Flags, Health, Input, ModeCommand, Output, Phase, Rule, Sensor,
    TensionLoopConfig,
};
use tss_reel::law::LawFault;

const N_RADPS: f32 = 1.060_237_2e-3;

fn paper() -> Controller<f32> {
    Controller::new(Config::paper()).unwrap()
}

/// A plausible sample on the deployment plateau.
fn sample(tick: u32, length_m: f32) -> Input<f32> {
    Input {
        tick,
        length_m,
        reel_rate_mps: None,
        tension_n: None,
        alpha_rad: Some(-0.7),
        alpha_rate_radps: Some(0.0),
        orbit_rate_radps: N_RADPS,
        true_anomaly_rad: 0.0,
    }
}

fn rejected(cfg: Config<f32>) -> (&'static str, Rule) {
    let e = Controller::new(cfg).expect_err("must be rejected");
    (e.param, e.rule)
}

#[test]
fn every_invalid_parameter_is_named() {
    let p = Config::<f32>::paper;
    let mut c = p();
    c.gains.k1_per_s = 0.0;
    assert_eq!(rejected(c), ("gains.k1_per_s", Rule::NotPositive));
    let mut c = p();
    c.gains.k2_per_s2 = -1.0;
    assert_eq!(rejected(c), ("gains.k2_per_s2", Rule::NotPositive));
    let mut c = p();
    c.stage1.decay_rate_per_s = -1e-3;
    assert_eq!(rejected(c), ("stage1.decay_rate_per_s", Rule::Negative));
    let mut c = p();
    c.masses.sub_kg = -100.0;
    assert_eq!(rejected(c), ("masses.sub_kg", Rule::NotPositive));
    let mut c = p();
    c.period_s = f32::NAN;
    assert_eq!(rejected(c), ("period_s", Rule::NotFinite));
    let mut c = p();
    c.stage1.schedule.low_length_m = 35_000.0;
    assert_eq!(rejected(c), ("stage1.schedule", Rule::BandInverted));
    let mut c = p();
    c.envelope.max_length_m = 20_000.0;
    assert_eq!(
        rejected(c),
        ("stage1.schedule.high_length_m", Rule::OutsideEnvelope)
    );
    let mut c = p();
    c.orbit.eccentricity = 0.75;
    assert_eq!(rejected(c), ("orbit.eccentricity", Rule::NoEquilibrium));
    let mut c = p();
    c.masses.tether_density_kg_per_m = 1.0;
    assert_eq!(
        rejected(c),
        (
            "masses.tether_density_kg_per_m",
            Rule::TetherHeavierThanSatellite
        )
    );
    let mut c = p();
    c.stage2.schedule.high_angle_rad = -0.3;
    assert_eq!(
        rejected(c),
        ("stage2.schedule.high_angle_rad", Rule::WrongQuadrant)
    );
    let mut c = p();
    c.initial_rate_mps = 100.0;
    assert_eq!(rejected(c), ("initial_rate_mps", Rule::OutsideEnvelope));
    let mut c = p();
    c.monitor.coast_ticks = 0;
    assert_eq!(rejected(c), ("monitor.coast_ticks", Rule::NotPositive));
    let msg = Controller::new(Config {
        period_s: -1.0,
        ..p()
    })
    .unwrap_err()
    .to_string();
    assert!(msg.contains("period_s") && msg.contains("-1"), "{msg}");
}

/// The tension loop's parameters (docs/equations.md §17) are checked with the rest, each named.
#[test]
fn every_invalid_tension_loop_parameter_is_named() {
    use tss_reel::controller::TensionLoopConfig;
    let with = |f: &dyn Fn(&mut TensionLoopConfig<f32>)| {
        let mut t = TensionLoopConfig::dyneema_half_mm();
        f(&mut t);
        Config {
            tension_loop: Some(t),
            ..Config::<f32>::flight()
        }
    };
    assert!(Controller::new(Config::<f32>::flight()).is_ok());
    type Edit = dyn Fn(&mut TensionLoopConfig<f32>);
    let cases: [(&Edit, &str, Rule); 10] = [
        (
            &|t| t.axial_stiffness_n = 0.0,
            "tension_loop.axial_stiffness_n",
            Rule::NotPositive,
        ),
        (
            &|t| t.damping_ratio = f32::NAN,
            "tension_loop.damping_ratio",
            Rule::NotFinite,
        ),
        (
            &|t| t.damping_ratio = 3.0,
            "tension_loop.damping_ratio",
            Rule::OutOfRange,
        ),
        (
            &|t| t.washout_s = 0.5,
            "tension_loop.washout_s",
            Rule::BelowMinimum,
        ),
        (
            &|t| t.min_tension_n = -0.1,
            "tension_loop.min_tension_n",
            Rule::Negative,
        ),
        (
            &|t| t.max_tension_n = 0.05,
            "tension_loop.max_tension_n",
            Rule::BandInverted,
        ),
        (
            &|t| t.overshoot = 0.9,
            "tension_loop.overshoot",
            Rule::BelowMinimum,
        ),
        (
            &|t| t.fallback_accel_mps2 = 0.0,
            "tension_loop.fallback_accel_mps2",
            Rule::NotPositive,
        ),
        (
            &|t| t.load_cell_timeout_ticks = 0,
            "tension_loop.load_cell_timeout_ticks",
            Rule::NotPositive,
        ),
        (
            &|t| t.yield_full_rad = 0.1,
            "tension_loop.yield_full_rad",
            Rule::BandInverted,
        ),
    ];
    for (f, param, rule) in cases {
        assert_eq!(rejected(with(f)), (param, rule));
    }
}

#[test]
fn dropout_coasts_then_holds_then_recovers_through_the_blend() {
    let mut ctl = paper();
    let cfg = *ctl.config();
    let mut l = 2_000.0_f32;
    let mut out = ctl.step(&sample(0, l));
    // Run nominally for a while so the law's rate differs from the initial rate.
    for t in 1..600 {
        l += out.rate_cmd_mps;
        out = ctl.step(&sample(t, l));
    }
    assert_eq!(out.health, Health::Nominal);
    let cruise = out.rate_cmd_mps;
    assert!(cruise > 0.2, "deploying at {cruise}");

    // Dropout: coast on the last command for coast_ticks, length predicted.
    let t0 = 600;
    let first = *ctl.step_missing(t0);
    assert_eq!(first.health, Health::Degraded);
    assert_eq!(first.fault, Some(Fault::Sensor(Sensor::Missing)));
    assert!(first
        .flags
        .contains(Flags::SAFE_ACTION | Flags::HEALTH_CHANGED));
    assert_eq!(first.rate_cmd_mps, cruise);
    assert!((first.length_estimate_m - (l + cruise)).abs() < 1e-2);
    let coast = cfg.monitor.coast_ticks;
    let mut last = first;
    for k in 1..coast {
        last = *ctl.step_missing(t0 + k);
        assert_eq!(last.health, Health::Degraded);
        assert_eq!(last.rate_cmd_mps, cruise);
    }
    // Then safe hold: ramp to zero at the safe hold's own deceleration (gentler than the
    // paper's 15 m/s² envelope), and stay there.
    let mut prev = last.rate_cmd_mps;
    let dv = cfg
        .monitor
        .safe_hold_decel_mps2
        .min(cfg.envelope.max_accel_mps2)
        * cfg.period_s;
    let mut t = t0 + coast;
    let hold = *ctl.step_missing(t);
    assert_eq!(hold.health, Health::SafeHold);
    assert!(hold.flags.contains(Flags::HEALTH_CHANGED));
    assert!((hold.rate_cmd_mps - prev).abs() <= dv * (1.0 + 1e-6));
    prev = hold.rate_cmd_mps;
    let ramp_ticks = (cruise / dv).ceil() as u32;
    for _ in 0..ramp_ticks + 10 {
        t += 1;
        let o = *ctl.step_missing(t);
        assert!(o.rate_cmd_mps.abs() <= prev.abs());
        assert!(
            (o.rate_cmd_mps - prev).abs() <= dv * (1.0 + 1e-6),
            "{prev} -> {o:?}"
        );
        assert!(o.accel_cmd_mps2.abs() <= cfg.monitor.safe_hold_decel_mps2 * (1.0 + 1e-6));
        prev = o.rate_cmd_mps;
    }
    assert_eq!(prev, 0.0);
    t += 1;

    // Recovery needs recovery_ticks good samples in a row, then the blend restarts from 0.
    let l_true = last.length_estimate_m;
    for k in 0..cfg.monitor.recovery_ticks - 1 {
        let o = ctl.step(&sample(t + k, l_true));
        assert_eq!(
            o.health,
            Health::SafeHold,
            "still holding after {} good samples",
            k + 1
        );
        assert_eq!(o.rate_cmd_mps, 0.0);
    }
    let back = ctl.step(&sample(t + cfg.monitor.recovery_ticks - 1, l_true));
    assert_eq!(back.health, Health::Nominal);
    assert!(back
        .flags
        .contains(Flags::BLEND_RESTART | Flags::HEALTH_CHANGED));
    assert_eq!(back.blend_weight, 1.0);
    assert_eq!(
        back.rate_cmd_mps, 0.0,
        "the blend starts from the held rate"
    );
    assert!(back.fault.is_none());
}

#[test]
fn a_short_gap_only_degrades() {
    let mut ctl = paper();
    ctl.step(&sample(0, 100.0));
    let o = ctl.step_missing(1);
    assert_eq!(o.health, Health::Degraded);
    let o = ctl.step(&sample(2, 100.2));
    assert_eq!(o.health, Health::Nominal);
    assert!(o.flags.contains(Flags::HEALTH_CHANGED) && o.fault.is_none());
}

#[test]
fn a_missing_first_sample_does_not_poison_the_length_check() {
    // No sample at tick 0: the estimate has nothing to start from, so the first real sample
    // (at any length) anchors it instead of failing as a jump.
    let mut ctl = paper();
    assert_eq!(ctl.step_missing(0).health, Health::Degraded);
    let o = *ctl.step(&sample(1, 12_345.0));
    assert_eq!(o.health, Health::Nominal, "{o:?}");
    assert_eq!(o.length_estimate_m, 12_345.0);
}

#[test]
fn length_glitch_is_rejected_and_the_prediction_used() {
    let mut ctl = paper();
    let o = *ctl.step(&sample(0, 5_000.0));
    let glitch = *ctl.step(&sample(1, 5_100.0));
    assert_eq!(glitch.fault, Some(Fault::Sensor(Sensor::LengthJump)));
    assert!((glitch.length_estimate_m - (5_000.0 + o.rate_cmd_mps)).abs() < 1e-2);
    let ok = *ctl.step(&sample(2, 5_000.0 + 2.0 * o.rate_cmd_mps));
    assert_eq!(ok.health, Health::Nominal);
}

#[test]
fn stuck_angle_sensor_is_detected() {
    let mut ctl = paper();
    let mut verdict = None;
    for t in 0..40 {
        // α frozen at −0.7 while α̇ claims 1e-4 rad/s.
        let o = ctl.step(&Input {
            alpha_rate_radps: Some(1e-4),
            ..sample(t, 100.0 + t as f32 * 0.1)
        });
        if let Some(f) = o.fault {
            verdict = Some((t, f));
            break;
        }
    }
    let (t, f) = verdict.expect("stuck sensor detected");
    assert_eq!(f, Fault::Sensor(Sensor::AlphaStuck));
    assert!((10..40).contains(&t), "after {t} ticks");
}

#[test]
fn non_finite_and_out_of_range_samples_are_typed() {
    let cases: [(Input<f32>, Sensor); 6] = [
        (
            Input {
                length_m: f32::NAN,
                ..sample(1, 1.0)
            },
            Sensor::Length,
        ),
        (
            Input {
                length_m: 1e9,
                ..sample(1, 1.0)
            },
            Sensor::Length,
        ),
        (
            Input {
                alpha_rad: Some(f32::INFINITY),
                ..sample(1, 1.0)
            },
            Sensor::Alpha,
        ),
        (
            Input {
                alpha_rate_radps: Some(1.0),
                ..sample(1, 1.0)
            },
            Sensor::AlphaRate,
        ),
        (
            Input {
                orbit_rate_radps: 0.0,
                ..sample(1, 1.0)
            },
            Sensor::OrbitRate,
        ),
        (
            Input {
                orbit_rate_radps: f32::MIN_POSITIVE / 4.0,
                ..sample(1, 1.0)
            },
            Sensor::OrbitRate,
        ),
    ];
    for (input, sensor) in cases {
        let mut ctl = paper();
        ctl.step(&sample(0, 1.0));
        let o: Output<f32> = *ctl.step(&input);
        assert_eq!(o.fault, Some(Fault::Sensor(sensor)), "{input:?}");
        assert!(o.rate_cmd_mps.is_finite());
    }
    let mut ctl = paper();
    ctl.step(&sample(10, 1.0));
    assert_eq!(
        ctl.step(&sample(9, 1.0)).fault,
        Some(Fault::Sensor(Sensor::Tick))
    );
}

#[test]
fn singular_law_is_a_fault_and_the_reel_coasts() {
    // α̇ = −n on the deployment plateau: n + δ̇ = 0, Eq. 27's denominator vanishes.
    let mut ctl = paper();
    ctl.step(&sample(0, 100.0));
    let o = ctl.step(&Input {
        alpha_rate_radps: Some(-N_RADPS),
        ..sample(1, 100.1)
    });
    assert_eq!(o.fault, Some(Fault::Law(LawFault::SingularDenominator)));
    assert_eq!(o.health, Health::Degraded);
    assert!(o.rate_cmd_mps.is_finite());
}

#[test]
fn stage2_starts_on_command_and_restarts_the_blend_from_the_current_rate() {
    let cfg = Config {
        stage2: tss_reel::controller::Stage2Config {
            start_tick: None,
            ..Config::<f32>::paper().stage2
        },
        ..Config::paper()
    };
    let mut ctl = Controller::new(cfg).unwrap();
    let mut l = 29_999.0;
    let mut o = ctl.step(&Input {
        alpha_rad: Some(0.0),
        ..sample(0, l)
    });
    for t in 1..100 {
        l += o.rate_cmd_mps;
        o = ctl.step(&Input {
            alpha_rad: Some(0.0),
            ..sample(t, l)
        });
    }
    assert_eq!(o.phase, Phase::Keep1);
    let before = o.rate_cmd_mps;
    ctl.start_stage2();
    let s = ctl.step(&Input {
        alpha_rad: Some(0.0),
        ..sample(100, l + before)
    });
    assert_eq!(s.phase, Phase::Slew);
    assert!(s.flags.contains(Flags::BLEND_RESTART | Flags::SLEWING));
    assert_eq!(s.blend_weight, 1.0);
    assert!(
        (s.rate_cmd_mps - before).abs() < 1e-6,
        "continuous: {before} -> {}",
        s.rate_cmd_mps
    );
}

#[test]
fn early_deployment_is_flagged_outside_the_equilibrium_region() {
    // l̇/l = 0.1 s⁻¹ at l = 1 m: x = 2·0.1/(n·1) ≈ 189 ≫ 1.5 (Eq. 13).
    let o = *paper().step(&sample(0, 1.0));
    assert!(o.flags.contains(Flags::NO_EQUILIBRIUM));
    assert!(o.equilibrium_margin < -100.0);
    // Station keeping at 30 km is inside with margin ≈ 1.5.
    let mut ctl = paper();
    let o = ctl.step(&Input {
        alpha_rad: Some(0.0),
        ..sample(0, 30_000.0)
    });
    let mut o2 = o;
    for t in 1..5000 {
        o2 = ctl.step(&Input {
            alpha_rad: Some(0.0),
            ..sample(t, 30_000.0)
        });
    }
    assert!(!o2.flags.contains(Flags::NO_EQUILIBRIUM), "{o2:?}");
    assert!((o2.equilibrium_margin - 1.5).abs() < 0.05);
}

#[test]
fn a_new_phase_is_flagged_and_recorded_at_its_step_only() {
    use tss_reel::controller::{EventKind, Phase};
    let mut ctl = paper();
    let first = *ctl.step(&sample(0, 20_000.0));
    assert!(!first.flags.contains(Flags::PHASE_CHANGED));
    assert_eq!(
        ctl.pop_event().map(|e| e.kind),
        Some(EventKind::BlendRestart)
    );
    ctl.start_stage2();
    let slew = *ctl.step(&sample(1, 20_000.0));
    assert_eq!(slew.phase, Phase::Slew);
    assert!(slew
        .flags
        .contains(Flags::PHASE_CHANGED | Flags::BLEND_RESTART));
    let kinds: Vec<_> = std::iter::from_fn(|| ctl.pop_event())
        .map(|e| (e.tick, e.kind))
        .collect();
    assert_eq!(
        kinds,
        vec![
            (1, EventKind::Phase(Phase::Slew)),
            (1, EventKind::BlendRestart)
        ]
    );
    let next = *ctl.step(&sample(2, 20_000.0));
    assert!(!next.flags.contains(Flags::PHASE_CHANGED));
    assert!(!next.flags.contains(Flags::BLEND_RESTART));
    assert_eq!(ctl.pop_event(), None);
}

#[test]
fn events_tell_each_change_once_and_count_what_overflows() {
    use tss_reel::controller::{EventKind, EVENT_CAPACITY};
    let mut ctl = paper();
    ctl.step(&sample(0, 100.0));
    assert_eq!(
        ctl.pop_event().map(|e| e.kind),
        Some(EventKind::BlendRestart)
    );
    assert_eq!(ctl.pop_event(), None);
    // A 40-tick dropout: one Health(Degraded) + one Fault(Missing), then one Health(SafeHold).
    for t in 1..41 {
        ctl.step_missing(t);
    }
    let kinds: Vec<_> = std::iter::from_fn(|| ctl.pop_event())
        .map(|e| (e.tick, e.kind))
        .collect();
    assert_eq!(
        kinds,
        vec![
            (
                1,
                EventKind::Health {
                    from: Health::Nominal,
                    to: Health::Degraded
                }
            ),
            (1, EventKind::Fault(Fault::Sensor(Sensor::Missing))),
            (
                31,
                EventKind::Health {
                    from: Health::Degraded,
                    to: Health::SafeHold
                }
            ),
        ]
    );
    // Alternating faults overflow the queue: the first are kept, the rest dropped and counted.
    let mut t = 41;
    for _ in 0..EVENT_CAPACITY {
        ctl.step(&Input {
            length_m: f32::NAN,
            ..sample(t, 100.0)
        });
        ctl.step_missing(t + 1);
        t += 2;
    }
    assert!(ctl.events_dropped() > 0);
    let kept: Vec<_> = std::iter::from_fn(|| ctl.pop_event()).collect();
    assert_eq!(kept.len(), EVENT_CAPACITY);
    assert_eq!(kept[0].tick, 41, "the first event of the burst is kept");
}

// ---- Issue 16: the time base, bounded commands, parameter ranges, FDIR ----

/// The paper's mission with a reel whose acceleration limit always binds (1 mm/s²): the law's
/// command runs ahead of what the reel may do, so any call pattern that let the command jump
/// would show.
fn slow_reel() -> Controller<f32> {
    let mut cfg = Config::paper();
    cfg.envelope.max_accel_mps2 = 1e-3;
    Controller::new(cfg).unwrap()
}

/// Flies `ticks` nominal periods from tick `from` on the deployment plateau, the length
/// following the command; returns the length and the last output.
fn fly(ctl: &mut Controller<f32>, from: u32, ticks: u32, mut l: f32) -> (f32, Output<f32>) {
    let mut out = *ctl.step(&sample(from, l));
    for k in 1..ticks {
        let t = from.wrapping_add(k);
        l += out.rate_cmd_mps;
        out = *ctl.step(&sample(t, l));
        assert_eq!(out.health, Health::Nominal, "{out:?}");
    }
    (l, out)
}

#[test]
fn a_repeated_tick_is_rejected_and_moves_nothing() {
    let mut ctl = slow_reel();
    let (l, before) = fly(&mut ctl, 0, 300, 2_000.0);
    assert!(before.flags.contains(Flags::ACCEL_SATURATED), "{before:?}");
    // 50 calls at the same tick: each a Tick fault, none moves the command (HZ-12).
    for _ in 0..50 {
        let o = ctl.step(&sample(before.tick, l));
        assert_eq!(o.fault, Some(Fault::Sensor(Sensor::Tick)), "{o:?}");
        assert_eq!(o.rate_cmd_mps, before.rate_cmd_mps);
        assert_eq!(o.accel_cmd_mps2, 0.0);
    }
}

#[test]
fn stale_ticks_and_gaps_do_not_let_the_command_jump() {
    let a_dt = 1e-3 * (1.0 + 1e-5);
    // 29 samples with stale ticks (one a period, as a faulty time stamp would come), then
    // the next good one 30 ticks on: one period's change, not (n+1)·a·Δt.
    let mut ctl = slow_reel();
    let (mut l, before) = fly(&mut ctl, 100, 300, 2_000.0);
    let mut prev = before.rate_cmd_mps;
    for k in 1..30 {
        l += prev;
        let o = ctl.step(&sample(before.tick - k, l));
        assert_eq!(o.fault, Some(Fault::Sensor(Sensor::Tick)));
        assert_eq!(o.rate_cmd_mps, prev, "a stale sample moved the command");
        prev = o.rate_cmd_mps;
    }
    l += prev;
    let next = ctl.step(&sample(before.tick + 30, l));
    assert_eq!(next.health, Health::Nominal, "{next:?}");
    assert!(
        (next.rate_cmd_mps - prev).abs() <= a_dt,
        "{prev} -> {} after stale ticks",
        next.rate_cmd_mps
    );
    // A gap of 30 ticks without any call: one command, one period's change.
    let mut ctl = slow_reel();
    let (l, before) = fly(&mut ctl, 0, 300, 2_000.0);
    let next = ctl.step(&sample(before.tick + 30, l + 30.0 * before.rate_cmd_mps));
    assert_eq!(next.health, Health::Nominal, "{next:?}");
    assert!(
        (next.rate_cmd_mps - before.rate_cmd_mps).abs() <= a_dt,
        "{} -> {} over a gap",
        before.rate_cmd_mps,
        next.rate_cmd_mps
    );
}

#[test]
fn the_tick_counter_wraps_without_a_fault() {
    // Ticks from u32::MAX − 99 through the wrap to 199: the same commands as ticks 0..300.
    let mut wrapping = paper();
    let mut plain = paper();
    let (_, a) = fly(&mut wrapping, u32::MAX - 99, 300, 1.0);
    let (_, b) = fly(&mut plain, 0, 300, 1.0);
    assert_eq!(a.tick, 199);
    assert_eq!(a.fault, None);
    assert_eq!(
        (a.rate_cmd_mps, a.blend_weight, a.phase),
        (b.rate_cmd_mps, b.blend_weight, b.phase)
    );
    // Stage 2 is due by mission time: started 100 ticks before the wrap, due 28 800 ticks on.
    let mut ctl = paper();
    let start = u32::MAX - 99;
    let (l, o) = fly(&mut ctl, start, 28_800, 1.0);
    assert_ne!(o.phase, Phase::Slew);
    let o = ctl.step(&sample(start.wrapping_add(28_800), l + o.rate_cmd_mps));
    assert_eq!(o.phase, Phase::Slew, "{o:?}");
}

#[test]
fn parameters_outside_their_meaningful_range_are_named() {
    let p = Config::<f32>::paper;
    let mut c = p();
    c.period_s = 1e-4;
    assert_eq!(rejected(c), ("period_s", Rule::BelowMinimum));
    // Eq. 28's fast pole must be representable at the period: k1 = 1e30 is not.
    let mut c = p();
    c.gains.k1_per_s = 1e30;
    assert_eq!(rejected(c), ("gains.k1_per_s", Rule::TooFastForPeriod));
    let mut c = p();
    c.gains.k2_per_s2 = 1.0; // complex poles, |s| = 1 rad/s at a 1 s period
    assert_eq!(rejected(c), ("gains.k2_per_s2", Rule::TooFastForPeriod));
    let mut c = p();
    c.stage2.decay_rate_per_s = 0.5;
    assert_eq!(
        rejected(c),
        ("stage2.decay_rate_per_s", Rule::TooFastForPeriod)
    );
    // A shorter period represents faster gains.
    let mut c = p();
    c.gains.k1_per_s = 0.5;
    c.period_s = 0.1;
    assert!(Controller::new(c).is_ok());
    let mut c = p();
    c.monitor.good_samples_per_bad = 0;
    assert_eq!(
        rejected(c),
        ("monitor.good_samples_per_bad", Rule::NotPositive)
    );
    let mut c = p();
    c.monitor.good_samples_per_bad = u32::MAX;
    assert_eq!(
        rejected(c),
        ("monitor.good_samples_per_bad", Rule::TooLarge)
    );
    let mut c = p();
    c.monitor.safe_hold_decel_mps2 = 0.0;
    assert_eq!(
        rejected(c),
        ("monitor.safe_hold_decel_mps2", Rule::NotPositive)
    );
}

#[test]
fn the_commanded_acceleration_stays_inside_the_envelope_at_a_blend_start() {
    // A blend start (E = 1) with n + δ̇ at 2 % of n: Eq. 27's value is about −150 m/s, and
    // Eq. 30's c·E·(u − l̇0) is 1.5 times the realistic reel's 0.1 m/s².
    let mut cfg = Config::paper();
    cfg.envelope.max_accel_mps2 = 0.1;
    cfg.envelope.max_rate_mps = 10.0;
    let mut ctl = Controller::new(cfg).unwrap();
    let o = ctl.step(&Input {
        alpha_rate_radps: Some(-0.98 * N_RADPS),
        ..sample(0, 2_000.0)
    });
    assert_eq!(o.health, Health::Nominal, "{o:?}");
    assert!(o.law_rate_mps < -100.0, "{o:?}");
    assert!(o.accel_cmd_mps2.abs() <= 0.1, "{o:?}");
    assert!(o.flags.contains(Flags::ACCEL_SATURATED));
}

#[test]
fn an_intermittent_sensor_reaches_safe_hold() {
    // 20 NaN α samples to 1 good one: each good sample used to reset the count, so the
    // controller coasted for ever. The leaky counter declares the sensor failed.
    let mut ctl = paper();
    let (mut l, mut out) = fly(&mut ctl, 0, 100, 1_000.0);
    let mut tick = out.tick;
    let mut held_at = None;
    for cycle in 0..10 {
        for k in 0..21 {
            tick += 1;
            l += out.rate_cmd_mps;
            let alpha_rad = if k < 20 { f32::NAN } else { -0.7 };
            out = *ctl.step(&Input {
                alpha_rad: Some(alpha_rad),
                ..sample(tick, l)
            });
            if out.health == Health::SafeHold && held_at.is_none() {
                held_at = Some(cycle);
            }
        }
    }
    assert_eq!(held_at, Some(1), "safe hold in the second cycle");
    assert_eq!(out.health, Health::SafeHold, "and it stays: {out:?}");
    // A single glitch now and then is forgiven: one bad sample per 10 good for 1000 ticks.
    let mut ctl = paper();
    let (mut l, mut out) = fly(&mut ctl, 0, 100, 1_000.0);
    for tick in 100..1_100 {
        l += out.rate_cmd_mps;
        let alpha_rad = if tick % 10 == 0 { f32::NAN } else { -0.7 };
        out = *ctl.step(&Input {
            alpha_rad: Some(alpha_rad),
            ..sample(tick, l)
        });
        assert_ne!(out.health, Health::SafeHold, "tick {tick}");
    }
}

#[test]
fn a_deployment_that_stops_progressing_is_reported() {
    // α held where Eq. 27 gives l̇ = 0 on the deployment plateau (k2 δ = 1.5 n² sin 2α): the
    // blend's tail carries the tether ≈ 100 m further, then it stays short of the keep.
    let (k2, n) = (9.8696e-6_f64, f64::from(N_RADPS));
    let alpha_ref = -std::f64::consts::FRAC_PI_4;
    let f = |a: f64| k2 * (a - alpha_ref) - 1.5 * n * n * (2.0 * a).sin();
    let (mut lo, mut hi) = (-1.2, alpha_ref);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let alpha_rad = (0.5 * (lo + hi)) as f32;
    let mut ctl = paper();
    let mut l = 2_000.0_f32;
    let mut first = None;
    let mut out = *ctl.step(&Input {
        alpha_rad: Some(alpha_rad),
        ..sample(0, l)
    });
    for tick in 1..20_000 {
        l += out.rate_cmd_mps;
        out = *ctl.step(&Input {
            alpha_rad: Some(alpha_rad),
            ..sample(tick, l)
        });
        assert_eq!((out.health, out.phase), (Health::Nominal, Phase::Deploy));
        if out.flags.contains(Flags::NO_PROGRESS) && first.is_none() {
            first = Some(tick);
        }
    }
    // Found within the 5 000-s window of stage 1 (5 × 1/c) after the last metre of progress.
    let first = first.expect("the stall is reported");
    assert!((5_000..15_000).contains(&first), "reported at tick {first}");
    let events: Vec<_> = core::iter::from_fn(|| ctl.pop_event()).collect();
    use tss_reel::controller::EventKind;
    let stalls: Vec<_> = events
        .iter()
        .filter(|e| matches!(e.kind, EventKind::NoProgress(_)))
        .collect();
    assert_eq!(stalls.len(), 1, "{events:?}");
    assert_eq!(stalls[0].kind, EventKind::NoProgress(Phase::Deploy));
    assert_eq!(stalls[0].tick, first);
    assert!(out.flags.contains(Flags::NO_PROGRESS), "still reported");
}

#[test]
fn estimator_parameters_are_named_by_their_path_in_the_config() {
    use tss_reel::controller::RateSource;
    use tss_reel::estimator;
    let with = |est: estimator::Config<f32>| Config {
        rate_source: RateSource::Estimator(est),
        ..Config::<f32>::paper()
    };
    assert!(with(estimator::Config::paper()).validate().is_ok());
    let mut est = estimator::Config::paper();
    est.alpha_noise_rad = -1.0;
    assert_eq!(
        rejected(with(est)),
        ("rate_source.estimator.alpha_noise_rad", Rule::OutOfRange)
    );
    est.alpha_noise_rad = f32::NAN;
    assert_eq!(
        rejected(with(est)),
        ("rate_source.estimator.alpha_noise_rad", Rule::NotFinite)
    );
    let mut est = estimator::Config::paper();
    est.max_rejections = 0;
    assert_eq!(
        rejected(with(est)),
        ("rate_source.estimator.max_rejections", Rule::OutOfRange)
    );
    // The estimator steps once per control period: its period is the controller's.
    let mut est = estimator::Config::paper();
    est.period_s = 2.0;
    assert_eq!(
        rejected(with(est)),
        ("rate_source.estimator.period_s", Rule::NotThePeriod)
    );
}

#[test]
fn on_the_rate_sensor_a_sample_without_alpha_or_its_rate_is_rejected() {
    for (x, sensor) in [
        (
            Input {
                alpha_rad: None,
                ..sample(1, 1.0)
            },
            Sensor::Alpha,
        ),
        (
            Input {
                alpha_rate_radps: None,
                ..sample(1, 1.0)
            },
            Sensor::AlphaRate,
        ),
    ] {
        let mut ctl = paper();
        ctl.step(&sample(0, 1.0));
        let o = ctl.step(&x);
        assert_eq!(o.fault, Some(Fault::Sensor(sensor)));
        assert_eq!(o.health, Health::Degraded);
    }
}

#[test]
fn a_gap_in_the_calls_longer_than_the_estimator_carries_drops_the_estimate() {
    use tss_reel::controller::{EventKind, MAX_CARRIED_PERIODS};
    let mut ctl = Controller::new(Config::<f32>::flight()).unwrap();
    let x = |tick| Input {
        alpha_rate_radps: None,
        ..sample(tick, 100.0)
    };
    let lost = |ctl: &mut Controller<f32>| {
        let mut at = None;
        while let Some(e) = ctl.pop_event() {
            if e.kind == EventKind::EstimateLost {
                at = Some(e.tick);
            }
        }
        at
    };
    ctl.step(&x(0));
    ctl.step(&x(1));
    assert_eq!(lost(&mut ctl), None);
    // Three periods later: the estimate is carried over each of them, and kept.
    ctl.step(&x(4));
    assert_eq!(lost(&mut ctl), None);
    assert!(ctl.estimate().is_some());
    // More periods than the estimator carries: dropped, and this sample starts it afresh.
    let tick = 4 + MAX_CARRIED_PERIODS + 1;
    let o = *ctl.step(&x(tick));
    assert_eq!(lost(&mut ctl), Some(tick));
    let e = ctl.estimate().expect("restarted from this sample");
    assert_eq!((e.alpha_rad, e.alpha_rate_radps), (-0.7, 0.0));
    assert_eq!(o.nis, None);
}

fn flight() -> Controller<f32> {
    Controller::new(Config::flight()).unwrap()
}

/// A swing sensor's reading on the estimator path: α near −0.7 rad with a sensor-like
/// variation of a few 1e-5 rad, never the same twice in a row.
fn noisy_alpha(tick: u32) -> f32 {
    -0.7 + 1e-5 * ((tick * 7) % 11) as f32
}

#[test]
fn on_the_estimator_a_frozen_swing_sensor_is_stuck_after_stuck_ticks_readings() {
    let stuck_ticks = Config::<f32>::flight().monitor.stuck_ticks;
    let mut ctl = flight();
    let mut l = 100.0;
    for tick in 0..50 {
        let x = Input {
            alpha_rad: Some(noisy_alpha(tick)),
            alpha_rate_radps: None,
            ..sample(tick, l)
        };
        let o = *ctl.step(&x);
        assert_eq!(o.fault, None, "tick {tick}");
        l += o.rate_cmd_mps;
    }
    // Frozen from tick 50: the reading of tick 50 repeats; the stuck_ticks-th is rejected.
    let frozen = noisy_alpha(50);
    for tick in 50..50 + stuck_ticks + 40 {
        let x = Input {
            alpha_rad: Some(frozen),
            alpha_rate_radps: None,
            ..sample(tick, l)
        };
        let o = *ctl.step(&x);
        l += o.rate_cmd_mps;
        let run = tick - 50 + 1;
        if run < stuck_ticks {
            assert_eq!(o.fault, None, "reading {run} of the run");
        } else {
            assert_eq!(o.fault, Some(Fault::Sensor(Sensor::AlphaStuck)), "{run}");
        }
        // A stuck sample is a bad sample: coast_ticks (30) of coasting, then safe hold.
        if run == stuck_ticks + 31 {
            assert_eq!(o.health, Health::SafeHold);
        }
    }
    // A reading that moves again ends the run.
    let x = Input {
        alpha_rad: Some(frozen + 1e-5),
        alpha_rate_radps: None,
        ..sample(50 + stuck_ticks + 40, l)
    };
    assert_ne!(ctl.step(&x).fault, Some(Fault::Sensor(Sensor::AlphaStuck)));
}

#[test]
fn a_reel_rate_the_reel_cannot_run_at_is_a_bad_sample() {
    let max = Config::<f32>::flight().envelope.max_rate_mps;
    for make in [flight, paper] {
        for bad in [f32::NAN, f32::INFINITY, -1000.0, 1.5 * max * 1.001] {
            let mut ctl = make();
            let mut l = 100.0;
            for tick in 0..3 {
                let x = Input {
                    reel_rate_mps: Some(0.1),
                    ..sample(tick, l)
                };
                assert_eq!(ctl.step(&x).fault, None);
                l += 0.1;
            }
            let x = Input {
                reel_rate_mps: Some(bad),
                ..sample(3, l)
            };
            let o = *ctl.step(&x);
            assert_eq!(o.fault, Some(Fault::Sensor(Sensor::ReelRate)), "{bad}");
            assert_eq!(o.health, Health::Degraded, "{bad}");
            assert!(o.rate_cmd_mps.is_finite());
            // The next good rate is accepted again.
            let x = Input {
                reel_rate_mps: Some(0.1),
                ..sample(4, l + 0.1)
            };
            assert_eq!(ctl.step(&x).fault, None, "{bad}");
        }
        // Inside the envelope's rate plus the margin: accepted.
        let mut ctl = make();
        let x = Input {
            reel_rate_mps: Some(-1.5 * max * 0.999),
            ..sample(0, 100.0)
        };
        assert_eq!(ctl.step(&x).fault, None);
    }
}

#[test]
fn a_libration_beyond_the_laws_domain_is_safe_hold_at_once() {
    use tss_reel::controller::MAX_LIBRATION_RAD;
    let beyond = -(MAX_LIBRATION_RAD as f32) * 1.01;
    // On the rate sensor the sensed α is judged; on the estimator α̂, started from this α.
    for (make, rate) in [
        (paper as fn() -> Controller<f32>, Some(0.0)),
        (flight, None),
    ] {
        let mut ctl = make();
        for tick in 0..3 {
            let x = Input {
                alpha_rad: Some(beyond - 1e-5 * tick as f32),
                alpha_rate_radps: rate,
                ..sample(tick, 100.0)
            };
            let o = *ctl.step(&x);
            assert_eq!(o.fault, Some(Fault::Libration), "tick {tick}");
            // At once, not after coast_ticks of coasting.
            assert_eq!(o.health, Health::SafeHold, "tick {tick}");
            assert!(o.flags.contains(Flags::SAFE_ACTION));
        }
        // Back inside: recovery_ticks (10) valid samples in a row, then the law again.
        let mut out = None;
        for tick in 3..14 {
            let x = Input {
                alpha_rad: Some(-0.7 - 1e-5 * tick as f32),
                alpha_rate_radps: rate,
                ..sample(tick, 100.0)
            };
            out = Some(*ctl.step(&x));
        }
        let o = out.unwrap();
        assert_eq!(o.fault, None);
    }
    // At the bound itself, the law flies.
    let mut ctl = paper();
    let x = Input {
        alpha_rad: Some(-(MAX_LIBRATION_RAD as f32)),
        ..sample(0, 100.0)
    };
    assert_ne!(ctl.step(&x).fault, Some(Fault::Libration));
}

/// The paper's controller with the tension loop on the deployment plateau, the length
/// following its command, a load cell reading a bounce of 0.5 N (31-s period) on a 5-N free
/// tension less the tension the last command's acceleration takes away (Eq. 5a, m_r ≈ 99 kg;
/// 0 when slack).
struct Plateau {
    ctl: Controller<f32>,
    length_m: f32,
}

impl Plateau {
    fn new() -> Self {
        let cfg = Config {
            tension_loop: Some(TensionLoopConfig::dyneema_half_mm()),
            ..Config::paper()
        };
        Self {
            ctl: Controller::new(cfg).unwrap(),
            length_m: 10_000.0,
        }
    }

    /// A step at `tick`; the load cell NaN unless `load_cell`, α̇ missing unless `rate_sensor`.
    fn step(&mut self, tick: u32, load_cell: bool, rate_sensor: bool) -> Output<f32> {
        let last = *self.ctl.output();
        self.length_m += last.rate_cmd_mps;
        let tension_n =
            (5.0 + 0.5 * (0.2 * tick as f32).sin() - 99.0 * last.accel_cmd_mps2).max(0.0);
        *self.ctl.step(&Input {
            tension_n: Some(if load_cell { tension_n } else { f32::NAN }),
            alpha_rate_radps: rate_sensor.then_some(0.0),
            ..sample(tick, self.length_m)
        })
    }

    fn fly(&mut self, ticks: core::ops::Range<u32>) {
        for tick in ticks {
            self.step(tick, true, true);
        }
    }
}

/// A safe action brings the reel to rest with the tension loop's admittance term added only on
/// a sample the monitor accepted and a load cell the loop tracks (docs/equations.md §17.8):
/// a safe hold on rejected samples, and a stop with the load cell lost, are the plain ramp to
/// the bit; a safe hold awaiting recovery and an abort, with the load cell tracked, damp.
#[test]
fn a_safe_action_uses_the_load_cell_only_on_an_accepted_sample_it_tracks() {
    let plain = |v: f32| v - v.clamp(-0.01, 0.01);

    // The swing's rate sensor fails: the health machine coasts, then holds safe, on rejected
    // samples whose load cell still reads the bounce: the plain ramp (or the coast).
    let mut p = Plateau::new();
    p.fly(0..60);
    assert_eq!(p.ctl.output().health, Health::Nominal);
    let mut previous = p.ctl.output().rate_cmd_mps;
    let mut held = 0;
    for tick in 60..1_500 {
        let out = p.step(tick, true, false);
        assert_eq!(out.fault, Some(Fault::Sensor(Sensor::AlphaRate)));
        match out.health {
            Health::SafeHold => {
                assert_eq!(out.rate_cmd_mps, plain(previous), "{tick}");
                held += 1;
            }
            _ => assert_eq!(out.rate_cmd_mps, previous, "{tick}"),
        }
        previous = out.rate_cmd_mps;
    }
    assert!(held > 30 && previous == 0.0, "{held}: at rest, {previous}");
    // Back, the samples accepted while the safe hold awaits recovery: the term damps the bounce.
    let mut damped = 0;
    for tick in 1_500..1_505 {
        let out = p.step(tick, true, true);
        assert_eq!(out.health, Health::SafeHold);
        damped += usize::from(out.rate_cmd_mps != plain(previous));
        assert!(
            out.rate_cmd_mps.abs() <= 0.01,
            "the term's authority: {out:?}"
        );
        previous = out.rate_cmd_mps;
    }
    assert!(damped > 0);

    // The load cell lost (NaN for longer than the timeout), then an abort: the plain ramp.
    let mut p = Plateau::new();
    p.fly(0..60);
    for tick in 60..70 {
        p.step(tick, false, true);
    }
    assert!(p.ctl.output().flags.contains(Flags::LOAD_CELL_LOST));
    p.ctl.command(ModeCommand::Abort).unwrap();
    let mut previous = p.ctl.output().rate_cmd_mps;
    assert!(
        previous.abs() > 0.02,
        "{previous}: a ramp of several periods"
    );
    for tick in 70..100 {
        let out = p.step(tick, false, true);
        assert!(out.flags.contains(Flags::ABORTED | Flags::SAFE_ACTION));
        assert_eq!(out.rate_cmd_mps, plain(previous), "{tick}");
        previous = out.rate_cmd_mps;
    }

    // Tracked, the abort's stop damps the bounce, and comes to rest on average.
    let mut p = Plateau::new();
    p.fly(0..70);
    p.ctl.command(ModeCommand::Abort).unwrap();
    let mut previous = p.ctl.output().rate_cmd_mps;
    let mut damped = 0;
    let mut rest_m = None;
    for tick in 70..2_000 {
        let out = p.step(tick, true, true);
        damped += usize::from(out.rate_cmd_mps != plain(previous));
        previous = out.rate_cmd_mps;
        if tick == 1_000 {
            rest_m = Some(p.length_m);
        }
    }
    assert!(damped > 1_000, "{damped}");
    // The term's length over 1 000 s at rest: K τ_w times the change of the washout's mean
    // (17.10), a bounce's worth at most: K(10 km) ≈ 0.12 m/s/N, τ_w = 100 s, 0.5 N.
    let moved_m = p.length_m - rest_m.unwrap();
    assert!(moved_m.abs() < 0.12 * 100.0 * 0.5, "{moved_m}");
}
