//! The law's α and α̇ from the onboard estimator ([`crate::estimator`]), when the controller
//! flies [`RateSource::Estimator`](crate::config::RateSource::Estimator): each step carries the
//! estimate over the period that just ended under the drive the last step commanded (or the
//! reel's measured rate), updates it with this period's α, and says whether the law may fly on
//! it (see the controller's docs, *Flying on the estimator*). With a tension loop configured,
//! the drive is the range between the satellites, the reel's length stretched by the load
//! cell's tension (docs/equations.md §13.2).

use crate::config::{estimator_error, ConfigError, MonitorConfig, Rule, TensionLoopConfig};
use crate::estimator::{
    self, Drive, DriveError, Estimate, Estimator, Measurement, OrbitTerms, Prediction,
};
use crate::monitor::{Input, Sensor};
use crate::orbit::Orbit;
use crate::real::Real;

use super::events::EventKind;

/// The most periods one step carries the estimate over (a gap in the calls): beyond it the
/// estimate is dropped and the next α starts afresh. 32 periods is longer than any overrun a
/// control loop survives, and bounds the step's work.
pub const MAX_CARRIED_PERIODS: u32 = 32;

/// The estimate is useless to the law once Var(α̂) exceeds this many times R, the α sample's
/// variance (its standard deviation ten times the sensor's), and stays so until an α sample is
/// used again: the estimator exists to be better than the sensor. With the paper's tuning a
/// swing sensor silent after a settled estimate gets there in the time measured by
/// `tests/estimator/closed_loop.rs::a_silent_swing_sensor_is_flown_through_until_the_estimate_is_useless`.
pub const MAX_ALPHA_VARIANCE_IN_SAMPLES: f64 = 100.0;

/// The largest |α| the law flies on, rad (≈ 89°): beyond it the swing is a libration outside
/// the law's domain, a fault ([`Fault::Libration`](super::Fault::Libration)). At a constant
/// length the in-plane swing is a pendulum in the gravity gradient's potential
/// (3/2)θ̇² sin²α (docs/equations.md §13), whose separatrix, the edge of a tumble, passes
/// |α| = π/2. The deployments themselves swing far out at short lengths, and a safe hold there
/// (the reel stopped) is what tumbles them: the paper's stage 1 reaches 1.23 rad, the SEDS-2-like
/// deployment (`scenarios/seds2.toml`) 1.47 rad. So the bound sits just inside the separatrix,
/// where only a tether that is already turning over arrives.
pub const MAX_LIBRATION_RAD: f64 = 1.55;

/// What one step commanded of the reel for the coming period: the drive of the next
/// prediction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Commanded<T> {
    /// The length at the start of the period (the length estimate), m.
    pub(super) length_m: T,
    /// The rate command, m/s.
    pub(super) rate_mps: T,
    /// The commanded acceleration, m/s².
    pub(super) accel_mps2: T,
    /// μ3 at that length.
    pub(super) mu3: T,
}

/// The tether's stretch, as the drive counts it (docs/equations.md §13.2): the range between
/// the satellites is the unstretched length l plus e = l·T/EA, T the load cell's tension.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Stretch<T> {
    /// 1/EA, the compliance the tension loop is told (`TensionLoopConfig::axial_stiffness_n`),
    /// 1/N.
    compliance_per_n: T,
    /// The largest tension counted, N (the loop's `max_tension_n`, the most the reel is asked
    /// to hold): a reading beyond it stretches the tether by no more, so one corrupt sample
    /// moves the drive by a bounded step.
    max_tension_n: T,
    /// e at the last step's sample, m (`None`: that sample had no usable tension).
    last_m: Option<T>,
}

impl<T: Real> Stretch<T> {
    /// e = l·T/EA of a sample (`None` without a usable tension: absent, not finite). A
    /// negative reading is a slack tether (no stretch).
    fn of(&self, x: &Input<T>) -> Option<T> {
        let t = x.tension_n.filter(|t| t.is_finite())?;
        // Finite (filtered above): no NaN for the clamp to handle.
        Some(x.length_m * t.clamp_finite(T::ZERO, self.max_tension_n) * self.compliance_per_n)
    }
}

