//! The drive's faults on the drum model: encoder jumps, lost and missing counts, a jammed
//! drum, a stall and what is not one, saturation, tension readings out of range, a non-finite
//! command, repeated ticks, drift-free odometry, a frozen encoder, a slipping brake, a load
//! cell reading ten times the tension and quiet cross-checks on a healthy drive.

use super::*;

#[test]
fn a_one_tick_encoder_jump_is_rejected_without_a_trip() {
    let mut run = settled_at(DriveConfig::example(), 2.0);
    let mut glitch = run.input();
    glitch.encoder_count = glitch.encoder_count.map(|c| c.wrapping_add(20_000));
    let out = run.tick_with(glitch);
    assert!(out.faults.contains(DriveFault::EncoderJump), "{out:?}");
    assert!((out.speed_mps - 2.0).abs() < 0.01, "{out:?}");
    for _ in 0..500 {
        let out = run.tick();
        assert!(out.faults.is_empty(), "{out:?}");
    }
    assert!((run.drum.speed_mps() - 2.0).abs() < 2e-3);
    // The length lost nothing: it is the drum's, to a count.
    let m_per_count = run.drive.config().geometry.m_per_count();
    assert_eq!(run.drive.odometer().total_counts(), run.read_counts);
    let error_m = f64::from(run.drive.paid_out_m()) - run.read_paid_out_m;
    assert!(error_m.abs() < 2.0 * f64::from(m_per_count), "{error_m}");
}

#[test]
fn a_counter_that_lost_counts_for_good_trips_the_drive() {
    let mut run = settled_at(DriveConfig::example(), 2.0);
    for k in 1..=11 {
        let mut bad = run.input();
        bad.encoder_count = bad.encoder_count.map(|c| c.wrapping_add(20_000));
        let out = run.tick_with(bad);
        assert!(out.faults.contains(DriveFault::EncoderJump));
        if k <= 10 {
            assert!(matches!(out.brake, Brake::Released { .. }), "{k}: {out:?}");
        } else {
            assert_eq!(out.brake, Brake::Tripped(DriveFault::EncoderJump));
            assert_eq!(out.duty, 0.0);
            assert!(!out.brake.brake_released() && !out.brake.motor_enabled());
            assert_eq!(
                out.faults.outer_reaction(),
                tss_reel::reel_drive::OuterReaction::Degrade
            );
        }
    }
    // Tripped stays tripped until cleared; then the brake is engaged and releases again.
    assert!(matches!(run.tick().brake, Brake::Tripped(_)));
    assert_eq!(run.drive.clear_trip(), Some(DriveFault::EncoderJump));
    assert_eq!(run.drive.brake(), Brake::Engaged);
}

#[test]
fn missing_counts_are_bridged_for_10_ticks_then_trip() {
    let mut run = settled_at(DriveConfig::example(), 2.0);
    for _ in 0..10 {
        let mut none = run.input();
        none.encoder_count = None;
        let out = run.tick_with(none);
        assert!(out.faults.contains(DriveFault::EncoderMissing));
        assert!(matches!(out.brake, Brake::Released { .. }));
    }
    let out = run.tick();
    assert!(out.faults.is_empty(), "{out:?}");
    for _ in 0..11 {
        let mut none = run.input();
        none.encoder_count = None;
        run.tick_with(none);
    }
    assert_eq!(
        run.drive.brake(),
        Brake::Tripped(DriveFault::EncoderMissing)
    );
    // A gap in the ticks longer than the encoder check bridges trips too.
    let mut run = settled_at(DriveConfig::example(), 2.0);
    run.tick += 11;
    let out = run.tick();
    assert_eq!(out.brake, Brake::Tripped(DriveFault::EncoderMissing));
    // Cleared after a long outage (the drum turned 1.5 counter ranges meanwhile): the next
    // reading is the new reference, not a (wrapped, ambiguous) change; the drive releases and
    // drives again without a fault.
    for _ in 0..5000 {
        run.tick();
    }
    run.drum.angle_rad += 1.5 * 65_536.0 / run.drum.counts_per_rev * TAU;
    assert_eq!(run.drive.clear_trip(), Some(DriveFault::EncoderMissing));
    let before = run.drive.odometer().total_counts();
    let start_counts = run.drum.counts(); // braked: it stays there until the release
    for _ in 0..3000 {
        let out = run.tick();
        assert!(out.faults.is_empty(), "{out:?}");
    }
    assert!(matches!(run.drive.brake(), Brake::Released { .. }));
    assert!((run.drum.speed_mps() - 2.0).abs() < 2e-3);
    let counted = run.drive.odometer().total_counts() - before;
    let driven = run.read_counts - start_counts;
    assert!(counted > 0 && counted == driven, "{counted} {driven}");
}

