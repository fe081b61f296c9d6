//! Host tests of the reel's inner speed loop (issue 19, `tss_reel::reel_drive`) against a drum
//! model: tracking of a ramp and a step, anti-windup, the brake sequence, every drive fault
//! raised when it must and not otherwise, drift-free odometry, and any input giving a finite,
//! bounded duty.
//!
//! The drum (in f64) has the shape of WinchModels.jl's winch: J ω̇ = τ + T r − b ω − c sgn ω,
//! with stiction at rest, the motor's torque limit and a spring brake that takes
//! `BRAKE_LIFT_TICKS` to lift. It is deliberately not the speed loop's own model: 10 % more
//! inertia, 20 % more viscous and 25 % more Coulomb friction than `DriveConfig::example()`
//! feeds forward. Its encoder is the 16-bit counter of the example (it wraps every 0.16 m).

use proptest::prelude::*;
use std::f64::consts::TAU;

/// The drive's faults in the outer controller's health (`Controller::step_with_drive`).
#[path = "reel_drive/health.rs"]
mod health;
use tss_reel::reel_drive::{
    Brake, DriveConfig, DriveFault, DriveInput, DriveOutput, DriveRule, RateCommand, SpeedLoop,
};

/// Ticks the test drum's brake takes to lift once its pin is high (the loop waits 50).
const BRAKE_LIFT_TICKS: u32 = 40;
/// Integration substeps of the drum per inner tick.
const SUBSTEPS: u32 = 10;

/// The test drum.
#[derive(Clone, Debug)]
struct Drum {
    inertia_kgm2: f64,
    viscous: f64,
    coulomb_nm: f64,
    radius_m: f64,
    max_torque_nm: f64,
    counts_per_rev: f64,
    angle_rad: f64,
    rate_radps: f64,
    /// Ticks the brake pin has been high.
    brake_high_ticks: u32,
    /// Seized: it does not turn whatever the torque.
    jammed: bool,
    /// The spring brake's holding torque, N m (infinite: it holds whatever the torque).
    brake_nm: f64,
}

impl Drum {
    fn new(cfg: &DriveConfig) -> Self {
        Self {
            inertia_kgm2: 1.1 * f64::from(cfg.drum.inertia_kgm2),
            viscous: 1.2 * f64::from(cfg.drum.viscous_nm_per_radps),
            coulomb_nm: 1.25 * f64::from(cfg.drum.coulomb_nm),
            radius_m: f64::from(cfg.geometry.drum_radius_m),
            max_torque_nm: f64::from(cfg.max_torque_nm),
            counts_per_rev: f64::from(cfg.geometry.counts_per_drum_rev()),
            angle_rad: 0.0,
            rate_radps: 0.0,
            brake_high_ticks: 0,
            jammed: false,
            brake_nm: f64::INFINITY,
        }
    }

    fn speed_mps(&self) -> f64 {
        self.rate_radps * self.radius_m
    }

    fn paid_out_m(&self) -> f64 {
        self.angle_rad * self.radius_m
    }

    fn counts(&self) -> i64 {
        (self.angle_rad / TAU * self.counts_per_rev).floor() as i64
    }

    /// The 16-bit hardware counter.
    fn raw_count(&self) -> u32 {
        (self.counts() as u32) & 0xFFFF
    }

    /// One inner tick of `dt_s` with the motor at `duty` and the brake pin as given.
    fn advance(&mut self, duty: f64, brake_pin_high: bool, tension_n: f64, dt_s: f64) {
        self.brake_high_ticks = if brake_pin_high {
            self.brake_high_ticks + 1
        } else {
            0
        };
        let braked = self.brake_high_ticks <= BRAKE_LIFT_TICKS;
        if self.jammed || (braked && self.brake_nm == f64::INFINITY) {
            self.rate_radps = 0.0;
            return;
        }
        // A brake that can slip adds its torque to the friction.
        let friction = if braked {
            self.coulomb_nm + self.brake_nm
        } else {
            self.coulomb_nm
        };
        let h = dt_s / f64::from(SUBSTEPS);
        let motor = (duty * self.max_torque_nm).clamp(-self.max_torque_nm, self.max_torque_nm);
        for _ in 0..SUBSTEPS {
            let w = self.rate_radps;
            let drive = motor + tension_n * self.radius_m - self.viscous * w;
            let next = if w == 0.0 && drive.abs() <= friction {
                0.0 // stiction holds
            } else {
                let sign = if w != 0.0 { w.signum() } else { drive.signum() };
                let n = w + (drive - friction * sign) / self.inertia_kgm2 * h;
                if w != 0.0 && n.signum() != w.signum() {
                    0.0
                } else {
                    n
                }
            };
            self.angle_rad += 0.5 * (w + next) * h;
            self.rate_radps = next;
        }
    }
}

