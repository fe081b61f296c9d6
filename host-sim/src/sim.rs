//! The closed loop: the `tss-reel` controller core (f32, exactly as on the target) flying the
//! f64 plant of Eq. 5, synchronised on the control period.
//!
//! Each tick: the plant's state is sensed (through the scenario's sensor errors and injected
//! faults, `faults::Injector`, then rounded to f32), the controller steps (or, in a dropout,
//! steps without a sample), its rate command is held over the period (zero-order hold) and
//! drives the reel (`reel::Reel`: ideal by default, else lagging and saturating) while RK4
//! integrates the plant. Every tick feeds the fault summary (`History::faults`).

use crate::faults::{InjectionPlan, Injector, Sensed, SummaryBuilder, TickRecord, Truth};
use crate::history::{History, PhaseLabel, Sample};
use crate::plant::{ix, Plant, State};
use crate::reel::{Reel, ReelDrive, ReelSaturation};
use crate::scenario::Scenario;
use tss_reel::controller::{Config, ConfigError, Controller, Input, Output, Phase};
use tss_reel::orbit::Orbit;
use tss_reel::schedule::BandSchedule;
use tss_reel::Real;

/// Why a run could not be completed.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The scenario's numbers do not make a valid controller.
    #[error("controller configuration rejected: {0}")]
    Config(ConfigError),
    /// A timing field is not a whole number of control periods.
    #[error("{field} = {value} s is not a whole number of control periods ({period_s} s)")]
    Timing {
        /// The scenario field.
        field: &'static str,
        /// Its value, s.
        value: f64,
        /// The control period, s.
        period_s: f64,
    },
    /// The controller in the loop failed (the processor-in-the-loop link, `crate::pil`).
    #[error("the processor-in-the-loop link failed")]
    Link(#[source] Box<dyn std::error::Error + Send + Sync>),
    /// The plant state stopped being finite (a physically impossible run).
    #[error("the plant state became non-finite at t = {t_s} s")]
    Diverged {
        /// Mission time, s.
        t_s: f64,
    },
}

/// The controller configuration a scenario describes, in the controller's scalar type
/// ([`Scenario::controller_config`]), once the stage-2 start is a whole number of periods.
pub fn controller_config<T: Real>(sc: &Scenario) -> Result<Config<T>, SimError> {
    ticks(
        "stage2.start_time_s",
        sc.stage2.start_time_s,
        sc.controller.period_s,
    )?;
    Ok(sc.controller_config())
}

/// The plant a scenario describes.
pub fn plant(sc: &Scenario) -> Plant {
    Plant {
        orbit: Orbit::elliptic(sc.orbit.semi_major_axis_m, sc.orbit.eccentricity),
        masses: sc.mass_model(),
    }
}

/// `value_s` as a whole number of periods (to 1e-9 relative), or a [`SimError::Timing`].
fn ticks(field: &'static str, value_s: f64, period_s: f64) -> Result<u32, SimError> {
    let n = (value_s / period_s).round();
    let ok = n >= 0.0
        && n <= f64::from(u32::MAX)
        && (n * period_s - value_s).abs() <= 1e-9 * value_s.abs().max(period_s);
    if ok {
        Ok(n as u32)
    } else {
        Err(SimError::Timing {
            field,
            value: value_s,
            period_s,
        })
    }
}

/// The initial plant state: l(0), α(0) = α_r(l0) + δ(0), α̇(0) = δ̇(0) + (∂α_r/∂l) l̇0, β, β̇,
/// with α_r the stage-1 schedule of `cfg`.
pub fn initial_state<T: Real>(sc: &Scenario, cfg: &Config<T>) -> State {
    let s = &cfg.stage1.schedule;
    let schedule = BandSchedule::<f64> {
        low_length_m: s.low_length_m.to_f64(),
        low_angle_rad: s.low_angle_rad.to_f64(),
        low_slope_rad_per_m: s.low_slope_rad_per_m.to_f64(),
        high_length_m: s.high_length_m.to_f64(),
        high_angle_rad: s.high_angle_rad.to_f64(),
        high_slope_rad_per_m: s.high_slope_rad_per_m.to_f64(),
    };
    let r = schedule.eval(sc.initial.length_m);
    State::from([
        sc.orbit.initial_true_anomaly_rad,
        sc.initial.length_m,
        r.angle_rad + sc.initial.delta_rad,
        sc.initial.delta_rate_radps + r.slope_rad_per_m * sc.initial.length_rate_mps,
        sc.initial.beta_rad,
        sc.initial.beta_rate_radps,
    ])
}

