//! Sensor monitoring: every sensed value is checked before use (as PX4's `_inputValid()`
//! does) — finite, inside its physical range, and consistent with what came before (no length
//! jump the reel cannot make, no angle jump, no stuck angle sensor, no reel rate the reel
//! cannot run at).
//!
//! A rejected sample never reaches the law; the controller takes its documented safe action
//! (see [`crate::controller`]).

use crate::config::{ConfigError, Rule};
use crate::real::Real;

pub use crate::config::MonitorConfig;

/// One control period's sensor sample.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Input<T> {
    /// Tick count of this sample (mission time = tick × period).
    pub tick: u32,
    /// Length from the reel encoder, m.
    pub length_m: T,
    /// The reel's rate measured by its encoder, m/s (None: not measured this period).
    pub reel_rate_mps: Option<T>,
    /// Tension at the reel from the load cell, N (None: no load cell, or no sample).
    pub tension_n: Option<T>,
    /// In-plane angle α from the swing sensor, rad (None: the swing sensor gave nothing this
    /// period; the estimator predicts only).
    pub alpha_rad: Option<T>,
    /// α̇ from an optional rate sensor, rad/s: used only by a controller configured to fly on
    /// it ([`RateSource::Sensor`](crate::config::RateSource::Sensor), the paper's
    /// idealisation, used for Table 1); None in flight.
    pub alpha_rate_radps: Option<T>,
    /// Orbit rate θ̇, rad/s.
    pub orbit_rate_radps: T,
    /// True anomaly θ, rad, from the onboard orbit source (used on an eccentric orbit;
    /// ignored when the configured eccentricity is 0).
    pub true_anomaly_rad: T,
}

/// Which sensed value was rejected, and why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Sensor {
    /// No sample arrived for this tick (dropout).
    Missing,
    /// The tick did not move forward: repeated, or from the past (wrap-aware, see
    /// [`crate::controller`]).
    Tick,
    /// Length NaN, infinite, below [`MIN_PLAUSIBLE_LENGTH_M`] or beyond the spool (+5 %).
    Length,
    /// Length differs from the length predicted from the command by more than allowed.
    LengthJump,
    /// α missing (flying on a rate sensor), NaN, infinite or |α| > π.
    Alpha,
    /// α jumped further than α̇ allows (flying on a rate sensor).
    AlphaJump,
    /// α repeats exactly while α̇ says the tether is moving (flying on a rate sensor), or
    /// `stuck_ticks` times in a row, which the swing sensor's noise does not allow (flying on
    /// the estimator: docs/equations.md §13, *A frozen swing sensor*).
    AlphaStuck,
    /// α failed the estimator's χ² innovation gate (flying on the estimator: an outlier, or a
    /// sensor that jumped or stuck; see [`crate::estimator`], *Gating and faults*).
    AlphaGated,
    /// No usable estimate of α and α̇ (flying on the estimator): no α sample yet, or none for
    /// so long that the estimate's α uncertainty is beyond use (see
    /// [`crate::controller`], *Flying on the estimator*).
    AlphaLost,
    /// α̇ missing (flying on a rate sensor), NaN, infinite or beyond its plausible range.
    AlphaRate,
    /// Orbit rate NaN, infinite or outside [min, max].
    OrbitRate,
    /// The encoder's reel rate NaN, infinite, or faster than the envelope's rate limit by
    /// more than [`REEL_RATE_MARGIN`]: the sample is rejected, and the estimator's drive over
    /// the period is the command.
    ReelRate,
}

/// Shortest length a length sensor can plausibly report, m (1 mm): anything shorter is a
/// sensor fault, not a tether.
pub const MIN_PLAUSIBLE_LENGTH_M: f64 = 1e-3;

/// A sensed length beyond the spool end by more than this fraction is a sensor fault.
pub const SPOOL_MARGIN: f64 = 0.05;

/// A reel rate beyond the envelope's rate limit by more than this fraction is a sensor fault:
/// the drive follows its command within its acceleration limit and never runs half again
/// faster than the fastest command.
pub const REEL_RATE_MARGIN: f64 = 0.5;

