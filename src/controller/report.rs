//! The last stage of a step: the decided command reported ([`Controller::output`]), and the
//! events of what changed since the last report, found by comparing what is reported now with
//! what was reported before.

use crate::real::Real;

use super::estimation::Commanded;
use super::events::{Event, EventKind};
use super::{Controller, Decided, Fault, Flags, Health, Output, Phase, MAX_REPORTED_MARGIN};

/// What a step reported that an event tells when it changes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Reported {
    pub(super) health: Health,
    pub(super) phase: Phase,
    pub(super) fault: Option<Fault>,
    /// How many times the Eq. 29 blend has (re)started.
    pub(super) blend_restarts: u32,
    /// The phase was found no longer getting closer to its keep length.
    pub(super) stalled: bool,
    pub(super) tension_limited: bool,
}

impl<T: Real> Controller<T> {
    /// Report the step at `tick` ([`Controller::output`]): the command becomes the last command
    /// (and, flying on the estimator, the drive of its next prediction), its place in the
    /// existence region (Eq. 13), and the events of what changed since the last report.
    // Inlined into the step: out of line, the decided command goes through memory once more
    // and the step grows by some 2 % (scripts/bench-target).
    #[inline(always)]
    pub(super) fn report(&mut self, tick: u32, d: &Decided<T>) {
        self.last_command = d.command;
        let margin = self.equilibrium_margin(d.normalised_rate);
        let mut flags = d.flags;
        flags.set_if(margin < T::ZERO, Flags::NO_EQUILIBRIUM);
        let nis = self.estimation.as_mut().and_then(|est| {
            est.end_step(Commanded {
                length_m: d.length_m,
                rate_mps: d.command.rate_mps,
                accel_mps2: d.command.accel_mps2,
                mu3: d.mu3,
            })
        });
        let now = Reported {
            health: self.health.health(),
            phase: self.sequencer.phase(),
            fault: d.fault,
            blend_restarts: self.sequencer.blend_restarts(),
            stalled: self.sequencer.stalled(),
            tension_limited: flags.contains(Flags::TENSION_LIMITED),
        };
        flags.set(self.record_changes(tick, now));
        let law = &d.law;
        self.out = Output {
            tick,
            phase: now.phase,
            health: now.health,
            rate_cmd_mps: d.command.rate_mps,
            accel_cmd_mps2: d.command.accel_mps2,
            law_rate_mps: law.law_rate_mps,
            blend_weight: d.blend_weight,
            alpha_ref_rad: d.alpha_ref_rad,
            alpha_ref_rate_radps: law.ref_rate_radps,
            delta_rad: law.delta_rad,
            delta_rate_radps: law.delta_rate_radps,
            length_estimate_m: d.length_m,
            equilibrium_margin: margin,
            nis,
            flags,
            fault: d.fault,
        };
    }

    /// The events of what changed from the last report to `now`, in this order: health,
    /// phase, a new fault, a blend restart, a stall, the tension bound beginning to act. Returns
    /// the flags that say so in the output ([`Flags::HEALTH_CHANGED`],
    /// [`Flags::PHASE_CHANGED`], [`Flags::BLEND_RESTART`], [`Flags::NO_PROGRESS`]).
    fn record_changes(&mut self, tick: u32, now: Reported) -> u32 {
        let mut flags = Flags::default();
        if now == self.reported {
            flags.set_if(now.stalled, Flags::NO_PROGRESS);
            return flags.0;
        }
        let last = core::mem::replace(&mut self.reported, now);
        let mut record = |kind| self.events.push(Event { tick, kind });
        if now.health != last.health {
            flags.set(Flags::HEALTH_CHANGED);
            record(EventKind::Health {
                from: last.health,
                to: now.health,
            });
        }
        if now.phase != last.phase {
            flags.set(Flags::PHASE_CHANGED);
            record(EventKind::Phase(now.phase));
        }
        if let Some(f) = now.fault.filter(|_| now.fault != last.fault) {
            record(EventKind::Fault(f));
        }
        if now.blend_restarts != last.blend_restarts {
            flags.set(Flags::BLEND_RESTART);
            record(EventKind::BlendRestart);
        }
        if now.stalled {
            flags.set(Flags::NO_PROGRESS);
            if !last.stalled {
                record(EventKind::NoProgress(now.phase));
            }
        }
        if now.tension_limited && !last.tension_limited {
            record(EventKind::TensionLimited);
        }
        flags.0
    }

    /// The Eq. 13 whole-orbit margin of a command whose normalised rate (Eq. 7) is `x`:
    /// min Depl − |x| (> 0 inside the region). Near docking x grows as 1/l, so the margin is
    /// reported no lower than −[`MAX_REPORTED_MARGIN`] (it is never above min Depl); a zero
    /// length estimate (a long coast toward docking) makes x infinite or NaN, reported as that
    /// bound: far outside.
    fn equilibrium_margin(&self, x: T) -> T {
        let margin = self.existence.whole_orbit_margin_of(x);
        let lowest = T::from_f64(-MAX_REPORTED_MARGIN);
        if margin >= lowest {
            margin
        } else {
            lowest
        }
    }
}
