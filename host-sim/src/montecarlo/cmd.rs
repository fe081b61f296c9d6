//! `tss-sim montecarlo` and `tss-sim merge`.
//!
//! An output directory holds `runs.csv`, `summary.txt`, `summary.json`, `campaign.toml` (what
//! the campaign is: the build that flew it, scenario fingerprint, seed, runs, shard),
//! `scenario.toml` (the scenario as loaded) and the figures; with `--consistency`,
//! `consistency.csv`, `consistency.txt`, `consistency_sums.csv` (the exact sums) and a figure.
//! While the runs fly, `runs.journal.csv` keeps each one as it finishes, so that an interrupted
//! campaign resumes where it stopped ([`super::journal`]).
//!
//! A shard's directory holds the same for its slice; `merge` checks that its inputs are the
//! shards of one campaign, flown by one build, and writes what the whole campaign run at once
//! writes (`runs.csv`, `summary.txt`, `summary.json` and the consistency files byte for byte).
//!
//! Both commands fail with [`BelowPassRate`] (exit code [`EXIT_BELOW_PASS_RATE`]) when fewer
//! runs pass than `--min-pass-rate` asks, after writing every output.

use std::collections::{BTreeMap, BTreeSet};
use std::fs::File;
use std::io::{BufReader, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context;
use serde::{Deserialize, Serialize};

use super::campaign::{Campaign, RunRecord};
use super::consistency::{self, ConsistencyFigure, ConsistencySums};
use super::journal::{journal_every, Identity, Journal, RUNS_JOURNAL};
use super::progress::{Progress, PROGRESS_EVERY_S};
use super::shard::{Shard, ShardSpec};
use super::stats::{render, CampaignInfo, SummaryJson};
use super::{plots, table};
use crate::output::{check_output_dir, OutputSet};
use crate::plots::{png_and_svg, write_png_and_svg};
use crate::scenario::Scenario;
use crate::usage::{quiet, UsageError};

/// The build of this program: the git commit it was built from (`+dirty.` and a digest of the
/// uncommitted changes to its sources, if any), or `unknown` outside a git checkout
/// (`host-sim/build.rs`). Shards of one campaign must share it.
pub const BUILD: &str = match option_env!("TSS_SIM_BUILD") {
    Some(build) => build,
    None => "unknown",
};

/// Largest `--runs`: a million runs (each run's record stays in memory until the campaign's
/// files are written; about 0.05 s of computing each).
pub const MAX_RUNS: u64 = 1_000_000;

/// Largest `--threads`: far above any machine's cores, below any operating system's limit.
pub const MAX_THREADS: usize = 1024;

/// Arguments of `tss-sim montecarlo`.
#[derive(clap::Args, Clone, Debug)]
pub struct MonteCarloArgs {
    /// Scenario file (TOML) with a `[montecarlo]` section, e.g. scenarios/paper-montecarlo.toml.
    pub scenario: PathBuf,
    /// Number of runs of the whole campaign (1 to 1 000 000).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=MAX_RUNS))]
    pub runs: u64,
    /// Seed of the campaign: run i depends on (seed, i) only.
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub seed: u64,
    /// Output directory (created if needed; the files of an earlier campaign in it are
    /// replaced; an interrupted run of the same campaign is resumed from its journal).
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
    /// Fly only shard K of N: the runs i with i mod N = K − 1 (merge the shards' directories
    /// with `tss-sim merge`). `auto`: K and N from a Slurm job array (SLURM_ARRAY_TASK_ID,
    /// _MIN, _MAX, _STEP and _COUNT); `auto/N`: also from a Kubernetes indexed job
    /// (JOB_COMPLETION_INDEX, 0-based, of N).
    #[arg(long, value_name = "K/N|auto|auto/N", value_parser = ShardSpec::parse)]
    pub shard: Option<ShardSpec>,
    /// Worker threads (0: one per core, or SLURM_CPUS_PER_TASK inside a Slurm job; at most
    /// 1024). The results do not depend on it.
    #[arg(long, value_name = "T", default_value_t = 0, value_parser = threads_in_range)]
    pub threads: usize,
    /// Exit with code 3 (after writing every output) if fewer runs pass: a fraction (0.95) or
    /// a percentage (95%).
    #[arg(long, value_name = "RATE", value_parser = pass_rate)]
    pub min_pass_rate: Option<f64>,
    /// Where stderr is not a terminal (a batch job's log), write a progress line every S
    /// seconds (0: after every run).
    #[arg(long, value_name = "S", default_value_t = PROGRESS_EVERY_S, value_parser = seconds)]
    pub progress_every: f64,
    /// Do not draw the figures (e.g. for shards: `merge` draws them).
    #[arg(long)]
    pub no_figures: bool,
    /// Fly the flight estimator beside each run's controller and judge its consistency:
    /// NEES and NIS averaged over the runs against their 95 % χ² bands (`consistency.csv`,
    /// `consistency.txt` and a figure; a shard's are its runs' alone).
    #[arg(long)]
    pub consistency: bool,
    /// Override one scenario field, dotted key and TOML value, e.g.
    /// `--set simulation.duration_s=3600` (repeatable; applied in order).
    #[arg(long = "set", short = 's', value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

/// Parses `--threads`: 0 to [`MAX_THREADS`].
fn threads_in_range(text: &str) -> Result<usize, String> {
    let n: usize = text
        .parse()
        .map_err(|_| format!("`{text}` is not a whole number"))?;
    if n > MAX_THREADS {
        return Err(format!("{n} is not in 0..={MAX_THREADS}"));
    }
    Ok(n)
}

/// Parses `--min-pass-rate`: a fraction in [0, 1], or a percentage in [0, 100] with `%`.
pub fn pass_rate(text: &str) -> Result<f64, String> {
    let (number, scale) = match text.trim().strip_suffix('%') {
        Some(percent) => (percent, 100.0),
        None => (text.trim(), 1.0),
    };
    match number.trim().parse::<f64>() {
        Ok(x) if (0.0..=scale).contains(&x) => Ok(x / scale),
        _ => Err(format!(
            "`{text}` is not a pass rate: a fraction in 0..=1 (0.95) or a percentage (95%)"
        )),
    }
}

/// Parses a non-negative, finite number of seconds.
fn seconds(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err(format!("`{text}` is not a number of seconds (0 or more)")),
    }
}

/// Fewer runs passed than `--min-pass-rate` asks (the outputs were written): exit code 3.
#[derive(Debug, thiserror::Error)]
#[error(
    "{passed} of {runs} runs pass ({:.2} %), below --min-pass-rate {:.2} % (every output is written)",
    100.0 * *passed as f64 / (*runs).max(1) as f64,
    100.0 * min
)]
pub struct BelowPassRate {
    /// Runs that passed.
    pub passed: usize,
    /// Runs judged.
    pub runs: usize,
    /// The rate asked for.
    pub min: f64,
}