/// A seized drum under the motor's growing torque: the tension its stillness implies is one
/// no tether pulls (the cross-checks' `NoResponse`) within a few tenths of a second, before the
/// stall's half second at the stall duty.
#[test]
fn a_jammed_drum_trips_as_unresponsive_within_a_third_of_a_second() {
    let mut run = settled_at(DriveConfig::example(), 1.0);
    run.drum.jammed = true;
    let jam = run.tick;
    let tripped_at = loop {
        let out = run.tick();
        if let Brake::Tripped(f) = out.brake {
            assert_eq!(f, DriveFault::NoResponse);
            assert_eq!(out.duty, 0.0);
            assert!(out.faults.contains(DriveFault::NoResponse));
            break out.tick;
        }
        assert!(run.tick < jam + 2000, "no trip");
    };
    // 100 ticks of an implied tension below −15 N, counted once the observer has seen the
    // drum stop (its 50 ms) and the PI's torque has grown past the tension's.
    let after = tripped_at - jam;
    println!("jammed drum: tripped after {after} ms");
    assert!((100..330).contains(&after), "{after}");
}

/// A drive whose implied tension stays plausible (a motor weaker than the drum's breakaway
/// friction, nothing moving) still trips as a stall after the stall ticks.
#[test]
fn a_motor_too_weak_to_break_the_drum_away_trips_as_a_stall() {
    let mut cfg = DriveConfig::example();
    // 0.1 N m of motor against 0.25 N m of friction: the duty saturates, nothing turns, and
    // the implied tension is −1 N (plausible).
    cfg.max_torque_nm = 0.1;
    cfg.drum.coulomb_nm = 0.0;
    let mut run = Run::new(cfg);
    run.drum.max_torque_nm = 0.1;
    run.drum.coulomb_nm = 0.25;
    run.tension_n = 0.0;
    run.command(1.0, 0.0, false);
    let tripped = (0..3000).find_map(|_| match run.tick().brake {
        Brake::Tripped(f) => Some((f, run.tick)),
        _ => None,
    });
    let (fault, at) = tripped.expect("tripped");
    assert_eq!(fault, DriveFault::MotorStall);
    assert!((550..700).contains(&at), "{at}");
}

#[test]
fn a_drum_held_at_rest_against_the_tension_is_not_a_stall() {
    // Commanded to rest, the drum still under 150 N (15 N m against a 5 N m motor: the duty
    // saturates, the stall duty is reached) and jammed (no motion): the brake engages after
    // its rest ticks, even when they outlast the stall ticks; no stall trip.
    let mut cfg = DriveConfig::example();
    cfg.brake.engage_ticks = 2 * cfg.faults.stall_ticks;
    let mut run = settled_at(cfg, 0.5);
    run.command(0.0, -5.0, false);
    run.tension_n = 150.0;
    run.drum.jammed = true;
    let engaged_at = loop {
        let out = run.tick();
        assert!(
            !out.faults.contains(DriveFault::MotorStall) && !matches!(out.brake, Brake::Tripped(_)),
            "{out:?}"
        );
        if out.brake == Brake::Engaged {
            break out.tick;
        }
        assert!(run.tick < 10_000, "never engaged");
    };
    assert!(engaged_at >= 2000 + cfg.brake.engage_ticks, "{engaged_at}");
}

