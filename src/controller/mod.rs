//! The reel controller: one fixed-step [`Controller::step`] from sensed length, α (and α̇, or
//! the onboard estimate of it) and orbit rate to a reel-rate command, through the reference schedules (Eqs. 34, 35), the implicit
//! range-rate law (Eq. 27 + 29, docs/equations.md §5), the commanded acceleration (Eq. 30) and the mission
//! sequencer (docs/equations.md §7).
//!
//! ```
//! use tss_reel::controller::{Config, Controller, Input, Phase};
//!
//! // The paper's mission, stage 2 at t = 8 h, 1 s control period.
//! let mut ctl = Controller::new(Config::<f32>::paper()).expect("the paper's numbers are valid");
//! let out = *ctl.step(&Input {
//!     tick: 0,
//!     length_m: 1.0,
//!     reel_rate_mps: None,
//!     tension_n: None,
//!     alpha_rad: Some(-35.0_f32.to_radians()),
//!     alpha_rate_radps: Some(0.0),
//!     orbit_rate_radps: 1.0602e-3,
//!     true_anomaly_rad: 0.0,
//! });
//! // The output, copied out of the controller (`step` returns a reference to the one it keeps),
//! // can be read while the controller is used again.
//! while let Some(event) = ctl.pop_event() {
//!     assert_eq!(event.tick, 0); // the stage-1 blend started
//! }
//! assert_eq!(out.phase, Phase::Deploy);
//! assert!((out.rate_cmd_mps - 0.1).abs() < 1e-6); // the blend starts from l̇0 = 0.1 m/s
//! assert!(out.fault.is_none());
//! assert_eq!(ctl.output(), &out);
//! ```
//!
//! A step reads as the paper's loop and PX4's `PositionControl` do, one stage after another,
//! each handing the next a typed value:
//!
//! ```text
//!   check     the sample (crate::monitor)                       → the accepted sample
//!   estimate  α and α̇: sensed, or the onboard EKF's             → Sensed
//!   sequence  stages, phases, α_r (sequencer)                    → Reference
//!   law       Eqs. 27 + 29 and the Eq. 30 acceleration           → Solved (the demand)
//!   shape     the tension loop (docs/equations.md §17)            → Shaped (the demand)
//!   limit     the envelope and the protection's bounds           → Decided (the command)
//!   report    the output, and the events of what changed since the last report
//! ```
//!
//! A stage that finds nothing the law may fly on (no usable sample, no estimate, a singular
//! point of the law, safe hold not yet recovered) hands over to the safe action instead
//! (`hold`), which the health state machine (`health`) chooses on the dead-reckoned length;
//! its command is reported the same way.
//!
//! Time is an integer tick count (one tick = one control period); the controller never
//! accumulates time in floating point.
//!
//! # Flying on the estimator
//!
//! [`RateSource::Sensor`] (the paper's idealisation, [`Config::paper`], Table 1) flies the law
//! on the sensed α and α̇. [`RateSource::Estimator`] ([`Config::flight`], the firmware's) flies
//! it on α̂ and α̇̂ of the onboard EKF ([`crate::estimator`]) from α alone, stepped once per
//! period inside the step (docs/equations.md §13): the estimate is carried over the period
//! under the drive the last step commanded (or the encoder's measured rate), then updated with
//! this period's α. For the fault logic:
//!
//! - a sample the χ² gate rejects is a bad sample ([`Sensor::AlphaGated`]); after
//!   `max_rejections` in a row the next one restarts α ([`EventKind::EstimateRestarted`]);
//! - a period without α (the swing sensor silent, the rest of the sample good) is predicted
//!   only and is **not** a bad sample, until the estimate is useless: Var(α̂) above
//!   [`MAX_ALPHA_VARIANCE_IN_SAMPLES`] times the α sample's variance R (its standard deviation
//!   ten times the sensor's), or no estimate at all (before the first α, or after the filter
//!   dropped it: [`EventKind::EstimateLost`]) — then [`Sensor::AlphaLost`];
//! - α̇ in the sample is not looked at; the monitor's α-jump check (judged on a sensed α̇)
//!   gives way to the gate, and its α-stuck check to a run of `stuck_ticks` bit-identical α
//!   readings, which the sensor's noise does not make ([`Sensor::AlphaStuck`],
//!   docs/equations.md §13);
//! - the encoder's reel rate, the drive of the prediction, is checked by the monitor
//!   ([`Sensor::ReelRate`]): a sample with a reel rate it rejects is a bad sample, and the
//!   estimate is carried over the period at the command;
//! - so is the orbit rate θ̇, which on a circular orbit gives the prediction's θ̇ and μ/R³ = θ̇²
//!   ([`Sensor::OrbitRate`]): the configuration is refused unless the monitor's band
//!   (`monitor.min_orbit_rate_radps` to `monitor.max_orbit_rate_radps`) lies within the rates
//!   the estimator admits, so a θ̇ the monitor accepts is one the prediction may use.
//!
//! On either rate source, an α (sensed, or α̂) beyond [`MAX_LIBRATION_RAD`] is a libration
//! beyond the law's domain ([`Fault::Libration`]): safe hold at once, the reel brought to rest
//! (at a constant length the swing's energy is conserved, and pays out or winds in no more), until
//! `recovery_ticks` samples in a row are back inside.

