//! Sensor monitoring: every sensed value is checked before use (as PX4's `_inputValid()`
//! does) — finite, inside its physical range, and consistent with what came before (no length
//! jump the reel cannot make, no angle jump, no stuck angle sensor).
//!
//! A rejected sample never reaches the law; the controller takes its documented safe action
//! (see [`crate::controller`]).

use crate::config::{positive, ConfigError, Rule};
use crate::controller::Input;
use crate::real::{MagnitudeBound, PositiveInterval, Real};

/// Which sensed value was rejected, and why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Sensor {
    /// No sample arrived for this tick (dropout).
    Missing,
    /// The tick count went backwards.
    Tick,
    /// Length NaN, infinite, below [`MIN_PLAUSIBLE_LENGTH_M`] or beyond the spool (+5 %).
    Length,
    /// Length differs from the length predicted from the command by more than allowed.
    LengthJump,
    /// α NaN, infinite or |α| > π.
    Alpha,
    /// α jumped further than α̇ allows.
    AlphaJump,
    /// α repeats exactly while α̇ says the tether is moving.
    AlphaStuck,
    /// α̇ NaN, infinite or beyond its plausible range.
    AlphaRate,
    /// Orbit rate NaN, infinite or outside [min, max].
    OrbitRate,
}

/// Shortest length a length sensor can plausibly report, m (1 mm): anything shorter is a
/// sensor fault, not a tether.
pub const MIN_PLAUSIBLE_LENGTH_M: f64 = 1e-3;

/// A sensed length beyond the spool end by more than this fraction is a sensor fault.
pub const SPOOL_MARGIN: f64 = 0.05;

/// Thresholds of the sensor checks and the fault timing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MonitorConfig<T> {
    /// Ticks without a valid sample (or with a law fault) during which the controller coasts
    /// before it goes to safe hold.
    pub coast_ticks: u32,
    /// Consecutive valid samples needed to leave safe hold.
    pub recovery_ticks: u32,
    /// Largest accepted |sensed − predicted| length, m (the prediction integrates the
    /// command; a reel with lag drifts from it by about lag × rate change per tick).
    pub length_jump_m: T,
    /// Largest accepted |α − (α_prev + α̇_prev Δt)| per tick, rad.
    pub alpha_jump_rad: T,
    /// Identical α readings in a row, with α̇ implying motion, that make a stuck sensor.
    pub stuck_ticks: u32,
    /// Motion (∫|α̇|dt over the identical readings) that a stuck verdict needs, rad.
    pub stuck_motion_rad: T,
    /// Largest plausible |α̇|, rad/s.
    pub max_alpha_rate_radps: T,
    /// Smallest plausible orbit rate, rad/s.
    pub min_orbit_rate_radps: T,
    /// Largest plausible orbit rate, rad/s.
    pub max_orbit_rate_radps: T,
}

impl<T: Real> MonitorConfig<T> {
    /// Defaults for a 1 s control period: coast 30 s, recover after 10 good samples, 20 m
    /// length jumps (an 11.8 m/s rate step through a 1 s reel lag is about 12 m), 0.1 rad angle
    /// jumps (the paper's |α̇| stays below 1e-3 rad/s), stuck after 20 identical readings
    /// spanning 1 mrad of implied motion, |α̇| ≤ 0.06 rad/s (≈ 60 n), 1e-5 ≤ n ≤ 0.01 rad/s
    /// (orbit periods from 10 minutes to a week; LEO is ≈ 1.1e-3).
    pub fn default_for_period() -> Self {
        Self {
            coast_ticks: 30,
            recovery_ticks: 10,
            length_jump_m: T::from_f64(20.0),
            alpha_jump_rad: T::from_f64(0.1),
            stuck_ticks: 20,
            stuck_motion_rad: T::from_f64(1e-3),
            max_alpha_rate_radps: T::from_f64(0.06),
            min_orbit_rate_radps: T::from_f64(1e-5),
            max_orbit_rate_radps: T::from_f64(0.01),
        }
    }

    /// Checks the thresholds.
    pub fn validate(&self) -> Result<(), ConfigError> {
        positive("monitor.coast_ticks", T::from_u32(self.coast_ticks))?;
        positive("monitor.recovery_ticks", T::from_u32(self.recovery_ticks))?;
        positive("monitor.length_jump_m", self.length_jump_m)?;
        positive("monitor.alpha_jump_rad", self.alpha_jump_rad)?;
        positive("monitor.stuck_ticks", T::from_u32(self.stuck_ticks))?;
        positive("monitor.stuck_motion_rad", self.stuck_motion_rad)?;
        positive("monitor.max_alpha_rate_radps", self.max_alpha_rate_radps)?;
        positive("monitor.min_orbit_rate_radps", self.min_orbit_rate_radps)?;
        crate::config::above(
            "monitor.max_orbit_rate_radps",
            self.max_orbit_rate_radps,
            self.min_orbit_rate_radps,
        )
    }
}

