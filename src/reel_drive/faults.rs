//! The reel drive's faults, and what the outer controller makes of them.

/// A fault of the reel drive.
///
/// How each maps onto the outer controller's fault logic ([`crate::controller::Health`]): see
/// [`DriveFault::outer_reaction`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum DriveFault {
    /// The tick did not advance (repeated or backwards): the step did nothing.
    Tick,
    /// The encoder count moved faster than the drum can turn; the reading was rejected.
    EncoderJump,
    /// No encoder reading this tick (or none for longer than the loop can bridge).
    EncoderMissing,
    /// Large duty, no motion, for `stall_ticks`, the drive not at rest (at rest, the brake
    /// about to engage, a large duty is the motor holding the tension).
    MotorStall,
    /// The duty has been saturated for `saturation_ticks`: the drum cannot follow.
    DutySaturated,
    /// Tension missing, not finite, or outside [min, max] (slack, break, overload).
    TensionOutOfRange,
    /// The rate command was not finite: the drum is brought to rest as in safe hold.
    CommandInvalid,
    /// A pin or the PWM refused a write (reported by the driver, [`super::hal::HalReelDrive`]).
    Actuator,
    /// The drum does not move as the motor's torque and any tether could make it: the tension
    /// its motion implies (the cross-checks, `reel_drive/checks.rs`) lies beyond the plausible range by more than
    /// `tension_mismatch_n`, or the integral has been pinned at its clamp, for
    /// `no_response_ticks` (a frozen or slipping encoder, a seized drum): tripped.
    NoResponse,
    /// The load cell disagrees with the tension the drive's torque and the drum's motion imply
    /// by more than `tension_mismatch_n` for `no_response_ticks`: the drive stops using it
    /// (its feed-forward takes no tension; the integral carries the load) until
    /// [`SpeedLoop::clear_trip`](super::SpeedLoop::clear_trip).
    TensionMismatch,
    /// The drum moved more than `brake_slip_m` with the brake engaged: the brake slips. The
    /// motor holds the drum at rest under the brake ([`Brake::MotorHold`](super::Brake::MotorHold))
    /// until [`SpeedLoop::clear_trip`](super::SpeedLoop::clear_trip).
    BrakeSlip,
}

/// What the outer controller makes of a drive fault (applied by
/// [`Controller::step_with_drive`](crate::controller::Controller::step_with_drive)). Ordered:
/// the strongest reaction of a period's faults wins.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum OuterReaction {
    /// Telemetry only: the drive copes (the fault is the caller's own, or the drive has taken
    /// its safe action and still follows the command).
    Report,
    /// The period's reel data (the encoder's length, the drum's motion) cannot be trusted, or
    /// the drum cannot follow the command: the period is a missing sample for the outer
    /// controller, which coasts (`Health::Degraded`, `Fault::Sensor(Sensor::Missing)`) and, if
    /// the fault persists past `coast_ticks` (its leaky counter), goes to `Health::SafeHold`.
    Degrade,
    /// The drive tripped (motor off, brake on) or holds the drum with its motor because the
    /// brake slips: the reel cannot follow the law, so its command means nothing.
    /// `Health::SafeHold` at once (its zero command keeps the brake engaged once the trip is
    /// cleared), left only after `recovery_ticks` valid periods in a row without one.
    SafeHold,
}

impl DriveFault {
    /// Every fault, in bit order.
    pub const ALL: [Self; 11] = [
        Self::Tick,
        Self::EncoderJump,
        Self::EncoderMissing,
        Self::MotorStall,
        Self::DutySaturated,
        Self::TensionOutOfRange,
        Self::CommandInvalid,
        Self::Actuator,
        Self::NoResponse,
        Self::TensionMismatch,
        Self::BrakeSlip,
    ];

