//! The closed loop: the `tss-reel` controller core (f32, exactly as on the target) flying the
//! f64 plant of Eq. 5, synchronised on the control period.
//!
//! Each tick: the plant is observed and sensed (through the scenario's sensor errors and
//! injected faults, `faults::Injector`, then rounded to f32), the controller steps (or, in a
//! dropout, steps without a sample), and its rate command is held over the period
//! (zero-order hold) while the plant steps. The plant is either of `[plant] model`'s, behind
//! the [`Plant`] trait: the rigid rod of Eq. 5 (`plant::RigidPlant`, its reel ideal or
//! lagging and saturating) or the elastic truth model (`elastic::ElasticPlant`). Every tick
//! feeds the fault summary (`History::faults`). A tether paid out beyond its spool
//! (`envelope.max_length_m`) ends the run at that tick (`History::spool_overrun`). Before a
//! tick's step the on-board computer sends the scenario's telecommands due then
//! (`crate::obc`); after it, the unit's telemetry is kept (`History::telemetry`).

use crate::elastic::{ElasticParams, ElasticPlant, InitialConditions};
use crate::faults::{InjectionPlan, Injector, Reading, Sensed, SummaryBuilder, TickRecord, Truth};
use crate::history::{History, PhaseLabel, Sample, SpoolOverrun};
use crate::laws::LawStepper;
use crate::obc::{Obc, Unit};
use crate::plant::{ix, Command, Observation, Plant, RigidModel, RigidPlant, State};
use crate::reel::{Reel, ReelDrive};
use crate::scenario::{PlantModel, Scenario};
use crate::stepper::ticks;
pub use crate::stepper::{controller_config, SimError, Stepper};
use tss_reel::controller::{Config, Controller, Input, Output, Phase};
use tss_reel::orbit::Orbit;
use tss_reel::schedule::BandSchedule;
use tss_reel::Real;