/// The last accepted sample, for the consistency checks. Before the first one, α is NaN: a
/// prediction from it is NaN, and every comparison with NaN is false, so no jump is seen.
#[derive(Clone, Copy, Debug)]
struct Accepted<T> {
    tick: u32,
    alpha_rad: T,
    alpha_rate_radps: T,
}

/// State of the sensor checks, and their range limits prepared once.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Monitor<T: Real> {
    /// [`MIN_PLAUSIBLE_LENGTH_M`, spool end + [`SPOOL_MARGIN`]].
    length_m: PositiveInterval<T>,
    /// [min, max] orbit rate.
    orbit_rate_radps: PositiveInterval<T>,
    /// |α| ≤ π.
    alpha_rad: MagnitudeBound<T>,
    /// |α̇| ≤ the configured maximum.
    alpha_rate_radps: MagnitudeBound<T>,
    last: Accepted<T>,
    /// Bits of the last α reading and how often it repeated (NaN's bits before the first
    /// reading: an accepted α is never NaN, so the first reading is always fresh).
    same_alpha_bits: T::Bits,
    same_count: u32,
    implied_motion_rad: T,
}

impl<T: Real> Monitor<T> {
    /// A monitor for a validated configuration: `spool_m` is the longest plausible length (the
    /// spool end plus [`SPOOL_MARGIN`]). Fails if that is not finite or below
    /// [`MIN_PLAUSIBLE_LENGTH_M`] (no length could ever be accepted).
    pub(crate) fn new(cfg: &MonitorConfig<T>, spool_m: T) -> Result<Self, ConfigError> {
        let length_m = PositiveInterval::new(T::from_f64(MIN_PLAUSIBLE_LENGTH_M), spool_m)
            .ok_or_else(|| {
                let rule = if spool_m.is_finite() {
                    Rule::BandInverted
                } else {
                    Rule::NotFinite
                };
                ConfigError::new("envelope.max_length_m", spool_m, rule)
            })?;
        let orbit_rate_radps =
            PositiveInterval::new(cfg.min_orbit_rate_radps, cfg.max_orbit_rate_radps).ok_or(
                ConfigError::new(
                    "monitor.max_orbit_rate_radps",
                    cfg.max_orbit_rate_radps,
                    Rule::BandInverted,
                ),
            )?;
        // (π always makes a bound; a validated configuration's α̇ limit does too.)
        let pi = T::from_f64(core::f64::consts::PI);
        let alpha_rad =
            MagnitudeBound::new(pi).ok_or(ConfigError::new("π", pi, Rule::NotFinite))?;
        let max_rate = cfg.max_alpha_rate_radps;
        let alpha_rate_radps = MagnitudeBound::new(max_rate).ok_or(ConfigError::new(
            "monitor.max_alpha_rate_radps",
            max_rate,
            Rule::NotPositive,
        ))?;
        Ok(Self {
            length_m,
            orbit_rate_radps,
            alpha_rad,
            alpha_rate_radps,
            last: Accepted {
                tick: 0,
                alpha_rad: T::from_f64(f64::NAN),
                alpha_rate_radps: T::ZERO,
            },
            same_alpha_bits: T::from_f64(f64::NAN).bits(),
            same_count: 0,
            implied_motion_rad: T::ZERO,
        })
    }

