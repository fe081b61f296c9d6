//! The reel drive's hardware boundary: the speed loop over embedded-hal 1.0.
//!
//! The motor is a PWM channel ([`embedded_hal::pwm::SetDutyCycle`]) into a driver in torque
//! (current) mode, with three [`embedded_hal::digital::OutputPin`]s:
//!
//! | pin | high | low |
//! |---|---|---|
//! | direction | pay out (duty > 0) | wind in |
//! | brake | brake released (coil energised) | brake engaged (spring-applied: a dead MCU or a cut wire brakes) |
//! | enable | motor driver enabled | driver off (no torque) |
//!
//! The motor is enabled with the brake released, or with it engaged while the motor holds the
//! drum against a slipping brake ([`super::Brake::MotorHold`]).
//!
//! embedded-hal 1.0 has no encoder or ADC traits, so the quadrature counter and the load cell
//! are small traits of our own in the style of [`crate::hal`] (associated error with a
//! [`kind`](Error::kind), fallible, blanket `&mut T`). A failed read is a missing sample for the
//! speed loop ([`DriveFault::EncoderMissing`], [`DriveFault::TensionOutOfRange`]); a refused
//! write trips the drive ([`DriveFault::Actuator`]) and the driver then tries to put every
//! output in its safe state.

use embedded_hal::digital::OutputPin;
use embedded_hal::pwm::SetDutyCycle;

pub use crate::hal::{Error, ErrorKind, ErrorType};

use super::{DriveFault, DriveOutput, MotorCommand, RateCommand, SpeedLoop};

/// The drum's quadrature encoder: a free-running hardware counter (a timer in encoder mode).
pub trait QuadratureEncoder: ErrorType {
    /// The raw counter value; only its low [`Geometry::encoder_bits`](super::Geometry::encoder_bits)
    /// are used, and it may wrap.
    fn read_count(&mut self) -> Result<u32, Self::Error>;
}

/// The tether-tension load cell at the reel.
pub trait LoadCell: ErrorType {
    /// The tension, N (pulling the tether out of the reel is positive).
    fn read_tension_n(&mut self) -> Result<f32, Self::Error>;
}

impl<T: QuadratureEncoder + ?Sized> QuadratureEncoder for &mut T {
    fn read_count(&mut self) -> Result<u32, Self::Error> {
        T::read_count(self)
    }
}

impl<T: LoadCell + ?Sized> LoadCell for &mut T {
    fn read_tension_n(&mut self) -> Result<f32, Self::Error> {
        T::read_tension_n(self)
    }
}

/// The motor driver's outputs.
#[derive(Debug)]
pub struct MotorPins<M, D, B, E> {
    /// Motor PWM (duty = |torque| / max torque).
    pub pwm: M,
    /// Direction (high: pay out).
    pub direction: D,
    /// Brake (high: released).
    pub brake: B,
    /// Driver enable (high: enabled).
    pub enable: E,
}

/// An output that refused a write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ActuatorError {
    /// The PWM channel.
    Pwm(embedded_hal::pwm::ErrorKind),
    /// The direction pin.
    Direction(embedded_hal::digital::ErrorKind),
    /// The brake pin.
    Brake(embedded_hal::digital::ErrorKind),
    /// The enable pin.
    Enable(embedded_hal::digital::ErrorKind),
}

// embedded-hal's kinds implement defmt 0.3's `Format` only (its `defmt-03` feature), not
// defmt 1's: they are logged through their `Debug`.
#[cfg(feature = "defmt")]
impl defmt::Format for ActuatorError {
    fn format(&self, f: defmt::Formatter) {
        use defmt::Debug2Format as D;
        match self {
            Self::Pwm(k) => defmt::write!(f, "Pwm({})", D(k)),
            Self::Direction(k) => defmt::write!(f, "Direction({})", D(k)),
            Self::Brake(k) => defmt::write!(f, "Brake({})", D(k)),
            Self::Enable(k) => defmt::write!(f, "Enable({})", D(k)),
        }
    }
}

/// What one tick of the driver did besides stepping the speed loop (whose output is
/// [`HalReelDrive::output`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriveCycle {
    /// The encoder's read error, if any (the speed loop saw a missing count).
    pub encoder_error: Option<ErrorKind>,
    /// The load cell's read error, if any (the speed loop saw a missing tension).
    pub load_cell_error: Option<ErrorKind>,
    /// The first refused write, if any (the drive is then tripped).
    pub actuator_error: Option<ActuatorError>,
}

/// The reel drive on real (or mocked) hardware: reads the encoder and load cell, steps the
/// [`SpeedLoop`] and sets the motor outputs, once an inner tick.
#[derive(Debug)]
pub struct HalReelDrive<C, L, M, D, B, E> {
    speed: SpeedLoop,
    encoder: C,
    load_cell: L,
    pins: MotorPins<M, D, B, E>,
    max_duty: u16,
    /// The direction pin's last written level (`None` before the first write).
    paying_out: Option<bool>,
}

