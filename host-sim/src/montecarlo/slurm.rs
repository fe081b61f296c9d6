//! `tss-sim campaign slurm`: a Monte Carlo campaign as a Slurm job array of shards and a merge
//! job that runs once every shard has succeeded.
//!
//! It writes into the campaign directory DIR:
//!
//! - `scenario.toml`, the scenario as loaded (file and `--set`), and `bin/tss-sim`, a copy of
//!   this program: the jobs fly these, so editing the scenario or rebuilding while they wait in
//!   the queue changes nothing;
//! - `shards.sbatch`, the job array `--array=1-K`: task k runs
//!   `montecarlo --shard auto/K --out DIR/shard-k` (with `--requeue`, a task requeued after a
//!   node failure or a preemption resumes from its journal; its log is appended to);
//! - `merge.sbatch`, `merge DIR/shard-1 … DIR/shard-K --out DIR/merged` (and
//!   `--min-pass-rate`: the shards do not judge the pass rate, the whole campaign does);
//! - `submit.sh`, which submits the array, then the merge with
//!   `--dependency=afterok:ARRAY --kill-on-invalid-dep=yes` (cancelled if a shard fails), and
//!   writes the two job ids to `jobs.env`. After a failure, running it again is cheap: the
//!   shards that had finished fly nothing (their journals are complete), the others resume.
//!
//! `--submit` runs `submit.sh`. Logs go to `DIR/logs/`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::Context as _;

use super::cmd::{fingerprint, pass_rate, MAX_RUNS};
use crate::output::check_output_dir;
use crate::scenario::Scenario;
use crate::usage::{quiet, UsageError};

/// Arguments of `tss-sim campaign slurm`.
#[derive(clap::Args, Clone, Debug)]
pub struct SlurmArgs {
    /// Scenario file (TOML) with a `[montecarlo]` section, e.g. scenarios/paper-montecarlo.toml.
    pub scenario: PathBuf,
    /// Number of runs of the whole campaign (1 to 1 000 000).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=MAX_RUNS))]
    pub runs: u64,
    /// Number of shards: the job array's tasks (at most the runs; Slurm's default MaxArraySize
    /// allows 1000).
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u64).range(1..=MAX_RUNS))]
    pub shards: u64,
    /// Seed of the campaign: run i depends on (seed, i) only.
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub seed: u64,
    /// The campaign directory (created if needed): job scripts, shards, logs, merged result.
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
    /// Override one scenario field, dotted key and TOML value (repeatable; applied in order).
    #[arg(long = "set", short = 's', value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Fly the flight estimator beside each run and judge its consistency (NEES/NIS).
    #[arg(long)]
    pub consistency: bool,
    /// CPUs of each shard (`--cpus-per-task`), and its threads.
    #[arg(long, value_name = "T", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub cpus_per_task: u32,
    /// Time limit of each job (`--time`, e.g. 2:00:00).
    #[arg(long, value_name = "LIMIT")]
    pub time: Option<String>,
    /// Partition of the jobs (`--partition`).
    #[arg(long, value_name = "NAME")]
    pub partition: Option<String>,
    /// Another sbatch option for both jobs, e.g. `--sbatch=--account=tss` (repeatable).
    #[arg(long = "sbatch", value_name = "OPTION", allow_hyphen_values = true)]
    pub sbatch: Vec<String>,
    /// At most M shards running at once (`--array=1-K%M`).
    #[arg(long, value_name = "M", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_running: Option<u64>,
    /// The merge exits with code 3 (its job fails) if fewer runs pass: a fraction (0.95) or a
    /// percentage (95%).
    #[arg(long, value_name = "RATE", value_parser = pass_rate)]
    pub min_pass_rate: Option<f64>,
    /// The merge draws no figures.
    #[arg(long)]
    pub no_figures: bool,
    /// Submit the jobs (run DIR/submit.sh) once written.
    #[arg(long)]
    pub submit: bool,
}

/// A path or option the job scripts carry unquoted: letters, digits and `/._-+,:=@~`.
fn plain(what: &str, text: &str) -> Result<(), UsageError> {
    match text
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || "/._-+,:=@~".contains(*c)))
    {
        Some(c) => Err(UsageError(format!(
            "{what} {text:?}: contains {c:?}, which the job scripts cannot carry; use letters, \
             digits and / . _ - + , : = @ ~"
        ))),
        None if text.is_empty() => Err(UsageError(format!("{what}: empty"))),
        None => Ok(()),
    }
}

