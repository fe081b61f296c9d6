//! What a new user meets on the command line: shell completions, `--quiet`, and `-o DIR` on
//! every command that writes files.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_tss-sim");

fn paper() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml")
}

fn tss_sim(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("tss-sim runs")
}

/// `tss-sim run scenarios/paper.toml -o OUT ARGS...`.
fn run_paper(out: &Path, args: &[&str]) -> Output {
    let (paper, out) = (paper(), out.to_str().unwrap().to_string());
    let mut all = vec!["run", paper.to_str().unwrap(), "-o", &out];
    all.extend(args);
    tss_sim(&all)
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn completions_are_generated_for_each_shell() {
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let o = tss_sim(&["completions", shell]);
        assert!(o.status.success(), "{shell}: {}", text(&o.stderr));
        let script = text(&o.stdout);
        for word in ["tss-sim", "montecarlo", "--set"] {
            assert!(script.contains(word), "{shell}: no {word}");
        }
    }
    let o = tss_sim(&["completions", "tcsh"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn quiet_prints_nothing_and_writes_everything() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("q");
    let o = run_paper(&out, &["--quiet", "--set", "simulation.duration_s=60"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(o.stdout.is_empty(), "{}", text(&o.stdout));
    assert!(o.stderr.is_empty(), "{}", text(&o.stderr));
    for f in [
        "history.csv",
        "summary.txt",
        "faults.txt",
        "fig4_length_tension.png",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

#[test]
fn every_command_that_writes_files_takes_dash_o() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("extent");
    let o = tss_sim(&[
        "extent",
        "--eccentricity",
        "0,0.1",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    // The written files are listed on stdout, as `run` lists its own.
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains(&out.join("fig3_extent.csv").display().to_string()),
        "{stdout}"
    );
    assert!(o.stderr.is_empty(), "{}", text(&o.stderr));
    for cmd in ["run", "extent", "montecarlo", "merge"] {
        let o = tss_sim(&[cmd, "--help"]);
        assert!(text(&o.stdout).contains("-o, --out"), "{cmd} --help");
    }
}

/// A PIL scenario longer than the firmware's bound (`link::MAX_TICKS` periods) is refused
/// before QEMU starts (exit 2), not run for 200 000 periods to fail then. Any existing file
/// passes the `--firmware` check, so this needs no ELF.
#[test]
fn a_pil_run_longer_than_the_firmware_allows_is_refused_before_it_starts() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("pil");
    let o = run_paper(
        &out,
        &[
            "--pil",
            "--firmware",
            BIN,
            "--set",
            "simulation.duration_s=200000",
        ],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(
        err.contains("simulation.duration_s = 200000") && err.contains("200001"),
        "{err}"
    );
    assert!(!out.exists());
}

/// Scenario values that the simulation refuses before its first step (here an output interval
/// that is no whole number of periods in f64) are the user's mistake: exit 2, not 1, and
/// nothing left behind.
#[test]
fn values_the_simulation_refuses_before_its_first_step_are_usage_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("timing");
    let o = run_paper(&out, &["--set", "simulation.output_interval_s=1e300"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("simulation.output_interval_s"));
    assert!(!out.exists());
}

/// With stderr not a terminal (a batch job's log) a run is not silent until it ends: it prints
/// a line per simulated hour (and nothing under `--quiet`, above).
#[test]
fn a_run_logs_its_progress_every_simulated_hour_when_not_on_a_terminal() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("p");
    let o = run_paper(&out, &["--set", "simulation.duration_s=10800"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    for h in 1..=3 {
        assert!(err.contains(&format!("simulated {h} h of 3.0 h")), "{err}");
    }
}

/// `tss-sim -q COMMAND scenarios/paper.toml --set simulation.duration_s=60 ARGS...` in `cwd`,
/// without `--out`.
fn paper_in(cwd: &Path, command: &str, args: &[&str]) -> Output {
    let paper = paper();
    Command::new(BIN)
        .args(["-q", command, paper.to_str().unwrap()])
        .args(["--set", "simulation.duration_s=60"])
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("tss-sim runs")
}

/// The README's eccentric example (`run scenarios/paper.toml --set orbit.eccentricity=0.1 …`,
/// no `--out`) must not replace the results of the plain `run scenarios/paper.toml` in
/// out/paper. A run with overrides writes beside it, and a PIL run too.
#[test]
fn a_run_without_out_never_replaces_another_runs_results() {
    let tmp = tempfile::tempdir().unwrap();
    let plain = paper_in(tmp.path(), "run", &[]);
    assert!(plain.status.success(), "{}", text(&plain.stderr));
    let dirs = |p: &Path| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(p)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    let first = dirs(&tmp.path().join("out"));
    assert_eq!(first.len(), 1, "{first:?}");
    let varied = paper_in(tmp.path(), "run", &["--set", "orbit.eccentricity=0.05"]);
    assert!(varied.status.success(), "{}", text(&varied.stderr));
    let second = dirs(&tmp.path().join("out"));
    assert_eq!(second.len(), 2, "{second:?}");
    assert!(second.contains(&first[0]));
    assert!(
        second.iter().any(|d| d.contains("orbit.eccentricity=0.05")),
        "{second:?}"
    );
    // `compare` writes into the scenario's directory, in one of its own named after it, and
    // with overrides into theirs: it replaces neither run's results nor another compare's.
    let plain_files = dirs(&tmp.path().join("out").join(&first[0]));
    let compared = paper_in(tmp.path(), "compare", &["--laws", "paper,rupp"]);
    assert!(compared.status.success(), "{}", text(&compared.stderr));
    let varied_compare = paper_in(
        tmp.path(),
        "compare",
        &["--laws", "paper,rupp", "--set", "orbit.eccentricity=0.05"],
    );
    assert!(
        varied_compare.status.success(),
        "{}",
        text(&varied_compare.stderr)
    );
    assert_eq!(dirs(&tmp.path().join("out")), second);
    for dir in &second {
        let compare = tmp.path().join("out").join(dir).join("compare");
        assert!(
            compare.join("compare.txt").is_file(),
            "{}",
            compare.display()
        );
    }
    let mut with_compare = plain_files.clone();
    with_compare.push("compare".to_string());
    with_compare.sort();
    assert_eq!(dirs(&tmp.path().join("out").join(&first[0])), with_compare);
}

/// A rigid run lists its figures as the paper's Figs. 4–6, not under a heading about the
/// tether's shape on the elastic plant.
#[test]
fn a_rigid_run_s_figures_are_not_said_to_show_the_tether_s_shape() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("r");
    let o = run_paper(&out, &["--set", "simulation.duration_s=60"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains("Figures (Figs. 4–6 of the paper):"),
        "{stdout}"
    );
    assert!(!stdout.contains("shape"), "{stdout}");
}

/// `compare --laws paper,paper` is refused, rather than flying the law once and saying
/// nothing.
#[test]
fn compare_refuses_a_law_named_twice() {
    let tmp = tempfile::tempdir().unwrap();
    let o = tss_sim(&[
        "compare",
        paper().to_str().unwrap(),
        "--laws",
        "paper,rupp,paper",
        "-o",
        tmp.path().join("c").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("named twice"),
        "{}",
        text(&o.stderr)
    );
}
