//! Fault injection between the plant and the controller, and the fault summary of a run.
//!
//! [`Injector`] turns the plant's true state into what the controller reads: sensor bias,
//! white Gaussian noise, quantisation and stuck windows (`[sensors]`), dropouts, corrupted
//! readings and length-encoder glitches (`[faults]`). [`SummaryBuilder`] watches every control
//! tick of a run and produces the [`FaultSummary`] stored in `History::faults`;
//! [`render_fault_summary`] formats it for the terminal and `faults.txt`.
//!
//! The noise is reproducible: each sensor has its own [`Pcg32`] stream seeded from
//! `sensors.seed`, drawn once per control tick whether or not the reading is used. A run
//! therefore depends only on its scenario (never on threads or on other runs), and switching
//! one fault on does not change the noise another sensor sees.

use std::fmt::Write as _;

use tss_reel::controller::{Envelope, Fault, Flags, Health, Output};
use tss_reel::Real;

use crate::reel::ReelDrive;
use crate::sensors::{
    EncoderModel, LoadCell, LoadCellModel, RateSensor, ReelEncoder, SwingSensor, SwingSensorModel,
};

// ---- a small deterministic generator ---------------------------------------------------------

/// PCG32 (O'Neill 2014, "PCG: A family of simple fast space-efficient statistically good
/// algorithms for random number generation", the `pcg32` XSH-RR 64/32 generator of
/// pcg-random.org): 64-bit LCG state, 32-bit output by xorshift-high and random rotation.
/// Independent streams come from different (odd) increments.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
    /// The second Box–Muller deviate, kept for the next call of [`Pcg32::normal`].
    spare: Option<u64>,
}

impl Pcg32 {
    const MULTIPLIER: u64 = 6_364_136_223_846_793_005;

    /// `pcg32_srandom(seed, stream)` of the reference implementation.
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut rng = Self {
            state: 0,
            inc: (stream << 1) | 1,
            spare: None,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    /// The next 32 uniformly distributed bits.
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(Self::MULTIPLIER).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in (0, 1), 53 random bits (never exactly 0, so its logarithm is finite).
    pub fn uniform_open(&mut self) -> f64 {
        let bits = (u64::from(self.next_u32()) << 21) ^ u64::from(self.next_u32() >> 11);
        (bits as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// A standard normal deviate (Box–Muller; the pair's second value is returned next call).
    pub fn normal(&mut self) -> f64 {
        if let Some(bits) = self.spare.take() {
            return f64::from_bits(bits);
        }
        let r = (-2.0 * self.uniform_open().ln()).sqrt();
        let phi = 2.0 * std::f64::consts::PI * self.uniform_open();
        self.spare = Some((r * phi.sin()).to_bits());
        r * phi.cos()
    }
}

// ---- what is injected: the fault model's parameters -------------------------------------------

/// One sensor's errors, in the sensor's own unit (m, rad, rad/s), applied in the order bias,
/// noise, quantisation, then a stuck window freezes the reading.
/// The default is a perfect sensor.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SensorErrors {
    /// Standard deviation of white Gaussian noise added every sample (0 = none).
    pub noise_std: f64,
    /// Constant offset added to every sample.
    pub bias: f64,
    /// Quantisation step: the reading is rounded to a multiple of it (0 = none).
    pub quantum: f64,
    /// While in this window the sensor repeats the reading it gave at its start (`None`:
    /// never stuck).
    pub stuck: Option<Window>,
}

impl SensorErrors {
    /// `true` if the sensor reads the truth.
    pub fn is_perfect(&self) -> bool {
        self.noise_std == 0.0 && self.bias == 0.0 && self.quantum == 0.0 && self.stuck.is_none()
    }
}

/// A quantity the controller reads, as a corrupted reading can hit it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SensedQuantity {
    /// The tether length (encoder), m.
    Length,
    /// α, rad.
    Alpha,
    /// α̇, rad/s.
    AlphaRate,
    /// The orbit rate θ̇, rad/s.
    OrbitRate,
    /// The reel's rate from the encoder, m/s.
    ReelRate,
    /// The tension from the load cell, N.
    Tension,
}

impl SensedQuantity {
    /// Its name in messages (as in scenario files).
    pub fn name(self) -> &'static str {
        match self {
            Self::Length => "length",
            Self::Alpha => "alpha",
            Self::AlphaRate => "alpha_rate",
            Self::OrbitRate => "orbit_rate",
            Self::ReelRate => "reel_rate",
            Self::Tension => "tension",
        }
    }
}

/// A time window [from_s, until_s) on the control ticks, s (until inf = to the end of the run).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    /// Start, s.
    pub from_s: f64,
    /// End (excluded), s.
    pub until_s: f64,
}

impl Window {
    /// `t_s` is inside the window.
    pub fn contains(&self, t_s: f64) -> bool {
        t_s >= self.from_s && t_s < self.until_s
    }
}

/// A reading replaced by a fixed value (NaN, inf, anything) during a window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corruption {
    /// Which quantity.
    pub sensor: SensedQuantity,
    /// When.
    pub window: Window,
    /// The reading, in the quantity's unit.
    pub value: f64,
}

/// A one-tick error of the length encoder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Glitch {
    /// When, s (the tick at or after it).
    pub at_s: f64,
    /// Size of the error, m.
    pub size_m: f64,
}

