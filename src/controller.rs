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

use crate::envelope::{PreparedEnvelope, Saturation};
use crate::equilibrium::ExistenceMonitor;
use crate::law::{self, Blend, LawFault, LawInput};
use crate::monitor::{Monitor, SPOOL_MARGIN};
use crate::real::Real;
use crate::schedule::{PreparedBand, Reference};

pub use crate::config::{Config, ConfigError, Rule, Stage1Config, Stage2Config};
pub use crate::envelope::Envelope;
pub use crate::monitor::{MonitorConfig, Sensor};

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

/// Health of the controller's inputs: the fault state machine.
///
/// ```text
///            bad sample / law fault                more than coast_ticks bad
///   Nominal ─────────────────────────▶ Degraded ───────────────────────────▶ SafeHold
///      ▲ ◀──────── next good sample ───────┘                                    │
///      └──────────────── recovery_ticks good samples in a row ──────────────────┘
///                        (the Eq. 29 blend restarts from the current rate)
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Health {
    /// Valid samples; the law commands the reel.
    Nominal,
    /// No usable sample (or no law solution) for at most `coast_ticks`: the reel coasts on its
    /// last command while the length is predicted from the integrated command.
    Degraded,
    /// Too long without a usable sample: the rate is ramped to zero within the acceleration
    /// limit and held there until the sensors recover.
    SafeHold,
}

/// Why this step's command is not the law's value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Fault {
    /// A sample was missing or rejected.
    Sensor(Sensor),
    /// The law is at one of its singular points.
    Law(LawFault),
}

/// Status bits reported with every command.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Flags(pub u32);

impl Flags {
    /// The law asked for more than the rate limit.
    pub const RATE_SATURATED: u32 = Saturation::RATE;
    /// The change from the previous command exceeded the acceleration limit.
    pub const ACCEL_SATURATED: u32 = Saturation::ACCEL;
    /// A length limit (docking or spool) restricted the command.
    pub const LENGTH_LIMITED: u32 = Saturation::LENGTH;
    /// The command is a safe action, not the law's value (see [`Output::fault`]).
    pub const SAFE_ACTION: u32 = 1 << 3;
    /// The blend (Eq. 29) restarted at this step (a stage began, or the controller recovered).
    pub const BLEND_RESTART: u32 = 1 << 4;
    /// α_r is slewing (stage 2 start).
    pub const SLEWING: u32 = 1 << 5;
    /// [`Output::health`] changed at this step.
    pub const HEALTH_CHANGED: u32 = 1 << 6;
    /// The commanded l̇/l lies outside the region where an equilibrium exists over the whole
    /// orbit (Eq. 13; see [`Output::equilibrium_margin`]). Reported, not acted on: the paper's
    /// own deployment starts far outside it (l̇/l = 0.1 s⁻¹ at l = 1 m).
    pub const NO_EQUILIBRIUM: u32 = 1 << 7;

    /// `true` if every bit of `mask` is set.
    pub fn contains(self, mask: u32) -> bool {
        self.0 & mask == mask
    }
    fn set(&mut self, mask: u32) {
        self.0 |= mask;
    }
    fn set_if(&mut self, cond: bool, mask: u32) {
        if cond {
            self.set(mask);
        }
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
    /// Input health after this step.
    pub health: Health,
    /// Reel-rate command l̇_real for the coming period, m/s (finite, inside the envelope).
    pub rate_cmd_mps: T,
    /// Commanded reel acceleration (Eq. 30, sign corrected; the ramp's slope when a limit or
    /// safe action shapes the command), m/s².
    pub accel_cmd_mps2: T,
    /// The Eq. 27 value l̇ before the blend, m/s (0 when the law did not run).
    pub law_rate_mps: T,
    /// Blend weight E = e^{−cτ} of Eq. 29.
    pub blend_weight: T,
    /// Reference angle α_r, rad.
    pub alpha_ref_rad: T,
    /// α̇_r = (∂α_r/∂l) l̇_real + ∂α_r/∂t, rad/s.
    pub alpha_ref_rate_radps: T,
    /// δ = α − α_r, rad (0 when the law did not run).
    pub delta_rad: T,
    /// δ̇ = α̇ − α̇_r, rad/s (0 when the law did not run).
    pub delta_rate_radps: T,
    /// The length the controller works with: the sensed one, or the prediction from the
    /// integrated command while coasting, m.
    pub length_estimate_m: T,
    /// Signed margin of the commanded x = (2+μ3) l̇/(ωl) inside the whole-orbit existence
    /// region [max Retr, min Depl] of Eq. 13: > 0 inside, < 0 outside (dimensionless).
    pub equilibrium_margin: T,
    /// Status bits.
    pub flags: Flags,
    /// The fault behind a safe action, if any.
    pub fault: Option<Fault>,
}

/// Capacity of the controller's event queue ([`Controller::pop_event`]).
pub const EVENT_CAPACITY: usize = 16;

/// Something that happened in one step, worth telling the ground about once.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum EventKind {
    /// The input health changed.
    Health {
        /// Before.
        from: Health,
        /// After.
        to: Health,
    },
    /// A fault was raised (recorded when it differs from the previous fault).
    Fault(Fault),
    /// The mission phase changed.
    Phase(Phase),
    /// The Eq. 29 blend restarted (a stage began, or the controller recovered).
    BlendRestart,
}