#[test]
fn a_drum_that_cannot_hold_the_tension_reports_saturation_but_is_not_stalled() {
    // 60 N pulls 6 N m out of a 5 N m motor: winding in at −1 m/s is impossible.
    let mut run = settled_at(DriveConfig::example(), 0.5);
    run.tension_n = 60.0;
    run.command(-1.0, -1.0, false);
    let mut first = None;
    for _ in 0..3000 {
        let out = run.tick();
        assert!(!matches!(out.brake, Brake::Tripped(_)), "tripped: {out:?}");
        if out.faults.contains(DriveFault::DutySaturated) && first.is_none() {
            first = Some(out.tick);
        }
    }
    let first = first.expect("saturation reported");
    println!("60 N against a 5 N m motor: DutySaturated from tick {first}");
    assert!(
        run.drum.speed_mps() > 0.5,
        "the tension pays the tether out"
    );
}

#[test]
fn tension_readings_out_of_range_are_typed_and_bounded() {
    let mut run = settled_at(DriveConfig::example(), 1.0);
    for (reading, used) in [
        (Some(f32::NAN), 20.0),
        (None, 20.0),
        (Some(f32::INFINITY), 20.0),
        (Some(500.0), 200.0),
        (Some(-50.0), -5.0),
        (Some(f32::NEG_INFINITY), -5.0),
    ] {
        let mut input = run.input();
        input.tension_n = reading;
        let out = run.tick_with(input);
        assert!(
            out.faults.contains(DriveFault::TensionOutOfRange),
            "{reading:?}"
        );
        assert_eq!(out.tension_n, used, "{reading:?}");
    }
    let out = run.tick();
    assert!(out.faults.is_empty());
    assert_eq!(out.tension_n, 20.0);
}

#[test]
fn a_non_finite_command_brings_the_drum_to_rest() {
    let mut run = settled_at(DriveConfig::example(), 2.0);
    let bad = RateCommand {
        rate_mps: f32::NAN,
        accel_mps2: 0.0,
        safe_hold: false,
    };
    assert_eq!(
        run.drive.set_command(bad, run.tick),
        Err(DriveFault::CommandInvalid)
    );
    let mut engaged = false;
    for _ in 0..2000 {
        let out = run.tick();
        assert!(out.faults.contains(DriveFault::CommandInvalid));
        assert!(out.duty.is_finite());
        engaged |= out.brake == Brake::Engaged;
    }
    assert!(engaged && run.drum.speed_mps() == 0.0);
    run.command(0.0, 0.0, false);
    assert!(run.tick().faults.is_empty());
}

#[test]
fn a_repeated_or_backward_tick_changes_nothing() {
    let mut run = settled_at(DriveConfig::example(), 1.0);
    let before = run.drive.output();
    for tick in [before.tick, before.tick - 5] {
        let mut input = run.input();
        input.tick = tick;
        run.drive.step(&input);
        let out = run.drive.output();
        assert!(out.faults.contains(DriveFault::Tick));
        assert_eq!(
            (out.tick, out.duty, out.brake),
            (before.tick, before.duty, before.brake)
        );
    }
    assert!(run.tick().faults.is_empty());
}

#[test]
fn the_length_is_the_integer_count_to_within_a_count() {
    // 20 s out at up to 5 m/s and 20 s back, through ~200 wraps of the 16-bit counter. (That
    // the same counts back give exactly 0 m is `encoder::tests` in the library.)
    let mut run = Run::new(DriveConfig::example());
    let m_per_count = f64::from(run.drive.config().geometry.m_per_count());
    let mut worst_m = 0.0_f64;
    // For contrast only: what summing the speed in f32 each tick would give.
    let mut summed_m = 0.0_f32;
    for (rate, ticks) in [(5.0, 20_000), (-5.0, 20_000), (0.0, 3000)] {
        run.command(rate, 0.0, false);
        for _ in 0..ticks {
            summed_m += run.tick().speed_mps * 1e-3;
            let counted = run.drive.odometer().total_counts();
            assert_eq!(counted, run.read_counts);
            worst_m = worst_m.max((f64::from(run.drive.paid_out_m()) - run.read_paid_out_m).abs());
        }
    }
    println!(
        "odometry over 200 m of travel: worst |length − drum| {worst_m:.2e} m (one count \
         {m_per_count:.2e} m); an f32 sum of speed × tick would be {:.2e} m off",
        (f64::from(summed_m) - run.read_paid_out_m).abs()
    );
    assert!(worst_m < 1.5 * m_per_count);
    // The length is exactly what the count says.
    let counts = run.drive.odometer().total_counts();
    assert_eq!(
        run.drive.paid_out_m(),
        counts as f32 * run.drive.config().geometry.m_per_count()
    );
}