/// `tss-sim campaign slurm`.
pub fn campaign_slurm(args: &SlurmArgs) -> anyhow::Result<()> {
    let scenario = Scenario::load(&args.scenario, &args.set)?;
    if scenario.montecarlo.dispersion.is_empty() {
        return Err(UsageError(format!(
            "{}: no [[montecarlo.dispersion]] in the scenario: nothing would vary between runs",
            args.scenario.display()
        ))
        .into());
    }
    if args.shards > args.runs {
        return Err(UsageError(format!(
            "--shards {}: more shards than runs (--runs {}): a shard would be empty",
            args.shards, args.runs
        ))
        .into());
    }
    for (what, value) in [("--time", &args.time), ("--partition", &args.partition)] {
        if let Some(v) = value {
            plain(what, v)?;
        }
    }
    for option in &args.sbatch {
        if !option.starts_with('-') {
            return Err(UsageError(format!(
                "--sbatch {option:?}: not an sbatch option (they start with -)"
            ))
            .into());
        }
        plain("--sbatch", option)?;
    }
    check_output_dir("--out", &args.out)?;
    let absolute = std::path::absolute(&args.out)
        .map_err(|e| UsageError(format!("--out {}: {e}", args.out.display())))?;
    plain("--out", &absolute.display().to_string())?;
    std::fs::create_dir_all(args.out.join("logs"))
        .map_err(|e| UsageError(format!("--out {}: cannot create: {e}", args.out.display())))?;
    let dir = std::fs::canonicalize(&args.out)
        .with_context(|| format!("resolving {}", args.out.display()))?;
    let dir_text = dir.display().to_string();
    // Its real path (through symbolic links) may hold what the path given did not.
    plain("--out", &dir_text)?;

    // The scenario as loaded, which the shards fly; read back, it is the same campaign.
    let resolved = toml::to_string_pretty(&scenario).context("serializing the scenario")?;
    let scenario_path = dir.join("scenario.toml");
    write_text(
        &scenario_path,
        &format!(
            "# The scenario of the campaign, as loaded: {} with {} override(s)\n{resolved}",
            args.scenario.display(),
            args.set.len()
        ),
    )?;
    let print = fingerprint(&scenario)?;
    let reread = Scenario::load(&scenario_path, &[])?;
    anyhow::ensure!(
        fingerprint(&reread)? == print,
        "{} does not read back as the scenario it was written from",
        scenario_path.display()
    );
    copy_program(&dir.join("bin"))?;

    let campaign = Plan {
        dir: &dir_text,
        name: job_name(&scenario.name),
        args,
        fingerprint: &print,
    };
    write_script(&dir.join("shards.sbatch"), &campaign.shards_script())?;
    write_script(&dir.join("merge.sbatch"), &campaign.merge_script())?;
    write_script(&dir.join("submit.sh"), &campaign.submit_script())?;
    if !quiet() {
        println!(
            "Wrote the campaign `{}` ({} runs, seed {}, {} shards) to {dir_text}:\n  \
             shards.sbatch  the job array: task k flies shard k/{} into shard-k/\n  \
             merge.sbatch   merges the shards into merged/ once every one has succeeded\n  \
             submit.sh      submits both (sbatch; sbatch --dependency=afterok:…)",
            scenario.name, args.runs, args.seed, args.shards, args.shards
        );
    }
    if args.submit {
        let status = Command::new("bash")
            .arg(dir.join("submit.sh"))
            .status()
            .context("running bash")?;
        anyhow::ensure!(
            status.success(),
            "{}/submit.sh failed ({status}): is sbatch on PATH, on a Slurm login node?",
            dir_text
        );
    } else if !quiet() {
        println!("Submit with: {dir_text}/submit.sh");
    }
    Ok(())
}

/// A Slurm job name from the scenario's name: `tss-` and its letters, digits, `-` and `_`.
fn job_name(scenario: &str) -> String {
    let name: String = scenario
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .take(40)
        .collect();
    format!("tss-{name}")
}

/// What the scripts say.
struct Plan<'a> {
    dir: &'a str,
    name: String,
    args: &'a SlurmArgs,
    fingerprint: &'a str,
}

