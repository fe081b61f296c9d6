use std::collections::BTreeSet;

use super::load::join_key;
use super::*;

/// A complete scenario (the paper's, with every section written out) for the rule tests.
const BASE: &str = r#"
name = "base"
description = "test scenario"
[orbit]
semi_major_axis_m = 7_078_000.0
eccentricity = 0.0
initial_true_anomaly_rad = 0.0
[masses]
main_initial_kg = 10_000.0
sub_kg = 100.0
[tether]
density_kg_per_m = 0.0
[initial]
length_m = 1.0
length_rate_mps = 0.1
delta_rad = 0.17453292519943295
delta_rate_radps = 0.0
beta_rad = 0.0
beta_rate_radps = 0.0
[controller]
period_s = 1.0
k1_per_s = 0.0057
k2_per_s2 = 9.8696e-6
keep_capture_m = 1.0
[stage1]
decay_rate_per_s = 1.0e-3
deploy_angle_rad = -0.7853981633974483
band_start_m = 10_000.0
keep_length_m = 30_000.0
keep_slope_rad_per_m = 3.141592653589793e-5
[stage2]
start_time_s = 28_800.0
decay_rate_per_s = 5.0e-4
retrieve_angle_rad = 0.3141592653589793
slew_rate_radps = 6.2932e-4
band_start_m = 5_000.0
keep_length_m = 2_000.0
keep_slope_rad_per_m = 1.5707963267948966e-4
[simulation]
duration_s = 72_000.0
substeps = 1
output_interval_s = 10.0
[envelope]
max_rate_mps = 10.0
max_accel_mps2 = 0.05
min_length_m = 0.5
max_length_m = 40_000.0
"#;
const FILE: &str = "scenarios/x.toml";

fn load(sets: &[&str]) -> Result<Scenario, ScenarioError> {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Scenario::from_toml_str(BASE, FILE, &sets)
}

