//! The reel's inner speed loop: the drum follows the outer law's rate command.
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
//! 5. **Faults** ([`DriveFault`]), returned by every step; the ones that leave the
//!    drum uncontrolled (no encoder, a stalled motor, a drum that does not answer the torque,
//!    a failed actuator) trip the drive: motor off, brake on, until [`SpeedLoop::clear_trip`].
//!    Besides each reading's own checks, the drive cross-checks its sensors against each other
//!    and its drum model (`reel_drive/checks.rs`): the tension the drum's motion implies under the motor's
//!    torque against the plausible range and the load cell, an integral pinned at its clamp,
//!    and motion with the brake engaged (the brake slips: the motor holds the drum,
//!    [`Brake::MotorHold`]).
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
//! // A step returns its faults; the motor's command and the telemetry are read from the loop.
//! assert!(drive.step(&input(0)).is_empty());
//! assert!(matches!(drive.motor().brake, Brake::Releasing { .. }));
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

mod brake;
mod checks;
mod faults;
mod reference;

pub use brake::Brake;
pub use config::{
    BrakeConfig, DriveConfig, DriveConfigError, DriveRule, DrumModel, FaultLimits, Geometry,
    SpeedGains,
};
pub use encoder::{CountFault, Odometer};
pub use faults::{DriveFault, DriveFaults, OuterReaction};

use brake::{BrakeEdge, BrakeTick};
use checks::{CrossChecks, TensionJudge};
use reference::{Ramp, RampLimits};

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

/// What the hardware is set to after a step ([`SpeedLoop::motor`]): the motor's duty and the
/// brake, which also says whether the motor is enabled.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MotorCommand {
    /// Motor duty in [−duty_limit, duty_limit] (sign = direction, pay-out positive).
    pub duty: f32,
    /// The brake (and motor enable).
    pub brake: Brake,
}

/// The last step's telemetry ([`SpeedLoop::output`]): the reference, the measurements it used,
/// the duty and the brake. (The torque's parts: [`SpeedLoop::torque_parts`].)
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
    /// one; 0 once the load cell is no longer trusted), N.
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

/// What the step drives the motor with: the torque asked for and its duty.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Drive {
    torque_nm: f32,
    duty: f32,
    saturated: bool,
}

impl Drive {
    /// The motor off.
    const OFF: Self = Self {
        torque_nm: 0.0,
        duty: 0.0,
        saturated: false,
    };
}

/// Constants derived once from the configuration, so that the step has no division.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Derived {
    /// What shapes the reference's ramps.
    ramp: RampLimits,
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
    /// tick × r / J: the observer's change of speed per N m over a tick, m/s.
    speed_per_impulse: f32,
    /// K J / r: the observer's gain, N m per m/s.
    observer_gain_nm_per_mps: f32,
    /// r / (K J): the observer's speed lag per N m it finds, m/s.
    observer_lag_mps_per_nm: f32,
    /// The implied tension's limits.
    judge: TensionJudge,
    /// [`FaultLimits::brake_slip_m`] in whole counts.
    brake_slip_counts: u32,
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
    /// The command lets the brake be free: moving, and not in safe hold.
    command_frees_brake: bool,
    /// The faults every step reports until the next command: [`DriveFault::CommandInvalid`]
    /// after a non-finite one, none otherwise.
    command_faults: DriveFaults,
    /// The reference's ramp: with the brake free, from the reference at the command's
    /// arrival; otherwise from rest, its `start_tick` set when the brake is free (the drum was
    /// held until then). Worked out with the command (and again by `clear_trip`), so that the
    /// release's step has no division.
    ramp: Ramp,
    /// The brake's state (which `trip` and `clear_trip` change too).
    brake: Brake,
    /// The tick of the last step; `None` before the first.
    last_tick: Option<u32>,
    /// The load cell's last usable tension (a reading in range, or clamped into it), N.
    load_cell_n: f32,
    /// The duty the motor applies until the next step (the last step's), whether it was
    /// saturated, and the torque it was asked for, N m.
    duty: f32,
    saturated: bool,
    torque_nm: f32,
    /// The last step's reference (v_ref m/s, a_ref m/s²) while the brake is free.
    reference: (f32, f32),
    /// The tension the last step's feed-forward used (0 once the load cell is not trusted), N.
    tension_n: f32,
    /// The last step's faults.
    faults: DriveFaults,
    integral_nm: f32,
    stall_ticks: u32,
    /// Ticks of duty saturation left before [`DriveFault::DutySaturated`] is reported (the
    /// configuration's `saturation_ticks` while unsaturated, 0 once reported).
    saturation_left_ticks: u32,
    /// The cross-checks' state.
    checks: CrossChecks,
}

