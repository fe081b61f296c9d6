//! `tss-sim run` rejects a bad scenario file, key, value or output path with exit code 2, a
//! message naming the file, field and value, and without creating or writing anything.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_tss-sim");

fn paper() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml")
}

fn run(args: &[&str], cwd: &Path) -> Output {
    Command::new(BIN)
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("tss-sim runs")
}

/// Runs `tss-sim run <scenario> --out <tmp>/out <extra...>` and checks exit 2, nothing
/// written, and stderr containing every one of `expect`.
fn rejected(scenario: &Path, extra: &[&str], expect: &[&str]) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let mut args = vec![
        "run",
        scenario.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = run(&args, tmp.path());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: stderr {stderr}");
    assert!(!out.exists(), "{args:?} created {}", out.display());
    // Nothing at all was written, not even a default output directory.
    let left: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().collect();
    assert!(left.is_empty(), "{args:?} wrote {left:?}");
    for e in expect {
        assert!(stderr.contains(e), "{args:?}: stderr lacks {e:?}: {stderr}");
    }
    assert!(o.stdout.is_empty(), "{args:?} printed on stdout");
}

#[test]
fn a_missing_file_exits_2() {
    rejected(
        Path::new("/nonexistent/scenario.toml"),
        &[],
        &["/nonexistent/scenario.toml", "cannot read"],
    );
}

#[test]
fn a_file_that_is_not_toml_exits_2() {
    let tmp = tempfile::tempdir().unwrap();
    let bad = tmp.path().join("bad.toml");
    std::fs::write(&bad, "name = \n").unwrap();
    rejected(&bad, &[], &["bad.toml", "not valid TOML", "line 1"]);
}

#[test]
fn an_unknown_key_in_the_file_exits_2() {
    let tmp = tempfile::tempdir().unwrap();
    let bad = tmp.path().join("typo.toml");
    let text = std::fs::read_to_string(paper()).unwrap();
    std::fs::write(
        &bad,
        text.replace("band_start_m = 10_000.0", "band_strat_m = 10_000.0"),
    )
    .unwrap();
    rejected(
        &bad,
        &[],
        &["typo.toml", "unknown key `stage1.band_strat_m`"],
    );
}

#[test]
fn an_unknown_override_key_exits_2() {
    rejected(
        &paper(),
        &["--set", "stage1.band_start=5"],
        &["paper.toml", "unknown key `stage1.band_start`"],
    );
}

#[test]
fn a_malformed_override_exits_2() {
    rejected(&paper(), &["--set", "stage1.band_start_m"], &["key=value"]);
}

#[test]
fn an_override_of_the_wrong_type_exits_2() {
    rejected(
        &paper(),
        &["--set", "simulation.substeps=two"],
        &["simulation.substeps = \"two\" must be an integer"],
    );
}

#[test]
fn a_physically_invalid_value_exits_2() {
    rejected(
        &paper(),
        &["--set", "stage1.band_start_m=40000"],
        &["paper.toml: stage1.band_start_m = 40000 must be below stage1.keep_length_m = 30000"],
    );
    rejected(
        &paper(),
        &["--set", "masses.sub_kg=0", "-s", "initial.beta_rad=2"],
        &[
            "masses.sub_kg = 0 must be above 0",
            "initial.beta_rad = 2 must be within (−π/2, π/2)",
        ],
    );
    // A rule of the controller's own, checked with the scenario (exit 2, not a failed run).
    rejected(
        &paper(),
        &["-s", "orbit.eccentricity=0.8"],
        &["paper.toml: orbit.eccentricity = 0.8 must be in [0, 0.75)"],
    );
}

/// A run too long for the simulator (unchecked, it aborts on a 48 GB allocation) is a usage
/// error before any work.
#[test]
fn a_run_too_long_for_the_simulator_exits_2() {
    rejected(
        &paper(),
        &["--set", "simulation.duration_s=4294967295"],
        &["paper.toml: simulation.duration_s = 4294967295 is 4294967295 control periods, more than the simulator's 10000000"],
    );
}

#[test]
fn a_value_that_overflows_the_controllers_f32_exits_2() {
    rejected(
        &paper(),
        &["--set", "masses.main_initial_kg=1e308"],
        &["paper.toml: masses.main_initial_kg = 1e308 overflows the controller's f32"],
    );
}

#[test]
fn an_output_path_that_is_a_file_exits_2_and_is_left_alone() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("taken");
    std::fs::write(&file, "keep me").unwrap();
    let scenario = paper();
    let args = [
        "run",
        scenario.to_str().unwrap(),
        "--out",
        file.to_str().unwrap(),
    ];
    let o = run(&args, tmp.path());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("not a directory"), "{stderr}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep me");
    // Below a file: cannot be created either.
    let below = file.join("sub");
    let o = run(
        &[
            "run",
            paper().to_str().unwrap(),
            "--out",
            below.to_str().unwrap(),
        ],
        tmp.path(),
    );
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn bad_command_line_arguments_exit_2() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run(&["run"], tmp.path());
    assert_eq!(o.status.code(), Some(2));
    let o = run(&["run", paper().to_str().unwrap(), "--bogus"], tmp.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(std::fs::read_dir(tmp.path()).unwrap().next().is_none());
}