fn err(sets: &[&str]) -> String {
    match load(sets) {
        Ok(_) => panic!("{sets:?} was accepted"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn the_base_and_every_shipped_scenario_load() {
    let s = load(&[]).unwrap();
    assert_eq!(s.name, "base");
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            Scenario::load(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
            n += 1;
        }
    }
    assert!(n >= 1);
}

#[test]
fn schema_lists_every_key() {
    let s = schema();
    for key in [
        "name",
        "description",
        "orbit.semi_major_axis_m",
        "tether.density_kg_per_m",
        "stage2.start_time_s",
        "simulation.output_interval_s",
        "envelope.max_length_m",
    ] {
        assert!(s.leaves.contains_key(key), "{key}");
    }
    assert_eq!(
        s.leaves.get("simulation.substeps"),
        Some(&LeafKind::Integer {
            min: 0,
            max: u32::MAX.into()
        })
    );
    assert!(s.tables.contains("stage1"));
    // Every leaf of a serialized scenario is in the schema and vice versa (an optional key
    // without a default is given, so that it is serialized).
    let value =
        toml::Value::try_from(load(&["protection.rate_resolution_mps=0.0"]).unwrap()).unwrap();
    let mut found = BTreeSet::new();
    fn walk(v: &toml::Value, prefix: &str, out: &mut BTreeSet<String>) {
        if let toml::Value::Table(t) = v {
            for (k, v) in t {
                let full = join_key(prefix, k);
                if v.is_table() {
                    walk(v, &full, out);
                } else {
                    out.insert(full);
                }
            }
        }
    }
    walk(&value, "", &mut found);
    // The base has no faults, so no element of an array of tables is serialized.
    let expected: BTreeSet<String> = s
        .leaves
        .keys()
        .filter(|k| s.array_of(k).is_none())
        .cloned()
        .collect();
    assert_eq!(found, expected);
    for array in ["faults.dropout", "faults.corrupt", "faults.length_glitch"] {
        assert!(s.arrays.contains(array), "{array}");
    }
    assert_eq!(
        s.leaves.get("faults.dropout.until_s"),
        Some(&LeafKind::Float)
    );
    assert_eq!(
        s.leaves.get("faults.corrupt.sensor"),
        Some(&LeafKind::OneOf(&[
            "length",
            "alpha",
            "alpha_rate",
            "orbit_rate",
            "reel_rate",
            "tension"
        ]))
    );
}

#[test]
fn fault_sections_default_to_a_perfect_system() {
    let s = load(&[]).unwrap();
    assert_eq!(s.sensors, SensorsSection::default());
    assert!(s.faults.dropout.is_empty() && s.faults.corrupt.is_empty());
    assert_eq!(s.reel.lag_s, 0.0);
    assert_eq!(s.reel.max_rate_mps, f64::INFINITY);
    assert_eq!(s.monitor, MonitorSection::default());
    assert_eq!(s.monitor.coast_ticks, 30);
    assert_eq!(s.monitor.length_jump_m, 20.0);
}

#[test]
fn fault_injection_from_the_file_and_from_overrides() {
    let text = format!(
        "{BASE}\n[sensors]\nseed = 7\n[sensors.alpha]\nnoise_std = 1e-4\n\
         [[faults.dropout]]\nfrom_s = 600\nuntil_s = 660.0\n\
         [[faults.corrupt]]\nsensor = \"alpha_rate\"\nfrom_s = 10.0\nuntil_s = 11.0\nvalue = nan\n"
    );
    let sets = [
        "faults.length_glitch=[{ at_s = 100, size_m = 100.0 }]".to_string(),
        "reel.lag_s=2".to_string(),
        "sensors.length.stuck_from_s=50".to_string(),
    ];
    let s = Scenario::from_toml_str(&text, FILE, &sets).unwrap();
    assert_eq!(s.sensors.seed, 7);
    assert_eq!(s.sensors.alpha.noise_std, 1e-4);
    assert_eq!(
        s.faults.dropout,
        [WindowSection {
            from_s: 600.0,
            until_s: 660.0
        }]
    );
    assert_eq!(
        s.faults.corrupt[0].sensor,
        crate::sensors::SensedQuantity::AlphaRate
    );
    assert!(s.faults.corrupt[0].value.is_nan());
    assert_eq!(
        s.faults.length_glitch,
        [GlitchSection {
            at_s: 100.0,
            size_m: 100.0
        }]
    );
    assert_eq!(s.reel.lag_s, 2.0);
    assert_eq!(s.sensors.length.stuck_from_s, 50.0);
    assert_eq!(s.sensors.length.stuck_until_s, f64::INFINITY);
    // The resolved scenario (as `run` writes it) reads back the same.
    let again = toml::to_string_pretty(&s).unwrap();
    let back = Scenario::from_toml_str(&again, FILE, &[]).unwrap();
    assert_eq!(back.faults.dropout, s.faults.dropout);
    assert_eq!(back.reel, s.reel);
}

#[test]
fn fault_keys_are_checked_like_every_other_key() {
    let e = err(&["faults.dropout.from_s=3"]);
    assert!(
        e.contains("array of tables") && e.contains("from_s, until_s"),
        "{e}"
    );
    let e = err(&["faults.dropout=3"]);
    assert!(
        e.contains("faults.dropout = 3 must be an array of tables"),
        "{e}"
    );
    let e = err(&["faults.dropout=[{ from_s = 1, until = 2 }]"]);
    assert!(e.contains("unknown key `faults.dropout.until`"), "{e}");
    let e = err(&["faults.corrupt=[{ sensor = \"beta\", from_s = 1, until_s = 2, value = 0 }]"]);
    assert!(
        e.contains("must be one of length, alpha, alpha_rate, orbit_rate"),
        "{e}"
    );
    let e = err(&["sensors.alpha.noise=1"]);
    assert!(
        e.contains("unknown key `sensors.alpha.noise`") && e.contains("noise_std"),
        "{e}"
    );
    let text = format!("{BASE}\n[faults.dropout]\nfrom_s = 1\nuntil_s = 2\n");
    let e = Scenario::from_toml_str(&text, FILE, &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("faults.dropout = ") && e.contains("array of tables"),
        "{e}"
    );
}

#[test]
fn overrides_take_floats_integers_strings_and_apply_in_order() {
    let s = load(&[
        "tether.density_kg_per_m=1e-3",
        "stage2.start_time_s=30000",
        "simulation.duration_s=3600",
        "name=foo",
        "description=\"quoted text\"",
        "simulation.substeps=4",
        "controller.k1_per_s = 0.006",
        "controller.k1_per_s=0.007",
    ])
    .unwrap();
    assert_eq!(s.tether.density_kg_per_m, 1e-3);
    assert_eq!(s.stage2.start_time_s, 30_000.0);
    assert_eq!(s.simulation.duration_s, 3600.0);
    assert_eq!(s.name, "foo");
    assert_eq!(s.description, "quoted text");
    assert_eq!(s.simulation.substeps, 4);
    assert_eq!(s.controller.k1_per_s, 0.007);
    // A string field takes any text, even one that looks like a number.
    assert_eq!(load(&["name=42"]).unwrap().name, "42");
}

#[test]
fn an_integer_in_the_file_is_accepted_for_a_float_field() {
    let text = BASE.replace("duration_s = 72_000.0", "duration_s = 7200");
    let s = Scenario::from_toml_str(&text, FILE, &[]).unwrap();
    assert_eq!(s.simulation.duration_s, 7200.0);
}

#[test]
fn an_override_can_set_a_key_the_file_leaves_to_its_default() {
    let text = BASE.replace("eccentricity = 0.0\n", "");
    let sets = ["orbit.eccentricity=0.01".to_string()];
    let s = Scenario::from_toml_str(&text, FILE, &sets).unwrap();
    assert_eq!(s.orbit.eccentricity, 0.01);
}

#[test]
fn an_override_into_a_defaulted_section_keeps_its_other_defaults() {
    let start = BASE.find("[envelope]").unwrap();
    let text = &BASE[..start];
    let sets = ["envelope.max_rate_mps=100".to_string()];
    let s = Scenario::from_toml_str(text, FILE, &sets).unwrap();
    assert_eq!(s.envelope.max_rate_mps, 100.0);
    assert_eq!(
        s.envelope.max_accel_mps2,
        EnvelopeSection::default().max_accel_mps2
    );
}

#[test]
fn malformed_overrides_are_errors_naming_the_argument() {
    let e = err(&["stage1.band_start_m"]);
    assert!(
        e.starts_with(FILE) && e.contains("stage1.band_start_m") && e.contains("key=value"),
        "{e}"
    );
    let e = err(&["=3"]);
    assert!(e.contains("dotted path"), "{e}");
    let e = err(&["stage1..band_start_m=3"]);
    assert!(e.contains("dotted path"), "{e}");
}

#[test]
fn unknown_override_keys_are_errors_naming_the_key() {
    let e = err(&["stage1.band_start=3"]);
    assert!(
        e.starts_with(&format!(
            "{FILE}: --set stage1.band_start=3: unknown key `stage1.band_start`"
        )),
        "{e}"
    );
    assert!(
        e.contains("band_start_m"),
        "the hint lists the valid keys: {e}"
    );
    let e = err(&["nosuch.key=1"]);
    assert!(
        e.contains("unknown key `nosuch.key`") && e.contains("top-level keys"),
        "{e}"
    );
    let e = err(&["stage1=1"]);
    assert!(
        e.contains("unknown key `stage1`") && e.contains("is a section"),
        "{e}"
    );
}

#[test]
fn override_values_of_the_wrong_type_are_errors_naming_key_and_value() {
    let e = err(&["simulation.substeps=1.5"]);
    assert!(
        e.contains(&format!(
            "{FILE}: --set simulation.substeps=1.5: simulation.substeps = 1.5 must be an integer"
        )),
        "{e}"
    );
    let e = err(&["simulation.substeps=-1"]);
    assert!(
        e.contains("simulation.substeps = -1 must be an integer in [0, 4294967295]"),
        "{e}"
    );
    let e = err(&["simulation.duration_s=abc"]);
    assert!(
        e.contains("simulation.duration_s = \"abc\" must be a number"),
        "{e}"
    );
    let e = err(&["simulation.duration_s=true"]);
    assert!(
        e.contains("simulation.duration_s = true must be a number"),
        "{e}"
    );
}

#[test]
fn file_errors_name_the_file_and_key() {
    let unknown = BASE.replace("[stage1]\n", "[stage1]\nbnad_start_m = 1.0\n");
    let e = Scenario::from_toml_str(&unknown, FILE, &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!("{FILE}: unknown key `stage1.bnad_start_m`")),
        "{e}"
    );
    let wrong = BASE.replace("substeps = 1", "substeps = \"one\"");
    let e = Scenario::from_toml_str(&wrong, FILE, &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!(
            "{FILE}: simulation.substeps = \"one\" must be an integer"
        )),
        "{e}"
    );
    let missing = BASE.replace("k1_per_s = 0.0057\n", "");
    let e = Scenario::from_toml_str(&missing, FILE, &[])
        .unwrap_err()
        .to_string();
    assert_eq!(e, format!("{FILE}: missing key `controller.k1_per_s`"));
    let no_section = BASE.replace("[masses]\nmain_initial_kg = 10_000.0\nsub_kg = 100.0\n", "");
    let e = Scenario::from_toml_str(&no_section, FILE, &[])
        .unwrap_err()
        .to_string();
    assert_eq!(e, format!("{FILE}: missing key `masses`"));
    let e = Scenario::from_toml_str("name = ", FILE, &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!("{FILE}: not valid TOML")) && e.contains("line 1"),
        "{e}"
    );
    let e = Scenario::load("/nonexistent/dir/x.toml", &[]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "/nonexistent/dir/x.toml: cannot read the scenario file"
    );
}