/// Everything injected between the plant and the controller: the parameters of an
/// [`Injector`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InjectionPlan {
    /// Seed of the noise generators (one stream per sensor).
    pub seed: u64,
    /// The reel encoder (length and rate).
    pub length: EncoderModel,
    /// The swing sensor (α): errors, latency, α dropouts.
    pub alpha: SwingSensorModel,
    /// The α̇ sensor is fitted.
    pub alpha_rate_enabled: bool,
    /// The α̇ sensor's errors.
    pub alpha_rate: SensorErrors,
    /// The load cell.
    pub load_cell: LoadCellModel,
    /// Windows without a sample (the controller's `step_missing`).
    pub dropout: Vec<Window>,
    /// Corrupted readings.
    pub corrupt: Vec<Corruption>,
    /// Length-encoder glitches.
    pub length_glitch: Vec<Glitch>,
}

impl InjectionPlan {
    /// `true` if nothing is injected: the controller reads the truth (rounded to its type),
    /// α̇ included.
    pub fn is_transparent(&self) -> bool {
        self.length.is_perfect()
            && self.alpha.is_perfect()
            && self.alpha_rate_enabled
            && self.alpha_rate.is_perfect()
            && self.load_cell.is_perfect()
            && self.dropout.is_empty()
            && self.corrupt.is_empty()
            && self.length_glitch.is_empty()
    }
}

// ---- sensors ----------------------------------------------------------------------------------

/// The plant's true values of what the controller senses, in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Truth {
    /// Tether length, m.
    pub length_m: f64,
    /// The drum's actual rate over the last period, m/s.
    pub reel_rate_mps: f64,
    /// Tension at the reel at the end of the last period (under the command held over it), N.
    pub tension_n: f64,
    /// α, rad.
    pub alpha_rad: f64,
    /// α̇, rad/s.
    pub alpha_rate_radps: f64,
    /// Orbit rate θ̇, rad/s.
    pub orbit_rate_radps: f64,
    /// True anomaly θ, rad.
    pub true_anomaly_rad: f64,
}

/// What the controller reads at one tick: the `Input` fields in f64, with the same options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    /// Length from the reel encoder, m.
    pub length_m: f64,
    /// The reel's rate from the encoder, m/s (`None`: not measured this period).
    pub reel_rate_mps: Option<f64>,
    /// Tension from the load cell, N (`None`: no load cell).
    pub tension_n: Option<f64>,
    /// α from the swing sensor, rad (`None`: it gave nothing this period).
    pub alpha_rad: Option<f64>,
    /// α̇ from the rate sensor, rad/s (`None`: none fitted).
    pub alpha_rate_radps: Option<f64>,
    /// Orbit rate θ̇, rad/s.
    pub orbit_rate_radps: f64,
    /// True anomaly θ, rad.
    pub true_anomaly_rad: f64,
}

/// One sensor: bias, noise, quantisation, stuck window.
#[derive(Clone, Debug)]
pub(crate) struct Channel {
    cfg: SensorErrors,
    rng: Pcg32,
    held: Option<f64>,
}

impl Channel {
    pub(crate) fn new(cfg: &SensorErrors, seed: u64, stream: u64) -> Self {
        Self {
            cfg: cfg.clone(),
            rng: Pcg32::new(seed, stream),
            held: None,
        }
    }

    pub(crate) fn read(&mut self, truth: f64, t_s: f64) -> f64 {
        let c = &self.cfg;
        // Drawn every tick, used or not, so that the noise sequence is tied to time.
        let noise = if c.noise_std > 0.0 {
            c.noise_std * self.rng.normal()
        } else {
            0.0
        };
        let mut v = truth;
        if c.bias != 0.0 {
            v += c.bias;
        }
        if noise != 0.0 {
            v += noise;
        }
        if c.quantum > 0.0 {
            v = (v / c.quantum).round() * c.quantum;
        }
        if c.stuck.is_some_and(|w| w.contains(t_s)) {
            *self.held.get_or_insert(v)
        } else {
            self.held = None;
            v
        }
    }
}

/// What the controller receives at one tick: a reading of every sensor, or nothing (dropout).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sensed {
    /// A sample (possibly wrong: noisy, biased, stuck, corrupted, glitched, or without α).
    Sample(Reading),
    /// No sample arrived (a `[[faults.dropout]]` window).
    Missing,
}

/// The noise streams of the sensors (`Pcg32` streams of `sensors.seed`): fixed, so that a
/// sensor's noise does not depend on which other sensors are modelled.
mod stream {
    pub const LENGTH: u64 = 1;
    pub const ALPHA: u64 = 2;
    pub const ALPHA_RATE: u64 = 3;
    pub const ALPHA_DROPOUT: u64 = 4;
    pub const LOAD_CELL: u64 = 5;
}

/// Applies an [`InjectionPlan`] (a scenario's `[sensors]` and `[faults]`) to the plant's truth,
/// tick by tick: the sensor models of [`crate::sensors`], then the injected faults.
#[derive(Clone, Debug)]
pub struct Injector {
    encoder: ReelEncoder,
    swing: SwingSensor,
    rate: RateSensor,
    load_cell: LoadCell,
    dropout: Vec<Window>,
    corrupt: Vec<Corruption>,
    /// (tick, size) of each length glitch.
    glitches: Vec<(u32, f64)>,
}

