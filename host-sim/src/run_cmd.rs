//! `tss-sim run SCENARIO [--out DIR] [--set key=value]... [--pil [--firmware ELF]]`: simulate a
//! mission and write its history, the paper's Figs. 4–6 (and on the elastic plant the tether's
//! shape, `plots::TetherShapes`), the Table-1 comparison and a summary.
//!
//! Everything the user gave is checked (scenario, overrides, output directory, firmware) before
//! the simulation starts; such errors are [`UsageError`] or [`ScenarioError`], which the binary
//! turns into exit code 2. The files are written through an [`OutputSet`]: a failed run leaves
//! the output directory as it was, and a successful one removes the files of the set
//! ([`output_names`]) that it did not write (`pil.txt` and `firmware.log` of an earlier PIL run,
//! the figures when they could not be drawn).
//!
//! [`ScenarioError`]: crate::scenario::ScenarioError

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};

use crate::history::History;
use crate::output::{self, OutputSet};
use crate::pil::{self, PilError, FIRMWARE_LOG};
use crate::plots;
use crate::report::summarize;
use crate::scenario::Scenario;
use crate::sim::SimError;
use crate::table1::{probe_times_for, Table1Comparison};
use crate::usage::{quiet, UsageError};
use crate::verdict::Verdict;

/// Arguments of `tss-sim run`.
#[derive(clap::Args, Clone, Debug)]
pub struct RunArgs {
    /// Scenario file (TOML), e.g. scenarios/paper.toml.
    pub scenario: PathBuf,
    /// Output directory (created if needed; the files of an earlier run in it are replaced)
    /// [default: out/NAME, NAME being the scenario's name].
    #[arg(long, short, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Override one scenario field, dotted key and TOML value, e.g.
    /// `--set tether.density_kg_per_m=1e-3` (repeatable; applied in order).
    #[arg(long = "set", short = 's', value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Processor-in-the-loop: `--pil [--firmware ELF]` (see `tss_sim::pil`).
    #[command(flatten)]
    pub pil: PilArgs,
}

/// The `--pil` options of `tss-sim run`.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct PilArgs {
    /// Processor-in-the-loop: fly the flight firmware in QEMU (mps2-an386) over its UART
    /// instead of the controller linked into the simulator. Writes the same outputs, plus the
    /// firmware's log (firmware.log) and the link's report (pil.txt).
    #[arg(id = "pil", long = "pil")]
    pub enabled: bool,
    /// The firmware ELF for --pil; it is not built here (`cargo fw-build` builds it)
    /// [default: target/thumbv7em-none-eabihf/firmware/tss-reel].
    #[arg(long, value_name = "ELF", requires = "pil")]
    pub firmware: Option<PathBuf>,
}

/// The report of the PIL link.
pub const PIL_TXT: &str = "pil.txt";

/// The unit's telemetry, decoded (`crate::obc::write_telemetry_csv`).
pub const TELEMETRY_CSV: &str = "telemetry.csv";

/// The run's verdict, machine-readable (`crate::verdict::Verdict::to_json`).
pub const VERDICT_JSON: &str = "verdict.json";

/// Every file `tss-sim run` may write into its output directory.
pub fn output_names() -> Vec<String> {
    let mut names: Vec<String> = [
        "history.csv",
        TELEMETRY_CSV,
        "table1.csv",
        "summary.txt",
        "faults.txt",
        "scenario.toml",
        VERDICT_JSON,
        PIL_TXT,
        FIRMWARE_LOG,
    ]
    .map(String::from)
    .to_vec();
    names.extend(plots::figure_names());
    names
}

/// The files one run wrote, and how long its parts took.
#[derive(Debug)]
pub struct RunOutcome {
    /// The output directory.
    pub dir: PathBuf,
    /// Every file written but the figures, in the order written.
    pub files: Vec<PathBuf>,
    /// The figures, PNG and SVG (empty if they could not be drawn).
    pub figures: Vec<PathBuf>,
    /// Why the figures could not be drawn (the other outputs are written regardless).
    pub figure_error: Option<anyhow::Error>,
    /// What the figures are, for the heading above their list.
    pub figures_heading: String,
    /// Wall time of the simulation.
    pub sim_time: Duration,
    /// Wall time of writing every output.
    pub write_time: Duration,
    /// The text printed on stdout (summary, Table 1, faults, and the PIL report).
    pub report: String,
}

/// `tss-sim run`: with the closed-loop simulation [`crate::sim::run`], or with the firmware in
/// the loop ([`crate::pil::run`]) under `--pil`.
pub fn run(args: RunArgs) -> anyhow::Result<()> {
    if args.pil.enabled {
        return run_pil(&args);
    }
    let mut outcome = run_with(&args, |scenario, probes, _, progress| {
        crate::sim::run(scenario, probes, progress)
    })?;
    print_outcome(&outcome);
    match outcome.figure_error.take() {
        Some(e) => Err(e.context("the figures were not drawn (every other output was written)")),
        None => Ok(()),
    }
}

