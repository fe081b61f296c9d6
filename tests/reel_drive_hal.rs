//! Host tests of the reel drive's hardware boundary (`tss_reel::reel_drive::hal`): the speed
//! loop driving embedded-hal 1.0 outputs, checked with `embedded-hal-mock`'s PWM and pins (every
//! write, in order) and hand mocks of our own encoder and load-cell traits.
//!
//! The pin rules under test (module docs of `reel_drive::hal`): motor enabled → enable high,
//! brake high (released), direction (after a zero duty, if it reverses), duty; otherwise duty
//! 0, enable low, brake low (engaged).

use embedded_hal_mock::eh1::digital::{Mock as PinMock, State, Transaction as Pin};
use embedded_hal_mock::eh1::pwm::{Mock as PwmMock, Transaction as Pwm};
use embedded_hal_mock::eh1::MockError;
use std::collections::VecDeque;
use tss_reel::reel_drive::hal::{
    duty_counts, ActuatorError, ErrorKind, ErrorType, HalReelDrive, LoadCell, MotorPins,
    QuadratureEncoder,
};
use tss_reel::reel_drive::{
    Brake, DriveConfig, DriveFault, DriveInput, DriveOutput, RateCommand, SpeedLoop,
};

/// PWM counts at duty 1.
const MAX_DUTY: u16 = 1000;

/// Readings handed out in order; once they run out, `NoSample`.
struct Readings<T>(VecDeque<Result<T, ErrorKind>>);

impl<T> ErrorType for Readings<T> {
    type Error = ErrorKind;
}

impl QuadratureEncoder for Readings<u32> {
    fn read_count(&mut self) -> Result<u32, ErrorKind> {
        self.0.pop_front().unwrap_or(Err(ErrorKind::NoSample))
    }
}

impl LoadCell for Readings<f32> {
    fn read_tension_n(&mut self) -> Result<f32, ErrorKind> {
        self.0.pop_front().unwrap_or(Err(ErrorKind::NoSample))
    }
}

/// The expected writes of each output.
#[derive(Default)]
struct Expected {
    pwm: Vec<Pwm>,
    direction: Vec<Pin>,
    brake: Vec<Pin>,
    enable: Vec<Pin>,
    /// The direction pin's level after the writes so far.
    paying_out: Option<bool>,
}

impl Expected {
    /// `new`: the maximum duty is read once, then the safe state.
    fn new() -> Self {
        let mut e = Self {
            pwm: vec![Pwm::max_duty_cycle(MAX_DUTY)],
            ..Self::default()
        };
        e.safe_state();
        e
    }

    fn safe_state(&mut self) {
        self.pwm.push(Pwm::set_duty_cycle(0));
        self.enable.push(Pin::set(State::Low));
        self.brake.push(Pin::set(State::Low));
    }

    /// The writes for one output of the speed loop.
    fn tick(&mut self, out: &DriveOutput) {
        if !out.brake.motor_enabled() {
            self.safe_state();
            return;
        }
        self.enable.push(Pin::set(State::High));
        let brake = if out.brake.brake_released() {
            State::High
        } else {
            State::Low
        };
        self.brake.push(Pin::set(brake));
        let paying_out = out.duty >= 0.0;
        if self.paying_out != Some(paying_out) {
            self.pwm.push(Pwm::set_duty_cycle(0));
            let level = if paying_out { State::High } else { State::Low };
            self.direction.push(Pin::set(level));
            self.paying_out = Some(paying_out);
        }
        self.pwm
            .push(Pwm::set_duty_cycle(duty_counts(out.duty, MAX_DUTY)));
    }
}

struct Mocks {
    pwm: PwmMock,
    direction: PinMock,
    brake: PinMock,
    enable: PinMock,
}

impl Mocks {
    fn new(e: &Expected) -> Self {
        Self {
            pwm: PwmMock::new(&e.pwm),
            direction: PinMock::new(&e.direction),
            brake: PinMock::new(&e.brake),
            enable: PinMock::new(&e.enable),
        }
    }

