//! The flight controller's own rules, named by scenario key. The scenario does not repeat them:
//! it builds the f32 controller the run will fly (`Controller::<f32>::new`, which runs
//! `Config::validate`) and maps the parameter path of the `ConfigError` it returns back to the
//! scenario key it came from. Because the check runs in f32, a value that overflows (or
//! underflows) the flight build's scalar type is caught here, before any work, and not as an
//! `inf` later in the run.
//!
//! The controller stops at the first parameter it rejects, so at most one problem comes from
//! here; the scenario's own rules (in the section files) all report at once.

use tss_reel::controller::{ConfigError, Controller, Rule};
use tss_reel::equilibrium::ECCENTRICITY_LIMIT;

use super::dispersible::nominal_value;
use super::error::Problem;
use super::mission::Scenario;
use super::rules::{num, Validator};

/// Records the first rule the flight controller's configuration breaks, if any.
/// A key the scenario's own rules already reported is not reported again.
pub(super) fn check(sc: &Scenario, v: &mut Validator) {
    if let Err(e) = Controller::<f32>::new(sc.controller_config::<f32>()) {
        let p = problem(sc, &e);
        if !v.problems.iter().any(|q| q.field == p.field) {
            v.problems.push(p);
        }
    }
}

/// `e` as a problem of the scenario key it came from, with the scenario's value (as written,
/// in f64) and the rule in words.
fn problem(sc: &Scenario, e: &ConfigError) -> Problem {
    let field = scenario_key(sc, e);
    let x = nominal_value(sc, &field).unwrap_or(e.value);
    Problem {
        message: message(sc, e, &field, x),
        value: num(x),
        field,
        from_override: false,
    }
}

/// The scenario key a controller parameter path comes from.
fn scenario_key(sc: &Scenario, e: &ConfigError) -> String {
    let key = match e.param {
        "period_s" => "controller.period_s",
        "gains.k1_per_s" => "controller.k1_per_s",
        "gains.k2_per_s2" => "controller.k2_per_s2",
        "keep_capture_m" => "controller.keep_capture_m",
        "initial_rate_mps" => "initial.length_rate_mps",
        // The estimator is told the swing sensor's figures (`Scenario::estimator_config`).
        "rate_source.estimator.alpha_noise_rad" => "sensors.alpha.noise_std",
        "rate_source.estimator.alpha_quantum_rad" => "sensors.alpha.quantum",
        "rate_source.estimator.period_s" => "controller.period_s",
        "masses.tether_density_kg_per_m" => "tether.density_kg_per_m",
        "stage1.schedule.low_angle_rad" => "stage1.deploy_angle_rad",
        "stage1.schedule.high_length_m" => "stage1.keep_length_m",
        "stage2.schedule.high_angle_rad" => "stage2.retrieve_angle_rad",
        "stage2.schedule.low_length_m" => "stage2.keep_length_m",
        // A whole schedule: an inverted band is named by its band start; a value that is not
        // finite (in f32) by the first such field.
        "stage1.schedule" | "stage2.schedule" => {
            let stage = &e.param[..6];
            let fields: [&str; 4] = if stage == "stage1" {
                [
                    "stage1.band_start_m",
                    "stage1.deploy_angle_rad",
                    "stage1.keep_length_m",
                    "stage1.keep_slope_rad_per_m",
                ]
            } else {
                [
                    "stage2.keep_length_m",
                    "stage2.keep_slope_rad_per_m",
                    "stage2.band_start_m",
                    "stage2.retrieve_angle_rad",
                ]
            };
            let in_f32 = |k: &&str| nominal_value(sc, k).map(|x| x as f32);
            match e.rule {
                Rule::NotFinite => fields
                    .iter()
                    .find(|k| in_f32(k).is_some_and(|x| !x.is_finite()))
                    .copied()
                    .unwrap_or(fields[0]),
                _ if stage == "stage1" => "stage1.band_start_m",
                _ => "stage2.band_start_m",
            }
        }
        // No equilibrium with e inside its range: the orbit itself is too wide for the
        // controller's f32 (its rate underflows), so the semi-major axis is at fault.
        "orbit.eccentricity"
            if e.rule == Rule::NoEquilibrium
                && (0.0..ECCENTRICITY_LIMIT).contains(&sc.orbit.eccentricity) =>
        {
            "orbit.semi_major_axis_m"
        }
        // orbit.*, masses.*, stage1/2 rates, monitor.*, envelope.*: the same path.
        same => same,
    };
    key.to_string()
}

