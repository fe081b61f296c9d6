//! `tss-sim run SCENARIO [--out DIR] [--set key=value]...`: simulate a mission and write its
//! history, the paper's Figs. 4–6, the Table-1 comparison and a summary.
//!
//! Everything the user gave is checked (scenario, overrides, output directory) before the
//! simulation starts and before anything is written; such errors are [`UsageError`] or
//! [`ScenarioError`], which the binary turns into exit code 2.

use std::fs::File;
use std::io::{BufWriter, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};

use crate::history::History;
use crate::report::summarize;
use crate::scenario::{Scenario, ScenarioError};
use crate::table1::{Table1Comparison, PROBE_TIMES_S};
use crate::{output, plots};

/// Arguments of `tss-sim run`.
#[derive(clap::Args, Clone, Debug)]
pub struct RunArgs {
    /// Scenario file (TOML), e.g. scenarios/paper.toml.
    pub scenario: PathBuf,
    /// Output directory (created if needed; files in it are overwritten)
    /// [default: out/<scenario name>].
    #[arg(long, short, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Override one scenario field, dotted key and TOML value, e.g.
    /// `--set tether.density_kg_per_m=1e-3` (repeatable; applied in order).
    #[arg(long = "set", short = 's', value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Processor-in-the-loop: `--pil [--firmware ELF]` (see `tss_sim::pil`).
    #[command(flatten)]
    pub pil: crate::pil::PilArgs,
}

/// A command-line mistake found before any work (exit code 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// Is `err` (or its cause) the user's mistake — a bad scenario, override or output path — so
/// that the process should exit with code 2 rather than 1?
pub fn is_usage_error(err: &anyhow::Error) -> bool {
    err.chain()
        .any(|e| e.is::<ScenarioError>() || e.is::<UsageError>())
}

/// The files one run writes, and how long its parts took.
#[derive(Debug)]
pub struct RunOutcome {
    /// The output directory.
    pub dir: PathBuf,
    /// `history.csv`.
    pub history_csv: PathBuf,
    /// `table1.csv`.
    pub table1_csv: PathBuf,
    /// `summary.txt`.
    pub summary_txt: PathBuf,
    /// `scenario.toml`: the scenario as run (file plus overrides).
    pub scenario_toml: PathBuf,
    /// The figures, PNG and SVG (empty if they could not be drawn).
    pub figures: Vec<PathBuf>,
    /// Why the figures could not be drawn (the other outputs are written regardless).
    pub figure_error: Option<anyhow::Error>,
    /// Wall time of the simulation.
    pub sim_time: Duration,
    /// Wall time of writing every output.
    pub write_time: Duration,
    /// The text printed on stdout (summary and Table 1).
    pub report: String,
}

/// `tss-sim run`: with the closed-loop simulation [`crate::sim::run`].
pub fn run(args: RunArgs) -> anyhow::Result<()> {
    if args.pil.enabled {
        return crate::pil::run_cmd(&args);
    }
    let mut outcome = run_with(&args, |scenario, probes, progress| {
        crate::sim::run(scenario, probes, progress)
    })?;
    print_outcome(&outcome);
    match outcome.figure_error.take() {
        Some(e) => Err(e.context("the figures were not drawn (every other output was written)")),
        None => Ok(()),
    }
}

/// Prints the report and where the files are.
pub fn print_outcome(o: &RunOutcome) {
    let mut stdout = std::io::stdout().lock();
    let _ = write!(stdout, "{}", o.report);
    let _ = writeln!(
        stdout,
        "\nSimulated in {:.2} s; outputs written in {:.2} s to {}",
        o.sim_time.as_secs_f64(),
        o.write_time.as_secs_f64(),
        o.dir.display()
    );
    for p in [
        &o.history_csv,
        &o.table1_csv,
        &o.summary_txt,
        &o.scenario_toml,
    ] {
        let _ = writeln!(stdout, "  {}", p.display());
    }
    if o.figure_error.is_none() {
        let _ = writeln!(stdout, "Figures (Figs. 4–6 of the paper):");
        for p in &o.figures {
            let _ = writeln!(stdout, "  {}", p.display());
        }
    }
}

/// The output directory: `--out`, else `out/<scenario name>`.
pub fn output_dir(args: &RunArgs, scenario: &Scenario) -> PathBuf {
    args.out
        .clone()
        .unwrap_or_else(|| Path::new("out").join(&scenario.name))
}

