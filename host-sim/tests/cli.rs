//! What a new user meets on the command line (issue 15 §5): shell completions, `--quiet`, and
//! `-o DIR` on every command that writes files.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_tss-sim");

fn paper() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml")
}

fn tss_sim(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("tss-sim runs")
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
    let o = tss_sim(&[
        "run",
        paper().to_str().unwrap(),
        "--quiet",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "simulation.duration_s=60",
    ]);
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

/// A PIL scenario longer than the firmware's bound (`link::MAX_TICKS` periods) used to run for
/// 200 000 periods and then fail; it is refused before QEMU starts (exit 2). Any existing file
/// passes the `--firmware` check, so this needs no ELF.
#[test]
fn a_pil_run_longer_than_the_firmware_allows_is_refused_before_it_starts() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("pil");
    let o = tss_sim(&[
        "run",
        paper().to_str().unwrap(),
        "--pil",
        "--firmware",
        BIN,
        "-o",
        out.to_str().unwrap(),
        "--set",
        "simulation.duration_s=200000",
    ]);
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
    let o = tss_sim(&[
        "run",
        paper().to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--set",
        "simulation.output_interval_s=1e300",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("simulation.output_interval_s"));
    assert!(!out.exists());
}