/// What the estimator made of this step's sample, for the law and the fault logic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Estimated<T> {
    /// The law flies on α̂ (rad) and α̇̂ (rad/s).
    Usable(T, T),
    /// No estimate the law may use: a bad sample of this kind ([`Sensor::AlphaGated`],
    /// [`Sensor::AlphaLost`]).
    Unusable(Sensor),
}

/// The orbit of an accepted sample, as the prediction's drive reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
enum SensedOrbit<T> {
    /// A circular orbit's θ̇, rad/s (θ̈ = 0, μ/R³ = θ̇²), in the estimator's range: the monitor
    /// checked it against its band, which [`Estimation::new`] checked against the estimator's.
    Circular(T),
    /// An eccentric orbit's θ̇, θ̈ and μ/R³ at the sample's θ, or why they were refused.
    Eccentric(Result<OrbitTerms<T>, DriveError>),
}

impl<T: Real> SensedOrbit<T> {
    /// The orbit's terms, or why they were refused.
    fn terms(&self) -> Result<OrbitTerms<T>, DriveError> {
        match *self {
            Self::Circular(rate_radps) => Ok(OrbitTerms::circular_in_range(rate_radps)),
            Self::Eccentric(terms) => terms,
        }
    }
}

/// The estimator in the loop.
#[derive(Clone, Debug)]
pub(super) struct Estimation<T: Real> {
    filter: Estimator<T>,
    /// The configured orbit when it is eccentric (θ̈ and μ/R³ from θ); `None` on a circular
    /// one (0 and θ̇²).
    eccentric: Option<Orbit<T>>,
    /// Var(α̂) beyond which the law may not use the estimate, rad².
    max_alpha_var_rad2: T,
    /// The orbit at the last accepted sample (a period without one is carried with it); before
    /// the first, the configured orbit at periapsis (no estimate to carry then: the estimate
    /// starts from an accepted sample's α).
    orbit: SensedOrbit<T>,
    /// What the last step commanded (`None` before the first step).
    commanded: Option<Commanded<T>>,
    /// The tether's stretch (`None`: no tension loop, a rigid tether's drive).
    stretch: Option<Stretch<T>>,
    /// The NIS of the last step's α sample, if one met the estimate.
    nis: Option<T>,
    /// The estimate was found useless, and no α has been used since: it stays useless (its α
    /// variance may shrink again while uncertainty swings from α̇ into α, which does not make it
    /// any better).
    useless: bool,
}

impl<T: Real> Estimation<T> {
    /// The estimator of `cfg` (validated with the controller's configuration) on `orbit`; with
    /// the tension loop `tension`, its drive counts the tether's stretch. The orbit rates
    /// `monitor` admits must be rates the estimator admits
    /// ([`estimator::MIN_CIRCULAR_ORBIT_RATE_RADPS`], [`estimator::MAX_ORBIT_RATE_RADPS`]):
    /// a sample's θ̇ is then checked once, by the monitor. (`monitor` is validated: its band is
    /// finite.)
    pub(super) fn new(
        cfg: &estimator::Config<T>,
        orbit: &Orbit<T>,
        tension: Option<&TensionLoopConfig<T>>,
        monitor: &MonitorConfig<T>,
    ) -> Result<Self, ConfigError> {
        let filter = Estimator::new(*cfg).map_err(estimator_error)?;
        let (min, max) = (monitor.min_orbit_rate_radps, monitor.max_orbit_rate_radps);
        if min < T::from_f64(estimator::MIN_CIRCULAR_ORBIT_RATE_RADPS) {
            return Err(ConfigError::new(
                "monitor.min_orbit_rate_radps",
                min,
                Rule::OutOfRange,
            ));
        }
        if max > T::from_f64(estimator::MAX_ORBIT_RATE_RADPS) {
            return Err(ConfigError::new(
                "monitor.max_orbit_rate_radps",
                max,
                Rule::OutOfRange,
            ));
        }
        let max_alpha_var_rad2 =
            T::from_f64(MAX_ALPHA_VARIANCE_IN_SAMPLES) * filter.measurement_var_rad2();
        let eccentric = (orbit.eccentricity > T::ZERO).then_some(*orbit);
        Ok(Self {
            filter,
            eccentric,
            max_alpha_var_rad2,
            orbit: match eccentric {
                None => SensedOrbit::Circular(orbit.true_anomaly_rate_radps(T::ZERO)),
                // sin θ = 0 at periapsis: θ̈ = 0.
                Some(o) => SensedOrbit::Eccentric(OrbitTerms::new(
                    o.true_anomaly_rate_radps(T::ZERO),
                    T::ZERO,
                    o.gravity_gradient_per_s2(T::ZERO),
                )),
            },
            commanded: None,
            stretch: tension.map(|t| Stretch {
                compliance_per_n: T::ONE / t.axial_stiffness_n,
                max_tension_n: t.max_tension_n,
                last_m: None,
            }),
            nis: None,
            useless: false,
        })
    }

