//! The reel drive's parameters and their validation.
//!
//! As for the outer controller ([`crate::config`]), every parameter is checked once, when the
//! speed loop is built ([`DriveConfig::validate`], called by
//! [`SpeedLoop::new`](super::SpeedLoop::new)): a speed loop that exists is a valid one. Errors
//! are typed and name the parameter (its path in [`DriveConfig`]), its value and the rule.

use core::f32::consts::PI;

/// The longest speed window [`DriveConfig::speed_window_ticks`] may ask for, ticks.
pub const SPEED_WINDOW_CAPACITY: usize = 8;

/// The slowest inner loop allowed, Hz.
pub const MIN_INNER_RATE_HZ: u32 = 100;

/// The longest tick count a threshold of the step's counters may ask for
/// ([`BrakeConfig::engage_ticks`], [`FaultLimits::stall_ticks`]: 2³¹ − 1, 24 days at 1 kHz):
/// a counter below it plus a step's tick gap (below 2³¹) cannot wrap, so the step adds
/// without saturating.
pub const MAX_COUNTED_TICKS: u32 = i32::MAX as u32;

/// Largest encoder counts per drum revolution: below 2²⁴ every count within a revolution is an
/// exact `f32`, so the metres-per-count scale is not the limit of the length's precision.
pub const MAX_COUNTS_PER_DRUM_REV: u32 = 1 << 24;

/// How encoder counts become drum angle and tether length.
///
/// The drum is taken as a single effective radius: the tether pays out from one layer, or from
/// a level-wound drum whose layer-to-layer change of radius is folded into
/// [`drum_radius_m`](Self::drum_radius_m) as its mean. (A layered drum makes the radius a
/// step function of the integer count; that is not modelled yet.)
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// Encoder counts per motor revolution (quadrature: 4 × lines).
    pub counts_per_motor_rev: u32,
    /// Motor revolutions per drum revolution (the gearbox ratio, an integer).
    pub gear_ratio: u32,
    /// Effective drum radius at the tether, m.
    pub drum_radius_m: f32,
    /// Width of the hardware counter, bits (16 for most timer encoder modes, up to 32).
    pub encoder_bits: u32,
}

impl Geometry {
    /// Encoder counts per drum revolution (saturating; validated below 2²⁴).
    pub fn counts_per_drum_rev(&self) -> u32 {
        self.counts_per_motor_rev.saturating_mul(self.gear_ratio)
    }

    /// Tether length per encoder count, m: 2π r / counts per drum revolution.
    pub fn m_per_count(&self) -> f32 {
        2.0 * PI * self.drum_radius_m / self.counts_per_drum_rev() as f32
    }
}

/// The drum as the feed-forward sees it: J ω̇ = τ_motor + T r − b ω − c sgn ω (pay-out positive).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrumModel {
    /// Inertia of drum, gearbox and motor, referred to the drum, kg m².
    pub inertia_kgm2: f32,
    /// Viscous friction b, N m per rad/s of drum rate.
    pub viscous_nm_per_radps: f32,
    /// Coulomb friction c, N m.
    pub coulomb_nm: f32,
    /// Below this |reference rate| the Coulomb feed-forward is proportional to it (no sign
    /// chatter around zero), m/s.
    pub coulomb_band_mps: f32,
}

/// The PI gains, on the drum's surface speed error, giving drum torque.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedGains {
    /// Proportional gain, N m per m/s.
    pub kp_nm_per_mps: f32,
    /// Integral gain, N m per m (per m/s of error and second).
    pub ki_nm_per_m: f32,
}

/// The brake's timing (see [`Brake`](super::Brake)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrakeConfig {
    /// Ticks from the release command to the brake being free (its mechanical delay).
    pub release_ticks: u32,
    /// Ticks at rest (commanded and measured) before the brake engages (at most
    /// [`MAX_COUNTED_TICKS`]).
    pub engage_ticks: u32,
    /// |speed| at or below which the drum counts as at rest, m/s.
    pub rest_speed_mps: f32,
}

