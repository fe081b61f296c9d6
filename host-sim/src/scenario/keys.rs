//! `tss-sim scenario keys`: every scenario key with its type, unit, default and rules.
//!
//! Nothing here is a second, hand-written list that could drift from validation:
//! - the keys and their types are the [schema](super::schema()), traced from the structs;
//! - the defaults are what deserialization fills in when the key (or its section) is left out
//!   of the paper's scenario;
//! - the rules are what validation answers: each key of the paper's scenario is set, one at a
//!   time, to a fixed ladder of probe values (0, ±1, 1e10, NaN, …) exactly as `--set key=value`
//!   sets it, and every distinct message that names the key is a rule, with the probe that
//!   breaks it as its example. Rules that need two keys to change at once (e.g. plant steps =
//!   duration × sub-steps) show under the key whose single change breaks them, if any.
//!
//! The elements of an array of tables (`[[faults.dropout]]`, …) are listed as
//! `faults.dropout[].from_s`; `--set` takes the whole array, e.g.
//! `--set 'faults.dropout=[{ from_s = 600, until_s = 660 }]'`.

use super::error::ScenarioError;
use super::load::parse_override_value;
use super::mission::Scenario;
use super::schema::{schema, LeafKind};

/// The base the defaults and rules are read from: the paper's scenario.
pub const BASE_TOML: &str = include_str!("../../../scenarios/paper.toml");

/// The name the base has in messages.
const BASE_FILE: &str = "paper.toml";

/// One valid element of each array of tables, the base its element keys are probed from.
pub const ARRAY_TEMPLATES: &[(&str, &str)] = &[
    ("faults.dropout", "{ from_s = 100.0, until_s = 200.0 }"),
    (
        "faults.alpha_dropout",
        "{ from_s = 100.0, until_s = 200.0 }",
    ),
    (
        "faults.corrupt",
        "{ sensor = \"alpha\", from_s = 100.0, until_s = 200.0, value = 0.0 }",
    ),
    ("faults.length_glitch", "{ at_s = 100.0, size_m = 1.0 }"),
    ("telecommand", "{ at_s = 100.0, command = \"hold\" }"),
    (
        "montecarlo.dispersion",
        "{ field = \"masses.sub_kg\", distribution = \"normal\", std = 1.0 }",
    ),
];

/// The probe values of a number key, in the order their examples are preferred.
const FLOAT_PROBES: &[&str] = &[
    "0", "-1", "1", "2", "0.5", "-0.5", "1e10", "-1e10", "1e39", "nan", "inf", "-inf",
];
/// The probe values of an integer key.
const INTEGER_PROBES: &[&str] = &["0", "1", "2", "1001", "10000001", "4294967295"];
/// The probe values of a string key.
const STRING_PROBES: &[&str] = &["\"\"", "\"a/b\"", "\"..\"", "\"nosuch.field\""];

/// One scenario key, as `tss-sim scenario keys` lists it.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyInfo {
    /// The dotted key (`faults.dropout[].from_s` for a field of an array's elements).
    pub key: String,
    /// The schema's key, as `schema().leaves` names it (`faults.dropout.from_s`).
    pub schema_key: String,
    /// Its type.
    pub kind: LeafKind,
    /// Its unit, read from its name (`_m`, `_mps`, …) by [`unit_of`]; empty when it has none.
    pub unit: &'static str,
    /// Its default.
    pub default: KeyDefault,
    /// Its value in the paper's scenario (defaults filled in), or in its array's element
    /// template; `None` when neither has one.
    pub base_value: Option<String>,
    /// What validation rejects, each with a value that breaks it.
    pub rules: Vec<KeyRule>,
}

/// A key's default.
#[derive(Clone, Debug, PartialEq)]
pub enum KeyDefault {
    /// The key must be given.
    Required,
    /// Left out, it takes this value (as TOML).
    Value(String),
    /// Required inside its section, which as a whole may be left out; then it takes this value.
    WithSection(String),
    /// Optional, and absent when left out (e.g. a normal dispersion's `min`).
    Unset,
}

/// A rule validation enforces on a key.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyRule {
    /// What the message says, with the other keys' values left out (`must be below
    /// stage1.keep_length_m`).
    pub message: String,
    /// A value that breaks it (as `--set` takes it).
    pub example: String,
}

impl KeyInfo {
    /// The `--set` argument that sets this key to `value` on the paper's scenario (for an
    /// element key, the whole array with one element).
    pub fn set_arg(&self, value: &str) -> String {
        match self.key.split_once("[].") {
            Some((array, field)) => {
                let mut element = template(array);
                element.insert(field.to_string(), parse_override_value(value));
                format!("{array}=[{}]", toml::Value::Table(element))
            }
            None => format!("{}={value}", self.key),
        }
    }

