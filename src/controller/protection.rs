//! Tension- and drive-aware protection (docs/equations.md §14): the command is
//! bounded by what the tether carries and by what a lagging drive will actually do.
//!
//! **The tension bound.** Eq. 5a with the reel's acceleration l̈ split out,
//!
//! ```text
//!   T = m_r (−l̈ + G),   G = μ2 l [(θ̇ + α̇)² + (μ/R³)(3 cos²α − 1)] − μ1 l̇²/l   (β = 0),
//! ```
//!
//! says the reel moves the tension at once only through l̈: the *free tension* m_r G (the
//! tension at l̈ = 0) changes with the state, slowly. So the protection estimates the free
//! tension T₀ and bounds the drive's acceleration to keep T_min ≤ T₀ − m_r l̈ ≤ T_max:
//!
//! ```text
//!   (T₀ − T_max)/m_r ≤ l̈ ≤ (T₀ − T_min)/m_r.
//! ```
//!
//! T₀ is estimated by a complementary filter: its fast part is Eq. 5a's model at the law's
//! state (θ̇, α, α̇, l; cos 2α and μ/R³ from the law: n² on a circular orbit, the orbit
//! source's μ/R³ = θ̇²/(1 + e cos θ) on an eccentric one, docs/equations.md §16.7), its slow
//! part the load cell's correction, the residual T_meas + m_r l̈_now − m_r G_model (l̈_now: the
//! drive's acceleration when the tension was measured) low-passed over `tension_filter_s` from
//! 0. The model follows G without lag; the load cell removes what the model misses slowly (a
//! mass error, an unmodelled drag: not an error with the orbit's period, hence μ/R³ in the
//! model) and its noise enters only through the slow correction: σ √(Δt/(2τ_f)), 1.2 mN for a
//! load cell of σ = 0.1 N and τ_f = 3600 s (a quarter hour's mean, 600 s, left 2.9 mN and let
//! the tether go slack in 3 runs of 4 in the early deployment; 3600 s: 28 runs of 28 taut,
//! the least tension 0.11 mN). While the law does not run (coast, safe hold) the estimate is
//! the load cell's own, T_meas + m_r l̈_now.
//! Without a tension sample (`Input::tension_n` None, or implausible) there is no
//! tension bound at that step: the command is today's envelope.
//!
//! The bound acts on the acceleration, so its words differ from the issue's ("below a minimum
//! tension, pay-out slows and wind-in stops"): below T_min it *slows a pay-out* (l̈ < 0 raises
//! T at once) and *does not brake a wind-in* (braking a wind-in, l̈ > 0, lowers T at once: the
//! O-4 slack); if the deficit persists it speeds a wind-in up, which raises T as long as the
//! tether is taut, the only state the rigid Eq. 5a describes and the one the bound keeps.
//! Stopping a wind-in is the lever of a *slack* flexible tether (do not reel in slack line);
//! a taut one is kept taut by the opposite. Above T_max the reverse: a wind-in slows, a pay-out
//! is not braked. The envelope's acceleration limit wins over the bound, and the length limits
//! win over both.
//!
//! The margin T_min cannot exceed the free tension the reel has to work with: at rest the
//! tension *is* the free tension, and a bound above it winds the tether in for as long as it
//! lasts (a fixed 2 mN at l ≈ 5 m wound the tether in against the law for 1 600 s). On a short
//! tether the margin is therefore a quarter of the vertical tether's gravity-gradient tension,
//! [`MARGIN_OF_GRAVITY_GRADIENT`] × 3 m_r n² l: half the free tension of the deployment's
//! reference state (α_r = −45°: 1.5 m_r n² l), so the bound never holds the law's reference
//! back. Past l ≈ 24 m (paper masses) T_min itself applies.
//!
//! **The drive.** A drive with a first-order lag τ runs at v with dv/dt = (u − v)/τ. Under a
//! command held for a period (h = Δt/τ): v_end = u + (v₀ − u)e^{−h}, its acceleration at the
//! end of the period is (u − v_end)/τ, and a step Δu of the next command adds Δu/τ to it at
//! once. The protection keeps v (the model, or the encoder's measured rate over the period,
//! v̄ = u + (v₀ − u)(1 − e^{−h})/h, turned into v_end) and bounds the *drive's* peak
//! acceleration, l̈_now + Δu/τ, not the command's slope. With τ = 0 the drive follows the
//! command and l̈ is the commanded acceleration (Eq. 30, as in the paper's Fig. 4).
//!
//! Over a whole stop the lagging drive covers ∫v = ∫u + τ(v₀ − v_end): τ v₀ more than the
//! commands. The envelope's length limits therefore measure their room from the length less
//! τ|v| in the direction of motion ([`Bounds::overrun_out_m`], [`Bounds::overrun_in_m`]), and
//! the discrete braking staircase is then exact for the drive: the room shrinks by u Δt per
//! period, as the staircase assumes.

use crate::config::{ProtectionConfig, MAX_PLAUSIBLE_TENSION_N};
use crate::envelope::Bounds;
use crate::mass::MassModel;
use crate::real::Real;

/// A measured reel rate beyond this many times the envelope's rate limit is not used.
const PLAUSIBLE_RATE_FACTOR: f64 = 2.0;

