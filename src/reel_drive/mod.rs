//! The reel's inner speed loop: the drum follows the outer law's rate command (issue 19).
//!
//! The outer controller ([`crate::controller`]) commands a reel rate l̇_real and its
//! acceleration (Eq. 30) once a law period (1 s). The reel-mechanism MCU turns that into motor
//! duty at the inner rate (≥ 100 Hz, 1 kHz in [`DriveConfig::example`]), one
//! [`SpeedLoop::step`] per inner tick:
//!
//! 1. **Odometry** ([`encoder`]): the drum's speed and paid-out length from the integer encoder
//!    count (wrap handled, jumps rejected), never from accumulated floats.
//! 2. **Reference**: from the reference at the moment a command arrives, a ramp toward the
//!    commanded rate at the Eq. 30 acceleration the law computed
//!    ([`Output::accel_cmd_mps2`](crate::controller::Output::accel_cmd_mps2)), at least fast
//!    enough to arrive within one law period and at most [`DriveConfig::max_accel_mps2`]; it
//!    stops at the command (never passes it), so the drum never runs ahead of the law.
//! 3. **Brake** ([`Brake`]): engaged at rest and in safe hold; released (with its mechanical
//!    delay) before any motion; engaged again after the commanded and measured speed have been
//!    ~0 for [`BrakeConfig::engage_ticks`].
//! 4. **PI + feed-forward**, on the drum's surface speed, giving drum torque. With pay-out
//!    positive, the drum obeys J ω̇ = τ + T r − b ω − c sgn ω (T the tether tension at the
//!    reel), so the torque that makes it follow v_ref with acceleration a_ref is
//!
//!    ```text
//!    τ = kp e + ∫ki e dt            e = v_ref − v          (PI)
//!      + J a_ref / r                                         (inertia, Eq. 30's acceleration)
//!      − T r                                                 (measured tension)
//!      + b v_ref / r + c sat(v_ref / v_band)                 (viscous + Coulomb friction)
//!    ```
//!
//!    and the duty is τ / τ_max, saturated at ± [`DriveConfig::duty_limit`]. Anti-windup is
//!    **conditional integration**: the integral does not grow while the output is saturated and
//!    the error pushes it further into saturation; it is also bounded to ± τ_max.
//! 5. **Faults** ([`DriveFault`]), reported in every [`DriveOutput`]; the ones that leave the
//!    drum uncontrolled (no encoder, a stalled motor, a failed actuator) trip the drive: motor
//!    off, brake on, until [`SpeedLoop::clear_trip`].
//!
//! Time is the integer inner tick (one tick = 1 / [`DriveConfig::inner_rate_hz`]), as the
//! outer loop's is: every duration is a tick difference.
//!
//! ```
//! use tss_reel::reel_drive::{Brake, DriveConfig, DriveInput, RateCommand, SpeedLoop};
//!
//! let mut drive = SpeedLoop::new(DriveConfig::example()).expect("the example is valid");
//! // The law asks for 0.1 m/s (its first deployment command, Eq. 29).
//! drive.set_command(RateCommand { rate_mps: 0.1, accel_mps2: 0.0, safe_hold: false }, 0);
//! let input = |tick| DriveInput { tick, encoder_count: Some(0), tension_n: Some(20.0) };
//! assert!(matches!(drive.step(&input(0)).brake, Brake::Releasing { .. }));
//! // While the brake lifts, the motor takes over the tension's torque (−T r = −2 N m of 5).
//! assert!((drive.output().duty - (-0.4)).abs() < 1e-6);
//! for tick in 1..=50 {
//!     drive.step(&input(tick));
//! }
//! assert!(matches!(drive.output().brake, Brake::Released { .. }));
//! assert!(drive.output().faults.is_empty());
//! ```

pub mod config;
pub mod encoder;
pub mod hal;
pub mod sim;

pub use config::{
    BrakeConfig, DriveConfig, DriveConfigError, DriveRule, DrumModel, FaultLimits, Geometry,
    SpeedGains,
};
pub use encoder::{CountFault, Odometer};

/// The rate command of one law period, as the inner loop needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RateCommand {
    /// Commanded reel rate l̇_real, m/s (pay-out positive).
    pub rate_mps: f32,
    /// Commanded reel acceleration (Eq. 30), m/s².
    pub accel_mps2: f32,
    /// The outer controller is in safe hold: the brake may engage but not release.
    pub safe_hold: bool,
}

/// One inner tick's sensor readings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriveInput {
    /// Inner tick count of this sample.
    pub tick: u32,
    /// The raw hardware encoder counter (only its low `encoder_bits` are used); `None` if the
    /// read failed.
    pub encoder_count: Option<u32>,
    /// Tether tension at the reel, N; `None` if the read failed.
    pub tension_n: Option<f32>,
}

/// The brake (and motor enable) state machine.
///
/// ```text
///            command moving, not safe hold, encoder read       release_ticks elapsed
///   Engaged ────────────────────────────────────────▶ Releasing ───────────────────▶ Released
///     ▲  ▲ ◀──── command at rest, or safe hold ────────────┘                           │
///     │  └────────── commanded and measured speed ~0 for engage_ticks ─────────────────┘
///     └──── clear_trip ──── Tripped(fault) ◀── encoder lost, stall, actuator (from any) ──
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Brake {
    /// Brake on, motor off (at rest, at start, in safe hold once at rest).
    Engaged,
    /// Brake lifting; the motor holds the tension's torque so the drum does not lurch.
    Releasing {
        /// Ticks until the brake is free.
        ticks_left: u32,
    },
    /// Brake free; the speed loop drives the drum.
    Released {
        /// Consecutive ticks the commanded and measured speed have been ~0.
        rest_ticks: u32,
    },
    /// A fault left the drum uncontrolled: brake on, motor off, until cleared.
    Tripped(DriveFault),
}

impl Brake {
    /// Whether the brake is commanded free (its pin energised).
    pub fn brake_released(self) -> bool {
        matches!(self, Self::Releasing { .. } | Self::Released { .. })
    }

