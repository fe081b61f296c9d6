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
//!
//! The data of Fig. 3 ([`ExtentRow`]) is defined here, so that `extent` (the command) uses
//! `plots` (the drawing) and not the other way round.

pub mod extent;
pub mod plots;
pub mod stability_cmd;

use serde::Serialize;

pub use extent::{run_extent, ExtentArgs};
pub use stability_cmd::{run_stability, StabilityArgs};

/// One row of Fig. 3: the whole-orbit bounds of Eq. 13 at one e.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ExtentRow {
    /// e.
    pub eccentricity: f64,
    /// min_θ Depl(e, θ).
    pub min_depl: f64,
    /// θ* of min Depl, rad.
    pub theta_star_depl_rad: f64,
    /// θ* of min Depl, deg.
    pub theta_star_depl_deg: f64,
    /// max_θ Retr(e, θ) (= −min Depl).
    pub max_retr: f64,
    /// θ* of max Retr, rad (= −θ* of min Depl).
    pub theta_star_retr_rad: f64,
    /// θ* of max Retr, deg.
    pub theta_star_retr_deg: f64,
    /// Root-finder iterations.
    pub iterations: u32,
    /// Whether an equilibrium can exist at every θ for some rate (min Depl ≥ 0, i.e. e ≤ 0.75).
    pub exists_whole_orbit: bool,
}

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