/// The exit code of a campaign below its `--min-pass-rate`.
pub const EXIT_BELOW_PASS_RATE: u8 = 3;

/// Is `err` a campaign below its `--min-pass-rate`?
pub fn is_below_pass_rate(err: &anyhow::Error) -> bool {
    err.chain().any(|e| e.is::<BelowPassRate>())
}

fn check_pass_rate(records: &[RunRecord], min: Option<f64>) -> anyhow::Result<()> {
    let passed = records.iter().filter(|r| r.passed()).count();
    match min {
        Some(min) if (passed as f64) < min * records.len() as f64 => Err(BelowPassRate {
            passed,
            runs: records.len(),
            min,
        }
        .into()),
        _ => Ok(()),
    }
}

/// Arguments of `tss-sim merge`.
#[derive(clap::Args, Clone, Debug)]
pub struct MergeArgs {
    /// Output directories of `tss-sim montecarlo --shard K/N`, one per shard (any order).
    #[arg(required = true, value_name = "SHARD_DIR")]
    pub dirs: Vec<PathBuf>,
    /// Output directory of the merged campaign (created if needed; the files of an earlier
    /// campaign in it are replaced).
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
    /// Do not draw the figures.
    #[arg(long)]
    pub no_figures: bool,
    /// Exit with code 3 (after writing every output) if fewer runs pass: a fraction (0.95) or
    /// a percentage (95%).
    #[arg(long, value_name = "RATE", value_parser = pass_rate)]
    pub min_pass_rate: Option<f64>,
}

