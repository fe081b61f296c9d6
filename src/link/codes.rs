//! The enumeration codes of the link: phase, health and fault as the bytes a [`super::Command`]
//! carries, and the conversion between a command frame and the controller output.

use crate::controller::{Fault, Flags, Health, Output, Phase, Sensor};
use crate::law::LawFault;

use super::error::LinkError;
use super::messages::{Command, SampleStatus};

/// The wire code of a phase.
pub fn phase_code(p: Phase) -> u8 {
    match p {
        Phase::Deploy => 0,
        Phase::Keep1 => 1,
        Phase::Slew => 2,
        Phase::Retrieve => 3,
        Phase::Keep2 => 4,
    }
}

/// The phase of a wire code.
pub fn phase_from_code(c: u8) -> Option<Phase> {
    [
        Phase::Deploy,
        Phase::Keep1,
        Phase::Slew,
        Phase::Retrieve,
        Phase::Keep2,
    ]
    .into_iter()
    .find(|&p| phase_code(p) == c)
}

/// The wire code of a health state.
pub fn health_code(h: Health) -> u8 {
    match h {
        Health::Nominal => 0,
        Health::Degraded => 1,
        Health::SafeHold => 2,
    }
}

/// The health state of a wire code.
pub fn health_from_code(c: u8) -> Option<Health> {
    [Health::Nominal, Health::Degraded, Health::SafeHold]
        .into_iter()
        .find(|&h| health_code(h) == c)
}

pub(super) const SENSOR_FAULTS: [Sensor; 12] = [
    Sensor::Missing,
    Sensor::Tick,
    Sensor::Length,
    Sensor::LengthJump,
    Sensor::Alpha,
    Sensor::AlphaJump,
    Sensor::AlphaStuck,
    Sensor::AlphaRate,
    Sensor::OrbitRate,
    Sensor::AlphaGated,
    Sensor::AlphaLost,
    Sensor::ReelRate,
];

pub(super) const LAW_FAULTS: [LawFault; 4] = [
    LawFault::SingularDenominator,
    LawFault::NoRealSolution,
    LawFault::AccelerationSingular,
    LawFault::NotFinite,
];

/// The wire code of a fault: 0 none, `0x10 + n` sensor fault n, `0x20 + n` law fault n, `0x30` a
/// libration beyond the law's domain (n in
/// declaration order).
pub fn fault_code(f: Option<Fault>) -> u8 {
    match f {
        None => 0,
        Some(Fault::Sensor(s)) => {
            0x10 + match s {
                Sensor::Missing => 0,
                Sensor::Tick => 1,
                Sensor::Length => 2,
                Sensor::LengthJump => 3,
                Sensor::Alpha => 4,
                Sensor::AlphaJump => 5,
                Sensor::AlphaStuck => 6,
                Sensor::AlphaRate => 7,
                Sensor::OrbitRate => 8,
                Sensor::AlphaGated => 9,
                Sensor::AlphaLost => 10,
                Sensor::ReelRate => 11,
            }
        }
        Some(Fault::Law(l)) => {
            0x20 + match l {
                LawFault::SingularDenominator => 0,
                LawFault::NoRealSolution => 1,
                LawFault::AccelerationSingular => 2,
                LawFault::NotFinite => 3,
            }
        }
        Some(Fault::Libration) => 0x30,
    }
}

/// The fault of a wire code (`Err` for an unknown code).
pub fn fault_from_code(c: u8) -> Result<Option<Fault>, LinkError> {
    if c == 0 {
        return Ok(None);
    }
    let sensor = SENSOR_FAULTS.into_iter().map(Fault::Sensor);
    let law = LAW_FAULTS.into_iter().map(Fault::Law);
    sensor
        .chain(law)
        .chain([Fault::Libration])
        .find(|&f| fault_code(Some(f)) == c)
        .map(Some)
        .ok_or(LinkError::Malformed)
}

impl Command {
    /// The command frame of a controller output, with the status of the period's sample.
    pub fn from_output(o: &Output<f32>, sample: SampleStatus) -> Self {
        Self {
            tick: o.tick,
            sample: sample as u8,
            rate_cmd_mps: o.rate_cmd_mps,
            accel_cmd_mps2: o.accel_cmd_mps2,
            law_rate_mps: o.law_rate_mps,
            blend_weight: o.blend_weight,
            alpha_ref_rad: o.alpha_ref_rad,
            alpha_ref_rate_radps: o.alpha_ref_rate_radps,
            delta_rad: o.delta_rad,
            delta_rate_radps: o.delta_rate_radps,
            length_estimate_m: o.length_estimate_m,
            equilibrium_margin: o.equilibrium_margin,
            nis: o.nis,
            phase: phase_code(o.phase),
            health: health_code(o.health),
            fault: fault_code(o.fault),
            flags: o.flags.0,
        }
    }

    /// The controller output this frame carries (bit for bit), or [`LinkError::Malformed`]
    /// for an unknown enumeration code.
    pub fn to_output(&self) -> Result<Output<f32>, LinkError> {
        SampleStatus::from_code(self.sample).ok_or(LinkError::Malformed)?;
        Ok(Output {
            tick: self.tick,
            phase: phase_from_code(self.phase).ok_or(LinkError::Malformed)?,
            health: health_from_code(self.health).ok_or(LinkError::Malformed)?,
            rate_cmd_mps: self.rate_cmd_mps,
            accel_cmd_mps2: self.accel_cmd_mps2,
            law_rate_mps: self.law_rate_mps,
            blend_weight: self.blend_weight,
            alpha_ref_rad: self.alpha_ref_rad,
            alpha_ref_rate_radps: self.alpha_ref_rate_radps,
            delta_rad: self.delta_rad,
            delta_rate_radps: self.delta_rate_radps,
            length_estimate_m: self.length_estimate_m,
            equilibrium_margin: self.equilibrium_margin,
            nis: self.nis,
            flags: Flags(self.flags),
            fault: fault_from_code(self.fault)?,
        })
    }
}