    /// Whether the motor driver is enabled.
    pub fn motor_enabled(self) -> bool {
        self.brake_released()
    }
}

/// A fault of the reel drive.
///
/// How each maps onto the outer controller's fault logic ([`crate::controller::Health`]): see
/// [`DriveFault::outer_reaction`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum DriveFault {
    /// The tick did not advance (repeated or backwards): the step did nothing.
    Tick,
    /// The encoder count moved faster than the drum can turn; the reading was rejected.
    EncoderJump,
    /// No encoder reading this tick (or none for longer than the loop can bridge).
    EncoderMissing,
    /// Large duty, no motion, for `stall_ticks`, the drive not at rest (at rest, the brake
    /// about to engage, a large duty is the motor holding the tension).
    MotorStall,
    /// The duty has been saturated for `saturation_ticks`: the drum cannot follow.
    DutySaturated,
    /// Tension missing, not finite, or outside [min, max] (slack, break, overload).
    TensionOutOfRange,
    /// The rate command was not finite: the drum is brought to rest as in safe hold.
    CommandInvalid,
    /// A pin or the PWM refused a write (reported by the driver, [`hal::HalReelDrive`]).
    Actuator,
}

/// What the outer controller makes of a drive fault (applied by
/// [`Controller::step_with_drive`](crate::controller::Controller::step_with_drive)). Ordered:
/// the strongest reaction of a period's faults wins.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum OuterReaction {
    /// Telemetry only: the drive copes (the fault is the caller's own, and its safe action is
    /// already taken by the drive).
    Report,
    /// The period's reel data (the encoder's length, the drum's motion) cannot be trusted, or
    /// the drum cannot follow the command: the period is a missing sample for the outer
    /// controller, which coasts (`Health::Degraded`, `Fault::Sensor(Sensor::Missing)`) and, if
    /// the fault persists past `coast_ticks` (its leaky counter), goes to `Health::SafeHold`.
    Degrade,
    /// The drive tripped (motor off, brake on): the reel cannot move, so the law's command
    /// means nothing. `Health::SafeHold` at once (its zero command keeps the brake engaged
    /// once the trip is cleared), left only after `recovery_ticks` valid periods in a row
    /// without a trip.
    SafeHold,
}

impl DriveFault {
    /// Every fault, in bit order.
    pub const ALL: [Self; 8] = [
        Self::Tick,
        Self::EncoderJump,
        Self::EncoderMissing,
        Self::MotorStall,
        Self::DutySaturated,
        Self::TensionOutOfRange,
        Self::CommandInvalid,
        Self::Actuator,
    ];

    /// The mapping onto the outer fault logic (docs/hazards.md for the hazards):
    ///
    /// | fault | reaction | why | hazard |
    /// |---|---|---|---|
    /// | `EncoderJump`, `EncoderMissing` | [`OuterReaction::Degrade`] | the length sample comes from this encoder | HZ-1 / HZ-6 |
    /// | `DutySaturated` | [`OuterReaction::Degrade`] | the drum does not follow the command: coast on the last one, safe hold if it lasts | HZ-7 |
    /// | `TensionOutOfRange` | [`OuterReaction::Degrade`] | slack, break or overload: the law's model does not hold | HZ-10 |
    /// | `MotorStall`, `Actuator` | [`OuterReaction::SafeHold`] | the drive tripped: the reel cannot move | HZ-7 |
    /// | `Tick`, `CommandInvalid` | [`OuterReaction::Report`] | the caller's own error; the drive already holds | HZ-12 |
    pub fn outer_reaction(self) -> OuterReaction {
        match self {
            Self::MotorStall | Self::Actuator => OuterReaction::SafeHold,
            Self::EncoderJump
            | Self::EncoderMissing
            | Self::DutySaturated
            | Self::TensionOutOfRange => OuterReaction::Degrade,
            Self::Tick | Self::CommandInvalid => OuterReaction::Report,
        }
    }

    fn bit(self) -> u16 {
        1 << self as u16
    }
}

/// The faults of one tick (a set).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriveFaults(u16);

impl DriveFaults {
    /// No fault.
    pub const NONE: Self = Self(0);

    /// Whether `f` is in the set.
    pub fn contains(self, f: DriveFault) -> bool {
        self.0 & f.bit() != 0
    }

    /// Whether the set is empty.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Adds `f`.
    pub fn insert(&mut self, f: DriveFault) {
        self.0 |= f.bit();
    }

    /// The faults in the set.
    pub fn iter(self) -> impl Iterator<Item = DriveFault> {
        DriveFault::ALL
            .into_iter()
            .filter(move |f| self.contains(*f))
    }

    /// The strongest reaction any fault of the set asks of the outer controller.
    pub fn outer_reaction(self) -> OuterReaction {
        self.iter()
            .map(DriveFault::outer_reaction)
            .max()
            .unwrap_or(OuterReaction::Report)
    }

    /// The set as bits, one per fault in [`DriveFault::ALL`] order (for telemetry).
    pub fn bits(self) -> u16 {
        self.0
    }

    /// The union of two sets (a period's faults are the union of its ticks').
    pub fn union(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }
}

/// What one inner step decided: the reference, the measurements it used, the duty and the
/// brake. (The torque's parts are worked out on demand, [`SpeedLoop::torque_parts`], not every
/// tick.)
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriveOutput {
    /// The inner tick this output belongs to.
    pub tick: u32,
    /// Reference drum speed v_ref, m/s.
    pub ref_rate_mps: f32,
    /// Reference acceleration a_ref (the ramp's slope; 0 once the command is reached), m/s².
    pub ref_accel_mps2: f32,
    /// Measured drum surface speed v, m/s.
    pub speed_mps: f32,
    /// The tension the feed-forward used (the reading, clamped into range, or the last good
    /// one), N.
    pub tension_n: f32,
    /// The drum torque asked for before saturation (PI + feed-forward), N m.
    pub torque_nm: f32,
    /// Motor duty in [−duty_limit, duty_limit] (sign = direction, pay-out positive).
    pub duty: f32,
    /// The duty was saturated this tick.
    pub saturated: bool,
    /// The brake after this step.
    pub brake: Brake,
    /// The faults of this step.
    pub faults: DriveFaults,
}