/// An event and the tick it happened at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Event {
    /// The tick.
    pub tick: u32,
    /// What happened.
    pub kind: EventKind,
}

/// The controller's event queue: a ring of [`EVENT_CAPACITY`] events in which a new event
/// overwrites the oldest unread one when the ring is full. The writer and the reader each
/// keep a free-running count (wrapping): a push is one store and one increment, with no test,
/// so a step that records events stays close to a quiet one; the reader finds any events
/// overwritten since it last read (more than [`EVENT_CAPACITY`] unread) and counts them as
/// dropped.
#[derive(Clone, Debug)]
struct EventRing {
    buf: [Event; EVENT_CAPACITY],
    /// Events ever written (wrapping); the next is written at `written mod capacity`.
    written: u32,
    /// Events ever read or dropped (wrapping).
    read: u32,
    /// Events dropped, up to the last read.
    dropped: u32,
}

const _: () = assert!(EVENT_CAPACITY.is_power_of_two() && EVENT_CAPACITY <= u32::MAX as usize);

impl EventRing {
    const CAPACITY: u32 = EVENT_CAPACITY as u32;

    const fn new() -> Self {
        Self {
            buf: [Event {
                tick: 0,
                kind: EventKind::BlendRestart,
            }; EVENT_CAPACITY],
            written: 0,
            read: 0,
            dropped: 0,
        }
    }

    /// Appends `e`; when the ring is full it takes the oldest unread event's slot.
    #[inline(always)]
    fn push(&mut self, e: Event) {
        self.buf[self.written as usize & (EVENT_CAPACITY - 1)] = e;
        self.written = self.written.wrapping_add(1);
    }

    /// Unread events overwritten since the last read.
    fn overwritten(&self) -> u32 {
        self.written
            .wrapping_sub(self.read)
            .saturating_sub(Self::CAPACITY)
    }

    /// Takes the oldest unread event (first counting any that were overwritten).
    fn pop(&mut self) -> Option<Event> {
        let lost = self.overwritten();
        self.dropped = self.dropped.saturating_add(lost);
        self.read = self.read.wrapping_add(lost);
        if self.read == self.written {
            return None;
        }
        let e = self.buf[self.read as usize & (EVENT_CAPACITY - 1)];
        self.read = self.read.wrapping_add(1);
        Some(e)
    }

    /// Events dropped so far, including those overwritten and not yet counted by a read.
    fn dropped(&self) -> u32 {
        self.dropped.saturating_add(self.overwritten())
    }
}

/// The acceleration of a command that a limit shaped: its change over the period. Out of line
/// and cold: a limit seldom acts, and the common step then keeps the law's Eq. 30 value
/// without computing this.
#[cold]
#[inline(never)]
fn ramp_slope<T: Real>(rate_mps: T, previous_mps: T, period_s: T) -> T {
    (rate_mps - previous_mps) / period_s
}

/// Bound on the reported [`Output::equilibrium_margin`] (x grows as 1/l toward docking).
pub const MAX_REPORTED_MARGIN: f64 = 1e6;

/// Largest |x| (normalised rate) whose margin a step reports without bounding it: the margin
/// is then at most |x| + the existence region's width, well inside [`MAX_REPORTED_MARGIN`].
const MODERATE_NORMALISED_RATE: f64 = 1e5;