impl Injector {
    /// The injector of `plan` on control period `period_s`.
    pub fn new(plan: &InjectionPlan, period_s: f64) -> Self {
        let seed = plan.seed;
        Self {
            encoder: ReelEncoder::new(&plan.length, period_s, seed, stream::LENGTH),
            swing: SwingSensor::new(&plan.alpha, seed, stream::ALPHA, stream::ALPHA_DROPOUT),
            rate: RateSensor::new(
                plan.alpha_rate_enabled,
                &plan.alpha_rate,
                seed,
                stream::ALPHA_RATE,
            ),
            load_cell: LoadCell::new(&plan.load_cell, seed, stream::LOAD_CELL),
            dropout: plan.dropout.clone(),
            corrupt: plan.corrupt.clone(),
            glitches: plan
                .length_glitch
                .iter()
                .map(|g| (first_tick_at(g.at_s, period_s), g.size_m))
                .collect(),
        }
    }

    /// What the controller reads at `tick` (mission time `t_s`). Every sensor measures every
    /// tick, a dropout's included (its noise stays tied to time).
    pub fn sense(&mut self, tick: u32, t_s: f64, truth: &Truth) -> Sensed {
        let encoder = self.encoder.read(truth.length_m, truth.reel_rate_mps, t_s);
        let mut r = Reading {
            length_m: encoder.length_m,
            reel_rate_mps: encoder.rate_mps,
            tension_n: self.load_cell.read(truth.tension_n, t_s),
            alpha_rad: self.swing.read(truth.alpha_rad, t_s),
            alpha_rate_radps: self.rate.read(truth.alpha_rate_radps, t_s),
            orbit_rate_radps: truth.orbit_rate_radps,
            true_anomaly_rad: truth.true_anomaly_rad,
        };
        if self.dropout.iter().any(|w| w.contains(t_s)) {
            return Sensed::Missing;
        }
        for &(at, size) in &self.glitches {
            if at == tick {
                r.length_m += size;
            }
        }
        for c in &self.corrupt {
            if c.window.contains(t_s) {
                match c.sensor {
                    SensedQuantity::Length => r.length_m = c.value,
                    SensedQuantity::Alpha => r.alpha_rad = Some(c.value),
                    SensedQuantity::AlphaRate => r.alpha_rate_radps = Some(c.value),
                    SensedQuantity::OrbitRate => r.orbit_rate_radps = c.value,
                    SensedQuantity::ReelRate => r.reel_rate_mps = Some(c.value),
                    SensedQuantity::Tension => r.tension_n = Some(c.value),
                }
            }
        }
        Sensed::Sample(r)
    }
}

/// The first tick at or after `t_s` (a time within 1e-9 periods of a tick is that tick).
fn first_tick_at(t_s: f64, period_s: f64) -> u32 {
    let k = t_s / period_s;
    let n = if (k - k.round()).abs() <= 1e-9 * k.abs().max(1.0) {
        k.round()
    } else {
        k.ceil()
    };
    n.clamp(0.0, f64::from(u32::MAX)) as u32
}

// ---- the summary -------------------------------------------------------------------------------

/// What happened at one instant of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FaultEventKind {
    /// The controller's health changed (with the fault it gave at that step, if any).
    Health {
        /// Health before this step.
        from: Health,
        /// Health after this step.
        to: Health,
        /// The fault reported at this step.
        fault: Option<Fault>,
    },
    /// A fault was reported that was not reported at the previous step.
    Raised(Fault),
}

/// One event of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultEvent {
    /// Control tick.
    pub tick: u32,
    /// Mission time, s.
    pub t_s: f64,
    /// What happened.
    pub kind: FaultEventKind,
}

/// One distinct fault over a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultTally {
    /// The fault.
    pub fault: Fault,
    /// First time it was reported, s.
    pub first_s: f64,
    /// Last time it was reported, s.
    pub last_s: f64,
    /// Ticks at which it was reported.
    pub ticks: u32,
}

/// Ticks at which each controller output flag was raised.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FlagTicks {
    /// `Flags::RATE_SATURATED`.
    pub rate_saturated: u32,
    /// `Flags::ACCEL_SATURATED`.
    pub accel_saturated: u32,
    /// `Flags::LENGTH_LIMITED`.
    pub length_limited: u32,
    /// `Flags::SAFE_ACTION`.
    pub safe_action: u32,
    /// `Flags::BLEND_RESTART`.
    pub blend_restart: u32,
    /// `Flags::SLEWING`.
    pub slewing: u32,
    /// `Flags::HEALTH_CHANGED`.
    pub health_changed: u32,
    /// `Flags::NO_EQUILIBRIUM`.
    pub no_equilibrium: u32,
    /// `Flags::NO_PROGRESS`.
    pub no_progress: u32,
}

impl FlagTicks {
    fn add(&mut self, flags: Flags) {
        let bump = |mask: u32, n: &mut u32| {
            if flags.contains(mask) {
                *n += 1;
            }
        };
        bump(Flags::RATE_SATURATED, &mut self.rate_saturated);
        bump(Flags::ACCEL_SATURATED, &mut self.accel_saturated);
        bump(Flags::LENGTH_LIMITED, &mut self.length_limited);
        bump(Flags::SAFE_ACTION, &mut self.safe_action);
        bump(Flags::BLEND_RESTART, &mut self.blend_restart);
        bump(Flags::SLEWING, &mut self.slewing);
        bump(Flags::HEALTH_CHANGED, &mut self.health_changed);
        bump(Flags::NO_EQUILIBRIUM, &mut self.no_equilibrium);
        bump(Flags::NO_PROGRESS, &mut self.no_progress);
    }