/// `campaign.toml`: what an output directory holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// The tss-sim version that flew the runs.
    pub tss_sim_version: String,
    /// Its build ([`BUILD`]).
    pub build: String,
    /// The scenario file as given.
    pub scenario_file: String,
    /// The `--set` overrides as given.
    pub overrides: Vec<String>,
    /// The scenario's name.
    pub scenario_name: String,
    /// [`fingerprint`] of the scenario as loaded.
    pub scenario_fingerprint: String,
    /// The campaign's seed (text: TOML integers stop at 2⁶³ − 1).
    pub seed: String,
    /// Runs of the whole campaign.
    pub runs: u64,
    /// The shard, `K/N` (`1/1`: the whole campaign).
    pub shard: String,
    /// Flown with `--consistency`.
    pub consistency: bool,
    /// The shard directories a merged campaign was made from.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub merged_from: Vec<String>,
}

/// FNV-1a (64 bit) of the scenario as TOML: two campaigns with the same fingerprint fly the
/// same scenario (file and overrides resolved).
pub fn fingerprint(sc: &Scenario) -> anyhow::Result<String> {
    let text = toml::to_string(sc).context("serializing the scenario")?;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    Ok(format!("fnv1a64:{h:016x}"))
}

/// The file names of an output directory.
pub const RUNS_CSV: &str = "runs.csv";
/// The summary.
pub const SUMMARY_TXT: &str = "summary.txt";
/// The manifest.
pub const CAMPAIGN_TOML: &str = "campaign.toml";
/// The scenario as loaded.
pub const SCENARIO_TOML: &str = "scenario.toml";
/// The estimator's consistency per instant (`--consistency`).
pub const CONSISTENCY_CSV: &str = "consistency.csv";
/// The estimator's consistency summary (`--consistency`).
pub const CONSISTENCY_TXT: &str = "consistency.txt";
/// The exact NEES/NIS sums (`--consistency`), which `merge` adds up.
pub const CONSISTENCY_SUMS: &str = "consistency_sums.csv";
/// The summary for programs.
pub const SUMMARY_JSON: &str = "summary.json";

/// Every file `montecarlo` and `merge` may write into their output directory.
pub fn output_names() -> Vec<String> {
    let mut names: Vec<String> = [
        RUNS_CSV,
        SUMMARY_TXT,
        SUMMARY_JSON,
        CAMPAIGN_TOML,
        SCENARIO_TOML,
        CONSISTENCY_CSV,
        CONSISTENCY_TXT,
        CONSISTENCY_SUMS,
    ]
    .map(String::from)
    .to_vec();
    names.extend(plots::figure_names());
    names.extend(png_and_svg(consistency::FIGURE_STEM));
    names
}

impl Manifest {
    /// What the journal of this campaign's directory must say it is.
    fn identity(&self) -> Identity {
        Identity {
            build: self.build.clone(),
            fingerprint: self.scenario_fingerprint.clone(),
            seed: self.seed.clone(),
            runs: self.runs,
            shard: self.shard.clone(),
            consistency: self.consistency,
        }
    }
}

/// The threads of `--threads T`: T, or if 0 SLURM_CPUS_PER_TASK inside a Slurm job, else one
/// per core.
fn threads(asked: usize) -> usize {
    let slurm = std::env::var("SLURM_CPUS_PER_TASK")
        .ok()
        .and_then(|v| v.trim().parse::<usize>().ok())
        .filter(|&n| (1..=MAX_THREADS).contains(&n));
    match (asked, slurm) {
        (0, Some(n)) => n,
        (0, None) => rayon::current_num_threads(),
        (t, _) => t,
    }
}

