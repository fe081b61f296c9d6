//! Controller parameters and their validation.
//!
//! Every parameter is checked once, when the controller is built ([`Config::validate`], called
//! by [`crate::controller::Controller::new`]): a controller that exists is a valid one. Errors
//! are typed and name the parameter (its path in [`Config`]) and the value.

use crate::envelope::Envelope;
use crate::estimator;
use crate::law::Gains;
use crate::mass::MassModel;
use crate::orbit::Orbit;
use crate::real::Real;
use crate::schedule::BandSchedule;

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
    /// Persistence and rate of bad samples (FDIR): a leaky counter gains this many for every
    /// unusable sample and loses one for every usable one, and the controller goes to safe
    /// hold when it exceeds `coast_ticks × good_samples_per_bad`. So `coast_ticks + 1` bad
    /// samples in a row still make a safe hold, and so does a sensor that, sustained,
    /// delivers fewer than `good_samples_per_bad` good samples per bad one (an intermittent
    /// sensor, whose single good samples would otherwise reset the count for ever).
    pub good_samples_per_bad: u32,
    /// Deceleration of the safe-hold ramp to zero, m/s² (used when below the envelope's
    /// acceleration limit). The reel is rate-commanded and the tether carries the ramp:
    /// stopping a wind-in (l̈ > 0) lowers the tension by about m_r·l̈ (Eq. 5a), so the ramp is
    /// kept gentle whatever the nominal envelope.
    pub safe_hold_decel_mps2: T,
}

impl<T: Real> MonitorConfig<T> {
    /// Defaults for a 1 s control period: coast 30 s, recover after 10 good samples, 20 m
    /// length jumps (an 11.8 m/s rate step through a 1 s reel lag is about 12 m), 0.1 rad angle
    /// jumps (the paper's |α̇| stays below 1e-3 rad/s), stuck after 20 identical readings
    /// spanning 1 mrad of implied motion, |α̇| ≤ 0.06 rad/s (≈ 60 n), 1e-5 ≤ n ≤ 0.01 rad/s
    /// (orbit periods from 10 minutes to a week; LEO is ≈ 1.1e-3); a sensor that delivers,
    /// sustained, more than one bad sample in five (4 good per bad) is declared failed; the
    /// safe hold ramps at 0.01 m/s² (≈ 1 N on the paper's ≈ 99 kg sub-satellite, where the
    /// paper's 15 m/s² envelope would change the tension by hundreds of newtons in one tick).
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
            good_samples_per_bad: 4,
            safe_hold_decel_mps2: T::from_f64(0.01),
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
        positive(
            "monitor.good_samples_per_bad",
            T::from_u32(self.good_samples_per_bad),
        )?;
        if self
            .coast_ticks
            .checked_mul(self.good_samples_per_bad)
            .is_none()
        {
            return Err(ConfigError::new(
                "monitor.good_samples_per_bad",
                T::from_u32(self.good_samples_per_bad),
                Rule::TooLarge,
            ));
        }
        positive("monitor.safe_hold_decel_mps2", self.safe_hold_decel_mps2)?;
        above(
            "monitor.max_orbit_rate_radps",
            self.max_orbit_rate_radps,
            self.min_orbit_rate_radps,
        )
    }
}

/// Stage 1 (Eq. 34): deploy, then keep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stage1Config<T> {
    /// The Eq. 34 reference schedule; its `high_length_m` is the keep length.
    pub schedule: BandSchedule<T>,
    /// c of Eq. 29 in stage 1, 1/s.
    pub decay_rate_per_s: T,
}

/// Stage 2 (slew, then Eq. 35): retrieve, then keep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stage2Config<T> {
    /// The Eq. 35 reference schedule; its `low_length_m` is the keep length.
    pub schedule: BandSchedule<T>,
    /// Slew rate of α_r from 0 to the plateau at the stage start, rad/s.
    pub slew_rate_radps: T,
    /// c of Eq. 29 in stage 2, 1/s.
    pub decay_rate_per_s: T,
    /// Mission time at which stage 2 starts by itself, in ticks since the first step (the
    /// tick count itself when it starts at 0; a tick counter may start anywhere and wrap);
    /// `None` waits for [`Controller::start_stage2`](crate::controller::Controller::start_stage2).
    pub start_tick: Option<u32>,
}

