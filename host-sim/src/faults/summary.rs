//! The fault summary of a run: [`SummaryBuilder`] watches every control tick and produces
//! the [`FaultSummary`] stored in `History::faults`.

use tss_reel::controller::{Envelope, Fault, Flags, Health, Output};
use tss_reel::Real;

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
    /// Largest |α| of the tether (the plant's truth), rad, and when (s).
    pub max_abs_alpha_rad: (f64, f64),
    /// First time |α| reached π/2 ([`TUMBLE_ANGLE_RAD`]: the tether tumbled),
    /// s (`None`: never).
    pub tumble_s: Option<f64>,
    /// Periods in which the reel drive's own rate limit clipped the command.
    pub reel_rate_saturated_ticks: u32,
    /// Periods in which the reel drive ran at its own acceleration limit.
    pub reel_accel_saturated_ticks: u32,
    /// The slack that counts: from the point the tether must be taut on
    /// (`simulation.taut_from_length_m`, docs/equations.md §17.7).
    pub taut: TautSummary,
}

/// Slack from the point the tether must be taut on: the first tick at which the length reached
/// `from_length_m` (docs/equations.md §17.7). Before it the tensions are millinewtons, below what
/// the reel's friction lets it regulate; every tick from it on counts.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TautSummary {
    /// The length from which the tether must be taut, m.
    pub from_length_m: f64,
    /// When the length first reached it, s (`None`: never).
    pub from_s: Option<f64>,
    /// Times the tension fell to ≤ 0 from then on (a tick already slack at the point counts as
    /// one).
    pub slack_events: u32,
    /// Time with tension ≤ 0 from then on, s.
    pub slack_s: f64,
    /// The least tension from then on, N, and when (s) (+∞ before the point is reached).
    pub min_tension_n: (f64, f64),
}

/// The |α| at which the tether has tumbled, rad: π/2, the line horizontal (past it the tether
/// librates over the top, outside every law's domain).
pub const TUMBLE_ANGLE_RAD: f64 = std::f64::consts::FRAC_PI_2;

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
    /// The tether's true in-plane angle α, rad.
    pub alpha_rad: f64,
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
    /// The last tick was slack and counted by the taut summary.
    taut_slack: bool,
}

impl SummaryBuilder {
    /// A builder for a run with control period `period_s` and the controller's envelope.
    pub fn new(period_s: f64, envelope: &Envelope<f64>) -> Self {
        Self {
            s: FaultSummary {
                period_s,
                min_tension_n: (f64::INFINITY, 0.0),
                length_range_m: (f64::INFINITY, f64::NEG_INFINITY),
                taut: TautSummary {
                    min_tension_n: (f64::INFINITY, 0.0),
                    ..TautSummary::default()
                },
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
            taut_slack: false,
        }
    }

    /// The tether must be taut from the first tick at which the length reaches `length_m` on
    /// (default 0: from the start).
    pub fn taut_from_length(mut self, length_m: f64) -> Self {
        self.s.taut.from_length_m = length_m;
        self
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
        let taut = &mut s.taut;
        if taut.from_s.is_none() && r.length_m >= taut.from_length_m {
            taut.from_s = Some(r.t_s);
        }
        if taut.from_s.is_some() {
            if r.tension_n < taut.min_tension_n.0 {
                taut.min_tension_n = (r.tension_n, r.t_s);
            }
            if slack {
                taut.slack_s += dt;
                if !self.taut_slack {
                    taut.slack_events += 1;
                }
            }
            self.taut_slack = slack;
        }
        let alpha = r.alpha_rad.abs();
        // NaN counts as the largest.
        if alpha > s.max_abs_alpha_rad.0 || (alpha.is_nan() && !s.max_abs_alpha_rad.0.is_nan()) {
            s.max_abs_alpha_rad = (alpha, r.t_s);
        }
        let tumbled = alpha >= TUMBLE_ANGLE_RAD || alpha.is_nan();
        if s.tumble_s.is_none() && tumbled {
            s.tumble_s = Some(r.t_s);
        }
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
