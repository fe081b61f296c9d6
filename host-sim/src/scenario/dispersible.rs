//! What a Monte Carlo campaign may disperse: the scenario's number fields, their nominal values,
//! and why the models a scenario flies would ignore one; `[montecarlo]` checked against them.

use super::mission::Scenario;
use super::plant::PlantModel;
use super::reel::ReelModelName;
use super::rules::Validator;
use super::schema::{schema, LeafKind};

/// The number fields a dispersion may name: every float key of the scenario outside
/// `[montecarlo]` and outside arrays of tables (`[[faults.dropout]]`, …).
pub fn dispersible_fields() -> Vec<&'static str> {
    let s = schema();
    s.leaves
        .iter()
        .filter(|(k, kind)| {
            **kind == LeafKind::Float && !k.starts_with("montecarlo.") && s.array_of(k).is_none()
        })
        .map(|(k, _)| k.as_str())
        .collect()
}

/// The nominal value of the number field `field` of `sc` (`None`: not a dispersible field).
pub fn nominal_value(sc: &Scenario, field: &str) -> Option<f64> {
    let table = toml::Table::try_from(sc).ok()?;
    nominal_in(&table, field)
}

/// The number at dotted `field` of a scenario's table.
pub(crate) fn nominal_in(table: &toml::Table, field: &str) -> Option<f64> {
    let mut parts = field.split('.');
    let mut value = table.get(parts.next()?)?;
    for part in parts {
        value = value.as_table()?.get(part)?;
    }
    match value {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

/// `[montecarlo]` against the scenario it disperses: at most one dispersion per number field,
/// each of a field that exists, that the models flown use and that is dispersed once, with a
/// complete distribution around its nominal value; sane criteria.
pub(super) fn check(sc: &Scenario, v: &mut Validator) {
    let mc = &sc.montecarlo;
    let fields = dispersible_fields();
    let count_ok = v.check(
        mc.dispersion.len() <= fields.len(),
        "montecarlo.dispersion",
        format!("[{} entries]", mc.dispersion.len()),
        &format!(
            "has more entries than the scenario's {} number fields (each is dispersed at \
             most once)",
            fields.len()
        ),
    );
    if count_ok && !mc.dispersion.is_empty() {
        let table = toml::Table::try_from(sc).ok();
        let mut seen: Vec<&str> = Vec::new();
        for (i, d) in mc.dispersion.iter().enumerate() {
            let at = format!("montecarlo.dispersion[{i}]");
            let field = format!("{at}.field");
            if !fields.contains(&d.field.as_str()) {
                v.check(
                    false,
                    &field,
                    format!("{:?}", d.field),
                    &format!(
                        "is not a number field of the scenario (the keys --set takes; {})",
                        fields_like(&fields, &d.field)
                    ),
                );
                continue;
            }
            v.check(
                !seen.contains(&d.field.as_str()),
                &field,
                format!("{:?}", d.field),
                "is dispersed twice",
            );
            seen.push(&d.field);
            if let Some(why) = ignored_by_models(sc, &d.field) {
                v.check(
                    false,
                    &field,
                    format!("{:?}", d.field),
                    &format!("has no effect on this scenario: {why}"),
                );
                continue;
            }
            let nominal = table.as_ref().and_then(|t| nominal_in(t, &d.field));
            d.check(&at, nominal, v);
        }
    }
    mc.criteria.check(v);
}

/// Why the models `sc` selects ignore the number field `field` (`None`: one of them uses it).
/// A dispersion of such a field would change nothing, so a campaign that asks for one is
/// refused rather than reporting a spread that was never flown.
pub fn ignored_by_models(sc: &Scenario, field: &str) -> Option<String> {
    const LAG_DRIVE: [&str; 3] = ["reel.lag_s", "reel.max_rate_mps", "reel.max_accel_mps2"];
    const MOTOR: [&str; 8] = [
        "reel.drum_radius_m",
        "reel.drum_inertia_kgm2",
        "reel.viscous_nms",
        "reel.coulomb_nm",
        "reel.static_nm",
        "reel.motor_max_torque_nm",
        "reel.brake_nm",
        "reel.speed_bandwidth_radps",
    ];
    // Read by the elastic plant only (the rigid one uses tether.density_kg_per_m alone).
    const ELASTIC_ONLY: [&str; 7] = [
        "plant.courant",
        "plant.shape_interval_s",
        "tether.axial_stiffness_n",
        "tether.damping_ns",
        "tether.segment_length_m",
        "tether.min_stiffness_length_m",
        "environment.inclination_rad",
    ];
    const DRAG: [&str; 4] = [
        "environment.main_drag_area_m2",
        "environment.sub_drag_area_m2",
        "tether.diameter_m",
        "tether.drag_coefficient",
    ];
    const WHOLE_PERIODS: [&str; 4] = [
        "simulation.duration_s",
        "simulation.output_interval_s",
        "plant.shape_interval_s",
        "stage2.start_time_s",
    ];
    let rigid = sc.plant.model == PlantModel::Rigid;
    if rigid && (ELASTIC_ONLY.contains(&field) || DRAG.contains(&field)) {
        return Some("the rigid plant (plant.model = \"rigid\") does not use it".to_string());
    }
    if sc.reel.model != ReelModelName::Drive && LAG_DRIVE.contains(&field) {
        return Some(format!(
            "reel.model = {:?} flies the drum and its speed loop, not the lag drive",
            reel_model_name(sc.reel.model)
        ));
    }
    if sc.reel.model == ReelModelName::FlightDrive && field == "reel.speed_bandwidth_radps" {
        return Some(
            "reel.model = \"flight_drive\" flies the flight speed loop's own gains".to_string(),
        );
    }
    // Whole numbers of control periods: a continuous draw is never one, so every run would
    // be refused (and the output interval changes what is written, not what is flown).
    if WHOLE_PERIODS.contains(&field) {
        return Some(
            "it must be a whole number of control periods, which a drawn value is not".to_string(),
        );
    }
    if field.starts_with("protection.") && !sc.protection.enabled {
        return Some("protection.enabled = false".to_string());
    }
    if field.starts_with("sensors.alpha_rate.") && !sc.sensors.alpha_rate.enabled {
        return Some("sensors.alpha_rate.enabled = false (no α̇ sensor is fitted)".to_string());
    }
    if field.starts_with("sensors.load_cell.") && !sc.sensors.load_cell.enabled {
        return Some("sensors.load_cell.enabled = false (no load cell is fitted)".to_string());
    }
    if sc.reel.model == ReelModelName::Drive && MOTOR.contains(&field) {
        return Some(
            "reel.model = \"drive\" has no drum (the motor keys need \"motor\")".to_string(),
        );
    }
    if DRAG.contains(&field) && !sc.environment.drag {
        return Some("environment.drag = false".to_string());
    }
    // Without J2 or drag gravity is central: the plane's tilt changes nothing.
    if field == "environment.inclination_rad" && !sc.environment.j2 && !sc.environment.drag {
        return Some("environment.j2 and environment.drag are both false".to_string());
    }
    None
}

/// The name of a reel model as scenario files write it.
fn reel_model_name(m: ReelModelName) -> &'static str {
    match m {
        ReelModelName::Drive => "drive",
        ReelModelName::Motor => "motor",
        ReelModelName::FlightDrive => "flight_drive",
    }
}

/// The dispersible fields in the section of `field`, or a few examples.
fn fields_like(fields: &[&str], field: &str) -> String {
    let section = |f: &str| f.rsplit_once('.').map_or("", |(p, _)| p).to_string();
    let near: Vec<&str> = fields
        .iter()
        .copied()
        .filter(|f| section(f) == section(field))
        .collect();
    if near.is_empty() {
        "e.g. initial.delta_rad, masses.sub_kg, tether.density_kg_per_m, \
         sensors.alpha.noise_std, reel.lag_s"
            .to_string()
    } else {
        near.join(", ")
    }
}