/// The rigid plant's equations a scenario describes.
pub fn plant(sc: &Scenario) -> RigidModel {
    RigidModel {
        orbit: Orbit::elliptic(sc.orbit.semi_major_axis_m, sc.orbit.eccentricity),
        masses: sc.mass_model(),
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

/// Runs the scenario with its `[controller] law` in the loop: the flight controller (f32)
/// behind its PUS services (`crate::obc::Unit`: the scenario's telecommands reach it, its
/// telemetry is kept) for the paper's law, a tension law of `crate::laws` otherwise.
///
/// `probe_times_s` are instants (whole control periods) at which the length is recorded in
/// [`History::probes`]; `progress` is called with the mission time every simulated minute.
pub fn run(
    sc: &Scenario,
    probe_times_s: &[f64],
    progress: &mut dyn FnMut(f64),
) -> Result<History, SimError> {
    match LawStepper::new(sc, sc.controller.law)? {
        Some(mut law) => run_stepper::<f32, _>(sc, &mut law, probe_times_s, progress),
        None => {
            let ctl = Controller::new(controller_config::<f32>(sc)?).map_err(SimError::Config)?;
            run_stepper(sc, &mut Unit::new(ctl), probe_times_s, progress)
        }
    }
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

/// Runs the scenario with `stepper` as the controller: the plant loop of [`run_with`].
pub fn run_stepper<T: Real, S: Stepper<T> + ?Sized>(
    sc: &Scenario,
    stepper: &mut S,
    probe_times_s: &[f64],
    progress: &mut dyn FnMut(f64),
) -> Result<History, SimError> {
    let period = sc.controller.period_s;
    let cfg = controller_config::<T>(sc)?;
    let mut plant = flown_plant(sc, &cfg)?;
    let total = ticks("simulation.duration_s", sc.simulation.duration_s, period)?;
    let every = ticks(
        "simulation.output_interval_s",
        sc.simulation.output_interval_s,
        period,
    )?
    .max(1);
    let shape_every = if sc.plant.shape_interval_s > 0.0 {
        let s = sc.plant.shape_interval_s;
        Some(ticks("plant.shape_interval_s", s, period)?.max(1))
    } else {
        None
    };
    let mut probes: Vec<(u32, f64)> = Vec::with_capacity(probe_times_s.len());
    for &t in probe_times_s {
        probes.push((ticks("probe time", t, period)?, t));
    }
    let progress_every = ticks("progress", 60.0, period).unwrap_or(60).max(1);

    let mut history = History {
        samples: Vec::new(), // grown as written: never sized from the asked duration
        probes: Vec::with_capacity(probes.len()),
        ..History::default()
    };
    let mut injector = Injector::new(&InjectionPlan::from(sc), period);
    let mut summary = SummaryBuilder::new(period, &sc.envelope.to_envelope())
        .taut_from_length(sc.simulation.taut_from_length_m);
    let mut next_probe = 0;
    // The command held over the last period (before the first: the release rate), and the
    // encoder's length at the start of it: the reel's truth at the end of the period.
    let mut held = Command {
        rate_mps: sc.initial.length_rate_mps,
        accel_mps2: 0.0,
        tension_n: None,
    };
    let mut last_length_m: Option<f64> = None;
    let spool_m = sc.envelope.max_length_m;
    let mut obc = Obc::new(sc)?;
    for tick in 0..=total {
        let t_s = f64::from(tick) * period;
        if !plant.is_finite() {
            return Err(SimError::Diverged { t_s });
        }
        let now = plant.observe(&held);
        let seen = now.sensors;
        let truth = Truth {
            length_m: seen.length_m,
            reel_rate_mps: last_length_m
                .map_or(release_rate_mps(sc), |l| (seen.length_m - l) / period),
            tension_n: now.tension_n,
            alpha_rad: seen.alpha_rad,
            alpha_rate_radps: seen.alpha_rate_radps,
            orbit_rate_radps: seen.orbit_rate_radps,
            true_anomaly_rad: seen.true_anomaly_rad,
        };
        last_length_m = Some(seen.length_m);
        let sensed = injector.sense(tick, t_s, &truth);
        // The flight drive's faults over the period that ended reach the outer health.
        let reading = match sensed {
            Sensed::Sample(r) => Some(input(tick, &r)),
            Sensed::Missing => None,
        };
        obc.send_due(tick, stepper)?;
        let out = stepper.step_with_drive(tick, reading.as_ref(), plant.take_drive_faults())?;
        let command = stepper.reel_command(&out);
        let obs = plant.observe(&command);
        summary.record(
            &TickRecord {
                tick,
                t_s,
                length_m: obs.length_m,
                tension_n: obs.tension_n,
                alpha_rad: obs.alpha_rad,
                missing: sensed == Sensed::Missing,
                reel: obs.reel,
            },
            &out,
        );
        while next_probe < probes.len() && probes[next_probe].0 <= tick {
            if probes[next_probe].0 == tick {
                history.probes.push((probes[next_probe].1, obs.length_m));
            }
            next_probe += 1;
        }
        // The tether cannot pay out beyond its spool: the run stops at the tick it does.
        if obs.length_m > spool_m {
            history.spool_overrun = Some(SpoolOverrun {
                t_s,
                length_m: obs.length_m,
                spool_m,
            });
        }
        let last = tick == total || history.spool_overrun.is_some();
        let recorded = tick % every == 0 || last;
        history.telemetry.extend(stepper.take_telemetry(recorded)?);
        if recorded {
            history.samples.push(sample(&obs, t_s, &out));
            if let Some(e) = obs.elastic {
                history.elastic.push(e);
            }
        }
        if shape_every.is_some_and(|n| tick % n == 0) || last {
            if let Some(nodes) = plant.shape() {
                history.shapes.push((t_s, nodes));
            }
        }
        if tick % progress_every == 0 {
            progress(t_s);
        }
        if last {
            break;
        }
        plant.step(&command, period);
        held = command;
    }
    history.faults = summary.finish();
    Ok(history)
}

/// The controller's input of a reading, field by field.
fn input<T: Real>(tick: u32, r: &Reading) -> Input<T> {
    Input {
        tick,
        length_m: T::from_f64(r.length_m),
        reel_rate_mps: r.reel_rate_mps.map(T::from_f64),
        tension_n: r.tension_n.map(T::from_f64),
        alpha_rad: r.alpha_rad.map(T::from_f64),
        alpha_rate_radps: r.alpha_rate_radps.map(T::from_f64),
        orbit_rate_radps: T::from_f64(r.orbit_rate_radps),
        true_anomaly_rad: T::from_f64(r.true_anomaly_rad),
    }
}

/// The elastic plant's initial conditions: the rigid plant's (straight at l(0), along
/// α(0), β(0), unstretched, paying out at l̇(0)).
pub fn elastic_initial<T: Real>(sc: &Scenario, cfg: &Config<T>) -> InitialConditions {
    let x = initial_state(sc, cfg);
    InitialConditions {
        length_m: x[ix::LENGTH],
        rate_mps: sc.initial.length_rate_mps,
        alpha_rad: x[ix::ALPHA],
        alpha_rate_radps: x[ix::ALPHA_RATE],
        beta_rad: x[ix::BETA],
        beta_rate_radps: x[ix::BETA_RATE],
    }
}

/// The reel's rate at t = 0: the release rate l̇(0), or 0 when the reel is locked (a locked
/// drum turns neither at once nor through its lag).
fn release_rate_mps(sc: &Scenario) -> f64 {
    if sc.reel.locked {
        0.0
    } else {
        sc.initial.length_rate_mps
    }
}

/// The plant `[plant] model` selects, at its initial state.
pub fn flown_plant<T: Real>(sc: &Scenario, cfg: &Config<T>) -> Result<Box<dyn Plant>, SimError> {
    Ok(match sc.plant.model {
        PlantModel::Rigid => Box::new(RigidPlant {
            model: plant(sc),
            x: initial_state(sc, cfg),
            reel: Reel::new(&ReelDrive::from(&sc.reel), release_rate_mps(sc)),
            substeps: sc.simulation.substeps.max(1),
            locked: sc.reel.locked,
            period_s: sc.controller.period_s,
        }),
        PlantModel::Elastic => Box::new(ElasticPlant::new(
            ElasticParams::from(sc),
            elastic_initial(sc, cfg),
        )?),
    })
}

fn sample<T: Real>(obs: &Observation, t_s: f64, out: &Output<T>) -> Sample {
    let rate = out.rate_cmd_mps.to_f64();
    let accel = out.accel_cmd_mps2.to_f64();
    Sample {
        t_s,
        length_m: obs.length_m,
        length_rate_mps: rate,
        alpha_rad: obs.alpha_rad,
        alpha_rate_radps: obs.alpha_rate_radps,
        alpha_ref_rad: out.alpha_ref_rad.to_f64(),
        delta_rad: out.delta_rad.to_f64(),
        delta_rate_radps: out.delta_rate_radps.to_f64(),
        beta_rad: obs.beta_rad,
        tension_n: obs.tension_n,
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
