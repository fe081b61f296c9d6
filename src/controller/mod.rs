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
//! A step reads as the paper's loop and PX4's `PositionControl` do: check the inputs
//! ([`crate::monitor`]) → sequence the mission (`sequencer`: stages, phases, the Eq. 29
//! blend, α_r) → the law ([`crate::law`]) → the envelope ([`crate::envelope`]) → the output
//! and its events. Without a usable sample the health state machine (`health`) takes a
//! safe action on the dead-reckoned length instead of the law.
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
//! - α̇ in the sample is not looked at; the monitor's α-jump and α-stuck checks (judged on a
//!   sensed α̇) give way to the gate.

mod clock;
mod drive;
mod estimation;
mod events;
mod health;
mod output;
pub(crate) mod protection;
mod sequencer;

use crate::envelope::PreparedEnvelope;
use crate::equilibrium::ExistenceMonitor;
use crate::estimator::Estimate;
use crate::law::{self, LawInput};
use crate::monitor::{Monitor, Swing, SPOOL_MARGIN};
use crate::real::Real;

pub use crate::config::{
    Config, ConfigError, MonitorConfig, RateSource, Rule, Stage1Config, Stage2Config,
};
pub use crate::envelope::Envelope;
pub use crate::monitor::{Input, Sensor};
pub use events::{Event, EventKind, EVENT_CAPACITY};
pub use output::{Fault, Flags, Health, Output, Phase};
pub use protection::{ProtectionConfig, MARGIN_OF_GRAVITY_GRADIENT, MAX_PLAUSIBLE_TENSION_N};

use clock::{Clock, Elapsed};
use estimation::{Commanded, Estimated, Estimation};
use events::EventRing;
use health::{DeadReckoning, HealthMachine};
use protection::{Bounds, FreeTensionModel, Protection};
use sequencer::{Progress, Sequencer};

