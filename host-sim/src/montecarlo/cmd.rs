//! `tss-sim montecarlo` and `tss-sim merge`.
//!
//! An output directory holds `runs.csv`, `summary.txt`, `campaign.toml` (what the campaign is:
//! scenario fingerprint, seed, runs, shard), `scenario.toml` (the scenario as loaded) and the
//! figures. A shard's directory holds the same for its slice; `merge` checks that its inputs
//! are the shards of one campaign and writes what the whole campaign run at once writes
//! (`runs.csv` and `summary.txt` byte for byte).

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufReader, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use serde::{Deserialize, Serialize};

use super::campaign::{Campaign, RunRecord};
use super::consistency::{self, ConsistencyFigure, ConsistencySums};
use super::stats::{render, CampaignInfo, Shard};
use super::{plots, table};
use crate::output::{check_output_dir, OutputSet};
use crate::plots::{png_and_svg, write_png_and_svg};
use crate::scenario::Scenario;
use crate::usage::{quiet, UsageError};

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
    /// replaced).
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
    /// Fly only shard K of N: the runs i with i mod N = K − 1 (merge the shards' directories
    /// with `tss-sim merge`).
    #[arg(long, value_name = "K/N", value_parser = Shard::parse)]
    pub shard: Option<Shard>,
    /// Worker threads (0: one per core; at most 1024). The results do not depend on it.
    #[arg(long, value_name = "T", default_value_t = 0, value_parser = threads_in_range)]
    pub threads: usize,
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
}

/// `campaign.toml`: what an output directory holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// The tss-sim version that flew the runs.
    pub tss_sim_version: String,
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

/// Every file `montecarlo` and `merge` may write into their output directory.
pub fn output_names() -> Vec<String> {
    let mut names: Vec<String> = [
        RUNS_CSV,
        SUMMARY_TXT,
        CAMPAIGN_TOML,
        SCENARIO_TOML,
        CONSISTENCY_CSV,
        CONSISTENCY_TXT,
    ]
    .map(String::from)
    .to_vec();
    names.extend(plots::figure_names());
    names.extend(png_and_svg(consistency::FIGURE_STEM));
    names
}

fn progress_bar(runs: u64) -> ProgressBar {
    if quiet() || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(runs);
    if let Ok(style) =
        ProgressStyle::with_template("{spinner} runs [{bar:30}] {pos}/{len}, {per_sec}, eta {eta}")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
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
    let shard = args.shard.unwrap_or(Shard::WHOLE);
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
        scenario_file: args.scenario.display().to_string(),
        overrides: args.set.clone(),
        scenario_name: scenario.name.clone(),
        scenario_fingerprint: fingerprint(&scenario)?,
        seed: args.seed.to_string(),
        runs: args.runs,
        shard: shard.to_string(),
        merged_from: Vec::new(),
    };
    let campaign = Campaign::new(scenario, args.seed, args.runs)?;
    let indices = shard.runs(args.runs);
    let bar = progress_bar(indices.len() as u64);
    let started = Instant::now();
    let threads = if args.threads == 0 {
        rayon::current_num_threads()
    } else {
        args.threads
    };
    let flown = campaign.run_all_watched(&indices, threads, args.consistency, &|| bar.inc(1));
    bar.finish_and_clear();
    let (records, sums) = flown?;
    let elapsed = started.elapsed().as_secs_f64();
    let (report, figures) = write_outputs(
        &mut out,
        &campaign.scenario,
        &manifest,
        shard,
        &records,
        !args.no_figures,
    )?;
    let consistency = match &sums {
        Some(sums) => write_consistency(
            &mut out,
            &campaign.scenario,
            sums,
            records.len(),
            !args.no_figures,
        )?,
        None => String::new(),
    };
    out.commit()?;
    if !quiet() {
        print!("{report}{consistency}");
        println!(
            "\nFlew {} runs in {elapsed:.2} s on {threads} thread(s) ({:.1} ms per run per \
             thread); outputs in {}",
            records.len(),
            1e3 * elapsed * threads as f64 / records.len().max(1) as f64,
            args.out.display()
        );
    }
    figures
}

/// Writes every output of `records` (sorted by run index) into `out`; returns the summary text
/// and the outcome of drawing the figures, if `draw_figures` (the other files are written
/// regardless).
fn write_outputs(
    out: &mut OutputSet,
    sc: &Scenario,
    manifest: &Manifest,
    shard: Shard,
    records: &[RunRecord],
    draw_figures: bool,
) -> anyhow::Result<(String, anyhow::Result<()>)> {
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
    };
    let summary = render(&info, records);
    out.write(SUMMARY_TXT, |w| w.write_all(summary.as_bytes()))?;
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
    let mark = out.mark();
    let figures = if draw_figures {
        plots::write_figures(out, sc, &fields, records)
            .map(|_| ())
            .map_err(|e| {
                out.abandon_since(mark);
                e.context("the figures were not drawn (every other output was written)")
            })
    } else {
        Ok(())
    };
    Ok((summary, figures))
}

/// Writes the estimator's consistency (`consistency.csv`, `consistency.txt` and, if
/// `draw_figure`, its figure) into `out`; returns the summary text.
fn write_consistency(
    out: &mut OutputSet,
    sc: &Scenario,
    sums: &ConsistencySums,
    runs: usize,
    draw_figure: bool,
) -> anyhow::Result<String> {
    out.write(CONSISTENCY_CSV, |w| sums.write_csv(w))?;
    let text = sums.summary().render(runs);
    out.write(CONSISTENCY_TXT, |w| w.write_all(text.as_bytes()))?;
    if draw_figure {
        crate::plots::check_font()?;
        let figure = ConsistencyFigure {
            sums,
            title: format!(
                "Estimator consistency over {runs} runs of `{}` (dashed: 95 % bands)",
                sc.name
            ),
        };
        write_png_and_svg(out, consistency::FIGURE_STEM, (1200, 1200), &figure)?;
    }
    Ok(text)
}

/// One shard directory, read and checked.
struct ShardDir {
    dir: PathBuf,
    manifest: Manifest,
    shard: Shard,
    scenario: Scenario,
    records: Vec<RunRecord>,
}

fn usage(msg: String) -> anyhow::Error {
    UsageError(msg).into()
}

fn read_shard(dir: &Path) -> anyhow::Result<ShardDir> {
    let d = dir.display();
    let path = dir.join(CAMPAIGN_TOML);
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
    Ok(ShardDir {
        dir: dir.to_path_buf(),
        manifest,
        shard,
        scenario,
        records,
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
    let manifest = Manifest {
        shard: Shard::WHOLE.to_string(),
        merged_from: args.dirs.iter().map(|d| d.display().to_string()).collect(),
        ..f.clone()
    };
    let (report, figures) = write_outputs(
        &mut out,
        &first.scenario,
        &manifest,
        Shard::WHOLE,
        &records,
        !args.no_figures,
    )?;
    out.commit()?;
    if !quiet() {
        print!("{report}");
        println!(
            "\nMerged {count} shards ({} runs) into {}",
            records.len(),
            args.out.display()
        );
    }
    figures
}