/// Everything that defines a controller. Validated once by [`Controller::new`](crate::controller::Controller::new).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config<T> {
    /// Control period, s (one tick).
    pub period_s: T,
    /// The orbit of the centre of mass, for the onboard existence check (Eqs. 9, 13).
    pub orbit: Orbit<T>,
    /// Masses (for μ3 of Eq. 27).
    pub masses: MassModel<T>,
    /// k1, k2 of Eq. 27.
    pub gains: Gains<T>,
    /// l̇0 of stage 1: the reel's rate at release, m/s (Eq. 29).
    pub initial_rate_mps: T,
    /// Stage 1.
    pub stage1: Stage1Config<T>,
    /// Stage 2.
    pub stage2: Stage2Config<T>,
    /// A keep phase is entered when l comes within this distance of its keep length, m.
    pub keep_capture_m: T,
    /// Rate, acceleration and length limits.
    pub envelope: Envelope<T>,
    /// Sensor checks and fault timing.
    pub monitor: MonitorConfig<T>,
    /// Tension- and drive-aware protection (docs/equations.md §14); `None`: the paper's
    /// controller, bounded by the envelope alone.
    pub protection: Option<ProtectionConfig<T>>,
    /// Where the law's α and α̇ come from.
    pub rate_source: RateSource<T>,
    /// The tension loop between the law and the envelope (docs/equations.md §17); `None`: the
    /// paper's controller, which does not read the load cell for the law.
    pub tension_loop: Option<TensionLoopConfig<T>>,
}

/// The tension loop's parameters (docs/equations.md §17, `Config::tension_loop`): the admittance
/// term that damps the tether's longitudinal mode, the tension window that shapes the law's
/// command, the attitude's share of authority and the load cell's failure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TensionLoopConfig<T> {
    /// EA, the tether's axial stiffness as the loop is told it, N (the gain schedule (17.5);
    /// known to ±50 %, §17.3).
    pub axial_stiffness_n: T,
    /// ζ_d, the damping ratio the admittance term gives the tether's bounce (17.4), in (0, 2].
    pub damping_ratio: T,
    /// τ_w, the washout's time constant, s: slower than the bounce, faster than the law
    /// (17.3; at least the period).
    pub washout_s: T,
    /// T_lo, the least mean tension the window keeps when it limits a braking (17.8), N (≥ 0).
    pub min_tension_n: T,
    /// T_hi, the most mean tension the window allows when it limits a wind-in's start (17.8), N:
    /// below the drum motor's torque limit at the tether.
    pub max_tension_n: T,
    /// κ, the elastic overshoot allowance of the window (17.8), ≥ 1.
    pub overshoot: T,
    /// The window on either side without a load cell (before its first sample, and once it is
    /// lost), m/s² (> 0; §17.6).
    pub fallback_accel_mps2: T,
    /// Periods without a load-cell sample after which the load cell is lost (§17.6; ≥ 1).
    pub load_cell_timeout_ticks: u32,
    /// |δ| from which the attitude takes authority from the tension window, rad (§17.5; > 0).
    pub yield_from_rad: T,
    /// |δ| from which the law flies unshaped (envelope only), rad (> `yield_from_rad`).
    pub yield_full_rad: T,
}

impl<T: Real> TensionLoopConfig<T> {
    /// The loop for the 0.5 mm Dyneema of `scenarios/paper-elastic.toml` (EA = 10 kN) on the
    /// paper's masses (docs/equations.md §17): ζ_d = 0.6, τ_w = 100 s, the mean tension kept in
    /// [0.1 N, 18 N] (the drum's motor holds 20 N at the tether) with κ = 1.5, a fallback of
    /// 0.1 m/s² without the load cell (a realistic reel's acceleration limit,
    /// `scenarios/paper-reel-limits.toml`), the load cell lost after 5 periods without a sample,
    /// the attitude's share from |δ| = 0.5 rad to 1.0 rad.
    pub fn dyneema_half_mm() -> Self {
        Self {
            axial_stiffness_n: T::from_f64(10_000.0),
            damping_ratio: T::from_f64(0.6),
            washout_s: T::from_f64(100.0),
            min_tension_n: T::from_f64(0.1),
            max_tension_n: T::from_f64(18.0),
            overshoot: T::from_f64(1.5),
            fallback_accel_mps2: T::from_f64(0.1),
            load_cell_timeout_ticks: 5,
            yield_from_rad: T::from_f64(0.5),
            yield_full_rad: T::from_f64(1.0),
        }
    }