    fn pins(&mut self) -> MotorPins<&mut PwmMock, &mut PinMock, &mut PinMock, &mut PinMock> {
        MotorPins {
            pwm: &mut self.pwm,
            direction: &mut self.direction,
            brake: &mut self.brake,
            enable: &mut self.enable,
        }
    }

    /// Every expected write happened, and no other.
    fn done(mut self) {
        self.pwm.done();
        self.direction.done();
        self.brake.done();
        self.enable.done();
    }
}

/// Counts of a drum paying out at `counts_per_tick` from tick `from` (0 before it), in a
/// 16-bit counter.
fn counts(ticks: u32, from: u32, counts_per_tick: u32) -> VecDeque<Result<u32, ErrorKind>> {
    (0..ticks)
        .map(|t| Ok((t.saturating_sub(from) * counts_per_tick) & 0xFFFF))
        .collect()
}

fn command(rate_mps: f32) -> RateCommand {
    RateCommand {
        rate_mps,
        accel_mps2: 0.0,
        safe_hold: false,
    }
}

#[test]
fn new_puts_the_outputs_in_the_safe_state() {
    let e = Expected::new();
    assert_eq!(e.pwm.len(), 2);
    let mut m = Mocks::new(&e);
    let speed = SpeedLoop::new(DriveConfig::example()).unwrap();
    let drive = HalReelDrive::new(
        speed,
        Readings::<u32>(VecDeque::new()),
        Readings::<f32>(VecDeque::new()),
        m.pins(),
    )
    .unwrap();
    drop(drive);
    m.done();
}

#[test]
fn the_brake_is_released_with_the_holding_torque_then_the_drum_is_driven_in_its_direction() {
    // The first release, written out: duty −0.02 (−T r = −0.1 N m of 5) = 20 counts winding
    // in, brake released, driver enabled.
    let cfg = DriveConfig::example();
    let mut twin = SpeedLoop::new(cfg).unwrap();
    twin.set_command(command(1.0), 0).unwrap();
    let tension = 1.0_f32;
    // The drum has not turned yet (count 0): the PI pushes it (for 100 ticks after the
    // release; a drum that never answers trips, `tests/reel_drive.rs`).
    let encoder = counts(150, 150, 65);
    let mut e = Expected::new();
    let mut outs = Vec::new();
    for (tick, count) in (0..150).zip(encoder.iter()) {
        twin.step(&DriveInput {
            tick,
            encoder_count: count.ok(),
            tension_n: Some(tension),
        });
        let out = twin.output();
        e.tick(&out);
        outs.push(out);
    }
    assert_eq!(outs[0].brake, Brake::Releasing { ticks_left: 50 });
    assert_eq!(
        (&e.pwm[2..5], &e.direction[..1], &e.brake[1], &e.enable[1]),
        (
            &[
                Pwm::set_duty_cycle(0),
                Pwm::set_duty_cycle(20),
                Pwm::set_duty_cycle(20)
            ][..],
            &[Pin::set(State::Low)][..],
            &Pin::set(State::High),
            &Pin::set(State::High)
        )
    );
    // Driving at 1 m/s against friction needs pay-out torque: the direction flips once.
    assert!(outs.last().unwrap().duty > 0.0);
    assert_eq!(
        e.direction,
        [Pin::set(State::Low), Pin::set(State::High)],
        "one reversal"
    );

    let mut m = Mocks::new(&e);
    let speed = SpeedLoop::new(cfg).unwrap();
    let tensions = (0..400).map(|_| Ok(tension)).collect();
    let mut drive =
        HalReelDrive::new(speed, Readings(encoder), Readings(tensions), m.pins()).unwrap();
    drive.set_command(command(1.0), 0).unwrap();
    for (tick, expected) in (0..400).zip(&outs) {
        let cycle = drive.tick(tick);
        assert_eq!(cycle, Default::default());
        assert_eq!(drive.output(), *expected);
    }
    drop(drive);
    m.done();
}