    /// (name, ticks) of every flag, in bit order.
    pub fn named(&self) -> [(&'static str, u32); 9] {
        [
            ("rate-saturated", self.rate_saturated),
            ("accel-saturated", self.accel_saturated),
            ("length-limited", self.length_limited),
            ("safe-action", self.safe_action),
            ("blend-restart", self.blend_restart),
            ("slewing", self.slewing),
            ("health-changed", self.health_changed),
            ("no-equilibrium", self.no_equilibrium),
            ("no-progress", self.no_progress),
        ]
    }
}

/// The fault summary of a run, from every control tick (not only the recorded samples).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FaultSummary {
    /// Control ticks observed (steps of the controller).
    pub ticks: u32,
    /// Control period, s.
    pub period_s: f64,
    /// Health transitions and fault onsets, in time order (at most [`MAX_EVENTS`]).
    pub events: Vec<FaultEvent>,
    /// Events not stored because [`MAX_EVENTS`] was reached.
    pub events_dropped: u32,
    /// Every distinct fault, in order of first appearance.
    pub faults: Vec<FaultTally>,
    /// Time with health Nominal, s.
    pub nominal_s: f64,
    /// Time with health Degraded, s.
    pub degraded_s: f64,
    /// Time with health SafeHold, s.
    pub safe_hold_s: f64,
    /// Health after the last step (`None` before any step).
    pub final_health: Option<Health>,
    /// Ticks at which no sample arrived (injected dropouts).
    pub missing_ticks: u32,
    /// Largest |controller's length estimate − true length|, m, and when (s).
    pub max_length_error_m: (f64, f64),
    /// Smallest tether tension (Eq. 5a, at the start of each period), N, and when (s).
    pub min_tension_n: (f64, f64),
    /// Times the tension fell to ≤ 0 (slack) after being positive.
    pub slack_events: u32,
    /// Total time with tension ≤ 0, s.
    pub slack_s: f64,
    /// Each slack episode (first slack tick, first taut tick after it — or the end of the run),
    /// s (at most [`MAX_EVENTS`]).
    pub slack_episodes: Vec<(f64, f64)>,
    /// Shortest and longest true tether length, m.
    pub length_range_m: (f64, f64),
    /// Time with the true length outside [envelope.min_length_m, envelope.max_length_m], s.
    pub outside_envelope_s: f64,
    /// Largest distance of the true length outside [min_length_m, max_length_m], m (0 inside).
    pub max_excursion_m: f64,
    /// Largest |rate command|, m/s.
    pub max_rate_cmd_mps: f64,
    /// Largest |change of the rate command| per period, over the period, m/s².
    pub max_accel_cmd_mps2: f64,
    /// Ticks whose command exceeded `envelope.max_rate_mps` (beyond f32 rounding, 1e-6
    /// relative).
    pub rate_exceeded_ticks: u32,
    /// Ticks whose command changed by more than `envelope.max_accel_mps2` × period (beyond f32
    /// rounding: 1e-5 relative, plus 1e-6 m/s).
    pub accel_exceeded_ticks: u32,
    /// Ticks per controller flag.
    pub flags: FlagTicks,
    /// Periods in which the reel drive's own rate limit clipped the command.
    pub reel_rate_saturated_ticks: u32,
    /// Periods in which the reel drive ran at its own acceleration limit.
    pub reel_accel_saturated_ticks: u32,
}

/// Largest number of events a [`FaultSummary`] stores.
pub const MAX_EVENTS: usize = 10_000;

impl FaultSummary {
    /// The tally of `fault`, if it was ever reported.
    pub fn tally(&self, fault: Fault) -> Option<&FaultTally> {
        self.faults.iter().find(|t| t.fault == fault)
    }

    /// Was `fault` reported at least once?
    pub fn raised(&self, fault: Fault) -> bool {
        self.tally(fault).is_some()
    }

    /// Health transitions `(t_s, from, to)`, in order.
    pub fn transitions(&self) -> Vec<(f64, Health, Health)> {
        self.events
            .iter()
            .filter_map(|e| match e.kind {
                FaultEventKind::Health { from, to, .. } => Some((e.t_s, from, to)),
                FaultEventKind::Raised(_) => None,
            })
            .collect()
    }
}

/// One tick as the summary sees it.
#[derive(Clone, Copy, Debug)]
pub struct TickRecord {
    /// Control tick.
    pub tick: u32,
    /// Mission time, s.
    pub t_s: f64,
    /// True tether length, m.
    pub length_m: f64,
    /// Tension at the start of the period, N.
    pub tension_n: f64,
    /// No sample arrived at this tick.
    pub missing: bool,
    /// The drive's saturation over the coming period.
    pub reel: crate::reel::ReelSaturation,
}

