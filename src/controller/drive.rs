//! The reel drive's faults in the outer fault logic: one outer step that knows what the inner
//! speed loop ([`crate::reel_drive`]) went through during the period, and the command the
//! inner loop takes from a step's output.
//!
//! The speed loop runs at the inner rate and reports typed faults every tick
//! ([`DriveFaults`]); the caller takes their union over the law period and hands it to
//! [`Controller::step_with_drive`] with the period's sample. The mapping is
//! [`DriveFault::outer_reaction`](crate::reel_drive::DriveFault::outer_reaction):
//!
//! - [`OuterReaction::Report`]: the sample is used as it is (the fault is telemetry: the
//!   caller's own error, or a load cell the drive no longer uses);
//! - [`OuterReaction::Degrade`] (encoder jump or missing, duty saturated too long, tension out
//!   of range): the period is a missing sample, as [`Controller::step_missing`]: the controller
//!   coasts on its last command (`Health::Degraded`) and goes to `Health::SafeHold` through its
//!   leaky counter if the faults persist;
//! - [`OuterReaction::SafeHold`] (stall, a drum that does not answer the torque, refused
//!   actuator: the drive tripped; a slipping brake: the motor holds the drum): safe hold at
//!   once, its zero command ramped as usual, and every such period starts the recovery count
//!   again.

use crate::real::Real;
use crate::reel_drive::{DriveFaults, OuterReaction, RateCommand};

use super::{Controller, Health, Input, Output};

impl<T: Real> Controller<T> {
    /// One control period whose reel drive reported `drive` (the union of its inner ticks'
    /// faults) with the sample `sample` (`None`: none arrived), at `tick`. See the module docs
    /// for what each reaction does; with no drive fault this is [`Controller::step`] (or
    /// [`Controller::step_missing`]).
    pub fn step_with_drive(
        &mut self,
        tick: u32,
        sample: Option<&Input<T>>,
        drive: DriveFaults,
    ) -> &Output<T> {
        let sample = match drive.outer_reaction() {
            OuterReaction::Report => sample,
            OuterReaction::Degrade => None,
            OuterReaction::SafeHold => {
                self.health.force_safe_hold();
                None
            }
        };
        self.run(tick, sample)
    }
}

/// The inner loop's command of one law period: the step's rate and acceleration, and whether
/// the controller is in safe hold (the brake may engage but not release).
impl From<&Output<f32>> for RateCommand {
    fn from(o: &Output<f32>) -> Self {
        Self {
            rate_mps: o.rate_cmd_mps,
            accel_mps2: o.accel_cmd_mps2,
            safe_hold: o.health == Health::SafeHold,
        }
    }
}
