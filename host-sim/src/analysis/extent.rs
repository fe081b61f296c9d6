//! `tss-sim extent`: the paper's Figs. 2 and 3 (Eqs. 9–13).
//!
//! Fig. 3 is computed exactly at each e by the flight crate's bounded root finder
//! (`tss_reel::equilibrium::extent`), not read off a grid; Fig. 2 samples Depl and Retr on a
//! θ grid only to draw them.

use std::fmt::Write as _;
use std::path::PathBuf;

use serde::Serialize;
use tss_reel::equilibrium::{self, ECCENTRICITY_LIMIT};

use super::flags::{eccentricity, invalid, AnalysisCliError, OutputFormat};
use super::plots::ExtentRow;
use crate::output::OutputSet;

/// Default spacing of the e grid of Fig. 3 over [0, 0.75].
pub const DEFAULT_ECCENTRICITY_STEP: f64 = 0.025;
/// Default number of θ samples over [−π, π] for the Fig. 2 surfaces.
pub const DEFAULT_THETA_POINTS: usize = 361;
/// Most θ samples accepted (the surfaces CSV has e-values × this rows).
pub const MAX_THETA_POINTS: usize = 100_000;
/// Most e values accepted.
pub const MAX_ECCENTRICITIES: usize = 10_000;

/// Arguments of `tss-sim extent`.
#[derive(Debug, Clone, clap::Args)]
pub struct ExtentArgs {
    /// Eccentricities to evaluate, comma-separated, each in [0, 1) (default: 0 to 0.75 in
    /// steps of --step).
    #[arg(long, value_delimiter = ',', num_args = 1, allow_hyphen_values = true)]
    pub eccentricity: Vec<f64>,
    /// Spacing of the default e grid over [0, 0.75].
    #[arg(long, default_value_t = DEFAULT_ECCENTRICITY_STEP, allow_hyphen_values = true)]
    pub step: f64,
    /// Number of θ samples over [−180°, 180°] for the Fig. 2 surfaces (≥ 3).
    #[arg(long, default_value_t = DEFAULT_THETA_POINTS)]
    pub theta_points: usize,
    /// How to print the Fig. 3 table on stdout.
    #[arg(long, value_enum, default_value_t = OutputFormat::Text)]
    pub format: OutputFormat,
    /// Also write fig3_extent.csv, fig2_surfaces.csv and the plots (PNG and SVG) to this
    /// directory (created if missing; checked before any work).
    #[arg(long, short, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

/// One sample of Fig. 2: Depl and Retr at (e, θ).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SurfaceRow {
    /// e.
    pub eccentricity: f64,
    /// θ, rad.
    pub true_anomaly_rad: f64,
    /// θ, deg.
    pub true_anomaly_deg: f64,
    /// Depl(e, θ) = F1/(1 − e²)^{3/2}.
    pub depl: f64,
    /// Retr(e, θ) = F2/(1 − e²)^{3/2}.
    pub retr: f64,
}

/// The e values to evaluate: the given list (validated) or the default grid.
pub fn eccentricities(args: &ExtentArgs) -> Result<Vec<f64>, AnalysisCliError> {
    if !args.eccentricity.is_empty() {
        if args.eccentricity.len() > MAX_ECCENTRICITIES {
            return Err(invalid(
                "--eccentricity",
                format!("at most {MAX_ECCENTRICITIES} values"),
            ));
        }
        return args
            .eccentricity
            .iter()
            .map(|&e| eccentricity("--eccentricity", e))
            .collect();
    }
    let step = args.step;
    if !(step.is_finite() && step > 0.0 && step <= ECCENTRICITY_LIMIT) {
        return Err(invalid(
            "--step",
            format!("must be in (0, {ECCENTRICITY_LIMIT}] (got {step})"),
        ));
    }
    let n = (ECCENTRICITY_LIMIT / step).round() as usize;
    if n > MAX_ECCENTRICITIES {
        return Err(invalid(
            "--step",
            format!("gives more than {MAX_ECCENTRICITIES} values"),
        ));
    }
    let mut v: Vec<f64> = (0..=n)
        .map(|i| (i as f64 * step).min(ECCENTRICITY_LIMIT))
        .collect();
    // Always end exactly at the limit, where the extent vanishes.
    if v.last().is_some_and(|&e| e < ECCENTRICITY_LIMIT) {
        v.push(ECCENTRICITY_LIMIT);
    }
    v.dedup();
    Ok(v)
}