/// `tss-sim montecarlo`.
pub fn montecarlo(args: &MonteCarloArgs) -> anyhow::Result<()> {
    let scenario = Scenario::load(&args.scenario, &args.set)?;
    if scenario.montecarlo.dispersion.is_empty() {
        return Err(UsageError(format!(
            "{}: no [[montecarlo.dispersion]] in the scenario: nothing would vary between runs \
             (each would fly the nominal scenario); add the dispersed fields, as \
             scenarios/paper-montecarlo.toml does",
            args.scenario.display()
        ))
        .into());
    }
    check_output_dir("--out", &args.out)?;
    let (shard, shard_from) = args
        .shard
        .unwrap_or(ShardSpec::Given(Shard::WHOLE))
        .resolve(&|name| std::env::var(name).ok())
        .map_err(UsageError)?;
    if shard.count > args.runs {
        return Err(UsageError(format!(
            "--shard {shard}: more shards than runs (--runs {}): a shard would be empty",
            args.runs
        ))
        .into());
    }
    let mut out = OutputSet::prepare("--out", &args.out, output_names())?;
    let manifest = Manifest {
        tss_sim_version: env!("CARGO_PKG_VERSION").to_string(),
        build: BUILD.to_string(),
        scenario_file: args.scenario.display().to_string(),
        overrides: args.set.clone(),
        scenario_name: scenario.name.clone(),
        scenario_fingerprint: fingerprint(&scenario)?,
        seed: args.seed.to_string(),
        runs: args.runs,
        shard: shard.to_string(),
        consistency: args.consistency,
        merged_from: Vec::new(),
    };
    let campaign = Campaign::new(scenario, args.seed, args.runs)?;
    let indices = shard.runs(args.runs);
    let fields = campaign.fields();
    let (mut journal, resumed) = Journal::open(out.dir(), &manifest.identity(), &fields, &indices)?;
    let mut records = resumed.records;
    let mut sums = resumed.sums;
    let from_journal = records.len();
    let flown_before: BTreeSet<u64> = records.iter().map(|r| r.run).collect();
    let todo: Vec<u64> = indices
        .iter()
        .copied()
        .filter(|i| !flown_before.contains(i))
        .collect();
    let threads = threads(args.threads);
    if !quiet() {
        if let Some(why) = &resumed.replaced {
            eprintln!("{why}");
        }
        let whose = match &shard_from {
            Some(from) => format!("shard {shard} ({from})"),
            None if shard == Shard::WHOLE => "the campaign".to_string(),
            None => format!("shard {shard}"),
        };
        let journaled = if from_journal > 0 {
            format!(
                ", {from_journal} already flown (resumed from {})",
                out.dir().join(RUNS_JOURNAL).display()
            )
        } else {
            String::new()
        };
        eprintln!(
            "{whose}: {} runs{journaled}; flying {} on {threads} thread(s), build {BUILD}",
            indices.len(),
            todo.len()
        );
    }
    let mut progress = Progress::new(
        indices.len() as u64,
        from_journal as u64,
        records.iter().filter(|r| r.passed()).count() as u64,
        Duration::from_secs_f64(args.progress_every),
    );
    let started = Instant::now();
    let mut batch: Vec<RunRecord> = Vec::new();
    let mut last_append = Instant::now();
    campaign.fly_each(&todo, threads, args.consistency, &mut |record, run_sums| {
        if let (Some(sums), Some(run)) = (&mut sums, &run_sums) {
            sums.add(run);
        }
        progress.run_done(record.passed());
        batch.push(record);
        if last_append.elapsed() >= journal_every() {
            journal.append(&batch, sums.as_ref())?;
            records.append(&mut batch);
            last_append = Instant::now();
        }
        Ok(())
    })?;
    journal.append(&batch, sums.as_ref())?;
    records.append(&mut batch);
    progress.finish();
    let elapsed = started.elapsed().as_secs_f64();
    records.sort_by_key(|r| r.run);
    let written = write_outputs(
        &mut out,
        &campaign.scenario,
        &manifest,
        shard,
        &records,
        sums.as_ref(),
        !args.no_figures,
    )?;
    out.commit()?;
    if !quiet() {
        print!("{}{}", written.summary, written.consistency);
        let flown = records.len() - from_journal;
        let resumed = if from_journal > 0 {
            format!(", {from_journal} more from the journal")
        } else {
            String::new()
        };
        // The processor time says what a run costs whatever else shares the cores.
        let cpu = match process_cpu_seconds() {
            Some(cpu) => format!(
                ", {cpu:.1} CPU-s in all ({:.3} CPU-s a run)",
                cpu / flown.max(1) as f64
            ),
            None => String::new(),
        };
        println!(
            "\nFlew {flown} runs in {elapsed:.2} s on {threads} thread(s) ({:.1} ms per run per \
             thread){cpu}{resumed}; outputs in {}",
            1e3 * elapsed * threads as f64 / flown.max(1) as f64,
            args.out.display()
        );
    }
    written.figures?;
    check_pass_rate(&records, args.min_pass_rate)
}