/// Thresholds of the drive's faults (see [`DriveFault`](super::DriveFault)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultLimits {
    /// The fastest the drum can physically turn, m/s: a count change faster than this is an
    /// encoder jump.
    pub max_encoder_rate_mps: f32,
    /// Consecutive ticks without an accepted count (jump or missing) that trip the drive.
    pub encoder_trip_ticks: u32,
    /// |duty| at or above which a drum that does not turn is stalled.
    pub stall_duty: f32,
    /// |speed| at or below which a driven drum does not turn, m/s.
    pub stall_speed_mps: f32,
    /// Ticks of stall that trip the drive (at most [`MAX_COUNTED_TICKS`]).
    pub stall_ticks: u32,
    /// Consecutive ticks of duty saturation that raise [`DriveFault::DutySaturated`](super::DriveFault::DutySaturated).
    pub saturation_ticks: u32,
    /// Lowest plausible tension, N (below: slack or a broken tether).
    pub min_tension_n: f32,
    /// Highest plausible tension, N (above: overload).
    pub max_tension_n: f32,
    /// Bandwidth of the observer of the tension the drum's motion implies (the generalised
    /// momentum observer of the drive's cross-checks, see the module docs of
    /// [`SpeedLoop`](super::SpeedLoop)), rad/s; times the tick at most 1/2.
    pub observer_bandwidth_radps: f32,
    /// How far the implied tension may lie from the load cell's reading, or beyond the
    /// plausible range, before the two disagree, N.
    pub tension_mismatch_n: f32,
    /// Ticks a disagreement, or an integral pinned at its clamp, must last before it is a fault
    /// ([`DriveFault::NoResponse`](super::DriveFault::NoResponse),
    /// [`DriveFault::TensionMismatch`](super::DriveFault::TensionMismatch); at most
    /// [`MAX_COUNTED_TICKS`]).
    pub no_response_ticks: u32,
    /// Travel of the drum with the brake engaged that is a slipping brake, m
    /// ([`DriveFault::BrakeSlip`](super::DriveFault::BrakeSlip)).
    pub brake_slip_m: f32,
}

/// Everything that defines a reel drive. Validated once by
/// [`SpeedLoop::new`](super::SpeedLoop::new).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriveConfig {
    /// Inner-loop rate, Hz (one inner tick = 1 / rate).
    pub inner_rate_hz: u32,
    /// Inner ticks per outer (law) period: the time over which a new rate command is reached.
    pub outer_period_ticks: u32,
    /// Encoder and drum geometry.
    pub geometry: Geometry,
    /// Ticks the speed is differenced over: a power of two up to [`SPEED_WINDOW_CAPACITY`].
    pub speed_window_ticks: u32,
    /// The drum's inertia and friction, for the feed-forward.
    pub drum: DrumModel,
    /// PI gains.
    pub gains: SpeedGains,
    /// Drum torque at duty 1, N m (the driver is in torque, i.e. current, mode).
    pub max_torque_nm: f32,
    /// Largest |duty| ever commanded, in (0, 1].
    pub duty_limit: f32,
    /// Largest |reference speed|, m/s: a command beyond it is clamped.
    pub max_speed_mps: f32,
    /// Largest |reference acceleration|, m/s².
    pub max_accel_mps2: f32,
    /// Brake timing.
    pub brake: BrakeConfig,
    /// Fault thresholds.
    pub faults: FaultLimits,
}

impl DriveConfig {
    /// An illustrative reel, not from the paper (which has no reel mechanism): 1 kHz inner loop
    /// under the 1 s law; a 0.1 m drum behind a 10:1 gearbox and a 1024-line encoder (40 960
    /// counts per drum revolution, 15.3 µm per count) in a 16-bit timer counter; J = 0.05
    /// kg m², b = 0.01 N m s/rad, c = 0.2 N m; 5 N m at full duty; 15 m/s and 5 m/s² (the
    /// paper envelope's rate); PI crossing over at ω_c = kp r / J = 30 rad/s with its zero at
    /// ω_c / 4; brake 50 ms to release, engaged after 200 ms at rest (5 mm/s); an encoder
    /// jump is a count faster than 20 m/s (1304 counts a tick), and 10 ticks without an
    /// accepted count trip the drive (11 × 1304 < 2¹⁵, so the 16-bit counter stays
    /// unambiguous); stall: duty ≥ 0.9 below 2 cm/s for 0.5 s; saturation reported after 2 s;
    /// tension plausible in [−5, 200] N; the implied tension observed at 20 rad/s (50 ms), and
    /// a disagreement of 20 N (2 N m at the drum, 40 % of the motor: ten times the feed-forward's
    /// friction error and the inertia's at 5 m/s²) or a pinned integral for 0.25 s a fault; a
    /// slipping brake after 20 mm of travel with the brake engaged (1 304 counts; an engaged
    /// brake allows none).
    pub fn example() -> Self {
        Self {
            inner_rate_hz: 1000,
            outer_period_ticks: 1000,
            geometry: Geometry {
                counts_per_motor_rev: 4096,
                gear_ratio: 10,
                drum_radius_m: 0.1,
                encoder_bits: 16,
            },
            speed_window_ticks: 8,
            drum: DrumModel {
                inertia_kgm2: 0.05,
                viscous_nm_per_radps: 0.01,
                coulomb_nm: 0.2,
                coulomb_band_mps: 0.01,
            },
            gains: SpeedGains {
                kp_nm_per_mps: 15.0,
                ki_nm_per_m: 112.5,
            },
            max_torque_nm: 5.0,
            duty_limit: 1.0,
            max_speed_mps: 15.0,
            max_accel_mps2: 5.0,
            brake: BrakeConfig {
                release_ticks: 50,
                engage_ticks: 200,
                rest_speed_mps: 0.005,
            },
            faults: FaultLimits {
                max_encoder_rate_mps: 20.0,
                encoder_trip_ticks: 10,
                stall_duty: 0.9,
                stall_speed_mps: 0.02,
                stall_ticks: 500,
                saturation_ticks: 2000,
                min_tension_n: -5.0,
                max_tension_n: 200.0,
                observer_bandwidth_radps: 20.0,
                tension_mismatch_n: 10.0,
                no_response_ticks: 100,
                brake_slip_m: 0.02,
            },
        }
    }