    /// The estimate after the last step.
    pub(super) fn estimate(&self) -> Option<Estimate<T>> {
        self.filter.estimate()
    }

    /// The law computed sin 2α and cos 2α for `alpha_rad`, the α̂ of this step's
    /// [`Estimated::Usable`] verdict: the next prediction reuses them.
    pub(super) fn lend_sin_cos_two_alpha(&mut self, alpha_rad: T, sin: T, cos: T) {
        self.filter.lend_sin_cos_two_alpha(alpha_rad, sin, cos);
    }

    /// The end of a step: it commanded `c` for the coming period (the drive of the next
    /// prediction). Returns the NIS of this step's α sample, if one met the estimate (for the
    /// output).
    pub(super) fn end_step(&mut self, c: Commanded<T>) -> Option<T> {
        self.commanded = Some(c);
        self.nis
    }

    /// One step: carries the estimate over the `periods` that passed since the last step
    /// (0 at the first), the reel having run at the accepted `sample`'s measured rate (if the
    /// encoder gave one) or at the last command, the tether stretched as its load cell says
    /// (with a tension loop), then updates it with this period's α (`None`: the swing sensor
    /// gave nothing, or the sample was rejected; an accepted one is an angle, the monitor
    /// checked it). The orbit's terms are those of the accepted
    /// sample (`None`: the last ones hold). Returns the verdict and the event it makes, if any.
    pub(super) fn step(
        &mut self,
        periods: u32,
        sample: Option<&Input<T>>,
        alpha_rad: Option<T>,
    ) -> (Estimated<T>, Option<EventKind>) {
        let mut reel_rate_mps = None;
        if let Some(x) = sample {
            self.sense_orbit(x.orbit_rate_radps, x.true_anomaly_rad);
            reel_rate_mps = x.reel_rate_mps;
        }
        let stretch_rate_mps = self.sense_stretch(periods, sample);
        // The last period with the encoder's rate (that of the period that just ended), after
        // the periods of a gap in the calls. One period, the common case, tested first.
        let lost = match periods {
            0 => false,
            1..=MAX_CARRIED_PERIODS => {
                // The periods of a gap in the calls at the last command, then the last one.
                let gap_lost = periods > 1 && self.carry_gap(periods - 1);
                let last_lost = self.carry(periods - 1, reel_rate_mps, stretch_rate_mps);
                gap_lost || last_lost
            }
            _ => {
                let had = self.filter.estimate().is_some();
                self.filter.reset();
                had
            }
        };
        // An accepted α is an angle: the monitor checked it (finite, |α| ≤ π).
        let m = match alpha_rad {
            Some(z) => self.filter.update(z),
            None => Measurement::Missing,
        };
        let estimate = self.filter.alpha_rate_and_variance();
        let (nis, event) = match m {
            Measurement::Accepted(i) | Measurement::Gated(i) => (Some(i.nis), None),
            Measurement::Reinitialised(i) => (Some(i.nis), Some(EventKind::EstimateRestarted)),
            Measurement::Missing | Measurement::Invalid | Measurement::Initialised => (None, None),
        };
        self.nis = nis;
        let event = if lost {
            Some(EventKind::EstimateLost)
        } else {
            event
        };
        // An α used now makes the estimate worth judging again.
        let used = matches!(
            m,
            Measurement::Accepted(_) | Measurement::Initialised | Measurement::Reinitialised(_)
        );
        let verdict = match (m, estimate) {
            (Measurement::Gated(_), _) => Estimated::Unusable(Sensor::AlphaGated),
            (_, Some((alpha_rad, alpha_rate_radps, alpha_var_rad2)))
                if (used || !self.useless) && alpha_var_rad2 <= self.max_alpha_var_rad2 =>
            {
                self.useless = false;
                Estimated::Usable(alpha_rad, alpha_rate_radps)
            }
            _ => {
                self.useless = true;
                Estimated::Unusable(Sensor::AlphaLost)
            }
        };
        (verdict, event)
    }

