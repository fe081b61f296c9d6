//! The reel controller: one fixed-step [`Controller::step`] from sensed length, α, α̇ and orbit
//! rate to a reel-rate command, through the reference schedules (Eqs. 34, 35), the implicit
//! range-rate law (Eq. 27 + 29, SPEC §5), the commanded acceleration (Eq. 30) and the mission
//! sequencer (SPEC §7).
//!
//! ```
//! use tss_reel::controller::{Config, Controller, Input, Phase};
//!
//! // The paper's mission, stage 2 at t = 8 h, 1 s control period.
//! let mut ctl = Controller::new(Config::<f32>::paper()).expect("the paper's numbers are valid");
//! let out = ctl.step(&Input {
//!     tick: 0,
//!     length_m: 1.0,
//!     alpha_rad: -35.0_f32.to_radians(),
//!     alpha_rate_radps: 0.0,
//!     orbit_rate_radps: 1.0602e-3,
//! });
//! assert_eq!(out.phase, Phase::Deploy);
//! assert!((out.rate_cmd_mps - 0.1).abs() < 1e-6); // the blend starts from l̇0 = 0.1 m/s
//! assert!(out.fault.is_none());
//! ```
//!
//! Time is an integer tick count (one tick = one control period); the controller never
//! accumulates time in floating point.

use crate::law::{self, Gains, LawFault, LawInput};
use crate::mass::MassModel;
use crate::real::Real;
use crate::schedule::{BandSchedule, Reference, SlewedSchedule};

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
    /// Tick at which stage 2 starts by itself; `None` waits for [`Controller::start_stage2`].
    pub start_tick: Option<u32>,
}

/// The operating envelope: the command never leaves it, whatever the law asks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Envelope<T> {
    /// Largest reel speed in either direction, m/s.
    pub max_rate_mps: T,
    /// Largest change of reel speed per second, m/s².
    pub max_accel_mps2: T,
    /// Shortest tether (docking), m.
    pub min_length_m: T,
    /// Longest tether (spool capacity), m.
    pub max_length_m: T,
}

/// Everything that defines a controller. Validated once by [`Controller::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config<T> {
    /// Control period, s (one tick).
    pub period_s: T,
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
}

impl<T: Real> Config<T> {
    /// The paper's Section 6 (SPEC §7): 1 s period, ρ = 0, l̇0 = 0.1 m/s, k1 = 0.0057 s⁻¹,
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
        }
    }

    /// Checks every parameter; the first violation is returned.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let z = T::ZERO;
        positive("period_s", self.period_s)?;
        positive("masses.main_initial_kg", self.masses.main_initial_kg)?;
        positive("masses.sub_kg", self.masses.sub_kg)?;
        at_least(
            "masses.tether_density_kg_per_m",
            self.masses.tether_density_kg_per_m,
            z,
        )?;
        positive("gains.k1_per_s", self.gains.k1_per_s)?;
        positive("gains.k2_per_s2", self.gains.k2_per_s2)?;
        at_least("stage1.decay_rate_per_s", self.stage1.decay_rate_per_s, z)?;
        at_least("stage2.decay_rate_per_s", self.stage2.decay_rate_per_s, z)?;
        positive("stage2.slew_rate_radps", self.stage2.slew_rate_radps)?;
        positive("keep_capture_m", self.keep_capture_m)?;
        let env = &self.envelope;
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
        if !(tether_kg < self.masses.main_initial_kg) {
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
            if !(s.low_length_m < s.high_length_m) {
                return Err(ConfigError::new(name, s.low_length_m, Rule::BandInverted));
            }
        }
        // Deployment needs α_r on the deployment side, (−π/2, 0) (Eq. 33, SPEC §9.5);
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

fn finite<T: Real>(param: &'static str, v: T) -> Result<(), ConfigError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ConfigError::new(param, v, Rule::NotFinite))
    }
}

fn positive<T: Real>(param: &'static str, v: T) -> Result<(), ConfigError> {
    finite(param, v)?;
    if v > T::ZERO {
        Ok(())
    } else {
        Err(ConfigError::new(param, v, Rule::NotPositive))
    }
}

fn at_least<T: Real>(param: &'static str, v: T, min: T) -> Result<(), ConfigError> {
    finite(param, v)?;
    if v >= min {
        Ok(())
    } else {
        Err(ConfigError::new(param, v, Rule::Negative))
    }
}

fn above<T: Real>(param: &'static str, v: T, min: T) -> Result<(), ConfigError> {
    finite(param, v)?;
    if v > min {
        Ok(())
    } else {
        Err(ConfigError::new(param, v, Rule::BandInverted))
    }
}

/// What a parameter violates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
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
}

