//! `tss-sim run` prints the fault summary after its report and writes it to `DIR/faults.txt`.

use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_tss-sim");

#[test]
fn run_prints_and_writes_the_fault_summary() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("faults");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml");
    let output = Command::new(BIN)
        .arg("run")
        .arg(&scenario)
        .arg("--out")
        .arg(&out)
        .args(["--set", "simulation.duration_s=900"])
        .args(["--set", "faults.dropout=[{ from_s = 100, until_s = 150 }]"])
        .args([
            "--set",
            "faults.length_glitch=[{ at_s = 600, size_m = 100 }]",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success() || stdout.contains("Faults, health and envelope"),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = std::fs::read_to_string(out.join("faults.txt")).unwrap();
    for needle in [
        "Faults, health and envelope of scenario `paper`",
        "dropout (no sample) 100–150 s",
        "length glitch 100 m at 600 s",
        "sensor Missing                   100 s       149 s      50",
        "sensor LengthJump",
        "degraded → safe hold (sensor Missing)",
        "outside [0.5, 40000] m for 0 s",
    ] {
        assert!(
            text.contains(needle),
            "{needle:?} not in faults.txt:\n{text}"
        );
    }
    assert!(stdout.contains(&text), "the summary is printed too");
}

fn scenario(file: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(file)
}

/// Runs `tss-sim run` of `file` with `sets` into a temporary directory; returns its stdout,
/// `verdict.json` and `faults.txt`.
fn fly(file: &str, sets: &[&str]) -> (String, String, String) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let mut cmd = Command::new(BIN);
    cmd.arg("run").arg(scenario(file)).arg("--out").arg(&out);
    for s in sets {
        cmd.args(["--set", s]);
    }
    let o = cmd.output().unwrap();
    assert!(
        o.status.success(),
        "{file} {sets:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let read = |f: &str| std::fs::read_to_string(out.join(f)).unwrap_or_default();
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        read("verdict.json"),
        read("faults.txt"),
    )
}

/// A run in which the tether tumbles (|α| past π/2) must not headline "deploy reaches 30 km".
/// Here a locked reel holds a tether
/// spun at 0.01 rad/s, ten times the orbit rate: it tumbles, and the headline and the verdict
/// say so first.
#[test]
fn a_tumbling_tether_is_headlined_as_a_failure() {
    let (stdout, verdict, faults) = fly(
        "paper.toml",
        &[
            "reel.locked=true",
            "initial.delta_rate_radps=0.01",
            "simulation.duration_s=3600",
        ],
    );
    let first = stdout.lines().next().unwrap_or_default();
    assert!(first.starts_with("verdict: FAILED: tumble"), "{stdout}");
    assert!(verdict.contains("\"passed\": false"), "{verdict}");
    assert!(verdict.contains("\"kind\": \"tumble\""), "{verdict}");
    assert!(faults.contains("past π/2 (tumbled)"), "{faults}");
}

/// α read as 0 from 1 h on: the tether goes slack. The slack tether and the mission that goes
/// no further are the headline and the verdict.
#[test]
fn a_slack_tether_is_headlined_as_a_failure() {
    let (stdout, verdict, _) = fly(
        "paper-reel-limits.toml",
        &[
            "faults.corrupt=[{ sensor = \"alpha\", from_s = 3600.0, until_s = 1e9, value = 0.0 }]",
            "simulation.duration_s=21600",
        ],
    );
    let first = stdout.lines().next().unwrap_or_default();
    assert!(first.starts_with("verdict: FAILED"), "{stdout}");
    assert!(first.contains("slack tether"), "{first}");
    assert!(verdict.contains("\"passed\": false"), "{verdict}");
    assert!(verdict.contains("\"kind\": \"slack\""), "{verdict}");
}