/// The state of Eq. 5a's free tension the model needs, at the law's step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FreeTensionModel<T> {
    /// l, m.
    pub(crate) length_m: T,
    /// n (θ̇), rad/s.
    pub(crate) orbit_rate_radps: T,
    /// μ/R³, 1/s²: n² on a circular orbit, θ̇²/(1 + e cos θ) on an eccentric one (from the
    /// law's [`crate::law::OrbitForcing`], docs/equations.md §16.3).
    pub(crate) gravity_gradient_per_s2: T,
    /// α̇ the law flies on, rad/s.
    pub(crate) alpha_rate_radps: T,
    /// cos 2α (the law's).
    pub(crate) cos_two_alpha: T,
}

impl<T: Real> FreeTensionModel<T> {
    /// The state the law solved for, from its input and solution ([`FreeTensionModel::at`]).
    #[cfg(test)]
    pub(crate) fn of(x: &crate::law::LawInput<T>, s: &crate::law::LawOutput<T>) -> Self {
        Self::at(
            x.length_m,
            x.orbit_rate_radps,
            x.orbit.as_ref(),
            x.alpha_rate_radps,
            s.cos_two_alpha,
        )
    }

    /// The state the law solved for: length `length_m` (m), orbit rate n = `orbit_rate_radps`,
    /// the law's orbit forcing `orbit` (`None` on a circular orbit), α̇ = `alpha_rate_radps`
    /// and the law's `cos_two_alpha`. μ/R³ is the law's: n² on a circular orbit (θ̇² would be
    /// wrong by the factor 1 + e cos θ on an eccentric one, ±30 % at e = 0.3).
    pub(crate) fn at(
        length_m: T,
        orbit_rate_radps: T,
        orbit: Option<&crate::law::OrbitForcing<T>>,
        alpha_rate_radps: T,
        cos_two_alpha: T,
    ) -> Self {
        let n = orbit_rate_radps;
        Self {
            length_m,
            orbit_rate_radps: n,
            gravity_gradient_per_s2: match orbit {
                // The law's 1.5 μ/R³.
                Some(o) => o.gradient_per_s2 * T::from_f64(2.0 / 3.0),
                None => n * n,
            },
            alpha_rate_radps,
            cos_two_alpha,
        }
    }
}

/// The drive model's constants for a lag τ > 0.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Lag<T> {
    /// τ, s.
    lag_s: T,
    /// 1/τ, 1/s.
    inv_lag_per_s: T,
    /// e^{−Δt/τ}: what is left of a rate gap after one period.
    decay: T,
    /// h/(e^h − 1), h = Δt/τ: v_end − u = (v̄ − u) × this (v̄ the mean over the period).
    mean_to_end: T,
    /// Its reciprocal, (e^h − 1)/h: v̄ − u = (v_end − u) × this.
    end_to_mean: T,
    /// h = Δt/τ.
    periods_per_lag: T,
    /// (1 − e^{−h})/h: the mean acceleration of a staircase whose peaks are 1.
    ramp_fraction: T,
}

/// The protection's state: the drive model and the tension estimate.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Protection<T> {
    cfg: ProtectionConfig<T>,
    /// The drive's lag constants (None: τ = 0, the drive follows the command).
    lag: Option<Lag<T>>,
    /// Largest accepted |measured reel rate|, m/s.
    max_plausible_rate_mps: T,
    masses: MassModel<T>,
    /// m_r and 1/m_r at the last law step (constant for a massless tether), kg and 1/kg.
    radial_kg: T,
    inv_radial_per_kg: T,
    /// The weight of a new residual in the correction: 1 − e^{−Δt/τ_f}.
    filter_gain: T,
    /// The drive's rate when the last sample was taken, m/s.
    drive_rate_mps: T,
    /// The drive's acceleration then, m/s² (with τ = 0: the last commanded acceleration).
    drive_accel_mps2: T,
    /// The load cell's correction of the model, N: the residual T_meas + m_r l̈_now − m_r G,
    /// low-passed over τ_f from 0 (the model trusted until the load cell says otherwise).
    correction_n: T,
    /// This step's load-cell sample, until [`Protection::bounds`] uses it.
    tension_sample_n: Option<T>,
    /// The model's free tension at the last law step, N (for the steps on which the law did
    /// not run: coast and safe hold).
    last_model_n: Option<T>,
    /// The least tension kept at the last law step, N: T_min, or less on a short tether
    /// ([`MARGIN_OF_GRAVITY_GRADIENT`]).
    min_tension_n: T,
}

/// On a short tether the least tension kept is at most this share of the vertical tether's
/// gravity-gradient tension 3 m_r n² l: half of what the deployment's reference state (α_r =
/// −45°, free tension 1.5 m_r n² l) has, so that the bound never holds the reel against the law
/// at the reference (a fixed T_min above 1.5 m_r n² l winds a short tether in for ever:
/// docs/equations.md §14).
pub const MARGIN_OF_GRAVITY_GRADIENT: f64 = 0.25;