    /// Checks the parameters against the control period `period_s`.
    pub fn validate(&self, period_s: T) -> Result<(), ConfigError> {
        positive("tension_loop.axial_stiffness_n", self.axial_stiffness_n)?;
        positive("tension_loop.damping_ratio", self.damping_ratio)?;
        if self.damping_ratio > T::from_f64(2.0) {
            return Err(ConfigError::new(
                "tension_loop.damping_ratio",
                self.damping_ratio,
                Rule::OutOfRange,
            ));
        }
        positive("tension_loop.washout_s", self.washout_s)?;
        if self.washout_s < period_s {
            return Err(ConfigError::new(
                "tension_loop.washout_s",
                self.washout_s,
                Rule::BelowMinimum,
            ));
        }
        at_least("tension_loop.min_tension_n", self.min_tension_n, T::ZERO)?;
        above(
            "tension_loop.max_tension_n",
            self.max_tension_n,
            self.min_tension_n,
        )?;
        if self.max_tension_n > T::from_f64(MAX_PLAUSIBLE_TENSION_N) {
            return Err(ConfigError::new(
                "tension_loop.max_tension_n",
                self.max_tension_n,
                Rule::TooLarge,
            ));
        }
        finite("tension_loop.overshoot", self.overshoot)?;
        if self.overshoot < T::ONE {
            return Err(ConfigError::new(
                "tension_loop.overshoot",
                self.overshoot,
                Rule::BelowMinimum,
            ));
        }
        positive("tension_loop.fallback_accel_mps2", self.fallback_accel_mps2)?;
        positive(
            "tension_loop.load_cell_timeout_ticks",
            T::from_u32(self.load_cell_timeout_ticks),
        )?;
        positive("tension_loop.yield_from_rad", self.yield_from_rad)?;
        above(
            "tension_loop.yield_full_rad",
            self.yield_full_rad,
            self.yield_from_rad,
        )
    }
}

/// Where the law's α and α̇ come from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RateSource<T> {
    /// The sensed α and α̇ ([`Input::alpha_rate_radps`](crate::monitor::Input::alpha_rate_radps)):
    /// the paper's assumption of a measured α̇, kept for Table 1 and for comparison. A sample
    /// without α or α̇ is a bad sample.
    Sensor,
    /// The onboard estimator ([`crate::estimator`]) on the sensed α alone: what flies, since
    /// no flight sensor measures α̇.
    Estimator(estimator::Config<T>),
}

impl<T: Real> Config<T> {
    /// The paper's Section 6 (docs/equations.md §7): 1 s period, ρ = 0, l̇0 = 0.1 m/s, k1 = 0.0057 s⁻¹,
    /// k2 = 9.8696e-6 s⁻², c = 1e-3 s⁻¹ then 5e-4 s⁻¹, slew 6.2932e-4 rad/s, stage 2 at
    /// t = 8 h.
    ///
    /// The envelope (15 m/s, 15 m/s², 0.5 m to 40 km) is wide enough never to act in the
    /// paper's mission, which had no reel limits: its law peaks at 13.1 m/s and steps the rate
    /// by 11.8 m/s in one second when the stage-2 slew hands over to Eq. 35 (α̇_r drops from
    /// the slew rate to 0). A real reel needs a tighter envelope; see
    /// `scenarios/paper-reel-limits.toml`.
    pub fn paper() -> Self {
        Self {
            period_s: T::ONE,
            orbit: Orbit::circular(T::from_f64(7_078_000.0)),
            masses: MassModel::paper(),
            gains: Gains::paper(),
            initial_rate_mps: T::from_f64(0.1),
            stage1: Stage1Config {
                schedule: BandSchedule::paper_stage1(),
                decay_rate_per_s: T::from_f64(1e-3),
            },
            stage2: Stage2Config {
                schedule: BandSchedule::paper_stage2(),
                slew_rate_radps: T::from_f64(6.2932e-4),
                decay_rate_per_s: T::from_f64(5e-4),
                start_tick: Some(8 * 3600),
            },
            keep_capture_m: T::ONE,
            envelope: Envelope {
                max_rate_mps: T::from_f64(15.0),
                max_accel_mps2: T::from_f64(15.0),
                min_length_m: T::from_f64(0.5),
                max_length_m: T::from_f64(40_000.0),
            },
            monitor: MonitorConfig::default_for_period(),
            protection: None,
            rate_source: RateSource::Sensor,
            tension_loop: None,
        }
    }

