//! Station keeping on eccentric orbits (issue 20 §1, docs/equations.md §16): the paper's mission
//! flown by the flight core (f32) on the rigid plant, with the librating reference. Before it
//! the law fought the orbit's forcing with the reel: at e = 0.1 (a = 7 800 km) the 30 km keep
//! erred by 1 711.8 m (the summary's Table-1 figure), at e = 0.3 (a = 10 000 km) by 4 762 m.

use std::path::{Path, PathBuf};
use std::process::Command;

use tss_sim::eccentric::{keep_row, sweep, KeepRow};
use tss_sim::scenario::Scenario;
use tss_sim::sim;
use tss_sim::table1::probe_times_for;

const BIN: &str = env!("CARGO_BIN_EXE_tss-sim");

fn paper() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml")
}

fn fly(sets: &[&str]) -> KeepRow {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let sc = Scenario::load(paper(), &sets).unwrap();
    let history = sim::run(&sc, &probe_times_for(&sc), &mut |_| {}).unwrap();
    keep_row(&sc, &history)
}

#[test]
fn at_e_0_1_both_keeps_hold_within_a_metre_and_the_mission_completes() {
    let r = fly(&["orbit.eccentricity=0.1", "orbit.semi_major_axis_m=7800000"]);
    // The summary's Table-1 figures (max |simulated − paper|): 0.33 m and 0.17 m.
    assert!(r.table1_stage1_m < 1.0, "{r:?}");
    assert!(r.table1_stage2_m < 1.0, "{r:?}");
    // The keep error proper, max |l − 30 km| over 7–8 h: 0.37 m.
    assert!(r.keep1_error_m < 1.0, "{r:?}");
    assert!(
        r.completed && (r.final_length_m - 2000.0).abs() < 0.01,
        "{r:?}"
    );
    // Taut once the paper's start-up transient is over (docs/equations.md §16.6: it dips to
    // −1.0e-4 N at l ≈ 25 m in the first 0.33 h, as it nearly does on the circular orbit).
    assert!(r.last_slack_s.is_nan() || r.last_slack_s < 1800.0, "{r:?}");
}

#[test]
fn at_e_0_3_the_keeps_hold_within_the_stated_figures() {
    // On the paper's timeline the 30 km keep has not settled by 7 h at a = 10 000 km (the
    // orbit is 1.7 times slower): 7.2 m and 1.2 m (Table 1), 4 762 m and 578 m before.
    let r = fly(&["orbit.eccentricity=0.3", "orbit.semi_major_axis_m=10000000"]);
    assert!(r.table1_stage1_m < 8.0, "{r:?}");
    assert!(r.table1_stage2_m < 1.5, "{r:?}");
    assert!(
        r.completed && (r.final_length_m - 2000.0).abs() < 0.01,
        "{r:?}"
    );
}

#[test]
fn given_time_to_settle_every_keep_holds_to_a_centimetre_up_to_e_0_3() {
    // Stage 2 at 16 h, 32 h in all: the keeps' last hours.
    let sets = [
        "orbit.semi_major_axis_m=10000000",
        "stage2.start_time_s=57600",
        "simulation.duration_s=115200",
    ]
    .map(String::from);
    for r in sweep(&paper(), &sets, &[0.05, 0.2, 0.3]).unwrap() {
        assert!(r.keep1_error_m < 0.01, "{r:?}");
        assert!(r.keep2_error_m < 0.01, "{r:?}");
        assert!(r.completed, "{r:?}");
    }
}

#[test]
fn eccentric_writes_its_table_csv_and_figure() {
    let dir = std::env::temp_dir().join(format!("tss-eccentric-{}", std::process::id()));
    let out = Command::new(BIN)
        .args(["-q", "eccentric"])
        .arg(paper())
        .args([
            "--eccentricity",
            "0,0.1",
            "--set",
            "orbit.semi_major_axis_m=7800000",
        ])
        .arg("--out")
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.join("eccentric.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    assert!(csv.starts_with("eccentricity,semi_major_axis_m,keep1_error_m"));
    let png = std::fs::read(dir.join("eccentric_keep_error.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert!(dir.join("eccentric.txt").is_file() && dir.join("eccentric_keep_error.svg").is_file());
    std::fs::remove_dir_all(&dir).unwrap();
    // A bad eccentricity is a usage error (exit 2), before anything is flown.
    let bad = Command::new(BIN)
        .args(["-q", "eccentric"])
        .arg(paper())
        .args(["--eccentricity", "0.9"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
}