#[test]
fn at_rest_the_brake_engages_and_the_driver_is_switched_off() {
    let mut cfg = DriveConfig::example();
    cfg.brake.release_ticks = 0;
    cfg.brake.engage_ticks = 5;
    // A law period of 10 ticks: the reference reaches 0 within 10 ticks of the command.
    cfg.outer_period_ticks = 10;
    let mut twin = SpeedLoop::new(cfg).unwrap();
    twin.set_command(command(0.5), 0).unwrap();
    let mut e = Expected::new();
    let mut outs = Vec::new();
    // Commanded 0 from tick 20; the drum never moved (count 0): at rest.
    for tick in 0..60 {
        if tick == 20 {
            twin.set_command(command(0.0), tick).unwrap();
        }
        twin.step(&DriveInput {
            tick,
            encoder_count: Some(0),
            tension_n: Some(0.0),
        });
        let out = twin.output();
        e.tick(&out);
        outs.push(out);
    }
    assert!(matches!(outs[19].brake, Brake::Released { .. }));
    // The reference ramps to 0 within a law period at most, then 5 ticks at rest.
    let engaged = outs.iter().position(|o| o.brake == Brake::Engaged);
    let engaged = engaged.unwrap_or_else(|| panic!("{:#?}", &outs[18..24]));
    assert!(engaged > 20 && engaged < 60, "{engaged}");
    assert_eq!(e.brake.last(), Some(&Pin::set(State::Low)));
    assert_eq!(e.enable.last(), Some(&Pin::set(State::Low)));
    assert_eq!(e.pwm.last(), Some(&Pwm::set_duty_cycle(0)));

    let mut m = Mocks::new(&e);
    let speed = SpeedLoop::new(cfg).unwrap();
    let encoder = (0..60).map(|_| Ok(0)).collect();
    let tensions = (0..60).map(|_| Ok(0.0)).collect();
    let mut drive =
        HalReelDrive::new(speed, Readings(encoder), Readings(tensions), m.pins()).unwrap();
    drive.set_command(command(0.5), 0).unwrap();
    for tick in 0..60 {
        if tick == 20 {
            drive.set_command(command(0.0), tick).unwrap();
        }
        assert_eq!(drive.tick(tick), Default::default());
        assert_eq!(drive.output(), outs[tick as usize]);
    }
    drop(drive);
    m.done();
}

#[test]
fn a_refused_pwm_write_trips_the_drive_into_the_safe_state() {
    let mut cfg = DriveConfig::example();
    cfg.brake.release_ticks = 0;
    let mut e = Expected::new();
    // Tick 0: released; the direction is set, then the duty write fails.
    e.enable.push(Pin::set(State::High));
    e.brake.push(Pin::set(State::High));
    e.pwm.push(Pwm::set_duty_cycle(0));
    e.direction.push(Pin::set(State::Low));
    e.pwm
        .push(Pwm::set_duty_cycle(400).with_error(MockError::Io(std::io::ErrorKind::NotConnected)));
    // Then the safe state, now and on the next tick (tripped).
    e.safe_state();
    e.safe_state();
    let mut m = Mocks::new(&e);
    let speed = SpeedLoop::new(cfg).unwrap();
    let encoder = (0..2).map(|_| Ok(0)).collect();
    let tensions = (0..2).map(|_| Ok(20.0)).collect();
    let mut drive =
        HalReelDrive::new(speed, Readings(encoder), Readings(tensions), m.pins()).unwrap();
    drive.set_command(command(1.0), 0).unwrap();
    let cycle = drive.tick(0);
    assert_eq!(
        cycle.actuator_error,
        Some(ActuatorError::Pwm(embedded_hal::pwm::ErrorKind::Other))
    );
    assert_eq!(
        drive.speed_loop().brake(),
        Brake::Tripped(DriveFault::Actuator)
    );
    drive.tick(1);
    assert_eq!(drive.output().duty, 0.0);
    assert!(drive.output().faults.contains(DriveFault::Actuator));
    drop(drive);
    m.done();
}