impl SpeedLoop {
    /// A speed loop at rest, brake engaged, after validating `cfg`.
    pub fn new(cfg: DriveConfig) -> Result<Self, DriveConfigError> {
        cfg.validate()?;
        let r = cfg.geometry.drum_radius_m;
        let f = &cfg.faults;
        let derived = Derived {
            ramp: RampLimits::new(&cfg),
            ki_tick: cfg.gains.ki_nm_per_m * cfg.tick_s(),
            inertia_per_radius: cfg.drum.inertia_kgm2 / r,
            viscous_per_radius: cfg.drum.viscous_nm_per_radps / r,
            coulomb_per_band: cfg.drum.coulomb_nm / cfg.drum.coulomb_band_mps,
            per_max_torque: 1.0 / cfg.max_torque_nm,
            speed_per_impulse: cfg.tick_s() * r / cfg.drum.inertia_kgm2,
            observer_gain_nm_per_mps: f.observer_bandwidth_radps * cfg.drum.inertia_kgm2 / r,
            observer_lag_mps_per_nm: r / (f.observer_bandwidth_radps * cfg.drum.inertia_kgm2),
            judge: TensionJudge {
                lowest_nm: (f.min_tension_n - f.tension_mismatch_n) * r,
                highest_nm: (f.max_tension_n + f.tension_mismatch_n) * r,
                mismatch_nm: f.tension_mismatch_n * r,
                ticks: f.no_response_ticks,
            },
            // (`as` saturates; validated positive.)
            brake_slip_counts: (f.brake_slip_m / cfg.geometry.m_per_count()) as u32,
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
            brake: Brake::Engaged,
            last_tick: None,
            load_cell_n: 0.0,
            duty: 0.0,
            saturated: false,
            torque_nm: 0.0,
            reference: (0.0, 0.0),
            tension_n: 0.0,
            faults: DriveFaults::NONE,
            integral_nm: 0.0,
            stall_ticks: 0,
            saturation_left_ticks: cfg.faults.saturation_ticks,
            checks: CrossChecks::START,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &DriveConfig {
        &self.cfg
    }

    /// The last step's telemetry (with the brake, duty and speed after a [`trip`](Self::trip)
    /// or [`clear_trip`](Self::clear_trip) since). Worked out when asked: the step itself keeps
    /// only what the next step needs and what it cannot work out again (the torque, the
    /// reference and the tension it used).
    pub fn output(&self) -> DriveOutput {
        let (ref_rate_mps, ref_accel_mps2) = match self.brake {
            Brake::Released { .. } => self.reference,
            Brake::Engaged | Brake::Releasing { .. } | Brake::MotorHold | Brake::Tripped(_) => {
                (0.0, 0.0)
            }
        };
        DriveOutput {
            tick: self.last_tick.unwrap_or(0),
            ref_rate_mps,
            ref_accel_mps2,
            speed_mps: self.odometer.speed_mps(),
            tension_n: self.tension_n,
            torque_nm: self.torque_nm,
            duty: self.duty,
            saturated: self.saturated,
            brake: self.brake,
            faults: self.faults,
        }
    }

    /// What the hardware is to be set to: the last step's duty and the brake (after a
    /// [`trip`](Self::trip) or [`clear_trip`](Self::clear_trip) since, the motor off).
    pub fn motor(&self) -> MotorCommand {
        MotorCommand {
            duty: self.duty,
            brake: self.brake,
        }
    }

    /// The last step's faults ([`DriveOutput::faults`], without the rest of the telemetry).
    pub fn faults(&self) -> DriveFaults {
        self.faults
    }

    /// The odometer (total count, paid-out length, speed).
    pub fn odometer(&self) -> &Odometer {
        &self.odometer
    }

    /// The brake's state.
    pub fn brake(&self) -> Brake {
        self.brake
    }

    /// The tension the drum's motion implies under the motor's torque (the cross-checks'
    /// observer, `reel_drive/checks.rs`; meaningful while the brake is free), N.
    pub fn implied_tension_n(&self) -> f32 {
        self.checks.implied_tether_nm / self.cfg.geometry.drum_radius_m
    }

    /// Whether the feed-forward uses the load cell (false after
    /// [`DriveFault::TensionMismatch`], until [`clear_trip`](Self::clear_trip)).
    pub fn load_cell_trusted(&self) -> bool {
        self.checks.load_cell_trusted()
    }

    /// The parts of the last step's torque ([`DriveOutput::torque_nm`] is their sum): with
    /// the brake free or the motor holding, PI and the three feed-forwards; while it lifts,
    /// only the tension's; otherwise none.
    pub fn torque_parts(&self) -> TorqueParts {
        let o = &self.output();
        match o.brake {
            Brake::Released { .. } | Brake::MotorHold => {
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
                rate_mps: saturate(cmd.rate_mps, max).0,
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
        let from_mps = match self.brake {
            Brake::Released { .. } => self.ramp.at(tick).0,
            Brake::Engaged | Brake::Releasing { .. } | Brake::MotorHold | Brake::Tripped(_) => 0.0,
        };
        self.ramp = self.ramp_toward_command(from_mps, tick);
        if valid {
            Ok(())
        } else {
            Err(DriveFault::CommandInvalid)
        }
    }

    /// The ramp from `start_mps` at `tick` toward the command ([`Ramp::toward`]).
    fn ramp_toward_command(&self, start_mps: f32, tick: u32) -> Ramp {
        let c = &self.command;
        Ramp::toward(
            c.rate_mps,
            c.accel_mps2,
            start_mps,
            tick,
            &self.derived.ramp,
        )
    }

    /// Trips the drive for `fault` (motor off, brake on) — for faults found outside the step,
    /// such as a refused actuator write. A drive already tripped keeps its first fault.
    pub fn trip(&mut self, fault: DriveFault) {
        if !matches!(self.brake, Brake::Tripped(_)) {
            self.brake = Brake::Tripped(fault);
            self.duty = 0.0;
            self.saturated = false;
            self.integral_nm = 0.0;
            self.torque_nm = 0.0;
        }
    }

    /// The step's own trip (the brake is free, and the step writes the duty and the output).
    fn trip_driven(&mut self, fault: DriveFault, faults: &mut DriveFaults) -> Drive {
        faults.insert(fault);
        self.brake = Brake::Tripped(fault);
        self.integral_nm = 0.0;
        Drive::OFF
    }

    /// Clears a trip, or the motor's hold of a slipping brake, and trusts the load cell again:
    /// the brake stays engaged and releases again only for a moving command and a fresh
    /// encoder reading, which becomes the counter's new reference ([`Odometer::resync`]:
    /// whatever the drum did while tripped is not counted). Returns the fault that was
    /// cleared ([`DriveFault::BrakeSlip`] for a hold).
    pub fn clear_trip(&mut self) -> Option<DriveFault> {
        let cleared = match self.brake {
            Brake::Tripped(f) => f,
            Brake::MotorHold => DriveFault::BrakeSlip,
            Brake::Engaged | Brake::Releasing { .. } | Brake::Released { .. } => {
                self.checks.trust_load_cell();
                return None;
            }
        };
        self.brake = Brake::Engaged;
        self.duty = 0.0;
        self.saturated = false;
        self.torque_nm = 0.0;
        self.integral_nm = 0.0;
        self.stall_ticks = 0;
        self.saturation_left_ticks = self.cfg.faults.saturation_ticks;
        self.checks = CrossChecks::START;
        self.odometer.resync();
        // The drum was held: the next release starts the ramp from rest.
        self.ramp = self.ramp_toward_command(0.0, 0);
        Some(cleared)
    }

    /// One inner tick: odometry, brake, reference, PI + feed-forward, faults. Returns the
    /// step's faults; what the hardware is to be set to is [`motor`](Self::motor), the
    /// telemetry [`output`](Self::output). Only the faults come back: a returned struct goes
    /// through memory and costs the step some 13 instructions, and each value written back at
    /// the step's end is one more kept alive through it (the ten of the telemetry cost some
    /// 17, `scripts/bench-target`).
    pub fn step(&mut self, input: &DriveInput) -> DriveFaults {
        let tick = input.tick;
        // Integer time: the tick must advance (wrapping, by less than half the range); the
        // first step's gap is one tick.
        let gap_ticks = match self.last_tick {
            Some(last) => tick.wrapping_sub(last),
            None => 1,
        };
        // (0 and anything beyond half the range in one comparison: 0 − 1 wraps to the top.)
        if gap_ticks.wrapping_sub(1) >= i32::MAX as u32 {
            return self.reject_tick();
        }
        self.last_tick = Some(tick);
        let mut faults = self.command_faults;

        let load_cell_n = self.take_tension(input.tension_n, &mut faults);
        let (counted, speed_mps) = self.odometry(tick, gap_ticks, input.encoder_count, &mut faults);
        let counted = counted.is_ok();
        // A dropped load cell is reported by every step, and the feed-forward takes no tension.
        let tension_n = if self.checks.load_cell_trusted() {
            load_cell_n
        } else {
            faults.insert(DriveFault::TensionMismatch);
            0.0
        };
        self.tension_n = tension_n;
        // Its torque at the drum, T r, N m (the feed-forward's, the observer's start, the
        // judgement's).
        let tether_nm = tension_n * self.cfg.geometry.drum_radius_m;

        // The brake's next state; leaving `Engaged` forgets where it held the drum, entering
        // `Released` starts the ramp from rest at this tick (the drum was held until now) and
        // the observer of the implied tension.
        let brake_tick = BrakeTick {
            gap_ticks,
            speed_mps,
            counted,
            command_moving: self.command_moving,
            command_frees_brake: self.command_frees_brake,
        };
        match self.brake.advance(&brake_tick, &self.cfg.brake) {
            Some(BrakeEdge::Lifting) => self.checks.held_at_count = None,
            Some(BrakeEdge::Freed) => {
                self.ramp.start_tick = tick;
                self.checks.start_observer(
                    speed_mps,
                    tether_nm,
                    self.derived.observer_lag_mps_per_nm,
                );
            }
            None => {}
        }

        // The torque: PI + feed-forward with the brake free (toward rest while the motor holds
        // a slipping brake), with the checks of a driven drum; while it lifts, the motor takes
        // over the tension's torque, nothing else; otherwise the motor is off.
        let drive = match self.brake {
            Brake::Released { rest_ticks } => {
                let (ref_mps, ref_accel_mps2) = self.ramp.at(tick);
                self.reference = (ref_mps, ref_accel_mps2);
                let torque_nm =
                    self.speed_law(ref_mps, ref_accel_mps2, gap_ticks, speed_mps, tether_nm);
                let drive = self.driven(torque_nm);
                if !counted {
                    // No measured motion: the checks neither count this tick nor clear.
                    drive
                } else if rest_ticks > 0 {
                    // At rest, the brake about to engage: a large duty holding a still drum is
                    // the motor holding the tension, not a stall.
                    self.stall_ticks = 0;
                    drive
                } else {
                    match self.driven_checks(gap_ticks, speed_mps, &drive, tether_nm, &mut faults) {
                        Some(fault) => self.trip_driven(fault, &mut faults),
                        None => drive,
                    }
                }
            }
            Brake::MotorHold => {
                // Whatever torque holding a slipping brake takes helps the brake: nothing
                // trips the motor here.
                faults.insert(DriveFault::BrakeSlip);
                self.stall_ticks = 0;
                let torque_nm = self.speed_law(0.0, 0.0, gap_ticks, speed_mps, tether_nm);
                self.driven(torque_nm)
            }
            Brake::Releasing { .. } => {
                self.stall_ticks = 0;
                self.driven(-tether_nm)
            }
            Brake::Engaged => {
                self.stall_ticks = 0;
                self.integral_nm = 0.0;
                if counted && self.brake_slipped() {
                    // The motor takes over from the next tick.
                    faults.insert(DriveFault::BrakeSlip);
                    self.brake = Brake::MotorHold;
                }
                Drive::OFF
            }
            Brake::Tripped(f) => {
                faults.insert(f);
                self.stall_ticks = 0;
                self.integral_nm = 0.0;
                // The motor off, the brake is all that holds the drum: its slip is reported.
                if counted && self.brake_slipped() {
                    faults.insert(DriveFault::BrakeSlip);
                }
                Drive::OFF
            }
        };

        // Saturation held too long (reported).
        if drive.saturated {
            self.saturation_left_ticks = self.saturation_left_ticks.saturating_sub(gap_ticks);
            if self.saturation_left_ticks == 0 {
                faults.insert(DriveFault::DutySaturated);
            }
        } else {
            self.saturation_left_ticks = self.cfg.faults.saturation_ticks;
        }

        self.duty = drive.duty;
        self.saturated = drive.saturated;
        self.torque_nm = drive.torque_nm;
        self.faults = faults;
        faults
    }

    /// A tick that did not advance: nothing is done, the motor and brake stay as they are, with
    /// [`DriveFault::Tick`].
    fn reject_tick(&mut self) -> DriveFaults {
        let mut faults = self.command_faults;
        faults.insert(DriveFault::Tick);
        self.faults = faults;
        faults
    }

    /// Tether paid out since the first encoder reading, m (a function of the integer count).
    pub fn paid_out_m(&self) -> f32 {
        self.odometer.paid_out_m()
    }

    /// The encoder reading of `tick`, `gap_ticks` after the last step's: whether the odometer
    /// took it, and the drum's speed. A reading it cannot take is a fault; too long without
    /// one trips. After a gap longer than the jump check bridges, the counter's change is
    /// ambiguous (it may have wrapped): the reading is not used.
    fn odometry(
        &mut self,
        tick: u32,
        gap_ticks: u32,
        count: Option<u32>,
        faults: &mut DriveFaults,
    ) -> (Result<(), CountFault>, f32) {
        let reading = if gap_ticks == 1 {
            count
        } else {
            // The ticks the overrun skipped get their predicted totals.
            self.odometer.skip(gap_ticks - 1);
            if gap_ticks <= self.cfg.faults.encoder_trip_ticks {
                count
            } else {
                None
            }
        };
        let (counted, speed_mps) = self.odometer.update_next(tick, reading);
        if let Err(f) = counted {
            self.count_fault(f, tick, gap_ticks, faults);
        }
        (counted, speed_mps)
    }

    /// A reading the odometer did not take at `tick`, `gap_ticks` after the last step: its
    /// fault, and the trip if the encoder has been without one for too long. Out of line:
    /// inlined, this rare branch costs the step's every path a register (`scripts/bench-target`).
    #[cold]
    #[inline(never)]
    fn count_fault(&mut self, f: CountFault, tick: u32, gap_ticks: u32, faults: &mut DriveFaults) {
        let trip_ticks = self.cfg.faults.encoder_trip_ticks;
        let since_accepted = self.odometer.ticks_since_accepted(tick);
        let (fault, lost) = match f {
            // A jump is a reading within the gap the check bridges, against an accepted one:
            // only the ticks since that one can have run out.
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

    /// The brake engaged: whether the drum has slipped beyond `brake_slip_m` from where it was
    /// first held.
    fn brake_slipped(&mut self) -> bool {
        let total = self.odometer.total_counts() as u32;
        self.checks
            .brake_slipped(total, self.derived.brake_slip_counts)
    }

    /// The brake free, not at rest, the speed measured: the stall, the implied tension and the
    /// pinned integral; the fault that trips the drive, if any. `used_nm` is the torque of the
    /// tension the feed-forward used (T_ff r).
    fn driven_checks(
        &mut self,
        gap_ticks: u32,
        speed_mps: f32,
        drive: &Drive,
        used_nm: f32,
        faults: &mut DriveFaults,
    ) -> Option<DriveFault> {
        if self.count_stall(gap_ticks, speed_mps, drive.duty, drive.saturated) {
            return Some(DriveFault::MotorStall);
        }
        // The loop at its limit: the duty saturated, or the integral at its clamp.
        let at_limit = drive.saturated || self.integral_nm.abs() >= self.cfg.max_torque_nm;
        match self
            .checks
            .judge_tension(used_nm, at_limit, gap_ticks, &self.derived.judge)
        {
            Some(DriveFault::TensionMismatch) => {
                faults.insert(DriveFault::TensionMismatch);
                None
            }
            fault => fault,
        }
    }

    /// The drive of a torque: the torque and its duty.
    fn driven(&self, torque_nm: f32) -> Drive {
        let (duty, saturated) =
            saturate(torque_nm * self.derived.per_max_torque, self.cfg.duty_limit);
        Drive {
            torque_nm,
            duty,
            saturated,
        }
    }

    /// PI + feed-forward toward the reference `ref_mps`, `ref_accel_mps2` (see the module
    /// docs), with conditional integration: the integral does not grow in the direction that
    /// held the last tick's duty in saturation; `tether_nm` is the tension's torque the
    /// feed-forward takes (T r). Steps the observer of the implied tension
    /// (`reel_drive/checks.rs`: the motor applied the last step's duty since; the model's
    /// friction is the feed-forward's). Returns the torque, N m. Inlined: out of line, the
    /// call and its six arguments cost every driven step about 7 instructions
    /// (`TSS_BENCH_EXACT=1 scripts/bench-target`).
    #[inline]
    fn speed_law(
        &mut self,
        ref_mps: f32,
        ref_accel_mps2: f32,
        gap_ticks: u32,
        speed_mps: f32,
        tether_nm: f32,
    ) -> f32 {
        let d = &self.derived;
        let gap = gap_ticks as f32;
        let error_mps = ref_mps - speed_mps;
        let winding_up = self.saturated && self.duty * error_mps > 0.0;
        if !winding_up {
            self.integral_nm = saturate(
                self.integral_nm + d.ki_tick * gap * error_mps,
                self.cfg.max_torque_nm,
            )
            .0;
        }
        let friction_nm = self.friction_torque_nm(ref_mps);
        self.checks.observe(
            speed_mps,
            self.duty * self.cfg.max_torque_nm - friction_nm,
            d.speed_per_impulse * gap,
            d.observer_gain_nm_per_mps,
        );
        self.cfg.gains.kp_nm_per_mps * error_mps
            + self.integral_nm
            + d.inertia_per_radius * ref_accel_mps2
            - tether_nm
            + friction_nm
    }

    /// The stall counter, brake free and not at rest: the ticks the drive has been stalled
    /// (|duty| at or above the stall duty, the drum slower than the stall speed), reset
    /// otherwise; true at the stall ticks.
    fn count_stall(&mut self, gap_ticks: u32, speed_mps: f32, duty: f32, saturated: bool) -> bool {
        let f = &self.cfg.faults;
        // (A saturated duty is at the limit, at or above the stall duty: validated.)
        let large = saturated || duty.abs() >= f.stall_duty;
        if large && speed_mps.abs() <= f.stall_speed_mps {
            // (Cannot wrap: below `stall_ticks` ≤ 2³¹ − 1, plus a gap below 2³¹.)
            self.stall_ticks = self.stall_ticks.wrapping_add(gap_ticks);
            self.stall_ticks >= f.stall_ticks
        } else {
            self.stall_ticks = 0;
            false
        }
    }

    /// Tension feed-forward −T r, N m.
    fn tension_torque_nm(&self, tension_n: f32) -> f32 {
        -tension_n * self.cfg.geometry.drum_radius_m
    }

    /// Friction at the drum's surface speed `speed_mps`, as the model has it:
    /// b v / r + c sat(v / v_band), N m (the feed-forward's at the reference).
    fn friction_torque_nm(&self, speed_mps: f32) -> f32 {
        let d = &self.derived;
        let coulomb_nm = saturate(speed_mps * d.coulomb_per_band, self.cfg.drum.coulomb_nm).0;
        d.viscous_per_radius * speed_mps + coulomb_nm
    }

    /// Takes the load cell's `reading`: one inside [min, max] as is, a finite one outside
    /// clamped into it, a missing or non-finite one not at all (the last usable value stays);
    /// anything but the first is [`DriveFault::TensionOutOfRange`]. Returns the last usable
    /// value, N.
    fn take_tension(&mut self, reading: Option<f32>, faults: &mut DriveFaults) -> f32 {
        let (lo, hi) = (self.cfg.faults.min_tension_n, self.cfg.faults.max_tension_n);
        match reading {
            Some(t) if t <= hi => {
                if t >= lo {
                    self.load_cell_n = t;
                    return t;
                }
                // Below the range: clamped if finite (−∞ is not).
                if t.is_finite() {
                    self.load_cell_n = lo;
                }
            }
            // Above the range (clamped if finite), or NaN.
            Some(t) if t.is_finite() => self.load_cell_n = hi,
            Some(_) | None => {}
        }
        faults.insert(DriveFault::TensionOutOfRange);
        self.load_cell_n
    }
}

/// `x` limited to [−limit, limit] (limit ≥ 0), and whether it was beyond, by comparisons
/// (`f32::clamp` panics on bad bounds; `f32::min`/`max` are library calls on the
/// Cortex-M4F). Inside the limit is the common case and costs one comparison; beyond it, the
/// sign says which side. A NaN `x` fails every comparison and gives 0 (no torque), not
/// saturated.
fn saturate(x: f32, limit: f32) -> (f32, bool) {
    if x.abs() <= limit {
        (x, false)
    } else if x > 0.0 {
        (limit, true)
    } else if x < 0.0 {
        (-limit, true)
    } else {
        (0.0, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saturate_limits_and_zeroes_nan() {
        assert_eq!(saturate(2.0, 1.0), (1.0, true));
        assert_eq!(saturate(-2.0, 1.0), (-1.0, true));
        assert_eq!(saturate(0.5, 1.0), (0.5, false));
        assert_eq!(saturate(-1.0, 1.0), (-1.0, false));
        assert_eq!(saturate(f32::NAN, 1.0), (0.0, false));
        assert_eq!(saturate(f32::NEG_INFINITY, 1.0), (-1.0, true));
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
        loop {
            s.step(&input(tick, Some(0)));
            if matches!(s.brake(), Brake::Released { .. }) {
                break;
            }
            tick += 1;
        }
        let counted = s.stall_ticks;
        assert!(counted > 0);
        tick += 1;
        let faults = s.step(&input(tick, None));
        assert!(faults.contains(DriveFault::EncoderMissing));
        assert_eq!(s.stall_ticks, counted);
        tick += 1;
        s.step(&input(tick, Some(0)));
        assert_eq!(s.stall_ticks, counted + 1);
    }

    #[test]
    fn a_tension_beyond_a_bound_is_clamped_and_an_infinite_one_not_used() {
        let mut s = SpeedLoop::new(DriveConfig::example()).unwrap();
        let mut faults = DriveFaults::NONE;
        s.take_tension(Some(20.0), &mut faults);
        assert_eq!(s.load_cell_n, 20.0);
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
            let in_range = reading.is_some_and(|t| (-5.0..=200.0).contains(&t));
            s.take_tension(reading, &mut faults);
            assert_eq!(s.load_cell_n, used, "{reading:?}");
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
        let faults = s.step(&DriveInput {
            tick: 0,
            encoder_count: Some(0),
            tension_n: Some(20.0),
        });
        assert_eq!(
            s.motor(),
            MotorCommand {
                duty: 0.0,
                brake: Brake::Engaged
            }
        );
        assert!(faults.is_empty());
    }
}
