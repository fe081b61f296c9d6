//! The classic deployment laws beside the paper's, as a simulator concept (`[controller] law`):
//! the laws that command the reel's **tension** rather than its rate (docs/equations.md §15).
//!
//! - [`rupp`]: Rupp's tension law T = m_e Ω²[a(l − l_f) + b l̇/Ω + c l_f] (NASA TM X-64963).
//! - [`tracking`]: a saturated tension law with an explicit positive-tension constraint,
//!   tracking a length-rate schedule through Eq. 5a.
//!
//! The paper's law stays the flight core (`tss_reel::controller::Controller`, f32); these are
//! f64 simulator code. They fly in the same closed loop (`crate::sim::run`, which picks the law) as a
//! [`Stepper`]: on the same sensed sample as the paper's law (sensor errors and injected faults
//! reach them the same way), against either plant, in the same missions and Monte Carlo
//! campaigns. Each period a law reads the sensed length, the reel's rate (the encoder's rate
//! when the sample has one, else the backward difference of the sensed lengths) and the orbit
//! rate (`Input::alpha_rad` is only reported: neither law feeds back on α), and commands a tension that the plant's reel holds over the period (zero-order hold):
//! the rigid plant integrates l̈ from Eq. 5a under it, the elastic plant's drum motor applies
//! the torque T·r (`crate::plant::Command::tension_n`).
//!
//! **Stages** as the paper's mission: l_f = `stage1.keep_length_m` (deployment and keep) until
//! `stage2.start_time_s`, then `stage2.keep_length_m` (retrieval and keep). The phase reported
//! is Deploy/Retrieve until l first comes within `controller.keep_capture_m` of l_f, then
//! Keep1/Keep2. **Dropouts**: a period without a sample, or with a non-finite length or orbit
//! rate, holds the last tension (health Degraded for that period). **Floor**: a tether only pulls: Rupp's command is floored at 0,
//! the tracking law's at its T_min > 0.

pub mod rupp;
mod sensed;
pub mod tracking;

use tss_reel::controller::{Controller, Flags, Health, Input, Output, Phase};
use tss_reel::mass::MassModel;

use crate::plant::Command;
use crate::scenario::{LawName, Scenario};
use crate::stepper::{controller_config, SimError, Stepper};
use rupp::{Rupp, RuppGains};
pub use sensed::Sensed;
use tracking::{Tracking, TrackingParams};

/// A tension law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TensionLaw {
    /// [`rupp::Rupp`].
    Rupp(Rupp),
    /// [`tracking::Tracking`].
    Tracking(Tracking),
}

impl TensionLaw {
    /// The law `name` configured by `sc` (`None` for the paper's, which is not a tension law).
    pub fn from_scenario(sc: &Scenario, name: LawName) -> Option<Self> {
        let masses: MassModel<f64> = sc.mass_model();
        match name {
            LawName::Paper => None,
            LawName::Rupp => {
                let r = &sc.controller.rupp;
                Some(Self::Rupp(Rupp {
                    gains: RuppGains {
                        length: r.length_gain,
                        rate: r.rate_gain,
                        bias: r.bias_gain,
                    },
                    masses,
                }))
            }
            LawName::Tracking => {
                let t = &sc.controller.tracking;
                Some(Self::Tracking(Tracking {
                    params: TrackingParams {
                        schedule_rate: t.schedule_rate,
                        retrieve_schedule_rate: t.retrieve_schedule_rate,
                        start_rate_mps: t.schedule_start_rate_mps,
                        rate_gain: t.rate_gain,
                        min_tension_n: t.min_tension_n,
                        max_tension_n: t.max_tension_n,
                    },
                    masses,
                }))
            }
        }
    }

    /// The smallest tension the law commands, N: Rupp's 0 (a tether only pulls), the tracking
    /// law's T_min > 0.
    pub fn floor_n(&self) -> f64 {
        match self {
            Self::Rupp(_) => 0.0,
            Self::Tracking(t) => t.params.min_tension_n,
        }
    }

    /// The commanded tension toward `target_m`, N: finite and ≥ [`TensionLaw::floor_n`] (a
    /// non-finite value, from a non-finite reading, becomes the floor too).
    pub fn tension_n(&self, s: &Sensed, target_m: f64) -> f64 {
        let t = match self {
            Self::Rupp(r) => r.tension_n(s, target_m),
            Self::Tracking(t) => t.saturated_tension_n(s, target_m),
        };
        if t.is_finite() {
            t.max(self.floor_n())
        } else {
            self.floor_n()
        }
    }

    /// The rate the law aims at now, m/s (the tracking law's schedule; 0 for Rupp's, which
    /// aims at rest at l_f).
    pub fn rate_ref_mps(&self, s: &Sensed, target_m: f64) -> f64 {
        match self {
            Self::Rupp(_) => 0.0,
            Self::Tracking(t) => t.schedule(s.length_m, target_m, s.orbit_rate_radps).0,
        }
    }
}

/// The mission's two stages as a tension law flies them.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Stages {
    keep1_m: f64,
    keep2_m: f64,
    stage2_tick: u32,
    capture_m: f64,
}