/// Runs the scenario with the flight controller (f32) in the loop.
///
/// `probe_times_s` are instants (whole control periods) at which the length is recorded in
/// [`History::probes`]; `progress` is called with the mission time every simulated minute.
pub fn run(
    sc: &Scenario,
    probe_times_s: &[f64],
    progress: &mut dyn FnMut(f64),
) -> Result<History, SimError> {
    run_with::<f32>(sc, probe_times_s, progress)
}

/// Runs the scenario with the controller evaluated in scalar type `T` (f32 is the flight
/// build; f64 evaluates the same law in double precision, for accuracy studies).
pub fn run_with<T: Real>(
    sc: &Scenario,
    probe_times_s: &[f64],
    progress: &mut dyn FnMut(f64),
) -> Result<History, SimError> {
    let mut ctl = Controller::new(controller_config::<T>(sc)?).map_err(SimError::Config)?;
    run_stepper(sc, &mut ctl, probe_times_s, progress)
}

/// The controller in the loop, one control period at a time: the core linked into the
/// simulator ([`Controller`]) or the flight firmware in QEMU over the processor-in-the-loop
/// link (`crate::pil`).
pub trait Stepper<T> {
    /// One control period: `input` is the sensed sample, `None` when none arrived (a dropout).
    fn step(&mut self, tick: u32, input: Option<&Input<T>>) -> Result<Output<T>, SimError>;
}

impl<T: Real> Stepper<T> for Controller<T> {
    fn step(&mut self, tick: u32, input: Option<&Input<T>>) -> Result<Output<T>, SimError> {
        Ok(match input {
            Some(x) => *Controller::step(self, x),
            None => *self.step_missing(tick),
        })
    }
}

/// Runs the scenario with `stepper` as the controller: the plant loop of [`run_with`].
pub fn run_stepper<T: Real, S: Stepper<T> + ?Sized>(
    sc: &Scenario,
    stepper: &mut S,
    probe_times_s: &[f64],
    progress: &mut dyn FnMut(f64),
) -> Result<History, SimError> {
    let period = sc.controller.period_s;
    let cfg = controller_config::<T>(sc)?;
    let mut x = initial_state(sc, &cfg);
    let plant = plant(sc);
    let total = ticks("simulation.duration_s", sc.simulation.duration_s, period)?;
    let every = ticks(
        "simulation.output_interval_s",
        sc.simulation.output_interval_s,
        period,
    )?
    .max(1);
    let mut probes: Vec<(u32, f64)> = Vec::with_capacity(probe_times_s.len());
    for &t in probe_times_s {
        probes.push((ticks("probe time", t, period)?, t));
    }
    let substeps = sc.simulation.substeps.max(1);
    let h = period / f64::from(substeps);
    let progress_every = ticks("progress", 60.0, period).unwrap_or(60).max(1);

    let mut history = History {
        samples: Vec::new(), // grown as written: never sized from the asked duration
        probes: Vec::with_capacity(probes.len()),
        ..History::default()
    };
    let mut injector = Injector::new(&InjectionPlan::from(sc), period);
    let mut reel = Reel::new(&ReelDrive::from(&sc.reel), sc.initial.length_rate_mps);
    let ideal_reel = reel.is_ideal();
    let mut summary = SummaryBuilder::new(period, &sc.envelope.to_envelope());
    let mut next_probe = 0;
    for tick in 0..=total {
        let t_s = f64::from(tick) * period;
        if !x.iter().all(|v| v.is_finite()) {
            return Err(SimError::Diverged { t_s });
        }
        let truth = Truth {
            length_m: x[ix::LENGTH],
            alpha_rad: x[ix::ALPHA],
            alpha_rate_radps: x[ix::ALPHA_RATE],
            orbit_rate_radps: plant.orbit_rate_radps(x[ix::THETA]),
        };
        let sensed = injector.sense(tick, t_s, &truth);
        let out = match sensed {
            Sensed::Sample(r) => stepper.step(
                tick,
                Some(&Input {
                    tick,
                    length_m: T::from_f64(r.length_m),
                    alpha_rad: T::from_f64(r.alpha_rad),
                    alpha_rate_radps: T::from_f64(r.alpha_rate_radps),
                    orbit_rate_radps: T::from_f64(r.orbit_rate_radps),
                }),
            )?,
            Sensed::Missing => stepper.step(tick, None)?,
        };
        let rate = out.rate_cmd_mps.to_f64();
        // The tension of Eq. 5a at the start of the period: with the ideal reel l̈ is the
        // commanded acceleration; with a real drive, its actual rate and acceleration.
        let (tension_n, reel_sat) = if ideal_reel {
            let accel = out.accel_cmd_mps2.to_f64();
            (plant.tension_n(&x, rate, accel), ReelSaturation::default())
        } else {
            let (v, a) = (reel.rate_after(rate, 0.0), reel.accel_after(rate, 0.0));
            (plant.tension_n(&x, v, a), reel.saturation(rate, period))
        };
        summary.record(
            &TickRecord {
                tick,
                t_s,
                length_m: x[ix::LENGTH],
                tension_n,
                missing: sensed == Sensed::Missing,
                reel: reel_sat,
            },
            &out,
        );
        while next_probe < probes.len() && probes[next_probe].0 <= tick {
            if probes[next_probe].0 == tick {
                history.probes.push((probes[next_probe].1, x[ix::LENGTH]));
            }
            next_probe += 1;
        }
        if tick % every == 0 || tick == total {
            history.samples.push(sample(&x, t_s, tension_n, &out));
        }
        if tick % progress_every == 0 {
            progress(t_s);
        }
        if tick == total {
            break;
        }
        if ideal_reel {
            for _ in 0..substeps {
                x = plant.rk4_step(&x, rate, h);
            }
        } else {
            for k in 0..substeps {
                x = rk4_with_reel(&plant, &x, &reel, rate, f64::from(k) * h, h);
            }
            reel.advance(rate, period);
        }
    }
    history.faults = summary.finish();
    Ok(history)
}