/// The speed loop flying the test drum.
struct Run {
    drive: SpeedLoop,
    drum: Drum,
    tick: u32,
    tension_n: f64,
    dt_s: f64,
    /// The drum's count and paid-out length when the encoder was last read.
    read_counts: i64,
    read_paid_out_m: f64,
    /// A frozen encoder: from its tick on, it counts at a fixed rate from the count it had,
    /// whatever the drum does (tick, count, counts per tick).
    frozen: Option<(u32, i64, f64)>,
}

impl Run {
    fn new(cfg: DriveConfig) -> Self {
        Self {
            drum: Drum::new(&cfg),
            dt_s: 1.0 / f64::from(cfg.inner_rate_hz),
            drive: SpeedLoop::new(cfg).unwrap(),
            tick: 0,
            tension_n: 20.0,
            read_counts: 0,
            read_paid_out_m: 0.0,
            frozen: None,
        }
    }

    /// Freezes the encoder from now on at `rate_mps`: its counter advances at that speed
    /// whatever the drum does.
    fn freeze_encoder_at(&mut self, rate_mps: f64) {
        let m_per_count = TAU * self.drum.radius_m / self.drum.counts_per_rev;
        self.frozen = Some((
            self.tick,
            self.drum.counts(),
            rate_mps * self.dt_s / m_per_count,
        ));
    }

    fn command(&mut self, rate_mps: f32, accel_mps2: f32, safe_hold: bool) {
        self.drive
            .set_command(
                RateCommand {
                    rate_mps,
                    accel_mps2,
                    safe_hold,
                },
                self.tick,
            )
            .unwrap();
    }

    fn input(&self) -> DriveInput {
        let raw = match self.frozen {
            Some((from, count, per_tick)) => {
                let counted = count + (f64::from(self.tick - from) * per_tick).floor() as i64;
                (counted as u32) & 0xFFFF
            }
            None => self.drum.raw_count(),
        };
        DriveInput {
            tick: self.tick,
            encoder_count: Some(raw),
            tension_n: Some(self.tension_n as f32),
        }
    }

    /// One tick with the given readings.
    fn tick_with(&mut self, input: DriveInput) -> DriveOutput {
        self.read_counts = self.drum.counts();
        self.read_paid_out_m = self.drum.paid_out_m();
        self.drive.step(&input);
        let out = self.drive.output();
        self.drum.advance(
            f64::from(out.duty),
            out.brake.brake_released(),
            self.tension_n,
            self.dt_s,
        );
        self.tick += 1;
        out
    }

    fn tick(&mut self) -> DriveOutput {
        self.tick_with(self.input())
    }
}

/// A configuration whose reference steps within one tick (law period of one tick, no
/// acceleration limit to speak of): the speed loop's step response.
fn stepping() -> DriveConfig {
    DriveConfig {
        outer_period_ticks: 1,
        max_accel_mps2: 1e6,
        ..DriveConfig::example()
    }
}

/// Releases the brake on a command of `rate_mps` and settles there for 2 s.
fn settled_at(cfg: DriveConfig, rate_mps: f32) -> Run {
    let mut run = Run::new(cfg);
    run.command(rate_mps, 0.0, false);
    for _ in 0..2000 {
        let out = run.tick();
        assert!(out.faults.is_empty(), "{out:?}");
    }
    assert!(matches!(run.drive.brake(), Brake::Released { .. }));
    assert!((run.drum.speed_mps() - f64::from(rate_mps)).abs() < 0.01);
    run
}

#[test]
fn follows_the_laws_ramp_within_5_mm_per_s() {
    // The law's commands once a second: 0.5 m/s² (its Eq. 30 value) up to 5 m/s, held 3 s.
    let mut run = Run::new(DriveConfig::example());
    let mut worst_ramp = 0.0_f64;
    let mut worst_hold = 0.0_f64;
    for period in 0..13_u32 {
        let rate = (0.5 * (period + 1) as f32).min(5.0);
        let accel = if rate < 5.0 { 0.5 } else { 0.0 };
        run.command(rate, accel, false);
        for _ in 0..1000 {
            let out = run.tick();
            assert!(out.faults.is_empty(), "tick {}: {out:?}", out.tick);
            // From 0.2 s after the brake is free: the speed against the reference.
            if run.tick > 250 {
                let err = (run.drum.speed_mps() - f64::from(out.ref_rate_mps)).abs();
                if out.ref_accel_mps2 != 0.0 {
                    worst_ramp = worst_ramp.max(err);
                } else if run.tick > 10_500 {
                    worst_hold = worst_hold.max(err);
                }
            }
        }
    }
    println!("ramp 0.5 m/s²: worst |v − v_ref| {worst_ramp:.5} m/s; at 5 m/s {worst_hold:.5} m/s");
    assert!(worst_ramp < 5e-3, "{worst_ramp}");
    assert!(worst_hold < 2e-3, "{worst_hold}");
    // The reference reaches each command by the end of its period: 5 m/s at the end.
    assert!((run.drum.speed_mps() - 5.0).abs() < 2e-3);
}