/// Accumulates a [`FaultSummary`] tick by tick.
#[derive(Clone, Debug)]
pub struct SummaryBuilder {
    s: FaultSummary,
    min_length_m: f64,
    max_length_m: f64,
    max_rate_mps: f64,
    max_accel_mps2: f64,
    health: Health,
    last_fault: Option<Fault>,
    last_rate_mps: Option<f64>,
    slack: bool,
}

impl SummaryBuilder {
    /// A builder for a run with control period `period_s` and the controller's envelope.
    pub fn new(period_s: f64, envelope: &Envelope<f64>) -> Self {
        Self {
            s: FaultSummary {
                period_s,
                min_tension_n: (f64::INFINITY, 0.0),
                length_range_m: (f64::INFINITY, f64::NEG_INFINITY),
                ..FaultSummary::default()
            },
            min_length_m: envelope.min_length_m,
            max_length_m: envelope.max_length_m,
            max_rate_mps: envelope.max_rate_mps,
            max_accel_mps2: envelope.max_accel_mps2,
            health: Health::Nominal,
            last_fault: None,
            last_rate_mps: None,
            slack: false,
        }
    }

    /// Records one controller step.
    pub fn record<T: Real>(&mut self, r: &TickRecord, out: &Output<T>) {
        let s = &mut self.s;
        let dt = s.period_s;
        s.ticks += 1;
        if r.missing {
            s.missing_ticks += 1;
        }
        let mut push = |kind| {
            if s.events.len() < MAX_EVENTS {
                s.events.push(FaultEvent {
                    tick: r.tick,
                    t_s: r.t_s,
                    kind,
                });
            } else {
                s.events_dropped += 1;
            }
        };
        if let Some(f) = out.fault {
            if self.last_fault != Some(f) {
                push(FaultEventKind::Raised(f));
            }
        }
        if out.health != self.health {
            push(FaultEventKind::Health {
                from: self.health,
                to: out.health,
                fault: out.fault,
            });
            self.health = out.health;
        }
        if let Some(f) = out.fault {
            match s.faults.iter_mut().find(|t| t.fault == f) {
                Some(t) => {
                    t.ticks += 1;
                    t.last_s = r.t_s;
                }
                None => s.faults.push(FaultTally {
                    fault: f,
                    first_s: r.t_s,
                    last_s: r.t_s,
                    ticks: 1,
                }),
            }
        }
        self.last_fault = out.fault;
        match out.health {
            Health::Nominal => s.nominal_s += dt,
            Health::Degraded => s.degraded_s += dt,
            Health::SafeHold => s.safe_hold_s += dt,
        }
        s.final_health = Some(out.health);

        let err = (out.length_estimate_m.to_f64() - r.length_m).abs();
        if err > s.max_length_error_m.0 || err.is_nan() {
            s.max_length_error_m = (err, r.t_s);
        }
        if r.tension_n < s.min_tension_n.0 {
            s.min_tension_n = (r.tension_n, r.t_s);
        }
        let slack = r.tension_n <= 0.0;
        if slack {
            s.slack_s += dt;
            if !self.slack {
                s.slack_events += 1;
                if s.slack_episodes.len() < MAX_EVENTS {
                    s.slack_episodes.push((r.t_s, f64::INFINITY));
                }
            }
        } else if self.slack {
            if let Some(last) = s.slack_episodes.last_mut() {
                if last.1 == f64::INFINITY {
                    last.1 = r.t_s;
                }
            }
        }
        self.slack = slack;
        let (lo, hi) = s.length_range_m;
        s.length_range_m = (lo.min(r.length_m), hi.max(r.length_m));
        let excursion = (self.min_length_m - r.length_m).max(r.length_m - self.max_length_m);
        // NaN counts as outside.
        if excursion > 0.0 || excursion.is_nan() {
            s.outside_envelope_s += dt;
            s.max_excursion_m = s.max_excursion_m.max(excursion);
        }
        let rate = out.rate_cmd_mps.to_f64();
        s.max_rate_cmd_mps = s.max_rate_cmd_mps.max(rate.abs());
        let rate_ok = rate.abs() <= self.max_rate_mps * (1.0 + 1e-6);
        if !rate_ok {
            s.rate_exceeded_ticks += 1;
        }
        if let Some(prev) = self.last_rate_mps {
            let change = (rate - prev).abs();
            s.max_accel_cmd_mps2 = s.max_accel_cmd_mps2.max(change / dt);
            let accel_ok = change <= self.max_accel_mps2 * dt * (1.0 + 1e-5) + 1e-6;
            if !accel_ok {
                s.accel_exceeded_ticks += 1;
            }
        }
        self.last_rate_mps = Some(rate);
        s.flags.add(out.flags);
        if r.reel.rate {
            s.reel_rate_saturated_ticks += 1;
        }
        if r.reel.accel {
            s.reel_accel_saturated_ticks += 1;
        }
    }

    /// The summary (a slack episode still open ends at the last tick + one period).
    pub fn finish(mut self) -> FaultSummary {
        if let Some(last) = self.s.slack_episodes.last_mut() {
            if last.1 == f64::INFINITY {
                last.1 = f64::from(self.s.ticks) * self.s.period_s;
            }
        }
        self.s
    }
}

// ---- text ---------------------------------------------------------------------------------------

/// How many events [`render_fault_summary`] lists.
pub const EVENTS_SHOWN: usize = 40;