    /// The inner tick, s.
    pub fn tick_s(&self) -> f32 {
        1.0 / self.inner_rate_hz as f32
    }

    /// The largest count change per tick the encoder check accepts (the ceiling of
    /// [`FaultLimits::max_encoder_rate_mps`] × tick / m per count).
    pub fn max_counts_per_tick(&self) -> u32 {
        let counts = self.faults.max_encoder_rate_mps * self.tick_s() / self.geometry.m_per_count();
        // Validated finite, positive and below 2³¹; `as` saturates anyway.
        let whole = counts as u32;
        if (whole as f32) < counts {
            whole.saturating_add(1)
        } else {
            whole
        }
    }

    /// Checks every parameter; the first violation is returned.
    pub fn validate(&self) -> Result<(), DriveConfigError> {
        if self.inner_rate_hz < MIN_INNER_RATE_HZ {
            return Err(DriveConfigError::new(
                "inner_rate_hz",
                self.inner_rate_hz,
                DriveRule::BelowMinimum,
            ));
        }
        nonzero("outer_period_ticks", self.outer_period_ticks)?;
        let g = &self.geometry;
        nonzero("geometry.counts_per_motor_rev", g.counts_per_motor_rev)?;
        nonzero("geometry.gear_ratio", g.gear_ratio)?;
        let per_rev = u64::from(g.counts_per_motor_rev) * u64::from(g.gear_ratio);
        if per_rev > u64::from(MAX_COUNTS_PER_DRUM_REV) {
            return Err(DriveConfigError::new(
                "geometry.gear_ratio",
                g.gear_ratio,
                DriveRule::TooManyCounts,
            ));
        }
        positive("geometry.drum_radius_m", g.drum_radius_m)?;
        if !(2..=32).contains(&g.encoder_bits) {
            return Err(DriveConfigError::new(
                "geometry.encoder_bits",
                g.encoder_bits,
                DriveRule::OutOfRange,
            ));
        }
        if !(self.speed_window_ticks.is_power_of_two()
            && self.speed_window_ticks <= SPEED_WINDOW_CAPACITY as u32)
        {
            return Err(DriveConfigError::new(
                "speed_window_ticks",
                self.speed_window_ticks,
                DriveRule::OutOfRange,
            ));
        }
        positive("drum.inertia_kgm2", self.drum.inertia_kgm2)?;
        at_least_zero("drum.viscous_nm_per_radps", self.drum.viscous_nm_per_radps)?;
        at_least_zero("drum.coulomb_nm", self.drum.coulomb_nm)?;
        positive("drum.coulomb_band_mps", self.drum.coulomb_band_mps)?;
        at_least_zero("gains.kp_nm_per_mps", self.gains.kp_nm_per_mps)?;
        at_least_zero("gains.ki_nm_per_m", self.gains.ki_nm_per_m)?;
        positive("max_torque_nm", self.max_torque_nm)?;
        positive("duty_limit", self.duty_limit)?;
        if self.duty_limit > 1.0 {
            return Err(DriveConfigError::new(
                "duty_limit",
                self.duty_limit,
                DriveRule::OutOfRange,
            ));
        }
        positive("max_speed_mps", self.max_speed_mps)?;
        positive("max_accel_mps2", self.max_accel_mps2)?;
        let b = &self.brake;
        positive("brake.rest_speed_mps", b.rest_speed_mps)?;
        counted_ticks("brake.engage_ticks", b.engage_ticks)?;
        let f = &self.faults;
        positive("faults.max_encoder_rate_mps", f.max_encoder_rate_mps)?;
        if f.max_encoder_rate_mps < self.max_speed_mps {
            return Err(DriveConfigError::new(
                "faults.max_encoder_rate_mps",
                f.max_encoder_rate_mps,
                DriveRule::BelowMaxSpeed,
            ));
        }
        nonzero("faults.encoder_trip_ticks", f.encoder_trip_ticks)?;
        // A count change is unambiguous only below half the counter's range: the longest gap
        // the encoder check bridges (trip ticks + 1) at the fastest rate must stay below it.
        let half_range = 1_u64 << (g.encoder_bits - 1);
        let bridged = u64::from(self.max_counts_per_tick()) * (u64::from(f.encoder_trip_ticks) + 1);
        if bridged >= half_range {
            return Err(DriveConfigError::new(
                "faults.encoder_trip_ticks",
                f.encoder_trip_ticks,
                DriveRule::CounterAmbiguous,
            ));
        }
        positive("faults.stall_duty", f.stall_duty)?;
        if f.stall_duty > self.duty_limit {
            return Err(DriveConfigError::new(
                "faults.stall_duty",
                f.stall_duty,
                DriveRule::OutOfRange,
            ));
        }
        positive("faults.stall_speed_mps", f.stall_speed_mps)?;
        counted_ticks("faults.stall_ticks", f.stall_ticks)?;
        nonzero("faults.saturation_ticks", f.saturation_ticks)?;
        finite("faults.min_tension_n", f.min_tension_n)?;
        finite("faults.max_tension_n", f.max_tension_n)?;
        if f.max_tension_n <= f.min_tension_n {
            return Err(DriveConfigError::new(
                "faults.max_tension_n",
                f.max_tension_n,
                DriveRule::BandInverted,
            ));
        }
        positive(
            "faults.observer_bandwidth_radps",
            f.observer_bandwidth_radps,
        )?;
        if f.observer_bandwidth_radps * self.tick_s() > 0.5 {
            return Err(DriveConfigError::new(
                "faults.observer_bandwidth_radps",
                f.observer_bandwidth_radps,
                DriveRule::OutOfRange,
            ));
        }
        positive("faults.tension_mismatch_n", f.tension_mismatch_n)?;
        counted_ticks("faults.no_response_ticks", f.no_response_ticks)?;
        positive("faults.brake_slip_m", f.brake_slip_m)?;
        Ok(())
    }
}