/// The processor time of this process so far, user and system, in seconds: fields 14 and 15
/// of `/proc/self/stat` (Linux; in clock ticks of `USER_HZ`, 100 on every Linux platform);
/// `None` elsewhere.
pub fn process_cpu_seconds() -> Option<f64> {
    const USER_HZ: f64 = 100.0;
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The program's name, field 2, is in parentheses and may hold spaces: count after it.
    let after_name = &stat[stat.rfind(')')? + 1..];
    let mut fields = after_name.split_whitespace().skip(11);
    let user: u64 = fields.next()?.parse().ok()?;
    let system: u64 = fields.next()?.parse().ok()?;
    Some((user + system) as f64 / USER_HZ)
}

/// What [`write_outputs`] wrote.
struct Written {
    /// The summary's text.
    summary: String,
    /// The consistency summary's text (empty without `--consistency`).
    consistency: String,
    /// Whether the figures were drawn (every other output is written regardless).
    figures: anyhow::Result<()>,
}

/// Writes every output of `records` (sorted by run index) and, with `--consistency`, of
/// `sums` into `out`; the figures if `draw_figures`.
fn write_outputs(
    out: &mut OutputSet,
    sc: &Scenario,
    manifest: &Manifest,
    shard: Shard,
    records: &[RunRecord],
    sums: Option<&ConsistencySums>,
    draw_figures: bool,
) -> anyhow::Result<Written> {
    let fields: Vec<&str> = sc
        .montecarlo
        .dispersion
        .iter()
        .map(|d| d.field.as_str())
        .collect();
    out.write(RUNS_CSV, |w| {
        table::write_runs(w, &fields, records).map_err(std::io::Error::other)
    })?;
    let seed: u64 = manifest.seed.parse().context("the manifest's seed")?;
    let info = CampaignInfo {
        scenario: sc,
        fingerprint: &manifest.scenario_fingerprint,
        seed,
        runs: manifest.runs,
        shard,
        build: &manifest.build,
    };
    let summary = render(&info, records);
    out.write(SUMMARY_TXT, |w| w.write_all(summary.as_bytes()))?;
    let json = SummaryJson::of(&info, records, sums.map(ConsistencySums::summary))
        .render()
        .context("serializing summary.json")?;
    out.write(SUMMARY_JSON, |w| w.write_all(json.as_bytes()))?;
    let text = toml::to_string_pretty(manifest).context("serializing the manifest")?;
    out.write(CAMPAIGN_TOML, |w| {
        writeln!(
            w,
            "# A tss-sim Monte Carlo campaign (tss-sim montecarlo / merge)"
        )?;
        w.write_all(text.as_bytes())
    })?;
    let resolved = toml::to_string_pretty(sc).context("serializing the scenario")?;
    out.write(SCENARIO_TOML, |w| {
        writeln!(
            w,
            "# The scenario as loaded: {} with {} override(s)",
            manifest.scenario_file,
            manifest.overrides.len()
        )?;
        w.write_all(resolved.as_bytes())
    })?;
    let consistency = match sums {
        Some(sums) => {
            out.write(CONSISTENCY_CSV, |w| sums.write_csv(w))?;
            out.write(CONSISTENCY_SUMS, |w| sums.write_sums(w))?;
            let text = sums.summary().render(records.len());
            out.write(CONSISTENCY_TXT, |w| w.write_all(text.as_bytes()))?;
            text
        }
        None => String::new(),
    };
    let figures = if draw_figures {
        let mark = out.mark();
        draw(out, sc, &fields, records, sums).map_err(|e| {
            out.abandon_since(mark);
            e.context("the figures were not drawn (every other output was written)")
        })
    } else {
        Ok(())
    };
    Ok(Written {
        summary,
        consistency,
        figures,
    })
}

