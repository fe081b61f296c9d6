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

#[path = "controller/time_base.rs"]
mod time_base;

#[path = "controller/on_the_estimator.rs"]
mod on_the_estimator;