impl<T: Real> Protection<T> {
    /// The protection of a validated configuration, the drive running at `initial_rate_mps`.
    pub(crate) fn new(
        cfg: ProtectionConfig<T>,
        masses: MassModel<T>,
        period_s: T,
        max_rate_mps: T,
        initial_rate_mps: T,
    ) -> Self {
        // In T (no f64 exponentials on the target: libm's exp and expm1 in f64 were 5 KB of
        // the flight firmware's flash). (e^{−h}, 1 − e^{−h}), the second without cancellation.
        let tau = cfg.drive_lag_s;
        let lag = (tau > T::ZERO).then(|| {
            let h = period_s / tau;
            let (decay, complement) = (-h).exp_and_complement();
            Lag {
                lag_s: tau,
                inv_lag_per_s: T::ONE / tau,
                decay,
                mean_to_end: h * decay / complement,
                end_to_mean: complement / (h * decay),
                periods_per_lag: h,
                ramp_fraction: complement / h,
            }
        });
        let filter_gain = (-period_s / cfg.tension_filter_s).exp_and_complement().1;
        let radial = masses.coefficients(T::ZERO).radial_kg;
        Self {
            cfg,
            lag,
            max_plausible_rate_mps: max_rate_mps * T::from_f64(PLAUSIBLE_RATE_FACTOR),
            masses,
            radial_kg: radial,
            inv_radial_per_kg: T::ONE / radial,
            filter_gain,
            drive_rate_mps: initial_rate_mps,
            drive_accel_mps2: T::ZERO,
            correction_n: T::ZERO,
            tension_sample_n: None,
            last_model_n: None,
            min_tension_n: cfg.min_tension_n,
        }
    }

    /// Start of a step in which time moved: the drive ran at `command_mps` (whose commanded
    /// acceleration was `accel_cmd_mps2`) for `elapsed_ticks` periods; `measured_rate_mps` is
    /// the encoder's mean rate over the last period and `tension_n` the load cell's sample, if
    /// any (kept for this step's [`Protection::bounds`]).
    // Out of line, as `bounds`.
    #[inline(never)]
    pub(crate) fn advance(
        &mut self,
        command_mps: T,
        accel_cmd_mps2: T,
        elapsed_ticks: u32,
        measured_rate_mps: Option<T>,
        tension_n: Option<T>,
    ) {
        self.tension_sample_n = tension_n;
        if elapsed_ticks == 0 {
            return;
        }
        let Some(lag) = self.lag else {
            // The drive follows the command; its acceleration is the commanded one (Eq. 30).
            self.drive_rate_mps = command_mps;
            self.drive_accel_mps2 = accel_cmd_mps2;
            return;
        };
        let measured =
            measured_rate_mps.filter(|v| v.is_finite() && v.abs() <= self.max_plausible_rate_mps);
        let gap_mps = match measured {
            // One period at `command_mps`: the mean rate over it tells the rate at its end,
            // once the count's rounding is taken out (a 4 096-count drum of r = 0.1 m reads
            // the rate in steps of 0.15 mm/s; taken as it is, that jitter made the drive's
            // acceleration swing by ~1e-4 m/s², the free tension by ~m_r × that ≈ 10 mN against
            // a 2 mN margin: every run of the Monte Carlo campaign went slack; with it, 995 of
            // 1 000 pass).
            Some(v) if elapsed_ticks == 1 => {
                let model_gap = (self.drive_rate_mps - command_mps) * lag.decay;
                let model_mean = command_mps + model_gap * lag.end_to_mean;
                let excess = v - model_mean;
                let resolution = self.cfg.rate_resolution_mps;
                let seen = if excess > resolution {
                    excess - resolution
                } else if excess < -resolution {
                    excess + resolution
                } else {
                    T::ZERO
                };
                (model_mean + seen - command_mps) * lag.mean_to_end
            }
            _ => {
                let decay = if elapsed_ticks == 1 {
                    lag.decay
                } else {
                    (-T::from_u32(elapsed_ticks) * lag.periods_per_lag).exp()
                };
                (self.drive_rate_mps - command_mps) * decay
            }
        };
        self.drive_rate_mps = command_mps + gap_mps;
        self.drive_accel_mps2 = -gap_mps * lag.inv_lag_per_s;
    }

    /// The bounds of this step, once per step (the load cell's sample of [`Protection::advance`]
    /// is used once). `model` is the law's state (None when the law did not run: the last
    /// model value stands in).
    // Out of line: an unprotected step (the flight configuration) then only tests the Option
    // and keeps the envelope's bounds constant, which holds the outer step inside its ceiling
    // (scripts/bench-target).
    #[inline(never)]
    pub(crate) fn bounds(
        &mut self,
        model: Option<&FreeTensionModel<T>>,
        previous_mps: T,
        dt_s: T,
    ) -> Bounds<T> {
        let v = self.drive_rate_mps;
        let (overrun_out_m, overrun_in_m) = match self.lag {
            Some(lag) if v > T::ZERO => (lag.lag_s * v, T::ZERO),
            Some(lag) => (T::ZERO, -lag.lag_s * v),
            None => (T::ZERO, T::ZERO),
        };
        let mut b = Bounds {
            overrun_out_m,
            overrun_in_m,
            braking_fraction: self.lag.map_or(T::ONE, |lag| lag.ramp_fraction),
            ..Bounds::none()
        };
        if let Some(m) = model {
            self.last_model_n = Some(self.model_free_tension_n(m));
            let gradient_l = m.gravity_gradient_per_s2 * m.length_m;
            let short = T::from_f64(3.0 * MARGIN_OF_GRAVITY_GRADIENT) * self.radial_kg * gradient_l;
            self.min_tension_n = self.cfg.min_tension_n.min(short);
        }
        let tension_n = self.tension_sample_n.take();
        let Some(free_n) = self.free_tension_n(tension_n, model.is_some()) else {
            return b;
        };
        let a_hi = (free_n - self.min_tension_n) * self.inv_radial_per_kg;
        let a_lo = (free_n - self.cfg.max_tension_n) * self.inv_radial_per_kg;
        // The change of command that keeps the drive's acceleration in [a_lo, a_hi].
        let (du_lo, du_hi) = match self.lag {
            Some(lag) => {
                let now = self.drive_accel_mps2;
                ((a_lo - now) * lag.lag_s, (a_hi - now) * lag.lag_s)
            }
            None => (a_lo * dt_s, a_hi * dt_s),
        };
        let (lo, hi) = (previous_mps + du_lo, previous_mps + du_hi);
        b.tension_rate_mps = Some((lo, hi));
        b.tension_accel_mps2 = Some((a_lo, a_hi));
        b
    }