/// Draws the campaign's figures, and the consistency figure with `sums`.
fn draw(
    out: &mut OutputSet,
    sc: &Scenario,
    fields: &[&str],
    records: &[RunRecord],
    sums: Option<&ConsistencySums>,
) -> anyhow::Result<()> {
    plots::write_figures(out, sc, fields, records)?;
    if let Some(sums) = sums {
        crate::plots::check_font()?;
        let figure = ConsistencyFigure {
            sums,
            title: format!(
                "Estimator consistency over {} runs of `{}` (dashed: 95 % bands)",
                records.len(),
                sc.name
            ),
        };
        write_png_and_svg(out, consistency::FIGURE_STEM, (1200, 1200), &figure)?;
    }
    Ok(())
}

/// One shard directory, read and checked.
struct ShardDir {
    dir: PathBuf,
    manifest: Manifest,
    shard: Shard,
    scenario: Scenario,
    records: Vec<RunRecord>,
    sums: Option<ConsistencySums>,
}

fn usage(msg: String) -> anyhow::Error {
    UsageError(msg).into()
}

fn read_shard(dir: &Path) -> anyhow::Result<ShardDir> {
    let d = dir.display();
    let path = dir.join(CAMPAIGN_TOML);
    if !path.exists() && dir.join(RUNS_JOURNAL).exists() {
        return Err(usage(format!(
            "{d}: the shard has not finished (it has a {RUNS_JOURNAL} but no results yet): run \
             its command again to resume it, then merge"
        )));
    }
    let text = crate::scenario::read_bounded(&path, crate::scenario::MAX_SCENARIO_BYTES)
        .map_err(|e| {
            usage(format!(
                "{d}: not the output of `tss-sim montecarlo` (cannot read {}: {e})",
                path.display()
            ))
        })?
        .ok_or_else(|| {
            usage(format!(
                "{}: larger than {} bytes: not a campaign manifest",
                path.display(),
                crate::scenario::MAX_SCENARIO_BYTES
            ))
        })?;
    let manifest: Manifest = toml::from_str(&text).map_err(|e| {
        usage(format!(
            "{}: not a campaign manifest: {}",
            path.display(),
            e.message()
        ))
    })?;
    let shard = Shard::parse(&manifest.shard).map_err(|e| {
        usage(format!(
            "{}: shard = {:?}: {e}",
            path.display(),
            manifest.shard
        ))
    })?;
    let scenario =
        Scenario::load(dir.join(SCENARIO_TOML), &[]).map_err(|e| usage(format!("{d}: {e}")))?;
    if fingerprint(&scenario)? != manifest.scenario_fingerprint {
        return Err(usage(format!(
            "{d}: {SCENARIO_TOML} does not match the fingerprint {} in {CAMPAIGN_TOML} (edited?)",
            manifest.scenario_fingerprint
        )));
    }
    let fields: Vec<&str> = scenario
        .montecarlo
        .dispersion
        .iter()
        .map(|d| d.field.as_str())
        .collect();
    let path = dir.join(RUNS_CSV);
    let file =
        File::open(&path).map_err(|e| usage(format!("{}: cannot read: {e}", path.display())))?;
    let records = table::read_runs(BufReader::new(file), &fields)
        .map_err(|e| usage(format!("{}: {e}", path.display())))?;
    let expected = shard.runs(manifest.runs);
    let got: Vec<u64> = records.iter().map(|r| r.run).collect();
    if got != expected {
        return Err(usage(format!(
            "{}: holds {} runs, not the {} runs of shard {} of a {}-run campaign (incomplete or \
             edited?)",
            path.display(),
            got.len(),
            expected.len(),
            shard,
            manifest.runs
        )));
    }
    let sums = if manifest.consistency {
        let path = dir.join(CONSISTENCY_SUMS);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| usage(format!("{}: cannot read: {e}", path.display())))?;
        let sums = ConsistencySums::read_sums(&text)
            .map_err(|e| usage(format!("{}: {e}", path.display())))?;
        Some(sums)
    } else {
        None
    };
    Ok(ShardDir {
        dir: dir.to_path_buf(),
        manifest,
        shard,
        scenario,
        records,
        sums,
    })
}