    /// The paper's mission ([`Config::paper`]) as it flies: on the onboard estimator's α̂ and α̇̂
    /// from the swing sensor's α alone ([`RateSource::Estimator`] with
    /// [`estimator::Config::paper`]: σ_α = 1e-4 rad at 1 s), since no flight sensor measures α̇,
    /// and with the tension loop that holds a real tether taut
    /// ([`TensionLoopConfig::dyneema_half_mm`], docs/equations.md §17). The flight firmware's
    /// configuration.
    pub fn flight() -> Self {
        Self {
            rate_source: RateSource::Estimator(estimator::Config::paper()),
            tension_loop: Some(TensionLoopConfig::dyneema_half_mm()),
            ..Self::paper()
        }
    }

    /// Checks every parameter; the first violation is returned.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let z = T::ZERO;
        positive("period_s", self.period_s)?;
        if self.period_s < T::from_f64(MIN_PERIOD_S) {
            return Err(ConfigError::new(
                "period_s",
                self.period_s,
                Rule::BelowMinimum,
            ));
        }
        positive("orbit.semi_major_axis_m", self.orbit.semi_major_axis_m)?;
        positive("orbit.mu_m3ps2", self.orbit.mu_m3ps2)?;
        // Equilibria exist over the whole orbit only for e < 0.75 (Eq. 13, Theorem 1).
        let e = self.orbit.eccentricity;
        at_least("orbit.eccentricity", e, T::ZERO)?;
        if e >= T::from_f64(0.75) {
            return Err(ConfigError::new(
                "orbit.eccentricity",
                e,
                Rule::NoEquilibrium,
            ));
        }
        positive("masses.main_initial_kg", self.masses.main_initial_kg)?;
        positive("masses.sub_kg", self.masses.sub_kg)?;
        at_least(
            "masses.tether_density_kg_per_m",
            self.masses.tether_density_kg_per_m,
            z,
        )?;
        positive("gains.k1_per_s", self.gains.k1_per_s)?;
        positive("gains.k2_per_s2", self.gains.k2_per_s2)?;
        // The discrete loop must represent Eq. 28: its fastest closed-loop pole, at the control
        // period, within MAX_POLE_PERIOD_PRODUCT.
        let pole_step = fastest_eq28_pole_per_s(self.gains.k1_per_s, self.gains.k2_per_s2)
            * self.period_s.to_f64();
        if pole_step > MAX_POLE_PERIOD_PRODUCT {
            // Real roots: k1 sets the fast pole; complex ones: k2 (|s| = √k2).
            let (k1, k2) = (self.gains.k1_per_s, self.gains.k2_per_s2);
            let err = if k1.to_f64() * k1.to_f64() >= 4.0 * k2.to_f64() {
                ConfigError::new("gains.k1_per_s", k1, Rule::TooFastForPeriod)
            } else {
                ConfigError::new("gains.k2_per_s2", k2, Rule::TooFastForPeriod)
            };
            return Err(err);
        }
        at_least("stage1.decay_rate_per_s", self.stage1.decay_rate_per_s, z)?;
        at_least("stage2.decay_rate_per_s", self.stage2.decay_rate_per_s, z)?;
        for (param, c) in [
            ("stage1.decay_rate_per_s", self.stage1.decay_rate_per_s),
            ("stage2.decay_rate_per_s", self.stage2.decay_rate_per_s),
        ] {
            if c.to_f64() * self.period_s.to_f64() > MAX_POLE_PERIOD_PRODUCT {
                return Err(ConfigError::new(param, c, Rule::TooFastForPeriod));
            }
        }
        positive("stage2.slew_rate_radps", self.stage2.slew_rate_radps)?;
        if let RateSource::Estimator(est) = &self.rate_source {
            validate_estimator(est, self.period_s)?;
        }
        positive("keep_capture_m", self.keep_capture_m)?;
        let env = &self.envelope;
        self.monitor.validate()?;
        if let Some(p) = &self.protection {
            p.validate(self.period_s)?;
        }
        if let Some(t) = &self.tension_loop {
            t.validate(self.period_s)?;
        }
        positive("envelope.max_rate_mps", env.max_rate_mps)?;
        positive("envelope.max_accel_mps2", env.max_accel_mps2)?;
        positive("envelope.min_length_m", env.min_length_m)?;
        above("envelope.max_length_m", env.max_length_m, env.min_length_m)?;
        finite("initial_rate_mps", self.initial_rate_mps)?;
        if self.initial_rate_mps.abs() > env.max_rate_mps {
            return Err(ConfigError::new(
                "initial_rate_mps",
                self.initial_rate_mps,
                Rule::OutsideEnvelope,
            ));
        }
        // The whole tether must weigh less than the main satellite that carries it.
        let tether_kg = self.masses.tether_density_kg_per_m * env.max_length_m;
        if tether_kg >= self.masses.main_initial_kg {
            return Err(ConfigError::new(
                "masses.tether_density_kg_per_m",
                self.masses.tether_density_kg_per_m,
                Rule::TetherHeavierThanSatellite,
            ));
        }
        for (name, s) in [
            ("stage1.schedule", &self.stage1.schedule),
            ("stage2.schedule", &self.stage2.schedule),
        ] {
            for v in [
                s.low_length_m,
                s.low_angle_rad,
                s.low_slope_rad_per_m,
                s.high_length_m,
                s.high_angle_rad,
                s.high_slope_rad_per_m,
            ] {
                finite(name, v)?;
            }
            if s.low_length_m >= s.high_length_m {
                return Err(ConfigError::new(name, s.low_length_m, Rule::BandInverted));
            }
        }
        // Deployment needs α_r on the deployment side, (−π/2, 0) (Eq. 33, docs/equations.md §9.5);
        // retrieval on the retrieval side, (0, π/2).
        let half_pi = T::from_f64(core::f64::consts::FRAC_PI_2);
        let deploy = self.stage1.schedule.low_angle_rad;
        if !(deploy < z && deploy > -half_pi) {
            return Err(ConfigError::new(
                "stage1.schedule.low_angle_rad",
                deploy,
                Rule::WrongQuadrant,
            ));
        }
        let retrieve = self.stage2.schedule.high_angle_rad;
        if !(retrieve > z && retrieve < half_pi) {
            return Err(ConfigError::new(
                "stage2.schedule.high_angle_rad",
                retrieve,
                Rule::WrongQuadrant,
            ));
        }
        let keep1 = self.stage1.schedule.high_length_m;
        let keep2 = self.stage2.schedule.low_length_m;
        for (name, v) in [
            ("stage1.schedule.high_length_m", keep1),
            ("stage2.schedule.low_length_m", keep2),
        ] {
            if !(v > env.min_length_m && v < env.max_length_m) {
                return Err(ConfigError::new(name, v, Rule::OutsideEnvelope));
            }
        }
        Ok(())
    }
}

