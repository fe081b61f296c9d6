//! The brake (and motor enable) state machine of the speed loop.

use super::config::BrakeConfig;
use super::faults::DriveFault;

/// The brake (and motor enable) state machine.
///
/// ```text
///            command moving, not safe hold, encoder read       release_ticks elapsed
///   Engaged ────────────────────────────────────────▶ Releasing ───────────────────▶ Released
///     ▲  ▲ ◀──── command at rest, or safe hold ────────────┘                           │
///     │  └────────── commanded and measured speed ~0 for engage_ticks ─────────────────┘
///     │  │
///     │  └─ drum moved brake_slip_m while engaged ──▶ MotorHold
///     └──── clear_trip ──── Tripped(fault) ◀── encoder lost, stall, no response, actuator (from any)
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Brake {
    /// Brake on, motor off (at rest, at start, in safe hold once at rest).
    Engaged,
    /// Brake lifting; the motor holds the tension's torque so the drum does not lurch.
    Releasing {
        /// Ticks until the brake is free.
        ticks_left: u32,
    },
    /// Brake free; the speed loop drives the drum.
    Released {
        /// Consecutive ticks the commanded and measured speed have been ~0.
        rest_ticks: u32,
    },
    /// The engaged brake slipped ([`DriveFault::BrakeSlip`]): it stays applied, and the motor
    /// holds the drum at rest with the speed loop (reference 0), whatever the command, until
    /// [`SpeedLoop::clear_trip`](crate::reel_drive::SpeedLoop::clear_trip).
    MotorHold,
    /// A fault left the drum uncontrolled: brake on, motor off, until cleared.
    Tripped(DriveFault),
}

impl Brake {
    /// Whether the brake is commanded free (its pin energised).
    pub fn brake_released(self) -> bool {
        matches!(self, Self::Releasing { .. } | Self::Released { .. })
    }

    /// Whether the motor driver is enabled.
    pub fn motor_enabled(self) -> bool {
        matches!(
            self,
            Self::Releasing { .. } | Self::Released { .. } | Self::MotorHold
        )
    }
}

/// What the brake's state machine sees at a tick.
#[derive(Clone, Copy, Debug)]
pub(super) struct BrakeTick {
    /// Ticks since the last step.
    pub(super) gap_ticks: u32,
    /// The drum's measured speed, m/s.
    pub(super) speed_mps: f32,
    /// The encoder was read at this tick (`speed_mps` is measured).
    pub(super) counted: bool,
    /// The command asks for motion.
    pub(super) command_moving: bool,
    /// The command lets the brake be free: moving, and not in safe hold.
    pub(super) command_frees_brake: bool,
}

/// A transition of the brake that the speed loop acts on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum BrakeEdge {
    /// `Engaged` left for `Releasing`: where the brake held the drum is forgotten.
    Lifting,
    /// `Releasing` left for `Released`: the drum is free from this tick on.
    Freed,
}

impl Brake {
    /// Moves the brake to its next state; returns the transition the speed loop acts on, if
    /// any. At rest means the command and the measured speed ~0; a tick without a measured
    /// speed (`counted` false) neither advances nor restarts the rest count. `MotorHold` and
    /// `Tripped` are left only by the loop itself.
    pub(super) fn advance(&mut self, x: &BrakeTick, cfg: &BrakeConfig) -> Option<BrakeEdge> {
        *self = match *self {
            Self::Tripped(_) | Self::MotorHold => return None,
            Self::Engaged if x.command_frees_brake && x.counted => {
                *self = Self::Releasing {
                    ticks_left: cfg.release_ticks,
                };
                return Some(BrakeEdge::Lifting);
            }
            Self::Engaged => return None,
            Self::Releasing { .. } if !x.command_frees_brake => Self::Engaged,
            Self::Releasing { ticks_left } if ticks_left <= x.gap_ticks => {
                *self = Self::Released { rest_ticks: 0 };
                return Some(BrakeEdge::Freed);
            }
            Self::Releasing { ticks_left } => Self::Releasing {
                ticks_left: ticks_left - x.gap_ticks,
            },
            Self::Released { .. } if !x.counted => return None,
            Self::Released { rest_ticks } => {
                // At rest: the command is rest and the drum is at rest (its reference, which
                // it follows, is on its way there).
                let at_rest = !x.command_moving && x.speed_mps.abs() <= cfg.rest_speed_mps;
                if !at_rest {
                    Self::Released { rest_ticks: 0 }
                } else {
                    // (Cannot wrap: below `engage_ticks` ≤ 2³¹ − 1, plus a gap below 2³¹.)
                    let rest_ticks = rest_ticks.wrapping_add(x.gap_ticks);
                    if rest_ticks >= cfg.engage_ticks {
                        Self::Engaged
                    } else {
                        Self::Released { rest_ticks }
                    }
                }
            }
        };
        None
    }
}