/// A tension law in the closed loop: a [`Stepper`] whose reel command is a tension.
#[derive(Clone, Debug)]
pub struct LawStepper {
    law: TensionLaw,
    stages: Stages,
    period_s: f64,
    /// The sensed length of the last sample and its tick.
    last_length: Option<(u32, f64)>,
    /// The rate used last, m/s (the scenario's initial rate before the first difference).
    rate_mps: f64,
    /// The tension held, N (the law's floor before the first usable sample).
    tension_n: f64,
    phase: Phase,
    /// An idle flight controller's output: the fields a tension law has no use for keep its
    /// values.
    template: Output<f32>,
}

impl LawStepper {
    /// The tension law `name` for `sc` (`None` for the paper's law).
    pub fn new(sc: &Scenario, name: LawName) -> Result<Option<Self>, SimError> {
        let Some(law) = TensionLaw::from_scenario(sc, name) else {
            return Ok(None);
        };
        let cfg = controller_config::<f32>(sc)?;
        let stage2_tick = (sc.stage2.start_time_s / sc.controller.period_s).round() as u32;
        let template = *Controller::new(cfg)
            .map_err(SimError::Config)?
            .step_missing(0);
        Ok(Some(Self {
            law,
            stages: Stages {
                keep1_m: sc.stage1.keep_length_m,
                keep2_m: sc.stage2.keep_length_m,
                stage2_tick,
                capture_m: sc.controller.keep_capture_m,
            },
            period_s: sc.controller.period_s,
            last_length: None,
            rate_mps: sc.initial.length_rate_mps,
            // Before the first usable sample: the law's floor.
            tension_n: law.floor_n(),
            phase: Phase::Deploy,
            template,
        }))
    }

    /// The law's reading of a sample: the sensed values, with the reel's rate from its encoder
    /// when the sample has it, else from the backward difference of the sensed lengths (kept
    /// from the last period at the first sample).
    fn sense(&mut self, tick: u32, x: &Input<f32>) -> Sensed {
        let l = f64::from(x.length_m);
        match x.reel_rate_mps.map(f64::from).filter(|v| v.is_finite()) {
            Some(v) => self.rate_mps = v,
            None => {
                if let Some((t0, l0)) = self.last_length {
                    let dt = f64::from(tick.saturating_sub(t0)) * self.period_s;
                    if dt > 0.0 {
                        self.rate_mps = (l - l0) / dt;
                    }
                }
            }
        }
        self.last_length = Some((tick, l));
        Sensed {
            length_m: l,
            rate_mps: self.rate_mps,
            alpha_rad: x.alpha_rad.map(f64::from),
            alpha_rate_radps: x.alpha_rate_radps.map(f64::from),
            orbit_rate_radps: f64::from(x.orbit_rate_radps),
        }
    }

    /// The stage's target and the phase after this sample.
    fn sequence(&mut self, tick: u32, l: f64) -> f64 {
        let s = self.stages;
        let stage2 = tick >= s.stage2_tick;
        let target = if stage2 { s.keep2_m } else { s.keep1_m };
        let near = (l - target).abs() <= s.capture_m;
        self.phase = match (self.phase, stage2) {
            (Phase::Deploy, false) if near => Phase::Keep1,
            (p @ (Phase::Deploy | Phase::Keep1), false) => p,
            (Phase::Deploy | Phase::Keep1, true) => Phase::Retrieve,
            (Phase::Retrieve | Phase::Slew, true) if near => Phase::Keep2,
            (p, _) => p,
        };
        target
    }
}

impl Stepper<f32> for LawStepper {
    fn step(&mut self, tick: u32, input: Option<&Input<f32>>) -> Result<Output<f32>, SimError> {
        // A reading the law cannot use (a non-finite length or orbit rate: a corrupted
        // sample) is treated as no reading: the last tension is held.
        let usable = input.filter(|x| x.length_m.is_finite() && x.orbit_rate_radps.is_finite());
        let (health, alpha, length, rate_ref) = match usable {
            Some(x) => {
                let s = self.sense(tick, x);
                let target = self.sequence(tick, s.length_m);
                self.tension_n = self.law.tension_n(&s, target);
                let rate_ref = self.law.rate_ref_mps(&s, target) as f32;
                (
                    Health::Nominal,
                    x.alpha_rad.unwrap_or(0.0),
                    x.length_m,
                    rate_ref,
                )
            }
            // No usable sample: hold the last tension.
            None => (
                Health::Degraded,
                self.template.delta_rad,
                self.last_length.map_or(0.0, |(_, l)| l as f32),
                0.0,
            ),
        };
        Ok(Output {
            tick,
            phase: self.phase,
            health,
            rate_cmd_mps: self.rate_mps as f32,
            accel_cmd_mps2: 0.0,
            // The history's law_rate column: the rate the law aims at.
            law_rate_mps: rate_ref,
            blend_weight: 0.0,
            alpha_ref_rad: 0.0,
            alpha_ref_rate_radps: 0.0,
            delta_rad: alpha,
            delta_rate_radps: 0.0,
            length_estimate_m: length,
            flags: Flags(0),
            fault: None,
            ..self.template
        })
    }

    fn reel_command(&self, _out: &Output<f32>) -> Command {
        Command {
            rate_mps: self.rate_mps,
            accel_mps2: 0.0,
            tension_n: Some(self.tension_n),
        }
    }
}