    /// Eq. 5a's free tension m_r G of the model at the law's state, N.
    fn model_free_tension_n(&mut self, m: &FreeTensionModel<T>) -> T {
        let l = m.length_m;
        let spin = m.orbit_rate_radps + m.alpha_rate_radps;
        // (μ/R³)(3 cos²α − 1), 3 cos²α − 1 = ½ + (3/2) cos 2α.
        let gradient =
            m.gravity_gradient_per_s2 * (T::from_f64(0.5) + T::from_f64(1.5) * m.cos_two_alpha);
        let field = spin * spin + gradient;
        if self.masses.tether_density_kg_per_m == T::ZERO {
            // μ1 = 0, μ2 = 1.
            self.radial_kg * l * field
        } else {
            let c = self.masses.coefficients(l);
            let v = self.drive_rate_mps;
            self.radial_kg = c.radial_kg;
            self.inv_radial_per_kg = T::ONE / c.radial_kg;
            c.radial_kg * (c.mu2 * l * field - c.mu1 * v * v / l)
        }
    }

    /// The free-tension estimate of this step, if the load cell gave a plausible sample now
    /// (N): the model corrected by the load cell's mean residual. With a stale model (the law
    /// did not run: coast, safe hold) the load cell's own measure of it, T_meas + m_r l̈_now:
    /// the last model no longer describes the state, and a stale estimate below T_min wound
    /// the reel in at a constant acceleration for as long as the hold lasted
    /// (docs/equations.md §16.7: at e = 0.3 from the 2 km keep to docking). The correction is
    /// not updated then.
    fn free_tension_n(&mut self, tension_n: Option<T>, fresh_model: bool) -> Option<T> {
        let model_n = self.last_model_n?;
        let plausible = T::from_f64(MAX_PLAUSIBLE_TENSION_N);
        let t = tension_n.filter(|t| t.is_finite() && t.abs() <= plausible)?;
        // The tension at zero drive acceleration, as measured.
        let measured_n = t + self.radial_kg * self.drive_accel_mps2;
        if !fresh_model {
            return Some(measured_n);
        }
        let residual = measured_n - model_n;
        self.correction_n = self.correction_n + self.filter_gain * (residual - self.correction_n);
        Some(model_n + self.correction_n)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    const N: f64 = 1.0602e-3;

    fn cfg(lag_s: f64) -> ProtectionConfig<f64> {
        ProtectionConfig {
            drive_lag_s: lag_s,
            ..ProtectionConfig::default_for_period()
        }
    }

    fn protection(lag_s: f64) -> Protection<f64> {
        Protection::new(cfg(lag_s), MassModel::paper(), 1.0, 10.0, 0.0)
    }

    impl Protection<f64> {
        /// This step's load-cell sample, as `advance` would keep it.
        fn sample(&mut self, t: f64) -> &mut Self {
            self.tension_sample_n = Some(t);
            self
        }
        fn sample_none(&mut self) -> &mut Self {
            self.tension_sample_n = None;
            self
        }
    }

    /// A state whose free tension is `radial × l × field`: α = 0, α̇ = 0 (3n² l m_r).
    fn vertical(length_m: f64) -> FreeTensionModel<f64> {
        FreeTensionModel {
            length_m,
            orbit_rate_radps: N,
            gravity_gradient_per_s2: N * N,
            alpha_rate_radps: 0.0,
            cos_two_alpha: 1.0,
        }
    }

    #[test]
    fn the_free_tension_model_is_eq_5a_at_zero_acceleration() {
        let mut p = protection(0.0);
        let m_r = MassModel::<f64>::paper().coefficients(0.0).radial_kg;
        let b = p.sample(0.0).bounds(Some(&vertical(1000.0)), 0.0, 1.0);
        // 3 n² l m_r: 0.334 N at 1 km. With T_meas = 0 the load cell's first sample moves the
        // estimate by the filter's gain k = 1 − e^{−Δt/τ_f} toward 0.
        let expect = 3.0 * N * N * 1000.0 * m_r;
        assert!((p.last_model_n.unwrap() - expect).abs() < 1e-12);
        let k = 1.0 - (-1.0 / 3600.0_f64).exp();
        let (_, a_hi) = b.tension_accel_mps2.unwrap();
        assert!(
            (a_hi - (expect * (1.0 - k) - 2e-3) / m_r).abs() < 1e-12,
            "{a_hi}"
        );
    }

    /// On an eccentric orbit the model's gravity gradient is the law's μ/R³ (θ̇²/(1 + e cos θ)),
    /// not θ̇²: the free tension is Eq. 5a evaluated directly, μ/R³ from the orbit's radius,
    /// around the orbit at e = 0.3 (with θ̇² it erred by up to 15 % of the tension at 20 km).
    #[test]
    fn on_an_eccentric_orbit_the_free_tension_is_eq_5a_with_mu_over_r_cubed() {
        use crate::law::{solve, Blend, Gains, LawInput};
        use crate::orbit::Orbit;
        use crate::schedule::{LibratingReference, RefAngle, Reference};
        let orbit = Orbit::<f64>::elliptic(10.0e6, 0.3);
        let librating = LibratingReference::new(&orbit).unwrap();
        let mut p = protection(0.0);
        let m_r = p.radial_kg;
        let (l, alpha, alpha_rate) = (20_000.0, 0.3_f64, 2.0e-4);
        let mut worst_wrong: f64 = 0.0;
        for theta in [0.0, 1.0, 2.0, core::f64::consts::PI, 4.0, 5.5] {
            let base = Reference {
                angle: RefAngle {
                    angle_rad: 0.2,
                    slope_rad_per_m: 0.0,
                    curvature_rad_per_m2: 0.0,
                },
                time_rate_radps: 0.0,
                slewing: false,
                orbit: None,
            };
            let r = librating.eval(base, theta);
            let rate = orbit.true_anomaly_rate_radps(theta);
            let x = LawInput {
                length_m: l,
                alpha_rad: alpha,
                alpha_rate_radps: alpha_rate,
                orbit_rate_radps: rate,
                orbit: r.orbit,
                ref_angle_rad: r.angle.angle_rad,
                ref_slope_rad_per_m: r.angle.slope_rad_per_m,
                ref_curvature_rad_per_m2: r.angle.curvature_rad_per_m2,
                ref_time_rate_radps: r.time_rate_radps,
                mu3: 0.0,
                mu3_per_m: 0.0,
                blend: Blend::from_weight(0.0),
                decay_rate_per_s: 5e-4,
                initial_rate_mps: 0.0,
                gains: Gains::paper(),
            };
            let s = solve(&x).unwrap();
            let free = p.model_free_tension_n(&FreeTensionModel::of(&x, &s));
            // Eq. 5a at l̈ = 0, β = 0, a massless tether (μ1 = 0, μ2 = 1), R from the orbit.
            let e = orbit.eccentricity;
            let radius = orbit.semi_major_axis_m * (1.0 - e * e) / (1.0 + e * theta.cos());
            let mu_over_r3 = orbit.mu_m3ps2 / radius.powi(3);
            let gradient = 3.0 * alpha.cos().powi(2) - 1.0;
            let expect = m_r * l * ((rate + alpha_rate).powi(2) + mu_over_r3 * gradient);
            assert!(
                (free - expect).abs() < 1e-12 * expect,
                "θ = {theta}: {free} vs {expect}"
            );
            let wrong = m_r * l * ((rate + alpha_rate).powi(2) + rate * rate * gradient);
            worst_wrong = worst_wrong.max((wrong / expect - 1.0).abs());
        }
        assert!(worst_wrong > 0.1, "{worst_wrong}");
    }

    /// In a hold (the law did not run, the model is stale) the free tension is the load
    /// cell's: a model that last said "below T_min" does not keep winding the reel in while
    /// the load cell reads a taut tether (it did, at a_hi < 0, for as long as the hold lasted).
    #[test]
    fn in_a_hold_the_free_tension_is_the_load_cells() {
        let mut p = protection(0.0);
        let m_r = p.radial_kg;
        // The law's last step: a tether swung near the horizontal, free tension negative.
        let swung = FreeTensionModel {
            length_m: 2_000.0,
            orbit_rate_radps: N,
            gravity_gradient_per_s2: N * N,
            alpha_rate_radps: -N,
            cos_two_alpha: -1.0,
        };
        let stale = p.model_free_tension_n(&swung);
        assert!(stale < 0.0, "{stale}");
        let (_, a_hi) = p
            .sample(stale)
            .bounds(Some(&swung), 0.0, 1.0)
            .tension_accel_mps2
            .unwrap();
        assert!(a_hi < 0.0);
        // Then the hold: the load cell reads 0.5 N with the drive at rest, step after step.
        for _ in 0..100 {
            let (_, a_hi) = p
                .sample(0.5)
                .bounds(None, 0.0, 1.0)
                .tension_accel_mps2
                .unwrap();
            assert!(
                (a_hi - (0.5 - p.min_tension_n) / m_r).abs() < 1e-12,
                "{a_hi}"
            );
        }
        // And with the drive accelerating at 1 mm/s² when it read 0.4 N: 0.4 N + m_r × 1e-3.
        p.drive_accel_mps2 = 1e-3;
        let (_, a_hi) = p
            .sample(0.4)
            .bounds(None, 0.0, 1.0)
            .tension_accel_mps2
            .unwrap();
        let free = 0.4 + m_r * 1e-3;
        assert!(
            (a_hi - (free - p.min_tension_n) / m_r).abs() < 1e-12,
            "{a_hi}"
        );
    }

    #[test]
    fn the_bound_keeps_the_tension_between_its_limits() {
        let mut p = protection(0.0);
        let m_r = p.radial_kg;
        let model = vertical(1000.0);
        let free = p.model_free_tension_n(&model);
        // A load cell that agrees with the model: the window is exactly Eq. 5a's.
        let b = p.sample(free).bounds(Some(&model), 1.0, 1.0);
        let (a_lo, a_hi) = b.tension_accel_mps2.unwrap();
        assert!((free - m_r * a_hi - 2e-3).abs() < 1e-12);
        assert!((free - m_r * a_lo - 50.0).abs() < 1e-9);
        let (lo, hi) = b.tension_rate_mps.unwrap();
        assert!((hi - (1.0 + a_hi)).abs() < 1e-12 && lo <= hi);
    }

    #[test]
    fn without_a_tension_sample_there_is_no_tension_bound() {
        let mut p = protection(0.0);
        let b = p.sample_none().bounds(Some(&vertical(100.0)), 1.0, 1.0);
        assert_eq!(b, Bounds::none());
        for bad in [f64::NAN, f64::INFINITY, -2e5] {
            let b = p.sample(bad).bounds(Some(&vertical(100.0)), 1.0, 1.0);
            assert!(b.tension_rate_mps.is_none(), "{bad}");
        }
        // Nor before the law has run once (no model yet).
        let mut p = protection(0.0);
        assert!(p
            .sample(1.0)
            .bounds(None, 1.0, 1.0)
            .tension_rate_mps
            .is_none());
    }

    /// Below T_min the bound lowers the command by the tension deficit over m_r per period
    /// (l̈ < 0 raises T, Eq. 5a), whatever the direction: a pay-out slows, a wind-in is not
    /// braked but sped up; above T_max the reverse.
    #[test]
    fn the_bound_acts_on_the_acceleration_in_either_direction() {
        let mut p = protection(0.0);
        let model = vertical(1000.0);
        let free = p.model_free_tension_n(&model);
        let m_r = p.radial_kg;
        for previous in [0.5, 0.0, -0.5] {
            // 1 N below T_min (the load cell has read so for long): the command must fall by
            // (1 N)/m_r within the period.
            let t = 2e-3 - 1.0;
            p.correction_n = t - free;
            let (_, hi) = p
                .sample(t)
                .bounds(Some(&model), previous, 1.0)
                .tension_rate_mps
                .unwrap();
            assert!(
                (hi - (previous - 1.0 / m_r)).abs() < 1e-9,
                "{previous}: {hi}"
            );
            // 1 N above T_max: it must rise by (1 N)/m_r.
            let mut q = protection(0.0);
            let t = 51.0;
            q.correction_n = t - free;
            let (lo, _) = q
                .sample(t)
                .bounds(Some(&model), previous, 1.0)
                .tension_rate_mps
                .unwrap();
            assert!(
                (lo - (previous + 1.0 / m_r)).abs() < 1e-9,
                "{previous}: {lo}"
            );
        }
        // (The model agreed with nothing here: the load cell's first sample sets the estimate.)
        assert!(free > 0.3);
    }

    /// On a short tether the margin is a quarter of 3 m_r n² l, so the reference state of the
    /// deployment (free tension 1.5 m_r n² l at α = −45°) is never held against the law.
    #[test]
    fn a_short_tether_keeps_a_quarter_of_its_gravity_gradient_tension() {
        let mut p = protection(0.0);
        let m_r = p.radial_kg;
        let at_45 = FreeTensionModel {
            length_m: 5.0,
            orbit_rate_radps: N,
            gravity_gradient_per_s2: N * N,
            alpha_rate_radps: 0.0,
            cos_two_alpha: 0.0,
        };
        let free = p.model_free_tension_n(&at_45);
        assert!((free - 1.5 * m_r * N * N * 5.0).abs() < 1e-15);
        let b = p.sample(free).bounds(Some(&at_45), 0.0, 1.0);
        let margin = 0.75 * m_r * N * N * 5.0;
        assert!((p.min_tension_n - margin).abs() < 1e-15);
        // At rest the reference state may pay out (a_hi > 0): nothing holds it back.
        let (_, a_hi) = b.tension_accel_mps2.unwrap();
        assert!((a_hi - (free - margin) / m_r).abs() < 1e-15 && a_hi > 0.0);
        // A long tether keeps T_min.
        let _ = p.sample(1.0).bounds(Some(&vertical(10_000.0)), 0.0, 1.0);
        assert_eq!(p.min_tension_n, 2e-3);
    }

    /// A lagging drive's peak acceleration, at the start of each period, is what the bound
    /// keeps: following the bound's own staircase, the exact first-order drive never
    /// accelerates beyond a_hi, and settles at a ramp of a_hi (1 − e^{−h})/h on average.
    #[test]
    fn a_lagging_drive_is_bounded_at_its_peak() {
        let lag = 2.0;
        let mut p = protection(lag);
        let model = vertical(1000.0);
        let free = p.model_free_tension_n(&model);
        let a_hi = (free - 2e-3) / p.radial_kg;
        let (mut u, mut v) = (0.0_f64, 0.0_f64);
        let mut peaks = Vec::new();
        let mut u_at_100 = 0.0;
        for k in 0..200 {
            if k == 100 {
                u_at_100 = u;
            }
            let b = p
                .sample(free - p.radial_kg * p.drive_accel_mps2)
                .bounds(Some(&model), u, 1.0);
            u = b.tension_rate_mps.unwrap().1; // the law asks for more: the bound acts
            peaks.push((u - v) / lag); // the drive's acceleration as the command steps
            let v0 = v;
            v = u + (v0 - u) * (-1.0 / lag).exp();
            let mean = u + (v0 - u) * lag * (1.0 - (-1.0 / lag).exp());
            p.advance(u, 0.0, 1, Some(mean), None);
            assert!((p.drive_rate_mps - v).abs() < 1e-12);
        }
        let worst = peaks.iter().fold(0.0_f64, |m, &a| m.max(a));
        assert!(worst <= a_hi * (1.0 + 1e-9), "{worst} > {a_hi}");
        // Steady state: each step adds τ a_hi (1 − e^{−h}), a mean ramp of a_hi (1 − e^{−h})/h.
        let h = 0.5_f64;
        let mean_ramp = u - u_at_100;
        let expect = 100.0 * a_hi * (1.0 - (-h).exp()) / h;
        assert!(
            (mean_ramp - expect).abs() < 1e-6 * expect,
            "{mean_ramp} vs {expect}"
        );
    }

    #[test]
    fn the_drive_model_follows_the_lag_without_a_measurement() {
        let mut p = protection(2.0);
        p.advance(1.0, 0.0, 1, None, None);
        let v1 = 1.0 - (-0.5_f64).exp();
        assert!((p.drive_rate_mps - v1).abs() < 1e-12);
        assert!((p.drive_accel_mps2 - (1.0 - v1) / 2.0).abs() < 1e-12);
        // A gap of 3 ticks decays by e^{−3h}.
        p.advance(1.0, 0.0, 3, None, None);
        assert!((p.drive_rate_mps - (1.0 - (1.0 - v1) * (-1.5_f64).exp())).abs() < 1e-12);
        // An implausible measurement is not used.
        let before = p.drive_rate_mps;
        p.advance(1.0, 0.0, 1, Some(f64::NAN), None);
        assert!((p.drive_rate_mps - (1.0 - (1.0 - before) * (-0.5_f64).exp())).abs() < 1e-12);
        p.advance(1.0, 0.0, 1, Some(1e9), None);
        assert!(p.drive_rate_mps < 1.0);
        // The overrun toward the spool end is τ v.
        let b = p.sample_none().bounds(None, 1.0, 1.0);
        assert!((b.overrun_out_m - 2.0 * p.drive_rate_mps).abs() < 1e-12);
        assert_eq!(b.overrun_in_m, 0.0);
    }

    /// A 4 096-count drum of r = 0.1 m read once a second: the measured mean rate is the
    /// model's to within one count per period (0.15 mm/s), rounded either way. Within the
    /// resolution the model stands (the drive's acceleration, m_r × which is a tension, does
    /// not jitter); a drive that really runs faster than the model is still seen, less the
    /// resolution.
    #[test]
    fn the_encoders_count_rounding_does_not_move_the_drive_model() {
        let resolution = core::f64::consts::TAU * 0.1 / 4096.0;
        let with_resolution = ProtectionConfig {
            rate_resolution_mps: resolution,
            ..cfg(0.5)
        };
        let mut model = protection(0.5);
        let mut counted = Protection::new(with_resolution, MassModel::paper(), 1.0, 10.0, 0.0);
        let mut raw = protection(0.5);
        let mut jitter_counted: f64 = 0.0;
        let mut jitter_raw: f64 = 0.0;
        for k in 0..200 {
            let rounding = if k % 2 == 0 { 0.9 } else { -0.9 } * resolution;
            model.advance(1.0, 0.0, 1, None, None);
            // The model's mean rate over the period, as a perfect encoder would read it.
            let lag = model.lag.unwrap();
            let mean = 1.0 + (model.drive_rate_mps - 1.0) * lag.end_to_mean;
            counted.advance(1.0, 0.0, 1, Some(mean + rounding), None);
            raw.advance(1.0, 0.0, 1, Some(mean + rounding), None);
            jitter_counted =
                jitter_counted.max((counted.drive_accel_mps2 - model.drive_accel_mps2).abs());
            jitter_raw = jitter_raw.max((raw.drive_accel_mps2 - model.drive_accel_mps2).abs());
        }
        assert!(jitter_counted < 1e-12, "{jitter_counted}");
        // Taken as it is, ±0.9 count is an acceleration of 8.6e-5 m/s²: 8.5 mN at m_r ≈ 99 kg,
        // four times the 2 mN margin.
        assert!(jitter_raw > 5e-5, "{jitter_raw}");
        // A drive 1 mm/s faster than the model is seen, less the resolution.
        let lag = counted.lag.unwrap();
        let mean = 1.0 + (counted.drive_rate_mps - 1.0) * lag.decay * lag.end_to_mean;
        counted.advance(1.0, 0.0, 1, Some(mean + 1e-3), None);
        let seen_mean = 1.0 + (counted.drive_rate_mps - 1.0) * lag.end_to_mean;
        assert!(
            (seen_mean - (mean + 1e-3 - resolution)).abs() < 1e-9,
            "{seen_mean} {mean}"
        );
    }

    /// Load-cell noise of σ = 0.1 N: the estimate's scatter is at most σ√(Δt/(2τ_f)) ≈ 1.2 mN
    /// (measured 0.5 mN over 17 000 periods), and the bound on the command moves by 1e-6 m/s²
    /// per period at most (against the 0.1 m/s² of a realistic envelope): no chatter.
    #[test]
    fn load_cell_noise_is_filtered_to_millinewtons() {
        let mut p = protection(0.0);
        let model = vertical(20_000.0);
        let free = p.model_free_tension_n(&model);
        // A reproducible Gaussian-ish noise: the sum of 12 uniforms (xorshift).
        let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut uniform = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut gauss = || (0..12).map(|_| uniform()).sum::<f64>() - 6.0;
        let mut highs = Vec::new();
        for k in 0..20_000 {
            let b = p
                .sample(free + 0.1 * gauss())
                .bounds(Some(&model), 0.0, 1.0);
            if k >= 3_000 {
                highs.push(b.tension_accel_mps2.unwrap().1);
            }
        }
        let m_r = p.radial_kg;
        let est: Vec<f64> = highs.iter().map(|a| a * m_r + 2e-3 - free).collect();
        let mean = est.iter().sum::<f64>() / est.len() as f64;
        let sd = (est.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / est.len() as f64).sqrt();
        let jump = highs
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max);
        std::eprintln!("σ = 0.1 N: estimate mean {mean:.2e} N, sd {sd:.2e} N, largest step of a_hi {jump:.2e} m/s²");
        assert!(sd < 1.5e-3 && mean.abs() < 1.5e-3, "{sd} {mean}");
        assert!(jump < 3e-6, "{jump}");
    }

