//! Hardware abstraction: the reel MCU's sensors and actuator as small traits in the style of
//! `embedded-hal` 1.0 (which has no encoder, ADC, capture or serial traits), the byte stream
//! to the on-board computer ([`BytePort`]), and the one function that connects the sensors and
//! the reel to the controller each control period.
//!
//! Every trait has an associated error whose [`Error::kind`] says what went wrong; every method
//! is fallible; blanket implementations for `&mut T` let drivers be borrowed. The firmware's
//! built-in replay, the processor-in-the-loop serial link and the real hardware are just
//! different implementations of these traits.

use crate::controller::{Controller, Input, Output};
use crate::reel_drive::DriveFaults;

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
    /// Received bytes were lost: the receiver was not read in time (a UART overrun, or a
    /// receive queue full).
    Overrun,
    /// A byte arrived damaged (a UART framing, noise or parity error).
    Framing,
    /// No room to send: the transmit queue is full.
    Full,
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

/// The reel's encoder: the paid-out length, and the reel's rate from it.
pub trait LengthSensor: ErrorType {
    /// The deployed tether length for control period `tick`, m.
    fn read_length_m(&mut self, tick: u32) -> Result<f32, Self::Error>;
    /// The reel's rate over the period that ended at `tick` (the encoder's count change over
    /// the period), m/s.
    fn read_rate_mps(&mut self, tick: u32) -> Result<f32, Self::Error>;
}

/// The tether swing-angle sensor: the in-plane angle α only (no flight sensor measures α̇;
/// the controller estimates it, [`crate::estimator`]).
pub trait SwingSensor: ErrorType {
    /// α for control period `tick`, rad.
    fn read_alpha_rad(&mut self, tick: u32) -> Result<f32, Self::Error>;
}

/// The load cell at the reel.
pub trait TensionSensor: ErrorType {
    /// The tether tension at the reel for control period `tick`, N.
    fn read_tension_n(&mut self, tick: u32) -> Result<f32, Self::Error>;
}

/// The orbit source (navigation): θ̇ and θ.
pub trait OrbitRateSource: ErrorType {
    /// The orbit rate θ̇ for control period `tick`, rad/s.
    fn read_orbit_rate_radps(&mut self, tick: u32) -> Result<f32, Self::Error>;
    /// The true anomaly θ for control period `tick`, rad (used on an eccentric orbit).
    fn read_true_anomaly_rad(&mut self, tick: u32) -> Result<f32, Self::Error>;
}

/// The reel drive: takes one command (with its explanation, for telemetry) per period.
pub trait ReelDrive: ErrorType {
    /// Applies the command for the coming period.
    fn command(&mut self, output: &Output<f32>) -> Result<(), Self::Error>;
}

/// A byte stream to another unit (a UART to the on-board computer), without waiting:
/// `embedded-io`'s `Read`/`Write` cut to what a packet link needs (embedded-hal 1.0 has no
/// serial trait). The bytes are framed by the link (`crate::link`); `crate::pus::port` is its
/// user.
pub trait BytePort: ErrorType {
    /// The next received byte, if one has arrived (`Ok(None)`: none yet). Bytes lost or damaged
    /// on the line are one `Err` (of kind [`ErrorKind::Overrun`] or [`ErrorKind::Framing`]) in
    /// their place in the stream, reported once.
    fn read_byte(&mut self) -> Result<Option<u8>, Self::Error>;
    /// Queues all of `bytes` to be sent, or none of them if they do not all fit (`Err` of kind
    /// [`ErrorKind::Full`]): a frame is never cut.
    fn send(&mut self, bytes: &[u8]) -> Result<(), Self::Error>;
}

impl<T: LengthSensor + ?Sized> LengthSensor for &mut T {
    fn read_length_m(&mut self, tick: u32) -> Result<f32, Self::Error> {
        T::read_length_m(self, tick)
    }
    fn read_rate_mps(&mut self, tick: u32) -> Result<f32, Self::Error> {
        T::read_rate_mps(self, tick)
    }
}

impl<T: SwingSensor + ?Sized> SwingSensor for &mut T {
    fn read_alpha_rad(&mut self, tick: u32) -> Result<f32, Self::Error> {
        T::read_alpha_rad(self, tick)
    }
}

impl<T: TensionSensor + ?Sized> TensionSensor for &mut T {
    fn read_tension_n(&mut self, tick: u32) -> Result<f32, Self::Error> {
        T::read_tension_n(self, tick)
    }
}

impl<T: OrbitRateSource + ?Sized> OrbitRateSource for &mut T {
    fn read_orbit_rate_radps(&mut self, tick: u32) -> Result<f32, Self::Error> {
        T::read_orbit_rate_radps(self, tick)
    }
    fn read_true_anomaly_rad(&mut self, tick: u32) -> Result<f32, Self::Error> {
        T::read_true_anomaly_rad(self, tick)
    }
}

