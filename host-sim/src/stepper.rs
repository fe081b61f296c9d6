//! The controller in the loop, as the closed loop (`crate::sim`) and the laws beside the
//! paper's (`crate::laws`) share it: the [`Stepper`] that decides each control period, the
//! controller configuration a scenario describes, and why a run fails ([`SimError`]). Both
//! use this module; neither uses the other's internals.

use crate::elastic::ElasticError;
use crate::plant::Command;
use crate::scenario::Scenario;
use tss_reel::controller::{Config, ConfigError, Controller, Input, Output};
use tss_reel::reel_drive::DriveFaults;
use tss_reel::Real;

/// Why a run could not be completed.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The scenario's numbers do not make a valid controller.
    #[error("controller configuration rejected: {0}")]
    Config(ConfigError),
    /// A timing field is not a whole number of control periods.
    #[error("{field} = {value} s is not a whole number of control periods ({period_s} s)")]
    Timing {
        /// The scenario field.
        field: &'static str,
        /// Its value, s.
        value: f64,
        /// The control period, s.
        period_s: f64,
    },
    /// The controller in the loop failed (the processor-in-the-loop link, `crate::pil`).
    #[error("the processor-in-the-loop link failed")]
    Link(#[source] Box<dyn std::error::Error + Send + Sync>),
    /// The elastic plant's parameters are invalid.
    #[error("{0}")]
    Elastic(#[from] ElasticError),
    /// The scenario lists telecommands and the controller in the loop has no PUS services to
    /// take them (the f64 evaluation, a tension law).
    #[error("the controller in the loop takes no telecommands (only the flight controller linked into the simulator does)")]
    NoTelecommands,
    /// The plant state stopped being finite (a physically impossible run).
    #[error("the plant state became non-finite at t = {t_s} s")]
    Diverged {
        /// Mission time, s.
        t_s: f64,
    },
}

/// The controller configuration a scenario describes, in the controller's scalar type
/// ([`Scenario::controller_config`]), once the stage-2 start is a whole number of periods.
pub fn controller_config<T: Real>(sc: &Scenario) -> Result<Config<T>, SimError> {
    ticks(
        "stage2.start_time_s",
        sc.stage2.start_time_s,
        sc.controller.period_s,
    )?;
    Ok(sc.controller_config())
}

/// `value_s` as a whole number of periods (to 1e-9 relative), or a [`SimError::Timing`].
pub(crate) fn ticks(field: &'static str, value_s: f64, period_s: f64) -> Result<u32, SimError> {
    let n = (value_s / period_s).round();
    let ok = n >= 0.0
        && n <= f64::from(u32::MAX)
        && (n * period_s - value_s).abs() <= 1e-9 * value_s.abs().max(period_s);
    if ok {
        Ok(n as u32)
    } else {
        Err(SimError::Timing {
            field,
            value: value_s,
            period_s,
        })
    }
}

/// The controller in the loop, one control period at a time: the core linked into the
/// simulator ([`Controller`]) or the flight firmware in QEMU over the processor-in-the-loop
/// link (`crate::pil`).
pub trait Stepper<T> {
    /// One control period: `input` is the sensed sample, `None` when none arrived (a dropout).
    fn step(&mut self, tick: u32, input: Option<&Input<T>>) -> Result<Output<T>, SimError>;

    /// One control period whose reel drive reported `drive` over the period that ended (the
    /// flight speed loop's faults, `Plant::take_drive_faults`), as the board's outer step
    /// takes them. The flight controller maps them onto its health
    /// (`Controller::step_with_drive`); a stepper with no use for them flies [`Stepper::step`].
    fn step_with_drive(
        &mut self,
        tick: u32,
        input: Option<&Input<T>>,
        drive: DriveFaults,
    ) -> Result<Output<T>, SimError> {
        let _ = drive;
        self.step(tick, input)
    }

    /// A telecommand of the on-board computer, before the next control period (`crate::obc`).
    /// A stepper without the unit's PUS services refuses it.
    fn telecommand(&mut self, raw: &[u8]) -> Result<(), SimError> {
        let _ = raw;
        Err(SimError::NoTelecommands)
    }

    /// The telemetry packets the unit sent since the last call, in order, with the
    /// housekeeping of the last step if `housekeeping` (none without PUS services).
    fn take_telemetry(&mut self, housekeeping: bool) -> Result<Vec<Vec<u8>>, SimError> {
        let _ = housekeeping;
        Ok(Vec::new())
    }

    /// The reel command of the period `out` was decided for: the rate command and its
    /// acceleration (the paper's law); a tension law (`crate::laws`) commands a tension.
    fn reel_command(&self, out: &Output<T>) -> Command
    where
        T: Real,
    {
        Command {
            rate_mps: out.rate_cmd_mps.to_f64(),
            accel_mps2: out.accel_cmd_mps2.to_f64(),
            tension_n: None,
        }
    }
}

impl<T: Real> Stepper<T> for Controller<T> {
    fn step(&mut self, tick: u32, input: Option<&Input<T>>) -> Result<Output<T>, SimError> {
        Ok(match input {
            Some(x) => *Controller::step(self, x),
            None => *self.step_missing(tick),
        })
    }

    fn step_with_drive(
        &mut self,
        tick: u32,
        input: Option<&Input<T>>,
        drive: DriveFaults,
    ) -> Result<Output<T>, SimError> {
        Ok(*Controller::step_with_drive(self, tick, input, drive))
    }
}