/// Shortest control period, s (1 kHz). The law's Eq. 27 and blend are written for a period
/// far below its time constants (see [`MAX_POLE_PERIOD_PRODUCT`]), so there is no lower limit
/// from the law; this one keeps the u32 tick count from wrapping in less than 49 days (the
/// controller handles a wrap, see [`crate::controller`]) and the step a small share of the
/// period.
pub const MIN_PERIOD_S: f64 = 1e-3;

/// Largest |s|·Δt of a rate the controller must represent at its period Δt: the fastest Eq. 28
/// closed-loop pole (the roots of s² + k1 s + k2) and each blend decay rate c (Eq. 29). At
/// 0.1 the period is a tenth of the fastest time constant (the usual rule for running a
/// continuous design in discrete time); the paper's gains give 0.003 at 1 s.
pub const MAX_POLE_PERIOD_PRODUCT: f64 = 0.1;

/// The largest |s| of the roots of s² + k1 s + k2 = 0 (Eq. 28's characteristic polynomial), 1/s:
/// (k1 + √(k1² − 4k2))/2 when the roots are real, √k2 when they are complex.
pub fn fastest_eq28_pole_per_s<T: Real>(k1_per_s: T, k2_per_s2: T) -> f64 {
    let (k1, k2) = (k1_per_s.to_f64(), k2_per_s2.to_f64());
    let disc = k1 * k1 - 4.0 * k2;
    if disc >= 0.0 {
        (k1 + libm::sqrt(disc)) / 2.0
    } else {
        libm::sqrt(k2)
    }
}