    /// The stretch's mean rate over the period that just ended, m/s: the change of e = l·T/EA
    /// from the last step's sample to this one's, when both had a tension and one period
    /// passed (0 otherwise: the drive is then the reel's alone). Keeps this sample's e.
    fn sense_stretch(&mut self, periods: u32, sample: Option<&Input<T>>) -> T {
        let Some(stretch) = &mut self.stretch else {
            return T::ZERO;
        };
        let now_m = sample.and_then(|x| stretch.of(x));
        let rate_mps = match (periods, stretch.last_m, now_m) {
            (1, Some(last_m), Some(now_m)) => (now_m - last_m) / self.filter.config().period_s,
            _ => T::ZERO,
        };
        stretch.last_m = now_m;
        rate_mps
    }

    /// Carries the estimate over the `k`-th period since the last step (see [`Self::drive`]);
    /// `true` if the filter dropped it. Without a command yet the estimate is dropped
    /// (nothing says how the reel moved); with orbit terms refused, too (as a refused drive).
    fn carry(&mut self, k: u32, reel_rate_mps: Option<T>, stretch_rate_mps: T) -> bool {
        let Some(c) = self.commanded else {
            self.filter.reset();
            return false;
        };
        match self.orbit.terms() {
            Ok(orbit) => matches!(
                self.filter.predict_period(&self.drive(
                    &c,
                    orbit,
                    k,
                    reel_rate_mps,
                    stretch_rate_mps
                )),
                Prediction::InvalidDrive(_) | Prediction::Diverged
            ),
            Err(_) => {
                let had = self.filter.estimate().is_some();
                self.filter.reset();
                had
            }
        }
    }

    /// Carries the estimate over the first `periods` periods since the last step (a gap in the
    /// calls: at most [`MAX_CARRIED_PERIODS`] − 1), at the last command; `true` if the filter
    /// dropped it.
    // Out of line: inlined, the gap's loop kept its state across the nominal one-period carry,
    // and the outer step exceeded its ceiling (scripts/bench-target).
    #[inline(never)]
    fn carry_gap(&mut self, periods: u32) -> bool {
        let mut lost = false;
        for k in 0..periods {
            lost |= self.carry(k, None, T::ZERO);
        }
        lost
    }

    /// Keeps the orbit's terms at an accepted sample: θ̈ and μ/R³ from θ on an eccentric orbit,
    /// θ̇² and no θ̈ on a circular one (θ̇ in range: the monitor checked it against its band,
    /// inside the estimator's, see [`Estimation::new`]).
    fn sense_orbit(&mut self, rate_radps: T, true_anomaly_rad: T) {
        self.orbit = match &self.eccentric {
            Some(o) => SensedOrbit::Eccentric(OrbitTerms::new(
                rate_radps,
                o.true_anomaly_accel_radps2(true_anomaly_rad),
                o.gravity_gradient_per_s2(true_anomaly_rad),
            )),
            None => SensedOrbit::Circular(rate_radps),
        };
    }