    /// The mapping onto the outer fault logic (docs/hazards.md for the hazards):
    ///
    /// | fault | reaction | why | hazard |
    /// |---|---|---|---|
    /// | `EncoderJump`, `EncoderMissing` | [`OuterReaction::Degrade`] | the length sample comes from this encoder | HZ-1 / HZ-6 |
    /// | `DutySaturated` | [`OuterReaction::Degrade`] | the drum does not follow the command: coast on the last one, safe hold if it lasts | HZ-7 |
    /// | `TensionOutOfRange` | [`OuterReaction::Degrade`] | slack, break or overload: the law's model does not hold | HZ-10 |
    /// | `MotorStall`, `Actuator`, `NoResponse` | [`OuterReaction::SafeHold`] | the drive tripped: the reel cannot move | HZ-7, HZ-R1 |
    /// | `BrakeSlip` | [`OuterReaction::SafeHold`] | the brake cannot hold: the motor holds the drum | HZ-R2 |
    /// | `TensionMismatch` | [`OuterReaction::Report`] | the drive no longer uses the load cell and still follows the command | HZ-R3 |
    /// | `Tick`, `CommandInvalid` | [`OuterReaction::Report`] | the caller's own error; the drive already holds | HZ-12 |
    pub fn outer_reaction(self) -> OuterReaction {
        match self {
            Self::MotorStall | Self::Actuator | Self::NoResponse | Self::BrakeSlip => {
                OuterReaction::SafeHold
            }
            Self::EncoderJump
            | Self::EncoderMissing
            | Self::DutySaturated
            | Self::TensionOutOfRange => OuterReaction::Degrade,
            Self::Tick | Self::CommandInvalid | Self::TensionMismatch => OuterReaction::Report,
        }
    }

    fn bit(self) -> u16 {
        1 << self as u16
    }
}

/// The faults of one tick (a set).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriveFaults(u16);

impl DriveFaults {
    /// No fault.
    pub const NONE: Self = Self(0);

    /// Whether `f` is in the set.
    pub fn contains(self, f: DriveFault) -> bool {
        self.0 & f.bit() != 0
    }

    /// Whether the set is empty.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Adds `f`.
    pub fn insert(&mut self, f: DriveFault) {
        self.0 |= f.bit();
    }

    /// The faults in the set.
    pub fn iter(self) -> impl Iterator<Item = DriveFault> {
        DriveFault::ALL
            .into_iter()
            .filter(move |f| self.contains(*f))
    }

    /// The strongest reaction any fault of the set asks of the outer controller.
    pub fn outer_reaction(self) -> OuterReaction {
        self.iter()
            .map(DriveFault::outer_reaction)
            .max()
            .unwrap_or(OuterReaction::Report)
    }

    /// The set as bits, one per fault in [`DriveFault::ALL`] order (for telemetry).
    pub fn bits(self) -> u16 {
        self.0
    }

    /// The union of two sets (a period's faults are the union of its ticks').
    pub fn union(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_faults_map_onto_the_outer_logic() {
        let mut set = DriveFaults::NONE;
        set.insert(DriveFault::TensionOutOfRange);
        assert_eq!(DriveFaults::NONE.outer_reaction(), OuterReaction::Report);
        assert_eq!(set.outer_reaction(), OuterReaction::Degrade);
        set.insert(DriveFault::EncoderJump);
        assert_eq!(set.outer_reaction(), OuterReaction::Degrade);
        set.insert(DriveFault::MotorStall);
        assert_eq!(set.outer_reaction(), OuterReaction::SafeHold);
        assert_eq!(
            set.iter().collect::<heapless::Vec<_, 11>>().as_slice(),
            &[
                DriveFault::EncoderJump,
                DriveFault::MotorStall,
                DriveFault::TensionOutOfRange
            ]
        );
        for f in [DriveFault::NoResponse, DriveFault::BrakeSlip] {
            assert_eq!(f.outer_reaction(), OuterReaction::SafeHold, "{f:?}");
        }
    }

    #[test]
    fn every_fault_has_its_own_bit() {
        let mut seen = 0_u16;
        for f in DriveFault::ALL {
            assert_eq!(seen & f.bit(), 0, "{f:?}");
            seen |= f.bit();
        }
        assert_eq!(seen.count_ones() as usize, DriveFault::ALL.len());
    }
}