#[test]
fn a_file_larger_than_any_scenario_is_not_read_and_exits_2() {
    // The paper's scenario padded with comments past the bound: valid TOML, too large.
    let tmp = tempfile::tempdir().unwrap();
    let big = tmp.path().join("big.toml");
    let mut text = std::fs::read_to_string(paper()).unwrap();
    let line = "# padding\n";
    let max = tss_sim::scenario::MAX_SCENARIO_BYTES as usize;
    text.push_str(&line.repeat(max / line.len() + 1));
    std::fs::write(&big, text).unwrap();
    rejected(&big, &[], &["big.toml", "larger than 1048576 bytes"]);

    // A device that never ends is read no further than the bound (it hung before).
    let zero = Path::new("/dev/zero");
    if zero.exists() {
        let mut child = Command::new(BIN)
            .args(["run", "/dev/zero", "--out"])
            .arg(tmp.path().join("out"))
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("tss-sim runs");
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
        let status = loop {
            if let Some(status) = child.try_wait().unwrap() {
                break Some(status);
            }
            if std::time::Instant::now() > deadline {
                child.kill().unwrap();
                child.wait().unwrap();
                break None;
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        };
        assert_eq!(status.and_then(|s| s.code()), Some(2), "run /dev/zero");
    }
}

#[test]
fn a_gain_too_fast_for_the_control_period_exits_2_and_says_why() {
    // k1 = 1e30 once passed validation and flew a 4 m tether to a claimed "2 km at 8.000 h".
    rejected(
        &paper(),
        &["--set", "controller.k1_per_s=1e30"],
        &[
            "controller.k1_per_s = 1e30",
            "too fast for controller.period_s = 1 s",
            "Eq. 28",
        ],
    );
    rejected(
        &paper(),
        &["--set", "controller.period_s=1e-4"],
        &["controller.period_s", "must be at least 0.001 s"],
    );
}

fn scenario(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(file)
}

/// An orbit whose perigee is inside the atmosphere is refused: unchecked, a = 6 500 km (122 km
/// of altitude) flies, pays 819 km of tether off a 40 km spool, and reports success.
#[test]
fn an_orbit_inside_the_atmosphere_exits_2() {
    rejected(
        &paper(),
        &["--set", "orbit.semi_major_axis_m=6500000"],
        &["orbit.semi_major_axis_m = 6500000", "122 km", "150 km"],
    );
}

/// a ≥ 1e14 m is refused as the semi-major axis, once, and the eccentricity (0, valid) is not
/// named.
#[test]
fn a_semi_major_axis_beyond_the_earths_reach_blames_the_semi_major_axis() {
    for a in ["1e14", "1e10", "1e300"] {
        let tmp = tempfile::tempdir().unwrap();
        let set = format!("orbit.semi_major_axis_m={a}");
        let o = run(
            &[
                "run",
                paper().to_str().unwrap(),
                "--out",
                tmp.path().join("o").to_str().unwrap(),
                "--set",
                &set,
            ],
            tmp.path(),
        );
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{a}: {stderr}");
        assert!(stderr.contains("orbit.semi_major_axis_m"), "{a}: {stderr}");
        assert!(!stderr.contains("orbit.eccentricity ="), "{a}: {stderr}");
        assert_eq!(
            stderr.matches("orbit.semi_major_axis_m =").count(),
            1,
            "{a}: {stderr}"
        );
    }
}

/// `reel.inner_rate_hz` in 100–400 is refused by the flight drive's own rule, checked with the
/// scenario (not when the run starts) and named once, its message printed once.
#[test]
fn an_inner_rate_the_flight_drive_refuses_exits_2_naming_its_rule_once() {
    for hz in ["100", "200", "400"] {
        let tmp = tempfile::tempdir().unwrap();
        let set = format!("reel.inner_rate_hz={hz}");
        let o = run(
            &[
                "run",
                scenario("paper-drive.toml").to_str().unwrap(),
                "--out",
                tmp.path().join("o").to_str().unwrap(),
                "--set",
                &set,
            ],
            tmp.path(),
        );
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{hz}: {stderr}");
        assert_eq!(
            stderr.matches("reel.inner_rate_hz").count(),
            1,
            "{hz}: {stderr}"
        );
        assert!(stderr.contains("DriveConfig::validate"), "{hz}: {stderr}");
        assert!(!tmp.path().join("o").exists());
    }
}

/// Each of these would hang or abort the run; refused at once with exit 2 and the key.
#[test]
fn an_elastic_run_too_costly_to_fly_exits_2_naming_the_key() {
    rejected(
        &scenario("paper-elastic.toml"),
        &[
            "--set",
            "tether.segment_length_m=0.001",
            "--set",
            "tether.min_stiffness_length_m=0.001",
        ],
        &["tether.segment_length_m = 0.001", "MAX_ELASTIC_NODES"],
    );
    rejected(
        &scenario("paper-elastic.toml"),
        &["--set", "tether.axial_stiffness_n=1e18"],
        &["tether.axial_stiffness_n = 1e18", "MAX_ELASTIC_NODE_STEPS"],
    );
}
