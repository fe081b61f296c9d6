//! The reel drive's faults in the outer fault logic (issue 19): one outer step that knows
//! what the inner speed loop ([`crate::reel_drive`]) went through during the period.
//!
//! The speed loop runs at the inner rate and reports typed faults every tick
//! ([`DriveFaults`]); the caller takes their union over the law period and hands it to
//! [`Controller::step_with_drive`] with the period's sample. The mapping is
//! [`DriveFault::outer_reaction`](crate::reel_drive::DriveFault::outer_reaction):
//!
//! - [`OuterReaction::Report`]: the sample is used as it is (the fault is telemetry);
//! - [`OuterReaction::Degrade`] (encoder jump or missing, duty saturated too long, tension out
//!   of range): the period is a missing sample, as [`Controller::step_missing`]: the controller
//!   coasts on its last command (`Health::Degraded`) and goes to `Health::SafeHold` through its
//!   leaky counter if the faults persist;
//! - [`OuterReaction::SafeHold`] (stall, refused actuator: the drive tripped): safe hold at
//!   once, its zero command ramped as usual, and every tripped period starts the recovery
//!   count again.

use crate::real::Real;
use crate::reel_drive::{DriveFaults, OuterReaction};

use super::{Controller, Flags, Input, Output};

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
        let health = self.health.health();
        let sample = match drive.outer_reaction() {
            OuterReaction::Report => sample,
            OuterReaction::Degrade => None,
            OuterReaction::SafeHold => {
                self.health.force_safe_hold();
                None
            }
        };
        self.decide(tick, sample);
        // A forced safe hold changed the health before the step: flag it as the step would.
        self.out
            .flags
            .set_if(self.out.health != health, Flags::HEALTH_CHANGED);
        self.record_events();
        &self.out
    }
}