/// What the law may use of an accepted sample's swing sensing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Swing<T> {
    /// The sensed α and α̇ (rad, rad/s), flying on a rate sensor.
    Sensed(T, T),
    /// The sensed α (rad) for the estimator, if the swing sensor gave one.
    Angle(Option<T>),
}

/// The angle checks, by rate source.
#[derive(Clone, Copy, Debug)]
enum AngleChecks<T> {
    /// Flying on a rate sensor: α and α̇ required, and the α-jump and α-stuck checks judged
    /// against the last accepted sample (`None` before the first).
    RateSensor(Option<Accepted<T>>),
    /// Flying on the estimator: α optional (a dropout of the swing sensor alone is not a bad
    /// sample), α̇ ignored; the estimator's innovation gate replaces the jump check, and a run
    /// of identical readings the sensor's noise cannot make is a frozen sensor
    /// (the monitor's `repeats`).
    Estimator,
}

/// The run of bit-identical α readings the last accepted α ends (flying on the estimator).
#[derive(Clone, Copy, Debug)]
struct Repeats<T> {
    alpha_rad: T,
    /// Readings of this α in a row, including any rejected as stuck since.
    count: u32,
}

/// The last accepted sample, for the consistency checks, and the run of identical α
/// readings it ends (the stuck-sensor check).
#[derive(Clone, Copy, Debug)]
struct Accepted<T> {
    tick: u32,
    alpha_rad: T,
    alpha_rate_radps: T,
    /// Readings of this α in a row, including any rejected as stuck since.
    same_alpha_count: u32,
    /// Motion that α̇ implied over those readings (∫|α̇|dt), rad.
    implied_motion_rad: T,
}

/// State of the sensor checks.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Monitor<T> {
    /// [`MIN_PLAUSIBLE_LENGTH_M`], m.
    min_length_m: T,
    /// The spool end plus [`SPOOL_MARGIN`], m.
    max_length_m: T,
    /// The envelope's rate limit plus [`REEL_RATE_MARGIN`], m/s.
    max_reel_rate_mps: T,
    /// The angle checks of the rate source.
    angles: AngleChecks<T>,
    /// Flying on the estimator, the run of identical α readings the last α ends (`None`
    /// before the first α).
    repeats: Option<Repeats<T>>,
}

/// `lo ≤ v ≤ hi` (false for NaN).
fn within<T: Real>(v: T, lo: T, hi: T) -> bool {
    v >= lo && v <= hi
}

/// `|v| ≤ max` (false for NaN).
fn magnitude_within<T: Real>(v: T, max: T) -> bool {
    v.abs() <= max
}

impl<T: Real> Monitor<T> {
    /// A monitor for a validated configuration: `spool_m` is the longest plausible length (the
    /// spool end plus [`SPOOL_MARGIN`]); `max_rate_mps` the envelope's rate limit;
    /// `rate_sensor` when the law flies on a sensed α̇. Fails if the length is not finite or
    /// below [`MIN_PLAUSIBLE_LENGTH_M`] (no length could ever be accepted).
    pub(crate) fn new(spool_m: T, max_rate_mps: T, rate_sensor: bool) -> Result<Self, ConfigError> {
        let min_length_m = T::from_f64(MIN_PLAUSIBLE_LENGTH_M);
        if !spool_m.is_finite() {
            return Err(ConfigError::new(
                "envelope.max_length_m",
                spool_m,
                Rule::NotFinite,
            ));
        }
        if spool_m < min_length_m {
            return Err(ConfigError::new(
                "envelope.max_length_m",
                spool_m,
                Rule::BandInverted,
            ));
        }
        Ok(Self {
            min_length_m,
            max_length_m: spool_m,
            max_reel_rate_mps: max_rate_mps * T::from_f64(1.0 + REEL_RATE_MARGIN),
            angles: if rate_sensor {
                AngleChecks::RateSensor(None)
            } else {
                AngleChecks::Estimator
            },
            repeats: None,
        })
    }