/// Fig. 3 at the given e values.
pub fn extent_rows(eccs: &[f64]) -> Result<Vec<ExtentRow>, AnalysisCliError> {
    eccs.iter()
        .map(|&e| {
            let x = equilibrium::extent(e)
                .map_err(|err| invalid("--eccentricity", format!("e = {e}: {err}")))?;
            Ok(ExtentRow {
                eccentricity: e,
                min_depl: x.min_depl.value,
                theta_star_depl_rad: x.min_depl.anomaly_rad,
                theta_star_depl_deg: x.min_depl.anomaly_rad.to_degrees(),
                max_retr: x.max_retr.value,
                theta_star_retr_rad: x.max_retr.anomaly_rad,
                theta_star_retr_deg: x.max_retr.anomaly_rad.to_degrees(),
                iterations: x.min_depl.iterations,
                exists_whole_orbit: x.min_depl.value >= 0.0,
            })
        })
        .collect()
}

/// The θ grid of Fig. 2: `n` points over [−π, π].
pub fn theta_grid(n: usize) -> Vec<f64> {
    let pi = std::f64::consts::PI;
    (0..n)
        .map(|i| -pi + 2.0 * pi * i as f64 / (n - 1) as f64)
        .collect()
}

/// Fig. 2 sampled on e × θ.
pub fn surface_rows(eccs: &[f64], thetas: &[f64]) -> Vec<SurfaceRow> {
    eccs.iter()
        .flat_map(|&e| {
            thetas.iter().map(move |&th| SurfaceRow {
                eccentricity: e,
                true_anomaly_rad: th,
                true_anomaly_deg: th.to_degrees(),
                depl: equilibrium::depl(e, th),
                retr: equilibrium::retr(e, th),
            })
        })
        .collect()
}

/// Writes rows as CSV with a header to any writer.
pub fn write_csv<W: std::io::Write, R: Serialize>(w: W, rows: &[R]) -> anyhow::Result<()> {
    let mut out = csv::Writer::from_writer(w);
    for r in rows {
        out.serialize(r)?;
    }
    out.flush()?;
    Ok(())
}

/// The Fig. 3 table for people.
pub fn format_table(rows: &[ExtentRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Whole-orbit extent of the equilibrium conditions (Eq. 13, Fig. 3):\n\
         deploying needs 0 < (2+mu3) ldot/(omega l) <= min Depl, retrieving max Retr <= it < 0.\n"
    );
    let _ = writeln!(
        s,
        "{:>8} {:>12} {:>14} {:>12} {:>14} {:>5}",
        "e", "min Depl", "theta* (deg)", "max Retr", "theta* (deg)", "iter"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:>8.4} {:>12.6} {:>14.4} {:>12.6} {:>14.4} {:>5}{}",
            r.eccentricity,
            r.min_depl,
            r.theta_star_depl_deg,
            r.max_retr,
            r.theta_star_retr_deg,
            r.iterations,
            if r.exists_whole_orbit {
                ""
            } else {
                "  (no equilibrium on the whole orbit)"
            }
        );
    }
    s
}

/// Runs `tss-sim extent`.
pub fn run_extent(args: &ExtentArgs) -> anyhow::Result<()> {
    let eccs = eccentricities(args)?;
    if args.theta_points < 3 || args.theta_points > MAX_THETA_POINTS {
        return Err(invalid(
            "--theta-points",
            format!(
                "must be in [3, {MAX_THETA_POINTS}] (got {})",
                args.theta_points
            ),
        )
        .into());
    }
    // An unusable output directory fails before anything is printed.
    let mut out = match &args.out {
        Some(dir) => Some(OutputSet::prepare("--out", dir, output_names())?),
        None => None,
    };
    let rows = extent_rows(&eccs)?;
    let quiet = crate::usage::quiet();
    // The table is the command's result: printed even under --quiet (which drops the list).
    match args.format {
        OutputFormat::Text => print!("{}", format_table(&rows)),
        OutputFormat::Csv => write_csv(std::io::stdout().lock(), &rows)?,
    }
    if let Some(mut out) = out.take() {
        let written = write_outputs(&mut out, &eccs, &rows, args.theta_points)?;
        out.commit()?;
        if !quiet {
            // As `run` does, on stdout; in CSV mode on stderr, so that stdout stays CSV.
            let list: String = written
                .iter()
                .map(|p| format!("  {}\n", p.display()))
                .collect();
            match args.format {
                OutputFormat::Text => print!("\nWritten:\n{list}"),
                OutputFormat::Csv => eprint!("Written:\n{list}"),
            }
        }
    }
    Ok(())
}