#[test]
fn a_step_of_0_2_m_per_s_rises_in_under_80_ms_with_less_than_25_percent_overshoot() {
    let mut run = settled_at(stepping(), 1.0);
    run.command(1.2, 0.0, false);
    let start = run.tick;
    let mut rise_ticks = None;
    let mut peak = 0.0_f64;
    let mut settled_from = None;
    for _ in 0..1000 {
        let out = run.tick();
        assert!(out.faults.is_empty(), "{out:?}");
        let v = run.drum.speed_mps();
        peak = peak.max(v);
        if rise_ticks.is_none() && v >= 1.0 + 0.9 * 0.2 {
            rise_ticks = Some(run.tick - start);
        }
        if (v - 1.2).abs() > 0.02 * 0.2 {
            settled_from = None;
        } else if settled_from.is_none() {
            settled_from = Some(run.tick - start);
        }
    }
    let overshoot = (peak - 1.2) / 0.2;
    println!(
        "step 1.0 -> 1.2 m/s: 90 % after {rise_ticks:?} ms, overshoot {:.1} %, within 2 % from {settled_from:?} ms",
        100.0 * overshoot
    );
    assert!(rise_ticks.is_some_and(|t| t < 80));
    assert!(overshoot < 0.25, "{overshoot}");
    assert!(settled_from.is_some_and(|t| t < 400));
}

#[test]
fn anti_windup_bounds_the_overshoot_after_a_saturated_step() {
    // 0 -> 10 m/s in one tick: the duty saturates for most of a second.
    let mut run = settled_at(stepping(), 0.5);
    run.command(10.0, 0.0, false);
    let mut saturated_ticks = 0;
    let mut peak = 0.0_f64;
    for _ in 0..3000 {
        let out = run.tick();
        saturated_ticks += u32::from(out.saturated);
        peak = peak.max(run.drum.speed_mps());
        assert!(out.faults.is_empty(), "{out:?}");
    }
    let overshoot_mps = peak - 10.0;
    println!(
        "step 0.5 -> 10 m/s: saturated {saturated_ticks} ms, overshoot {overshoot_mps:.4} m/s"
    );
    assert!(
        saturated_ticks > 500,
        "the step must saturate to test anti-windup"
    );
    // Measured: 0.046 m/s; with the integral only clamped (no conditional integration),
    // 0.239 m/s.
    assert!(overshoot_mps < 0.08, "{overshoot_mps}");
    assert!((run.drum.speed_mps() - 10.0).abs() < 0.01);
}

#[test]
fn the_brake_releases_before_motion_and_engages_after_rest() {
    let mut run = Run::new(DriveConfig::example());
    for _ in 0..10 {
        let out = run.tick();
        assert_eq!((out.brake, out.duty), (Brake::Engaged, 0.0));
    }
    run.command(1.0, 1.0, false);
    let first = run.tick();
    assert_eq!(first.brake, Brake::Releasing { ticks_left: 50 });
    // While the brake lifts, the motor holds the tension's torque (−T r = −2 N m of 5) and the
    // reference stays at rest: the drum does not lurch when the brake lets go.
    for _ in 1..50 {
        let out = run.tick();
        assert!(matches!(out.brake, Brake::Releasing { .. }), "{out:?}");
        assert_eq!((out.ref_rate_mps, out.duty), (0.0, -0.4));
    }
    assert!(
        run.drum.speed_mps().abs() < 1e-3,
        "{}",
        run.drum.speed_mps()
    );
    assert_eq!(run.tick().brake, Brake::Released { rest_ticks: 0 });
    for _ in 0..2000 {
        run.tick();
    }
    assert!((run.drum.speed_mps() - 1.0).abs() < 2e-3);
    // Stop: the law ramps to 0 at 1 m/s²; the brake engages 200 ticks after the drum is at
    // rest, not before.
    run.command(0.0, -1.0, false);
    let mut rest_from = None;
    let engaged_at = loop {
        let out = run.tick();
        assert!(out.faults.is_empty(), "{out:?}");
        if out.brake == Brake::Engaged {
            break out.tick;
        }
        let resting = out.ref_rate_mps.abs() <= 0.005 && out.speed_mps.abs() <= 0.005;
        match (resting, rest_from) {
            (true, None) => rest_from = Some(out.tick),
            (false, _) => rest_from = None,
            _ => {}
        }
        assert!(run.tick < 10_000, "never engaged");
    };
    // Engaged on the 200th tick at rest.
    assert_eq!(engaged_at - rest_from.unwrap(), 199);
    assert_eq!(run.tick().duty, 0.0);
}