    /// Checks one sample and returns what the law may use of its swing sensing. Flying on a
    /// rate sensor, a sample without α or α̇ is rejected ([`Sensor::Alpha`],
    /// [`Sensor::AlphaRate`]), as a missing sensor; flying on the estimator, α may be absent
    /// and α̇ is not looked at. `expected_length_m` is the length the controller predicts for
    /// this tick (`None` when it has no trustworthy prediction). The controller never checks a
    /// sample whose tick is before the last accepted one (it rejects a tick that goes
    /// backwards first).
    pub(crate) fn check(
        &mut self,
        cfg: &MonitorConfig<T>,
        x: &Input<T>,
        expected_length_m: Option<T>,
        period_s: T,
    ) -> Result<Swing<T>, Sensor> {
        // Range checks: each is false for NaN, and a finite bound excludes the infinities.
        if !within(x.length_m, self.min_length_m, self.max_length_m) {
            return Err(Sensor::Length);
        }
        if let Some(r) = x.reel_rate_mps {
            if !magnitude_within(r, self.max_reel_rate_mps) {
                return Err(Sensor::ReelRate);
            }
        }
        let pi = T::from_f64(core::f64::consts::PI);
        let swing = match self.angles {
            AngleChecks::RateSensor(_) => {
                let Some(alpha_rad) = x.alpha_rad.filter(|&a| magnitude_within(a, pi)) else {
                    return Err(Sensor::Alpha);
                };
                let Some(alpha_rate_radps) = x
                    .alpha_rate_radps
                    .filter(|&r| magnitude_within(r, cfg.max_alpha_rate_radps))
                else {
                    return Err(Sensor::AlphaRate);
                };
                Swing::Sensed(alpha_rad, alpha_rate_radps)
            }
            AngleChecks::Estimator => match x.alpha_rad {
                Some(a) if !magnitude_within(a, pi) => return Err(Sensor::Alpha),
                Some(a) => {
                    Self::not_frozen(cfg, &mut self.repeats, a)?;
                    Swing::Angle(Some(a))
                }
                None => Swing::Angle(None),
            },
        };
        if !within(
            x.orbit_rate_radps,
            cfg.min_orbit_rate_radps,
            cfg.max_orbit_rate_radps,
        ) {
            return Err(Sensor::OrbitRate);
        }
        if let Some(expected) = expected_length_m {
            if (x.length_m - expected).abs() > cfg.length_jump_m {
                return Err(Sensor::LengthJump);
            }
        }
        if let (AngleChecks::RateSensor(last), Swing::Sensed(alpha_rad, alpha_rate_radps)) =
            (&mut self.angles, swing)
        {
            Self::consistent(cfg, last, x.tick, alpha_rad, alpha_rate_radps, period_s)?;
        }
        Ok(swing)
    }

    /// The frozen-sensor check flying on the estimator: the `stuck_ticks`-th bit-identical α
    /// in a row, and every one after it, is rejected (docs/equations.md §13, *A frozen swing
    /// sensor*: a sensor with the estimator's noise model repeats a reading with probability
    /// below q/(2σ√π) per period, moving or not).
    fn not_frozen(
        cfg: &MonitorConfig<T>,
        run: &mut Option<Repeats<T>>,
        alpha_rad: T,
    ) -> Result<(), Sensor> {
        match run {
            Some(r) if r.alpha_rad == alpha_rad => {
                r.count = r.count.saturating_add(1);
                if r.count >= cfg.stuck_ticks {
                    return Err(Sensor::AlphaStuck);
                }
            }
            _ => {
                *run = Some(Repeats {
                    alpha_rad,
                    count: 1,
                })
            }
        }
        Ok(())
    }