    /// The field name validation gives this key's problems.
    fn problem_field(&self) -> String {
        self.key.replace("[].", "[0].")
    }
}

/// The element template of array `array` (empty if it has none).
fn template(array: &str) -> toml::Table {
    ARRAY_TEMPLATES
        .iter()
        .find(|(a, _)| *a == array)
        .and_then(|(_, t)| toml::from_str::<toml::Table>(&format!("v = {t}")).ok())
        .and_then(|mut t| t.remove("v"))
        .and_then(|v| v.as_table().cloned())
        .unwrap_or_default()
}

/// Every key of the scenario, in the schema's (alphabetical) order.
pub fn keys() -> Vec<KeyInfo> {
    let s = schema();
    let full = full_base();
    s.leaves
        .iter()
        .map(|(schema_key, &kind)| {
            let key = match s.array_of(schema_key) {
                Some(array) => format!("{array}[].{}", &schema_key[array.len() + 1..]),
                None => schema_key.clone(),
            };
            let mut info = KeyInfo {
                key,
                schema_key: schema_key.clone(),
                kind,
                unit: unit_of(schema_key),
                default: KeyDefault::Required,
                base_value: None,
                rules: Vec::new(),
            };
            info.default = default_of(&info, &full);
            info.base_value = match info.key.split_once("[].") {
                Some((array, field)) => template(array).get(field).map(toml::Value::to_string),
                None => lookup(&full, &schema_key.split('.').collect::<Vec<_>>()),
            };
            info.rules = rules_of(&info);
            info
        })
        .collect()
}

/// The paper's scenario with every default filled in, as a table.
fn full_base() -> toml::Table {
    let sc = Scenario::from_toml_str(BASE_TOML, BASE_FILE, &[])
        .unwrap_or_else(|e| panic!("the built-in paper scenario is invalid: {e}"));
    toml::Table::try_from(sc).unwrap_or_default()
}

/// What deserialization fills in when `info`'s key, or else its section, is left out.
fn default_of(info: &KeyInfo, full: &toml::Table) -> KeyDefault {
    let path: Vec<&str> = info.schema_key.split('.').collect();
    let mut base = full.clone();
    if let Some((array, field)) = info.key.split_once("[].") {
        // One element of the array, without the field.
        let mut element = template(array);
        element.remove(field);
        let _ = insert(&mut base, array, toml::Value::Array(vec![element.into()]));
        return match resolve(&base) {
            Some(t) => {
                lookup_element(&t, array, field).map_or(KeyDefault::Unset, KeyDefault::Value)
            }
            None => KeyDefault::Required,
        };
    }
    remove(&mut base, &path);
    if let Some(t) = resolve(&base) {
        return lookup(&t, &path).map_or(KeyDefault::Unset, KeyDefault::Value);
    }
    if path.len() > 1 {
        let mut without_section = full.clone();
        without_section.remove(path[0]);
        if let Some(v) = resolve(&without_section).and_then(|t| lookup(&t, &path)) {
            return KeyDefault::WithSection(v);
        }
    }
    KeyDefault::Required
}

/// `table` deserialized as a scenario (not validated) and serialized back, defaults filled in.
fn resolve(table: &toml::Table) -> Option<toml::Table> {
    let sc: Scenario = toml::Value::Table(table.clone()).try_into().ok()?;
    toml::Table::try_from(sc).ok()
}

fn lookup(table: &toml::Table, path: &[&str]) -> Option<String> {
    let (last, sections) = path.split_last()?;
    let mut t = table;
    for p in sections {
        t = t.get(*p)?.as_table()?;
    }
    t.get(*last).map(toml::Value::to_string)
}

fn lookup_element(table: &toml::Table, array: &str, field: &str) -> Option<String> {
    let path: Vec<&str> = array.split('.').collect();
    let (last, sections) = path.split_last()?;
    let mut t = table;
    for p in sections {
        t = t.get(*p)?.as_table()?;
    }
    let element = t.get(*last)?.as_array()?.first()?.as_table()?;
    element.get(field).map(toml::Value::to_string)
}

fn remove(table: &mut toml::Table, path: &[&str]) {
    let Some((last, sections)) = path.split_last() else {
        return;
    };
    let mut t = table;
    for p in sections {
        match t.get_mut(*p).and_then(toml::Value::as_table_mut) {
            Some(sub) => t = sub,
            None => return,
        }
    }
    t.remove(*last);
}