/// Every validation rule: the override that breaks it, the field and value named, and a
/// piece of the message.
#[test]
fn every_rule_names_file_field_and_value() {
    let cases: &[(&[&str], &str, &str, &str)] = &[
        (&["name=a/b"], "name", "\"a/b\"", "file name"),
        (&["name=.."], "name", "\"..\"", "file name"),
        (&["orbit.semi_major_axis_m=-1"], "orbit.semi_major_axis_m", "-1", "must be above 0"),
        (&["orbit.semi_major_axis_m=6000000"], "orbit.semi_major_axis_m", "6000000", "below the simulator's 150 km"),
        (&["orbit.eccentricity=0.2"], "orbit.semi_major_axis_m", "7078000", "below the simulator's 150 km"),
        (&["orbit.eccentricity=1"], "orbit.eccentricity", "1", "must be in [0, 0.75): beyond it no equilibrium"),
        (&["orbit.eccentricity=-0.1"], "orbit.eccentricity", "-0.1", "must be in [0, 0.75)"),
        (&["orbit.initial_true_anomaly_rad=nan"], "orbit.initial_true_anomaly_rad", "NaN", "finite"),
        (&["masses.main_initial_kg=0"], "masses.main_initial_kg", "0", "must be above 0"),
        (&["masses.sub_kg=-5"], "masses.sub_kg", "-5", "must be above 0"),
        (&["masses.sub_kg=inf"], "masses.sub_kg", "inf", "finite"),
        (&["initial.length_m=0"], "initial.length_m", "0", "must be above 0"),
        (&["initial.length_m=0.25"], "initial.length_m", "0.25", "within [envelope.min_length_m, envelope.max_length_m] = [0.5, 40000]"),
        (&["initial.length_rate_mps=inf"], "initial.length_rate_mps", "inf", "finite"),
        (&["initial.length_rate_mps=-11"], "initial.length_rate_mps", "-11", "±envelope.max_rate_mps = 10"),
        (&["initial.delta_rad=nan"], "initial.delta_rad", "NaN", "finite"),
        (&["initial.delta_rate_radps=-inf"], "initial.delta_rate_radps", "-inf", "finite"),
        (&["initial.beta_rad=2"], "initial.beta_rad", "2", "(−π/2, π/2)"),
        (&["initial.beta_rate_radps=nan"], "initial.beta_rate_radps", "NaN", "finite"),
        (&["controller.period_s=0"], "controller.period_s", "0", "must be above 0"),
        (&["controller.k1_per_s=0"], "controller.k1_per_s", "0", "must be above 0"),
        (&["controller.k2_per_s2=-1e-6"], "controller.k2_per_s2", "-0.000001", "must be above 0"),
        (&["controller.keep_capture_m=0"], "controller.keep_capture_m", "0", "must be above 0"),
        (&["envelope.max_rate_mps=0"], "envelope.max_rate_mps", "0", "must be above 0"),
        (&["envelope.max_accel_mps2=-1"], "envelope.max_accel_mps2", "-1", "must be above 0"),
        (&["envelope.min_length_m=0"], "envelope.min_length_m", "0", "must be above 0"),
        (&["envelope.max_length_m=0.4"], "envelope.max_length_m", "0.4", "must be above envelope.min_length_m = 0.5"),
        (&["stage1.decay_rate_per_s=-1e-3"], "stage1.decay_rate_per_s", "-0.001", "must not be negative"),
        (&["stage1.deploy_angle_rad=0.1"], "stage1.deploy_angle_rad", "0.1", "(−π/2, 0)"),
        (&["stage1.deploy_angle_rad=-1.6"], "stage1.deploy_angle_rad", "-1.6", "(−π/2, 0)"),
        (&["stage1.band_start_m=40000"], "stage1.band_start_m", "40000", "must be below stage1.keep_length_m = 30000"),
        (&["stage1.band_start_m=0"], "stage1.band_start_m", "0", "must be above 0"),
        (&["stage1.keep_length_m=45000"], "stage1.keep_length_m", "45000", "inside the envelope"),
        (&["stage1.keep_slope_rad_per_m=-1e-5"], "stage1.keep_slope_rad_per_m", "-0.00001", "must not be negative"),
        (&["stage2.start_time_s=-1"], "stage2.start_time_s", "-1", "must not be negative"),
        (&["stage2.start_time_s=0.5"], "stage2.start_time_s", "0.5", "whole multiple of controller.period_s = 1"),
        (&["stage2.decay_rate_per_s=-1"], "stage2.decay_rate_per_s", "-1", "must not be negative"),
        (&["stage2.retrieve_angle_rad=-0.3"], "stage2.retrieve_angle_rad", "-0.3", "(0, π/2)"),
        (&["stage2.slew_rate_radps=0"], "stage2.slew_rate_radps", "0", "must be above 0"),
        (&["stage2.band_start_m=1000"], "stage2.band_start_m", "1000", "must be above stage2.keep_length_m = 2000"),
        (&["stage2.keep_length_m=31000", "stage2.band_start_m=32000"], "stage2.keep_length_m", "31000", "must be below stage1.keep_length_m = 30000"),
        (&["stage2.keep_length_m=0.5"], "stage2.keep_length_m", "0.5", "inside the envelope"),
        (&["stage2.keep_slope_rad_per_m=-1"], "stage2.keep_slope_rad_per_m", "-1", "must not be negative"),
        (&["tether.density_kg_per_m=-1e-3"], "tether.density_kg_per_m", "-0.001", "must not be negative"),
        (&["tether.density_kg_per_m=0.25"], "tether.density_kg_per_m", "0.25", "envelope.max_length_m = 40000 m weigh 10000 kg, not below masses.main_initial_kg = 10000"),
        (&["simulation.duration_s=0"], "simulation.duration_s", "0", "must be above 0"),
        (&["simulation.duration_s=600.5"], "simulation.duration_s", "600.5", "whole multiple of controller.period_s"),
        (&["simulation.duration_s=1e10"], "simulation.duration_s", "10000000000", "more than the simulator's"),
        (&["simulation.substeps=0"], "simulation.substeps", "0", "must be at least 1"),
        (&["simulation.output_interval_s=0"], "simulation.output_interval_s", "0", "must be above 0"),
        (&["simulation.output_interval_s=2.5"], "simulation.output_interval_s", "2.5", "positive whole multiple of controller.period_s = 1"),
        (&["sensors.length.noise_std=-1"], "sensors.length.noise_std", "-1", "must not be negative"),
        (&["sensors.alpha.bias=nan"], "sensors.alpha.bias", "NaN", "finite"),
        (&["sensors.alpha_rate.quantum=-1e-6"], "sensors.alpha_rate.quantum", "-0.000001", "must not be negative"),
        (&["sensors.alpha.stuck_from_s=-5"], "sensors.alpha.stuck_from_s", "-5", "must not be negative"),
        (&["sensors.alpha.stuck_from_s=50", "sensors.alpha.stuck_until_s=40"], "sensors.alpha.stuck_until_s", "40", "must be after sensors.alpha.stuck_from_s = 50"),
        (&["sensors.alpha.dropout_prob=1.5"], "sensors.alpha.dropout_prob", "1.5", "must be a probability, in [0, 1]"),
        (&["sensors.alpha.dropout_prob=nan"], "sensors.alpha.dropout_prob", "NaN", "must be a probability"),
        (&["sensors.alpha.noise_std=0.6"], "sensors.alpha.noise_std", "0.6", "beyond what the controller's estimator can be tuned for"),
        (&["sensors.length.counts_per_rev=4096", "sensors.length.drum_radius_m=0"], "sensors.length.drum_radius_m", "0", "must be above 0"),
        (&["sensors.length.drum_radius_m=-1"], "sensors.length.drum_radius_m", "-1", "must not be negative"),
        (&["sensors.load_cell.noise_std_n=-1"], "sensors.load_cell.noise_std_n", "-1", "must not be negative"),
        (&["sensors.load_cell.bias_n=inf"], "sensors.load_cell.bias_n", "inf", "finite"),
        (&["sensors.load_cell.full_scale_n=0"], "sensors.load_cell.full_scale_n", "0", "must be above 0 (inf = no limit)"),
        (&["faults.alpha_dropout=[{ from_s = 100, until_s = 50 }]"], "faults.alpha_dropout[0].until_s", "50", "must be after faults.alpha_dropout[0].from_s = 100"),
        (&["faults.dropout=[{ from_s = 100, until_s = 100 }]"], "faults.dropout[0].until_s", "100", "must be after faults.dropout[0].from_s = 100"),
        (&["faults.dropout=[{ from_s = inf, until_s = inf }]"], "faults.dropout[0].from_s", "inf", "finite"),
        (&["faults.corrupt=[{ sensor = \"alpha\", from_s = 5, until_s = nan, value = 0 }]"], "faults.corrupt[0].until_s", "NaN", "must be a number"),
        (&["faults.length_glitch=[{ at_s = -1, size_m = 100 }]"], "faults.length_glitch[0].at_s", "-1", "must not be negative"),
        (&["faults.length_glitch=[{ at_s = 1, size_m = inf }]"], "faults.length_glitch[0].size_m", "inf", "finite"),
        (&["reel.lag_s=-1"], "reel.lag_s", "-1", "must not be negative"),
        (&["reel.max_rate_mps=0"], "reel.max_rate_mps", "0", "must be above 0 (inf = no limit)"),
        (&["reel.max_accel_mps2=nan"], "reel.max_accel_mps2", "NaN", "must be above 0"),
        (&["monitor.coast_ticks=0"], "monitor.coast_ticks", "0", "must be at least 1"),
        (&["monitor.length_jump_m=0"], "monitor.length_jump_m", "0", "must be above 0"),
        (&["monitor.max_orbit_rate_radps=-1"], "monitor.max_orbit_rate_radps", "-1", "must be above monitor.min_orbit_rate_radps"),
        (&["monitor.max_orbit_rate_radps=1e-6"], "monitor.max_orbit_rate_radps", "0.000001", "must be above monitor.min_orbit_rate_radps = 0.00001"),
        (&["sensors.alpha_rate.enabled=false", "monitor.max_orbit_rate_radps=0.02"], "monitor.max_orbit_rate_radps", "0.02", "must be within the orbit rates the controller's estimator admits"),
        (&["protection.enabled=true", "protection.min_tension_n=-1"], "protection.min_tension_n", "-1", "must not be negative"),
        (&["protection.enabled=true", "protection.max_tension_n=0.001"], "protection.max_tension_n", "0.001", "must be above protection.min_tension_n = 0.002"),
        (&["protection.enabled=true", "protection.max_tension_n=1e6"], "protection.max_tension_n", "1000000", "must be at most 100000 N"),
        (&["protection.enabled=true", "protection.tension_filter_s=0.5"], "protection.tension_filter_s", "0.5", "must be at least controller.period_s = 1 s"),
        (&["protection.enabled=true", "protection.tension_filter_s=nan"], "protection.tension_filter_s", "NaN", "finite"),
        (&["protection.enabled=true", "protection.drive_lag_s=-2"], "protection.drive_lag_s", "-2", "must not be negative"),
    ];
    for (sets, field, value, message) in cases {
        let e = err(sets);
        let head = format!("{FILE}: {field} = {value} ");
        let line = e
            .lines()
            .find(|l| l.starts_with(&head))
            .unwrap_or_else(|| panic!("{sets:?}: no line starting {head:?} in:\n{e}"));
        assert!(
            line.contains(message),
            "{sets:?}: {line:?} lacks {message:?}"
        );
        let base = field.split('[').next().unwrap_or(field);
        if sets.iter().any(|s| s.starts_with(&format!("{base}="))) {
            assert!(line.ends_with("(set by --set)"), "{line}");
        }
    }
}

