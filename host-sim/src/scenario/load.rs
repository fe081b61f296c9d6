//! Loading a scenario: the TOML file, its keys checked against the [schema](super::schema),
//! `--set key=value` overrides applied on top, then deserialization and validation.

use std::collections::BTreeSet;
use std::io::Read;
use std::path::Path;

use super::error::ScenarioError;
use super::mission::Scenario;
use super::schema::{schema, LeafKind, Schema};

/// The largest scenario file read, bytes: the paper's scenarios are 2–6 KiB; a file of fault
/// lists at their bounds stays well under this.
pub const MAX_SCENARIO_BYTES: u64 = 1 << 20;

/// The text of the file at `path` if it has at most `max_bytes` bytes, `None` if it has more
/// (it is not read beyond `max_bytes + 1`: a device or a huge file costs nothing).
pub fn read_bounded(path: &Path, max_bytes: u64) -> std::io::Result<Option<String>> {
    let mut text = String::new();
    std::fs::File::open(path)?
        .take(max_bytes + 1)
        .read_to_string(&mut text)?;
    Ok((text.len() as u64 <= max_bytes).then_some(text))
}

impl Scenario {
    /// Reads a scenario file, applies `--set key=value` overrides (dotted keys, values parsed as
    /// TOML scalars; a bare word is a string), deserializes and validates it.
    ///
    /// ```
    /// # use tss_sim::scenario::Scenario;
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/paper.toml");
    /// let s = Scenario::load(path, &["simulation.duration_s=3600".to_string()]).unwrap();
    /// assert_eq!(s.simulation.duration_s, 3600.0);
    /// ```
    pub fn load(path: impl AsRef<Path>, overrides: &[String]) -> Result<Scenario, ScenarioError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let io = |error| ScenarioError::Io {
            file: file.clone(),
            error,
        };
        let text = read_bounded(path, MAX_SCENARIO_BYTES)
            .map_err(io)?
            .ok_or_else(|| ScenarioError::TooLarge {
                file: file.clone(),
                max_bytes: MAX_SCENARIO_BYTES,
            })?;
        Self::from_toml_str(&text, &file, overrides)
    }

    /// Like [`Scenario::load`] on text already read; `file` is the name used in messages.
    pub fn from_toml_str(
        text: &str,
        file: &str,
        overrides: &[String],
    ) -> Result<Scenario, ScenarioError> {
        let mut table: toml::Table = toml::from_str(text).map_err(|e| ScenarioError::Syntax {
            file: file.to_string(),
            message: e.to_string().trim_end().to_string(),
        })?;
        let schema = schema();
        check_table(&table, "", schema, file, "")?;
        if !overrides.is_empty() {
            // Apply overrides on top of the file *with its defaults filled in*, so that setting
            // one key of a section the file leaves to its default (e.g. `[envelope]`) keeps the
            // section's other defaults. A file that is incomplete by itself is used as it is.
            let complete = toml::Value::Table(table.clone())
                .try_into::<Scenario>()
                .ok()
                .and_then(|sc| toml::Table::try_from(sc).ok());
            if let Some(complete) = complete {
                table = complete;
            }
        }
        let mut overridden = BTreeSet::new();
        for arg in overrides {
            let key = apply_override(&mut table, arg, schema, file)?;
            overridden.insert(key);
        }
        let scenario: Scenario = toml::Value::Table(table.clone())
            .try_into()
            .map_err(|e: toml::de::Error| deserialize_error(&e, &table, schema, file))?;
        let mut problems = scenario.problems();
        if problems.is_empty() {
            return Ok(scenario);
        }
        for p in &mut problems {
            // `faults.dropout[0].from_s` came from `--set faults.dropout=[...]`.
            let element_of = |k: &String| {
                p.field
                    .strip_prefix(k.as_str())
                    .is_some_and(|r| r.starts_with('['))
            };
            p.from_override = overridden.contains(&p.field) || overridden.iter().any(element_of);
        }
        Err(ScenarioError::Invalid {
            file: file.to_string(),
            problems,
        })
    }
}