/// An encoder frozen at a low speed (its counter advancing at 0.01–0.05 m/s
/// whatever the drum does) under a command above it. Before the cross-checks the integral
/// wound up to its clamp below the stall duty and the drum ran away (42–47 m/s in 30 s, ≈ 1 km
/// paid out, no fault). The drum's motion now implies a tension no tether can pull (the
/// motor's torque goes unanswered): `NoResponse`, tripped within 0.4 s (0.1 s after a command
/// above the frozen speed has wound the integral), the drum below 2.5 m/s, less than 0.3 m
/// paid out, and stopped by the brake; winding in, within 0.6 s and 1 m.
#[test]
fn a_frozen_encoder_trips_the_drive_before_the_drum_runs_away() {
    for frozen_mps in [0.01, 0.02, 0.05] {
        // (Winding in at 0.5 m/s, the drum's motion implies a tension a tether could pull but
        // the load cell does not read: the load cell is dropped after 0.1 s, then the loop,
        // pinned at its limit, trips the drive.)
        for command_mps in [0.1_f32, 0.5, 1.0, -0.5] {
            let mut run = settled_at(DriveConfig::example(), command_mps);
            let start_m = run.drum.paid_out_m();
            run.freeze_encoder_at(frozen_mps);
            let frozen_at = run.tick;
            let mut tripped = None;
            let mut fastest_mps: f64 = 0.0;
            for _ in 0..30_000 {
                let out = run.tick();
                fastest_mps = fastest_mps.max(run.drum.speed_mps().abs());
                if let Brake::Tripped(f) = out.brake {
                    assert_eq!(out.duty, 0.0);
                    tripped.get_or_insert((f, run.tick - frozen_at));
                }
            }
            let (fault, after) = tripped.unwrap_or_else(|| {
                panic!("frozen at {frozen_mps} m/s under {command_mps} m/s: no trip, {fastest_mps} m/s")
            });
            let paid_m = run.drum.paid_out_m() - start_m;
            println!(
                "frozen at {frozen_mps} m/s under {command_mps} m/s: {fault:?} after {after} ms, \
                 fastest {fastest_mps:.2} m/s, paid out {paid_m:.2} m in 30 s"
            );
            let (latest_ms, fastest, longest_m) = if command_mps > 0.0 {
                assert_eq!(fault, DriveFault::NoResponse);
                (400, 2.5, 0.3)
            } else {
                assert!(matches!(
                    fault,
                    DriveFault::NoResponse | DriveFault::MotorStall
                ));
                (600, 3.0, 1.0)
            };
            assert!(after <= latest_ms, "{after} ms");
            assert!(fastest_mps < fastest, "{fastest_mps} m/s");
            assert_eq!(run.drum.speed_mps(), 0.0, "the brake holds the drum");
            assert!(paid_m.abs() < longest_m, "{paid_m} m");
        }
    }
}