/// The scenario's own rules all report at once; the controller's configuration adds the
/// first of its rules that fails (it stops there), last.
#[test]
fn all_problems_are_reported_at_once() {
    let e = load(&[
        "masses.sub_kg=0",
        "controller.k1_per_s=0",
        "initial.delta_rad=nan",
        "simulation.substeps=0",
    ])
    .unwrap_err();
    match e {
        ScenarioError::Invalid { problems, .. } => {
            let fields: Vec<&str> = problems.iter().map(|p| p.field.as_str()).collect();
            assert_eq!(
                fields,
                ["initial.delta_rad", "simulation.substeps", "masses.sub_kg"]
            );
        }
        other => panic!("{other}"),
    }
}

#[test]
fn the_paper_scenario_is_valid_and_its_rules_hold_in_the_example_from_the_brief() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/paper.toml");
    let e = Scenario::load(path, &["stage1.band_start_m=40000".to_string()])
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        format!(
            "{path}: stage1.band_start_m = 40000 must be below stage1.keep_length_m = 30000 \
             (set by --set)"
        )
    );
}

/// The controller's rules are not repeated here: the scenario builds the f32 controller and
/// names what it rejects by scenario key. e = 0.8 passed the scenario's old `[0, 1)` and then
/// failed the run (exit 1, "controller configuration rejected").
#[test]
fn the_controllers_own_rules_are_named_by_scenario_key() {
    for (sets, line) in [
        (
            &["orbit.eccentricity=0.8"][..],
            "orbit.eccentricity = 0.8 must be in [0, 0.75): beyond it no equilibrium exists",
        ),
        (
            &["controller.k2_per_s2=0"][..],
            "controller.k2_per_s2 = 0 must be above 0",
        ),
        (
            &["envelope.max_length_m=20000"][..],
            "stage1.keep_length_m = 30000 must be inside the envelope",
        ),
        (
            &["monitor.stuck_ticks=0"][..],
            "monitor.stuck_ticks = 0 must be at least 1",
        ),
        (
            &["initial.length_rate_mps=nan"][..],
            "initial.length_rate_mps = NaN must be a finite number",
        ),
        (
            &["stage2.keep_slope_rad_per_m=inf"][..],
            "stage2.keep_slope_rad_per_m = inf must be a finite number",
        ),
    ] {
        let e = err(sets);
        assert!(e.contains(&format!("{FILE}: {line}")), "{sets:?}: {e}");
    }
}

