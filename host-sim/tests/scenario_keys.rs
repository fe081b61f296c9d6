//! `tss-sim scenario keys`: every key the schema has is listed, every listed key is taken by
//! `--set`, every rule it states is enforced, and the rules a reader relies on are found.

use std::path::{Path, PathBuf};
use std::process::Command;

use tss_sim::scenario::keys::{keys, KeyDefault, KeyInfo, DIMENSIONLESS_NAMES};
use tss_sim::scenario::{schema, LeafKind, Scenario, ScenarioError};

fn paper() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml")
}

/// Loads the paper's scenario from its file with one `--set`.
fn load_with(set: &str) -> Result<Scenario, ScenarioError> {
    Scenario::load(paper(), &[set.to_string()])
}

#[test]
fn every_schema_key_is_listed_once() {
    let listed = keys();
    let mut names: Vec<&str> = listed.iter().map(|k| k.schema_key.as_str()).collect();
    names.dedup();
    let expected: Vec<&str> = schema().leaves.keys().map(String::as_str).collect();
    assert_eq!(names, expected);
    for k in &listed {
        let in_array = schema().array_of(&k.schema_key).is_some();
        assert_eq!(k.key.contains("[]."), in_array, "{}", k.key);
    }
}

/// `--set` takes every listed key: its value in the paper's scenario (or its array's
/// template) loads; a key without one is at least known and of the right type.
#[test]
fn every_listed_key_is_accepted_by_set() {
    for k in keys() {
        match &k.base_value {
            Some(v) => {
                let set = k.set_arg(v);
                load_with(&set).unwrap_or_else(|e| panic!("--set {set}: {e}"));
            }
            None => {
                let value = match k.kind {
                    LeafKind::Float => "1.5".to_string(),
                    LeafKind::Integer { .. } => "1".to_string(),
                    LeafKind::Bool => "true".to_string(),
                    LeafKind::String => "\"x\"".to_string(),
                    LeafKind::OneOf(names) => format!("{:?}", names[0]),
                };
                let set = k.set_arg(&value);
                match load_with(&set) {
                    Ok(_) | Err(ScenarioError::Invalid { .. }) => {}
                    Err(e) => panic!("--set {set}: not taken: {e}"),
                }
            }
        }
    }
}

/// The part of a rule's text up to the first key it names (the message goes on with that
/// key's value).
fn stem(message: &str) -> &str {
    let mut end = message.len();
    let mut at = 0;
    for w in message.split(' ') {
        if w.contains('.') && w.contains('_') {
            end = at + w.trim_end_matches([',', ')', ';']).len();
            break;
        }
        at += w.len() + 1;
    }
    &message[..end]
}

/// Every rule the listing states is enforced: `--set key=<its example>` on the paper's
/// scenario file is rejected with a line naming the file, the key and the rule.
#[test]
fn every_stated_rule_is_enforced() {
    let path = paper();
    let file = path.display().to_string();
    let mut n = 0;
    for k in keys() {
        let field = k.key.replace("[].", "[0].");
        for r in &k.rules {
            let set = k.set_arg(&r.example);
            let e = match load_with(&set) {
                Err(e @ ScenarioError::Invalid { .. }) => e.to_string(),
                other => panic!("--set {set}: not rejected as invalid: {other:?}"),
            };
            let head = format!("{file}: {field} = ");
            let stem = stem(&r.message);
            assert!(
                e.lines()
                    .any(|l| l.starts_with(&head) && l[head.len()..].contains(stem)),
                "--set {set}: no line {head}… {stem:?} in\n{e}"
            );
            n += 1;
        }
    }
    assert!(n > 100, "only {n} rules");
}

fn rules_of<'a>(all: &'a [KeyInfo], key: &str) -> Vec<&'a str> {
    let k = all
        .iter()
        .find(|k| k.key == key)
        .unwrap_or_else(|| panic!("{key} not listed"));
    k.rules.iter().map(|r| r.message.as_str()).collect()
}