/// One RK4 step of `h_s` seconds starting `t0_s` into the period, with the reel's rate v(t)
/// under the held command (`reel` is the drive at the start of the period): each stage sees
/// the rate at its own time, so l integrates v(t) (Simpson's rule) and Eq. 5b sees l̇ = v(t).
fn rk4_with_reel(
    plant: &Plant,
    x: &State,
    reel: &Reel,
    command_mps: f64,
    t0_s: f64,
    h_s: f64,
) -> State {
    let v = |t: f64| reel.rate_after(command_mps, t);
    let (v0, v1, v2) = (v(t0_s), v(t0_s + 0.5 * h_s), v(t0_s + h_s));
    plant.rk4_step_varying(x, [v0, v1, v2], h_s)
}

fn sample<T: Real>(x: &State, t_s: f64, tension_n: f64, out: &Output<T>) -> Sample {
    let rate = out.rate_cmd_mps.to_f64();
    let accel = out.accel_cmd_mps2.to_f64();
    Sample {
        t_s,
        length_m: x[ix::LENGTH],
        length_rate_mps: rate,
        alpha_rad: x[ix::ALPHA],
        alpha_rate_radps: x[ix::ALPHA_RATE],
        alpha_ref_rad: out.alpha_ref_rad.to_f64(),
        delta_rad: out.delta_rad.to_f64(),
        delta_rate_radps: out.delta_rate_radps.to_f64(),
        beta_rad: x[ix::BETA],
        tension_n,
        length_accel_mps2: accel,
        law_rate_mps: out.law_rate_mps.to_f64(),
        blend_weight: out.blend_weight.to_f64(),
        phase: phase_label(out.phase),
        flags: out.flags.0,
    }
}

/// The history label of a controller phase.
pub fn phase_label(p: Phase) -> PhaseLabel {
    match p {
        Phase::Deploy => PhaseLabel::Deploy,
        Phase::Keep1 => PhaseLabel::Keep1,
        Phase::Slew => PhaseLabel::Slew,
        Phase::Retrieve => PhaseLabel::Retrieve,
        Phase::Keep2 => PhaseLabel::Keep2,
    }
}