/// Checks, without creating anything, that `dir` is a directory or can be created as one.
pub fn check_output_dir(dir: &Path) -> Result<(), UsageError> {
    if dir.as_os_str().is_empty() {
        return Err(UsageError("--out: the output directory is empty".into()));
    }
    let mut probe = Some(dir);
    while let Some(p) = probe {
        if p.as_os_str().is_empty() {
            break; // a relative path: its base is the working directory
        }
        match std::fs::metadata(p) {
            Ok(m) if m.is_dir() => return Ok(()),
            Ok(_) if p == dir => {
                return Err(UsageError(format!(
                    "--out {}: exists and is not a directory",
                    dir.display()
                )))
            }
            Ok(_) => {
                return Err(UsageError(format!(
                    "--out {}: cannot be created: {} is not a directory",
                    dir.display(),
                    p.display()
                )))
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => probe = p.parent(),
            Err(e) => {
                return Err(UsageError(format!(
                    "--out {}: cannot inspect {}: {e}",
                    dir.display(),
                    p.display()
                )))
            }
        }
    }
    Ok(())
}

/// The Table-1 instants a run of `scenario` reaches (t ≤ duration, whole control periods).
pub fn probe_times_for(scenario: &Scenario) -> Vec<f64> {
    let period = scenario.controller.period_s;
    PROBE_TIMES_S
        .iter()
        .copied()
        .filter(|&t| {
            let n = (t / period).round();
            t <= scenario.simulation.duration_s && (n * period - t).abs() <= 1e-9 * t.max(period)
        })
        .collect()
}

fn progress_bar(duration_s: f64) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    // Whole seconds of mission time; the bar's unit.
    let bar = ProgressBar::new(duration_s.ceil().max(1.0) as u64);
    if let Ok(style) =
        ProgressStyle::with_template("{spinner} simulating [{bar:30}] {pos}/{len} s, eta {eta}")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

/// `tss-sim run` with a given simulation function (tests pass a synthetic one).
///
/// Loads and validates the scenario, checks the output directory, runs `simulate` with the
/// Table-1 probe times and a progress callback, then writes every output. Nothing is created
/// before `simulate` has succeeded.
pub fn run_with<E>(
    args: &RunArgs,
    simulate: impl FnOnce(&Scenario, &[f64], &mut dyn FnMut(f64)) -> Result<History, E>,
) -> anyhow::Result<RunOutcome>
where
    E: std::error::Error + Send + Sync + 'static,
{
    let scenario = Scenario::load(&args.scenario, &args.set)?;
    let dir = output_dir(args, &scenario);
    check_output_dir(&dir)?;

    let probes = probe_times_for(&scenario);
    let bar = progress_bar(scenario.simulation.duration_s);
    let started = Instant::now();
    let history = simulate(&scenario, &probes, &mut |t_s| {
        bar.set_position(t_s.max(0.0) as u64)
    })
    .with_context(|| format!("simulating {}", args.scenario.display()));
    bar.finish_and_clear();
    let history = history?;
    let sim_time = started.elapsed();

    let started = Instant::now();
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let history_csv = dir.join("history.csv");
    write_file(&history_csv, |w| {
        if history.elastic.is_empty() {
            output::write_history_csv(w, &history.samples)
        } else {
            output::write_elastic_history_csv(w, &history.samples, &history.elastic)
        }
    })?;
    let table = Table1Comparison::new(&history.probes);
    let table1_csv = dir.join("table1.csv");
    write_file(&table1_csv, |w| table.write_csv(w))?;
    let scenario_toml = dir.join("scenario.toml");
    let resolved = toml::to_string_pretty(&scenario).context("serializing the scenario")?;
    write_file(&scenario_toml, |w| {
        writeln!(
            w,
            "# The scenario as run: {} with {} override(s){}",
            args.scenario.display(),
            args.set.len(),
            if args.set.is_empty() {
                String::new()
            } else {
                format!(": --set {}", args.set.join(" --set "))
            }
        )?;
        w.write_all(resolved.as_bytes())
    })?;
    let summary = summarize(&scenario, &history);
    let report = format!("{}\n{}", summary.render(), table.render());
    let summary_txt = dir.join("summary.txt");
    write_file(&summary_txt, |w| w.write_all(report.as_bytes()))?;
    // The fault summary (faults.rs): printed after the report and written to faults.txt.
    let faults = crate::faults::render_fault_summary(&scenario, &history.faults);
    write_file(&dir.join("faults.txt"), |w| w.write_all(faults.as_bytes()))?;
    let report = format!("{report}\n{faults}");
    let (figures, figure_error) = match plots::write_figures(&dir, &scenario, &history) {
        Ok(paths) => (paths, None),
        Err(e) => (Vec::new(), Some(e)),
    };
    let write_time = started.elapsed();

    Ok(RunOutcome {
        dir,
        history_csv,
        table1_csv,
        summary_txt,
        scenario_toml,
        figures,
        figure_error,
        sim_time,
        write_time,
        report,
    })
}

/// Creates `path` and writes it through a buffer with `body`; an error names the file.
pub(crate) fn write_file(
    path: &Path,
    body: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> anyhow::Result<()> {
    let file = File::create(path).with_context(|| format!("creating {}", path.display()))?;
    let mut w = BufWriter::new(file);
    body(&mut w)
        .and_then(|()| w.flush())
        .with_context(|| format!("writing {}", path.display()))
}
