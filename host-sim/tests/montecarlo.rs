//! `tss-sim montecarlo` and `tss-sim merge`, through the built binary: reproducible whatever
//! the thread count, shards that merge into the whole campaign byte for byte, clear errors
//! (exit 2) for bad dispersions, shard specs and mismatched shards, and criteria that fail.
//! On a batch system: `--shard auto` from a Slurm array or a Kubernetes index, shards that
//! resume after a kill, merges that refuse other builds, `--min-pass-rate`, progress lines, the
//! pass rate's confidence interval, the consistency sums merged exactly, and the job scripts of
//! `tss-sim campaign slurm` (scripts/slurm-test runs them on a real Slurm).
//!
//! The campaigns fly the whole paper mission of `scenarios/paper-montecarlo.toml` (about 0.05 s
//! a run in the test profile), except where said.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_tss-sim");

fn scenario() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper-montecarlo.toml")
}

/// Overrides that shorten the mission to its first 10 minutes, with the criteria on what happens
/// later (reaching 30 km, overshoot, station keeping, final length) switched off.
const SHORT: [&str; 10] = [
    "--set",
    "simulation.duration_s=600",
    "--set",
    "montecarlo.criteria.max_keep1_error_m=inf",
    "--set",
    "montecarlo.criteria.max_final_error_m=inf",
    "--set",
    "montecarlo.criteria.max_time_to_keep1_s=inf",
    "--set",
    "montecarlo.criteria.max_overshoot_m=inf",
];

/// The environment variables a batch system sets that tss-sim reads: removed, so that the
/// tests behave the same inside a batch job.
const BATCH_VARIABLES: [&str; 7] = [
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_MIN",
    "SLURM_ARRAY_TASK_MAX",
    "SLURM_ARRAY_TASK_STEP",
    "SLURM_ARRAY_TASK_COUNT",
    "SLURM_CPUS_PER_TASK",
    "JOB_COMPLETION_INDEX",
];

/// `tss-sim` with `args`, outside any batch system but for the variables `env`.
fn command(args: &[&str], env: &[(&str, &str)]) -> Command {
    let mut c = Command::new(BIN);
    c.args(args);
    for v in BATCH_VARIABLES {
        c.env_remove(v);
    }
    c.envs(env.iter().copied());
    c
}

fn tss_sim(args: &[&str]) -> Output {
    tss_sim_env(args, &[])
}