#[test]
fn safe_hold_brings_the_drum_to_rest_and_keeps_the_brake_engaged() {
    // At rest, a moving command in safe hold does not release the brake.
    let mut run = Run::new(DriveConfig::example());
    run.command(1.0, 0.0, true);
    for _ in 0..2000 {
        assert_eq!(run.tick().brake, Brake::Engaged);
    }
    // Releasing, then safe hold: back to engaged at once.
    run.command(1.0, 0.0, false);
    assert!(matches!(run.tick().brake, Brake::Releasing { .. }));
    run.command(1.0, 0.0, true);
    assert_eq!(run.tick().brake, Brake::Engaged);
    // Moving when safe hold begins: the drum follows the outer ramp down (no hard stop), the
    // brake engages at rest and stays engaged.
    let mut run = settled_at(DriveConfig::example(), 2.0);
    run.command(1.0, -1.0, true);
    for _ in 0..1000 {
        assert!(matches!(run.tick().brake, Brake::Released { .. }));
    }
    run.command(0.0, -1.0, true);
    let mut engaged = false;
    for _ in 0..2000 {
        let out = run.tick();
        engaged |= out.brake == Brake::Engaged;
        if engaged {
            assert_eq!((out.brake, out.duty), (Brake::Engaged, 0.0));
        }
    }
    assert!(engaged);
    run.command(1.0, 1.0, true);
    for _ in 0..1000 {
        assert_eq!(run.tick().brake, Brake::Engaged);
    }
}

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

/// Issue 28 §2: an encoder frozen at a low speed (its counter advancing at 0.01–0.05 m/s
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

/// Issue 28 §2: a brake that slips while engaged. In safe hold at 20 N (2 N m at the drum)
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

/// Issue 28 §2: a load cell reading 199 N against a true 20 N (inside its range) held the drum
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

#[test]
fn every_invalid_parameter_is_named() {
    let ok = DriveConfig::example();
    assert_eq!(ok.validate(), Ok(()));
    type Breaker = fn(&mut DriveConfig);
    let cases: [(&str, DriveRule, Breaker); 18] = [
        ("inner_rate_hz", DriveRule::BelowMinimum, |c| {
            c.inner_rate_hz = 50
        }),
        ("outer_period_ticks", DriveRule::NotPositive, |c| {
            c.outer_period_ticks = 0
        }),
        ("geometry.gear_ratio", DriveRule::TooManyCounts, |c| {
            c.geometry.gear_ratio = 5000
        }),
        ("geometry.drum_radius_m", DriveRule::NotFinite, |c| {
            c.geometry.drum_radius_m = f32::NAN
        }),
        ("geometry.encoder_bits", DriveRule::OutOfRange, |c| {
            c.geometry.encoder_bits = 33
        }),
        ("speed_window_ticks", DriveRule::OutOfRange, |c| {
            c.speed_window_ticks = 6
        }),
        ("drum.coulomb_nm", DriveRule::Negative, |c| {
            c.drum.coulomb_nm = -0.1
        }),
        ("duty_limit", DriveRule::OutOfRange, |c| c.duty_limit = 1.5),
        (
            "faults.max_encoder_rate_mps",
            DriveRule::BelowMaxSpeed,
            |c| c.faults.max_encoder_rate_mps = 10.0,
        ),
        (
            "faults.encoder_trip_ticks",
            DriveRule::CounterAmbiguous,
            |c| c.faults.encoder_trip_ticks = 30,
        ),
        ("faults.stall_duty", DriveRule::OutOfRange, |c| {
            c.faults.stall_duty = 0.95
        }),
        ("brake.engage_ticks", DriveRule::OutOfRange, |c| {
            c.brake.engage_ticks = 1 << 31
        }),
        ("faults.stall_ticks", DriveRule::OutOfRange, |c| {
            c.faults.stall_ticks = u32::MAX
        }),
        ("faults.max_tension_n", DriveRule::BandInverted, |c| {
            c.faults.max_tension_n = -10.0
        }),
        (
            "faults.observer_bandwidth_radps",
            DriveRule::OutOfRange,
            |c| c.faults.observer_bandwidth_radps = 600.0,
        ),
        ("faults.tension_mismatch_n", DriveRule::NotPositive, |c| {
            c.faults.tension_mismatch_n = 0.0
        }),
        ("faults.no_response_ticks", DriveRule::NotPositive, |c| {
            c.faults.no_response_ticks = 0
        }),
        ("faults.brake_slip_m", DriveRule::NotFinite, |c| {
            c.faults.brake_slip_m = f32::INFINITY
        }),
    ];
    for (param, rule, break_it) in cases {
        let mut cfg = DriveConfig {
            duty_limit: 0.9,
            ..ok
        };
        cfg.faults.stall_duty = 0.8;
        break_it(&mut cfg);
        let err = SpeedLoop::new(cfg).expect_err(param);
        assert_eq!((err.param, err.rule), (param, rule), "{err}");
    }
}