impl<T: ReelDrive + ?Sized> ReelDrive for &mut T {
    fn command(&mut self, output: &Output<f32>) -> Result<(), Self::Error> {
        T::command(self, output)
    }
}

impl<T: BytePort + ?Sized> BytePort for &mut T {
    fn read_byte(&mut self) -> Result<Option<u8>, Self::Error> {
        T::read_byte(self)
    }
    fn send(&mut self, bytes: &[u8]) -> Result<(), Self::Error> {
        T::send(self, bytes)
    }
}

/// The devices of one reel controller.
#[derive(Debug)]
pub struct Devices<L, S, O, R, F> {
    /// Length encoder.
    pub length: L,
    /// Swing sensor.
    pub swing: S,
    /// Orbit source.
    pub orbit: O,
    /// Reel drive.
    pub reel: R,
    /// Load cell.
    pub tension: F,
}

/// What one control cycle did besides stepping the controller (its output, already sent to
/// the reel unless `reel_error` is set, is [`Controller::output`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Cycle {
    /// The sample the controller stepped on (`None`: it stepped without one), for its
    /// telemetry (`crate::pus::Services::after_step`).
    pub input: Option<Input<f32>>,
    /// The first error of the length encoder or the orbit source this period, if any: the
    /// controller stepped without a sample ([`Controller::step_missing`]).
    pub sensor_error: Option<ErrorKind>,
    /// The first error of the swing sensor, the encoder's rate or the load cell this period, if
    /// any: the controller stepped without that reading (its [`Input`] field `None`).
    pub reading_error: Option<ErrorKind>,
    /// The reel drive's error, if it refused the command.
    pub reel_error: Option<ErrorKind>,
}