fn insert(table: &mut toml::Table, dotted: &str, value: toml::Value) -> Option<()> {
    let path: Vec<&str> = dotted.split('.').collect();
    let (last, sections) = path.split_last()?;
    let mut t = table;
    for p in sections {
        t = t
            .entry(p.to_string())
            .or_insert_with(|| toml::Table::new().into())
            .as_table_mut()?;
    }
    t.insert(last.to_string(), value);
    Some(())
}

/// What validation answers when `info`'s key alone is set to each probe value.
fn rules_of(info: &KeyInfo) -> Vec<KeyRule> {
    let probes: &[&str] = match info.kind {
        LeafKind::Float => FLOAT_PROBES,
        LeafKind::Integer { .. } => INTEGER_PROBES,
        LeafKind::String => STRING_PROBES,
        LeafKind::Bool | LeafKind::OneOf(_) => &[],
    };
    let field = info.problem_field();
    let mut rules: Vec<KeyRule> = Vec::new();
    let mut seen: Vec<String> = Vec::new();
    for probe in probes {
        for message in rejections(info, probe, &field) {
            let shape = masked(&message);
            if !seen.contains(&shape) {
                seen.push(shape);
                rules.push(KeyRule {
                    message,
                    example: (*probe).to_string(),
                });
            }
        }
    }
    rules
}

/// The messages of the problems naming `field` when `info`'s key is set to `value` on the
/// paper's scenario (other keys' values left out of them).
pub fn rejections(info: &KeyInfo, value: &str, field: &str) -> Vec<String> {
    let set = info.set_arg(value);
    match Scenario::from_toml_str(BASE_TOML, BASE_FILE, &[set]) {
        Err(ScenarioError::Invalid { problems, .. }) => problems
            .iter()
            .filter(|p| p.field == field)
            .map(|p| without_values(&p.message))
            .collect(),
        _ => Vec::new(),
    }
}

/// `message` without the values of the keys it names: `must be below stage1.keep_length_m =
/// 30000` → `must be below stage1.keep_length_m` (a bracketed value, `= [0.5, 40000]`, whole).
fn without_values(message: &str) -> String {
    let mut out = String::new();
    let mut words = message.split(' ').peekable();
    while let Some(w) = words.next() {
        if !out.is_empty() {
            out.push(' ');
        }
        out.push_str(w);
        let names_a_key = w.contains('.') && w.contains('_');
        if names_a_key && words.peek() == Some(&"=") {
            words.next();
            // The value: one word, or a bracketed list up to its closing word; what follows the
            // value in its last word (`30000),` → `),`) stays.
            let mut value = words.next().unwrap_or("");
            if value.starts_with('[') {
                while !value.contains(']') {
                    match words.next() {
                        Some(next) => value = next,
                        None => break,
                    }
                }
                out.push_str(value.split_once(']').map_or("", |(_, tail)| tail));
            } else {
                let tail: String = value
                    .chars()
                    .skip_while(|c| !matches!(c, ',' | ')' | ';'))
                    .collect();
                out.push_str(&tail);
            }
        }
    }
    out
}

/// `message` with its numbers masked (`1e10`, `0.5`, `-3` → `#`), so that two probes
/// breaking one rule are one rule.
fn masked(message: &str) -> String {
    let chars: Vec<char> = message.chars().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < chars.len() {
        if !chars[i].is_ascii_digit() {
            out.push(chars[i]);
            i += 1;
            continue;
        }
        out.push('#');
        while let Some(&c) = chars.get(i) {
            let next_is = |f: fn(&char) -> bool| chars.get(i + 1).is_some_and(f);
            let part_of_number = c.is_ascii_digit()
                || (c == '.' && next_is(char::is_ascii_digit))
                || ((c == 'e' || c == 'E') && next_is(|n| n.is_ascii_digit() || *n == '-'))
                || (c == '-' && matches!(chars[i - 1], 'e' | 'E'));
            if !part_of_number {
                break;
            }
            i += 1;
        }
    }
    out
}

/// The names of the number keys that have no unit: ratios, coefficients and counts (the last
/// part of the key; `tss-sim scenario keys` shows "-" for them).
pub const DIMENSIONLESS_NAMES: [&str; 15] = [
    "eccentricity",
    "courant",
    "drag_coefficient",
    "seed",
    "substeps",
    "good_samples_per_bad",
    "counts_per_rev",
    "encoder_counts_per_rev",
    // The tension laws' gains (`[controller.rupp]`, `[controller.tracking]`): in units of Ω.
    "length_gain",
    "rate_gain",
    "bias_gain",
    "schedule_rate",
    "retrieve_schedule_rate",
    // The tension loop's (`[tension_loop]`): a damping ratio and an overshoot allowance.
    "damping_ratio",
    "overshoot",
];