mod clock;
mod command;
mod drive;
mod estimation;
mod events;
mod health;
mod output;
pub(crate) mod protection;
mod report;
mod sequencer;
mod tension;

use crate::envelope::{Bounds, PreparedEnvelope};
use crate::equilibrium::ExistenceMonitor;
use crate::estimator::Estimate;
use crate::law::{self, LawInput};
use crate::monitor::{Monitor, Swing, SPOOL_MARGIN};
use crate::real::Real;
use crate::schedule::Reference;

pub use crate::config::{
    Config, ConfigError, MonitorConfig, ProtectionConfig, RateSource, Rule, Stage1Config,
    Stage2Config, TensionLoopConfig, MAX_PLAUSIBLE_TENSION_N,
};
pub use crate::envelope::Envelope;
pub use crate::monitor::{Input, Sensor};
pub use command::{Mode, ModeCommand, Refusal};
pub use events::{Event, EventKind, EVENT_CAPACITY};
pub use output::{Fault, Flags, Health, Output, Phase};
pub use protection::MARGIN_OF_GRAVITY_GRADIENT;

use clock::{Clock, Elapsed};
use estimation::{Estimated, Estimation};
use events::EventQueue;
use health::{DeadReckoning, HealthMachine};
use protection::{FreeTensionModel, Protection};
use report::Reported;
use sequencer::Sequencer;
use tension::{RestInput, StageInput, TensionStage};

pub use tension::TensionLoopMode;

pub use estimation::{MAX_ALPHA_VARIANCE_IN_SAMPLES, MAX_CARRIED_PERIODS, MAX_LIBRATION_RAD};
pub use sequencer::PROGRESS_TIME_CONSTANTS;

/// Bound on the reported [`Output::equilibrium_margin`] (x grows as 1/l toward docking).
pub const MAX_REPORTED_MARGIN: f64 = 1e6;

/// The reel controller (see the module docs for a complete example).
#[derive(Clone, Debug)]
pub struct Controller<T: Real> {
    cfg: Config<T>,
    /// The envelope, its guarded length limits worked out.
    envelope: PreparedEnvelope<T>,
    /// The tension- and drive-aware protection (None: not configured).
    protection: Option<Protection<T>>,
    existence: ExistenceMonitor<T>,
    monitor: Monitor<T>,
    /// The estimator the law flies on (`None`: it flies on the sensed α̇).
    estimation: Option<Estimation<T>>,
    /// The tension loop between the law and the limits (None: not configured).
    tension: Option<TensionStage<T>>,
    sequencer: Sequencer<T>,
    health: HealthMachine,
    length: DeadReckoning<T>,
    /// The time base: the last accepted tick.
    clock: Clock,
    /// The safe hold's largest change of rate in one period, m/s: the smaller of
    /// `monitor.safe_hold_decel_mps2` and the envelope's acceleration limit, times the period.
    safe_hold_step_mps: T,
    /// The command of the last step: the reel ran at it over the period that just ended (l̇0
    /// and no acceleration before the first step).
    last_command: Command<T>,
    /// What the last step reported, the "before" of this step's events.
    reported: Reported,
    events: EventQueue,
    /// The last step's output ([`Controller::output`]).
    out: Output<T>,
}

/// A command for the coming period: the reel rate and its acceleration.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Command<T> {
    /// Reel-rate command l̇_real, m/s.
    rate_mps: T,
    /// Commanded reel acceleration, m/s².
    accel_mps2: T,
}