/// A brake that slips while engaged. In safe hold at 20 N (2 N m at the drum)
/// with a brake of 1 N m the drum ran to 14.6 m/s and paid out 808 m in 60 s, the brake
/// "Engaged", no fault. Now the odometer's travel under the engaged brake beyond
/// `brake_slip_m` (20 mm) is `BrakeSlip`, and the motor holds the drum at rest under the
/// brake (`Brake::MotorHold`) whatever the command, until the slip is cleared.
#[test]
fn a_slipping_brake_is_detected_and_the_motor_holds_the_drum() {
    let mut run = settled_at(DriveConfig::example(), 1.0);
    run.drum.brake_nm = 1.0;
    // Safe hold: the drum is brought to rest and the brake engages (and slips).
    run.command(0.0, -1.0, true);
    let mut engaged_m = None;
    let mut held = None;
    for _ in 0..60_000 {
        let out = run.tick();
        if out.brake == Brake::Engaged && engaged_m.is_none() {
            engaged_m = Some(run.drum.paid_out_m());
        }
        if out.brake == Brake::MotorHold && held.is_none() {
            assert!(out.faults.contains(DriveFault::BrakeSlip));
            held = Some((run.tick, run.drum.paid_out_m() - engaged_m.unwrap()));
        }
        if held.is_some() {
            assert_eq!(out.brake, Brake::MotorHold);
            assert!(out.faults.contains(DriveFault::BrakeSlip));
        }
    }
    let engaged_m = engaged_m.expect("the brake engaged");
    let (at, slip_m) = held.expect("the slip is detected");
    let total_m = run.drum.paid_out_m() - engaged_m;
    println!(
        "slipping brake: held by the motor at tick {at} after {:.1} mm of slip; {:.1} mm in 60 s, \
         drum at {:.4} m/s",
        slip_m * 1e3,
        total_m * 1e3,
        run.drum.speed_mps()
    );
    assert!(slip_m < 0.03, "{slip_m} m");
    assert!(total_m < 0.05, "{total_m} m");
    assert!(run.drum.speed_mps().abs() < 1e-3);
    // A moving command does not release the hold; clearing it engages the brake again.
    run.command(1.0, 1.0, false);
    for _ in 0..1000 {
        assert_eq!(run.tick().brake, Brake::MotorHold);
    }
    assert_eq!(run.drive.clear_trip(), Some(DriveFault::BrakeSlip));
    assert_eq!(run.drive.brake(), Brake::Engaged);
    // A brake that holds is never taken for a slipping one.
    let mut run = settled_at(DriveConfig::example(), 1.0);
    run.command(0.0, -1.0, true);
    for _ in 0..10_000 {
        assert!(run.tick().faults.is_empty());
    }
    assert_eq!(run.drive.brake(), Brake::Engaged);
}

/// A load cell reading 199 N against a true 20 N (inside its range) held the drum
/// at 0.14 m/s for a 1 m/s command, no fault. The tension the drum's motion implies under the
/// motor's torque (≈ 20 N) disagrees with it: `TensionMismatch` within half a second, the load
/// cell is dropped from the feed-forward (the integral carries the load) and the drum follows
/// the command again.
#[test]
fn a_load_cell_reading_ten_times_the_tension_is_dropped_and_the_drum_follows() {
    let mut run = settled_at(DriveConfig::example(), 0.5);
    run.command(1.0, 1.0, false);
    let start = run.tick;
    let mut detected = None;
    for _ in 0..5000 {
        let mut input = run.input();
        input.tension_n = Some(199.0);
        let out = run.tick_with(input);
        assert!(!matches!(out.brake, Brake::Tripped(_)), "{out:?}");
        if out.faults.contains(DriveFault::TensionMismatch) && detected.is_none() {
            detected = Some((run.tick - start, run.drive.implied_tension_n()));
        }
    }
    let (after, implied_n) = detected.expect("the mismatch is found");
    println!(
        "load cell 199 N against 20 N: TensionMismatch after {after} ms (implied {implied_n:.1} N); \
         drum at {:.3} m/s for 1 m/s",
        run.drum.speed_mps()
    );
    assert!(after <= 500, "{after} ms");
    assert!(!run.drive.load_cell_trusted());
    assert_eq!(run.drive.output().tension_n, 0.0);
    assert!(
        (run.drum.speed_mps() - 1.0).abs() < 0.01,
        "{}",
        run.drum.speed_mps()
    );
    let implied = f64::from(run.drive.implied_tension_n());
    assert!((implied - 20.0).abs() < 5.0, "{implied} N");
    // Trusted again once cleared.
    assert_eq!(run.drive.clear_trip(), None);
    assert!(run.drive.load_cell_trusted());
}

/// The cross-checks raise nothing on a healthy drive: the law's ramps both ways, through the
/// model's mismatch (10 % inertia, 20 % / 25 % friction), at every tension the motor can hold.
#[test]
fn the_cross_checks_are_quiet_on_a_healthy_drive() {
    for tension_n in [-5.0, 0.0, 10.0, 20.0] {
        let mut run = Run::new(DriveConfig::example());
        run.tension_n = tension_n;
        for (rate, accel) in [(5.0, 5.0), (15.0, 5.0), (-3.0, -5.0), (0.0, 5.0)] {
            run.command(rate, accel, false);
            for _ in 0..5000 {
                let out = run.tick();
                assert!(out.faults.is_empty(), "{tension_n} N, {rate} m/s: {out:?}");
            }
        }
        assert!(run.drive.load_cell_trusted());
    }
}