/// What the f32 controller will see is validated: a value beyond f32's range (finite in the
/// file) is an error naming the field and the value, not an `inf` later in the run.
#[test]
fn values_that_overflow_the_controllers_f32_are_rejected() {
    for (set, field, value) in [
        (
            "masses.main_initial_kg=1e308",
            "masses.main_initial_kg",
            "1e308",
        ),
        ("controller.k1_per_s=1e39", "controller.k1_per_s", "1e39"),
        (
            "envelope.max_rate_mps=-1e300",
            "envelope.max_rate_mps",
            "-1e300",
        ),
        ("stage1.band_start_m=4e38", "stage1.band_start_m", "4e38"),
    ] {
        let e = err(&[set]);
        let head = format!("{FILE}: {field} = {value} overflows the controller's f32");
        assert!(e.starts_with(&head), "{set}: {e}");
    }
    let e = err(&["controller.period_s=1e-50"]);
    assert!(
        e.contains("controller.period_s = 1e-50 must be above 0 (it is 0 in the controller's f32)"),
        "{e}"
    );
}

/// Every size has a bound, checked at load (before any work), naming the field and value.
/// Without it, `simulation.duration_s = 4294967295` passes and aborts the run on a 48 GB
/// allocation.
#[test]
fn every_size_and_count_has_a_bound() {
    let window = "{ from_s = 1, until_s = 2 }";
    let many = |n: usize| vec![window; n].join(", ");
    let dropouts = format!("faults.dropout=[{}]", many(MAX_FAULT_ENTRIES + 1));
    let cases: Vec<(Vec<String>, &str, &str)> = vec![
        (
            vec!["simulation.duration_s=4294967295".into()],
            "simulation.duration_s = 4294967295 is 4294967295 control periods, more than the simulator's 10000000",
            "",
        ),
        (
            vec!["simulation.substeps=1001".into()],
            "simulation.substeps = 1001 must be at most 1000",
            "",
        ),
        (
            vec![
                "simulation.duration_s=200000".into(),
                "simulation.substeps=1000".into(),
            ],
            "simulation.substeps = 1000 makes 200000000 plant steps",
            "more than the simulator's 100000000",
        ),
        (
            vec![
                "simulation.duration_s=2000000".into(),
                "simulation.output_interval_s=1".into(),
            ],
            "simulation.output_interval_s = 1 makes 2000001 rows of history",
            "more than the simulator's 1000000",
        ),
        (
            vec![dropouts],
            "faults.dropout = [1001 entries] has more entries than the simulator's 1000",
            "",
        ),
        (
            vec!["monitor.coast_ticks=10000001".into()],
            "monitor.coast_ticks = 10000001 must be at most 10000000",
            "",
        ),
    ];
    for (sets, head, rest) in cases {
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let e = err(&sets);
        let line = e
            .lines()
            .find(|l| l.starts_with(&format!("{FILE}: {head}")))
            .unwrap_or_else(|| panic!("no {head:?} in {e}"));
        assert!(line.contains(rest), "{line}");
        // A list beyond its bound is one problem, not one per entry.
        assert!(e.lines().count() <= 2, "{e}");
    }
    // At the bounds, accepted.
    load(&["simulation.substeps=1000"]).unwrap();
    load(&[&format!("faults.dropout=[{}]", many(MAX_FAULT_ENTRIES))]).unwrap_or_else(|e| {
        // Identical windows are valid; only the count is under test.
        panic!("{e}")
    });
    load(&[
        "simulation.duration_s=999990",
        "simulation.output_interval_s=1",
    ])
    .unwrap();
}

