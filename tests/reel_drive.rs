//! Host tests of the reel's inner speed loop (`tss_reel::reel_drive`) against a drum
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

#[path = "reel_drive/faults.rs"]
mod faults;
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