/// A period in which time moved: how far, and the length predicted for its end.
#[derive(Clone, Copy, Debug)]
struct Period<T> {
    /// The tick time moved to.
    tick: u32,
    /// Periods since the last accepted tick (0 at the first step).
    elapsed_ticks: u32,
    /// The length dead-reckoned from the last command, m (`None` before the first accepted
    /// sample).
    predicted_m: Option<T>,
}

/// A sample the law may fly on: checked, with the α and α̇ it flies on (sensed, or the
/// estimator's).
#[derive(Clone, Copy, Debug)]
struct Sensed<'a, T> {
    input: &'a Input<T>,
    alpha_rad: T,
    alpha_rate_radps: T,
}

/// Why the law does not fly this period, and what the safe action knows.
#[derive(Clone, Copy, Debug)]
struct Unusable<T> {
    fault: Fault,
    /// The length to coast from: the prediction, or the sensed length of a valid sample the
    /// law could not use, m.
    length_m: Option<T>,
    /// α_r, when the reference was already worked out at the sensed length, rad.
    alpha_ref_rad: Option<T>,
}

/// What the sequencer makes of a usable sample.
#[derive(Clone, Copy, Debug)]
enum Sequenced<T> {
    /// The law flies on this reference.
    Law(Reference<T>),
    /// The reel stays held: safe hold until the inputs have recovered, or a hold by command;
    /// α_r at the sensed length, rad.
    Held { alpha_ref_rad: T },
}

/// The law's solution of this period (Eqs. 27, 29, 30): the command it asks for before the
/// limits, and what the limits and the report need of it.
#[derive(Clone, Copy, Debug)]
struct Solved<T> {
    demand: Command<T>,
    parts: LawParts<T>,
    /// μ3 at the sensed length.
    mu3: T,
    /// The reduced length the law's normalised rate is worked out at, m.
    reduced_length_m: T,
    /// The Eq. 29 blend weight E.
    blend_weight: T,
    /// cos 2α of the solution, for the protection's model of Eq. 5a's free tension.
    cos_two_alpha: T,
}

/// The law's demand after the tension loop (docs/equations.md §17): shaped to what the tether
/// carries, with the admittance term that damps its bounce; the law's own without a loop.
#[derive(Clone, Copy, Debug)]
struct Shaped<T> {
    demand: Command<T>,
    /// [`Flags::TENSION_SHAPED`], [`Flags::LOAD_CELL_LOST`].
    flags: Flags,
}

/// A step's command, limited, with what the report says about it.
#[derive(Clone, Copy, Debug)]
struct Decided<T> {
    command: Command<T>,
    /// The length the command was judged at (sensed or estimated), m.
    length_m: T,
    /// μ3 at that length.
    mu3: T,
    /// The normalised rate x = (2 + μ3) l̇/(ωl) of the command (Eq. 7).
    normalised_rate: T,
    /// α_r, rad.
    alpha_ref_rad: T,
    /// The Eq. 29 blend weight E.
    blend_weight: T,
    /// The law's parts (zero when a safe action stood in for the law).
    law: LawParts<T>,
    /// The limits that acted, and the step's own status bits.
    flags: Flags,
    /// The fault behind a safe action.
    fault: Option<Fault>,
}