#[test]
fn a_campaign_disperses_each_field_at_most_once() {
    let n = dispersible_fields().len() + 1;
    let entry = "[[montecarlo.dispersion]]\nfield = \"masses.sub_kg\"\ndistribution = \"normal\"\nstd = 1.0\n";
    let text = format!("{BASE}{}", entry.repeat(n));
    let e = Scenario::from_toml_str(&text, FILE, &[])
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        format!(
            "{FILE}: montecarlo.dispersion = [{n} entries] has more entries than the scenario's {} number fields (each is dispersed at most once)",
            n - 1
        )
    );
}

/// The models' parameter types mean what the sections' defaults mean: a perfect sensor, an
/// ideal reel, nothing injected; a stuck window from its start to its end.
#[test]
fn conversions_keep_the_meaning_of_the_defaults() {
    use crate::faults::{InjectionPlan, SensorErrors, Window};
    use crate::reel::ReelDrive;
    // The default has no α̇ sensor (the controller estimates α̇): not the paper's idealisation.
    assert!(!InjectionPlan::from(&load(&[]).unwrap()).is_transparent());
    let s = load(&["sensors.alpha_rate.enabled=true"]).unwrap();
    assert!(InjectionPlan::from(&s).is_transparent());
    assert!(ReelDrive::from(&s.reel).is_ideal());
    assert_eq!(
        SensorErrors::from(&super::RateSensorSection::default()),
        SensorErrors::default()
    );
    let s = load(&[
        "sensors.alpha.stuck_from_s=50",
        "sensors.length.bias=0.5",
        "reel.lag_s=2",
    ])
    .unwrap();
    let plan = InjectionPlan::from(&s);
    assert_eq!(
        plan.alpha.errors.stuck,
        Some(Window {
            from_s: 50.0,
            until_s: f64::INFINITY
        })
    );
    assert_eq!(plan.length.errors.bias, 0.5);
    assert!(!plan.is_transparent());
    assert!(!ReelDrive::from(&s.reel).is_ideal());
    let cfg = s.controller_config::<f32>();
    assert_eq!(cfg.stage2.start_tick, Some(28_800));
    assert_eq!(cfg.envelope.max_rate_mps, 10.0);
}