    /// A protected controller fed every special value in the load cell and the encoder's rate
    /// (and a lagging drive model): every command finite, inside the envelope, each step
    /// within the acceleration limit of the last (the length limits do not bind here).
    #[test]
    fn bad_tension_and_rate_samples_never_make_a_bad_command() {
        use crate::controller::{Config, Controller, Input};
        let specials = [
            None,
            Some(f32::NAN),
            Some(f32::INFINITY),
            Some(f32::NEG_INFINITY),
            Some(f32::MAX),
            Some(-f32::MAX),
            Some(f32::MIN_POSITIVE),
            Some(-1e5),
            Some(0.0),
            Some(3.0),
        ];
        for lag in [0.0, 2.0] {
            let cfg = Config {
                protection: Some(ProtectionConfig {
                    drive_lag_s: lag,
                    ..ProtectionConfig::default_for_period()
                }),
                envelope: crate::envelope::Envelope {
                    max_rate_mps: 10.0,
                    max_accel_mps2: 0.1,
                    ..Config::<f32>::paper().envelope
                },
                ..Config::<f32>::paper()
            };
            let env = cfg.envelope;
            let mut ctl = Controller::new(cfg).unwrap();
            let mut previous = cfg.initial_rate_mps;
            for tick in 0..400u32 {
                let k = tick as usize;
                let out = ctl.step(&Input {
                    tick,
                    length_m: 100.0 + 0.1 * tick as f32,
                    reel_rate_mps: specials[(k * 7 + 3) % specials.len()],
                    tension_n: specials[k % specials.len()],
                    alpha_rad: Some(-0.7),
                    alpha_rate_radps: Some(0.0),
                    orbit_rate_radps: 1.06e-3,
                    true_anomaly_rad: 0.0,
                });
                let y = out.rate_cmd_mps;
                assert!(y.is_finite() && y.abs() <= env.max_rate_mps, "{tick}: {y}");
                assert!(
                    (y - previous).abs() <= env.max_accel_mps2 * 1.0001,
                    "{tick}"
                );
                assert!(out.accel_cmd_mps2.is_finite());
                previous = y;
            }
        }
    }