pub use estimation::{MAX_ALPHA_VARIANCE_IN_SAMPLES, MAX_CARRIED_PERIODS};
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
    sequencer: Sequencer<T>,
    health: HealthMachine,
    length: DeadReckoning<T>,
    /// The time base: the last accepted tick.
    clock: Clock,
    /// The safe hold's largest change of rate in one period, m/s: the smaller of
    /// `monitor.safe_hold_decel_mps2` and the envelope's acceleration limit, times the period.
    safe_hold_step_mps: T,
    /// The command of the last step, m/s (l̇0 before the first).
    last_rate_cmd_mps: T,
    /// The health of the last step (the `from` of a change of health, an event).
    last_health: Health,
    /// The fault of the last step (a fault is an event when it differs from the last).
    last_fault: Option<Fault>,
    /// The last step's command was tension limited (the limit beginning is an event).
    last_tension_limited: bool,
    events: EventRing,
    /// The last step's output ([`Controller::output`]).
    out: Output<T>,
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
            RateSource::Estimator(est) => {
                let rates = (
                    cfg.monitor.min_orbit_rate_radps,
                    cfg.monitor.max_orbit_rate_radps,
                );
                Some(Estimation::new(est, &cfg.orbit, rates)?)
            }
        };
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
            monitor: Monitor::new(spool_m, estimation.is_none())?,
            estimation,
            sequencer: Sequencer::new(&cfg),
            health: HealthMachine::new(),
            length: DeadReckoning::new(spool_m),
            clock: Clock::new(),
            safe_hold_step_mps: cfg
                .monitor
                .safe_hold_decel_mps2
                .min(cfg.envelope.max_accel_mps2)
                * cfg.period_s,
            last_rate_cmd_mps: cfg.initial_rate_mps,
            last_health: Health::Nominal,
            last_fault: None,
            last_tension_limited: false,
            events: EventRing::new(),
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
    /// after the estimate was lost, and on the rate sensor). By value: the filter keeps its
    /// state in its own form, and a step need not copy it out for a caller who may not ask.
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

    /// One control period with a fresh sensor sample: the command for the coming period and
    /// what it was made of, the output the controller keeps ([`Controller::output`]).
    // By reference, not a copy: the caller copies it out only if it keeps it (the firmware
    // reads it in place), 10 instructions less a step (scripts/bench-target, mission
    // 898/918 → 885/908, replay 885/955 → 875/945).
    pub fn step(&mut self, input: &Input<T>) -> &Output<T> {
        self.run(input.tick, Some(input))
    }

    /// One control period in which no sample arrived (a sensor dropout): the controller coasts
    /// on the predicted length, then goes to safe hold (see [`Health`]). Its output, as
    /// [`Controller::step`]'s.
    pub fn step_missing(&mut self, tick: u32) -> &Output<T> {
        self.run(tick, None)
    }

    /// A step, then its events and the kept output.
    fn run(&mut self, tick: u32, sample: Option<&Input<T>>) -> &Output<T> {
        self.decide(tick, sample);
        self.record_events();
        &self.out
    }

    /// Check inputs → sequence the mission → law → envelope → the output, kept in `self.out`.
    // The output is built in place rather than returned by value and then kept (one copy of
    // it less): with `record_events` inlined, 10 instructions less on the mission's worst step
    // (scripts/bench-target: 560 → 550).
    fn decide(&mut self, tick: u32, sample: Option<&Input<T>>) {
        let mut flags = Flags::default();
        let dt = self.cfg.period_s;

        // The time base: a tick that did not move forward (repeated, or from the past) is a
        // bad sample, and time does not move (see `clock`).
        let elapsed_ticks = match self.clock.advance(tick) {
            Ok(Elapsed::First) => {
                // Sequence the mission: stage 1 begins with the first step (docs/equations.md §7).
                self.sequencer.begin_stage1(tick, &mut flags);
                0
            }
            Ok(Elapsed::Ticks(n)) => n,
            Err(s) => return self.reject_stale(tick, Fault::Sensor(s), flags),
        };
        let elapsed_s = T::from_u32(elapsed_ticks) * dt;
        if let Some(p) = &mut self.protection {
            p.advance(
                self.last_rate_cmd_mps,
                self.out.accel_cmd_mps2,
                elapsed_ticks,
                sample.and_then(|x| x.reel_rate_mps),
                sample.and_then(|x| x.tension_n),
            );
        }
        // Dead reckoning: the reel ran at the last command since the last step.
        let predicted_m = self.length.predict(self.last_rate_cmd_mps, elapsed_s);

        // Sequence the mission: stage 2 at its tick or on command, restarting the blend.
        self.sequencer
            .begin_stage2_if_due(tick, self.last_rate_cmd_mps, &mut flags);

        // Check the inputs. Before the first accepted sample, and in safe hold, there is no
        // trusted prediction: the next valid sample (re-)anchors it.
        let expected = match self.health.health() {
            Health::SafeHold => None,
            Health::Nominal | Health::Degraded => predicted_m,
        };
        let checked = match sample {
            None => Err(Sensor::Missing),
            Some(x) => self
                .monitor
                .check(&self.cfg.monitor, x, expected, dt)
                .map(|swing| (x, swing)),
        };
        // The law's α and α̇: sensed, or estimated over the periods that passed (the estimate
        // is carried over the period whether or not the sample was accepted).
        let (accepted, swing) = match &checked {
            Ok((x, swing)) => (Some(*x), *swing),
            Err(_) => (None, Swing::Angle(None)),
        };
        let angles = self.swing(tick, elapsed_ticks, accepted, swing);
        let x = match checked {
            Ok((x, _)) => x,
            Err(s) => return self.reject(tick, predicted_m, Fault::Sensor(s), None, flags),
        };
        let (alpha_rad, alpha_rate_radps) = match angles {
            Ok(angles) => angles,
            Err(s) => {
                let sensed = Some(x.length_m);
                return self.reject(tick, sensed, Fault::Sensor(s), None, flags);
            }
        };
        self.length.sensed(x.length_m);

        let reference = self
            .sequencer
            .reference_at(tick, x.length_m, x.true_anomaly_rad);
        if self.health.health() == Health::SafeHold {
            if !self.health.recovered(&self.cfg.monitor) {
                return self.hold(tick, Some(tick), reference.angle.angle_rad, None, flags);
            }
            // Recovered: re-engage the law through the Eq. 29 blend from the current rate.
            self.sequencer
                .restart_blend(tick, self.last_rate_cmd_mps, &mut flags);
        }

        // The law: Eqs. 27 + 29 solved implicitly, and the Eq. 30 acceleration.
        let (mu3, mu3_per_m) = self.cfg.masses.mu3_and_slope(x.length_m);
        let law_in = LawInput {
            length_m: x.length_m,
            alpha_rad,
            alpha_rate_radps,
            orbit_rate_radps: x.orbit_rate_radps,
            orbit: reference.orbit,
            ref_angle_rad: reference.angle.angle_rad,
            ref_slope_rad_per_m: reference.angle.slope_rad_per_m,
            ref_curvature_rad_per_m2: reference.angle.curvature_rad_per_m2,
            ref_time_rate_radps: reference.time_rate_radps,
            mu3,
            mu3_per_m,
            blend: self.sequencer.blend(tick),
            decay_rate_per_s: self.sequencer.blend_decay_rate_per_s(),
            initial_rate_mps: self.sequencer.blend_initial_rate_mps(),
            gains: self.cfg.gains,
        };
        let (law, accel_mps2) =
            match law::solve(&law_in).and_then(|s| Ok((s, law::acceleration(&law_in, &s)?))) {
                Ok(v) => v,
                Err(f) => {
                    let alpha_ref = Some(reference.angle.angle_rad);
                    return self.reject(tick, Some(x.length_m), Fault::Law(f), alpha_ref, flags);
                }
            };
        self.health.usable(&mut flags);
        if let Some(est) = &mut self.estimation {
            est.lend_sin_cos_two_alpha(alpha_rad, law.sin_two_alpha, law.cos_two_alpha);
        }

        // Sequence the mission: the phase after this step of the law, and its progress. Before
        // the envelope, which neither reads nor changes them: the slew's flag is not carried
        // across it (mission worst 928 → 920, scripts/bench-target).
        flags.set_if(reference.slewing, Flags::SLEWING);
        match self
            .sequencer
            .advance_phase(tick, x.length_m, reference.slewing, &mut flags)
        {
            Progress::OnTrack => {}
            Progress::Stalled { first } => {
                flags.set(Flags::NO_PROGRESS);
                if first {
                    let kind = EventKind::NoProgress(self.sequencer.phase());
                    self.events.push(Event { tick, kind });
                }
            }
        }

        // The envelope. The acceleration limit holds per command: a command differs from the
        // previous one by at most a·Δt, whatever the calls' pattern (a gap of n ticks does
        // not allow n·a·Δt: the reel ran at the previous command all along, and would step).
        // The protection bounds it further by the tension the tether carries (and the drive).
        // One match on the protection, the envelope inlined into each arm: without one its
        // bounds are constants, and cost the step nothing (scripts/bench-target, mission
        // median 950 → 920, worst 980 → 948).
        let previous = self.last_rate_cmd_mps;
        let (env, l) = (&self.envelope, x.length_m);
        let (rate, accel, sat) = match &mut self.protection {
            None => env.limit_law(law.rate_mps, accel_mps2, previous, l, dt, &Bounds::none()),
            Some(p) => {
                let bounds = p.bounds(Some(&FreeTensionModel::of(&law_in, &law)), previous, dt);
                env.limit_law(law.rate_mps, accel_mps2, previous, l, dt, &bounds)
            }
        };
        flags.set(sat.0);
        self.last_rate_cmd_mps = rate;

        // The output.
        let x_rate = self
            .existence
            .normalised_rate_at_reduced_length(law.reduced_length_m, rate);
        let margin = self.equilibrium_margin(x_rate);
        flags.set_if(margin < T::ZERO, Flags::NO_EQUILIBRIUM);
        let nis = self.commanded(x.length_m, accel, mu3);
        self.out = Output {
            tick,
            phase: self.sequencer.phase(),
            health: self.health.health(),
            rate_cmd_mps: rate,
            accel_cmd_mps2: accel,
            law_rate_mps: law.law_rate_mps,
            blend_weight: law_in.blend.weight,
            alpha_ref_rad: reference.angle.angle_rad,
            alpha_ref_rate_radps: law.ref_rate_radps,
            delta_rad: law.delta_rad,
            delta_rate_radps: law.delta_rate_radps,
            length_estimate_m: x.length_m,
            equilibrium_margin: margin,
            nis,
            flags,
            fault: None,
        };
    }

    /// The α and α̇ the law flies on: the sensed ones, or the estimate carried over the
    /// `periods` that passed and updated with the α of `swing` (`x`: the accepted sample, if
    /// any). An estimator event is recorded at `tick`.
    // Inlined into its one caller: out of line it cost a call, its prologue and the spills of
    // its arguments: 30 instructions a step (scripts/bench-target, mission: median 1008 → 978,
    // worst 1045 → 1018).
    #[inline(always)]
    fn swing(
        &mut self,
        tick: u32,
        periods: u32,
        x: Option<&Input<T>>,
        swing: Swing<T>,
    ) -> Result<(T, T), Sensor> {
        match (&mut self.estimation, swing) {
            (None, Swing::Sensed(alpha_rad, alpha_rate_radps)) => Ok((alpha_rad, alpha_rate_radps)),
            (Some(est), Swing::Angle(alpha_rad)) => {
                let sample = x.map(|x| (x.orbit_rate_radps, x.true_anomaly_rad, x.reel_rate_mps));
                let (verdict, event) = est.step(periods, sample, alpha_rad);
                if let Some(kind) = event {
                    self.events.push(Event { tick, kind });
                }
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
        }
    }

    /// Flying on the estimator, the end of its step: the command of this step, the drive of
    /// the next prediction (the reel at `length_m`, at the kept command, accelerating at
    /// `accel_mps2`). Returns the NIS of this step's α sample for the output.
    // One test for the estimator for both, where there were two (the command after the output,
    // the NIS for it): with the last step's health and phase kept as state, mission 905/935 →
    // 900/928 (scripts/bench-target; the law's sin/cos 2α̂ lent at the end of the step as well
    // took 5 more: they stayed live across the envelope).
    fn commanded(&mut self, length_m: T, accel_mps2: T, mu3: T) -> Option<T> {
        let c = Commanded {
            length_m,
            rate_mps: self.last_rate_cmd_mps,
            accel_mps2,
            mu3,
        };
        match &mut self.estimation {
            Some(est) => est.end_step(c),
            None => None,
        }
    }

    /// No usable sample or no law solution at this tick: the health machine counts it, and
    /// `length_m` (the prediction, or the sensed length of a valid sample the law could not
    /// use) becomes the length estimate. Then the safe action.
    fn reject(
        &mut self,
        tick: u32,
        length_m: Option<T>,
        fault: Fault,
        alpha_ref_rad: Option<T>,
        mut flags: Flags,
    ) {
        self.length.coast(length_m);
        self.health.unusable(&self.cfg.monitor, &mut flags);
        // Without a usable sample, α_r is reported at the estimated length.
        let alpha_ref_rad = alpha_ref_rad.unwrap_or_else(|| {
            let l = self.length.length_m().unwrap_or(T::ZERO);
            self.sequencer.reference(tick, l).angle.angle_rad
        });
        self.hold(tick, Some(tick), alpha_ref_rad, Some(fault), flags)
    }

    /// A sample whose tick did not move forward: a bad sample for the health machine, at a
    /// time that did not move. The length estimate stays, and so does the command (no time
    /// passed for the acceleration limit to allow a change, in any health state); α_r and the
    /// blend are reported at the last accepted tick. A clock that stops for good therefore
    /// ends in safe hold with the command held where it was, until time moves again.
    fn reject_stale(&mut self, tick: u32, fault: Fault, mut flags: Flags) {
        self.health.unusable(&self.cfg.monitor, &mut flags);
        // (Only a tick after an accepted one can be stale or repeated.)
        let now = self.clock.last_tick().unwrap_or(tick);
        let l = self.length.length_m().unwrap_or(T::ZERO);
        let alpha_ref_rad = self.sequencer.reference(now, l).angle.angle_rad;
        self.hold(tick, None, alpha_ref_rad, Some(fault), flags)
    }

    /// The safe actions at `tick`: `moved_to` is `Some(tick)` when time moved to it, `None`
    /// when the tick did not move forward (time stays at the last accepted tick). Degraded:
    /// keep the last command (coast). Safe hold: ramp the rate to zero at
    /// `monitor.safe_hold_decel_mps2` (at most the envelope's limit). When time did not move,
    /// the command stays. All stay inside the length limits, judged on the estimated length
    /// (before any accepted sample, on the docking end: 0 m).
    fn hold(
        &mut self,
        tick: u32,
        moved_to: Option<u32>,
        alpha_ref_rad: T,
        fault: Option<Fault>,
        mut flags: Flags,
    ) {
        flags.set(Flags::SAFE_ACTION);
        flags.set_if(self.sequencer.stalled(), Flags::NO_PROGRESS);
        let now = moved_to.or(self.clock.last_tick()).unwrap_or(tick);
        let dt = self.cfg.period_s;
        let previous = self.last_rate_cmd_mps;
        let target = match (moved_to, self.health.health()) {
            (None, _) | (Some(_), Health::Degraded) => previous,
            (Some(_), Health::Nominal | Health::SafeHold) => {
                let step = self.safe_hold_step_mps;
                previous - previous.clamp_finite(-step, step)
            }
        };
        let length_m = self.length.length_m().unwrap_or(T::ZERO);
        let bounds = self.hold_bounds(previous);
        let (rate, sat) = self
            .envelope
            .limit_request(target, previous, length_m, dt, &bounds);
        flags.set(sat.0 & (Flags::LENGTH_LIMITED | Flags::TENSION_LIMITED));
        self.last_rate_cmd_mps = rate;
        let mu3 = self.cfg.masses.mu3_and_slope(length_m).0;
        let x_rate = self.existence.normalised_rate(mu3, length_m, rate);
        let accel_mps2 = (rate - previous) / dt;
        let margin = self.equilibrium_margin(x_rate);
        flags.set_if(margin < T::ZERO, Flags::NO_EQUILIBRIUM);
        let nis = self.commanded(length_m, accel_mps2, mu3);
        self.out = Output {
            tick,
            phase: self.sequencer.phase(),
            health: self.health.health(),
            rate_cmd_mps: rate,
            accel_cmd_mps2: accel_mps2,
            law_rate_mps: T::ZERO,
            blend_weight: self.sequencer.blend(now).weight,
            alpha_ref_rad,
            alpha_ref_rate_radps: T::ZERO,
            delta_rad: T::ZERO,
            delta_rate_radps: T::ZERO,
            length_estimate_m: length_m,
            equilibrium_margin: margin,
            nis,
            flags,
            fault,
        };
    }

    /// The protection's bounds of a step in which the law did not run (a hold: the model is
    /// stale, the free tension the load cell's own); none without a protection.
    fn hold_bounds(&mut self, previous_mps: T) -> Bounds<T> {
        let dt = self.cfg.period_s;
        match &mut self.protection {
            Some(p) => p.bounds(None, previous_mps, dt),
            None => Bounds::none(),
        }
    }

    /// The Eq. 13 whole-orbit margin of a command whose normalised rate (Eq. 7) is `x`:
    /// min Depl − |x| (> 0 inside the region). Near docking x grows as 1/l, so the margin is
    /// reported no lower than −[`MAX_REPORTED_MARGIN`] (it is never above min Depl); a zero
    /// length estimate (a long coast toward docking) makes x infinite or NaN, reported as that
    /// bound: far outside.
    fn equilibrium_margin(&self, x: T) -> T {
        let margin = self.existence.whole_orbit_margin_of(x);
        let lowest = T::from_f64(-MAX_REPORTED_MARGIN);
        if margin >= lowest {
            margin
        } else {
            lowest
        }
    }

    /// Records a step's events, in this order: health change, phase change, new fault, blend
    /// restart, the tension bound beginning to act. A quiet step (the common case) records
    /// nothing.
    // Inlined into the step (a quiet step's checks without a call): 8 instructions less on the
    // mission's worst step (scripts/bench-target: 558 → 550). The changes are read from the
    // step's flags, each set where its change happened (health, phase, blend restart, a safe
    // action for a fault): a quiet step is one test of its flags where comparing the health,
    // phase, fault and tension limit with the last step's took 23 instructions (mission
    // median/worst 805/828 → 788/823; the phase's events recorded by the sequencer where it
    // changes instead: 795/828). A step with the sequencer's events alone (a new phase, a
    // blend restart) skips the fault and tension comparisons: worst 823 → 813.
    #[inline(always)]
    fn record_events(&mut self) {
        let out = &self.out;
        let flags = out.flags;
        let eventful = Flags::HEALTH_CHANGED
            | Flags::PHASE_CHANGED
            | Flags::BLEND_RESTART
            | Flags::SAFE_ACTION
            | Flags::TENSION_LIMITED;
        if flags.0 & eventful == 0 {
            // No fault without a safe action, no tension limit: both end here.
            debug_assert!(out.health == self.last_health && out.fault.is_none());
            self.last_fault = None;
            self.last_tension_limited = false;
            return;
        }
        let tick = out.tick;
        if flags.0 & (Flags::HEALTH_CHANGED | Flags::SAFE_ACTION | Flags::TENSION_LIMITED) == 0 {
            // The sequencer's changes alone: a new phase, a blend restart.
            self.last_fault = None;
            self.last_tension_limited = false;
            if flags.contains(Flags::PHASE_CHANGED) {
                let kind = EventKind::Phase(out.phase);
                self.events.push(Event { tick, kind });
            }
            if flags.contains(Flags::BLEND_RESTART) {
                let kind = EventKind::BlendRestart;
                self.events.push(Event { tick, kind });
            }
            return;
        }
        if flags.contains(Flags::HEALTH_CHANGED) {
            let kind = EventKind::Health {
                from: self.last_health,
                to: out.health,
            };
            self.last_health = out.health;
            self.events.push(Event { tick, kind });
        }
        if flags.contains(Flags::PHASE_CHANGED) {
            let kind = EventKind::Phase(out.phase);
            self.events.push(Event { tick, kind });
        }
        if let Some(f) = out.fault {
            if out.fault != self.last_fault {
                let kind = EventKind::Fault(f);
                self.events.push(Event { tick, kind });
            }
        }
        self.last_fault = out.fault;
        if flags.contains(Flags::BLEND_RESTART) {
            let kind = EventKind::BlendRestart;
            self.events.push(Event { tick, kind });
        }
        let tension_limited = flags.contains(Flags::TENSION_LIMITED);
        if tension_limited && !self.last_tension_limited {
            let kind = EventKind::TensionLimited;
            self.events.push(Event { tick, kind });
        }
        self.last_tension_limited = tension_limited;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's stage 1 at `tick` with the load cell reading `tension_n`.
    fn sample(tick: u32, tension_n: Option<f64>) -> Input<f64> {
        Input {
            tick,
            length_m: 1.0 + 0.1 * f64::from(tick),
            reel_rate_mps: None,
            tension_n,
            alpha_rad: Some(-35.0_f64.to_radians()),
            alpha_rate_radps: Some(0.0),
            orbit_rate_radps: 1.0602e-3,
            true_anomaly_rad: 0.0,
        }
    }

    #[test]
    fn the_tension_limit_is_an_event_each_time_it_begins() {
        // A load cell the protection follows within a period, and a low tension limit.
        let protection = ProtectionConfig {
            max_tension_n: 0.5,
            tension_filter_s: 1.0,
            ..ProtectionConfig::default_for_period()
        };
        let cfg = Config {
            protection: Some(protection),
            ..Config::<f64>::paper()
        };
        let mut ctl = Controller::new(cfg).unwrap();
        // Inside the window, above it (limited), no reading (no tension bound), above it again.
        let (ok, over) = (Some(0.1), Some(5.0));
        let tensions = [ok, ok, over, over, over, None, None, over, over];
        let mut limited = [false; 9];
        let mut began = [false; 9];
        for (tick, &t) in (0u32..).zip(&tensions) {
            let out = ctl.step(&sample(tick, t));
            limited[tick as usize] = out.flags.contains(Flags::TENSION_LIMITED);
            while let Some(e) = ctl.pop_event() {
                began[tick as usize] |= e.kind == EventKind::TensionLimited;
            }
        }
        let (f, t) = (false, true);
        assert_eq!(limited, [f, f, t, t, t, f, f, t, t]);
        assert_eq!(began, [f, f, t, f, f, f, f, t, f]);
    }
}