/// `tss-sim merge`.
pub fn merge(args: &MergeArgs) -> anyhow::Result<()> {
    let shards = args
        .dirs
        .iter()
        .map(|d| read_shard(d))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let first = &shards[0];
    let f = &first.manifest;
    for s in &shards[1..] {
        let m = &s.manifest;
        let differ = |what: &str, a: &str, b: &str| {
            usage(format!(
                "{} and {} are not shards of one campaign: {what} {a} ≠ {b}",
                first.dir.display(),
                s.dir.display()
            ))
        };
        if m.build != f.build {
            return Err(differ(
                "build (rebuild once and fly every shard with that build)",
                &f.build,
                &m.build,
            ));
        }
        if m.scenario_fingerprint != f.scenario_fingerprint {
            return Err(differ(
                "scenario (file and overrides)",
                &format!("`{}` {}", f.scenario_name, f.scenario_fingerprint),
                &format!("`{}` {}", m.scenario_name, m.scenario_fingerprint),
            ));
        }
        if m.seed != f.seed {
            return Err(differ("seed", &f.seed, &m.seed));
        }
        if m.runs != f.runs {
            return Err(differ("runs", &f.runs.to_string(), &m.runs.to_string()));
        }
        if s.shard.count != first.shard.count {
            return Err(differ(
                "shard count",
                &first.shard.to_string(),
                &s.shard.to_string(),
            ));
        }
        if m.tss_sim_version != f.tss_sim_version {
            return Err(differ(
                "tss-sim version",
                &f.tss_sim_version,
                &m.tss_sim_version,
            ));
        }
        if m.consistency != f.consistency {
            return Err(differ(
                "--consistency",
                &f.consistency.to_string(),
                &m.consistency.to_string(),
            ));
        }
    }
    let mut by_index: BTreeMap<u64, &ShardDir> = BTreeMap::new();
    for s in &shards {
        if let Some(other) = by_index.insert(s.shard.index, s) {
            return Err(usage(format!(
                "{} and {} are both shard {}",
                other.dir.display(),
                s.dir.display(),
                s.shard
            )));
        }
    }
    let count = first.shard.count;
    let missing: Vec<String> = (1..=count)
        .filter(|k| !by_index.contains_key(k))
        .map(|k| format!("{k}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(usage(format!(
            "missing shard(s) {} of the {}-run campaign (seed {})",
            missing.join(", "),
            f.runs,
            f.seed
        )));
    }
    let out_abs = std::path::absolute(&args.out).unwrap_or_else(|_| args.out.clone());
    for s in &shards {
        let dir_abs = std::path::absolute(&s.dir).unwrap_or_else(|_| s.dir.clone());
        if dir_abs == out_abs {
            return Err(usage(format!(
                "--out {}: is one of the shard directories; merge into another directory",
                args.out.display()
            )));
        }
    }
    let mut out = OutputSet::prepare("--out", &args.out, output_names())?;
    let mut records: Vec<RunRecord> = shards
        .iter()
        .flat_map(|s| s.records.iter().cloned())
        .collect();
    records.sort_by_key(|r| r.run);
    let sums = first.sums.as_ref().map(|_| {
        let mut total = ConsistencySums::default();
        for s in shards.iter().filter_map(|s| s.sums.as_ref()) {
            total.merge(s);
        }
        total
    });
    let manifest = Manifest {
        shard: Shard::WHOLE.to_string(),
        merged_from: args.dirs.iter().map(|d| d.display().to_string()).collect(),
        ..f.clone()
    };
    let written = write_outputs(
        &mut out,
        &first.scenario,
        &manifest,
        Shard::WHOLE,
        &records,
        sums.as_ref(),
        !args.no_figures,
    )?;
    out.commit()?;
    if !quiet() {
        print!("{}{}", written.summary, written.consistency);
        println!(
            "\nMerged {count} shards ({} runs) into {}",
            records.len(),
            args.out.display()
        );
    }
    written.figures?;
    check_pass_rate(&records, args.min_pass_rate)
}