#[test]
fn failed_reads_are_missing_samples_and_keep_the_brake_engaged() {
    let mut e = Expected::new();
    // Two ticks without a count: the brake is not released for a moving command.
    e.safe_state();
    e.safe_state();
    // The third has one: the release begins (duty −0.4 holds the 20 N).
    e.enable.push(Pin::set(State::High));
    e.brake.push(Pin::set(State::High));
    e.pwm.push(Pwm::set_duty_cycle(0));
    e.direction.push(Pin::set(State::Low));
    e.pwm.push(Pwm::set_duty_cycle(400));
    let mut m = Mocks::new(&e);
    let speed = SpeedLoop::new(DriveConfig::example()).unwrap();
    let encoder = [Err(ErrorKind::Device), Err(ErrorKind::Corrupted), Ok(0)].into();
    let tensions = [Err(ErrorKind::NoSample), Ok(20.0), Ok(20.0)].into();
    let mut drive =
        HalReelDrive::new(speed, Readings(encoder), Readings(tensions), m.pins()).unwrap();
    drive.set_command(command(1.0), 0).unwrap();
    let c0 = drive.tick(0);
    assert_eq!(
        (c0.encoder_error, c0.load_cell_error),
        (Some(ErrorKind::Device), Some(ErrorKind::NoSample))
    );
    let f = drive.output().faults;
    assert!(f.contains(DriveFault::EncoderMissing) && f.contains(DriveFault::TensionOutOfRange));
    assert_eq!(drive.output().brake, Brake::Engaged);
    let c1 = drive.tick(1);
    assert_eq!(c1.encoder_error, Some(ErrorKind::Corrupted));
    assert_eq!(drive.output().brake, Brake::Engaged);
    assert_eq!(drive.tick(2), Default::default());
    assert_eq!(drive.output().brake, Brake::Releasing { ticks_left: 50 });
    drop(drive);
    m.done();
}

/// The QEMU firmware's inner loop on the host: the drive over the simulated reel
/// (`reel_drive::sim`, its drum 10 % / 20 % / 25 % off the drive's model) follows the law's
/// ramps (each reaches its command within the law period) through the brake release, a
/// reversal and a stop, within 1 cm/s of its reference after the release's first 100 ms.
#[test]
fn the_drive_over_the_simulated_reel_tracks_ramps_and_stops() {
    use std::cell::RefCell;
    use tss_reel::reel_drive::sim::{PinRole, SimDrum, SimEncoder, SimLoadCell, SimPin, SimPwm};

    let cfg = DriveConfig::example();
    let drum = RefCell::new(SimDrum::mismatched(&cfg, 20.0));
    let pins = MotorPins {
        pwm: SimPwm(&drum),
        direction: SimPin(&drum, PinRole::Direction),
        brake: SimPin(&drum, PinRole::Brake),
        enable: SimPin(&drum, PinRole::Enable),
    };
    let speed = SpeedLoop::new(cfg).unwrap();
    let mut drive = HalReelDrive::new(speed, SimEncoder(&drum), SimLoadCell(&drum), pins).unwrap();
    // Commands once a second: up to 2 m/s, hold, down to −1 m/s, stop.
    let commands = [0.5, 1.0, 2.0, 2.0, 1.0, -1.0, -1.0, 0.0, 0.0, 0.0];
    let mut worst_mps = 0.0_f32;
    let mut released_ticks = 0;
    for (period, &rate) in commands.iter().enumerate() {
        let start = period as u32 * 1000;
        let cmd = RateCommand {
            rate_mps: rate,
            accel_mps2: 0.0,
            safe_hold: false,
        };
        drive.set_command(cmd, start).unwrap();
        for tick in start..start + 1000 {
            let cycle = drive.tick(tick);
            assert_eq!(cycle, Default::default(), "{tick}");
            drum.borrow_mut().advance(1e-3);
            let out = drive.output();
            assert!(out.faults.is_empty(), "{tick}: {out:?}");
            if matches!(out.brake, Brake::Released { .. }) {
                released_ticks += 1;
                if released_ticks > 100 {
                    let error = (drum.borrow().speed_mps() - out.ref_rate_mps).abs();
                    worst_mps = worst_mps.max(error);
                }
            }
        }
        if (1..=6).contains(&period) {
            assert!((drum.borrow().speed_mps() - rate).abs() < 0.01, "{period}");
        }
    }
    assert!(worst_mps < 0.01, "{worst_mps}");
    // Stopped and braked at the end; the counted length is the drum's, to a count.
    assert_eq!(drive.output().brake, Brake::Engaged);
    assert_eq!(drum.borrow().speed_mps(), 0.0);
    let m_per_count = cfg.geometry.m_per_count();
    let counted = drive.speed_loop().paid_out_m();
    assert!((counted - drum.borrow().paid_out_m()).abs() <= 2.0 * m_per_count);
}

