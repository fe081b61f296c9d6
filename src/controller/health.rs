//! Health of the controller's inputs (the fault state machine of [`Health`]) and dead
//! reckoning of the tether length while no sample can be used.

use crate::config::MonitorConfig;
use crate::real::Real;

use super::output::{Flags, Health};

/// The fault state machine: how long the inputs have been bad, and how long good again.
#[derive(Clone, Copy, Debug)]
pub(super) struct HealthMachine {
    health: Health,
    /// Consecutive ticks without a usable sample or law solution.
    bad_ticks: u32,
    /// Consecutive valid samples while in safe hold.
    good_ticks: u32,
}

impl HealthMachine {
    pub(super) const fn new() -> Self {
        Self {
            health: Health::Nominal,
            bad_ticks: 0,
            good_ticks: 0,
        }
    }

    /// The current health.
    pub(super) fn health(&self) -> Health {
        self.health
    }

    fn set(&mut self, h: Health, flags: &mut Flags) {
        if self.health != h {
            self.health = h;
            flags.set(Flags::HEALTH_CHANGED);
        }
    }

    /// A usable sample that the law could use: Nominal.
    pub(super) fn usable(&mut self, flags: &mut Flags) {
        self.set(Health::Nominal, flags);
        self.bad_ticks = 0;
        self.good_ticks = 0;
    }

    /// No usable sample or law solution at this tick: Degraded for up to `coast_ticks`, then
    /// SafeHold (which only valid samples leave, see [`HealthMachine::recovered`]).
    pub(super) fn unusable<T>(&mut self, cfg: &MonitorConfig<T>, flags: &mut Flags) {
        self.bad_ticks = self.bad_ticks.saturating_add(1);
        self.good_ticks = 0;
        let next = if self.health == Health::SafeHold || self.bad_ticks > cfg.coast_ticks {
            Health::SafeHold
        } else {
            Health::Degraded
        };
        self.set(next, flags);
    }

    /// A valid sample in safe hold: `true` once `recovery_ticks` have arrived in a row (the
    /// law may run again; [`HealthMachine::usable`] then makes the health Nominal).
    pub(super) fn recovered<T>(&mut self, cfg: &MonitorConfig<T>) -> bool {
        self.good_ticks = self.good_ticks.saturating_add(1);
        self.good_ticks >= cfg.recovery_ticks
    }
}

/// Dead reckoning: the length the controller works with — the last sensed length, or the
/// prediction from the integrated command while no sample can be used.
#[derive(Clone, Copy, Debug)]
pub(super) struct DeadReckoning<T> {
    /// `None` until a sample has been accepted: there is no length to predict from.
    length_m: Option<T>,
    /// The longest physical length: the spool end plus the monitor's margin, m.
    spool_m: T,
}

impl<T: Real> DeadReckoning<T> {
    pub(super) fn new(spool_m: T) -> Self {
        Self {
            length_m: None,
            spool_m,
        }
    }

    /// The length estimate, m (`None` before the first accepted sample).
    pub(super) fn length_m(&self) -> Option<T> {
        self.length_m
    }

    /// The estimate `elapsed_s` later, the reel having run at `rate_mps`.
    pub(super) fn predict(&self, rate_mps: T, elapsed_s: T) -> Option<T> {
        self.length_m.map(|l| l + rate_mps * elapsed_s)
    }

    /// A sensed length was accepted.
    pub(super) fn sensed(&mut self, length_m: T) {
        self.length_m = Some(length_m);
    }

    /// No sample could be used: `length_m` (the prediction, or a valid sensed length the law
    /// could not use) becomes the estimate, limited to the physical range (the reel cannot pay
    /// out past its spool nor wind in past zero).
    pub(super) fn coast(&mut self, length_m: Option<T>) {
        self.length_m = length_m.map(|l| l.clamp_finite(T::ZERO, self.spool_m));
    }
}