/// One control period: read every sensor, step the controller, and send the command to the
/// reel. Without a length or an orbit rate there is no sample ([`Controller::step_missing`]);
/// without α, the encoder's rate or the tension, the sample has that field `None` (flying on
/// the estimator, a period without α is predicted only). There is no α̇ sensor: a controller
/// that flies on one ([`crate::config::RateSource::Sensor`]) is not flown through this cycle.
///
/// `drive` is what the reel's inner speed loop reported over the law period that ended (the
/// union of its ticks' faults, [`DriveFaults::NONE`] for a drive without one): it reaches the
/// controller's health through [`Controller::step_with_drive`] (a drive fault degrades the
/// period or forces a safe hold, see [`crate::reel_drive::OuterReaction`]).
pub fn control_cycle<L, S, O, R, F>(
    controller: &mut Controller<f32>,
    tick: u32,
    dev: &mut Devices<L, S, O, R, F>,
    drive: DriveFaults,
) -> Cycle
where
    L: LengthSensor,
    S: SwingSensor,
    O: OrbitRateSource,
    R: ReelDrive,
    F: TensionSensor,
{
    let sample = dev
        .length
        .read_length_m(tick)
        .map_err(|e| e.kind())
        .and_then(|length_m| {
            let kind = |e: O::Error| e.kind();
            let orbit_rate_radps = dev.orbit.read_orbit_rate_radps(tick).map_err(kind)?;
            let true_anomaly_rad = dev.orbit.read_true_anomaly_rad(tick).map_err(kind)?;
            Ok((length_m, orbit_rate_radps, true_anomaly_rad))
        });
    let (output, input, sensor_error, reading_error) = match sample {
        Ok((length_m, orbit_rate_radps, true_anomaly_rad)) => {
            let alpha = dev.swing.read_alpha_rad(tick).map_err(|e| e.kind());
            let rate = dev.length.read_rate_mps(tick).map_err(|e| e.kind());
            let tension = dev.tension.read_tension_n(tick).map_err(|e| e.kind());
            let reading_error = [alpha, rate, tension].into_iter().find_map(Result::err);
            let input = Input {
                tick,
                length_m,
                reel_rate_mps: rate.ok(),
                tension_n: tension.ok(),
                alpha_rad: alpha.ok(),
                alpha_rate_radps: None,
                orbit_rate_radps,
                true_anomaly_rad,
            };
            (
                controller.step_with_drive(tick, Some(&input), drive),
                Some(input),
                None,
                reading_error,
            )
        }
        Err(kind) => (
            controller.step_with_drive(tick, None, drive),
            None,
            Some(kind),
            None,
        ),
    };
    let reel_error = dev.reel.command(output).err().map(|e| e.kind());
    Cycle {
        input,
        sensor_error,
        reading_error,
        reel_error,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controller::{Config, Fault, Health, Sensor};
    use crate::estimator;

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
        fn read_rate_mps(&mut self, _: u32) -> Result<f32, ErrorKind> {
            Err(ErrorKind::NoSample)
        }
    }
    impl SwingSensor for Fixed {
        fn read_alpha_rad(&mut self, tick: u32) -> Result<f32, ErrorKind> {
            if self.fail_at == Some(tick) {
                Err(ErrorKind::Device)
            } else {
                Ok(-0.7)
            }
        }
    }
    impl TensionSensor for Fixed {
        fn read_tension_n(&mut self, _: u32) -> Result<f32, ErrorKind> {
            Ok(1e-3)
        }
    }
    impl OrbitRateSource for Fixed {
        fn read_orbit_rate_radps(&mut self, _: u32) -> Result<f32, ErrorKind> {
            Ok(1.06e-3)
        }
        fn read_true_anomaly_rad(&mut self, _: u32) -> Result<f32, ErrorKind> {
            Ok(0.0)
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

    fn flight() -> Controller<f32> {
        let cfg = Config {
            rate_source: crate::config::RateSource::Estimator(estimator::Config::paper()),
            ..Config::paper()
        };
        Controller::new(cfg).unwrap()
    }

    #[test]
    fn a_failed_read_is_a_dropout_and_the_reel_still_gets_a_command() {
        let mut ctl = flight();
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
        let mut others3 = Fixed {
            length_m: 0.0,
            fail_at: None,
        };
        let mut reel = Reel { last: None };
        let mut dev = Devices {
            length: &mut length,
            swing: &mut others,
            orbit: &mut others2,
            reel: &mut reel,
            tension: &mut others3,
        };
        let c0 = control_cycle(&mut ctl, 0, &mut dev, DriveFaults::NONE);
        assert!(c0.sensor_error.is_none() && ctl.output().fault.is_none());
        let c1 = control_cycle(&mut ctl, 1, &mut dev, DriveFaults::NONE);
        assert_eq!(c1.sensor_error, Some(ErrorKind::Corrupted));
        let o = ctl.output();
        assert_eq!((o.tick, o.fault), (1, Some(Fault::Sensor(Sensor::Missing))));
        assert_eq!(o.health, Health::Degraded);
        assert_eq!(reel.last, Some(o.rate_cmd_mps));
    }

    #[test]
    fn a_stalled_drive_reported_to_the_cycle_forces_a_safe_hold() {
        let mut ctl = flight();
        let fixed = || Fixed {
            length_m: 100.0,
            fail_at: None,
        };
        let (mut length, mut swing, mut orbit, mut load) = (fixed(), fixed(), fixed(), fixed());
        let mut reel = Reel { last: None };
        let mut dev = Devices {
            length: &mut length,
            swing: &mut swing,
            orbit: &mut orbit,
            reel: &mut reel,
            tension: &mut load,
        };
        control_cycle(&mut ctl, 0, &mut dev, DriveFaults::NONE);
        assert_eq!(ctl.output().health, Health::Nominal);
        let mut stalled = DriveFaults::NONE;
        stalled.insert(crate::reel_drive::DriveFault::MotorStall);
        let c = control_cycle(&mut ctl, 1, &mut dev, stalled);
        // The sensors were fine: the safe hold is the drive's doing.
        assert_eq!((c.sensor_error, c.reel_error), (None, None));
        assert_eq!(ctl.output().health, Health::SafeHold, "{:?}", ctl.output());
        assert_eq!(reel.last, Some(ctl.output().rate_cmd_mps));
    }

    #[test]
    fn without_alpha_the_estimate_is_predicted_and_the_law_still_runs() {
        let mut ctl = flight();
        let fixed = |fail_at| Fixed {
            length_m: 100.0,
            fail_at,
        };
        let (mut length, mut swing, mut orbit, mut load) =
            (fixed(None), fixed(Some(2)), fixed(None), fixed(None));
        let mut reel = Reel { last: None };
        let mut dev = Devices {
            length: &mut length,
            swing: &mut swing,
            orbit: &mut orbit,
            reel: &mut reel,
            tension: &mut load,
        };
        for tick in 0..2 {
            let c = control_cycle(&mut ctl, tick, &mut dev, DriveFaults::NONE);
            // The encoder gives no rate: a reading error, not a dropout.
            assert_eq!(c.sensor_error, None);
            assert_eq!(c.reading_error, Some(ErrorKind::NoSample));
        }
        let c = control_cycle(&mut ctl, 2, &mut dev, DriveFaults::NONE);
        assert_eq!(c.reading_error, Some(ErrorKind::Device));
        let o = ctl.output();
        assert_eq!((o.fault, o.health), (None, Health::Nominal), "{o:?}");
        assert_eq!(o.nis, None);
        assert!(ctl.estimate().is_some());
    }
}
