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
//! `extent.rs` and `stability_cmd.rs` are the commands, `plots.rs` draws Figs. 2 and 3 (and
//! holds their data, [`ExtentRow`], which `extent` computes), `flags.rs` checks the flags.

pub mod extent;
mod flags;
pub mod plots;
pub mod stability_cmd;

pub use extent::{run_extent, ExtentArgs};
pub use flags::{is_usage_error, AnalysisCliError, OutputFormat};
pub use plots::ExtentRow;
pub use stability_cmd::{run_stability, StabilityArgs};