/// `tss-sim run --pil`: [`pil::run`] through [`run_with`], plus `pil.txt` and `firmware.log`.
///
/// The firmware's log is written as the run goes, as `firmware.partial.log`: if the run fails,
/// it stays under that name and explains why.
fn run_pil(args: &RunArgs) -> anyhow::Result<()> {
    let firmware = args
        .pil
        .firmware
        .clone()
        .unwrap_or_else(|| PathBuf::from(pil::DEFAULT_FIRMWARE));
    if !firmware.is_file() {
        return Err(UsageError(PilError::MissingFirmware(firmware).to_string()).into());
    }
    // Checked here too, so that a scenario too long for the firmware is a usage error.
    let scenario = Scenario::load(&args.scenario, &args.set)?;
    pil::check_duration(&scenario).map_err(|e| UsageError(e.to_string()))?;
    if scenario.controller.law != crate::scenario::LawName::Paper {
        return Err(UsageError(format!(
            "--pil flies the flight firmware, whose law is the paper's: controller.law = {:?} \
             is a simulator law (run it without --pil)",
            scenario.controller.law.as_str()
        ))
        .into());
    }
    let mut report = None;
    let mut outcome = run_with(args, |sc, probes, out, progress| {
        let log = out.stage(FIRMWARE_LOG);
        out.keep_on_failure(FIRMWARE_LOG);
        let (history, r) = pil::run(sc, &firmware, &log, probes, progress)?;
        let text = r.render();
        out.write(PIL_TXT, |w| w.write_all(text.as_bytes()))
            .map_err(|e| SimError::Link(e.into()))?;
        report = Some(r);
        Ok::<_, SimError>(history)
    })?;
    let report = report.context("the PIL run returned no report")?;
    outcome.report.push('\n');
    outcome.report.push_str(&report.render());
    print_outcome(&outcome);
    if let Some(e) = outcome.figure_error.take() {
        return Err(e.context("the figures were not drawn (every other output was written)"));
    }
    if !report.consistent() {
        anyhow::bail!(
            "the two ends of the link disagree on what happened (see {})",
            outcome.dir.join(PIL_TXT).display()
        );
    }
    Ok(())
}

/// Prints the report and where the files are (nothing under `--quiet`).
pub fn print_outcome(o: &RunOutcome) {
    if quiet() {
        return;
    }
    let mut stdout = std::io::stdout().lock();
    let _ = write!(stdout, "{}", o.report);
    let _ = writeln!(
        stdout,
        "\nSimulated in {:.2} s; outputs written in {:.2} s to {}",
        o.sim_time.as_secs_f64(),
        o.write_time.as_secs_f64(),
        o.dir.display()
    );
    for p in &o.files {
        let _ = writeln!(stdout, "  {}", p.display());
    }
    if o.figure_error.is_none() {
        let _ = writeln!(stdout, "Figures ({}):", o.figures_heading);
        for p in &o.figures {
            let _ = writeln!(stdout, "  {}", p.display());
        }
    }
}

/// The output directory: `--out`, else [`output::default_dir`] of the scenario and its
/// overrides (`-pil` after it for a run with the firmware in the loop), so that a run never
/// replaces another's results unasked.
pub fn output_dir(args: &RunArgs, scenario: &Scenario) -> PathBuf {
    if let Some(dir) = &args.out {
        return dir.clone();
    }
    let dir = output::default_dir(&scenario.name, &args.set);
    if args.pil.enabled {
        let mut name = dir.into_os_string();
        name.push("-pil");
        PathBuf::from(name)
    } else {
        dir
    }
}

/// Seconds per hour: a line of progress per simulated hour when stderr is not a terminal.
const PROGRESS_LINE_S: f64 = 3600.0;

/// How a run shows its progress: a bar on a terminal, a line per simulated hour elsewhere
/// (a batch log is never silent), nothing under `--quiet`.
enum Progress {
    Bar(ProgressBar),
    Lines {
        duration_s: f64,
        next_s: f64,
        started: Instant,
    },
    Silent,
}

impl Progress {
    fn new(duration_s: f64) -> Self {
        if quiet() {
            Self::Silent
        } else if std::io::stderr().is_terminal() {
            Self::Bar(progress_bar(duration_s))
        } else {
            Self::Lines {
                duration_s,
                next_s: PROGRESS_LINE_S,
                started: Instant::now(),
            }
        }
    }