impl Plan<'_> {
    /// The `#SBATCH` lines both jobs share.
    fn common_options(&self, o: &mut String) {
        if let Some(t) = &self.args.time {
            let _ = writeln!(o, "#SBATCH --time={t}");
        }
        if let Some(p) = &self.args.partition {
            let _ = writeln!(o, "#SBATCH --partition={p}");
        }
        for option in &self.args.sbatch {
            let _ = writeln!(o, "#SBATCH {option}");
        }
    }

    fn shards_script(&self) -> String {
        let a = self.args;
        let (dir, k) = (self.dir, a.shards);
        let throttle = a.max_running.map(|m| format!("%{m}")).unwrap_or_default();
        let mut o = String::new();
        let _ = writeln!(
            o,
            "#!/bin/bash\n\
             # The shards of the tss-sim campaign on `{name}` (scenario {print}): {runs} runs,\n\
             # seed {seed}, {k} shards. Array task k flies shard k/{k} into {dir}/shard-k, journaling\n\
             # each run as it finishes: requeued, or submitted again (submit.sh), it resumes.\n\
             # Written by `tss-sim campaign slurm`; submit with submit.sh.",
            name = self.name.trim_start_matches("tss-"),
            print = self.fingerprint,
            runs = a.runs,
            seed = a.seed,
        );
        let _ = writeln!(o, "#SBATCH --job-name={}", self.name);
        let _ = writeln!(o, "#SBATCH --array=1-{k}{throttle}");
        let _ = writeln!(o, "#SBATCH --ntasks=1");
        let _ = writeln!(o, "#SBATCH --cpus-per-task={}", a.cpus_per_task);
        let _ = writeln!(o, "#SBATCH --output={dir}/logs/shard-%a.log");
        let _ = writeln!(o, "#SBATCH --open-mode=append");
        let _ = writeln!(o, "#SBATCH --requeue");
        self.common_options(&mut o);
        let consistency = if a.consistency { " --consistency" } else { "" };
        let _ = writeln!(
            o,
            "set -euo pipefail\n\
             exec {dir}/bin/tss-sim montecarlo {dir}/scenario.toml --runs {runs} --seed {seed} \\\n  \
             --shard auto/{k} --threads {t} --no-figures --progress-every 30{consistency} \\\n  \
             --out {dir}/shard-\"$SLURM_ARRAY_TASK_ID\"",
            runs = a.runs,
            seed = a.seed,
            t = a.cpus_per_task,
        );
        o
    }

    fn merge_script(&self) -> String {
        let a = self.args;
        let (dir, k) = (self.dir, a.shards);
        let mut o = String::new();
        let _ = writeln!(
            o,
            "#!/bin/bash\n\
             # The merge of the tss-sim campaign's {k} shards into {dir}/merged (the whole\n\
             # campaign's files, byte for byte those of one unsharded run). submit.sh queues it\n\
             # after the array (afterok); by hand: sbatch merge.sbatch.\n\
             # Written by `tss-sim campaign slurm`."
        );
        let _ = writeln!(o, "#SBATCH --job-name={}-merge", self.name);
        let _ = writeln!(o, "#SBATCH --ntasks=1");
        let _ = writeln!(o, "#SBATCH --cpus-per-task=1");
        let _ = writeln!(o, "#SBATCH --output={dir}/logs/merge.log");
        let _ = writeln!(o, "#SBATCH --open-mode=append");
        self.common_options(&mut o);
        let mut options = String::new();
        if let Some(rate) = a.min_pass_rate {
            let _ = write!(options, " --min-pass-rate {rate}");
        }
        if a.no_figures {
            options += " --no-figures";
        }
        let _ = writeln!(
            o,
            "set -euo pipefail\n\
             shards=()\n\
             for k in $(seq 1 {k}); do shards+=({dir}/shard-\"$k\"); done\n\
             exec {dir}/bin/tss-sim merge \"${{shards[@]}}\" --out {dir}/merged{options}"
        );
        o
    }

    fn submit_script(&self) -> String {
        let (dir, k) = (self.dir, self.args.shards);
        format!(
            "#!/bin/bash\n\
             # Submits the tss-sim campaign: the shards as a job array, then the merge, which\n\
             # Slurm starts once every shard has succeeded (afterok) and cancels if one fails.\n\
             # Safe to run again after a failure: finished shards fly nothing, the others resume.\n\
             # The job ids go to {dir}/jobs.env. Written by `tss-sim campaign slurm`.\n\
             set -euo pipefail\n\
             cd {dir}\n\
             array=$(sbatch --parsable shards.sbatch)\n\
             array=${{array%%;*}}\n\
             merge=$(sbatch --parsable --dependency=afterok:\"$array\" --kill-on-invalid-dep=yes merge.sbatch)\n\
             merge=${{merge%%;*}}\n\
             printf 'ARRAY_JOB=%s\\nMERGE_JOB=%s\\n' \"$array\" \"$merge\" > jobs.env\n\
             echo \"array job $array: {k} shards into {dir}/shard-1 … shard-{k} (logs: {dir}/logs/)\"\n\
             echo \"merge job $merge: once every shard has succeeded (afterok:$array), into {dir}/merged\"\n"
        )
    }
}

/// Writes `text` to `path` through a temporary file renamed into place.
fn write_text(path: &Path, text: &str) -> anyhow::Result<()> {
    let tmp = path.with_extension("partial");
    std::fs::write(&tmp, text).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("renaming {}", tmp.display()))
}

/// Writes an executable script.
fn write_script(path: &Path, text: &str) -> anyhow::Result<()> {
    write_text(path, text)?;
    set_executable(path)
}

#[cfg(unix)]
fn set_executable(path: &Path) -> anyhow::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755))
        .with_context(|| format!("making {} executable", path.display()))
}

#[cfg(not(unix))]
fn set_executable(_: &Path) -> anyhow::Result<()> {
    Ok(())
}

/// Copies this program to `bin/tss-sim` (through a temporary file: a shard may be running the
/// copy written before).
fn copy_program(bin: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(bin).with_context(|| format!("creating {}", bin.display()))?;
    let me = std::env::current_exe().context("finding this program's file")?;
    let to = bin.join("tss-sim");
    let tmp = bin.join("tss-sim.partial");
    std::fs::copy(&me, &tmp)
        .with_context(|| format!("copying {} to {}", me.display(), tmp.display()))?;
    std::fs::rename(&tmp, &to).with_context(|| format!("renaming {}", tmp.display()))?;
    set_executable(&to)
}
