//! Flying on the estimator (`Config::flight`): its parameters, gaps in the calls, a frozen
//! swing sensor, the reel rate, a libration beyond the law's domain and the load cell in a safe
//! action.

use super::*;

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