/// A rejected parameter: its name (the field path in [`Config`]), its value and the rule.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct ConfigError {
    /// Field path, e.g. `gains.k1_per_s`.
    pub param: &'static str,
    /// The offending value (widened to f64).
    pub value: f64,
    /// The rule it breaks.
    pub rule: Rule,
}

impl ConfigError {
    fn new<T: Real>(param: &'static str, value: T, rule: Rule) -> Self {
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

/// One control period's sensor sample.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Input<T> {
    /// Tick count of this sample (mission time = tick × period).
    pub tick: u32,
    /// Sensed tether length l, m.
    pub length_m: T,
    /// Sensed in-plane angle α, rad.
    pub alpha_rad: T,
    /// Sensed in-plane rate α̇, rad/s.
    pub alpha_rate_radps: T,
    /// Orbit rate n (θ̇), rad/s.
    pub orbit_rate_radps: T,
}

/// Mission phase.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Phase {
    /// Stage 1, paying out.
    Deploy,
    /// Stage 1, holding at the stage-1 keep length.
    Keep1,
    /// Stage 2, α_r slewing to its plateau.
    Slew,
    /// Stage 2, winding in.
    Retrieve,
    /// Stage 2, holding at the stage-2 keep length.
    Keep2,
}

/// Which sensed value was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Sensor {
    /// Tether length.
    Length,
    /// In-plane angle.
    Alpha,
    /// In-plane rate.
    AlphaRate,
    /// Orbit rate.
    OrbitRate,
    /// The tick count went backwards.
    Tick,
}

/// Why this step's command is a safe action rather than the law's value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Fault {
    /// A sensed value is NaN, infinite or outside its physical range.
    InvalidInput(Sensor),
    /// The law is at one of its singular points.
    Law(LawFault),
}

/// Status bits reported with every command.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Flags(pub u32);

impl Flags {
    /// The law asked for more than the rate limit.
    pub const RATE_SATURATED: u32 = 1 << 0;
    /// The change from the previous command exceeded the acceleration limit.
    pub const ACCEL_SATURATED: u32 = 1 << 1;
    /// A length limit (docking or spool) restricted the command.
    pub const LENGTH_LIMITED: u32 = 1 << 2;
    /// The command is a safe action because of a fault (see [`Output::fault`]).
    pub const SAFE_ACTION: u32 = 1 << 3;
    /// The blend (Eq. 29) restarted at this step (a stage began).
    pub const BLEND_RESTART: u32 = 1 << 4;
    /// α_r is slewing (stage 2 start).
    pub const SLEWING: u32 = 1 << 5;

    /// `true` if every bit of `mask` is set.
    pub fn contains(self, mask: u32) -> bool {
        self.0 & mask == mask
    }
    fn set(&mut self, mask: u32) {
        self.0 |= mask;
    }
}

/// What one step decided, and why: the command and the parts it was made of.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Output<T> {
    /// The tick this output belongs to.
    pub tick: u32,
    /// Mission phase after this step.
    pub phase: Phase,
    /// Reel-rate command l̇_real for the coming period, m/s (inside the envelope, finite).
    pub rate_cmd_mps: T,
    /// Commanded reel acceleration (Eq. 30, sign corrected), m/s².
    pub accel_cmd_mps2: T,
    /// The Eq. 27 value l̇ before the blend, m/s (0 when the law has no value).
    pub law_rate_mps: T,
    /// Blend weight E = e^{−cτ} of Eq. 29.
    pub blend_weight: T,
    /// Reference angle α_r, rad.
    pub alpha_ref_rad: T,
    /// α̇_r = (∂α_r/∂l) l̇_real + ∂α_r/∂t, rad/s.
    pub alpha_ref_rate_radps: T,
    /// δ = α − α_r, rad.
    pub delta_rad: T,
    /// δ̇ = α̇ − α̇_r, rad/s.
    pub delta_rate_radps: T,
    /// Status bits.
    pub flags: Flags,
    /// The fault behind a safe action, if any.
    pub fault: Option<Fault>,
}

/// Physical plausibility limits of the sensed inputs (beyond which a value is a sensor fault).
mod limits {
    /// |α̇| above this is not a tether swing (≈ 60 × orbit rate), rad/s.
    pub const MAX_ALPHA_RATE_RADPS: f64 = 0.06;
    /// Orbit rates outside (0, this] are not an Earth orbit (LEO ≈ 1.2e-3), rad/s.
    pub const MAX_ORBIT_RATE_RADPS: f64 = 1.0e-2;
    /// A sensed length beyond the spool by more than this fraction is a sensor fault.
    pub const LENGTH_MARGIN: f64 = 0.05;
}

