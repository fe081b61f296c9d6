//! The brake (and motor enable) state machine of the speed loop.

use super::{DriveFault, SpeedLoop};

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
    /// [`SpeedLoop::clear_trip`].
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

impl SpeedLoop {
    /// Moves the brake to its next state. Entering `Released` starts the ramp from rest at
    /// `tick` (the drum was held until now) and the observer of the implied tension; leaving
    /// `Engaged` forgets where the brake held the drum. At rest means the command and the
    /// measured speed ~0; a tick without a measured speed (`counted` false) neither advances
    /// nor restarts the rest count. `tether_nm` is the torque of the tension the feed-forward
    /// uses (T r).
    pub(super) fn advance_brake(
        &mut self,
        tick: u32,
        gap_ticks: u32,
        speed_mps: f32,
        counted: bool,
        tether_nm: f32,
    ) {
        self.brake = match self.brake {
            Brake::Tripped(_) | Brake::MotorHold => return,
            Brake::Engaged if self.command_frees_brake && counted => {
                self.checks.held_at_count = None;
                Brake::Releasing {
                    ticks_left: self.cfg.brake.release_ticks,
                }
            }
            Brake::Engaged => return,
            Brake::Releasing { .. } if !self.command_frees_brake => Brake::Engaged,
            Brake::Releasing { ticks_left } if ticks_left <= gap_ticks => {
                // The ramp is from rest: the brake was not free at the command.
                self.ramp.start_tick = tick;
                self.checks.start_observer(
                    speed_mps,
                    tether_nm,
                    self.derived.observer_lag_mps_per_nm,
                );
                Brake::Released { rest_ticks: 0 }
            }
            Brake::Releasing { ticks_left } => Brake::Releasing {
                ticks_left: ticks_left - gap_ticks,
            },
            Brake::Released { .. } if !counted => return,
            Brake::Released { rest_ticks } => {
                // At rest: the command is rest and the drum is at rest (its reference, which
                // it follows, is on its way there).
                let at_rest =
                    !self.command_moving && speed_mps.abs() <= self.cfg.brake.rest_speed_mps;
                if !at_rest {
                    Brake::Released { rest_ticks: 0 }
                } else {
                    // (Cannot wrap: below `engage_ticks` ≤ 2³¹ − 1, plus a gap below 2³¹.)
                    let rest_ticks = rest_ticks.wrapping_add(gap_ticks);
                    if rest_ticks >= self.cfg.brake.engage_ticks {
                        Brake::Engaged
                    } else {
                        Brake::Released { rest_ticks }
                    }
                }
            }
        };
    }
}