/// A slipping brake on the simulated reel the firmware flies (`reel_drive::sim`), through the
/// hardware boundary: the drum at rest in safe hold under 20 N (2 N m) with a brake of 1 N m.
/// Before the cross-checks it ran away under the "engaged" brake (14.6 m/s and 808 m in 60 s).
/// Now the drive finds the slip (`BrakeSlip`), keeps the brake pin low and enables the motor,
/// which holds the drum: it stops within the slip threshold and stays.
#[test]
fn a_slipping_brake_is_held_by_the_motor_through_the_pins() {
    use core::cell::RefCell;
    use tss_reel::reel_drive::sim::{PinRole, SimDrum, SimEncoder, SimLoadCell, SimPin, SimPwm};
    let cfg = DriveConfig::example();
    let mut sim = SimDrum::mismatched(&cfg, 20.0);
    sim.brake_nm = 1.0;
    let drum = RefCell::new(sim);
    let pins = MotorPins {
        pwm: SimPwm(&drum),
        direction: SimPin(&drum, PinRole::Direction),
        brake: SimPin(&drum, PinRole::Brake),
        enable: SimPin(&drum, PinRole::Enable),
    };
    let speed = SpeedLoop::new(cfg).unwrap();
    let mut drive = HalReelDrive::new(speed, SimEncoder(&drum), SimLoadCell(&drum), pins).unwrap();
    let hold = RateCommand {
        rate_mps: 0.0,
        accel_mps2: 0.0,
        safe_hold: true,
    };
    drive.set_command(hold, 0).unwrap();
    let mut held_at = None;
    for tick in 0..60_000 {
        drive.tick(tick);
        let out = drive.output();
        if out.brake == Brake::MotorHold {
            held_at.get_or_insert((tick, drum.borrow().paid_out_m()));
            assert!(out.faults.contains(DriveFault::BrakeSlip));
        }
        drum.borrow_mut().advance(1e-3);
    }
    let (tick, slip_m) = held_at.expect("the slip is found");
    let d = drum.borrow();
    println!(
        "slipping brake on the simulated reel: held at tick {tick} after {:.1} mm; {:.1} mm in 60 s",
        slip_m * 1e3,
        d.paid_out_m() * 1e3
    );
    assert!(
        slip_m < 0.03 && d.paid_out_m() < 0.05,
        "{slip_m} m, {} m",
        d.paid_out_m()
    );
    assert!(d.speed_mps().abs() < 1e-3, "{}", d.speed_mps());
    assert_eq!(drive.output().brake, Brake::MotorHold);
    assert!(drive.output().brake.motor_enabled() && !drive.output().brake.brake_released());
}