    #[test]
    fn the_configuration_is_checked() {
        assert!(cfg(0.0).validate(1.0).is_ok());
        let bad = [
            (
                ProtectionConfig {
                    min_tension_n: -1.0,
                    ..cfg(0.0)
                },
                "protection.min_tension_n",
            ),
            (
                ProtectionConfig {
                    max_tension_n: 1e-3,
                    ..cfg(0.0)
                },
                "protection.max_tension_n",
            ),
            (
                ProtectionConfig {
                    max_tension_n: 1e9,
                    ..cfg(0.0)
                },
                "protection.max_tension_n",
            ),
            (
                ProtectionConfig {
                    tension_filter_s: 0.5,
                    ..cfg(0.0)
                },
                "protection.tension_filter_s",
            ),
            (
                ProtectionConfig {
                    tension_filter_s: f64::NAN,
                    ..cfg(0.0)
                },
                "protection.tension_filter_s",
            ),
            (
                ProtectionConfig {
                    drive_lag_s: -1.0,
                    ..cfg(0.0)
                },
                "protection.drive_lag_s",
            ),
            (
                ProtectionConfig {
                    drive_lag_s: f64::INFINITY,
                    ..cfg(0.0)
                },
                "protection.drive_lag_s",
            ),
        ];
        for (c, param) in bad {
            assert_eq!(c.validate(1.0).unwrap_err().param, param, "{c:?}");
        }
    }
}
