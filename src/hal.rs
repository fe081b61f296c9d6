//! Hardware abstraction: the reel MCU's sensors and actuator as small traits in the style of
//! `embedded-hal` 1.0 (which has no encoder, ADC or capture traits), and the one function that
//! connects them to the controller each control period.
//!
//! Every trait has an associated error whose [`Error::kind`] says what went wrong; every method
//! is fallible; blanket implementations for `&mut T` let drivers be borrowed. The firmware's
//! built-in replay, the processor-in-the-loop serial link and the real hardware are just
//! different implementations of these traits.

use crate::controller::{Controller, Input, Output};

/// What kind of failure a sensor or actuator reported.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ErrorKind {
    /// No new sample this period (dropout, timeout, link loss).
    NoSample,
    /// A sample arrived but failed its integrity check (CRC, framing, sequence).
    Corrupted,
    /// The device reported a fault of its own.
    Device,
    /// Anything else.
    Other,
}

/// A sensor or actuator error.
pub trait Error: core::fmt::Debug {
    /// The kind of failure.
    fn kind(&self) -> ErrorKind;
}

impl Error for ErrorKind {
    fn kind(&self) -> ErrorKind {
        *self
    }
}

/// The error type of a device.
pub trait ErrorType {
    /// Its error.
    type Error: Error;
}

impl<T: ErrorType + ?Sized> ErrorType for &mut T {
    type Error = T::Error;
}

/// The reel's length encoder.
pub trait LengthSensor: ErrorType {
    /// The deployed tether length for control period `tick`, m.
    fn read_length_m(&mut self, tick: u32) -> Result<f32, Self::Error>;
}

/// One reading of the in-plane swing sensor.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Swing {
    /// In-plane angle α, rad.
    pub alpha_rad: f32,
    /// In-plane rate α̇, rad/s.
    pub alpha_rate_radps: f32,
}

/// The tether swing-angle sensor (α and α̇).
pub trait SwingSensor: ErrorType {
    /// α and α̇ for control period `tick`.
    fn read_swing(&mut self, tick: u32) -> Result<Swing, Self::Error>;
}

/// The orbit-rate source (navigation), n = θ̇.
pub trait OrbitRateSource: ErrorType {
    /// The orbit rate for control period `tick`, rad/s.
    fn read_orbit_rate_radps(&mut self, tick: u32) -> Result<f32, Self::Error>;
}

/// The reel drive: takes one command (with its explanation, for telemetry) per period.
pub trait ReelDrive: ErrorType {
    /// Applies the command for the coming period.
    fn command(&mut self, output: &Output<f32>) -> Result<(), Self::Error>;
}

impl<T: LengthSensor + ?Sized> LengthSensor for &mut T {
    fn read_length_m(&mut self, tick: u32) -> Result<f32, Self::Error> {
        T::read_length_m(self, tick)
    }
}

impl<T: SwingSensor + ?Sized> SwingSensor for &mut T {
    fn read_swing(&mut self, tick: u32) -> Result<Swing, Self::Error> {
        T::read_swing(self, tick)
    }
}

impl<T: OrbitRateSource + ?Sized> OrbitRateSource for &mut T {
    fn read_orbit_rate_radps(&mut self, tick: u32) -> Result<f32, Self::Error> {
        T::read_orbit_rate_radps(self, tick)
    }
}

impl<T: ReelDrive + ?Sized> ReelDrive for &mut T {
    fn command(&mut self, output: &Output<f32>) -> Result<(), Self::Error> {
        T::command(self, output)
    }
}

/// The devices of one reel controller.
#[derive(Debug)]
pub struct Devices<L, S, O, R> {
    /// Length encoder.
    pub length: L,
    /// Swing sensor.
    pub swing: S,
    /// Orbit-rate source.
    pub orbit: O,
    /// Reel drive.
    pub reel: R,
}

/// What one control cycle did besides stepping the controller (its output, already sent to
/// the reel unless `reel_error` is set, is [`Controller::output`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Cycle {
    /// The first sensor error of this period, if any (the controller treated it as a dropout).
    pub sensor_error: Option<ErrorKind>,
    /// The reel drive's error, if it refused the command.
    pub reel_error: Option<ErrorKind>,
}