// ---- checking the file's table and applying overrides ----------------------------------------

pub(super) fn join_key(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

fn hint_for(schema: &Schema, prefix: &str) -> String {
    if prefix.is_empty() {
        format!("top-level keys: {}", schema.keys_under(""))
    } else if schema.tables.contains(prefix) {
        format!("keys in [{prefix}]: {}", schema.keys_under(prefix))
    } else {
        format!("top-level keys: {}", schema.keys_under(""))
    }
}

/// Checks every key of `table` (at dotted `prefix`) against the schema: unknown keys and values
/// of the wrong type are errors.
fn check_table(
    table: &toml::Table,
    prefix: &str,
    schema: &Schema,
    file: &str,
    origin: &str,
) -> Result<(), ScenarioError> {
    for (key, value) in table {
        let full = join_key(prefix, key);
        if schema.arrays.contains(&full) {
            check_array(value, &full, schema, file, origin)?;
        } else if let Some(kind) = schema.leaves.get(&full) {
            if !kind.accepts(value) {
                return Err(ScenarioError::WrongType {
                    file: file.to_string(),
                    origin: origin.to_string(),
                    key: full,
                    value: value.to_string(),
                    message: kind.describe(),
                });
            }
        } else if schema.tables.contains(&full) {
            match value {
                toml::Value::Table(sub) => check_table(sub, &full, schema, file, origin)?,
                other => {
                    return Err(ScenarioError::WrongType {
                        file: file.to_string(),
                        origin: origin.to_string(),
                        key: full.clone(),
                        value: other.to_string(),
                        message: format!("must be a table ([{full}])"),
                    })
                }
            }
        } else {
            return Err(ScenarioError::UnknownKey {
                file: file.to_string(),
                origin: origin.to_string(),
                key: full,
                hint: hint_for(schema, prefix),
            });
        }
    }
    Ok(())
}

/// Checks an array of tables (`[[key]]`): every element is a table of the element's keys.
fn check_array(
    value: &toml::Value,
    key: &str,
    schema: &Schema,
    file: &str,
    origin: &str,
) -> Result<(), ScenarioError> {
    let wrong = || ScenarioError::WrongType {
        file: file.to_string(),
        origin: origin.to_string(),
        key: key.to_string(),
        value: value.to_string(),
        message: format!(
            "must be an array of tables ([[{key}]], or inline [{{ {} }}, ...])",
            schema.keys_under(key)
        ),
    };
    let toml::Value::Array(items) = value else {
        return Err(wrong());
    };
    for item in items {
        match item {
            toml::Value::Table(t) => check_table(t, key, schema, file, origin)?,
            _ => return Err(wrong()),
        }
    }
    Ok(())
}

/// Parses the value of a `--set`: a TOML scalar (integer, float, bool, quoted string), or else the
/// raw text as a string.
pub(super) fn parse_override_value(raw: &str) -> toml::Value {
    let raw = raw.trim();
    if let Ok(mut t) = toml::from_str::<toml::Table>(&format!("v = {raw}")) {
        if t.len() == 1 {
            if let Some(v) = t.remove("v") {
                return v;
            }
        }
    }
    toml::Value::String(raw.to_string())
}

/// Applies one `key=value` override to `table`; returns the dotted key.
fn apply_override(
    table: &mut toml::Table,
    arg: &str,
    schema: &Schema,
    file: &str,
) -> Result<String, ScenarioError> {
    let bad = |message: &str| ScenarioError::BadOverride {
        file: file.to_string(),
        arg: arg.to_string(),
        message: message.to_string(),
    };
    let (key, raw) = arg
        .split_once('=')
        .ok_or_else(|| bad("expected key=value, e.g. tether.density_kg_per_m=1e-3"))?;
    let key = key.trim();
    if key.is_empty() || key.split('.').any(|part| part.trim().is_empty()) {
        return Err(bad(
            "the key must be a dotted path such as stage2.start_time_s",
        ));
    }
    let origin = format!("--set {arg}: ");
    if let Some(array) = schema.array_of(key) {
        return Err(bad(&format!(
            "`{array}` is an array of tables; set it whole, e.g. \
             {array}=[{{ {} }}]",
            schema.keys_under(array)
        )));
    }
    if schema.arrays.contains(key) {
        let value = parse_override_value(raw);
        check_array(&value, key, schema, file, &origin)?;
        insert_dotted(table, key, value).map_err(|m| bad(&m))?;
        return Ok(key.to_string());
    }
    let Some(&kind) = schema.leaves.get(key) else {
        let prefix = key.rsplit_once('.').map_or("", |(p, _)| p);
        let hint = if schema.tables.contains(key) {
            format!(
                "`{key}` is a section; set one of its keys: {}",
                schema.keys_under(key)
            )
        } else {
            hint_for(schema, prefix)
        };
        return Err(ScenarioError::UnknownKey {
            file: file.to_string(),
            origin,
            key: key.to_string(),
            hint,
        });
    };
    let mut value = parse_override_value(raw);
    value = match (kind, value) {
        // A string field takes the text as written, whatever it looks like.
        (LeafKind::String, toml::Value::String(s)) => toml::Value::String(s),
        (LeafKind::String, _) => toml::Value::String(raw.trim().to_string()),
        // An integer given for a float field is that float.
        (LeafKind::Float, toml::Value::Integer(i)) => toml::Value::Float(i as f64),
        (_, v) => v,
    };
    if !kind.accepts(&value) {
        return Err(ScenarioError::WrongType {
            file: file.to_string(),
            origin,
            key: key.to_string(),
            value: value.to_string(),
            message: kind.describe(),
        });
    }
    insert_dotted(table, key, value).map_err(|m| bad(&m))?;
    Ok(key.to_string())
}

/// Sets dotted `key` of `table` to `value`, creating sections as needed.
fn insert_dotted(table: &mut toml::Table, key: &str, value: toml::Value) -> Result<(), String> {
    let parts: Vec<&str> = key.split('.').collect();
    let (last, sections) = parts.split_last().ok_or("empty key")?;
    let mut cursor = table;
    let mut walked = String::new();
    for part in sections {
        walked = join_key(&walked, part);
        let entry = cursor
            .entry(part.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        cursor = match entry {
            toml::Value::Table(t) => t,
            _ => return Err(format!("`{walked}` in the file is not a table")),
        };
    }
    cursor.insert(last.to_string(), value);
    Ok(())
}

/// Turns a deserialization error of the (already schema-checked) table into a clear message;
/// in practice a missing required key.
fn deserialize_error(
    e: &toml::de::Error,
    table: &toml::Table,
    schema: &Schema,
    file: &str,
) -> ScenarioError {
    let message = e.message();
    if let Some(field) = message
        .strip_prefix("missing field `")
        .and_then(|rest| rest.split('`').next())
    {
        let absent = |k: &String| {
            k.rsplit('.').next() == Some(field) && lookup(table, k).is_none() && {
                // The enclosing section is present (or is the top level); otherwise the section
                // itself is what is missing.
                k.rsplit_once('.')
                    .is_none_or(|(parent, _)| lookup(table, parent).is_some())
            }
        };
        let candidate = schema
            .leaves
            .keys()
            .chain(schema.tables.iter())
            .find(|k| absent(k));
        if let Some(key) = candidate {
            return ScenarioError::MissingKey {
                file: file.to_string(),
                key: key.clone(),
            };
        }
    }
    ScenarioError::Deserialize {
        file: file.to_string(),
        message: e.to_string().trim_end().replace('\n', " "),
    }
}

fn lookup<'t>(table: &'t toml::Table, dotted: &str) -> Option<&'t toml::Value> {
    let mut parts = dotted.split('.');
    let mut value = table.get(parts.next()?)?;
    for part in parts {
        value = value.as_table()?.get(part)?;
    }
    Some(value)
}