/// The reel controller (see the module docs for a complete example).
#[derive(Clone, Debug)]
pub struct Controller<T: Real> {
    cfg: Config<T>,
    stage2: bool,
    /// The first tick at which stage 2 begins: the configured start, 0 once stage 2 is
    /// requested, never (`u64::MAX`) once it has begun. One comparison a step.
    stage2_due_tick: u64,
    stage_start_tick: u32,
    blend_start_tick: u32,
    blend_initial_rate_mps: T,
    /// The current stage's blend: log₂E per tick and c (copied from [`Derived`] at each
    /// restart, so a step reads them without selecting the stage).
    blend_log2_per_tick: T,
    blend_decay_rate_per_s: T,
    phase: Phase,
    /// The phase ends by length when `capture_sign · l ≥ capture_m` (Deploy: l reaches the
    /// stage-1 keep; Retrieve: l comes down to the stage-2 keep; never in the other phases:
    /// `capture_m` = +∞). Set with the phase, one comparison a step.
    capture_sign: T,
    capture_m: T,
    health: Health,
    /// Consecutive ticks without a usable sample or law solution.
    bad_ticks: u32,
    /// Consecutive valid samples while in safe hold.
    good_ticks: u32,
    last_tick: Option<u32>,
    last_rate_cmd_mps: T,
    length_estimate_m: T,
    /// `true` once a sample has anchored the length estimate (until then there is no
    /// prediction to check a sensed length against).
    anchored: bool,
    monitor: Monitor<T>,
    existence: ExistenceMonitor<T>,
    derived: Derived<T>,
    /// Events not yet read, oldest first; when full the oldest is dropped and counted.
    events: EventRing,
    last_fault: Option<Fault>,
    /// The last step's output ([`Controller::output`]); each step writes its parts as they
    /// become known (values written early need no register until the end of the step).
    out: Output<T>,
}

/// What a step needs of the configuration beyond its plain numbers, worked out once in
/// [`Controller::new`] (in f64 where it is arithmetic, rounded once to `T`), so that no step
/// repeats arithmetic that depends on parameters only.
#[derive(Clone, Copy, Debug)]
struct Derived<T> {
    /// The longest plausible length: the spool end plus [`SPOOL_MARGIN`], m.
    spool_m: T,
    /// The envelope, its guarded length limits and 2a worked out.
    envelope: PreparedEnvelope<T>,
    /// The Eq. 34 (stage 1) and Eq. 35 (stage 2) schedules, their quintics' coefficients
    /// computed.
    bands: [PreparedBand<T>; 2],
    /// log₂E per tick of the stage-1 and stage-2 blends, −cΔt·log₂e: E = e^{−cΔt·k} =
    /// 2^{−cΔt·log₂e·k} k ticks after a (re)start.
    log2_decay_per_tick: [T; 2],
    /// c of the stage-1 and stage-2 blends, 1/s (Eq. 29; the Eq. 30 acceleration needs it).
    decay_rate_per_s: [T; 2],
    /// ρ = 0: μ3 and its slope are 0 at every length (the paper's massless tether).
    massless_tether: bool,
    /// Deploy becomes Keep1 at this length: the stage-1 keep length less the capture, m.
    keep1_entry_m: T,
    /// Retrieve becomes Keep2 at this length: the stage-2 keep length plus the capture, m.
    keep2_entry_m: T,
}

impl<T: Real> Derived<T> {
    fn new(cfg: &Config<T>) -> Self {
        let dt = cfg.period_s.to_f64();
        let log2_decay = |c: T| T::from_f64(-c.to_f64() * dt * core::f64::consts::LOG2_E);
        Self {
            spool_m: T::from_f64(cfg.envelope.max_length_m.to_f64() * (1.0 + SPOOL_MARGIN)),
            envelope: PreparedEnvelope::new(cfg.envelope),
            bands: [cfg.stage1.schedule.prepare(), cfg.stage2.schedule.prepare()],
            log2_decay_per_tick: [
                log2_decay(cfg.stage1.decay_rate_per_s),
                log2_decay(cfg.stage2.decay_rate_per_s),
            ],
            decay_rate_per_s: [cfg.stage1.decay_rate_per_s, cfg.stage2.decay_rate_per_s],
            massless_tether: cfg.masses.tether_density_kg_per_m == T::ZERO,
            keep1_entry_m: cfg.stage1.schedule.high_length_m - cfg.keep_capture_m,
            keep2_entry_m: cfg.stage2.schedule.low_length_m + cfg.keep_capture_m,
        }
    }
}

/// Health and phase when a step began (its events are the differences).
#[derive(Clone, Copy)]
struct Before {
    health: Health,
    phase: Phase,
}

/// The law's contribution to an output.
struct LawPart<T> {
    reference: Reference<T>,
    rate_mps: T,
    accel_mps2: T,
    law_rate_mps: T,
    ref_rate_radps: T,
    delta_rad: T,
    delta_rate_radps: T,
    /// L′ = l/(2 + μ3), m.
    reduced_length_m: T,
}

