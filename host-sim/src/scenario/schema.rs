//! The scenario's key schema: every dotted key with its value type, traced once from
//! `Scenario`'s own `Deserialize` impl (a small serde `Deserializer` that feeds every field a
//! placeholder and records where it was asked for what), so it follows the structs by itself.
//! The loader checks files and `--set` overrides against it; `tss-sim scenario keys` lists it.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::OnceLock;

use serde::Deserialize;

use super::mission::Scenario;

/// The type a scenario key holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeafKind {
    /// A float (an integer is accepted and converted).
    Float,
    /// An integer within `[min, max]`.
    Integer {
        /// Smallest allowed value.
        min: i64,
        /// Largest allowed value.
        max: i64,
    },
    /// A string.
    String,
    /// A boolean.
    Bool,
    /// One of the listed strings (an enum).
    OneOf(&'static [&'static str]),
}

impl LeafKind {
    pub(super) fn describe(self) -> String {
        match self {
            LeafKind::Float => "must be a number".to_string(),
            LeafKind::Integer { min, max } => format!("must be an integer in [{min}, {max}]"),
            LeafKind::String => "must be a string".to_string(),
            LeafKind::Bool => "must be true or false".to_string(),
            LeafKind::OneOf(names) => format!("must be one of {}", names.join(", ")),
        }
    }

    /// Does `value` fit? (Integers fit floats.)
    pub(super) fn accepts(self, value: &toml::Value) -> bool {
        match (self, value) {
            (LeafKind::Float, toml::Value::Float(_) | toml::Value::Integer(_)) => true,
            (LeafKind::Integer { min, max }, toml::Value::Integer(i)) => (min..=max).contains(i),
            (LeafKind::String, toml::Value::String(_)) => true,
            (LeafKind::Bool, toml::Value::Boolean(_)) => true,
            (LeafKind::OneOf(names), toml::Value::String(s)) => names.contains(&s.as_str()),
            _ => false,
        }
    }
}

/// Every key of a scenario file: dotted leaf keys with their types, and the section tables.
#[derive(Debug, Default)]
pub struct Schema {
    /// Dotted key → value type, e.g. `stage1.band_start_m` → `Float`.
    pub leaves: BTreeMap<String, LeafKind>,
    /// Dotted keys of the sections (tables), e.g. `stage1`.
    pub tables: BTreeSet<String>,
    /// Dotted keys of the arrays of tables, e.g. `faults.dropout` (`[[faults.dropout]]`); the
    /// keys of one element are in `leaves` under the array's key, e.g. `faults.dropout.from_s`.
    pub arrays: BTreeSet<String>,
}

impl Schema {
    /// The array of tables that `key` is a field of an element of, if any.
    pub fn array_of(&self, key: &str) -> Option<&str> {
        self.arrays
            .iter()
            .find(|a| {
                key.strip_prefix(a.as_str())
                    .is_some_and(|r| r.starts_with('.'))
            })
            .map(String::as_str)
    }

    /// The keys directly under `prefix` ("" for the top level), comma-separated.
    pub(super) fn keys_under(&self, prefix: &str) -> String {
        let under = |k: &&String| match prefix {
            "" => !k.contains('.'),
            p => k
                .strip_prefix(p)
                .and_then(|rest| rest.strip_prefix('.'))
                .is_some_and(|rest| !rest.contains('.')),
        };
        let mut keys: Vec<&String> = self.leaves.keys().filter(under).collect();
        keys.extend(self.tables.iter().filter(under));
        keys.sort();
        keys.iter()
            .map(|k| k.rsplit('.').next().unwrap_or(k))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The scenario's key schema (traced once from `Scenario`'s `Deserialize` impl, so it follows
/// the structs automatically).
pub fn schema() -> &'static Schema {
    static SCHEMA: OnceLock<Schema> = OnceLock::new();
    SCHEMA.get_or_init(|| {
        let mut schema = Schema::default();
        let tracer = Tracer {
            path: String::new(),
            out: &mut schema,
        };
        // The tracer feeds every field a placeholder, so this cannot fail for plain structs of
        // numbers, strings, bools, options and unit enums; anything else is a programming error.
        if let Err(e) = <Scenario as Deserialize>::deserialize(tracer) {
            panic!("scenario schema tracing failed: {e}");
        }
        schema
    })
}

struct Tracer<'a> {
    path: String,
    out: &'a mut Schema,
}

type TraceError = serde::de::value::Error;

impl Tracer<'_> {
    fn leaf(self, kind: LeafKind) {
        self.out.leaves.insert(self.path, kind);
    }
    fn int(self, min: i64, max: i64) {
        self.leaf(LeafKind::Integer { min, max });
    }
}