fn finite(param: &'static str, v: f32) -> Result<(), DriveConfigError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(DriveConfigError::new(param, v, DriveRule::NotFinite))
    }
}

fn positive(param: &'static str, v: f32) -> Result<(), DriveConfigError> {
    finite(param, v)?;
    if v > 0.0 {
        Ok(())
    } else {
        Err(DriveConfigError::new(param, v, DriveRule::NotPositive))
    }
}

fn at_least_zero(param: &'static str, v: f32) -> Result<(), DriveConfigError> {
    finite(param, v)?;
    if v >= 0.0 {
        Ok(())
    } else {
        Err(DriveConfigError::new(param, v, DriveRule::Negative))
    }
}

fn counted_ticks(param: &'static str, v: u32) -> Result<(), DriveConfigError> {
    nonzero(param, v)?;
    if v <= MAX_COUNTED_TICKS {
        Ok(())
    } else {
        Err(DriveConfigError::new(param, v, DriveRule::OutOfRange))
    }
}

fn nonzero(param: &'static str, v: u32) -> Result<(), DriveConfigError> {
    if v > 0 {
        Ok(())
    } else {
        Err(DriveConfigError::new(param, v, DriveRule::NotPositive))
    }
}

/// What a drive parameter violates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DriveRule {
    /// NaN or infinite.
    NotFinite,
    /// Must be > 0.
    NotPositive,
    /// Must be ≥ 0.
    Negative,
    /// A lower bound is not below its upper bound.
    BandInverted,
    /// Outside the range its documentation gives.
    OutOfRange,
    /// Below [`MIN_INNER_RATE_HZ`].
    BelowMinimum,
    /// More than [`MAX_COUNTS_PER_DRUM_REV`] counts per drum revolution.
    TooManyCounts,
    /// The encoder's plausible rate is below the reference's largest speed: normal motion
    /// would be a jump.
    BelowMaxSpeed,
    /// The counter wraps within the longest gap the encoder check bridges, so a count change
    /// could not be told from its wrap.
    CounterAmbiguous,
}

/// A rejected drive parameter: its name (the field path in [`DriveConfig`]), its value and the
/// rule.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriveConfigError {
    /// Field path, e.g. `geometry.drum_radius_m`.
    pub param: &'static str,
    /// The offending value (widened to f64).
    pub value: f64,
    /// The rule it breaks.
    pub rule: DriveRule,
}

impl DriveConfigError {
    fn new(param: &'static str, value: impl Into<f64>, rule: DriveRule) -> Self {
        Self {
            param,
            value: value.into(),
            rule,
        }
    }
}

impl core::fmt::Display for DriveConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "invalid reel-drive parameter {} = {}: {:?}",
            self.param, self.value, self.rule
        )
    }
}
