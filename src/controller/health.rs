//! Health of the controller's inputs (the fault state machine of [`Health`]) and dead
//! reckoning of the tether length while no sample can be used.

use crate::config::MonitorConfig;
use crate::real::Real;

use super::output::Health;

/// The fault state machine, with persistence and rate (FDIR): a leaky counter of unusable
/// samples (see [`MonitorConfig::good_samples_per_bad`]), and how long the inputs have been
/// good again in safe hold.
#[derive(Clone, Copy, Debug)]
pub(super) struct HealthMachine {
    health: Health,
    /// The leaky counter: + `good_samples_per_bad` for every unusable sample (or law fault),
    /// − 1 for every usable one.
    fault_level: u32,
    /// Consecutive valid samples while in safe hold.
    good_ticks: u32,
}

impl HealthMachine {
    pub(super) const fn new() -> Self {
        Self {
            health: Health::Nominal,
            fault_level: 0,
            good_ticks: 0,
        }
    }

    /// The current health.
    pub(super) fn health(&self) -> Health {
        self.health
    }

    /// A usable sample that the law could use: Nominal, and the counter leaks by one.
    pub(super) fn usable(&mut self) {
        self.health = Health::Nominal;
        if self.fault_level > 0 {
            self.fault_level -= 1;
        }
    }

    /// No usable sample or law solution at this tick: Degraded, until the leaky counter
    /// exceeds `coast_ticks × good_samples_per_bad` (`coast_ticks + 1` bad samples in a row
    /// from a clean record, sooner after recent faults): then SafeHold, which only
    /// `recovery_ticks` valid samples in a row leave (see [`HealthMachine::recovered`]).
    pub(super) fn unusable<T>(&mut self, cfg: &MonitorConfig<T>) {
        self.fault_level = self.fault_level.saturating_add(cfg.good_samples_per_bad);
        self.good_ticks = 0;
        // (`Config::validate` checks that the product does not saturate.)
        let limit = cfg.coast_ticks.saturating_mul(cfg.good_samples_per_bad);
        self.health = if self.health == Health::SafeHold || self.fault_level > limit {
            Health::SafeHold
        } else {
            Health::Degraded
        };
    }

    /// The reel drive tripped (`drive`): safe hold at once, and the run of valid samples that
    /// leaves it starts again.
    pub(super) fn force_safe_hold(&mut self) {
        self.health = Health::SafeHold;
        self.good_ticks = 0;
    }

    /// A valid sample in safe hold: `true` once `recovery_ticks` have arrived in a row, which
    /// clears the leaky counter and the run (the law may run again; [`HealthMachine::usable`]
    /// then makes the health Nominal).
    pub(super) fn recovered<T>(&mut self, cfg: &MonitorConfig<T>) -> bool {
        self.good_ticks = self.good_ticks.saturating_add(1);
        let recovered = self.good_ticks >= cfg.recovery_ticks;
        if recovered {
            self.fault_level = 0;
            self.good_ticks = 0;
        }
        recovered
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
