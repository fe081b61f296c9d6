//! Campaigns on a batch system: shards that read their index from the environment and merge
//! exactly, a killed shard that resumes, merges refused across builds or before the end, the
//! pass-rate exit code, the Slurm job scripts and a directory another campaign is flying in.

use super::*;

/// The campaign of the batch-system tests: the first hour of the paper campaign (long enough
/// for the estimator's consistency from 30 min on), the criteria on what happens later off.
fn hour() -> Vec<&'static str> {
    let mut args = SHORT.to_vec();
    args.extend(["--set", "simulation.duration_s=3600"]);
    args
}

/// `a` then `b`.
fn with<'a>(a: &[&'a str], b: &[&'a str]) -> Vec<&'a str> {
    [a, b].concat()
}

/// The files a campaign flown whole and the merge of its shards must agree on, byte for byte.
const SAME_BYTES: [&str; 3] = ["runs.csv", "summary.txt", "summary.json"];
/// And with `--consistency`.
const SAME_BYTES_CONSISTENCY: [&str; 3] =
    ["consistency.csv", "consistency.txt", "consistency_sums.csv"];

fn assert_same_files(a: &Path, b: &Path, names: &[&str]) {
    for name in names {
        assert_eq!(
            read(&a.join(name)),
            read(&b.join(name)),
            "{name}: {} and {} differ",
            a.display(),
            b.display()
        );
    }
}

fn merge(dirs: &[PathBuf], out: &Path, extra: &[&str]) -> Output {
    let mut args: Vec<&str> = vec!["merge"];
    args.extend(dirs.iter().map(|d| d.to_str().unwrap()));
    args.extend(["--out", out.to_str().unwrap(), "--no-figures"]);
    args.extend_from_slice(extra);
    tss_sim(&args)
}

/// `--shard auto` takes the shard from a Slurm array task (whatever the array's first id: here
/// `--array=0-3`) or from a Kubernetes completion index with `auto/N`; the shards merge into
/// the campaign flown whole, the exact NEES/NIS sums included (consistency.csv, .txt and the
/// sums themselves byte for byte); without a batch system, `auto` is a clear error.
#[test]
fn shard_auto_reads_the_batch_system_and_the_shards_merge_exactly_with_consistency() {
    let tmp = tempfile::tempdir().unwrap();
    let mut extra = hour();
    extra.push("--consistency");
    let whole = tmp.path().join("whole");
    let o = montecarlo_env(
        &whole,
        "10",
        "3",
        &with(&extra, &["--progress-every", "0"]),
        &[],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // On a pipe, a progress line after every run (--progress-every 0), the last at 10/10.
    let progress: Vec<String> = stderr(&o)
        .lines()
        .filter(|l| l.starts_with("progress: "))
        .map(String::from)
        .collect();
    assert_eq!(progress.len(), 10, "{}", stderr(&o));
    assert!(
        progress[9].starts_with("progress: 10/10 runs (100.0 %), ")
            && progress[9].contains(" pass"),
        "{progress:?}"
    );
    assert!(
        progress[3].starts_with("progress: 4/10 runs (40.0 %)"),
        "{progress:?}"
    );

    let mut shards = Vec::new();
    for id in 0..4u64 {
        let dir = tmp.path().join(format!("task{id}"));
        let id_text = id.to_string();
        let env = [
            ("SLURM_ARRAY_TASK_ID", id_text.as_str()),
            ("SLURM_ARRAY_TASK_MIN", "0"),
            ("SLURM_ARRAY_TASK_MAX", "3"),
            ("SLURM_ARRAY_TASK_STEP", "1"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ];
        let o = montecarlo_env(&dir, "10", "3", &with(&extra, &["--shard", "auto"]), &env);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!(
                "shard {}/4 (Slurm array task {id} of 0-3)",
                id + 1
            )),
            "{}",
            stderr(&o)
        );
        assert!(read(&dir.join("campaign.toml")).contains(&format!("shard = \"{}/4\"", id + 1)));
        shards.push(dir);
    }
    let merged = tmp.path().join("merged");
    let o = merge(&shards, &merged, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_same_files(&merged, &whole, &SAME_BYTES);
    assert_same_files(&merged, &whole, &SAME_BYTES_CONSISTENCY);
    // The consistency was judged (instants from 30 min on), not an empty file.
    assert!(
        read(&whole.join("consistency.txt")).contains("of 31 instants"),
        "{}",
        read(&whole.join("consistency.txt"))
    );

    // A Kubernetes indexed job's pod 1 of 4 is shard 2/4: the Slurm task 1's runs.
    let pod = tmp.path().join("pod1");
    let o = montecarlo_env(
        &pod,
        "10",
        "3",
        &with(&extra, &["--shard", "auto/4"]),
        &[("JOB_COMPLETION_INDEX", "1")],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_same_files(&pod, &shards[1], &["runs.csv", "consistency_sums.csv"]);

    // No batch system, a Kubernetes index without the count, an array given as a list: exit 2.
    type Env<'a> = &'a [(&'a str, &'a str)];
    let cases: [(Env, &str); 3] = [
        (&[], "neither SLURM_ARRAY_TASK_ID"),
        (&[("JOB_COMPLETION_INDEX", "0")], "--shard auto/N"),
        (
            &[
                ("SLURM_ARRAY_TASK_ID", "3"),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_MAX", "8"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
            "not a range",
        ),
    ];
    for (env, expect) in cases {
        let out = tmp.path().join("refused");
        let o = montecarlo_env(&out, "10", "3", &["--shard", "auto"], env);
        assert_eq!(o.status.code(), Some(2), "{env:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(expect), "{env:?}: {}", stderr(&o));
        assert!(!out.exists());
    }
}

/// A shard whose process died keeps the runs it had journaled: run again, it flies only the
/// others, and its files are the same bytes as those of a shard never interrupted. Shown by
/// cutting a journal short mid-line (as a kill during a write leaves it), by an edited journal
/// row that comes out unchanged in runs.csv (it was not flown again), and by killing the
/// process (SIGKILL) with --consistency, whose sums resume from their checkpoint.
#[test]
fn a_killed_shard_resumes_where_it_stopped_with_byte_identical_results() {
    let tmp = tempfile::tempdir().unwrap();
    let short = SHORT.to_vec();
    let shard = ["--shard", "2/3"];
    let reference = tmp.path().join("reference");
    let o = montecarlo_env(&reference, "15", "4", &with(&short, &shard), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let journal = read(&reference.join("runs.journal.csv"));
    let lines: Vec<&str> = journal.lines().collect();
    // The campaign's identity, the header, the shard's five runs.
    assert!(
        lines[0].starts_with("# tss-sim campaign journal: build "),
        "{}",
        lines[0]
    );
    assert_eq!(lines.len(), 2 + 5, "{journal}");

    // Cut after three runs and half of the fourth.
    let cut = tmp.path().join("cut");
    std::fs::create_dir_all(&cut).unwrap();
    let mut text: String = lines[..5].iter().map(|l| format!("{l}\n")).collect();
    text.push_str(&lines[5][..lines[5].len() / 2]);
    std::fs::write(cut.join("runs.journal.csv"), &text).unwrap();
    let o = montecarlo_env(&cut, "15", "4", &with(&short, &shard), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("5 runs, 3 already flown (resumed from"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("flying 2 on"), "{}", stderr(&o));
    assert_same_files(&cut, &reference, &SAME_BYTES);
    assert_eq!(read(&cut.join("runs.journal.csv")).lines().count(), 7);

    // A journaled run is not flown again: an edited value (the first run's final length)
    // comes out as edited.
    let edited = tmp.path().join("edited");
    std::fs::create_dir_all(&edited).unwrap();
    let header: Vec<&str> = lines[1].split(',').collect();
    let col = header.iter().position(|h| *h == "final_length_m").unwrap();
    let mut row: Vec<String> = lines[2].split(',').map(String::from).collect();
    row[col] = "1234.5".to_string();
    let text = format!("{}\n{}\n{}\n", lines[0], lines[1], row.join(","));
    std::fs::write(edited.join("runs.journal.csv"), text).unwrap();
    let o = montecarlo_env(&edited, "15", "4", &with(&short, &shard), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The journal is in the order the runs finished (threads), runs.csv in the runs' order.
    let (_, rows) = read_rows(&edited);
    let run_col = header.iter().position(|h| *h == "run").unwrap();
    let edited_row = rows.iter().find(|r| r[run_col] == row[run_col]).unwrap();
    assert_eq!(edited_row[col], "1234.5");
    assert_eq!(rows.len(), 5);

    // The journal of another campaign (another seed) is replaced: that campaign starts over.
    let o = montecarlo_env(&edited, "15", "5", &with(&short, &shard), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("is the journal of another campaign"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("flying 5 on"), "{}", stderr(&o));

    // Killed for real, with --consistency: whole paper missions, one thread, killed once the
    // first runs are journaled; run again, it completes the same files as an uninterrupted run.
    let consistency = ["--consistency", "--threads", "1"];
    let uninterrupted = tmp.path().join("uninterrupted");
    let o = montecarlo_env(&uninterrupted, "60", "6", &consistency, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let killed = tmp.path().join("killed");
    let sc = scenario();
    let mut child = command(
        &[
            "montecarlo",
            sc.to_str().unwrap(),
            "--runs",
            "60",
            "--seed",
            "6",
            "--out",
            killed.to_str().unwrap(),
            "--no-figures",
            "--consistency",
            "--threads",
            "1",
        ],
        &[],
    )
    .stdout(std::process::Stdio::null())
    .stderr(std::process::Stdio::null())
    .spawn()
    .unwrap();
    // The runs journaled with their NEES and NIS: those the checkpoint covers.
    let covered = |dir: &Path| {
        std::fs::read_to_string(dir.join("consistency.checkpoint.csv"))
            .ok()
            .and_then(|t| {
                t.lines()
                    .nth(1)?
                    .strip_prefix("# covers ")?
                    .split(' ')
                    .next()?
                    .parse::<usize>()
                    .ok()
            })
            .unwrap_or(0)
    };
    let mut polls = 0;
    while covered(&killed) == 0 {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the campaign ended before it was killed"
        );
        polls += 1;
        assert!(polls < 60_000, "no run journaled after 10 min");
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(
        child.try_wait().unwrap().is_none(),
        "the campaign ended before it was killed"
    );
    child.kill().unwrap();
    child.wait().unwrap();
    let before = covered(&killed);
    assert!((1..60).contains(&before), "{before}");
    assert!(!killed.join("runs.csv").exists());
    let o = montecarlo_env(&killed, "60", "6", &consistency, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&format!("60 runs, {before} already flown (resumed from")),
        "{}",
        stderr(&o)
    );
    assert_same_files(&killed, &uninterrupted, &SAME_BYTES);
    assert_same_files(&killed, &uninterrupted, &SAME_BYTES_CONSISTENCY);
    // Run once more, the finished campaign flies nothing and writes the same files.
    let o = montecarlo_env(&killed, "60", "6", &consistency, &[]);
    assert!(
        stderr(&o).contains("60 runs, 60 already flown"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("flying 0 on"), "{}", stderr(&o));
    assert_same_files(&killed, &uninterrupted, &SAME_BYTES_CONSISTENCY);
}

/// `merge` takes only shards flown by one build, with or without --consistency alike, and
/// finished: a shard of another build (its manifest says so), one flown without the
/// estimator's consistency, or one that has only a journal, is refused (exit 2, saying why).
#[test]
fn merge_refuses_shards_of_other_builds_or_unfinished() {
    let tmp = tempfile::tempdir().unwrap();
    let short = SHORT.to_vec();
    let dir = |name: &str| tmp.path().join(name);
    for (name, extra) in [
        ("a1", vec!["--shard", "1/2"]),
        ("a2", vec!["--shard", "2/2"]),
        ("c2", vec!["--shard", "2/2", "--consistency"]),
    ] {
        let o = montecarlo_env(&dir(name), "4", "1", &with(&short, &extra), &[]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let manifest = read(&dir("a1").join("campaign.toml"));
    let build = manifest
        .lines()
        .find_map(|l| l.strip_prefix("build = "))
        .expect("the manifest names the build")
        .trim_matches('"')
        .to_string();
    assert!(!build.is_empty());
    let out = dir("merged");
    let o = merge(&[dir("a1"), dir("a2")], &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));

    // Another build: the manifest of a shard flown by another binary.
    std::fs::create_dir_all(dir("b2")).unwrap();
    for f in std::fs::read_dir(dir("a2")).unwrap() {
        let f = f.unwrap().path();
        std::fs::copy(&f, dir("b2").join(f.file_name().unwrap())).unwrap();
    }
    let other = manifest.replace(
        &format!("build = \"{build}\""),
        "build = \"0123456789abcdef\"",
    );
    let other = other.replace("shard = \"1/2\"", "shard = \"2/2\"");
    std::fs::write(dir("b2").join("campaign.toml"), other).unwrap();
    // An unfinished shard: a journal, no results.
    std::fs::create_dir_all(dir("u2")).unwrap();
    std::fs::copy(
        dir("a2").join("runs.journal.csv"),
        dir("u2").join("runs.journal.csv"),
    )
    .unwrap();
    let bad_out = dir("bad");
    for (shards, expect) in [
        ([dir("a1"), dir("b2")], format!("build (rebuild once and fly every shard with that build) {build} ≠ 0123456789abcdef")),
        ([dir("a1"), dir("c2")], "--consistency false ≠ true".to_string()),
        ([dir("a1"), dir("u2")], "the shard has not finished".to_string()),
    ] {
        let o = merge(&shards, &bad_out, &[]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(&expect), "{expect}: {}", stderr(&o));
        assert!(!bad_out.exists());
    }
}

/// Below `--min-pass-rate`, `montecarlo` and `merge` exit with code 3 after writing every
/// output (a batch job fails, a dependent job does not run); at or above it, 0. The summary
/// carries the pass rate's 95 % intervals: for 0 of 4, Wilson's upper end z²/(4 + z²) and
/// Clopper–Pearson's 1 − 0.025^(1/4).
#[test]
fn below_min_pass_rate_the_exit_code_is_3_and_the_interval_is_reported() {
    let tmp = tempfile::tempdir().unwrap();
    let mut impossible = SHORT.to_vec();
    impossible.extend([
        "--set",
        "montecarlo.criteria.min_tension_n=1000",
        "--set",
        "montecarlo.criteria.no_slack=false",
    ]);
    let out = tmp.path().join("mc");
    let o = montecarlo_env(
        &out,
        "4",
        "1",
        &with(&impossible, &["--min-pass-rate", "0.5"]),
        &[],
    );
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("0 of 4 runs pass (0.00 %), below --min-pass-rate 50.00 %"),
        "{}",
        stderr(&o)
    );
    let summary = read(&out.join("summary.txt"));
    assert!(
        summary.contains("Result: 0 of 4 runs pass (0.0 %)"),
        "{summary}"
    );
    assert!(
        summary.contains(
            "pass rate, 95 % confidence: Wilson [0.000, 48.989] %, Clopper–Pearson [0.000, 60.236] %"
        ),
        "{summary}"
    );
    let json: serde_json::Value = serde_json::from_str(&read(&out.join("summary.json"))).unwrap();
    assert_eq!(json["flown"], 4);
    assert_eq!(json["passed"], 0);
    assert_eq!(json["pass_rate"], 0.0);
    let high = json["pass_rate_wilson"]["high"].as_f64().unwrap();
    let z2 = 1.959_963_984_540_054f64.powi(2);
    assert!((high - z2 / (4.0 + z2)).abs() < 1e-12, "{high}");
    let cp = json["pass_rate_clopper_pearson"]["high"].as_f64().unwrap();
    assert!((cp - (1.0 - 0.025f64.powf(0.25))).abs() < 1e-12, "{cp}");
    assert_eq!(json["criteria"][0]["name"], "min_tension");
    assert_eq!(json["criteria"][0]["failed"], 4);
    assert_eq!(json["failed_runs"], serde_json::json!([0, 1, 2, 3]));
    // A rate of 0 is met; so is a percentage at the rate flown.
    for rate in ["0", "0%"] {
        let o = montecarlo_env(
            &out,
            "4",
            "1",
            &with(&impossible, &["--min-pass-rate", rate]),
            &[],
        );
        assert_eq!(o.status.code(), Some(0), "{rate}: {}", stderr(&o));
    }
    // The merge judges the whole campaign.
    let shards: Vec<PathBuf> = (1..=2).map(|k| tmp.path().join(format!("s{k}"))).collect();
    for (k, dir) in shards.iter().enumerate() {
        let spec = format!("{}/2", k + 1);
        let o = montecarlo_env(dir, "4", "1", &with(&impossible, &["--shard", &spec]), &[]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let merged = tmp.path().join("merged");
    let o = merge(&shards, &merged, &["--min-pass-rate", "95%"]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert_same_files(&merged, &out, &SAME_BYTES);
    // Rates that are not rates.
    for bad in ["1.5", "120%", "x"] {
        let sc = scenario();
        rejected(
            &[sc.to_str().unwrap(), "--runs", "2", "--min-pass-rate", bad],
            &["is not a pass rate"],
        );
    }
}

/// `tss-sim campaign slurm` writes the job array, the merge job and submit.sh; run as Slurm
/// would run them (each array task with its SLURM_ARRAY_TASK_* variables, then the merge),
/// they give the files of the campaign flown whole; with --submit, submit.sh queues the merge
/// after the array (`--dependency=afterok:ARRAY`), here through a stand-in sbatch.
#[cfg(unix)]
#[test]
fn campaign_slurm_writes_job_scripts_that_fly_and_merge_the_campaign() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("campaign");
    let sc = scenario();
    let short = SHORT.to_vec();
    let mut args = vec![
        "campaign",
        "slurm",
        sc.to_str().unwrap(),
        "--runs",
        "6",
        "--shards",
        "3",
        "--seed",
        "2",
        "--cpus-per-task",
        "2",
        "--time",
        "0:30:00",
        "--sbatch=--account=tss",
        "--no-figures",
        "-o",
        dir.to_str().unwrap(),
    ];
    args.extend_from_slice(&short);
    let o = tss_sim(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let shards_script = read(&dir.join("shards.sbatch"));
    for expect in [
        "#SBATCH --array=1-3\n",
        "#SBATCH --cpus-per-task=2\n",
        "#SBATCH --requeue\n",
        "#SBATCH --time=0:30:00\n",
        "#SBATCH --account=tss\n",
        "--shard auto/3 --threads 2 --no-figures",
    ] {
        assert!(shards_script.contains(expect), "{expect}: {shards_script}");
    }
    let submit = read(&dir.join("submit.sh"));
    assert!(
        submit.contains("--dependency=afterok:\"$array\" --kill-on-invalid-dep=yes merge.sbatch"),
        "{submit}"
    );

    // As Slurm runs them: the array's tasks 1..3, then the merge.
    for id in ["1", "2", "3"] {
        let mut task = Command::new("bash");
        task.arg(dir.join("shards.sbatch"));
        for v in BATCH_VARIABLES {
            task.env_remove(v);
        }
        let o = task
            .envs([
                ("SLURM_ARRAY_TASK_ID", id),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_MAX", "3"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let o = Command::new("bash")
        .arg(dir.join("merge.sbatch"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let whole = tmp.path().join("whole");
    let o = montecarlo_env(&whole, "6", "2", &short, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_same_files(&dir.join("merged"), &whole, &SAME_BYTES);

    // --submit through a stand-in sbatch that records its arguments and answers job ids.
    let fake = tmp.path().join("fake-bin");
    std::fs::create_dir_all(&fake).unwrap();
    let log = tmp.path().join("sbatch.log");
    std::fs::write(
        fake.join("sbatch"),
        format!(
            "#!/bin/bash\necho \"$*\" >> {log}\necho $((4241 + $(wc -l < {log})))\n",
            log = log.display()
        ),
    )
    .unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(fake.join("sbatch"), std::fs::Permissions::from_mode(0o755)).unwrap();
    let path = format!(
        "{}:{}",
        fake.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    args.push("--submit");
    let o = command(&args, &[("PATH", path.as_str())]).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("array job 4242: 3 shards"), "{stdout}");
    assert!(
        stdout.contains("merge job 4243: once every shard has succeeded (afterok:4242)"),
        "{stdout}"
    );
    assert_eq!(
        read(&log),
        "--parsable shards.sbatch\n--parsable --dependency=afterok:4242 --kill-on-invalid-dep=yes merge.sbatch\n"
    );
    assert_eq!(
        read(&dir.join("jobs.env")),
        "ARRAY_JOB=4242\nMERGE_JOB=4243\n"
    );

    // Paths the scripts cannot carry, and more shards than runs, are refused before writing.
    let spaced = tmp.path().join("with space");
    let o = tss_sim(&[
        "campaign",
        "slurm",
        sc.to_str().unwrap(),
        "--runs",
        "2",
        "--shards",
        "1",
        "-o",
        spaced.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("which the job scripts cannot carry"),
        "{}",
        stderr(&o)
    );
    let o = tss_sim(&[
        "campaign",
        "slurm",
        sc.to_str().unwrap(),
        "--runs",
        "2",
        "--shards",
        "3",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("more shards than runs"),
        "{}",
        stderr(&o)
    );
}

/// While a campaign flies, its directory is locked: a second process on it (a requeued job
/// whose first copy still runs) is refused (exit 2) instead of interleaving the journal.
#[test]
fn a_directory_another_campaign_is_flying_in_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("mc");
    std::fs::create_dir_all(&out).unwrap();
    let held = std::fs::File::create(out.join("campaign.lock")).unwrap();
    held.try_lock().expect("the test holds the lock");
    let o = montecarlo_env(&out, "2", "1", &SHORT, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("another tss-sim is flying a campaign in"),
        "{}",
        stderr(&o)
    );
    assert!(!out.join("runs.csv").exists());
    held.unlock().unwrap();
    let o = montecarlo_env(&out, "2", "1", &SHORT, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
}