impl DriveOutput {
    const IDLE: Self = Self {
        tick: 0,
        ref_rate_mps: 0.0,
        ref_accel_mps2: 0.0,
        speed_mps: 0.0,
        tension_n: 0.0,
        torque_nm: 0.0,
        duty: 0.0,
        saturated: false,
        brake: Brake::Engaged,
        faults: DriveFaults::NONE,
    };
}

/// The parts the last step's torque was made of (telemetry: [`SpeedLoop::torque_parts`]).
/// Their sum is [`DriveOutput::torque_nm`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TorqueParts {
    /// v_ref − v, m/s.
    pub error_mps: f32,
    /// Proportional part, N m.
    pub p_nm: f32,
    /// Integral part, N m.
    pub i_nm: f32,
    /// Inertia feed-forward J a_ref / r, N m.
    pub ff_inertia_nm: f32,
    /// Tension feed-forward −T r, N m.
    pub ff_tension_nm: f32,
    /// Friction feed-forward b v_ref / r + c sat(v_ref / v_band), N m.
    pub ff_friction_nm: f32,
}

/// The ramp the reference follows toward the commanded rate.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Ramp {
    /// Reference at `start_tick`, m/s.
    start_mps: f32,
    start_tick: u32,
    /// The commanded rate it stops at, m/s.
    target_mps: f32,
    /// Signed slope toward the target (0 if already there), m/s².
    slope_mps2: f32,
    /// The slope × tick: the reference's change per tick, m/s.
    step_mps: f32,
    /// Ticks from `start_tick` until the target is reached (integer time: the reference is the
    /// target from then on, and never passes it before).
    ramp_ticks: u32,
}

impl Ramp {
    const REST: Self = Self {
        start_mps: 0.0,
        start_tick: 0,
        target_mps: 0.0,
        slope_mps2: 0.0,
        step_mps: 0.0,
        ramp_ticks: 0,
    };
}

/// Constants derived once from the configuration, so that the step has no division.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Derived {
    tick_s: f32,
    outer_period_per_s: f32,
    /// ki × tick: the integral's growth per tick and m/s of error, N m.
    ki_tick: f32,
    /// J / r: inertia feed-forward per m/s².
    inertia_per_radius: f32,
    /// b / r: viscous feed-forward per m/s.
    viscous_per_radius: f32,
    /// c / v_band: Coulomb feed-forward per m/s inside the band.
    coulomb_per_band: f32,
    /// 1 / τ_max: duty per N m.
    per_max_torque: f32,
}

/// The inner speed loop with its brake and fault logic.
#[derive(Clone, Debug)]
pub struct SpeedLoop {
    cfg: DriveConfig,
    derived: Derived,
    odometer: Odometer,
    /// The last command, as received (after sanitising).
    command: RateCommand,
    /// The command asks for motion: |rate| above the brake's rest speed.
    command_moving: bool,
    /// The command lets the brake be free: moving, and not in safe hold (worked out with the
    /// command: one test on the brake's engaged and releasing steps instead of two).
    command_frees_brake: bool,
    /// The faults every step reports until the next command: [`DriveFault::CommandInvalid`]
    /// after a non-finite one, none otherwise.
    command_faults: DriveFaults,
    /// The reference's ramp: with the brake free, from the reference at the command's
    /// arrival; otherwise from rest, its `start_tick` set when the brake is free (the drum was
    /// held until then). Worked out with the command (and again by `clear_trip`), so that the
    /// release's step has no division and sets one field (a second ramp from rest, kept
    /// beside this one and copied in at the release, made that step the mission's worst, 14
    /// instructions above the next one; 7 above it this way, exact, `scripts/bench-target`
    /// with `TSS_BENCH_EXACT=1`; `set_command` works out one ramp instead of two).
    ramp: Ramp,
    integral_nm: f32,
    /// A step has been taken, so the output's `tick` is the last step's tick (kept once,
    /// there: an `Option` of it beside the output cost the step a store, 2 instructions on the
    /// mission's worst path, `scripts/bench-target` with `TSS_BENCH_EXACT=1`).
    stepped: bool,
    stall_ticks: u32,
    /// Ticks of duty saturation left before [`DriveFault::DutySaturated`] is reported (the
    /// configuration's `saturation_ticks` while unsaturated, 0 once reported): counted down,
    /// so that a saturated step does not load the limit (3 instructions less on it than
    /// counting up, saturating, and comparing, exact, `scripts/bench-target` with
    /// `TSS_BENCH_EXACT=1`).
    saturation_left_ticks: u32,
    /// The last step's output. Its `brake` is the brake's state, which the step, `trip` and
    /// `clear_trip` change in place, and its `tension_n` the tension the feed-forward uses
    /// (the last good reading, clamped into range), which `tension` keeps (a copy of each
    /// beside the output cost the step a load and a store, then a store: worst 230 → 226 →
    /// 225, `scripts/bench-target` with `TSS_BENCH_EXACT=1`).
    out: DriveOutput,
}