/// The reel controller (see the module docs for a complete example).
#[derive(Clone, Debug)]
pub struct Controller<T> {
    cfg: Config<T>,
    stage2: bool,
    stage_start_tick: u32,
    stage_initial_rate_mps: T,
    phase: Phase,
    last_tick: Option<u32>,
    last_rate_cmd_mps: T,
    stage2_requested: bool,
}

impl<T: Real> Controller<T> {
    /// Builds a controller from a validated configuration. A controller that exists is a valid
    /// one.
    pub fn new(cfg: Config<T>) -> Result<Self, ConfigError> {
        cfg.validate()?;
        Ok(Self {
            stage2: false,
            stage_start_tick: 0,
            stage_initial_rate_mps: cfg.initial_rate_mps,
            phase: Phase::Deploy,
            last_tick: None,
            last_rate_cmd_mps: cfg.initial_rate_mps,
            stage2_requested: false,
            cfg,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &Config<T> {
        &self.cfg
    }

    /// The current phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Asks for stage 2 (retrieval) to begin at the next step, whatever the configured start.
    pub fn start_stage2(&mut self) {
        self.stage2_requested = true;
    }

    /// One control period: validates the sample, runs the sequencer, the reference, the law
    /// and the envelope, and returns the command with its explanation.
    pub fn step(&mut self, input: &Input<T>) -> Output<T> {
        let mut flags = Flags::default();
        let tick = input.tick;

        // Sequencer: stage 2 starts at its tick or on command; the blend restarts from the
        // current rate so the command is continuous (SPEC §7).
        let due = self.cfg.stage2.start_tick.is_some_and(|s| tick >= s);
        if !self.stage2 && (due || self.stage2_requested) {
            self.stage2 = true;
            self.stage_start_tick = tick;
            self.stage_initial_rate_mps = self.last_rate_cmd_mps;
            self.phase = Phase::Slew;
            flags.set(Flags::BLEND_RESTART);
        } else if !self.stage2 && self.last_tick.is_none() {
            self.stage_start_tick = tick;
            flags.set(Flags::BLEND_RESTART);
        }

        let tau_s = T::from_u32(tick.saturating_sub(self.stage_start_tick)) * self.cfg.period_s;
        let decay = if self.stage2 {
            self.cfg.stage2.decay_rate_per_s
        } else {
            self.cfg.stage1.decay_rate_per_s
        };
        let blend_weight = (-decay * tau_s).exp();

        let reference = match self.check_input(input) {
            Ok(()) => self.reference(tau_s, input.length_m),
            Err(sensor) => {
                self.last_tick = Some(tick.max(self.last_tick.unwrap_or(0)));
                return self.safe_action(
                    tick,
                    blend_weight,
                    None,
                    flags,
                    Fault::InvalidInput(sensor),
                );
            }
        };
        if reference.slewing {
            flags.set(Flags::SLEWING);
        }
        self.last_tick = Some(tick);

        let mass = self.cfg.masses;
        let l = input.length_m;
        let c = mass.coefficients(l);
        let law_in = LawInput {
            length_m: l,
            alpha_rad: input.alpha_rad,
            alpha_rate_radps: input.alpha_rate_radps,
            orbit_rate_radps: input.orbit_rate_radps,
            ref_angle_rad: reference.angle.angle_rad,
            ref_slope_rad_per_m: reference.angle.slope_rad_per_m,
            ref_curvature_rad_per_m2: reference.angle.curvature_rad_per_m2,
            ref_time_rate_radps: reference.time_rate_radps,
            mu3: c.mu3,
            mu3_per_m: mass.mu3_rate_per_s(l, T::ONE),
            blend_weight,
            decay_rate_per_s: decay,
            initial_rate_mps: self.stage_initial_rate_mps,
            gains: self.cfg.gains,
        };
        let solved =
            law::solve(&law_in).and_then(|s| law::acceleration(&law_in, &s).map(|a| (s, a)));
        let (sol, accel) = match solved {
            Ok(v) => v,
            Err(f) => {
                return self.safe_action(tick, blend_weight, Some(&reference), flags, Fault::Law(f))
            }
        };

        let rate = self.limit(sol.rate_mps, l, &mut flags);
        let limited = rate != sol.rate_mps;
        let accel_cmd = if limited {
            (rate - self.last_rate_cmd_mps) / self.cfg.period_s
        } else {
            accel
        };
        self.last_rate_cmd_mps = rate;
        self.update_phase(l, reference.slewing);
        Output {
            tick,
            phase: self.phase,
            rate_cmd_mps: rate,
            accel_cmd_mps2: accel_cmd,
            law_rate_mps: sol.law_rate_mps,
            blend_weight,
            alpha_ref_rad: reference.angle.angle_rad,
            alpha_ref_rate_radps: sol.ref_rate_radps,
            delta_rad: sol.delta_rad,
            delta_rate_radps: sol.delta_rate_radps,
            flags,
            fault: None,
        }
    }

    fn reference(&self, tau_s: T, length_m: T) -> Reference<T> {
        if self.stage2 {
            SlewedSchedule {
                schedule: self.cfg.stage2.schedule,
                slew_rate_radps: self.cfg.stage2.slew_rate_radps,
            }
            .eval(tau_s, length_m)
        } else {
            Reference {
                angle: self.cfg.stage1.schedule.eval(length_m),
                time_rate_radps: T::ZERO,
                slewing: false,
            }
        }
    }

    fn check_input(&self, x: &Input<T>) -> Result<(), Sensor> {
        let env = &self.cfg.envelope;
        let max_len = env.max_length_m * (T::ONE + T::from_f64(limits::LENGTH_MARGIN));
        let pi = T::from_f64(core::f64::consts::PI);
        if self.last_tick.is_some_and(|t| x.tick < t) {
            return Err(Sensor::Tick);
        }
        if !(x.length_m.is_finite() && x.length_m > T::ZERO && x.length_m <= max_len) {
            return Err(Sensor::Length);
        }
        if !(x.alpha_rad.is_finite() && x.alpha_rad.abs() <= pi) {
            return Err(Sensor::Alpha);
        }
        if !(x.alpha_rate_radps.is_finite()
            && x.alpha_rate_radps.abs() <= T::from_f64(limits::MAX_ALPHA_RATE_RADPS))
        {
            return Err(Sensor::AlphaRate);
        }
        if !(x.orbit_rate_radps.is_finite()
            && x.orbit_rate_radps > T::ZERO
            && x.orbit_rate_radps <= T::from_f64(limits::MAX_ORBIT_RATE_RADPS))
        {
            return Err(Sensor::OrbitRate);
        }
        Ok(())
    }

    /// Rate limit, then the hard length limits (which win), then the acceleration limit
    /// unless a length limit had to act.
    fn limit(&self, rate: T, length_m: T, flags: &mut Flags) -> T {
        let env = &self.cfg.envelope;
        let dt = self.cfg.period_s;
        let mut y = rate;
        if y.abs() > env.max_rate_mps {
            flags.set(Flags::RATE_SATURATED);
            y = y.clamp_to(-env.max_rate_mps, env.max_rate_mps);
        }
        let step = env.max_accel_mps2 * dt;
        let prev = self.last_rate_cmd_mps;
        if (y - prev).abs() > step {
            flags.set(Flags::ACCEL_SATURATED);
            y = y.clamp_to(prev - step, prev + step);
        }
        let up = (env.max_length_m - length_m) / dt;
        let down = (env.min_length_m - length_m) / dt;
        if y > up || y < down {
            flags.set(Flags::LENGTH_LIMITED);
            y = y.clamp_to(down.min(up), up.max(down));
        }
        y
    }

    /// The documented safe action: the previous command ramped toward zero at the
    /// acceleration limit (and inside the length limits as far as they are known).
    fn safe_action(
        &mut self,
        tick: u32,
        blend_weight: T,
        reference: Option<&Reference<T>>,
        mut flags: Flags,
        fault: Fault,
    ) -> Output<T> {
        flags.set(Flags::SAFE_ACTION);
        let step = self.cfg.envelope.max_accel_mps2 * self.cfg.period_s;
        let prev = self.last_rate_cmd_mps;
        let rate = if prev.abs() <= step {
            T::ZERO
        } else if prev > T::ZERO {
            prev - step
        } else {
            prev + step
        };
        self.last_rate_cmd_mps = rate;
        Output {
            tick,
            phase: self.phase,
            rate_cmd_mps: rate,
            accel_cmd_mps2: (rate - prev) / self.cfg.period_s,
            law_rate_mps: T::ZERO,
            blend_weight,
            alpha_ref_rad: reference.map_or(T::ZERO, |r| r.angle.angle_rad),
            alpha_ref_rate_radps: T::ZERO,
            delta_rad: T::ZERO,
            delta_rate_radps: T::ZERO,
            flags,
            fault: Some(fault),
        }
    }

    fn update_phase(&mut self, length_m: T, slewing: bool) {
        let capture = self.cfg.keep_capture_m;
        self.phase = match self.phase {
            Phase::Deploy if length_m >= self.cfg.stage1.schedule.high_length_m - capture => {
                Phase::Keep1
            }
            Phase::Slew if !slewing => Phase::Retrieve,
            Phase::Retrieve if length_m <= self.cfg.stage2.schedule.low_length_m + capture => {
                Phase::Keep2
            }
            p => p,
        };
    }
}