fn health_name(h: Health) -> &'static str {
    match h {
        Health::Nominal => "nominal",
        Health::Degraded => "degraded",
        Health::SafeHold => "safe hold",
    }
}

/// A fault as text, e.g. `sensor: missing`, `law: …`.
pub fn fault_name(f: Fault) -> String {
    match f {
        Fault::Sensor(s) => format!("sensor {s:?}"),
        Fault::Law(l) => format!("law {l:?}"),
    }
}

fn window(from_s: f64, until_s: f64) -> String {
    if until_s == f64::INFINITY {
        format!("from {from_s} s")
    } else {
        format!("{from_s}–{until_s} s")
    }
}

/// What a fault summary describes besides its counts: the run's name, what was injected, the
/// reel drive and the controller's envelope (a scenario converts into it).
#[derive(Clone, Debug, PartialEq)]
pub struct FaultSetup {
    /// The scenario's name.
    pub name: String,
    /// The sensor errors and faults injected.
    pub injection: InjectionPlan,
    /// The reel drive.
    pub reel: ReelDrive,
    /// The controller's envelope.
    pub envelope: Envelope<f64>,
}

/// What `setup` injects, one line per item (empty: nothing).
pub fn injected_faults(setup: &FaultSetup) -> Vec<String> {
    let mut v = Vec::new();
    let plan = &setup.injection;
    for (name, c) in [
        ("length (m)", &plan.length.errors),
        ("alpha (rad)", &plan.alpha.errors),
        ("alpha_rate (rad/s)", &plan.alpha_rate),
        ("tension (N)", &plan.load_cell.errors),
    ] {
        let mut parts = Vec::new();
        if c.noise_std > 0.0 {
            parts.push(format!("noise σ = {}", c.noise_std));
        }
        if c.bias != 0.0 {
            parts.push(format!("bias {}", c.bias));
        }
        if c.quantum > 0.0 {
            parts.push(format!("quantum {}", c.quantum));
        }
        if let Some(w) = c.stuck {
            parts.push(format!("stuck {}", window(w.from_s, w.until_s)));
        }
        if !parts.is_empty() {
            v.push(format!("sensor {name}: {}", parts.join(", ")));
        }
    }
    if v.iter().any(|l| l.contains("noise")) || plan.alpha.dropout_prob > 0.0 {
        v.push(format!("noise seed {}", plan.seed));
    }
    if let Some(q) = plan.length.count_m() {
        v.push(format!(
            "reel encoder: {} counts per revolution of a {} m drum ({:.4e} m per count)",
            plan.length.counts_per_rev, plan.length.drum_radius_m, q
        ));
    }
    let a = &plan.alpha;
    if a.latency_periods > 0 {
        v.push(format!(
            "swing sensor latency: {} periods",
            a.latency_periods
        ));
    }
    if a.dropout_prob > 0.0 {
        v.push(format!(
            "swing sensor: no α with probability {}",
            a.dropout_prob
        ));
    }
    for w in &a.dropout {
        v.push(format!("no α {}", window(w.from_s, w.until_s)));
    }
    if !plan.load_cell.enabled {
        v.push("no load cell".to_string());
    } else if plan.load_cell.full_scale_n < f64::INFINITY {
        v.push(format!(
            "load cell full scale {} N",
            plan.load_cell.full_scale_n
        ));
    }
    for w in &plan.dropout {
        v.push(format!(
            "dropout (no sample) {}",
            window(w.from_s, w.until_s)
        ));
    }
    for c in &plan.corrupt {
        v.push(format!(
            "{} reads {} {}",
            c.sensor.name(),
            c.value,
            window(c.window.from_s, c.window.until_s)
        ));
    }
    for g in &plan.length_glitch {
        v.push(format!("length glitch {} m at {} s", g.size_m, g.at_s));
    }
    let r = &setup.reel;
    if r.lag_s > 0.0 || r.max_rate_mps < f64::INFINITY || r.max_accel_mps2 < f64::INFINITY {
        v.push(format!(
            "reel drive: lag {} s, rate limit {} m/s, acceleration limit {} m/s²",
            r.lag_s, r.max_rate_mps, r.max_accel_mps2
        ));
    }
    v
}