    /// Checks one sample. `expected_length_m` is the length the controller predicts for this
    /// tick (`None` when it has no trustworthy prediction). The controller never checks a
    /// sample whose tick is before the last accepted one (it rejects a tick that goes
    /// backwards first).
    ///
    /// Each range check is one unsigned comparison of bit patterns that NaN and ±∞ fail (see
    /// [`PositiveInterval`] and [`MagnitudeBound`]), so "finite and in range" costs no separate
    /// finiteness test.
    pub(crate) fn check(
        &mut self,
        cfg: &MonitorConfig<T>,
        x: &Input<T>,
        expected_length_m: Option<T>,
        period_s: T,
    ) -> Result<(), Sensor> {
        if !self.length_m.contains(x.length_m) {
            return Err(Sensor::Length);
        }
        if !self.alpha_rad.contains(x.alpha_rad) {
            return Err(Sensor::Alpha);
        }
        if !self.alpha_rate_radps.contains(x.alpha_rate_radps) {
            return Err(Sensor::AlphaRate);
        }
        if !self.orbit_rate_radps.contains(x.orbit_rate_radps) {
            return Err(Sensor::OrbitRate);
        }
        if let Some(expected) = expected_length_m {
            if (x.length_m - expected).abs() > cfg.length_jump_m {
                return Err(Sensor::LengthJump);
            }
        }
        // (No wrap-around: see above. Before any accepted sample `predicted` is NaN and the
        // test is false.)
        let last = &self.last;
        let ticks = T::from_u32(x.tick.wrapping_sub(last.tick).max(1));
        let predicted = last.alpha_rad + last.alpha_rate_radps * (ticks * period_s);
        if (x.alpha_rad - predicted).abs() > cfg.alpha_jump_rad * ticks {
            return Err(Sensor::AlphaJump);
        }
        // Stuck: the same reading again and again while α̇ says it should have moved.
        let bits = x.alpha_rad.bits();
        if bits == self.same_alpha_bits {
            self.same_count = self.same_count.saturating_add(1);
            self.implied_motion_rad = self.implied_motion_rad + x.alpha_rate_radps.abs() * period_s;
            if self.same_count >= cfg.stuck_ticks && self.implied_motion_rad >= cfg.stuck_motion_rad
            {
                return Err(Sensor::AlphaStuck);
            }
        } else {
            // A fresh reading (the usual case) cannot be stuck: no implied motion yet, and
            // `stuck_motion_rad` > 0.
            self.same_alpha_bits = bits;
            self.same_count = 1;
            self.implied_motion_rad = T::ZERO;
        }
        self.last = Accepted {
            tick: x.tick,
            alpha_rad: x.alpha_rad,
            alpha_rate_radps: x.alpha_rate_radps,
        };
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(tick: u32, alpha_rad: f64, alpha_rate_radps: f64) -> Input<f64> {
        Input {
            tick,
            length_m: 1_000.0,
            alpha_rad,
            alpha_rate_radps,
            orbit_rate_radps: 1.06e-3,
        }
    }

    #[test]
    fn alpha_jump_is_judged_against_the_last_accepted_sample() {
        let cfg = MonitorConfig::<f64>::default_for_period();
        let mut m = Monitor::new(&cfg, 42_000.0).unwrap();
        // No previous sample: any α in range is accepted (the NaN prediction sees no jump).
        assert_eq!(m.check(&cfg, &sample(5, 3.0, 0.01), None, 1.0), Ok(()));
        // Predicted 3.01 one tick later; 0.1 rad allowed.
        assert_eq!(m.check(&cfg, &sample(6, 3.105, 0.0), None, 1.0), Ok(()));
        assert_eq!(
            m.check(&cfg, &sample(7, 2.9, 0.0), None, 1.0),
            Err(Sensor::AlphaJump)
        );
        // Three ticks after the last accepted one (tick 6): 0.3 rad allowed.
        assert_eq!(m.check(&cfg, &sample(9, 2.85, 0.0), None, 1.0), Ok(()));
        // The same tick again: one tick's allowance, no motion predicted.
        assert_eq!(m.check(&cfg, &sample(9, 2.93, 0.0), None, 1.0), Ok(()));
        assert_eq!(
            m.check(&cfg, &sample(9, 3.1, 0.0), None, 1.0),
            Err(Sensor::AlphaJump)
        );
    }

    #[test]
    fn a_first_reading_of_zero_starts_a_fresh_count() {
        let cfg = MonitorConfig::<f64> {
            stuck_ticks: 2,
            stuck_motion_rad: 0.015,
            ..MonitorConfig::default_for_period()
        };
        let mut m = Monitor::new(&cfg, 42_000.0).unwrap();
        // 0.0 rad is not mistaken for a repeat of anything before the first reading.
        assert_eq!(m.check(&cfg, &sample(0, 0.0, 0.01), None, 1.0), Ok(()));
        assert_eq!(m.same_count, 1);
        assert_eq!(m.implied_motion_rad, 0.0);
        // Second identical reading: 2 in a row, 0.01 rad implied (< 0.015): still accepted.
        assert_eq!(m.check(&cfg, &sample(1, 0.0, 0.01), None, 1.0), Ok(()));
        assert_eq!(
            m.check(&cfg, &sample(2, 0.0, 0.01), None, 1.0),
            Err(Sensor::AlphaStuck)
        );
    }
}
