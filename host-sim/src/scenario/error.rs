//! Why a scenario could not be loaded: errors that name the file, the field and the value.

use std::fmt;

/// Why a scenario could not be loaded. Every message names the file and, where there is one,
/// the field (dotted path, e.g. `stage1.band_start_m`) and the value at fault.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("{file}: cannot read the scenario file")]
    Io {
        /// The scenario file, as given.
        file: String,
        /// The underlying I/O error.
        #[source]
        error: std::io::Error,
    },
    /// The file is larger than any scenario ([`MAX_SCENARIO_BYTES`](super::MAX_SCENARIO_BYTES)):
    /// not read further (a device such as `/dev/zero` would otherwise be read for ever).
    #[error("{file}: larger than {max_bytes} bytes: not a scenario file")]
    TooLarge {
        /// The scenario file, as given.
        file: String,
        /// The bound, bytes.
        max_bytes: u64,
    },
    /// The file is not valid TOML.
    #[error("{file}: not valid TOML: {message}")]
    Syntax {
        /// The scenario file, as given.
        file: String,
        /// The TOML parser's message (with line and column).
        message: String,
    },
    /// A `--set` argument is not of the form `key=value`.
    #[error("{file}: --set {arg:?}: {message}")]
    BadOverride {
        /// The scenario file, as given.
        file: String,
        /// The `--set` argument as given.
        arg: String,
        /// What is wrong with it.
        message: String,
    },
    /// A key (in the file or in a `--set`) that the scenario does not have.
    #[error("{file}: {origin}unknown key `{key}` ({hint})")]
    UnknownKey {
        /// The scenario file, as given.
        file: String,
        /// `"--set k=v: "` when the key came from an override, else empty.
        origin: String,
        /// The dotted key.
        key: String,
        /// The keys that are valid at that place.
        hint: String,
    },
    /// A value of the wrong type (a string for a number, a float for an integer, …).
    #[error("{file}: {origin}{key} = {value} {message}")]
    WrongType {
        /// The scenario file, as given.
        file: String,
        /// `"--set k=v: "` when the value came from an override, else empty.
        origin: String,
        /// The dotted key.
        key: String,
        /// The offending value, as TOML.
        value: String,
        /// What was expected.
        message: String,
    },
    /// A required key is absent.
    #[error("{file}: missing key `{key}`")]
    MissingKey {
        /// The scenario file, as given.
        file: String,
        /// The dotted key.
        key: String,
    },
    /// Any other deserialization failure (the TOML library's message).
    #[error("{file}: {message}")]
    Deserialize {
        /// The scenario file, as given.
        file: String,
        /// The deserializer's message.
        message: String,
    },
    /// The scenario deserialized but makes no physical sense: one line per problem.
    #[error("{}", format_problems(file, problems))]
    Invalid {
        /// The scenario file, as given.
        file: String,
        /// Every rule that failed, in field order.
        problems: Vec<Problem>,
    },
}

/// One failed validation rule: `field = value message`.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    /// Dotted path of the field at fault, e.g. `stage1.band_start_m`.
    pub field: String,
    /// The offending value as written in messages.
    pub value: String,
    /// What is wrong, e.g. `must be below stage1.keep_length_m = 30000`.
    pub message: String,
    /// True when the value came from a `--set` override.
    pub from_override: bool,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {} {}", self.field, self.value, self.message)?;
        if self.from_override {
            write!(f, " (set by --set)")?;
        }
        Ok(())
    }
}

fn format_problems(file: &str, problems: &[Problem]) -> String {
    let lines: Vec<String> = problems.iter().map(|p| format!("{file}: {p}")).collect();
    lines.join("\n")
}