/// A campaign refuses dispersions that change nothing (the lag drive's keys under the flight
/// drive, the protection's with the protection off, the α̇ sensor's with no α̇ sensor) and the
/// output interval, whose drawn values are never whole periods (every run would end
/// "did_not_complete"). Each is refused, with the reason.
#[test]
fn dispersions_that_change_nothing_are_refused() {
    let entry = |field: &str| {
        format!(
            "[[montecarlo.dispersion]]\nfield = \"{field}\"\ndistribution = \"normal\"\nstd = 0.1\n"
        )
    };
    let elastic = "[plant]\nmodel = \"elastic\"\n[reel]\nmodel = \"flight_drive\"\n";
    let cases: &[(&str, &str, &str)] = &[
        (elastic, "reel.lag_s", "flies the drum"),
        (elastic, "reel.max_rate_mps", "flies the drum"),
        ("", "protection.max_tension_n", "protection.enabled = false"),
        ("", "sensors.alpha_rate.noise_std", "no α̇ sensor"),
        (
            "",
            "simulation.output_interval_s",
            "whole number of control periods",
        ),
        ("", "stage2.start_time_s", "whole number of control periods"),
    ];
    for (sections, field, why) in cases {
        let text = format!("{BASE}{sections}{}", entry(field));
        let e = Scenario::from_toml_str(&text, FILE, &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("field = \"{field}\" has no effect")) && e.contains(why),
            "{field}: {e}"
        );
    }
    // Switched on, the same dispersions are flown.
    for (sections, field) in [
        ("[protection]\nenabled = true\n", "protection.max_tension_n"),
        (
            "[sensors.alpha_rate]\nenabled = true\n",
            "sensors.alpha_rate.noise_std",
        ),
    ] {
        let text = format!("{BASE}{sections}{}", entry(field));
        Scenario::from_toml_str(&text, FILE, &[]).unwrap_or_else(|e| panic!("{field}: {e}"));
    }
}