/// The estimator's parameters, its errors mapped to their path in [`Config`]
/// (`rate_source.estimator.alpha_noise_rad`); its period must be the controller's.
fn validate_estimator<T: Real>(est: &estimator::Config<T>, period_s: T) -> Result<(), ConfigError> {
    est.validate().map_err(estimator_error)?;
    if est.period_s != period_s {
        return Err(ConfigError::new(
            "rate_source.estimator.period_s",
            est.period_s,
            Rule::NotThePeriod,
        ));
    }
    Ok(())
}

/// An estimator parameter's error as the controller's: named by its path in [`Config`].
pub(crate) fn estimator_error(e: estimator::ConfigError) -> ConfigError {
    ConfigError {
        param: estimator_path(e.param),
        value: e.value,
        rule: if e.value.is_finite() {
            Rule::OutOfRange
        } else {
            Rule::NotFinite
        },
    }
}

/// The path in [`Config`] of an estimator parameter named by [`estimator::ConfigError`].
fn estimator_path(param: &'static str) -> &'static str {
    match param {
        "period_s" => "rate_source.estimator.period_s",
        "alpha_noise_rad" => "rate_source.estimator.alpha_noise_rad",
        "alpha_quantum_rad" => "rate_source.estimator.alpha_quantum_rad",
        "accel_noise_density" => "rate_source.estimator.accel_noise_density",
        "disturbance_drift_density" => "rate_source.estimator.disturbance_drift_density",
        "initial_rate_std_radps" => "rate_source.estimator.initial_rate_std_radps",
        "initial_disturbance_std_radps2" => "rate_source.estimator.initial_disturbance_std_radps2",
        "gate_nis" => "rate_source.estimator.gate_nis",
        "max_rejections" => "rate_source.estimator.max_rejections",
        _ => "rate_source.estimator",
    }
}

/// The protection's parameters (`Config::protection`; `None` there: the paper's controller,
/// no protection).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProtectionConfig<T> {
    /// T_min, the least tension the command keeps at the reel, N (≥ 0).
    pub min_tension_n: T,
    /// T_max, the most tension the command allows at the reel, N (> T_min).
    pub max_tension_n: T,
    /// τ_f, the time constant over which the load cell corrects the free-tension model, s
    /// (at least the control period).
    pub tension_filter_s: T,
    /// τ, the reel drive's first-order lag, s (0: the drive follows the command).
    pub drive_lag_s: T,
    /// The resolution of the encoder's measured mean rate, m/s: one count per period
    /// (2πr/N/Δt). A measured rate within it of the drive model's mean rate is the count's
    /// rounding, not the drive's motion, and does not correct the model; beyond it the model is
    /// corrected by the excess only. 0: every measured rate is taken as it is; a resolution
    /// larger than any rate leaves the drive to the model alone (no upper bound is needed).
    pub rate_resolution_mps: T,
}

impl<T: Real> ProtectionConfig<T> {
    /// Defaults for a real reel: T_min = 2 mN (docs/equations.md §14: 10 mN winds the paper's
    /// release back to docking, 5 mN deploys), T_max = 50 N (4× the mission's nominal peak),
    /// τ_f = 3600 s (a load cell of σ = 0.1 N then corrects the model to 1.2 mN), no drive lag.
    pub fn default_for_period() -> Self {
        Self {
            min_tension_n: T::from_f64(2e-3),
            max_tension_n: T::from_f64(50.0),
            tension_filter_s: T::from_f64(3600.0),
            drive_lag_s: T::ZERO,
            rate_resolution_mps: T::ZERO,
        }
    }