    /// The drive of the `k`-th period since the last step: the last step's command `c`, its
    /// length advanced by k periods of it; the rate measured over the period when the encoder
    /// gave one (taken as the period's mean: the drive's rate at mid-period, so its start rate
    /// is the mean less half the period's commanded change); plus the stretch's mean rate over
    /// the period (docs/equations.md §13.2; 0 without a tension loop).
    fn drive(
        &self,
        c: &Commanded<T>,
        orbit: OrbitTerms<T>,
        k: u32,
        reel_rate_mps: Option<T>,
        stretch_rate_mps: T,
    ) -> Drive<T> {
        let h = self.filter.config().period_s;
        let rate_mps = match reel_rate_mps {
            Some(mean) => mean - T::from_f64(0.5) * c.accel_mps2 * h,
            None => c.rate_mps,
        } + stretch_rate_mps;
        Drive {
            length_m: c.length_m + c.rate_mps * T::from_u32(k) * h,
            rate_mps,
            accel_mps2: c.accel_mps2,
            mu3: c.mu3,
            orbit,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default monitor's configuration.
    fn monitor() -> MonitorConfig<f64> {
        MonitorConfig::default_for_period()
    }

    /// A monitor that admits orbit rates the estimator does not is refused: the estimator
    /// builds a circular orbit's terms from the θ̇ the monitor accepted, unchecked.
    #[test]
    fn the_monitor_admits_only_orbit_rates_the_estimator_admits() {
        let cfg = estimator::Config::<f64>::paper();
        let orbit = Orbit::circular(7_078_000.0);
        let wide = |min: f64, max: f64| MonitorConfig {
            min_orbit_rate_radps: min,
            max_orbit_rate_radps: max,
            ..monitor()
        };
        let refused = |m: MonitorConfig<f64>| Estimation::new(&cfg, &orbit, None, &m).err();
        assert_eq!(refused(monitor()), None);
        let low = refused(wide(1e-11, 1e-2)).unwrap();
        assert_eq!(
            (low.param, low.rule),
            ("monitor.min_orbit_rate_radps", Rule::OutOfRange)
        );
        let high = refused(wide(1e-5, 2e-2)).unwrap();
        assert_eq!(
            (high.param, high.rule),
            ("monitor.max_orbit_rate_radps", Rule::OutOfRange)
        );
    }

    /// An accepted sample at the orbit rate `n`, the length `length_m` and the load cell's
    /// `tension_n`.
    fn sample(n: f64, length_m: f64, tension_n: Option<f64>) -> Input<f64> {
        Input {
            tick: 0,
            length_m,
            reel_rate_mps: None,
            tension_n,
            alpha_rad: Some(0.3),
            alpha_rate_radps: None,
            orbit_rate_radps: n,
            true_anomaly_rad: 0.0,
        }
    }

    /// With a tension loop the drive's rate is the range's: the reel's plus the change of
    /// l·T/EA over the period; a tension beyond the loop's `max_tension_n` stretches no more,
    /// a period without a tension (or a gap) adds nothing.
    #[test]
    fn the_drive_counts_the_stretch_the_load_cell_measures() {
        let cfg = estimator::Config::<f64>::paper();
        let loop_cfg = TensionLoopConfig::<f64>::dyneema_half_mm();
        let orbit = Orbit::circular(7_078_000.0);
        let mut e = Estimation::new(&cfg, &orbit, Some(&loop_cfg), &monitor()).unwrap();
        let n = 1.06e-3;
        let ea = loop_cfg.axial_stiffness_n;
        assert_eq!(
            e.sense_stretch(0, Some(&sample(n, 20_000.0, Some(5.0)))),
            0.0
        );
        // 5 → 6 N at 20 km: 2 m more of stretch in one period.
        let rate = e.sense_stretch(1, Some(&sample(n, 20_000.0, Some(6.0))));
        assert!((rate - 20_000.0 * 1.0 / ea).abs() < 1e-12, "{rate}");
        let c = Commanded {
            length_m: 20_000.0,
            rate_mps: -3.0,
            accel_mps2: 0.0,
            mu3: 0.01,
        };
        let terms = OrbitTerms::circular(n).unwrap();
        assert_eq!(e.drive(&c, terms, 0, None, rate).rate_mps, -3.0 + rate);
        // A corrupt reading counts as the loop's largest tension.
        let rate = e.sense_stretch(1, Some(&sample(n, 20_000.0, Some(1e4))));
        let most = 20_000.0 * (loop_cfg.max_tension_n - 6.0) / ea;
        assert!((rate - most).abs() < 1e-9, "{rate}");
        // No tension, a gap, or no loop: the reel's drive alone.
        assert_eq!(e.sense_stretch(1, Some(&sample(n, 20_000.0, None))), 0.0);
        assert_eq!(
            e.sense_stretch(1, Some(&sample(n, 20_000.0, Some(5.0)))),
            0.0
        );
        assert_eq!(
            e.sense_stretch(2, Some(&sample(n, 20_000.0, Some(6.0)))),
            0.0
        );
        let mut rigid = Estimation::new(&cfg, &orbit, None, &monitor()).unwrap();
        let _ = rigid.sense_stretch(0, Some(&sample(n, 20_000.0, Some(5.0))));
        assert_eq!(
            rigid.sense_stretch(1, Some(&sample(n, 20_000.0, Some(6.0)))),
            0.0
        );
    }

    #[test]
    fn the_drive_takes_the_orbit_terms_from_theta_on_an_eccentric_orbit_only() {
        let cfg = estimator::Config::<f64>::paper();
        let mut circular =
            Estimation::new(&cfg, &Orbit::circular(7_078_000.0), None, &monitor()).unwrap();
        let n = 1.06e-3;
        circular.sense_orbit(n, 2.0);
        let t = circular.orbit.terms().unwrap();
        assert_eq!(t.rate_radps(), n);
        assert_eq!(t.accel_radps2().to_bits(), 0.0_f64.to_bits());
        assert_eq!(t.gravity_gradient_per_s2(), n * n);
        let orbit = Orbit::elliptic(7_078_000.0, 0.1);
        let mut eccentric = Estimation::new(&cfg, &orbit, None, &monitor()).unwrap();
        let theta = 2.0;
        eccentric.sense_orbit(n, theta);
        let t = eccentric.orbit.terms().unwrap();
        assert_eq!(t.rate_radps(), n);
        assert_eq!(t.accel_radps2(), orbit.true_anomaly_accel_radps2(theta));
        assert_eq!(
            t.gravity_gradient_per_s2(),
            orbit.gravity_gradient_per_s2(theta)
        );
        assert!(t.accel_radps2() != 0.0);
    }

    #[test]
    fn refused_orbit_terms_drop_the_estimate_as_a_refused_drive() {
        let cfg = estimator::Config::<f64>::paper();
        // On an eccentric orbit (a circular one's θ̇ is the monitor's to refuse).
        let orbit = Orbit::elliptic(7_078_000.0, 0.1);
        let mut e = Estimation::new(&cfg, &orbit, None, &monitor()).unwrap();
        let c = Commanded {
            length_m: 100.0,
            rate_mps: 2.0,
            accel_mps2: 0.0,
            mu3: 0.01,
        };
        e.end_step(c);
        let x = sample(1.06e-3, 100.0, None);
        let (verdict, event) = e.step(0, Some(&x), Some(-0.5));
        assert!(matches!(verdict, Estimated::Usable(..)));
        assert_eq!(event, None);
        // An orbit rate the drive does not admit: the estimate is lost, the next α restarts it.
        let (_, event) = e.step(1, Some(&sample(0.5, 100.0, None)), None);
        assert_eq!(event, Some(EventKind::EstimateLost));
        assert!(e.estimate().is_none());
    }

    #[test]
    fn the_drive_is_the_last_command_or_the_measured_mean_rate() {
        let cfg = estimator::Config::<f64>::paper();
        let e = Estimation::new(&cfg, &Orbit::circular(7_078_000.0), None, &monitor()).unwrap();
        let orbit = OrbitTerms::circular(1.06e-3).unwrap();
        let c = Commanded {
            length_m: 100.0,
            rate_mps: 2.0,
            accel_mps2: 0.1,
            mu3: 0.01,
        };
        let d = e.drive(&c, orbit, 0, None, 0.0);
        assert_eq!(
            (d.length_m, d.rate_mps, d.accel_mps2, d.mu3),
            (100.0, 2.0, 0.1, 0.01)
        );
        // The encoder's mean rate over the period is the drive's rate at mid-period.
        let d = e.drive(&c, orbit, 0, Some(2.2), 0.0);
        assert_eq!(d.rate_mps + 0.5 * d.accel_mps2 * 1.0, 2.2);
        // The k-th period of a gap starts k periods of the command further on.
        assert_eq!(e.drive(&c, orbit, 3, None, 0.0).length_m, 106.0);
    }
}