/// The parts of the law's solution the output reports.
#[derive(Clone, Copy, Debug)]
struct LawParts<T> {
    law_rate_mps: T,
    ref_rate_radps: T,
    delta_rad: T,
    delta_rate_radps: T,
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
        // The longest plausible length: the spool end plus the monitor's margin.
        let spool_m = T::from_f64(cfg.envelope.max_length_m.to_f64() * (1.0 + SPOOL_MARGIN));
        let estimation = match &cfg.rate_source {
            RateSource::Sensor => None,
            RateSource::Estimator(est) => Some(Estimation::new(
                est,
                &cfg.orbit,
                cfg.tension_loop.as_ref(),
                &cfg.monitor,
            )?),
        };
        let sequencer = Sequencer::new(&cfg);
        Ok(Self {
            envelope: PreparedEnvelope::new(cfg.envelope),
            protection: cfg.protection.map(|p| {
                let env = &cfg.envelope;
                Protection::new(
                    p,
                    cfg.masses,
                    cfg.period_s,
                    env.max_rate_mps,
                    cfg.initial_rate_mps,
                )
            }),
            existence,
            monitor: Monitor::new(spool_m, cfg.envelope.max_rate_mps, estimation.is_none())?,
            estimation,
            tension: cfg.tension_loop.map(|t| {
                TensionStage::new(t, cfg.masses, cfg.period_s, cfg.envelope.max_accel_mps2)
            }),
            reported: Reported {
                health: Health::Nominal,
                phase: sequencer.phase(),
                fault: None,
                blend_restarts: sequencer.blend_restarts(),
                stalled: false,
                tension_limited: false,
            },
            sequencer,
            health: HealthMachine::new(),
            length: DeadReckoning::new(spool_m),
            clock: Clock::new(),
            safe_hold_step_mps: cfg
                .monitor
                .safe_hold_decel_mps2
                .min(cfg.envelope.max_accel_mps2)
                * cfg.period_s,
            last_command: Command {
                rate_mps: cfg.initial_rate_mps,
                accel_mps2: T::ZERO,
            },
            events: EventQueue::new(),
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
                nis: None,
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

    /// Flying on the estimator: the estimate after the last step (`None` before the first α,
    /// after the estimate was lost, and on the rate sensor).
    pub fn estimate(&self) -> Option<Estimate<T>> {
        self.estimation.as_ref().and_then(Estimation::estimate)
    }

    /// The current phase.
    pub fn phase(&self) -> Phase {
        self.sequencer.phase()
    }

    /// The current input health.
    pub fn health(&self) -> Health {
        self.health.health()
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

    /// Asks for stage 2 (retrieval) to begin at the next step, whatever the configured start.
    pub fn start_stage2(&mut self) {
        self.sequencer.request_stage2();
    }

    /// A mission-mode command (docs/equations.md §7.1): taken if it is legal in the current
    /// mode and phase and no other command waits, and applied at the next period boundary
    /// (then [`EventKind::Command`]); refused, it changes nothing.
    pub fn command(&mut self, command: ModeCommand) -> Result<(), Refusal> {
        self.sequencer.command(command)
    }

    /// The mode: flying, or held by command ([`Flags::HELD`], [`Flags::ABORTED`]).
    pub fn mode(&self) -> Mode {
        self.sequencer.mode()
    }

    /// One control period with a fresh sensor sample: the command for the coming period and
    /// what it was made of, the output the controller keeps ([`Controller::output`]).
    pub fn step(&mut self, input: &Input<T>) -> &Output<T> {
        self.run(input.tick, Some(input))
    }

    /// One control period in which no sample arrived (a sensor dropout): the controller coasts
    /// on the predicted length, then goes to safe hold (see [`Health`]). Its output, as
    /// [`Controller::step`]'s.
    pub fn step_missing(&mut self, tick: u32) -> &Output<T> {
        self.run(tick, None)
    }

    /// A step: its command decided, then reported (kept as the last output).
    fn run(&mut self, tick: u32, sample: Option<&Input<T>>) -> &Output<T> {
        let decided = self.decide(tick, sample);
        self.report(tick, &decided);
        &self.out
    }

    /// The command of one period: check → estimate → sequence → law → shape → limit, or the
    /// safe action where a stage finds nothing the law may fly on.
    fn decide(&mut self, tick: u32, sample: Option<&Input<T>>) -> Decided<T> {
        let period = match self.clock.advance(tick) {
            Ok(elapsed) => self.begin_period(tick, elapsed, sample),
            Err(s) => return self.reject_stale(tick, Fault::Sensor(s)),
        };
        let checked = self.check(&period, sample);
        let sensed = match self.estimate_swing(&period, checked) {
            Ok(sensed) => sensed,
            Err(unusable) => return self.reject(tick, unusable),
        };
        let reference = match self.sequence(tick, &sensed) {
            Sequenced::Law(reference) => reference,
            Sequenced::Held { alpha_ref_rad } => {
                return self.hold(tick, true, Some(sensed.input), alpha_ref_rad, None)
            }
        };
        let solved = match self.law(tick, &sensed, &reference) {
            Ok(solved) => solved,
            Err(unusable) => return self.reject(tick, unusable),
        };
        self.advance_phase(tick, &sensed, &reference);
        let shaped = self.shape(tick, &sensed, &solved);
        self.limit(&sensed, &reference, &solved, &shaped)
    }

    /// The start of a period in which time moved to `tick`: the mission's stages begin when
    /// due (stage 1 with the first step, stage 2 at its tick or on command, restarting the
    /// blend), a mode command that waits is applied, the protection's drive model runs over the periods that passed, and the length
    /// is dead-reckoned at the last command.
    fn begin_period(
        &mut self,
        tick: u32,
        elapsed: Elapsed,
        sample: Option<&Input<T>>,
    ) -> Period<T> {
        let elapsed_ticks = match elapsed {
            Elapsed::First => {
                self.sequencer.begin_stage1(tick);
                0
            }
            Elapsed::Ticks(n) => n,
        };
        let last = self.last_command;
        if let Some(p) = &mut self.protection {
            p.advance(
                last.rate_mps,
                last.accel_mps2,
                elapsed_ticks,
                sample.and_then(|x| x.reel_rate_mps),
                sample.and_then(|x| x.tension_n),
            );
        }
        let elapsed_s = T::from_u32(elapsed_ticks) * self.cfg.period_s;
        let predicted_m = self.length.predict(last.rate_mps, elapsed_s);
        if self.sequencer.command_waits() {
            self.apply_command(tick, last.rate_mps);
        }
        self.sequencer.begin_stage2_if_due(tick, last.rate_mps);
        Period {
            tick,
            elapsed_ticks,
            predicted_m,
        }
    }

    /// The mode command that waits, applied at the boundary `tick` with the reel at `rate_mps`
    /// ([`EventKind::Command`]).
    // Out of line: inlined into the step, the command's match becomes a computed branch
    // (`mov pc`) there, which scripts/panic-check cannot follow; a command waits in few periods.
    #[inline(never)]
    fn apply_command(&mut self, tick: u32, rate_mps: T) {
        let applied = self.sequencer.apply_pending(tick, rate_mps);
        self.events.record(tick, applied.map(EventKind::Command));
    }

    /// Check the sample ([`crate::monitor`]). Before the first accepted sample, and in safe
    /// hold, there is no trusted prediction of the length: the next valid sample (re-)anchors
    /// it.
    fn check<'a>(
        &mut self,
        period: &Period<T>,
        sample: Option<&'a Input<T>>,
    ) -> Result<(&'a Input<T>, Swing<T>), Sensor> {
        let expected = match self.health.health() {
            Health::SafeHold => None,
            Health::Nominal | Health::Degraded => period.predicted_m,
        };
        let x = sample.ok_or(Sensor::Missing)?;
        let swing = self
            .monitor
            .check(&self.cfg.monitor, x, expected, self.cfg.period_s)?;
        Ok((x, swing))
    }

    /// The α and α̇ the law flies on: the sensed ones, or the estimate carried over the periods
    /// that passed (whether or not the sample was accepted) and updated with the sample's α.
    /// An estimator event is recorded as it happens.
    fn estimate_swing<'a>(
        &mut self,
        period: &Period<T>,
        checked: Result<(&'a Input<T>, Swing<T>), Sensor>,
    ) -> Result<Sensed<'a, T>, Unusable<T>> {
        let (accepted, swing) = match &checked {
            Ok((x, swing)) => (Some(*x), *swing),
            Err(_) => (None, Swing::Angle(None)),
        };
        let angles = match (&mut self.estimation, swing) {
            (None, Swing::Sensed(alpha_rad, alpha_rate_radps)) => Ok((alpha_rad, alpha_rate_radps)),
            (Some(est), Swing::Angle(alpha_rad)) => {
                let (verdict, event) = est.step(period.elapsed_ticks, accepted, alpha_rad);
                self.events.record(period.tick, event);
                match verdict {
                    Estimated::Usable(alpha_rad, alpha_rate_radps) => {
                        Ok((alpha_rad, alpha_rate_radps))
                    }
                    Estimated::Unusable(s) => Err(s),
                }
            }
            // Not reached: the monitor checks the angles by the same rate source.
            (None, Swing::Angle(_)) => Err(Sensor::AlphaRate),
            (Some(_), Swing::Sensed(..)) => Err(Sensor::AlphaLost),
        };
        match (checked, angles) {
            (Err(s), _) => Err(Unusable {
                fault: Fault::Sensor(s),
                length_m: period.predicted_m,
                alpha_ref_rad: None,
            }),
            (Ok((x, _)), Err(s)) => Err(Unusable {
                fault: Fault::Sensor(s),
                length_m: Some(x.length_m),
                alpha_ref_rad: None,
            }),
            (Ok((x, _)), Ok((alpha_rad, _)))
                if alpha_rad.abs() > T::from_f64(MAX_LIBRATION_RAD) =>
            {
                Err(Unusable {
                    fault: Fault::Libration,
                    length_m: Some(x.length_m),
                    alpha_ref_rad: None,
                })
            }
            (Ok((x, _)), Ok((alpha_rad, alpha_rate_radps))) => {
                self.length.sensed(x.length_m);
                Ok(Sensed {
                    input: x,
                    alpha_rad,
                    alpha_rate_radps,
                })
            }
        }
    }

    /// Sequence the mission (docs/equations.md §7): α_r of the phase at the sensed length. In
    /// safe hold the law re-engages only once the inputs have recovered, through the Eq. 29
    /// blend restarted from the current rate; held by command (§7.1), it does not, and the
    /// sample counts as usable.
    fn sequence(&mut self, tick: u32, s: &Sensed<T>) -> Sequenced<T> {
        let x = s.input;
        let reference = self
            .sequencer
            .reference_at(tick, x.length_m, x.true_anomaly_rad);
        if self.health.health() == Health::SafeHold {
            if !self.health.recovered(&self.cfg.monitor) {
                let alpha_ref_rad = reference.angle.angle_rad;
                return Sequenced::Held { alpha_ref_rad };
            }
            self.sequencer
                .restart_blend(tick, self.last_command.rate_mps);
        }
        if self.sequencer.mode().holds() {
            self.health.usable();
            let alpha_ref_rad = reference.angle.angle_rad;
            return Sequenced::Held { alpha_ref_rad };
        }
        Sequenced::Law(reference)
    }

    /// The law: Eqs. 27 + 29 solved implicitly for the rate, and the Eq. 30 acceleration. A
    /// solution makes the sample usable for the health machine; a singular point is a fault.
    fn law(
        &mut self,
        tick: u32,
        s: &Sensed<T>,
        reference: &Reference<T>,
    ) -> Result<Solved<T>, Unusable<T>> {
        let x = s.input;
        let (mu3, mu3_per_m) = self.cfg.masses.mu3_and_slope(x.length_m);
        let input = LawInput {
            length_m: x.length_m,
            alpha_rad: s.alpha_rad,
            alpha_rate_radps: s.alpha_rate_radps,
            orbit_rate_radps: x.orbit_rate_radps,
            orbit: reference.orbit,
            ref_angle_rad: reference.angle.angle_rad,
            ref_slope_rad_per_m: reference.angle.slope_rad_per_m,
            ref_curvature_rad_per_m2: reference.angle.curvature_rad_per_m2,
            ref_time_rate_radps: reference.time_rate_radps,
            mu3,
            mu3_per_m,
            blend: self.sequencer.carry_blend_to(tick),
            decay_rate_per_s: self.sequencer.blend_decay_rate_per_s(),
            initial_rate_mps: self.sequencer.blend_initial_rate_mps(),
            gains: self.cfg.gains,
        };
        let solved = law::solve(&input).and_then(|solution| {
            let accel_mps2 = law::acceleration(&input, &solution)?;
            Ok((solution, accel_mps2))
        });
        let (solution, accel_mps2) = solved.map_err(|f| Unusable {
            fault: Fault::Law(f),
            length_m: Some(x.length_m),
            alpha_ref_rad: Some(reference.angle.angle_rad),
        })?;
        self.health.usable();
        if let Some(est) = &mut self.estimation {
            est.lend_sin_cos_two_alpha(s.alpha_rad, solution.sin_two_alpha, solution.cos_two_alpha);
        }
        Ok(Solved {
            demand: Command {
                rate_mps: solution.rate_mps,
                accel_mps2,
            },
            parts: LawParts {
                law_rate_mps: solution.law_rate_mps,
                ref_rate_radps: solution.ref_rate_radps,
                delta_rad: solution.delta_rad,
                delta_rate_radps: solution.delta_rate_radps,
            },
            mu3,
            reduced_length_m: solution.reduced_length_m,
            blend_weight: input.blend.weight,
            cos_two_alpha: solution.cos_two_alpha,
        })
    }

    /// Sequence the mission after a step of the law: the phase at the sensed length, and its
    /// progress toward its keep length.
    fn advance_phase(&mut self, tick: u32, s: &Sensed<T>, reference: &Reference<T>) {
        self.sequencer
            .advance_phase(tick, s.input.length_m, reference.slewing);
    }

    /// The tension loop (docs/equations.md §17): the law's demand shaped to the accelerations
    /// the tether carries, plus the admittance term that damps its bounce, from the sample's
    /// load cell. A change of the loop's mode is an event at `tick`. Without a loop, the law's
    /// demand as it is.
    fn shape(&mut self, tick: u32, s: &Sensed<T>, solved: &Solved<T>) -> Shaped<T> {
        let mut flags = Flags::default();
        let Some(stage) = &mut self.tension else {
            return Shaped {
                demand: solved.demand,
                flags,
            };
        };
        let out = stage.step(&StageInput {
            law_rate_mps: solved.demand.rate_mps,
            law_accel_mps2: solved.demand.accel_mps2,
            previous_mps: self.last_command.rate_mps,
            length_m: s.input.length_m,
            delta_rad: solved.parts.delta_rad,
            tension_n: s.input.tension_n,
        });
        flags.set_if(out.shaped, Flags::TENSION_SHAPED);
        flags.set_if(stage.mode() == TensionLoopMode::Lost, Flags::LOAD_CELL_LOST);
        self.events
            .record(tick, out.mode_changed.map(EventKind::TensionLoop));
        Shaped {
            demand: Command {
                rate_mps: out.rate_mps,
                accel_mps2: out.accel_mps2,
            },
            flags,
        }
    }

    /// Limit the (shaped) demand to the envelope and the protection's bounds. The acceleration
    /// limit holds per command: a command differs from the previous one by at most a·Δt,
    /// whatever the calls' pattern (a gap of n ticks does not allow n·a·Δt: the reel ran at the
    /// previous command all along, and would step).
    fn limit(
        &mut self,
        s: &Sensed<T>,
        reference: &Reference<T>,
        solved: &Solved<T>,
        shaped: &Shaped<T>,
    ) -> Decided<T> {
        let (l, dt) = (s.input.length_m, self.cfg.period_s);
        let previous = self.last_command.rate_mps;
        let x = s.input;
        let model = self.protection.is_some().then(|| {
            FreeTensionModel::at(
                l,
                x.orbit_rate_radps,
                reference.orbit.as_ref(),
                s.alpha_rate_radps,
                solved.cos_two_alpha,
            )
        });
        let bounds = self.bounds(model.as_ref(), previous, true);
        let demand = shaped.demand;
        let (rate_mps, accel_mps2, sat) =
            self.envelope
                .limit_law(demand.rate_mps, demand.accel_mps2, previous, l, dt, &bounds);
        let mut flags = Flags(sat.0 | shaped.flags.0);
        flags.set_if(reference.slewing, Flags::SLEWING);
        Decided {
            command: Command {
                rate_mps,
                accel_mps2,
            },
            length_m: l,
            mu3: solved.mu3,
            normalised_rate: self
                .existence
                .normalised_rate_at_reduced_length(solved.reduced_length_m, rate_mps),
            alpha_ref_rad: reference.angle.angle_rad,
            blend_weight: solved.blend_weight,
            law: solved.parts,
            flags,
            fault: None,
        }
    }

    /// The protection's bounds of this step, from the law's state `model` (`None` when the law
    /// did not run: the model is stale, the free tension the load cell's own; the law's step
    /// builds it only for a protection); none without a protection. `shared`: the law's command, whose floor gives way to the attitude as the
    /// tension loop's window does (docs/equations.md §17.5), when there is a tension loop.
    fn bounds(
        &mut self,
        model: Option<&FreeTensionModel<T>>,
        previous_mps: T,
        shared: bool,
    ) -> Bounds<T> {
        let dt = self.cfg.period_s;
        let Some(p) = &mut self.protection else {
            return Bounds::none();
        };
        let bounds = p.bounds(model, previous_mps, dt);
        match &self.tension {
            Some(t) if shared => t.share_bounds(bounds, previous_mps, dt),
            _ => bounds,
        }
    }

    /// No usable sample or no law solution at this tick: the health machine counts it (a
    /// libration beyond the law's domain is safe hold at once), and the length to coast from
    /// becomes the length estimate. Then the safe action.
    fn reject(&mut self, tick: u32, unusable: Unusable<T>) -> Decided<T> {
        self.length.coast(unusable.length_m);
        match unusable.fault {
            Fault::Libration => self.health.force_safe_hold(),
            _ => self.health.unusable(&self.cfg.monitor),
        }
        // Without a usable sample, α_r is reported at the estimated length.
        let alpha_ref_rad = unusable.alpha_ref_rad.unwrap_or_else(|| {
            let l = self.length.length_m().unwrap_or(T::ZERO);
            self.sequencer.reference(tick, l).angle.angle_rad
        });
        self.hold(tick, true, None, alpha_ref_rad, Some(unusable.fault))
    }

    /// A sample whose tick did not move forward: a bad sample for the health machine, at a
    /// time that did not move. The length estimate stays, and so does the command (no time
    /// passed for the acceleration limit to allow a change, in any health state); α_r and the
    /// blend are reported at the last accepted tick. A clock that stops for good therefore
    /// ends in safe hold with the command held where it was, until time moves again.
    fn reject_stale(&mut self, tick: u32, fault: Fault) -> Decided<T> {
        self.health.unusable(&self.cfg.monitor);
        // (Only a tick after an accepted one can be stale or repeated.)
        let now = self.clock.last_tick().unwrap_or(tick);
        let l = self.length.length_m().unwrap_or(T::ZERO);
        let alpha_ref_rad = self.sequencer.reference(now, l).angle.angle_rad;
        self.hold(now, false, None, alpha_ref_rad, Some(fault))
    }

    /// The safe actions at `now` (`time_moved`: to `now`; otherwise `now` is the last accepted
    /// tick). Degraded: keep the last command (coast). Safe hold, and a hold by command in any
    /// health: ramp the rate to zero at `monitor.safe_hold_decel_mps2` (at most the envelope's
    /// limit), on a sample the monitor `accepted` with the tension loop's admittance term added,
    /// which damps the tether's bounce the stop excites (docs/equations.md §17.8). When time
    /// did not move, the command stays. All stay inside the length limits, judged on the
    /// estimated length (before any accepted sample, on the docking end: 0 m).
    fn hold(
        &mut self,
        now: u32,
        time_moved: bool,
        accepted: Option<&Input<T>>,
        alpha_ref_rad: T,
        fault: Option<Fault>,
    ) -> Decided<T> {
        let dt = self.cfg.period_s;
        let previous = self.last_command.rate_mps;
        let mode = self.sequencer.mode();
        let ramps = match (time_moved, self.health.health(), mode.holds()) {
            (false, _, _) | (true, Health::Degraded, false) => false,
            (true, Health::Nominal | Health::SafeHold, _) | (true, Health::Degraded, true) => true,
        };
        let step = self.safe_hold_step_mps;
        let target = match (&mut self.tension, accepted.filter(|_| ramps)) {
            (Some(t), Some(x)) => {
                let (target, mode_changed) = t.bring_to_rest(&RestInput {
                    previous_mps: previous,
                    step_mps: step,
                    length_m: x.length_m,
                    tension_n: x.tension_n,
                });
                self.events
                    .record(now, mode_changed.map(EventKind::TensionLoop));
                target
            }
            (tension, _) => {
                if let Some(t) = tension {
                    t.skipped();
                }
                if ramps {
                    previous - previous.clamp_finite(-step, step)
                } else {
                    previous
                }
            }
        };
        let length_m = self.length.length_m().unwrap_or(T::ZERO);
        let bounds = self.bounds(None, previous, false);
        let (rate_mps, sat) = self
            .envelope
            .limit_request(target, previous, length_m, dt, &bounds);
        let mut flags = Flags(sat.0 & (Flags::LENGTH_LIMITED | Flags::TENSION_LIMITED));
        flags.set(Flags::SAFE_ACTION);
        flags.set_if(matches!(mode, Mode::Held { .. }), Flags::HELD);
        flags.set_if(mode == Mode::Aborted, Flags::ABORTED);
        let mu3 = self.cfg.masses.mu3_and_slope(length_m).0;
        Decided {
            command: Command {
                rate_mps,
                accel_mps2: (rate_mps - previous) / dt,
            },
            length_m,
            mu3,
            normalised_rate: self.existence.normalised_rate(mu3, length_m, rate_mps),
            alpha_ref_rad,
            blend_weight: self.sequencer.carry_blend_to(now).weight,
            law: LawParts {
                law_rate_mps: T::ZERO,
                ref_rate_radps: T::ZERO,
                delta_rad: T::ZERO,
                delta_rate_radps: T::ZERO,
            },
            flags,
            fault,
        }
    }
}

#[cfg(test)]
mod tests;