fn tss_sim_env(args: &[&str], env: &[(&str, &str)]) -> Output {
    command(args, env).output().expect("tss-sim runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `tss-sim montecarlo` on the paper campaign into `out`, without figures; panics unless it
/// succeeds.
fn campaign(out: &Path, runs: u32, seed: u32, extra: &[&str]) -> Output {
    let o = montecarlo_env(out, &runs.to_string(), &seed.to_string(), extra, &[]);
    assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
    o
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The header and the rows of a runs.csv.
fn read_rows(dir: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = read(&dir.join("runs.csv"));
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

#[test]
fn the_same_seed_gives_byte_identical_results_on_1_and_2_threads_and_shards_merge_exactly() {
    let tmp = tempfile::tempdir().unwrap();
    let one = tmp.path().join("one");
    let two = tmp.path().join("two");
    campaign(&one, 20, 7, &["--threads", "1"]);
    let o = campaign(&two, 20, 7, &["--threads", "2"]);
    let csv = read(&one.join("runs.csv"));
    assert_eq!(csv, read(&two.join("runs.csv")));
    let summary = read(&one.join("summary.txt"));
    assert_eq!(summary, read(&two.join("summary.txt")));
    // The terminal shows the summary.
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("Result: "),
        "{o:?}"
    );

    // Twenty rows, in run order, every input dispersed and within its declared range.
    let (header, rows) = read_rows(&one);
    assert_eq!(rows.len(), 20);
    assert_eq!(&header[..3], ["run", "sensor_seed", "initial.delta_rad"]);
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row.len(), header.len(), "{row:?}");
        assert_eq!(row[0], i.to_string());
    }
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let values =
        |name: &str| -> Vec<f64> { rows.iter().map(|r| r[col(name)].parse().unwrap()).collect() };
    let accel = values("reel.max_accel_mps2");
    assert!(accel.iter().all(|x| (2.0..=20.0).contains(x)), "{accel:?}");
    let delta = values("initial.delta_rad");
    let mut distinct = delta.clone();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup();
    assert_eq!(distinct.len(), 20, "{delta:?}");
    let seeds: Vec<&String> = rows.iter().map(|r| &r[1]).collect();
    assert!(seeds.windows(2).all(|w| w[0] != w[1]));
    // Every outcome defined (the whole mission was flown); the verdict agrees with `failed`.
    for r in &rows {
        for m in [
            "time_to_keep1_s",
            "keep1_max_error_m",
            "table1_stage2_max_error_m",
            "final_length_m",
        ] {
            assert!(
                r[col(m)].parse::<f64>().is_ok_and(f64::is_finite),
                "{m}: {r:?}"
            );
        }
        assert_eq!(
            r[col("pass")] == "true",
            r[col("failed")].is_empty(),
            "{r:?}"
        );
    }
    let passed = rows.iter().filter(|r| r[col("pass")] == "true").count();
    assert!(
        summary.contains(&format!("Result: {passed} of 20 runs pass")),
        "{summary}"
    );

    // Run i is the same in a smaller campaign: it depends on (seed, i) only.
    let ten = tmp.path().join("ten");
    campaign(&ten, 10, 7, &[]);
    let prefix: String = csv.lines().take(11).map(|l| format!("{l}\n")).collect();
    assert_eq!(read(&ten.join("runs.csv")), prefix);

    // Shards 1/3, 2/3, 3/3 (each its slice only), merged in any order, give the same files.
    let shard_dirs: Vec<PathBuf> = (1..=3)
        .map(|k| tmp.path().join(format!("shard{k}")))
        .collect();
    for (k, dir) in shard_dirs.iter().enumerate() {
        let spec = format!("{}/3", k + 1);
        campaign(dir, 20, 7, &["--shard", &spec, "--threads", "2"]);
        let (_, rows) = read_rows(dir);
        let expect: Vec<String> = (k..20).step_by(3).map(|i| i.to_string()).collect();
        let got: Vec<String> = rows.iter().map(|r| r[0].clone()).collect();
        assert_eq!(got, expect);
        assert!(read(&dir.join("summary.txt")).contains(&format!("shard {spec}")));
    }
    let merged = tmp.path().join("merged");
    let o = tss_sim(&[
        "merge",
        shard_dirs[2].to_str().unwrap(),
        shard_dirs[0].to_str().unwrap(),
        shard_dirs[1].to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
        "--no-figures",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(read(&merged.join("runs.csv")), csv);
    assert_eq!(read(&merged.join("summary.txt")), summary);

    // Shards that are not of one campaign, or that do not make a whole one, are refused.
    let other_seed = tmp.path().join("other_seed");
    campaign(&other_seed, 20, 8, &["--shard", "2/3"]);
    let other_runs = tmp.path().join("other_runs");
    campaign(&other_runs, 21, 7, &["--shard", "2/3"]);
    let other_scenario = tmp.path().join("other_scenario");
    campaign(
        &other_scenario,
        20,
        7,
        &["--shard", "2/3", "--set", "masses.sub_kg=90"],
    );
    let two_shards = tmp.path().join("two_shards");
    campaign(&two_shards, 20, 7, &["--shard", "2/2"]);
    let s = |p: &PathBuf| p.to_str().unwrap().to_string();
    let out = tmp.path().join("bad_merge");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec![s(&shard_dirs[0]), s(&other_seed), s(&shard_dirs[2])],
            "seed 7 ≠ 8",
        ),
        (
            vec![s(&shard_dirs[0]), s(&other_runs), s(&shard_dirs[2])],
            "runs 20 ≠ 21",
        ),
        (
            vec![s(&shard_dirs[0]), s(&other_scenario), s(&shard_dirs[2])],
            "scenario (file and overrides)",
        ),
        (
            vec![s(&shard_dirs[0]), s(&two_shards)],
            "shard count 1/3 ≠ 2/2",
        ),
        (
            vec![s(&shard_dirs[0]), s(&shard_dirs[2])],
            "missing shard(s) 2/3",
        ),
        (
            vec![s(&shard_dirs[0]), s(&shard_dirs[0]), s(&shard_dirs[2])],
            "are both shard 1/3",
        ),
        (
            vec![
                s(&shard_dirs[0]),
                tmp.path().join("nothing").to_str().unwrap().to_string(),
            ],
            "not the output of `tss-sim montecarlo`",
        ),
    ];
    for (dirs, expect) in cases {
        let mut args: Vec<&str> = vec!["merge"];
        args.extend(dirs.iter().map(String::as_str));
        args.extend(["--out", out.to_str().unwrap()]);
        let o = tss_sim(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(expect), "{args:?}: {}", stderr(&o));
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
    }
    // A shard whose runs.csv lost a row is refused too.
    let csv1 = read(&shard_dirs[0].join("runs.csv"));
    let cut: String = csv1.lines().take(3).map(|l| format!("{l}\n")).collect();
    std::fs::write(shard_dirs[0].join("runs.csv"), cut).unwrap();
    let o = tss_sim(&[
        "merge",
        &s(&shard_dirs[0]),
        &s(&shard_dirs[1]),
        &s(&shard_dirs[2]),
        "--out",
        &s(&out),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("holds 2 runs, not the 7 runs of shard 1/3"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn an_impossible_criterion_fails_every_run_and_says_which() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("mc");
    let mut args = SHORT.to_vec();
    args.extend([
        "--set",
        "montecarlo.criteria.min_tension_n=1000",
        "--set",
        "montecarlo.criteria.no_slack=false",
    ]);
    let o = campaign(&out, 4, 1, &args);
    let summary = read(&out.join("summary.txt"));
    assert!(
        summary.contains("min_tension      tension ≥ 1000 N at every tick"),
        "{summary}"
    );
    assert!(
        summary.contains("Result: 0 of 4 runs pass (0.0 %)"),
        "{summary}"
    );
    assert!(
        summary.contains("failures by criterion (a run can fail several): min_tension 4"),
        "{summary}"
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("Result: 0 of 4 runs pass"));
    let (header, rows) = read_rows(&out);
    let pass = header.iter().position(|h| h == "pass").unwrap();
    for r in &rows {
        assert_eq!(r[pass], "false");
        assert_eq!(r[pass + 1], "min_tension");
    }
}

#[test]
fn figures_are_drawn_as_png_and_svg() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("mc");
    let sc = scenario();
    let mut args = vec![
        "montecarlo",
        sc.to_str().unwrap(),
        "--runs",
        "3",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(&SHORT);
    let o = tss_sim(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    for stem in [
        "mc_histograms",
        "mc_scatter_keep1_max_error_m",
        "mc_scatter_overshoot_m",
        "mc_scatter_min_tension_n",
    ] {
        for ext in ["png", "svg"] {
            let p = out.join(format!("{stem}.{ext}"));
            assert!(
                std::fs::metadata(&p)
                    .map(|m| m.len() > 1000)
                    .unwrap_or(false),
                "{}",
                p.display()
            );
        }
    }
    for f in ["runs.csv", "summary.txt", "campaign.toml", "scenario.toml"] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

/// Runs `tss-sim montecarlo` with `extra` and expects exit 2 with every piece of `expect` in
/// stderr and nothing written.
fn rejected(extra: &[&str], expect: &[&str]) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("mc");
    let mut args = vec!["montecarlo", "--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = tss_sim(&args);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    for e in expect {
        assert!(
            stderr(&o).contains(e),
            "{args:?}: {e:?} not in {}",
            stderr(&o)
        );
    }
    assert!(!out.exists(), "{args:?} wrote {}", out.display());
}

#[test]
fn bad_dispersions_shards_and_runs_are_clear_errors() {
    let sc = scenario();
    let sc = sc.to_str().unwrap();
    let set = |d: &str| format!("montecarlo.dispersion=[{d}]");
    let cases: Vec<(String, Vec<&str>)> = vec![
        (
            set(r#"{ field = "initial.delta", distribution = "normal", std = 0.1 }"#),
            vec![
                "montecarlo.dispersion[0].field = \"initial.delta\" is not a number field of the scenario",
                "initial.delta_rad",
                "(set by --set)",
            ],
        ),
        (
            set(r#"{ field = "name", distribution = "normal", std = 0.1 }"#),
            vec!["montecarlo.dispersion[0].field = \"name\" is not a number field"],
        ),
        (
            set(r#"{ field = "initial.delta_rad", distribution = "gaussian", std = 0.1 }"#),
            vec!["montecarlo.dispersion.distribution = \"gaussian\" must be one of normal, uniform"],
        ),
        (
            set(r#"{ field = "initial.delta_rad", distribution = "uniform", min = 0.2 }"#),
            vec!["montecarlo.dispersion[0].max = (missing) is required by distribution = \"uniform\""],
        ),
        (
            set(r#"{ field = "initial.delta_rad", distribution = "normal", std = 0.1, min = 0 }"#),
            vec!["montecarlo.dispersion[0].min = 0 is not used by distribution = \"normal\""],
        ),
        (
            set(r#"{ field = "initial.delta_rad", distribution = "uniform", min = 0.3, max = 0.2 }"#),
            vec!["montecarlo.dispersion[0].max = 0.2 must not be below montecarlo.dispersion[0].min = 0.3"],
        ),
        (
            set(r#"{ field = "initial.delta_rate_radps", distribution = "normal", std = 0.1, relative = true }"#),
            vec!["montecarlo.dispersion[0].relative = true cannot scale initial.delta_rate_radps = 0"],
        ),
        (
            set(r#"{ field = "reel.lag_s", distribution = "normal", std = -1 }"#),
            vec!["montecarlo.dispersion[0].std = -1 must not be negative"],
        ),
        (
            set(r#"{ field = "initial.delta_rad", distribution = "normal", sigma = 1 }"#),
            vec!["unknown key `montecarlo.dispersion.sigma`", "std"],
        ),
        (
            "montecarlo.criteria.max_keep1_error_m=-1".to_string(),
            vec!["montecarlo.criteria.max_keep1_error_m = -1 must not be negative"],
        ),
    ];
    for (arg, expect) in &cases {
        rejected(&[sc, "--runs", "2", "--set", arg], expect);
    }
    // The same checks hold for a campaign written in a file.
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("bad.toml");
    let text = std::fs::read_to_string(scenario()).unwrap().replace(
        "field = \"masses.sub_kg\"",
        "field = \"masses.sub_mass_kg\"",
    );
    std::fs::write(&file, text).unwrap();
    rejected(
        &[file.to_str().unwrap(), "--runs", "2"],
        &["bad.toml: montecarlo.dispersion[4].field = \"masses.sub_mass_kg\" is not a number field", "masses.main_initial_kg, masses.sub_kg"],
    );
    for (shard, expect) in [
        ("4/3", "K must be in 1..=N"),
        ("0/3", "K must be in 1..=N"),
        ("1/0", "K must be in 1..=N"),
        ("2", "expected K/N"),
        ("a/3", "K `a` is not a whole number"),
    ] {
        rejected(&[sc, "--runs", "10", "--shard", shard], &[expect]);
    }
    rejected(
        &[sc, "--runs", "2", "--shard", "3/3"],
        &["more shards than runs"],
    );
    rejected(&[sc, "--runs", "0"], &["--runs"]);
}

/// Absurd counts are refused before any work (exit 2, naming the flag and value), not a
/// capacity-overflow panic (18 446 744 073 709 551 615 runs) or an aborted allocation
/// (4 000 000 000 runs); `--threads` has an upper bound too.
#[test]
fn absurd_runs_and_threads_are_refused_before_any_work() {
    let sc = scenario();
    let sc = sc.to_str().unwrap();
    for runs in ["18446744073709551615", "4000000000", "1000001"] {
        rejected(&[sc, "--runs", runs], &["--runs", runs, "1..=1000000"]);
    }
    for threads in ["1025", "18446744073709551615"] {
        rejected(
            &[sc, "--runs", "2", "--threads", threads],
            &["--threads", threads],
        );
    }
}

/// A scenario without `[montecarlo]` dispersions would fly N identical runs and report 100 %
/// pass; it is an error that says what is missing.
#[test]
fn a_scenario_without_dispersions_is_an_error() {
    let sc = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml");
    rejected(
        &[sc.to_str().unwrap(), "--runs", "3"],
        &["paper.toml", "no [[montecarlo.dispersion]]"],
    );
}

/// A campaign replaces the files of an earlier one in its directory, figures included: with
/// --no-figures, the earlier campaign's figures are removed rather than left next to results
/// they do not show; other files stay.
#[test]
fn a_campaign_replaces_an_earlier_campaigns_files() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("mc");
    std::fs::create_dir_all(&out).unwrap();
    for f in [
        "mc_histograms.png",
        "mc_scatter_keep1_max_error_m.svg",
        "notes.md",
    ] {
        std::fs::write(out.join(f), "earlier").unwrap();
    }
    campaign(&out, 2, 7, &SHORT);
    assert!(!out.join("mc_histograms.png").exists());
    assert!(!out.join("mc_scatter_keep1_max_error_m.svg").exists());
    assert!(out.join("notes.md").exists());
    assert!(out.join("runs.csv").is_file());
}

/// A dispersion of a key the selected models ignore would report a spread that was never
/// flown: with `reel.model = "motor"` the lag drive's keys, with the lag drive the drum's, on
/// the rigid plant the elastic tether's. Refused (exit 2, naming the key and why).
#[test]
fn dispersing_a_key_the_models_ignore_is_refused() {
    let paper = scenario();
    let paper = paper.to_str().unwrap();
    let elastic = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper-elastic.toml");
    let elastic = elastic.to_str().unwrap();
    let one = |field: &str| {
        format!(
            "montecarlo.dispersion=[{{ field = \"{field}\", distribution = \"uniform\", \
             min = 0.5, max = 1.0 }}]"
        )
    };
    for field in ["reel.lag_s", "reel.max_rate_mps", "reel.max_accel_mps2"] {
        rejected(
            &[elastic, "--runs", "2", "--set", &one(field)],
            &[
                &format!("montecarlo.dispersion[0].field = \"{field}\" has no effect"),
                "reel.model = \"motor\"",
            ],
        );
    }
    for field in ["reel.drum_inertia_kgm2", "tether.axial_stiffness_n"] {
        rejected(
            &[paper, "--runs", "2", "--set", &one(field)],
            &[&format!(
                "montecarlo.dispersion[0].field = \"{field}\" has no effect"
            )],
        );
    }
    // The same keys are dispersible where a selected model reads them.
    for (file, field) in [
        (elastic, "reel.drum_inertia_kgm2"),
        (elastic, "tether.axial_stiffness_n"),
        (paper, "reel.lag_s"),
    ] {
        let loaded = tss_sim::scenario::Scenario::load(Path::new(file), &[one(field)]);
        assert!(loaded.is_ok(), "{file} {field}: {:?}", loaded.err());
    }
}

/// `montecarlo` on the paper campaign into `out`, without figures, with `extra`, and the
/// environment `env`.
fn montecarlo_env(
    out: &Path,
    runs: &str,
    seed: &str,
    extra: &[&str],
    env: &[(&str, &str)],
) -> Output {
    let sc = scenario();
    let mut args = vec![
        "montecarlo",
        sc.to_str().unwrap(),
        "--runs",
        runs,
        "--seed",
        seed,
        "--out",
        out.to_str().unwrap(),
        "--no-figures",
    ];
    args.extend_from_slice(extra);
    tss_sim_env(&args, env)
}

#[path = "montecarlo/batch.rs"]
mod batch;