impl SpeedLoop {
    /// A speed loop at rest, brake engaged, after validating `cfg`.
    pub fn new(cfg: DriveConfig) -> Result<Self, DriveConfigError> {
        cfg.validate()?;
        let r = cfg.geometry.drum_radius_m;
        let derived = Derived {
            tick_s: cfg.tick_s(),
            outer_period_per_s: cfg.inner_rate_hz as f32 / cfg.outer_period_ticks as f32,
            ki_tick: cfg.gains.ki_nm_per_m * cfg.tick_s(),
            inertia_per_radius: cfg.drum.inertia_kgm2 / r,
            viscous_per_radius: cfg.drum.viscous_nm_per_radps / r,
            coulomb_per_band: cfg.drum.coulomb_nm / cfg.drum.coulomb_band_mps,
            per_max_torque: 1.0 / cfg.max_torque_nm,
        };
        Ok(Self {
            cfg,
            derived,
            odometer: Odometer::new(&cfg),
            command: RateCommand {
                rate_mps: 0.0,
                accel_mps2: 0.0,
                safe_hold: false,
            },
            command_moving: false,
            command_frees_brake: false,
            command_faults: DriveFaults::NONE,
            ramp: Ramp::REST,
            integral_nm: 0.0,
            stepped: false,
            stall_ticks: 0,
            saturation_left_ticks: cfg.faults.saturation_ticks,
            out: DriveOutput::IDLE,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &DriveConfig {
        &self.cfg
    }

    /// The last step's output (with the brake's state after a [`trip`](Self::trip) or
    /// [`clear_trip`](Self::clear_trip) since).
    pub fn output(&self) -> &DriveOutput {
        &self.out
    }

    /// The odometer (total count, paid-out length, speed).
    pub fn odometer(&self) -> &Odometer {
        &self.odometer
    }

    /// The brake's state.
    pub fn brake(&self) -> Brake {
        self.out.brake
    }

    /// The parts of the last step's torque ([`DriveOutput::torque_nm`] is their sum): with
    /// the brake free, PI and the three feed-forwards; while it lifts, only the tension's;
    /// otherwise none.
    pub fn torque_parts(&self) -> TorqueParts {
        let o = &self.out;
        match o.brake {
            Brake::Released { .. } => {
                let error_mps = o.ref_rate_mps - o.speed_mps;
                TorqueParts {
                    error_mps,
                    p_nm: self.cfg.gains.kp_nm_per_mps * error_mps,
                    i_nm: self.integral_nm,
                    ff_inertia_nm: self.derived.inertia_per_radius * o.ref_accel_mps2,
                    ff_tension_nm: self.tension_torque_nm(o.tension_n),
                    ff_friction_nm: self.friction_torque_nm(o.ref_rate_mps),
                }
            }
            Brake::Releasing { .. } => TorqueParts {
                ff_tension_nm: self.tension_torque_nm(o.tension_n),
                ..TorqueParts::default()
            },
            Brake::Engaged | Brake::Tripped(_) => TorqueParts::default(),
        }
    }

    /// Takes a new rate command at inner tick `tick` (normally once a law period). The
    /// reference ramps from where it is now toward it (see the module docs). A non-finite rate
    /// or acceleration is [`DriveFault::CommandInvalid`] (returned, and reported by every step
    /// until a finite command arrives): the drum is then brought to rest as in safe hold.
    pub fn set_command(&mut self, cmd: RateCommand, tick: u32) -> Result<(), DriveFault> {
        let valid = cmd.rate_mps.is_finite() && cmd.accel_mps2.is_finite();
        let max = self.cfg.max_speed_mps;
        self.command_faults = DriveFaults::NONE;
        self.command = if valid {
            RateCommand {
                rate_mps: clamp_abs(cmd.rate_mps, max),
                ..cmd
            }
        } else {
            self.command_faults.insert(DriveFault::CommandInvalid);
            RateCommand {
                rate_mps: 0.0,
                accel_mps2: 0.0,
                safe_hold: true,
            }
        };
        self.command_moving = self.command.rate_mps.abs() > self.cfg.brake.rest_speed_mps;
        self.command_frees_brake = self.command_moving && !self.command.safe_hold;
        let from_mps = match self.out.brake {
            Brake::Released { .. } => self.reference_at(tick).0,
            Brake::Engaged | Brake::Releasing { .. } | Brake::Tripped(_) => 0.0,
        };
        self.ramp = self.ramp_toward_command(from_mps, tick);
        if valid {
            Ok(())
        } else {
            Err(DriveFault::CommandInvalid)
        }
    }

    /// Trips the drive for `fault` (motor off, brake on) — for faults found outside the step,
    /// such as a refused actuator write. A drive already tripped keeps its first fault.
    pub fn trip(&mut self, fault: DriveFault) {
        if !matches!(self.out.brake, Brake::Tripped(_)) {
            self.out.brake = Brake::Tripped(fault);
            self.out.duty = 0.0;
            self.integral_nm = 0.0;
        }
    }

    /// Clears a trip: the brake stays engaged and releases again only for a moving command
    /// and a fresh encoder reading, which becomes the counter's new reference
    /// ([`Odometer::resync`]: whatever the drum did while tripped is not counted). Returns the
    /// fault that was cleared.
    pub fn clear_trip(&mut self) -> Option<DriveFault> {
        match self.out.brake {
            Brake::Tripped(f) => {
                self.out.brake = Brake::Engaged;
                self.stall_ticks = 0;
                self.saturation_left_ticks = self.cfg.faults.saturation_ticks;
                self.odometer.resync();
                // The drum was held: the next release starts the ramp from rest.
                self.ramp = self.ramp_toward_command(0.0, 0);
                Some(f)
            }
            _ => None,
        }
    }

    /// One inner tick: odometry, brake, reference, PI + feed-forward, faults. The duty and
    /// brake in the output are what the hardware is to be set to.
    pub fn step(&mut self, input: &DriveInput) -> &DriveOutput {
        let tick = input.tick;
        // Integer time: the tick must advance (wrapping, by less than half the range); the
        // first step's gap is one tick.
        let gap_ticks = if self.stepped {
            tick.wrapping_sub(self.out.tick)
        } else {
            self.stepped = true;
            1
        };
        // (0 and anything beyond half the range in one comparison: 0 − 1 wraps to the top.)
        if gap_ticks.wrapping_sub(1) >= i32::MAX as u32 {
            return self.reject_tick();
        }
        let mut faults = self.command_faults;

        // Odometry: a reading the odometer cannot take is a fault; too long without one trips.
        // After a gap longer than the jump check bridges, the counter's change is ambiguous
        // (it may have wrapped): the reading is not used.
        // (An overrun is told apart once: a gap of one tick is within the bridged ones.)
        let trip_ticks = self.cfg.faults.encoder_trip_ticks;
        let reading = if gap_ticks == 1 {
            input.encoder_count
        } else {
            // The ticks the overrun skipped get their predicted totals.
            self.odometer.skip(gap_ticks.wrapping_sub(1));
            if gap_ticks <= trip_ticks {
                input.encoder_count
            } else {
                None
            }
        };
        let (counted, speed_mps) = self.odometer.update_next(tick, reading);
        if let Err(f) = counted {
            let since_accepted = self.odometer.ticks_since_accepted(tick);
            let (fault, lost) = match f {
                // (A jump is a reading within the gap the check bridges, against an accepted
                // one: only the ticks since that one can have run out. Telling the two apart
                // here, every fault branch of one step 224 → 219, exact, `scripts/bench-target`
                // with `TSS_BENCH_EXACT=1`.)
                CountFault::Jump => (
                    DriveFault::EncoderJump,
                    since_accepted.is_some_and(|t| t > trip_ticks),
                ),
                CountFault::Missing => (
                    DriveFault::EncoderMissing,
                    gap_ticks > trip_ticks || since_accepted.is_some_and(|t| t > trip_ticks),
                ),
            };
            faults.insert(fault);
            if lost {
                self.trip(fault);
            }
        }
        let tension_n = self.tension(input.tension_n, &mut faults);

        self.advance_brake(tick, gap_ticks, speed_mps, counted.is_ok());

        // The torque: PI + feed-forward with the brake free; while it lifts, the motor takes
        // over the tension's torque, nothing else; otherwise the motor is off.
        let limit = self.cfg.duty_limit;
        let per_max_torque = self.derived.per_max_torque;
        let (ref_mps, ref_accel_mps2, torque_nm, (duty, saturated)) = match self.out.brake {
            Brake::Released { rest_ticks } => {
                let (ref_mps, ref_accel_mps2, torque_nm) =
                    self.speed_law(tick, gap_ticks, speed_mps, tension_n);
                let law = (
                    ref_mps,
                    ref_accel_mps2,
                    torque_nm,
                    saturate(torque_nm * per_max_torque, limit),
                );
                if rest_ticks > 0 {
                    // At rest, the brake about to engage: a large duty holding a still drum
                    // is the motor holding the tension, not a stall (and the step counts one
                    // or the other: 12 instructions less on its worst path,
                    // `scripts/bench-target` with `TSS_BENCH_EXACT=1`).
                    self.stall_ticks = 0;
                    law
                } else if counted.is_err() {
                    // No measured motion this tick (its reading rejected or missing, the speed
                    // held): the stall is judged on measured motion, so the tick neither counts
                    // toward a stall nor clears one, as the brake's rest count (and the fault
                    // paths of a jump and of a stall's or rest's count are not paid in one
                    // tick: every fault branch of one step 212 → 208, exact,
                    // `scripts/bench-target` with `TSS_BENCH_EXACT=1`).
                    law
                } else if self.count_stall(gap_ticks, speed_mps, law.3) {
                    faults.insert(DriveFault::MotorStall);
                    (law.0, law.1, 0.0, (0.0, false))
                } else {
                    law
                }
            }
            Brake::Releasing { .. } => {
                self.stall_ticks = 0;
                let torque_nm = self.tension_torque_nm(tension_n);
                (
                    0.0,
                    0.0,
                    torque_nm,
                    saturate(torque_nm * per_max_torque, limit),
                )
            }
            Brake::Engaged => {
                self.stall_ticks = 0;
                self.integral_nm = 0.0;
                (0.0, 0.0, 0.0, (0.0, false))
            }
            Brake::Tripped(f) => {
                faults.insert(f);
                self.stall_ticks = 0;
                self.integral_nm = 0.0;
                (0.0, 0.0, 0.0, (0.0, false))
            }
        };

        // Saturation held too long (reported); the stall is `count_stall`'s.
        let f = &self.cfg.faults;
        if saturated {
            self.saturation_left_ticks = self.saturation_left_ticks.saturating_sub(gap_ticks);
            if self.saturation_left_ticks == 0 {
                faults.insert(DriveFault::DutySaturated);
            }
        } else {
            self.saturation_left_ticks = f.saturation_ticks;
        }

        // (The brake and the tension are in place.)
        let out = &mut self.out;
        out.tick = tick;
        out.ref_rate_mps = ref_mps;
        out.ref_accel_mps2 = ref_accel_mps2;
        out.speed_mps = speed_mps;
        out.torque_nm = torque_nm;
        out.duty = duty;
        out.saturated = saturated;
        out.faults = faults;
        &self.out
    }

    /// A tick that did not advance: nothing is done, the last output stands, with
    /// [`DriveFault::Tick`]. Cold, out of line (as the other rare paths of the step: its
    /// registers are the nominal path's; 7 instructions less a step with the three of them,
    /// `examples/bench_speed_loop.rs`).
    #[cold]
    #[inline(never)]
    fn reject_tick(&mut self) -> &DriveOutput {
        let mut faults = self.command_faults;
        faults.insert(DriveFault::Tick);
        self.out.faults = faults;
        &self.out
    }

    /// Tether paid out since the first encoder reading, m (a function of the integer count).
    pub fn paid_out_m(&self) -> f32 {
        self.odometer.paid_out_m()
    }

    /// The brake free: the reference at `tick`, and PI + feed-forward toward it (see the module
    /// docs), with conditional integration: the integral does not grow in the direction that
    /// held the last tick's duty in saturation. Returns v_ref, a_ref and the torque, N m.
    fn speed_law(
        &mut self,
        tick: u32,
        gap_ticks: u32,
        speed_mps: f32,
        tension_n: f32,
    ) -> (f32, f32, f32) {
        let (ref_mps, ref_accel_mps2) = self.reference_at(tick);
        let error_mps = ref_mps - speed_mps;
        let last = &self.out;
        let winding_up = last.saturated && last.duty * error_mps > 0.0;
        if !winding_up {
            let growth_nm = self.derived.ki_tick * gap_ticks as f32 * error_mps;
            // (Finite: the error and the gains are.)
            self.integral_nm =
                clamp_finite_abs(self.integral_nm + growth_nm, self.cfg.max_torque_nm);
        }
        let torque_nm = self.cfg.gains.kp_nm_per_mps * error_mps
            + self.integral_nm
            + self.derived.inertia_per_radius * ref_accel_mps2
            + self.tension_torque_nm(tension_n)
            + self.friction_torque_nm(ref_mps);
        (ref_mps, ref_accel_mps2, torque_nm)
    }

    /// The stall counter, brake free and not at rest: the ticks the drive has been stalled
    /// (|duty| at or above the stall duty, the drum slower than the stall speed), reset
    /// otherwise; at the stall ticks it trips the drive (returns true: the step's torque is
    /// then 0). Run from the `Released` arm of the step, it needs no test of the brake's state
    /// (the other arms reset the counter), and the threshold is compared only while counting.
    /// It takes the duty after saturation: a saturated one is large without a comparison (the
    /// torque compared with the stall duty's before saturation: every fault branch of one step
    /// 200 → 194, for the unsaturated stall's count at the mission's stop 187 → 192, exact,
    /// `scripts/bench-target` with `TSS_BENCH_EXACT=1`).
    fn count_stall(
        &mut self,
        gap_ticks: u32,
        speed_mps: f32,
        (duty, saturated): (f32, bool),
    ) -> bool {
        let f = &self.cfg.faults;
        // (A saturated duty is at the limit, at or above the stall duty: validated.)
        let large = saturated || duty.abs() >= f.stall_duty;
        if large && speed_mps.abs() <= f.stall_speed_mps {
            // (Cannot wrap: below `stall_ticks` ≤ 2³¹ − 1, plus a gap below 2³¹; added
            // without saturating, as the rest count, 2 instructions less on the benchmark's
            // worst paths, 240 → 238 and 208 → 206, `scripts/bench-target` with
            // `TSS_BENCH_EXACT=1`.)
            self.stall_ticks = self.stall_ticks.wrapping_add(gap_ticks);
            if self.stall_ticks >= f.stall_ticks {
                // `trip` without its test of the brake (free here) and without its write of
                // the duty, which the step writes next.
                self.out.brake = Brake::Tripped(DriveFault::MotorStall);
                self.integral_nm = 0.0;
                return true;
            }
        } else {
            self.stall_ticks = 0;
        }
        false
    }

    /// Tension feed-forward −T r, N m.
    fn tension_torque_nm(&self, tension_n: f32) -> f32 {
        -tension_n * self.cfg.geometry.drum_radius_m
    }

    /// Friction feed-forward b v_ref / r + c sat(v_ref / v_band), N m.
    fn friction_torque_nm(&self, ref_mps: f32) -> f32 {
        let d = &self.derived;
        // (Finite: the reference is.)
        let coulomb_nm = clamp_finite_abs(ref_mps * d.coulomb_per_band, self.cfg.drum.coulomb_nm);
        d.viscous_per_radius * ref_mps + coulomb_nm
    }

    /// The tension the feed-forward uses: a reading inside [min, max] as is; a finite one
    /// outside, clamped into it; a missing or non-finite one, the last good value. Anything
    /// but the first is [`DriveFault::TensionOutOfRange`]. Each bound is compared once, and
    /// the infinities are told apart only beyond a bound (a reading in range takes the same
    /// two comparisons as before; an overload 9 instructions less than testing range, then
    /// finiteness, then the side: the step's worst paths 206 → 199 with one fault, 236 → 230
    /// with all of them, with [`Odometer`]'s speed from the total it has just written,
    /// `scripts/bench-target` with `TSS_BENCH_EXACT=1`).
    fn tension(&mut self, reading: Option<f32>, faults: &mut DriveFaults) -> f32 {
        let (lo, hi) = (self.cfg.faults.min_tension_n, self.cfg.faults.max_tension_n);
        match reading {
            Some(t) if t > hi => {
                // (Finite: above `hi`, so not NaN, and not +∞; 1 instruction less than
                // `t < ∞`.)
                if t != f32::INFINITY {
                    self.out.tension_n = hi;
                }
                faults.insert(DriveFault::TensionOutOfRange);
            }
            Some(t) if t >= lo => {
                // (Returned as well as kept: the nominal step 1 instruction shorter than
                // reading it back, mission mean 158.6 → 157.6, exact.)
                self.out.tension_n = t;
                return t;
            }
            Some(t) => {
                // (Below `lo` or NaN: finite and not NaN if at or above the lowest finite
                // value; one branch, where `t > −∞` took two and a jump, the slack reading's
                // step 186 → 184, exact.)
                if t >= f32::MIN {
                    self.out.tension_n = lo;
                }
                faults.insert(DriveFault::TensionOutOfRange);
            }
            None => faults.insert(DriveFault::TensionOutOfRange),
        }
        self.out.tension_n
    }

    /// Moves the brake (the output's, see [`Brake`]) to its next state, in place: a state
    /// that stays is not written again (the rest count alone; 2 instructions less on the
    /// mission's worst path, 189 → 187, `scripts/bench-target` with `TSS_BENCH_EXACT=1`).
    /// Entering `Released` starts the ramp from rest at `tick` (the drum was held until now).
    /// At rest means the command and the measured speed ~0.
    fn advance_brake(&mut self, tick: u32, gap_ticks: u32, speed_mps: f32, counted: bool) {
        let frees = self.command_frees_brake;
        let target_moving = self.command_moving;
        let next = match self.out.brake {
            Brake::Tripped(_) => return,
            Brake::Engaged => {
                if frees && counted {
                    Brake::Releasing {
                        ticks_left: self.cfg.brake.release_ticks,
                    }
                } else {
                    return;
                }
            }
            Brake::Releasing { ticks_left } => {
                if !frees {
                    Brake::Engaged
                } else if ticks_left <= gap_ticks {
                    // (The ramp is from rest: the brake was not free at the command.)
                    self.ramp.start_tick = tick;
                    Brake::Released { rest_ticks: 0 }
                } else {
                    Brake::Releasing {
                        ticks_left: ticks_left - gap_ticks,
                    }
                }
            }
            Brake::Released { ref mut rest_ticks } => {
                if !counted {
                    // No measured motion (the speed held): the rest count neither advances
                    // nor restarts, as the stall's (see the step).
                    return;
                }
                // At rest: the command is rest and the drum is at rest (its reference, which
                // it follows, is on its way there; waiting for it as well made the step's
                // worst path 5 instructions longer, `examples/bench_speed_loop.rs`).
                let at_rest = !target_moving && speed_mps.abs() <= self.cfg.brake.rest_speed_mps;
                if !at_rest {
                    *rest_ticks = 0;
                    return;
                }
                // (Cannot wrap: below `engage_ticks` ≤ 2³¹ − 1, plus a gap below 2³¹.)
                *rest_ticks = rest_ticks.wrapping_add(gap_ticks);
                if *rest_ticks >= self.cfg.brake.engage_ticks {
                    Brake::Engaged
                } else {
                    return;
                }
            }
        };
        self.out.brake = next;
    }

    /// The ramp from `start_mps` at `tick` toward the command: its slope is the command's
    /// (Eq. 30) acceleration if that points toward the command, at least what reaches the
    /// command within one law period, at most `max_accel_mps2`.
    fn ramp_toward_command(&self, start_mps: f32, tick: u32) -> Ramp {
        let target = self.command.rate_mps;
        let dv = target - start_mps;
        let law = if self.command.accel_mps2 * dv > 0.0 {
            self.command.accel_mps2.abs()
        } else {
            0.0
        };
        let per_period = dv.abs() * self.derived.outer_period_per_s;
        let fastest = if law > per_period { law } else { per_period };
        let magnitude = clamp_abs(fastest, self.cfg.max_accel_mps2);
        // Whole ticks to the target, rounded up (`as` saturates; 0 when already there).
        let ticks = dv.abs() / magnitude * self.cfg.inner_rate_hz as f32;
        let whole = ticks as u32;
        let slope_mps2 = magnitude.copysign(dv);
        Ramp {
            start_mps,
            start_tick: tick,
            target_mps: target,
            slope_mps2,
            step_mps: slope_mps2 * self.derived.tick_s,
            ramp_ticks: if (whole as f32) < ticks {
                whole.saturating_add(1)
            } else {
                whole
            },
        }
    }

    /// The reference speed and acceleration at `tick`: the ramp, stopped at its target. (Only
    /// used while the brake is free; the ramp restarts from rest when it is released.)
    fn reference_at(&self, tick: u32) -> (f32, f32) {
        let r = &self.ramp;
        let age_ticks = tick.wrapping_sub(r.start_tick);
        if age_ticks >= r.ramp_ticks {
            (r.target_mps, 0.0)
        } else {
            (r.start_mps + r.step_mps * age_ticks as f32, r.slope_mps2)
        }
    }
}

/// `x` limited to [−limit, limit] (limit ≥ 0), and whether it was beyond: by comparisons,
/// which decide both at once (`f32::clamp` panics on bad bounds, and `f32::min`/`max` are
/// library calls, `fminf`/`fmaxf`, on the Cortex-M4F: with them the step took 420 instructions,
/// median, `examples/bench_speed_loop.rs`). A NaN `x` gives 0 (no torque), not saturated: it
/// fails both comparisons of the in-range test, so a value inside the limits takes two
/// comparisons and no NaN test (6 instructions less on the step's unsaturated path than
/// testing for NaN after the two bounds, `scripts/bench-target` with `TSS_BENCH_EXACT=1`).
/// The lower bound first: a saturation either way takes two comparisons too (the upper bound
/// first, one above and three below: every fault branch of one step 208 → 206, exact).
fn saturate(x: f32, limit: f32) -> (f32, bool) {
    if x >= -limit {
        if x > limit {
            (limit, true)
        } else {
            (x, false)
        }
    } else if x < -limit {
        (-limit, true)
    } else {
        nan_duty()
    }
}

/// [`saturate`]'s NaN: no torque. Cold and out of line, so that the saturation's branches
/// stay branches (if-converted by LLVM, they cost every step 11 instructions more, exact,
/// `scripts/bench-target` with `TSS_BENCH_EXACT=1`).
#[cold]
#[inline(never)]
fn nan_duty() -> (f32, bool) {
    (0.0, false)
}

/// [`saturate`]'s value.
fn clamp_abs(x: f32, limit: f32) -> f32 {
    saturate(x, limit).0
}

/// A finite `x` limited to [−limit, limit] (limit ≥ 0): [`clamp_abs`] without its NaN check,
/// for values finite by construction (every input is checked before it reaches the law), 4
/// instructions less a use (`examples/bench_speed_loop.rs`). A NaN `x` stays NaN.
fn clamp_finite_abs(x: f32, limit: f32) -> f32 {
    if x > limit {
        limit
    } else if x < -limit {
        -limit
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clamp_abs_saturates_and_zeroes_nan() {
        assert_eq!(clamp_abs(2.0, 1.0), 1.0);
        assert_eq!(clamp_abs(-2.0, 1.0), -1.0);
        assert_eq!(clamp_abs(0.5, 1.0), 0.5);
        assert_eq!(clamp_abs(f32::NAN, 1.0), 0.0);
        assert_eq!(clamp_abs(f32::NEG_INFINITY, 1.0), -1.0);
    }

    #[test]
    fn the_ramp_meets_the_command_within_a_period_and_never_passes_it() {
        let mut s = SpeedLoop::new(DriveConfig::example()).unwrap();
        // A limited command: 1 m/s reached at 1 m/s² (Eq. 30 value = the ramp's slope).
        s.set_command(
            RateCommand {
                rate_mps: 1.0,
                accel_mps2: 1.0,
                safe_hold: false,
            },
            0,
        )
        .unwrap();
        assert_eq!(s.reference_at(500), (0.5, 1.0));
        assert_eq!(s.reference_at(1000), (1.0, 0.0));
        assert_eq!(s.reference_at(5000), (1.0, 0.0));
        // With the brake free, the next command ramps from the reference; an acceleration
        // pointing away from the command does not move the reference away.
        s.out.brake = Brake::Released { rest_ticks: 0 };
        s.set_command(
            RateCommand {
                rate_mps: 0.5,
                accel_mps2: 2.0,
                safe_hold: false,
            },
            1000,
        )
        .unwrap();
        let (v, a) = s.reference_at(1500);
        assert!((v - 0.75).abs() < 1e-6 && a == -0.5, "{v} {a}");
    }

    #[test]
    fn the_ramp_starts_from_rest_at_every_release() {
        let mut s = SpeedLoop::new(DriveConfig::example()).unwrap();
        let input = |tick| DriveInput {
            tick,
            encoder_count: Some(0),
            tension_n: Some(20.0),
        };
        // 1 m/s at 1 m/s², commanded while the brake is on: the ramp starts at the release.
        s.set_command(
            RateCommand {
                rate_mps: 1.0,
                accel_mps2: 1.0,
                safe_hold: false,
            },
            0,
        )
        .unwrap();
        let mut tick = 0;
        while !matches!(s.step(&input(tick)).brake, Brake::Released { .. }) {
            tick += 1;
        }
        let released = tick;
        assert!(released > 0);
        assert_eq!(s.output().ref_rate_mps, 0.0);
        for t in released + 1..=released + 500 {
            s.step(&input(t));
        }
        assert!((s.output().ref_rate_mps - 0.5).abs() < 1e-6);
        // Tripped mid-ramp and cleared, under the same command: the drum was held, so the
        // next release starts the ramp from rest again (not from where it stood).
        s.trip(DriveFault::Actuator);
        s.clear_trip();
        let mut tick = released + 501;
        while !matches!(s.step(&input(tick)).brake, Brake::Released { .. }) {
            tick += 1;
        }
        assert_eq!(s.output().ref_rate_mps, 0.0);
        for t in tick + 1..=tick + 100 {
            s.step(&input(t));
        }
        assert!((s.output().ref_rate_mps - 0.1).abs() < 1e-6);
    }

    #[test]
    fn a_tick_without_a_measured_speed_neither_counts_toward_a_stall_nor_clears_it() {
        let mut s = SpeedLoop::new(DriveConfig::example()).unwrap();
        s.set_command(
            RateCommand {
                rate_mps: 1.0,
                accel_mps2: 0.0,
                safe_hold: false,
            },
            0,
        )
        .unwrap();
        // A still drum under the largest tension: the duty saturates, a stall is counted.
        let input = |tick, encoder_count| DriveInput {
            tick,
            encoder_count,
            tension_n: Some(200.0),
        };
        let mut tick = 0;
        while !matches!(s.step(&input(tick, Some(0))).brake, Brake::Released { .. }) {
            tick += 1;
        }
        let counted = s.stall_ticks;
        assert!(counted > 0);
        tick += 1;
        let out = *s.step(&input(tick, None));
        assert!(out.faults.contains(DriveFault::EncoderMissing));
        assert_eq!(s.stall_ticks, counted);
        tick += 1;
        s.step(&input(tick, Some(0)));
        assert_eq!(s.stall_ticks, counted + 1);
    }

    #[test]
    fn a_tension_beyond_a_bound_is_clamped_and_an_infinite_one_not_used() {
        let mut s = SpeedLoop::new(DriveConfig::example()).unwrap();
        let mut faults = DriveFaults::NONE;
        assert_eq!(s.tension(Some(20.0), &mut faults), 20.0);
        assert!(faults.is_empty());
        for (reading, used) in [
            (Some(200.0), 200.0),
            (Some(-5.0), -5.0),
            (Some(f32::INFINITY), -5.0),
            (Some(f32::NEG_INFINITY), -5.0),
            (Some(f32::NAN), -5.0),
            (Some(f32::MAX), 200.0),
            (Some(f32::NEG_INFINITY), 200.0),
            (Some(f32::MIN), -5.0),
            (None, -5.0),
        ] {
            let mut faults = DriveFaults::NONE;
            assert_eq!(s.tension(reading, &mut faults), used, "{reading:?}");
            let in_range = reading.is_some_and(|t| (-5.0..=200.0).contains(&t));
            assert_eq!(faults.is_empty(), in_range, "{reading:?}");
        }
    }

    #[test]
    fn the_output_shows_the_brake_after_a_trip_and_its_clearing() {
        let mut s = SpeedLoop::new(DriveConfig::example()).unwrap();
        s.trip(DriveFault::Actuator);
        assert_eq!(s.output().brake, Brake::Tripped(DriveFault::Actuator));
        assert_eq!(s.brake(), s.output().brake);
        assert_eq!(s.clear_trip(), Some(DriveFault::Actuator));
        assert_eq!(
            (s.brake(), s.output().brake),
            (Brake::Engaged, Brake::Engaged)
        );
        let out = *s.step(&DriveInput {
            tick: 0,
            encoder_count: Some(0),
            tension_n: Some(20.0),
        });
        assert_eq!((out.brake, out.duty), (Brake::Engaged, 0.0));
        assert!(out.faults.is_empty());
    }

    #[test]
    fn the_faults_map_onto_the_outer_logic() {
        let mut set = DriveFaults::NONE;
        set.insert(DriveFault::TensionOutOfRange);
        assert_eq!(DriveFaults::NONE.outer_reaction(), OuterReaction::Report);
        assert_eq!(set.outer_reaction(), OuterReaction::Degrade);
        set.insert(DriveFault::EncoderJump);
        assert_eq!(set.outer_reaction(), OuterReaction::Degrade);
        set.insert(DriveFault::MotorStall);
        assert_eq!(set.outer_reaction(), OuterReaction::SafeHold);
        assert_eq!(
            set.iter().collect::<heapless::Vec<_, 8>>().as_slice(),
            &[
                DriveFault::EncoderJump,
                DriveFault::MotorStall,
                DriveFault::TensionOutOfRange
            ]
        );
    }
}