    /// The α-jump and α-stuck checks of a sensed α and α̇ at `tick`, against the last accepted
    /// sample (which this one becomes when it passes).
    fn consistent(
        cfg: &MonitorConfig<T>,
        last: &mut Option<Accepted<T>>,
        tick: u32,
        alpha_rad: T,
        alpha_rate_radps: T,
        period_s: T,
    ) -> Result<(), Sensor> {
        let Some(last) = last else {
            *last = Some(Accepted {
                tick,
                alpha_rad,
                alpha_rate_radps,
                same_alpha_count: 1,
                implied_motion_rad: T::ZERO,
            });
            return Ok(());
        };
        // At least one tick's allowance (a repeated tick predicts no motion).
        let ticks = T::from_u32(tick.wrapping_sub(last.tick).max(1));
        let predicted = last.alpha_rad + last.alpha_rate_radps * (ticks * period_s);
        if (alpha_rad - predicted).abs() > cfg.alpha_jump_rad * ticks {
            return Err(Sensor::AlphaJump);
        }
        // Stuck: the same reading again and again while α̇ says it should have moved.
        if alpha_rad == last.alpha_rad {
            last.same_alpha_count = last.same_alpha_count.saturating_add(1);
            last.implied_motion_rad = last.implied_motion_rad + alpha_rate_radps.abs() * period_s;
            if last.same_alpha_count >= cfg.stuck_ticks
                && last.implied_motion_rad >= cfg.stuck_motion_rad
            {
                return Err(Sensor::AlphaStuck);
            }
        } else {
            last.same_alpha_count = 1;
            last.implied_motion_rad = T::ZERO;
        }
        // Accepted: the run of identical readings goes on, or starts with this one.
        last.tick = tick;
        last.alpha_rad = alpha_rad;
        last.alpha_rate_radps = alpha_rate_radps;
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
            reel_rate_mps: None,
            tension_n: None,
            alpha_rad: Some(alpha_rad),
            alpha_rate_radps: Some(alpha_rate_radps),
            orbit_rate_radps: 1.06e-3,
            true_anomaly_rad: 0.0,
        }
    }

    #[test]
    fn alpha_jump_is_judged_against_the_last_accepted_sample() {
        let cfg = MonitorConfig::<f64>::default_for_period();
        let mut m = Monitor::new(42_000.0, 15.0, true).unwrap();
        // No previous sample: any α in range is accepted.
        assert_eq!(
            m.check(&cfg, &sample(5, 3.0, 0.01), None, 1.0).map(drop),
            Ok(())
        );
        // Predicted 3.01 one tick later; 0.1 rad allowed.
        assert_eq!(
            m.check(&cfg, &sample(6, 3.105, 0.0), None, 1.0).map(drop),
            Ok(())
        );
        assert_eq!(
            m.check(&cfg, &sample(7, 2.9, 0.0), None, 1.0),
            Err(Sensor::AlphaJump)
        );
        // Three ticks after the last accepted one (tick 6): 0.3 rad allowed.
        assert_eq!(
            m.check(&cfg, &sample(9, 2.85, 0.0), None, 1.0).map(drop),
            Ok(())
        );
        // The same tick again: one tick's allowance, no motion predicted.
        assert_eq!(
            m.check(&cfg, &sample(9, 2.93, 0.0), None, 1.0).map(drop),
            Ok(())
        );
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
        let mut m = Monitor::new(42_000.0, 15.0, true).unwrap();
        // 0.0 rad is not mistaken for a repeat of anything before the first reading.
        assert_eq!(
            m.check(&cfg, &sample(0, 0.0, 0.01), None, 1.0).map(drop),
            Ok(())
        );
        let AngleChecks::RateSensor(Some(last)) = m.angles else {
            panic!("a rate-sensor monitor with an accepted sample");
        };
        assert_eq!((last.same_alpha_count, last.implied_motion_rad), (1, 0.0));
        // Second identical reading: 2 in a row, 0.01 rad implied (< 0.015): still accepted.
        assert_eq!(
            m.check(&cfg, &sample(1, 0.0, 0.01), None, 1.0).map(drop),
            Ok(())
        );
        assert_eq!(
            m.check(&cfg, &sample(2, 0.0, 0.01), None, 1.0),
            Err(Sensor::AlphaStuck)
        );
    }

    #[test]
    fn range_checks_reject_nan_infinities_and_bounds() {
        let cfg = MonitorConfig::<f32>::default_for_period();
        let ok = Input {
            tick: 0,
            length_m: 1_000.0_f32,
            reel_rate_mps: None,
            tension_n: None,
            alpha_rad: Some(0.5),
            alpha_rate_radps: Some(1e-4),
            orbit_rate_radps: 1.06e-3,
            true_anomaly_rad: 0.0,
        };
        let pi = core::f32::consts::PI;
        let cases = [
            (
                Input {
                    length_m: f32::NAN,
                    ..ok
                },
                Sensor::Length,
            ),
            (
                Input {
                    length_m: 0.0,
                    ..ok
                },
                Sensor::Length,
            ),
            (
                Input {
                    length_m: f32::INFINITY,
                    ..ok
                },
                Sensor::Length,
            ),
            (
                Input {
                    length_m: 42_001.0,
                    ..ok
                },
                Sensor::Length,
            ),
            (
                Input {
                    alpha_rad: Some(pi.next_up()),
                    ..ok
                },
                Sensor::Alpha,
            ),
            (
                Input {
                    alpha_rad: Some(f32::NEG_INFINITY),
                    ..ok
                },
                Sensor::Alpha,
            ),
            (
                Input {
                    alpha_rad: Some(-f32::NAN),
                    ..ok
                },
                Sensor::Alpha,
            ),
            (
                Input {
                    alpha_rate_radps: Some(0.0601),
                    ..ok
                },
                Sensor::AlphaRate,
            ),
            (
                Input {
                    alpha_rate_radps: Some(f32::NAN),
                    ..ok
                },
                Sensor::AlphaRate,
            ),
            (
                Input {
                    alpha_rad: None,
                    ..ok
                },
                Sensor::Alpha,
            ),
            (
                Input {
                    alpha_rate_radps: None,
                    ..ok
                },
                Sensor::AlphaRate,
            ),
            (
                Input {
                    orbit_rate_radps: 0.0,
                    ..ok
                },
                Sensor::OrbitRate,
            ),
            (
                Input {
                    orbit_rate_radps: f32::INFINITY,
                    ..ok
                },
                Sensor::OrbitRate,
            ),
        ];
        for (x, expected) in cases {
            let mut m = Monitor::new(42_000.0_f32, 15.0, true).unwrap();
            assert_eq!(m.check(&cfg, &x, None, 1.0), Err(expected), "{x:?}");
        }
        for x in [
            ok,
            Input {
                alpha_rad: Some(-pi),
                ..ok
            },
            Input {
                length_m: 42_000.0,
                ..ok
            },
            Input {
                length_m: 1e-3,
                ..ok
            },
        ] {
            let mut m = Monitor::new(42_000.0_f32, 15.0, true).unwrap();
            assert_eq!(m.check(&cfg, &x, None, 1.0).map(drop), Ok(()), "{x:?}");
        }
    }

    #[test]
    fn on_the_estimator_alpha_is_optional_its_rate_ignored_and_jumps_left_to_the_gate() {
        let cfg = MonitorConfig::<f64>::default_for_period();
        let mut m = Monitor::new(42_000.0, 15.0, false).unwrap();
        let x = |tick, alpha_rad: Option<f64>, rate: Option<f64>| Input {
            alpha_rad,
            alpha_rate_radps: rate,
            ..sample(tick, 0.0, 0.0)
        };
        assert_eq!(
            m.check(&cfg, &x(0, Some(0.5), None), None, 1.0),
            Ok(Swing::Angle(Some(0.5)))
        );
        // No α: accepted, for the estimator to predict; α̇, even absurd, is not looked at.
        assert_eq!(
            m.check(&cfg, &x(1, None, Some(f64::NAN)), None, 1.0),
            Ok(Swing::Angle(None))
        );
        // A jump far beyond alpha_jump_rad: the estimator's gate judges it, not the monitor.
        assert_eq!(
            m.check(&cfg, &x(2, Some(-2.0), Some(5.0)), None, 1.0),
            Ok(Swing::Angle(Some(-2.0)))
        );
        // The range check stays.
        assert_eq!(
            m.check(&cfg, &x(3, Some(f64::INFINITY), None), None, 1.0),
            Err(Sensor::Alpha)
        );
    }
}