impl<C, L, M, D, B, E> HalReelDrive<C, L, M, D, B, E>
where
    C: QuadratureEncoder,
    L: LoadCell,
    M: SetDutyCycle,
    D: OutputPin,
    B: OutputPin,
    E: OutputPin,
{
    /// Takes the hardware and puts it in the safe state (duty 0, driver off, brake engaged).
    pub fn new(
        speed: SpeedLoop,
        encoder: C,
        load_cell: L,
        pins: MotorPins<M, D, B, E>,
    ) -> Result<Self, ActuatorError> {
        let max_duty = pins.pwm.max_duty_cycle();
        let mut drive = Self {
            speed,
            encoder,
            load_cell,
            pins,
            max_duty,
            paying_out: None,
        };
        drive.safe_state()?;
        Ok(drive)
    }

    /// Takes the law's command (see [`SpeedLoop::set_command`]).
    pub fn set_command(&mut self, cmd: RateCommand, tick: u32) -> Result<(), DriveFault> {
        self.speed.set_command(cmd, tick)
    }

    /// One inner tick: read, step, write.
    pub fn tick(&mut self, tick: u32) -> DriveCycle {
        let count = self.encoder.read_count().map_err(|e| e.kind());
        let tension = self.load_cell.read_tension_n().map_err(|e| e.kind());
        self.speed.step(&super::DriveInput {
            tick,
            encoder_count: count.ok(),
            tension_n: tension.ok(),
        });
        let actuator_error = self.apply(self.speed.motor()).err();
        if actuator_error.is_some() {
            self.speed.trip(DriveFault::Actuator);
            // Best effort: the first error is the one reported.
            let _ = self.safe_state();
        }
        DriveCycle {
            encoder_error: count.err(),
            load_cell_error: tension.err(),
            actuator_error,
        }
    }

    /// The speed loop's last output (what the outputs were set to), worked out when asked
    /// ([`SpeedLoop::output`]).
    pub fn output(&self) -> DriveOutput {
        self.speed.output()
    }

    /// The speed loop.
    pub fn speed_loop(&self) -> &SpeedLoop {
        &self.speed
    }

    /// The speed loop, to clear a trip.
    pub fn speed_loop_mut(&mut self) -> &mut SpeedLoop {
        &mut self.speed
    }

    /// Gives the hardware back.
    pub fn release(self) -> (SpeedLoop, C, L, MotorPins<M, D, B, E>) {
        (self.speed, self.encoder, self.load_cell, self.pins)
    }

    /// Sets the outputs for `out`: with the motor enabled, enable, the brake (released, or
    /// engaged while the motor holds a slipping brake), then direction (after a zero duty if
    /// it reverses) and duty; otherwise duty 0, driver off, brake engaged, in that order.
    fn apply(&mut self, out: MotorCommand) -> Result<(), ActuatorError> {
        if !out.brake.motor_enabled() {
            return self.safe_state();
        }
        let p = &mut self.pins;
        p.enable
            .set_high()
            .map_err(|e| ActuatorError::Enable(embedded_hal::digital::Error::kind(&e)))?;
        p.brake
            .set_state(out.brake.brake_released().into())
            .map_err(|e| ActuatorError::Brake(embedded_hal::digital::Error::kind(&e)))?;
        let paying_out = out.duty >= 0.0;
        if self.paying_out != Some(paying_out) {
            p.pwm.set_duty_cycle(0).map_err(pwm_error)?;
            p.direction
                .set_state(paying_out.into())
                .map_err(|e| ActuatorError::Direction(embedded_hal::digital::Error::kind(&e)))?;
            self.paying_out = Some(paying_out);
        }
        p.pwm
            .set_duty_cycle(duty_counts(out.duty, self.max_duty))
            .map_err(pwm_error)
    }

    /// Duty 0, driver off, brake engaged.
    fn safe_state(&mut self) -> Result<(), ActuatorError> {
        let p = &mut self.pins;
        p.pwm.set_duty_cycle(0).map_err(pwm_error)?;
        p.enable
            .set_low()
            .map_err(|e| ActuatorError::Enable(embedded_hal::digital::Error::kind(&e)))?;
        p.brake
            .set_low()
            .map_err(|e| ActuatorError::Brake(embedded_hal::digital::Error::kind(&e)))
    }
}

fn pwm_error<T: embedded_hal::pwm::Error>(e: T) -> ActuatorError {
    ActuatorError::Pwm(e.kind())
}

/// |duty| as PWM counts of `max` (rounded to nearest; a non-finite or out-of-range duty,
/// which the speed loop never gives, is clamped to [0, max]).
pub fn duty_counts(duty: f32, max: u16) -> u16 {
    let counts = duty.abs() * f32::from(max) + 0.5;
    // `as` saturates (NaN → 0), and the result is clamped to max.
    (counts as u16).min(max)
}