/// The rule `e` states, in the scenario's words (the other keys it compares with, by name and
/// value).
fn message(sc: &Scenario, e: &ConfigError, key: &str, x: f64) -> String {
    let env = &sc.envelope;
    if x.is_finite() && !e.value.is_finite() {
        return format!(
            "overflows the controller's f32 (largest finite value {:e})",
            f32::MAX
        );
    }
    match e.rule {
        Rule::NotFinite => "must be a finite number".to_string(),
        Rule::Negative | Rule::NoEquilibrium if key == "orbit.eccentricity" => format!(
            "must be in [0, {ECCENTRICITY_LIMIT}): beyond it no equilibrium exists over the \
             whole orbit (Eq. 13)"
        ),
        Rule::NotPositive if key.ends_with("_ticks") => "must be at least 1".to_string(),
        Rule::NotPositive if x > 0.0 => {
            format!(
                "must be above 0 (it is {} in the controller's f32)",
                e.value
            )
        }
        Rule::NotPositive => "must be above 0".to_string(),
        Rule::Negative => "must not be negative".to_string(),
        Rule::BandInverted => match key {
            "envelope.max_length_m" => format!(
                "must be above envelope.min_length_m = {}",
                num(env.min_length_m)
            ),
            "monitor.max_orbit_rate_radps" => format!(
                "must be above monitor.min_orbit_rate_radps = {}",
                num(sc.monitor.min_orbit_rate_radps)
            ),
            "protection.max_tension_n" => format!(
                "must be above protection.min_tension_n = {}",
                num(sc.protection.min_tension_n)
            ),
            "tension_loop.max_tension_n" => format!(
                "must be above tension_loop.min_tension_n = {}",
                num(sc.tension_loop.min_tension_n)
            ),
            "tension_loop.yield_full_rad" => format!(
                "must be above tension_loop.yield_from_rad = {}",
                num(sc.tension_loop.yield_from_rad)
            ),
            "stage1.band_start_m" => format!(
                "must be below stage1.keep_length_m = {}",
                num(sc.stage1.keep_length_m)
            ),
            "stage2.band_start_m" => format!(
                "must be above stage2.keep_length_m = {}",
                num(sc.stage2.keep_length_m)
            ),
            _ => "must be above its lower bound".to_string(),
        },
        Rule::OutsideEnvelope if key == "initial.length_rate_mps" => format!(
            "must be within ±envelope.max_rate_mps = {}",
            num(env.max_rate_mps)
        ),
        Rule::OutsideEnvelope => format!(
            "must be inside the envelope (envelope.min_length_m = {}, envelope.max_length_m = {})",
            num(env.min_length_m),
            num(env.max_length_m)
        ),
        Rule::WrongQuadrant if key.starts_with("stage1") => {
            "must be within (−π/2, 0) (the deployment side, Eq. 33)".to_string()
        }
        Rule::WrongQuadrant => "must be within (0, π/2) (the retrieval side, Eq. 33)".to_string(),
        Rule::TetherHeavierThanSatellite => format!(
            "makes the tether at envelope.max_length_m = {} m weigh {} kg, not below \
             masses.main_initial_kg = {}",
            num(env.max_length_m),
            num(sc.tether.density_kg_per_m * env.max_length_m),
            num(sc.masses.main_initial_kg)
        ),
        Rule::NoEquilibrium => "leaves no equilibrium over the whole orbit (Eq. 13)".to_string(),
        Rule::BelowMinimum if key == "tension_loop.overshoot" => {
            "must be at least 1 (an allowance for the elastic overshoot)".to_string()
        }
        Rule::OutOfRange if key == "tension_loop.damping_ratio" => {
            "must be at most 2 (a damping ratio of the tether's bounce)".to_string()
        }
        Rule::BelowMinimum
            if key == "protection.tension_filter_s" || key == "tension_loop.washout_s" =>
        {
            format!(
                "must be at least controller.period_s = {} s",
                num(sc.controller.period_s)
            )
        }
        Rule::TooLarge
            if key == "protection.max_tension_n" || key == "tension_loop.max_tension_n" =>
        {
            format!(
                "must be at most {} N (tss_reel::controller::MAX_PLAUSIBLE_TENSION_N)",
                num(tss_reel::controller::MAX_PLAUSIBLE_TENSION_N)
            )
        }
        Rule::BelowMinimum => format!(
            "must be at least {} s (tss_reel::config::MIN_PERIOD_S)",
            num(tss_reel::config::MIN_PERIOD_S)
        ),
        Rule::TooFastForPeriod => format!(
            "is too fast for controller.period_s = {} s: the fastest Eq. 28 closed-loop pole (k1, \
             k2) or blend rate c, times the period, must be at most {} \
             (tss_reel::config::MAX_POLE_PERIOD_PRODUCT)",
            num(sc.controller.period_s),
            num(tss_reel::config::MAX_POLE_PERIOD_PRODUCT)
        ),
        Rule::OutOfRange if key == "sensors.alpha.noise_std" || key == "sensors.alpha.quantum" => {
            "is beyond what the controller's estimator can be tuned for (at most 0.5 rad: \
             tss_reel::estimator::Config::validate); fit an α̇ sensor \
             (sensors.alpha_rate.enabled = true) to fly without the estimator"
                .to_string()
        }
        Rule::OutOfRange
            if key == "monitor.min_orbit_rate_radps" || key == "monitor.max_orbit_rate_radps" =>
        {
            format!(
                "must be within the orbit rates the controller's estimator admits, {} to {} \
                 rad/s (tss_reel::estimator::MIN_CIRCULAR_ORBIT_RATE_RADPS, \
                 MAX_ORBIT_RATE_RADPS)",
                num(tss_reel::estimator::MIN_CIRCULAR_ORBIT_RATE_RADPS),
                num(tss_reel::estimator::MAX_ORBIT_RATE_RADPS)
            )
        }
        Rule::TooLarge => "is so large that monitor.coast_ticks × monitor.good_samples_per_bad \
                           overflows a 32-bit count"
            .to_string(),
        // A rule the controller learns after this mapping was written.
        #[allow(unreachable_patterns)]
        other => format!("breaks the controller's rule {other:?}"),
    }
}
