//! The analysis subcommands' flags: each checked by a rule that names the flag when it fails,
//! and the format a subcommand prints in.

/// How a subcommand prints its result on stdout.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum OutputFormat {
    /// An aligned table for people.
    #[default]
    Text,
    /// CSV with a header row, for programs.
    Csv,
}

/// A bad input of the analysis subcommands, naming the flag (exit code 2; an unusable output
/// directory is a [`crate::usage::UsageError`]).
#[derive(Debug, thiserror::Error)]
pub enum AnalysisCliError {
    /// A flag's value is impossible.
    #[error("{flag}: {message}")]
    Invalid {
        /// The flag, e.g. `--length-m`.
        flag: &'static str,
        /// What is wrong with its value.
        message: String,
    },
}

/// `true` if `err` came from the analysis subcommands (they all exit with code 2).
pub fn is_usage_error(err: &anyhow::Error) -> bool {
    err.chain().any(|e| e.is::<AnalysisCliError>())
}

/// Shorthand for an [`AnalysisCliError::Invalid`].
pub(crate) fn invalid(flag: &'static str, message: impl Into<String>) -> AnalysisCliError {
    AnalysisCliError::Invalid {
        flag,
        message: message.into(),
    }
}

/// `Ok(x)` if finite, else an error naming `flag`.
pub(crate) fn finite(flag: &'static str, x: f64) -> Result<f64, AnalysisCliError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(invalid(flag, format!("must be a finite number (got {x})")))
    }
}

/// `Ok(x)` if finite and > 0, else an error naming `flag`.
pub(crate) fn positive(flag: &'static str, x: f64) -> Result<f64, AnalysisCliError> {
    if finite(flag, x)? > 0.0 {
        Ok(x)
    } else {
        Err(invalid(flag, format!("must be > 0 (got {x})")))
    }
}

/// `Ok(e)` if e ∈ [0, 1), else an error naming `flag`.
pub(crate) fn eccentricity(flag: &'static str, e: f64) -> Result<f64, AnalysisCliError> {
    if (0.0..1.0).contains(&finite(flag, e)?) {
        Ok(e)
    } else {
        Err(invalid(
            flag,
            format!("eccentricity must be in [0, 1) (got {e})"),
        ))
    }
}
