//! Mission-mode commands (docs/equations.md §7.1): what the on-board computer may tell the
//! sequencer, where each is legal, and the mode the controller flies in.
//!
//! ```text
//!                 Hold                          Abort (from Flying or Held)
//!   Flying ─────────────────▶ Held ──────────────────────────────▶ Aborted
//!     ▲ ◀── Resume (the phase held) ──┘                              │
//!     │ ◀── Retrieve (stage 1 only: stage 2 begins) ─┘                │
//!     └────────────── StartDeployment (stage 1 afresh) ──────────────┘
//! ```
//!
//! A command is judged when it is given ([`transition`]): a refused one changes nothing. An
//! accepted one waits for the next period boundary (the start of the next step in which time
//! moves) and is applied there, before anything else of that step; until then no other
//! command is taken ([`Refusal::Pending`]). Nothing else changes the mode or the phase between
//! two steps, so the command applied is the one judged.

use super::output::Phase;

/// A mission-mode command of the on-board computer (its TC\[8,1\] function identifier is the
/// discriminant, docs/interface.md §3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ModeCommand {
    /// After an abort: a new deployment, stage 1 afresh from the length the reel is at (the
    /// Eq. 29 blend from the current rate, the mission's clock from now).
    StartDeployment = 1,
    /// Bring the reel to rest and keep the length (within the envelope's acceleration, at
    /// `monitor.safe_hold_decel_mps2`); the phase and the mission's clock stop.
    Hold = 2,
    /// Leave a hold: the phase that was held goes on, the Eq. 29 blend restarted from the
    /// current rate, the mission's clock (the stage-2 start, the slew) moved on by the hold.
    Resume = 3,
    /// Begin stage 2 (slew, then retrieval) now; from a hold, this ends it.
    Retrieve = 4,
    /// Abort to a safe hold: the reel brought to rest as by `Hold`, for good (only
    /// `StartDeployment` leaves it).
    Abort = 5,
}

impl ModeCommand {
    /// Every command, in the order of their identifiers.
    pub const ALL: [Self; 5] = [
        Self::StartDeployment,
        Self::Hold,
        Self::Resume,
        Self::Retrieve,
        Self::Abort,
    ];

    /// The command of a function identifier (`None` for an unknown one).
    pub fn from_id(id: u16) -> Option<Self> {
        Self::ALL.into_iter().find(|&m| m as u16 == id)
    }
}

/// The mode the controller flies in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Mode {
    /// The sequencer's phases fly the law.
    Flying,
    /// Commanded hold: the reel brought to rest, the phase kept.
    Held {
        /// The tick the hold began at (its period boundary).
        since_tick: u32,
    },
    /// Aborted to a safe hold.
    Aborted,
}

impl Mode {
    /// The reel is held at rest by command (held or aborted).
    pub fn holds(self) -> bool {
        self != Mode::Flying
    }
}

/// Why a mode command was refused (its TM\[1,2\] failure code, docs/interface.md §3). A refused
/// command changes nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Refusal {
    /// Another command waits for the next period boundary.
    Pending = 12,
    /// Hold: the reel is already held (or aborted).
    AlreadyHeld = 13,
    /// Resume: no hold to leave (flying, or aborted: only a new deployment leaves an abort).
    NotHeld = 14,
    /// Retrieve: stage 2 has begun, or the mission is aborted.
    NotInStage1 = 15,
    /// Start deployment: a deployment is flying or held (abort it first).
    NotAborted = 16,
    /// Abort: already aborted.
    AlreadyAborted = 17,
}

/// What applying a command does to the sequencer, besides the new mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Effect {
    /// Only the mode changes.
    None,
    /// Leave the hold that began at this tick: the mission's clock moves on by it.
    Resume {
        /// The tick the hold began at.
        held_since_tick: u32,
    },
    /// Stage 2 begins at this boundary.
    BeginStage2,
    /// Stage 1 afresh.
    NewDeployment,
}

/// The mode after `command` in `mode` and `phase` at the boundary `tick`, and what else it
/// does; or why it is not legal there.
pub(super) fn transition(
    mode: Mode,
    phase: Phase,
    command: ModeCommand,
    tick: u32,
) -> Result<(Mode, Effect), Refusal> {
    let stage1 = matches!(phase, Phase::Deploy | Phase::Keep1);
    match (command, mode) {
        (ModeCommand::Hold, Mode::Flying) => Ok((Mode::Held { since_tick: tick }, Effect::None)),
        (ModeCommand::Hold, Mode::Held { .. } | Mode::Aborted) => Err(Refusal::AlreadyHeld),
        (ModeCommand::Resume, Mode::Held { since_tick }) => Ok((
            Mode::Flying,
            Effect::Resume {
                held_since_tick: since_tick,
            },
        )),
        (ModeCommand::Resume, Mode::Flying | Mode::Aborted) => Err(Refusal::NotHeld),
        (ModeCommand::Retrieve, Mode::Flying | Mode::Held { .. }) if stage1 => {
            Ok((Mode::Flying, Effect::BeginStage2))
        }
        (ModeCommand::Retrieve, _) => Err(Refusal::NotInStage1),
        (ModeCommand::StartDeployment, Mode::Aborted) => Ok((Mode::Flying, Effect::NewDeployment)),
        (ModeCommand::StartDeployment, Mode::Flying | Mode::Held { .. }) => {
            Err(Refusal::NotAborted)
        }
        (ModeCommand::Abort, Mode::Flying | Mode::Held { .. }) => Ok((Mode::Aborted, Effect::None)),
        (ModeCommand::Abort, Mode::Aborted) => Err(Refusal::AlreadyAborted),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifiers_round_trip_and_unknown_ones_are_none() {
        for c in ModeCommand::ALL {
            assert_eq!(ModeCommand::from_id(c as u16), Some(c));
        }
        assert_eq!(ModeCommand::from_id(0), None);
        assert_eq!(ModeCommand::from_id(6), None);
    }

    #[test]
    fn each_command_is_legal_exactly_where_the_diagram_says() {
        let phases = [
            Phase::Deploy,
            Phase::Keep1,
            Phase::Slew,
            Phase::Retrieve,
            Phase::Keep2,
        ];
        let modes = [Mode::Flying, Mode::Held { since_tick: 3 }, Mode::Aborted];
        for phase in phases {
            let stage1 = matches!(phase, Phase::Deploy | Phase::Keep1);
            for mode in modes {
                for c in ModeCommand::ALL {
                    let legal = match c {
                        ModeCommand::Hold => mode == Mode::Flying,
                        ModeCommand::Resume => matches!(mode, Mode::Held { .. }),
                        ModeCommand::Retrieve => stage1 && mode != Mode::Aborted,
                        ModeCommand::StartDeployment => mode == Mode::Aborted,
                        ModeCommand::Abort => mode != Mode::Aborted,
                    };
                    assert_eq!(
                        transition(mode, phase, c, 9).is_ok(),
                        legal,
                        "{c:?} in {mode:?}, {phase:?}"
                    );
                }
            }
        }
    }
}
