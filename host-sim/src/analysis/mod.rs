//! Desk analysis of the equilibria (Eqs. 6–19): the `extent` and `stability` subcommands.
//!
//! - `tss-sim extent`: the whole-orbit extent of the equilibrium conditions (Fig. 3: min Depl,
//!   max Retr and θ* against e) and the Depl/Retr surfaces over e and θ (Fig. 2), printed as a
//!   table or CSV and, with `--out DIR`, written as CSV, PNG and SVG.
//! - `tss-sim stability`: the characteristic roots, D1, D2 and verdicts of Eqs. 17–19 at one
//!   state, with the nalgebra eigenvalues of the full Jacobian as a cross-check.
//!
//! The numbers come from the flight crate (`tss_reel::equilibrium`, `tss_reel::stability`) in
//! `f64`; this module only validates input, formats and draws. Every invalid input is an
//! [`AnalysisCliError`] naming the flag, which `main` reports with exit code 2.

pub mod extent;
pub mod plots;
pub mod stability_cmd;

use std::path::PathBuf;

pub use extent::{run_extent, ExtentArgs};
pub use stability_cmd::{run_stability, StabilityArgs};

/// How a subcommand prints its result on stdout.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum OutputFormat {
    /// An aligned table for people.
    #[default]
    Text,
    /// CSV with a header row, for programs.
    Csv,
}

/// An error of the analysis subcommands: bad input (naming the flag) or an output that could
/// not be written. All of them exit with code 2.
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
    /// A file or directory could not be written.
    #[error("cannot write {}: {message}", path.display())]
    Output {
        /// The path at fault.
        path: PathBuf,
        /// Why.
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

/// Creates `dir` (and parents) for output.
pub(crate) fn create_dir(dir: &std::path::Path) -> Result<(), AnalysisCliError> {
    std::fs::create_dir_all(dir).map_err(|e| AnalysisCliError::Output {
        path: dir.to_path_buf(),
        message: e.to_string(),
    })
}