    /// Checks the parameters against the control period `period_s`.
    pub fn validate(&self, period_s: T) -> Result<(), ConfigError> {
        at_least("protection.min_tension_n", self.min_tension_n, T::ZERO)?;
        above(
            "protection.max_tension_n",
            self.max_tension_n,
            self.min_tension_n,
        )?;
        positive("protection.tension_filter_s", self.tension_filter_s)?;
        if self.tension_filter_s < period_s {
            return Err(ConfigError::new(
                "protection.tension_filter_s",
                self.tension_filter_s,
                Rule::BelowMinimum,
            ));
        }
        at_least("protection.drive_lag_s", self.drive_lag_s, T::ZERO)?;
        at_least(
            "protection.rate_resolution_mps",
            self.rate_resolution_mps,
            T::ZERO,
        )?;
        if self.max_tension_n > T::from_f64(MAX_PLAUSIBLE_TENSION_N) {
            return Err(ConfigError::new(
                "protection.max_tension_n",
                self.max_tension_n,
                Rule::TooLarge,
            ));
        }
        Ok(())
    }
}

/// A tension reading beyond ± this is a sensor fault, not a tether (N): it is not used.
pub const MAX_PLAUSIBLE_TENSION_N: f64 = 1e5;

pub(crate) fn finite<T: Real>(param: &'static str, v: T) -> Result<(), ConfigError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ConfigError::new(param, v, Rule::NotFinite))
    }
}

pub(crate) fn positive<T: Real>(param: &'static str, v: T) -> Result<(), ConfigError> {
    finite(param, v)?;
    if v > T::ZERO {
        Ok(())
    } else {
        Err(ConfigError::new(param, v, Rule::NotPositive))
    }
}

pub(crate) fn at_least<T: Real>(param: &'static str, v: T, min: T) -> Result<(), ConfigError> {
    finite(param, v)?;
    if v >= min {
        Ok(())
    } else {
        Err(ConfigError::new(param, v, Rule::Negative))
    }
}

pub(crate) fn above<T: Real>(param: &'static str, v: T, min: T) -> Result<(), ConfigError> {
    finite(param, v)?;
    if v > min {
        Ok(())
    } else {
        Err(ConfigError::new(param, v, Rule::BandInverted))
    }
}

/// What a parameter violates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Rule {
    /// NaN or infinite.
    NotFinite,
    /// Must be > 0.
    NotPositive,
    /// Must be ≥ 0.
    Negative,
    /// A lower bound is not below its upper bound.
    BandInverted,
    /// Outside the configured envelope.
    OutsideEnvelope,
    /// An angle on the wrong side of the vertical for its stage (Eq. 33).
    WrongQuadrant,
    /// ρ × maximum length ≥ m01.
    TetherHeavierThanSatellite,
    /// e ≥ 0.75: no equilibrium exists over the whole orbit (Eq. 13).
    NoEquilibrium,
    /// Below the documented minimum (the control period: [`MIN_PERIOD_S`]).
    BelowMinimum,
    /// A rate too fast for the control period to represent: the fastest Eq. 28 closed-loop
    /// pole or a blend decay rate, times the period, above [`MAX_POLE_PERIOD_PRODUCT`].
    TooFastForPeriod,
    /// Outside the range its module admits (an estimator parameter: see
    /// [`estimator::Config::validate`]).
    OutOfRange,
    /// Not the controller's control period (the estimator's `period_s`).
    NotThePeriod,
    /// So large that a derived count overflows (`monitor.coast_ticks ×
    /// monitor.good_samples_per_bad`).
    TooLarge,
}

/// A rejected parameter: its name (the field path in [`Config`]), its value and the rule.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ConfigError {
    /// Field path, e.g. `gains.k1_per_s`.
    pub param: &'static str,
    /// The offending value (widened to f64).
    pub value: f64,
    /// The rule it breaks.
    pub rule: Rule,
}

impl ConfigError {
    pub(crate) fn new<T: Real>(param: &'static str, value: T, rule: Rule) -> Self {
        Self {
            param,
            value: value.to_f64(),
            rule,
        }
    }
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "invalid parameter {} = {}: {:?}",
            self.param, self.value, self.rule
        )
    }
}