/// The fault summary of a run as text (printed by `tss-sim run`, written to `faults.txt`);
/// `setup` is typically the run's `&Scenario`.
pub fn render_fault_summary(setup: impl Into<FaultSetup>, s: &FaultSummary) -> String {
    let setup = setup.into();
    let mut o = String::new();
    let dt = s.period_s;
    let _ = writeln!(
        o,
        "Faults, health and envelope of scenario `{}`",
        setup.name
    );
    let injected = injected_faults(&setup);
    if injected.is_empty() {
        let _ = writeln!(o, "  injected: nothing (perfect sensors, ideal reel)");
    } else {
        let _ = writeln!(o, "  injected:");
        for l in &injected {
            let _ = writeln!(o, "    {l}");
        }
    }
    let _ = writeln!(
        o,
        "  health: nominal {:.0} s, degraded {:.0} s, safe hold {:.0} s; final {} ({} ticks, {} without a sample)",
        s.nominal_s,
        s.degraded_s,
        s.safe_hold_s,
        s.final_health.map_or("-", health_name),
        s.ticks,
        s.missing_ticks
    );
    if s.faults.is_empty() {
        let _ = writeln!(o, "  faults raised: none");
    } else {
        let _ = writeln!(o, "  faults raised (first, last, ticks):");
        for t in &s.faults {
            let _ = writeln!(
                o,
                "    {:<26} {:>9.0} s {:>9.0} s {:>7}",
                fault_name(t.fault),
                t.first_s,
                t.last_s,
                t.ticks
            );
        }
    }
    let total = s.events.len() + s.events_dropped as usize;
    if total > 0 {
        let shown = s.events.len().min(EVENTS_SHOWN);
        let _ = writeln!(o, "  events ({shown} of {total} shown):");
        for e in s.events.iter().take(shown) {
            let what = match e.kind {
                FaultEventKind::Health { from, to, fault } => format!(
                    "{} → {}{}",
                    health_name(from),
                    health_name(to),
                    fault.map_or(String::new(), |f| format!(" ({})", fault_name(f)))
                ),
                FaultEventKind::Raised(f) => format!("raised {}", fault_name(f)),
            };
            let _ = writeln!(o, "    {:>9.0} s  {what}", e.t_s);
        }
    }
    let _ = writeln!(
        o,
        "  length estimate: max |estimate − true| = {:.4} m at {:.0} s",
        s.max_length_error_m.0, s.max_length_error_m.1
    );
    let _ = writeln!(
        o,
        "  tension: min {:.6} N at {:.0} s; slack (T ≤ 0): {} events, {:.0} s",
        s.min_tension_n.0, s.min_tension_n.1, s.slack_events, s.slack_s
    );
    if !s.slack_episodes.is_empty() {
        let shown: Vec<String> = s
            .slack_episodes
            .iter()
            .take(8)
            .map(|(a, b)| format!("{a:.0}–{b:.0} s"))
            .collect();
        let more = s.slack_episodes.len().saturating_sub(shown.len());
        let _ = writeln!(
            o,
            "    slack episodes: {}{}",
            shown.join(", "),
            if more > 0 {
                format!(" (+{more} more)")
            } else {
                String::new()
            }
        );
    }
    let _ = writeln!(
        o,
        "  tether: {:.3} … {:.3} m; outside [{}, {}] m for {:.0} s (by at most {:.4} m)",
        s.length_range_m.0,
        s.length_range_m.1,
        setup.envelope.min_length_m,
        setup.envelope.max_length_m,
        s.outside_envelope_s,
        s.max_excursion_m
    );
    let _ = writeln!(
        o,
        "  commands: max |l̇| = {:.4} m/s (limit {}), max |Δl̇|/Δt = {:.4} m/s² (limit {}); \
         beyond the limits: rate {} ticks, acceleration {} ticks",
        s.max_rate_cmd_mps,
        setup.envelope.max_rate_mps,
        s.max_accel_cmd_mps2,
        setup.envelope.max_accel_mps2,
        s.rate_exceeded_ticks,
        s.accel_exceeded_ticks
    );
    let flags: Vec<String> = s
        .flags
        .named()
        .iter()
        .filter(|(_, n)| *n > 0)
        .map(|(name, n)| format!("{name} {n}"))
        .collect();
    let _ = writeln!(
        o,
        "  controller flags (ticks): {}",
        if flags.is_empty() {
            "none".to_string()
        } else {
            flags.join(", ")
        }
    );
    if s.reel_rate_saturated_ticks > 0 || s.reel_accel_saturated_ticks > 0 {
        let _ = writeln!(
            o,
            "  reel drive saturated: rate {} ticks ({:.0} s), acceleration {} ticks ({:.0} s)",
            s.reel_rate_saturated_ticks,
            f64::from(s.reel_rate_saturated_ticks) * dt,
            s.reel_accel_saturated_ticks,
            f64::from(s.reel_accel_saturated_ticks) * dt
        );
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pcg32_matches_the_reference_implementation() {
        // pcg32-demo of pcg-random.org: pcg32_srandom(42, 54), first six outputs.
        let mut rng = Pcg32::new(42, 54);
        let got: Vec<u32> = (0..6).map(|_| rng.next_u32()).collect();
        assert_eq!(
            got,
            [0xa15c02b7, 0x7b47f409, 0xba1d3330, 0x83d2f293, 0xbfa4784b, 0xcbed606e]
        );
    }

    #[test]
    fn normal_deviates_have_unit_variance_and_are_reproducible() {
        let mut a = Pcg32::new(7, 2);
        let n = 200_000;
        let xs: Vec<f64> = (0..n).map(|_| a.normal()).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        // 5σ bounds of the sample mean and variance.
        assert!(mean.abs() < 5.0 / (n as f64).sqrt(), "{mean}");
        assert!((var - 1.0).abs() < 5.0 * (2.0 / n as f64).sqrt(), "{var}");
        let mut b = Pcg32::new(7, 2);
        assert!(xs.iter().take(100).all(|&x| x == b.normal()));
        let mut c = Pcg32::new(7, 3);
        assert_ne!(xs[0], c.normal());
    }

    fn channel(cfg: SensorErrors) -> Channel {
        Channel::new(&cfg, 1, 1)
    }

    #[test]
    fn bias_quantum_and_stuck_window() {
        let mut c = channel(SensorErrors {
            bias: 0.3,
            quantum: 0.25,
            stuck: Some(Window {
                from_s: 2.0,
                until_s: 4.0,
            }),
            ..SensorErrors::default()
        });
        assert_eq!(c.read(1.0, 0.0), 1.25); // 1.3 → 1.25
        assert_eq!(c.read(1.2, 1.0), 1.5);
        assert_eq!(c.read(2.0, 2.0), 2.25); // stuck from here
        assert_eq!(c.read(3.0, 3.0), 2.25);
        assert_eq!(c.read(4.0, 4.0), 4.25); // released
    }

    #[test]
    fn noise_has_the_stated_deviation() {
        let mut c = channel(SensorErrors {
            noise_std: 0.01,
            ..SensorErrors::default()
        });
        let n = 20_000;
        let rms = ((0..n)
            .map(|i| c.read(5.0, f64::from(i)) - 5.0)
            .map(|e| e * e)
            .sum::<f64>()
            / f64::from(n))
        .sqrt();
        assert!((rms - 0.01).abs() < 5e-4, "{rms}");
    }

    fn truth(t_s: f64) -> Truth {
        Truth {
            length_m: 100.0 + 2.0 * t_s,
            reel_rate_mps: 2.0,
            tension_n: 0.5,
            alpha_rad: -0.7,
            alpha_rate_radps: 1e-4,
            orbit_rate_radps: 1.06e-3,
            true_anomaly_rad: 1.06e-3 * t_s,
        }
    }

    fn sample(s: Sensed) -> Reading {
        match s {
            Sensed::Sample(r) => r,
            Sensed::Missing => panic!("no sample"),
        }
    }

    #[test]
    fn by_default_every_sensor_but_the_rate_sensor_reads_the_truth() {
        let mut inj = Injector::new(&InjectionPlan::default(), 1.0);
        let t = truth(3.0);
        assert_eq!(
            sample(inj.sense(3, 3.0, &t)),
            Reading {
                length_m: t.length_m,
                reel_rate_mps: Some(2.0),
                tension_n: Some(0.5),
                alpha_rad: Some(-0.7),
                alpha_rate_radps: None,
                orbit_rate_radps: t.orbit_rate_radps,
                true_anomaly_rad: t.true_anomaly_rad,
            }
        );
        let mut ideal = Injector::new(
            &InjectionPlan {
                alpha_rate_enabled: true,
                ..InjectionPlan::default()
            },
            1.0,
        );
        assert_eq!(sample(ideal.sense(3, 3.0, &t)).alpha_rate_radps, Some(1e-4));
    }

    #[test]
    fn an_alpha_dropout_keeps_the_sample_and_a_sample_dropout_loses_it() {
        let window = Window {
            from_s: 10.0,
            until_s: 12.0,
        };
        let mut inj = Injector::new(
            &InjectionPlan {
                alpha: SwingSensorModel {
                    dropout: vec![window],
                    ..SwingSensorModel::default()
                },
                dropout: vec![Window {
                    from_s: 20.0,
                    until_s: 21.0,
                }],
                ..InjectionPlan::default()
            },
            1.0,
        );
        for k in 0..25 {
            let t_s = f64::from(k);
            let s = inj.sense(k, t_s, &truth(t_s));
            match k {
                10 | 11 => {
                    let r = sample(s);
                    assert_eq!(r.alpha_rad, None);
                    assert_eq!(r.length_m, truth(t_s).length_m);
                }
                20 => assert_eq!(s, Sensed::Missing),
                _ => assert_eq!(sample(s).alpha_rad, Some(-0.7)),
            }
        }
    }

    #[test]
    fn the_encoder_s_rate_is_its_count_difference_and_corruptions_reach_every_reading() {
        let mut inj = Injector::new(
            &InjectionPlan {
                length: EncoderModel {
                    counts_per_rev: 1000,
                    drum_radius_m: 0.1,
                    ..EncoderModel::default()
                },
                corrupt: vec![
                    Corruption {
                        sensor: SensedQuantity::Tension,
                        window: Window {
                            from_s: 2.0,
                            until_s: 3.0,
                        },
                        value: f64::NAN,
                    },
                    Corruption {
                        sensor: SensedQuantity::ReelRate,
                        window: Window {
                            from_s: 2.0,
                            until_s: 3.0,
                        },
                        value: 99.0,
                    },
                ],
                ..InjectionPlan::default()
            },
            1.0,
        );
        let q = std::f64::consts::TAU * 0.1 / 1000.0;
        let first = sample(inj.sense(0, 0.0, &truth(0.0)));
        assert_eq!(first.reel_rate_mps, None);
        assert_eq!(first.length_m, (100.0 / q).floor() * q);
        let second = sample(inj.sense(1, 1.0, &truth(1.0)));
        let counts = (102.0 / q).floor() - (100.0 / q).floor();
        assert_eq!(second.reel_rate_mps, Some(counts * q));
        let third = sample(inj.sense(2, 2.0, &truth(2.0)));
        assert!(third.tension_n.is_some_and(f64::is_nan));
        assert_eq!(third.reel_rate_mps, Some(99.0));
    }

    #[test]
    fn glitch_tick_rounding() {
        assert_eq!(first_tick_at(100.0, 1.0), 100);
        assert_eq!(first_tick_at(100.2, 1.0), 101);
        assert_eq!(first_tick_at(0.3, 0.1), 3);
    }
}
