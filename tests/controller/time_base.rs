//! The time base and bounded commands: repeated, stale and wrapping ticks, parameters outside
//! their meaningful range, the acceleration limit at a blend start, an intermittent sensor and
//! a deployment that stops progressing.

use super::*;

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