/// The probing finds the rules of every kind: the scenario's own, the controller's, the f32
/// range, the bounds, the arrays' and the campaign's.
#[test]
fn the_listing_states_the_rules_a_reader_relies_on() {
    let all = keys();
    for (key, fragment) in [
        ("orbit.semi_major_axis_m", "below the simulator's 150 km"),
        ("orbit.semi_major_axis_m", "Hill sphere"),
        ("orbit.eccentricity", "must be in [0, 0.75)"),
        ("masses.main_initial_kg", "overflows the controller's f32"),
        ("masses.sub_kg", "must be above 0"),
        ("initial.beta_rad", "(−π/2, π/2)"),
        ("initial.length_rate_mps", "±envelope.max_rate_mps"),
        ("controller.k1_per_s", "must be above 0"),
        (
            "envelope.max_length_m",
            "must be above envelope.min_length_m",
        ),
        ("stage1.deploy_angle_rad", "the deployment side"),
        ("stage1.band_start_m", "must be below stage1.keep_length_m"),
        ("stage2.keep_length_m", "must be inside the envelope"),
        (
            "stage2.start_time_s",
            "whole multiple of controller.period_s",
        ),
        (
            "tether.density_kg_per_m",
            "not below masses.main_initial_kg",
        ),
        (
            "simulation.duration_s",
            "more than the simulator's 10000000",
        ),
        ("simulation.substeps", "must be at most 1000"),
        ("monitor.coast_ticks", "must be at least 1"),
        (
            "monitor.max_orbit_rate_radps",
            "above monitor.min_orbit_rate_radps",
        ),
        ("sensors.alpha.noise_std", "must not be negative"),
        ("reel.max_rate_mps", "inf = no limit"),
        ("link.drop_prob", "must be in [0, 1]"),
        (
            "faults.dropout[].until_s",
            "must be after faults.dropout[0].from_s",
        ),
        ("faults.length_glitch[].size_m", "finite"),
        ("montecarlo.dispersion[].field", "is not a number field"),
        ("montecarlo.criteria.keep1_until_s", "must not be before"),
        ("name", "file name"),
    ] {
        let rules = rules_of(&all, key);
        assert!(
            rules.iter().any(|r| r.contains(fragment)),
            "{key}: no rule with {fragment:?} in {rules:?}"
        );
    }
    let default = |key: &str| all.iter().find(|k| k.key == key).unwrap().default.clone();
    assert_eq!(default("stage1.band_start_m"), KeyDefault::Required);
    assert_eq!(
        default("simulation.output_interval_s"),
        KeyDefault::Value("10.0".into())
    );
    assert_eq!(
        default("envelope.max_rate_mps"),
        KeyDefault::WithSection("15.0".into())
    );
    assert_eq!(
        default("reel.max_rate_mps"),
        KeyDefault::Value("inf".into())
    );
    assert_eq!(default("montecarlo.dispersion[].mean"), KeyDefault::Unset);
    let unit = |key: &str| all.iter().find(|k| k.key == key).unwrap().unit;
    assert_eq!(unit("stage1.keep_slope_rad_per_m"), "rad/m");
    assert_eq!(unit("controller.k2_per_s2"), "1/s²");
    assert_eq!(unit("sensors.alpha_rate.bias"), "rad/s");
    assert_eq!(unit("simulation.substeps"), "");
    assert_eq!(unit("reel.coulomb_nm"), "N·m");
    assert_eq!(unit("reel.viscous_nms"), "N·m·s/rad");
    assert_eq!(unit("tether.damping_ns"), "N·s");
    assert_eq!(unit("environment.main_drag_area_m2"), "m²");
    assert_eq!(unit("reel.drum_inertia_kgm2"), "kg·m²");
    assert_eq!(unit("faults.corrupt[].value"), "sensor's unit");
    assert_eq!(unit("montecarlo.dispersion[].std"), "field's unit");
}

/// Every number key has a unit, unless its name says it has none (a ratio, coefficient or
/// count of [`DIMENSIONLESS_NAMES`]): a key whose suffix the unit table does not know (say a
/// new `_nm` before `_nm` was added) fails here. Text, switches and choices have none.
#[test]
fn every_number_key_has_a_known_unit_or_is_dimensionless_by_name() {
    for k in keys() {
        let number = matches!(k.kind, LeafKind::Float | LeafKind::Integer { .. });
        let name = k.key.rsplit('.').next().unwrap();
        if number && k.unit.is_empty() {
            assert!(
                DIMENSIONLESS_NAMES.contains(&name),
                "{} has no unit and is not dimensionless by name",
                k.key
            );
        }
        if !number {
            assert_eq!(k.unit, "", "{} is not a number but has a unit", k.key);
        }
    }
    // The dimensionless names are keys that exist and have no unit.
    let all = keys();
    for name in DIMENSIONLESS_NAMES {
        assert!(
            all.iter()
                .any(|k| k.key.ends_with(&format!(".{name}")) && k.unit.is_empty()),
            "{name}"
        );
    }
}

#[test]
fn the_command_lists_every_key_as_text_and_tsv() {
    let bin = env!("CARGO_BIN_EXE_tss-sim");
    let text = Command::new(bin)
        .args(["scenario", "keys"])
        .output()
        .unwrap();
    assert!(text.status.success());
    let text = String::from_utf8(text.stdout).unwrap();
    let tsv = Command::new(bin)
        .args(["scenario", "keys", "--format", "tsv"])
        .output()
        .unwrap();
    assert!(tsv.status.success());
    let tsv = String::from_utf8(tsv.stdout).unwrap();
    let all = keys();
    assert_eq!(tsv.lines().count(), all.len() + 1, "{tsv}");
    for k in &all {
        assert!(
            text.lines().any(|l| l.starts_with(&format!("{} ", k.key))),
            "{}",
            k.key
        );
        assert!(
            tsv.lines().any(|l| l.starts_with(&format!("{}\t", k.key))),
            "{}",
            k.key
        );
    }
    assert!(text.contains("stage1.band_start_m"));
    assert!(text.contains("    must be below stage1.keep_length_m (e.g. 1e10)"));
}