impl<T: Real> Controller<T> {
    /// Builds a controller from a validated configuration. A controller that exists is a valid
    /// one.
    pub fn new(cfg: Config<T>) -> Result<Self, ConfigError> {
        cfg.validate()?;
        let existence = ExistenceMonitor::from_orbit(&cfg.orbit).map_err(|_| {
            ConfigError::new(
                "orbit.eccentricity",
                cfg.orbit.eccentricity,
                Rule::NoEquilibrium,
            )
        })?;
        let derived = Derived::new(&cfg);
        let monitor = Monitor::new(&cfg.monitor, derived.spool_m)?;
        Ok(Self {
            existence,
            derived,
            monitor,
            stage2: false,
            stage2_due_tick: cfg.stage2.start_tick.map_or(u64::MAX, u64::from),
            stage_start_tick: 0,
            blend_start_tick: 0,
            blend_initial_rate_mps: cfg.initial_rate_mps,
            blend_log2_per_tick: derived.log2_decay_per_tick[0],
            blend_decay_rate_per_s: cfg.stage1.decay_rate_per_s,
            phase: Phase::Deploy,
            capture_sign: T::ONE,
            capture_m: derived.keep1_entry_m,
            health: Health::Nominal,
            bad_ticks: 0,
            good_ticks: 0,
            last_tick: None,
            last_rate_cmd_mps: cfg.initial_rate_mps,
            length_estimate_m: T::ZERO,
            anchored: false,
            events: EventRing::new(),
            last_fault: None,
            out: Output {
                tick: 0,
                phase: Phase::Deploy,
                health: Health::Nominal,
                rate_cmd_mps: T::ZERO,
                accel_cmd_mps2: T::ZERO,
                law_rate_mps: T::ZERO,
                blend_weight: T::ONE,
                alpha_ref_rad: T::ZERO,
                alpha_ref_rate_radps: T::ZERO,
                delta_rad: T::ZERO,
                delta_rate_radps: T::ZERO,
                length_estimate_m: T::ZERO,
                equilibrium_margin: T::ZERO,
                flags: Flags(0),
                fault: None,
            },
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

    /// The current input health.
    pub fn health(&self) -> Health {
        self.health
    }

    /// The last step's output. Before the first step: tick 0, a zero rate and acceleration,
    /// blend weight 1, the stage-1 phase and nominal health, no flags and no fault.
    pub fn output(&self) -> &Output<T> {
        &self.out
    }

    /// The oldest unread event (health and phase changes, faults, blend restarts), if any.
    ///
    /// The queue holds [`EVENT_CAPACITY`] events; read it every period so none are dropped
    /// ([`Controller::events_dropped`] counts any that were).
    pub fn pop_event(&mut self) -> Option<Event> {
        self.events.pop()
    }

    /// Events dropped because the queue was full when they happened.
    pub fn events_dropped(&self) -> u32 {
        self.events.dropped()
    }

    #[inline(always)]
    fn record(&mut self, tick: u32, kind: EventKind) {
        self.events.push(Event { tick, kind });
    }

    /// Asks for stage 2 (retrieval) to begin at the next step, whatever the configured start.
    pub fn start_stage2(&mut self) {
        if !self.stage2 {
            self.stage2_due_tick = 0;
        }
    }

    /// One control period with a fresh sensor sample. The output stays in the controller until
    /// the next step ([`Controller::output`]): the step writes each part of it as soon as it
    /// is known, and nothing is copied.
    pub fn step(&mut self, input: &Input<T>) -> &Output<T> {
        self.advance(input.tick, Some(input));
        &self.out
    }

    /// One control period in which no sample arrived (a sensor dropout): the controller coasts
    /// on the predicted length, then goes to safe hold (see [`Health`]). The output is kept as
    /// [`Controller::step`]'s is.
    pub fn step_missing(&mut self, tick: u32) -> &Output<T> {
        self.advance(tick, None);
        &self.out
    }

    fn advance(&mut self, tick: u32, sample: Option<&Input<T>>) {
        let before = Before {
            health: self.health,
            phase: self.phase,
        };
        self.advance_inner(tick, sample, before)
    }

    /// Records a step's events just before its output is made, in this order: health change,
    /// phase change, new fault, blend restart. A quiet step (the common case) records nothing.
    #[inline(always)]
    fn note_events(&mut self, tick: u32, before: Before, fault: Option<Fault>, flags: Flags) {
        if self.health != before.health {
            self.record(
                tick,
                EventKind::Health {
                    from: before.health,
                    to: self.health,
                },
            );
        }
        if self.phase != before.phase {
            self.record(tick, EventKind::Phase(self.phase));
        }
        if let Some(f) = fault {
            if fault != self.last_fault {
                self.record(tick, EventKind::Fault(f));
            }
        }
        self.last_fault = fault;
        if flags.contains(Flags::BLEND_RESTART) {
            self.record(tick, EventKind::BlendRestart);
        }
    }

    fn advance_inner(&mut self, tick: u32, sample: Option<&Input<T>>, before: Before) {
        let mut flags = Flags::default();
        let dt = self.cfg.period_s;
        // A tick that goes backwards is a bad sample; time does not move.
        let elapsed_ticks = match self.last_tick {
            None => 0,
            Some(last) if tick >= last => tick - last,
            Some(_) => {
                let unmoved = self.length_estimate_m;
                return self.reject(
                    tick,
                    unmoved,
                    Fault::Sensor(Sensor::Tick),
                    None,
                    flags,
                    before,
                );
            }
        };
        let first = self.last_tick.is_none();
        self.last_tick = Some(tick);
        let elapsed_s = T::from_u32(elapsed_ticks) * dt;
        // Dead reckoning: the reel ran at the last command since the last step. A valid sample
        // replaces the prediction; without one it becomes the estimate (see `reject`).
        // (Both terms are finite: the estimate is clamped, the command is inside the envelope.)
        let predicted_m = self.length_estimate_m + self.last_rate_cmd_mps * elapsed_s;

        // Sequencer: stage 1 starts with the first step; stage 2 at its tick or on command.
        // Each stage restarts the blend from the current rate (SPEC §7).
        if first {
            self.stage_start_tick = tick;
            self.restart_blend(tick, self.cfg.initial_rate_mps, &mut flags);
        }
        if u64::from(tick) >= self.stage2_due_tick {
            self.stage2 = true;
            self.stage2_due_tick = u64::MAX;
            self.stage_start_tick = tick;
            self.restart_blend(tick, self.last_rate_cmd_mps, &mut flags);
            self.enter(Phase::Slew);
        }

        let Some(x) = sample else {
            let f = Fault::Sensor(Sensor::Missing);
            return self.reject(tick, predicted_m, f, None, flags, before);
        };
        // Before the first accepted sample, and in safe hold, there is no trusted prediction:
        // the next valid sample (re-)anchors it.
        let expected = if self.anchored && self.health != Health::SafeHold {
            Some(predicted_m)
        } else {
            None
        };
        if let Err(s) = self.monitor.check(&self.cfg.monitor, x, expected, dt) {
            return self.reject(tick, predicted_m, Fault::Sensor(s), None, flags, before);
        }
        self.length_estimate_m = x.length_m;
        self.anchored = true;

        let reference = self.reference(tick, x.length_m);
        if self.health == Health::SafeHold {
            self.good_ticks = self.good_ticks.saturating_add(1);
            if self.good_ticks < self.cfg.monitor.recovery_ticks {
                return self.hold(tick, reference.angle.angle_rad, flags, None, before);
            }
            // Recovered: re-engage the law through the Eq. 29 blend from the current rate.
            self.restart_blend(tick, self.last_rate_cmd_mps, &mut flags);
        }
        let (mu3, mu3_per_m) = self.mu3_and_slope(x.length_m);
        let blend = self.blend(tick);
        let law = match self.solve(x, &reference, mu3, mu3_per_m, blend) {
            Ok(v) => v,
            Err(f) => {
                let (sensed, f) = (x.length_m, Fault::Law(f));
                let alpha_ref = Some(reference.angle.angle_rad);
                return self.reject(tick, sensed, f, alpha_ref, flags, before);
            }
        };
        self.out.law_rate_mps = law.law_rate_mps;
        self.out.blend_weight = blend.weight;
        self.out.alpha_ref_rad = law.reference.angle.angle_rad;
        self.out.alpha_ref_rate_radps = law.ref_rate_radps;
        self.out.delta_rad = law.delta_rad;
        self.out.delta_rate_radps = law.delta_rate_radps;
        self.set_health(Health::Nominal, &mut flags);
        self.bad_ticks = 0;

        // The first step has no previous period: the envelope judges it over one period.
        let limit_s = if elapsed_ticks == 0 { dt } else { elapsed_s };
        let (rate, sat) = self.derived.envelope.limit_request(
            law.rate_mps,
            self.last_rate_cmd_mps,
            x.length_m,
            limit_s,
        );
        let limited = sat.any();
        flags.set(sat.0);
        flags.set_if(law.reference.slewing, Flags::SLEWING);
        let accel = if limited {
            ramp_slope(rate, self.last_rate_cmd_mps, limit_s)
        } else {
            law.accel_mps2
        };
        self.last_rate_cmd_mps = rate;
        self.out.rate_cmd_mps = rate;
        self.out.accel_cmd_mps2 = accel;
        self.update_phase(x.length_m, law.reference.slewing);
        let x_rate = self
            .existence
            .normalised_rate_at_reduced_length(law.reduced_length_m, rate);
        let margin = self.equilibrium_margin(x_rate, mu3, x.length_m, rate, &mut flags);
        self.note_events(tick, before, None, flags);
        self.out.tick = tick;
        self.out.phase = self.phase;
        self.out.health = self.health;
        self.out.length_estimate_m = x.length_m;
        self.out.equilibrium_margin = margin;
        self.out.flags = flags;
        self.out.fault = None;
    }

    /// (μ3, dμ3/dl) at `length_m` (Eq. 5's mass coefficient, [`crate::mass::MassModel`]):
    /// both 0 for the massless tether, decided once in [`Controller::new`] (one flag test a
    /// step instead of the model's float comparison).
    #[inline(always)]
    fn mu3_and_slope(&self, length_m: T) -> (T, T) {
        if self.derived.massless_tether {
            (T::ZERO, T::ZERO)
        } else {
            self.cfg.masses.mu3_and_slope(length_m)
        }
    }

    /// Restarts the Eq. 29 blend of the current stage at `tick` from `rate_mps`.
    #[inline(always)]
    fn restart_blend(&mut self, tick: u32, rate_mps: T, flags: &mut Flags) {
        let stage = usize::from(self.stage2);
        self.blend_start_tick = tick;
        self.blend_initial_rate_mps = rate_mps;
        self.blend_log2_per_tick = self.derived.log2_decay_per_tick[stage];
        self.blend_decay_rate_per_s = self.derived.decay_rate_per_s[stage];
        flags.set(Flags::BLEND_RESTART);
    }

    /// E = e^{−cτ} and 1 − E, τ = k·Δt the time since the blend (re)started k ticks ago
    /// (Eq. 29), as 2^{k·(−cΔt·log₂e)}.
    #[inline(always)]
    fn blend(&self, tick: u32) -> Blend<T> {
        // The blend started at this tick or before (`advance` rejects a tick that goes
        // backwards, and `hold` reports one at the blend's start): no wrap-around.
        let k = T::from_u32(tick.wrapping_sub(self.blend_start_tick));
        Blend::from_log2(self.blend_log2_per_tick * k)
    }

    /// α_r and its derivatives at this tick and length: Eq. 34 in stage 1; in stage 2, the
    /// slew from the stage's start until it first meets Eq. 35 ([`Phase::Slew`]), then Eq. 35.
    /// (The slew is over for good once met: the phase never returns to `Slew`.)
    #[inline(always)]
    fn reference(&self, tick: u32, length_m: T) -> Reference<T> {
        if self.phase == Phase::Slew {
            let tau_s = T::from_u32(tick.saturating_sub(self.stage_start_tick)) * self.cfg.period_s;
            return self.derived.bands[1].eval_slewed(
                self.cfg.stage2.slew_rate_radps,
                tau_s,
                length_m,
            );
        }
        let band = &self.derived.bands[usize::from(self.stage2)];
        Reference {
            angle: band.eval(length_m),
            time_rate_radps: T::ZERO,
            slewing: false,
        }
    }

    /// Eqs. 27 + 29 solved implicitly, and the Eq. 30 acceleration (SPEC §5).
    fn solve(
        &self,
        x: &Input<T>,
        reference: &Reference<T>,
        mu3: T,
        mu3_per_m: T,
        blend: Blend<T>,
    ) -> Result<LawPart<T>, LawFault> {
        let law_in = LawInput {
            length_m: x.length_m,
            alpha_rad: x.alpha_rad,
            alpha_rate_radps: x.alpha_rate_radps,
            orbit_rate_radps: x.orbit_rate_radps,
            ref_angle_rad: reference.angle.angle_rad,
            ref_slope_rad_per_m: reference.angle.slope_rad_per_m,
            ref_curvature_rad_per_m2: reference.angle.curvature_rad_per_m2,
            ref_time_rate_radps: reference.time_rate_radps,
            mu3,
            mu3_per_m,
            blend,
            decay_rate_per_s: self.blend_decay_rate_per_s,
            initial_rate_mps: self.blend_initial_rate_mps,
            gains: self.cfg.gains,
        };
        let s = law::solve(&law_in)?;
        // The acceleration's own inputs read again here, where they are used: values held
        // across the solve would be kept on the stack.
        let law_in = LawInput {
            decay_rate_per_s: self.blend_decay_rate_per_s,
            initial_rate_mps: self.blend_initial_rate_mps,
            gains: self.cfg.gains,
            ..law_in
        };
        let accel = law::acceleration(&law_in, &s)?;
        Ok(LawPart {
            reference: *reference,
            rate_mps: s.rate_mps,
            accel_mps2: accel,
            law_rate_mps: s.law_rate_mps,
            ref_rate_radps: s.ref_rate_radps,
            delta_rad: s.delta_rad,
            delta_rate_radps: s.delta_rate_radps,
            reduced_length_m: s.reduced_length_m,
        })
    }

    #[inline(always)]
    fn set_health(&mut self, h: Health, flags: &mut Flags) {
        if self.health != h {
            self.health = h;
            flags.set(Flags::HEALTH_CHANGED);
        }
        if h != Health::SafeHold {
            self.good_ticks = 0;
        }
    }

    /// No usable sample or no law solution at this tick: coast (Degraded) for up to
    /// `coast_ticks`, then safe hold. `length_m` becomes the length estimate (the dead-reckoned
    /// prediction, or the sensed length of a valid sample the law could not use), limited to
    /// the physical range: the reel cannot pay out past its spool nor wind in past zero.
    #[allow(clippy::too_many_arguments)]
    fn reject(
        &mut self,
        tick: u32,
        length_m: T,
        fault: Fault,
        alpha_ref_rad: Option<T>,
        mut flags: Flags,
        before: Before,
    ) {
        self.length_estimate_m = length_m.clamp_finite(T::ZERO, self.derived.spool_m);
        self.bad_ticks = self.bad_ticks.saturating_add(1);
        let next =
            if self.health == Health::SafeHold || self.bad_ticks > self.cfg.monitor.coast_ticks {
                Health::SafeHold
            } else {
                Health::Degraded
            };
        self.set_health(next, &mut flags);
        self.good_ticks = 0;
        // Without a usable sample, α_r is reported at the predicted length.
        let alpha_ref_rad = match alpha_ref_rad {
            Some(a) => a,
            None => self.reference(tick, self.length_estimate_m).angle.angle_rad,
        };
        self.hold(tick, alpha_ref_rad, flags, Some(fault), before)
    }

    /// The safe actions. Degraded: keep the last command (coast). Safe hold: ramp the rate to
    /// zero at the acceleration limit. Both stay inside the length limits, judged on the
    /// predicted length.
    fn hold(
        &mut self,
        tick: u32,
        alpha_ref_rad: T,
        mut flags: Flags,
        fault: Option<Fault>,
        before: Before,
    ) {
        flags.set(Flags::SAFE_ACTION);
        let dt = self.cfg.period_s;
        let prev = self.last_rate_cmd_mps;
        let target = if self.health == Health::Degraded {
            prev
        } else {
            T::ZERO
        };
        let (rate, sat) =
            self.derived
                .envelope
                .limit_request(target, prev, self.length_estimate_m, dt);
        flags.set(sat.0 & Flags::LENGTH_LIMITED);
        self.last_rate_cmd_mps = rate;
        let mu3 = self.mu3_and_slope(self.length_estimate_m).0;
        let l = self.length_estimate_m;
        let x_rate = self.existence.normalised_rate(mu3, l, rate);
        let margin = self.equilibrium_margin(x_rate, mu3, l, rate, &mut flags);
        self.note_events(tick, before, fault, flags);
        self.out = Output {
            tick,
            phase: self.phase,
            health: self.health,
            rate_cmd_mps: rate,
            accel_cmd_mps2: (rate - prev) / dt,
            law_rate_mps: T::ZERO,
            // (A tick that went backwards is reported at the blend's start.)
            blend_weight: self.blend(tick.max(self.blend_start_tick)).weight,
            alpha_ref_rad,
            alpha_ref_rate_radps: T::ZERO,
            delta_rad: T::ZERO,
            delta_rate_radps: T::ZERO,
            length_estimate_m: self.length_estimate_m,
            equilibrium_margin: margin,
            flags,
            fault,
        };
    }

    /// The Eq. 13 margin of the command `rate_mps` at `length_m` (whole orbit), flagging a
    /// command outside the region. `x` is its normalised rate (Eq. 7), which the caller forms:
    /// from the law's L′ = l/(2 + μ3) on the law's path, from μ3 and l on a safe action.
    ///
    /// The common case takes one comparison: a normalised rate x of moderate size, whose
    /// margin is within the reported bound as it is (|margin| ≤ |x| + the extent's width, far
    /// below [`MAX_REPORTED_MARGIN`]). NaN, infinities and huge values (a length estimate
    /// near zero) fail it and take [`Self::far_equilibrium_margin`].
    #[inline(always)]
    fn equilibrium_margin(&self, x: T, mu3: T, length_m: T, rate_mps: T, flags: &mut Flags) -> T {
        let (margin, outside) = if x.abs() <= T::from_f64(MODERATE_NORMALISED_RATE) {
            let m = self.existence.whole_orbit_margin_of(x);
            (m, m < T::ZERO)
        } else {
            self.far_equilibrium_margin(mu3, length_m, rate_mps)
        };
        flags.set_if(outside, Flags::NO_EQUILIBRIUM);
        margin
    }

    /// [`Self::equilibrium_margin`] beyond the moderate range: (margin, outside the region).
    #[inline(never)]
    fn far_equilibrium_margin(&self, mu3: T, length_m: T, rate_mps: T) -> (T, bool) {
        match self.existence.whole_orbit_margin(mu3, length_m, rate_mps) {
            Some(margin) => {
                // x grows as 1/l: near docking the margin can exceed f32; report it bounded.
                let bound = T::from_f64(MAX_REPORTED_MARGIN);
                (margin.clamp_finite(-bound, bound), margin < T::ZERO)
            }
            // Only a non-positive length estimate gets here (a long coast toward docking): no
            // equilibrium statement can be made.
            None => (T::ZERO, true),
        }
    }

    /// The phase after a step at `length_m`: Deploy becomes Keep1 at the stage-1 keep length
    /// (less the capture), Slew becomes Retrieve once α_r meets the Eq. 35 schedule, Retrieve
    /// becomes Keep2 at the stage-2 keep length (plus the capture).
    #[inline(always)]
    fn update_phase(&mut self, length_m: T, slewing: bool) {
        if self.phase == Phase::Slew {
            if !slewing {
                self.enter(Phase::Retrieve);
            }
        } else if self.capture_sign * length_m >= self.capture_m {
            match self.phase {
                Phase::Deploy => self.enter(Phase::Keep1),
                Phase::Retrieve => self.enter(Phase::Keep2),
                _ => {}
            }
        }
    }

    /// Makes `phase` the current phase, with its length capture.
    #[inline(always)]
    fn enter(&mut self, phase: Phase) {
        let never = T::from_f64(f64::INFINITY);
        (self.capture_sign, self.capture_m) = match phase {
            Phase::Deploy => (T::ONE, self.derived.keep1_entry_m),
            Phase::Retrieve => (-T::ONE, -self.derived.keep2_entry_m),
            Phase::Keep1 | Phase::Slew | Phase::Keep2 => (T::ONE, never),
        };
        self.phase = phase;
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::{Event, EventKind, EventRing, Phase, EVENT_CAPACITY};
    use std::{vec, vec::Vec};

    fn event(i: u32) -> Event {
        Event {
            tick: i,
            kind: EventKind::Phase(Phase::Deploy),
        }
    }

    fn drain(ring: &mut EventRing) -> Vec<u32> {
        core::iter::from_fn(|| ring.pop()).map(|e| e.tick).collect()
    }

    #[test]
    fn ring_keeps_the_newest_and_counts_the_overwritten() {
        let mut ring = EventRing::new();
        assert_eq!(ring.pop(), None);
        for i in 0..3 {
            ring.push(event(i));
        }
        assert_eq!((drain(&mut ring), ring.dropped()), (vec![0, 1, 2], 0));
        // 16 + 5 unread: the 5 oldest are overwritten, counted before and after the read.
        for i in 3..3 + EVENT_CAPACITY as u32 + 5 {
            ring.push(event(i));
        }
        assert_eq!(ring.dropped(), 5);
        let expected: Vec<u32> = (8..24).collect();
        assert_eq!(drain(&mut ring), expected);
        assert_eq!(ring.dropped(), 5);
        // A partial read, then more than a ring's worth: only the unread are lost.
        for i in 24..30 {
            ring.push(event(i));
        }
        assert_eq!(ring.pop().map(|e| e.tick), Some(24));
        for i in 30..50 {
            ring.push(event(i));
        }
        assert_eq!(ring.dropped(), 5 + 9);
        assert_eq!(drain(&mut ring), (34..50).collect::<Vec<u32>>());
    }

    #[test]
    fn ring_counters_wrap_around() {
        let mut ring = EventRing::new();
        ring.written = u32::MAX - 2;
        ring.read = u32::MAX - 2;
        for i in 0..EVENT_CAPACITY as u32 + 2 {
            ring.push(event(i));
        }
        assert_eq!(ring.written, EVENT_CAPACITY as u32 - 1);
        assert_eq!(ring.dropped(), 2);
        assert_eq!(drain(&mut ring), (2..18).collect::<Vec<u32>>());
        assert_eq!((ring.pop(), ring.dropped()), (None, 2));
    }
}