impl<'de> serde::Deserializer<'de> for Tracer<'_> {
    type Error = TraceError;

    fn deserialize_any<V: serde::de::Visitor<'de>>(self, _: V) -> Result<V::Value, TraceError> {
        Err(serde::de::Error::custom(format!(
            "unsupported field type at `{}`",
            self.path
        )))
    }
    fn deserialize_f64<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.leaf(LeafKind::Float);
        v.visit_f64(0.0)
    }
    fn deserialize_f32<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.leaf(LeafKind::Float);
        v.visit_f32(0.0)
    }
    fn deserialize_u8<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(0, u8::MAX.into());
        v.visit_u8(1)
    }
    fn deserialize_u16<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(0, u16::MAX.into());
        v.visit_u16(1)
    }
    fn deserialize_u32<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(0, u32::MAX.into());
        v.visit_u32(1)
    }
    fn deserialize_u64<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(0, i64::MAX);
        v.visit_u64(1)
    }
    fn deserialize_i8<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(i8::MIN.into(), i8::MAX.into());
        v.visit_i8(1)
    }
    fn deserialize_i16<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(i16::MIN.into(), i16::MAX.into());
        v.visit_i16(1)
    }
    fn deserialize_i32<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(i32::MIN.into(), i32::MAX.into());
        v.visit_i32(1)
    }
    fn deserialize_i64<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.int(i64::MIN, i64::MAX);
        v.visit_i64(1)
    }
    fn deserialize_bool<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.leaf(LeafKind::Bool);
        v.visit_bool(false)
    }
    fn deserialize_str<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.leaf(LeafKind::String);
        v.visit_str("")
    }
    fn deserialize_string<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        self.leaf(LeafKind::String);
        v.visit_string(String::new())
    }
    fn deserialize_option<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        v.visit_some(self)
    }
    fn deserialize_struct<V: serde::de::Visitor<'de>>(
        self,
        _name: &'static str,
        fields: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, TraceError> {
        if !self.path.is_empty() {
            self.out.tables.insert(self.path.clone());
        }
        v.visit_map(TraceFields {
            path: self.path,
            fields,
            next: 0,
            out: self.out,
        })
    }
    fn deserialize_seq<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, TraceError> {
        // An array of tables: trace one element at the array's own path.
        self.out.arrays.insert(self.path.clone());
        v.visit_seq(TraceSeq {
            path: self.path,
            done: false,
            out: self.out,
        })
    }
    fn deserialize_enum<V: serde::de::Visitor<'de>>(
        self,
        _name: &'static str,
        variants: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, TraceError> {
        use serde::de::IntoDeserializer;
        self.leaf(LeafKind::OneOf(variants));
        let first: &'static str = variants.first().copied().unwrap_or("");
        v.visit_enum(first.into_deserializer())
    }

    serde::forward_to_deserialize_any! {
        i128 u128 char bytes byte_buf unit unit_struct newtype_struct tuple
        tuple_struct map identifier ignored_any
    }
}

struct TraceSeq<'a> {
    path: String,
    done: bool,
    out: &'a mut Schema,
}

impl<'de> serde::de::SeqAccess<'de> for TraceSeq<'_> {
    type Error = TraceError;

    fn next_element_seed<S: serde::de::DeserializeSeed<'de>>(
        &mut self,
        seed: S,
    ) -> Result<Option<S::Value>, TraceError> {
        if self.done {
            return Ok(None);
        }
        self.done = true;
        seed.deserialize(Tracer {
            path: self.path.clone(),
            out: &mut *self.out,
        })
        .map(Some)
    }
}

struct TraceFields<'a> {
    path: String,
    fields: &'static [&'static str],
    next: usize,
    out: &'a mut Schema,
}

impl<'de> serde::de::MapAccess<'de> for TraceFields<'_> {
    type Error = TraceError;

    fn next_key_seed<K: serde::de::DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, TraceError> {
        use serde::de::IntoDeserializer;
        match self.fields.get(self.next) {
            Some(&field) => seed.deserialize(field.into_deserializer()).map(Some),
            None => Ok(None),
        }
    }

    fn next_value_seed<V: serde::de::DeserializeSeed<'de>>(
        &mut self,
        seed: V,
    ) -> Result<V::Value, TraceError> {
        let field = self.fields.get(self.next).copied().unwrap_or("");
        self.next += 1;
        let path = if self.path.is_empty() {
            field.to_string()
        } else {
            format!("{}.{field}", self.path)
        };
        seed.deserialize(Tracer {
            path,
            out: &mut *self.out,
        })
    }
}