    fn at(&mut self, t_s: f64) {
        match self {
            Self::Bar(bar) => bar.set_position(t_s.max(0.0) as u64),
            Self::Lines {
                duration_s,
                next_s,
                started,
            } => {
                if t_s >= *next_s {
                    eprintln!(
                        "simulated {:.0} h of {:.1} h ({:.0} s of wall time)",
                        (t_s / PROGRESS_LINE_S).floor(),
                        *duration_s / PROGRESS_LINE_S,
                        started.elapsed().as_secs_f64()
                    );
                    *next_s = (t_s / PROGRESS_LINE_S).floor() * PROGRESS_LINE_S + PROGRESS_LINE_S;
                }
            }
            Self::Silent => {}
        }
    }

    fn finish(self) {
        if let Self::Bar(bar) = self {
            bar.finish_and_clear();
        }
    }
}

fn progress_bar(duration_s: f64) -> ProgressBar {
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
/// Loads and validates the scenario, prepares the output directory ([`OutputSet::prepare`]:
/// an unusable one is a usage error, found before any work), runs `simulate` with the Table-1
/// probe times, the output set (for files of its own) and a progress callback, then writes
/// every output and commits the set. If `simulate` or a write fails, nothing is committed.
pub fn run_with<E>(
    args: &RunArgs,
    simulate: impl FnOnce(&Scenario, &[f64], &mut OutputSet, &mut dyn FnMut(f64)) -> Result<History, E>,
) -> anyhow::Result<RunOutcome>
where
    E: std::error::Error + Send + Sync + 'static,
{
    let scenario = Scenario::load(&args.scenario, &args.set)?;
    let dir = output_dir(args, &scenario);
    let mut out = OutputSet::prepare("--out", &dir, output_names())?;

    let probes = probe_times_for(&scenario);
    let mut progress = Progress::new(scenario.simulation.duration_s);
    let started = Instant::now();
    let history = simulate(&scenario, &probes, &mut out, &mut |t_s| progress.at(t_s))
        .with_context(|| format!("simulating {}", args.scenario.display()));
    progress.finish();
    let history = history?;
    let sim_time = started.elapsed();

    let started = Instant::now();
    let mut files = Vec::new();
    files.push(out.write("history.csv", |w| {
        if history.elastic.is_empty() {
            output::write_history_csv(w, &history.samples)
        } else {
            output::write_elastic_history_csv(w, &history.samples, &history.elastic)
        }
    })?);
    if !history.telemetry.is_empty() {
        let period_s = scenario.controller.period_s;
        files.push(out.write(TELEMETRY_CSV, |w| {
            crate::obc::write_telemetry_csv(w, &history.telemetry, period_s)
        })?);
    }
    let table = Table1Comparison::new(&history.probes);
    files.push(out.write("table1.csv", |w| table.write_csv(w))?);
    let resolved = toml::to_string_pretty(&scenario).context("serializing the scenario")?;
    files.push(out.write("scenario.toml", |w| {
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
    })?);
    let verdict = Verdict::of(&scenario, &history);
    files.push(out.write(VERDICT_JSON, |w| w.write_all(verdict.to_json().as_bytes()))?);
    let summary = summarize(&scenario, &history);
    let mut report = format!(
        "{}\n{}\n{}",
        verdict.headline(),
        summary.render(),
        table.render()
    );
    if !history.telemetry.is_empty() {
        let c = crate::obc::counts(&history.telemetry);
        report.push_str(&format!(
            "\nTelemetry (telemetry.csv): {} verification reports ({} failures), {} events, {} \
             housekeeping reports kept (one per history row; the unit sends one every period)\n",
            c.verified + c.failed,
            c.failed,
            c.events,
            c.housekeeping
        ));
    }
    files.push(out.write("summary.txt", |w| w.write_all(report.as_bytes()))?);
    // The fault summary (`crate::faults`): printed after the report and written to faults.txt.
    let faults = crate::faults::render_fault_summary(&scenario, &history.faults);
    files.push(out.write("faults.txt", |w| w.write_all(faults.as_bytes()))?);
    let report = format!("{report}\n{faults}");
    let mark = out.mark();
    let (figures, figure_error) = match plots::write_figures(&mut out, &scenario, &history) {
        Ok(paths) => (paths, None),
        Err(e) => {
            out.abandon_since(mark);
            (Vec::new(), Some(e))
        }
    };
    // Files `simulate` staged itself (PIL: pil.txt, firmware.log) are listed too.
    for name in [PIL_TXT, FIRMWARE_LOG] {
        if out.is_staged(name) {
            files.push(dir.join(name));
        }
    }
    out.commit()?;
    let write_time = started.elapsed();

    Ok(RunOutcome {
        dir,
        files,
        figures,
        figure_error,
        figures_heading: plots::figures_heading(&scenario, &history),
        sim_time,
        write_time,
        report,
    })
}