/// One control period: read every sensor, step the controller (a failed read is a dropout:
/// [`Controller::step_missing`]), and send the command to the reel.
pub fn control_cycle<L, S, O, R>(
    controller: &mut Controller<f32>,
    tick: u32,
    dev: &mut Devices<L, S, O, R>,
) -> Cycle
where
    L: LengthSensor,
    S: SwingSensor,
    O: OrbitRateSource,
    R: ReelDrive,
{
    let sample = dev
        .length
        .read_length_m(tick)
        .map_err(|e| e.kind())
        .and_then(|length_m| {
            let swing = dev.swing.read_swing(tick).map_err(|e| e.kind())?;
            let n = dev
                .orbit
                .read_orbit_rate_radps(tick)
                .map_err(|e| e.kind())?;
            Ok(Input {
                tick,
                length_m,
                reel_rate_mps: None,
                tension_n: None,
                alpha_rad: Some(swing.alpha_rad),
                alpha_rate_radps: Some(swing.alpha_rate_radps),
                orbit_rate_radps: n,
                true_anomaly_rad: 0.0,
            })
        });
    let (output, sensor_error) = match sample {
        Ok(input) => (controller.step(&input), None),
        Err(kind) => (controller.step_missing(tick), Some(kind)),
    };
    let reel_error = dev.reel.command(&output).err().map(|e| e.kind());
    Cycle {
        sensor_error,
        reel_error,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controller::{Config, Fault, Health, Sensor};

    struct Fixed {
        length_m: f32,
        fail_at: Option<u32>,
    }
    impl ErrorType for Fixed {
        type Error = ErrorKind;
    }
    impl LengthSensor for Fixed {
        fn read_length_m(&mut self, tick: u32) -> Result<f32, ErrorKind> {
            if self.fail_at == Some(tick) {
                Err(ErrorKind::Corrupted)
            } else {
                Ok(self.length_m)
            }
        }
    }
    impl SwingSensor for Fixed {
        fn read_swing(&mut self, _: u32) -> Result<Swing, ErrorKind> {
            Ok(Swing {
                alpha_rad: -0.7,
                alpha_rate_radps: 0.0,
            })
        }
    }
    impl OrbitRateSource for Fixed {
        fn read_orbit_rate_radps(&mut self, _: u32) -> Result<f32, ErrorKind> {
            Ok(1.06e-3)
        }
    }
    struct Reel {
        last: Option<f32>,
    }
    impl ErrorType for Reel {
        type Error = ErrorKind;
    }
    impl ReelDrive for Reel {
        fn command(&mut self, o: &Output<f32>) -> Result<(), ErrorKind> {
            self.last = Some(o.rate_cmd_mps);
            Ok(())
        }
    }

    #[test]
    fn a_failed_read_is_a_dropout_and_the_reel_still_gets_a_command() {
        let mut ctl = Controller::new(Config::<f32>::paper()).unwrap();
        let mut length = Fixed {
            length_m: 100.0,
            fail_at: Some(1),
        };
        let mut others = Fixed {
            length_m: 0.0,
            fail_at: None,
        };
        let mut others2 = Fixed {
            length_m: 0.0,
            fail_at: None,
        };
        let mut reel = Reel { last: None };
        let mut dev = Devices {
            length: &mut length,
            swing: &mut others,
            orbit: &mut others2,
            reel: &mut reel,
        };
        let c0 = control_cycle(&mut ctl, 0, &mut dev);
        assert!(c0.sensor_error.is_none() && ctl.output().fault.is_none());
        let c1 = control_cycle(&mut ctl, 1, &mut dev);
        assert_eq!(c1.sensor_error, Some(ErrorKind::Corrupted));
        let o = ctl.output();
        assert_eq!((o.tick, o.fault), (1, Some(Fault::Sensor(Sensor::Missing))));
        assert_eq!(o.health, Health::Degraded);
        assert_eq!(reel.last, Some(o.rate_cmd_mps));
    }
}