/// Every file `extent --out` writes.
pub fn output_names() -> Vec<String> {
    let mut names = vec![EXTENT_CSV.to_string(), SURFACES_CSV.to_string()];
    names.extend(super::plots::figure_names());
    names
}

/// The Fig. 3 table.
pub const EXTENT_CSV: &str = "fig3_extent.csv";
/// The Fig. 2 samples.
pub const SURFACES_CSV: &str = "fig2_surfaces.csv";

/// Writes the CSVs and plots of `extent` into `out`; returns the paths written.
pub fn write_outputs(
    out: &mut OutputSet,
    eccs: &[f64],
    rows: &[ExtentRow],
    theta_points: usize,
) -> anyhow::Result<Vec<PathBuf>> {
    let thetas = theta_grid(theta_points);
    let surfaces = surface_rows(eccs, &thetas);
    let mut written = Vec::new();
    written.push(write_csv_file(out, EXTENT_CSV, rows)?);
    written.push(write_csv_file(out, SURFACES_CSV, &surfaces)?);
    written.extend(super::plots::write_extent_plots(out, rows, &thetas)?);
    Ok(written)
}

fn write_csv_file<R: Serialize>(
    out: &mut OutputSet,
    name: &str,
    rows: &[R],
) -> anyhow::Result<PathBuf> {
    out.write(name, |w| write_csv(w, rows).map_err(std::io::Error::other))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args() -> ExtentArgs {
        ExtentArgs {
            eccentricity: vec![],
            step: DEFAULT_ECCENTRICITY_STEP,
            theta_points: DEFAULT_THETA_POINTS,
            format: OutputFormat::Csv,
            out: None,
        }
    }

    #[test]
    fn default_grid_ends_at_the_limit() {
        let e = eccentricities(&args()).unwrap();
        assert_eq!(e.len(), 31);
        assert_eq!(e[0], 0.0);
        assert_eq!(*e.last().unwrap(), 0.75);
        let e = eccentricities(&ExtentArgs {
            step: 0.2,
            ..args()
        })
        .unwrap();
        assert_eq!(e, vec![0.0, 0.2, 0.4, 0.6000000000000001, 0.75]);
    }

    #[test]
    fn bad_eccentricity_names_the_flag() {
        let err = eccentricities(&ExtentArgs {
            eccentricity: vec![0.1, 1.0],
            ..args()
        })
        .unwrap_err();
        assert!(err.to_string().starts_with("--eccentricity"), "{err}");
        let err = eccentricities(&ExtentArgs {
            step: 0.0,
            ..args()
        })
        .unwrap_err();
        assert!(err.to_string().starts_with("--step"), "{err}");
    }

    #[test]
    fn family_keeps_ends_and_is_bounded() {
        use crate::analysis::plots::{pick_family, MAX_FAMILY};
        let eccs: Vec<f64> = (0..=30).map(|i| i as f64 * 0.025).collect();
        let rows = extent_rows(&eccs).unwrap();
        let f = pick_family(&rows);
        assert_eq!(f.len(), MAX_FAMILY);
        assert_eq!(f[0].eccentricity, 0.0);
        assert_eq!(f.last().unwrap().eccentricity, 0.75);
        assert_eq!(pick_family(&rows[..3]).len(), 3);
    }

    #[test]
    fn rows_mirror() {
        let r = extent_rows(&[0.0, 0.3]).unwrap();
        assert_eq!(r[0].min_depl, 1.5);
        assert_eq!(r[1].max_retr, -r[1].min_depl);
        assert_eq!(r[1].theta_star_retr_rad, -r[1].theta_star_depl_rad);
        assert_eq!(surface_rows(&[0.1, 0.2], &theta_grid(5)).len(), 10);
    }
}