/// The unit in a key's name, by the naming convention (`_m`, `_mps`, `_rad_per_m`, `_nm`, …);
/// empty for a key without one (text, switches, [`DIMENSIONLESS_NAMES`]).
pub fn unit_of(key: &str) -> &'static str {
    // Longest first where one suffix ends another (`_kgm2` before `_m2`).
    const SUFFIXES: &[(&str, &str)] = &[
        ("_kg_per_m", "kg/m"),
        ("_hz", "Hz"),
        ("_rad_per_m", "rad/m"),
        ("_per_s2", "1/s²"),
        ("_per_s", "1/s"),
        ("_radps", "rad/s"),
        ("_mps2", "m/s²"),
        ("_mps", "m/s"),
        ("_kgm2", "kg·m²"),
        ("_m2", "m²"),
        ("_nms", "N·m·s/rad"),
        ("_nm", "N·m"),
        ("_ns", "N·s"),
        ("_kg", "kg"),
        ("_rad", "rad"),
        ("_n", "N"),
        ("_m", "m"),
        ("_s", "s"),
        ("_ticks", "ticks"),
        ("_periods", "control periods"),
        ("_prob", "probability"),
    ];
    let name = key.rsplit('.').next().unwrap_or(key);
    if let Some((_, unit)) = SUFFIXES.iter().find(|(s, _)| name.ends_with(s)) {
        return unit;
    }
    // A sensor's errors are in the sensor's unit; so is an injected corrupt value, and a
    // dispersion's parameters are in the unit of the field it disperses.
    match key.rsplit_once('.').map(|(section, _)| section) {
        Some(section)
            if !matches!(name, "noise_std" | "bias" | "quantum")
                && section.starts_with("sensors.") =>
        {
            ""
        }
        Some("sensors.length") => "m",
        Some("sensors.alpha") => "rad",
        Some("sensors.alpha_rate") => "rad/s",
        Some("faults.corrupt[]" | "faults.corrupt") if name == "value" => "sensor's unit",
        Some("montecarlo.dispersion[]" | "montecarlo.dispersion")
            if matches!(name, "mean" | "std" | "min" | "max") =>
        {
            "field's unit"
        }
        _ => "",
    }
}

fn kind_name(kind: LeafKind) -> String {
    match kind {
        LeafKind::Float => "number".to_string(),
        LeafKind::Integer { min, max } => format!("integer [{min}, {max}]"),
        LeafKind::String => "string".to_string(),
        LeafKind::Bool => "bool".to_string(),
        LeafKind::OneOf(names) => names.join("|"),
    }
}

fn default_text(d: &KeyDefault) -> String {
    match d {
        KeyDefault::Required => "required".to_string(),
        KeyDefault::Value(v) => format!("default {v}"),
        KeyDefault::WithSection(v) => format!("required in its section (section default {v})"),
        KeyDefault::Unset => "optional (no default)".to_string(),
    }
}

/// The keys as text: one line per key (key, type, unit, default), then its rules indented.
pub fn render_text(keys: &[KeyInfo]) -> String {
    let width = keys.iter().map(|k| k.key.len()).max().unwrap_or(0);
    let mut o = String::new();
    o.push_str(
        "Scenario keys (type, unit, default; rules with a value that breaks them). Arrays of\n\
         tables are set whole: --set 'faults.dropout=[{ from_s = 600, until_s = 660 }]'.\n",
    );
    for k in keys {
        let unit = if k.unit.is_empty() { "-" } else { k.unit };
        o.push_str(&format!(
            "{:width$}  {}  {}  {}\n",
            k.key,
            kind_name(k.kind),
            unit,
            default_text(&k.default)
        ));
        for r in &k.rules {
            o.push_str(&format!("    {} (e.g. {})\n", r.message, r.example));
        }
    }
    o
}

/// The keys as tab-separated values with a header: key, type, unit, default, rules (`; `).
pub fn render_tsv(keys: &[KeyInfo]) -> String {
    let mut o = String::from("key\ttype\tunit\tdefault\trules\n");
    for k in keys {
        let rules: Vec<String> = k
            .rules
            .iter()
            .map(|r| format!("{} (e.g. {})", r.message, r.example))
            .collect();
        o.push_str(&format!(
            "{}\t{}\t{}\t{}\t{}\n",
            k.key,
            kind_name(k.kind),
            k.unit,
            default_text(&k.default),
            rules.join("; ")
        ));
    }
    o
}
