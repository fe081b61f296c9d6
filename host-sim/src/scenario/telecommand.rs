//! `[[telecommand]]`: the on-board computer's timed telecommands. Each is encoded as the OBC
//! sends it (a CCSDS/PUS TC\[8,1\], `tss_reel::pus::encode`) and handed to the unit's PUS
//! services (`tss_reel::pus::Services`) before the control period that starts at `at_s`; the
//! controller applies it at that period's boundary if it is legal there (docs/equations.md
//! §7.1), and its verification reports go to `telemetry.csv`.

use serde::{Deserialize, Serialize};
use tss_reel::controller::ModeCommand;

use super::rules::Validator;

/// The most telecommands a scenario lists.
pub const MAX_TELECOMMANDS: usize = 1_000;

/// One `[[telecommand]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TelecommandSection {
    /// Mission time at which it is sent, s: before the control period that starts then (a
    /// whole number of control periods).
    pub at_s: f64,
    /// The mission-mode command.
    pub command: CommandName,
}

/// A mission-mode command as a scenario names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CommandName {
    /// After an abort, a new deployment.
    StartDeployment,
    /// Bring the reel to rest and keep the length.
    Hold,
    /// Leave a hold.
    Resume,
    /// Begin stage 2 now.
    Retrieve,
    /// Abort to a safe hold.
    Abort,
}

impl CommandName {
    /// The controller's command.
    pub fn to_mode_command(self) -> ModeCommand {
        match self {
            Self::StartDeployment => ModeCommand::StartDeployment,
            Self::Hold => ModeCommand::Hold,
            Self::Resume => ModeCommand::Resume,
            Self::Retrieve => ModeCommand::Retrieve,
            Self::Abort => ModeCommand::Abort,
        }
    }
}

/// At most [`MAX_TELECOMMANDS`], each at a non-negative whole number of control periods.
pub(super) fn check(list: &[TelecommandSection], period_s: f64, v: &mut Validator) {
    v.check(
        list.len() <= MAX_TELECOMMANDS,
        "telecommand",
        list.len().to_string(),
        &format!("must list at most {MAX_TELECOMMANDS} telecommands"),
    );
    for (i, tc) in list.iter().enumerate() {
        let field = format!("telecommand[{i}].at_s");
        if v.non_negative(&field, tc.at_s) {
            v.whole_multiple_of_period(&field, tc.at_s, period_s, true);
        }
    }
}