/// The same slack counts only from the point the tether must be taut on
/// (`simulation.taut_from_length_m`): a point the run never reaches leaves no slack in the
/// verdict, and one reached in the middle of the slack episode (about 145 m, 24 s into it)
/// counts the episode from there.
#[test]
fn slack_fails_the_verdict_only_from_the_point_the_tether_must_be_taut_on() {
    let corrupt =
        "faults.corrupt=[{ sensor = \"alpha\", from_s = 3600.0, until_s = 1e9, value = 0.0 }]";
    let taut_from = |length_m: &str| {
        fly(
            "paper-reel-limits.toml",
            &[
                corrupt,
                "simulation.duration_s=21600",
                &format!("simulation.taut_from_length_m={length_m}"),
            ],
        )
    };
    let (stdout, verdict, faults) = taut_from("1e9");
    let first = stdout.lines().next().unwrap_or_default();
    assert!(!first.contains("slack"), "{first}");
    assert!(!verdict.contains("\"kind\": \"slack\""), "{verdict}");
    assert!(faults.contains("slack (T ≤ 0): 1 events"), "{faults}");

    let (stdout, verdict, _) = taut_from("145");
    let first = stdout.lines().next().unwrap_or_default();
    assert!(
        first.contains("slack tether once 145 m long: 1 episode(s)"),
        "{first}"
    );
    let number = |key: &str| -> f64 {
        let at = verdict.find(&format!("\"{key}\": ")).unwrap() + key.len() + 4;
        let end = verdict[at..].find([',', '}']).unwrap() + at;
        verdict[at..end].parse().unwrap()
    };
    let (first_s, total_s) = (number("first_s"), number("total_s"));
    assert!((3620.0..3650.0).contains(&first_s), "{verdict}");
    assert!(total_s > 0.0 && total_s < 71.0 - 10.0, "{verdict}");
}

/// The swing sensor stuck from 1 h: the controller finds it stuck and holds the reel in safe
/// hold, so the deployment stops short of the keep; the run's headline and verdict say the
/// mission stalled.
#[test]
fn a_stalled_mission_is_headlined_as_a_failure() {
    let (stdout, verdict, _) = fly(
        "paper-reel-limits.toml",
        &[
            "sensors.alpha_rate.enabled=false",
            "sensors.alpha.noise_std=1e-4",
            "sensors.seed=3",
            "sensors.alpha.stuck_from_s=3600",
            "sensors.alpha.stuck_until_s=1e9",
            "simulation.duration_s=21600",
        ],
    );
    let first = stdout.lines().next().unwrap_or_default();
    assert!(first.starts_with("verdict: FAILED"), "{stdout}");
    assert!(verdict.contains("\"passed\": false"), "{verdict}");
    assert!(verdict.contains("\"kind\": \"stalled\""), "{verdict}");
}

/// A run that does what it should says so, and says what it checked.
#[test]
fn a_run_without_failures_passes() {
    let (stdout, verdict, _) = fly("paper.toml", &["simulation.duration_s=3600"]);
    assert!(stdout.starts_with("verdict: passed"), "{stdout}");
    assert!(verdict.contains("\"passed\": true") && verdict.contains("\"failures\": []"));
}

/// A sensed length stuck at 1 km deploys the tether for ever: without the spool's bound it
/// pays out past the spool's 40 km and on. The run stops at the spool's end and says so.
#[test]
fn a_tether_paid_out_past_its_spool_stops_the_run_and_fails_it() {
    let (stdout, verdict, _) = fly(
        "paper.toml",
        &[
            "faults.corrupt=[{ sensor = \"length\", from_s = 0.0, until_s = 1e9, value = 1000.0 }]",
            "simulation.duration_s=40000",
        ],
    );
    assert!(stdout.starts_with("verdict: FAILED"), "{stdout}");
    assert!(stdout.contains("spool overrun"), "{stdout}");
    assert!(verdict.contains("\"kind\": \"spool_overrun\""), "{verdict}");
    let end: f64 = verdict
        .split("\"end_s\": ")
        .nth(1)
        .and_then(|r| r.split(',').next())
        .and_then(|x| x.parse().ok())
        .unwrap();
    assert!(end < 40_000.0, "the run went on to {end} s");
}

/// A motor reel's run does not say "injected: nothing (perfect sensors, ideal reel)": it names
/// the motor drum.
#[test]
fn a_motor_reel_is_not_called_an_ideal_reel() {
    let (_, _, faults) = fly("paper-elastic.toml", &["simulation.duration_s=60"]);
    assert!(!faults.contains("ideal reel"), "{faults}");
    assert!(faults.contains("reel: the motor drum"), "{faults}");
}

/// `reel.locked = true` pays out nothing, even while the lag drive would decay from l̇(0).
#[test]
fn a_locked_reel_with_a_lag_pays_out_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let o = Command::new(BIN)
        .arg("run")
        .arg(scenario("paper.toml"))
        .arg("--out")
        .arg(&out)
        .args(["--set", "reel.locked=true"])
        .args(["--set", "reel.lag_s=30"])
        .args(["--set", "initial.length_rate_mps=2"])
        .args(["--set", "simulation.duration_s=300"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let lengths: Vec<f64> = history
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert!(lengths.iter().all(|&l| l == lengths[0]), "{lengths:?}");
}