/// Any f32, NaN and infinities included, often.
fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        any::<u32>().prop_map(f32::from_bits),
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(f32::NEG_INFINITY),
        -300.0_f32..300.0,
    ]
}

#[derive(Clone, Debug)]
enum Event {
    Step {
        tick_advance: i16,
        count: Option<u32>,
        count_step: i32,
        tension_n: Option<f32>,
    },
    Command(f32, f32, bool),
    ClearTrip,
}

fn event() -> impl Strategy<Value = Event> {
    prop_oneof![
        6 => (
            prop_oneof![4 => Just(1_i16), 1 => any::<i16>()],
            proptest::option::weighted(0.1, any::<u32>()),
            -3000_i32..3000,
            proptest::option::weighted(0.9, any_f32()),
        )
            .prop_map(|(tick_advance, count, count_step, tension_n)| Event::Step {
                tick_advance,
                count,
                count_step,
                tension_n,
            }),
        1 => (any_f32(), any_f32(), any::<bool>()).prop_map(|(r, a, h)| Event::Command(r, a, h)),
        1 => Just(Event::ClearTrip),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Any readings (every f32, missing, huge or wrapping counts, repeated, backward or
    /// jumping ticks) and any commands: the duty is finite and within the limit, every part of
    /// the output is finite, and the motor is off whenever the brake is engaged.
    #[test]
    fn any_input_gives_a_finite_bounded_duty(
        bits32 in any::<bool>(),
        start_tick in any::<u32>(),
        events in proptest::collection::vec(event(), 1..400),
    ) {
        let mut cfg = DriveConfig::example();
        if bits32 {
            cfg.geometry.encoder_bits = 32;
        }
        let mut drive = SpeedLoop::new(cfg).unwrap();
        let mut tick = start_tick;
        let mut raw = 0_u32;
        for e in events {
            match e {
                Event::Command(rate_mps, accel_mps2, safe_hold) => {
                    let r = drive.set_command(RateCommand { rate_mps, accel_mps2, safe_hold }, tick);
                    prop_assert_eq!(r.is_ok(), rate_mps.is_finite() && accel_mps2.is_finite());
                }
                Event::ClearTrip => {
                    drive.clear_trip();
                }
                Event::Step { tick_advance, count, count_step, tension_n } => {
                    tick = tick.wrapping_add_signed(i32::from(tick_advance));
                    raw = raw.wrapping_add_signed(count_step);
                    drive.step(&DriveInput {
                        tick,
                        encoder_count: count.or(Some(raw)),
                        tension_n,
                    });
                    let out = drive.output();
                    prop_assert!(out.duty.is_finite() && out.duty.abs() <= cfg.duty_limit, "{:?}", out);
                    let p = drive.torque_parts();
                    for v in [
                        out.ref_rate_mps, out.ref_accel_mps2, out.speed_mps, p.error_mps,
                        p.p_nm, p.i_nm, p.ff_inertia_nm, p.ff_tension_nm,
                        p.ff_friction_nm, out.tension_n, out.torque_nm,
                    ] {
                        prop_assert!(v.is_finite(), "{:?}", out);
                    }
                    prop_assert!(out.ref_rate_mps.abs() <= cfg.max_speed_mps);
                    if !out.brake.motor_enabled() {
                        prop_assert_eq!(out.duty, 0.0);
                    }
                    prop_assert!(drive.paid_out_m().is_finite());
                }
            }
        }
    }
}
