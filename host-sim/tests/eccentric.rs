//! Station keeping on eccentric orbits (docs/equations.md §16): the paper's mission flown by the
//! flight core (f32) on the rigid plant, with the librating reference and the tension
//! protection (§14, its free tension on the orbit's μ/R³: §16.7). Without the librating
//! reference the law fights the orbit's forcing with the reel: at e = 0.1 (a = 7 800 km) the
//! 30 km keep errs by 1 711.8 m (the summary's Table-1 figure), at e = 0.3 (a = 10 000 km) by
//! 4 762 m. With a circular orbit's θ̇² in place of μ/R³ the protected missions go slack
//! (e = 0.1) or dock (e = 0.3); without the protection the paper's law goes slack (O-10).

use std::path::{Path, PathBuf};
use std::process::Command;

use tss_sim::eccentric::{keep_row, sweep, KeepRow};
use tss_sim::scenario::Scenario;
use tss_sim::sim;
use tss_sim::table1::probe_times_for;

const BIN: &str = env!("CARGO_BIN_EXE_tss-sim");

fn scenario(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(name)
}

fn paper() -> PathBuf {
    scenario("paper.toml")
}

fn fly(path: &Path, sets: &[&str]) -> KeepRow {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let sc = Scenario::load(path, &sets).unwrap();
    let history = sim::run(&sc, &probe_times_for(&sc), &mut |_| {}).unwrap();
    keep_row(&sc, &history)
}

/// Taut from the first sample after the start to the end: no sample at T ≤ 0.
fn taut(r: &KeepRow) -> bool {
    r.min_tension_n > 0.0 && r.slack_samples == 0
}

#[test]
fn at_e_0_1_both_keeps_hold_within_a_metre_the_mission_completes_and_the_tether_is_taut() {
    let r = fly(
        &paper(),
        &[
            "orbit.eccentricity=0.1",
            "orbit.semi_major_axis_m=7800000",
            "protection.enabled=true",
        ],
    );
    // The summary's Table-1 figures (max |simulated − paper|): 0.33 m and 0.14 m.
    assert!(r.table1_stage1_m < 1.0, "{r:?}");
    assert!(r.table1_stage2_m < 1.0, "{r:?}");
    // The keep error proper, max |l − 30 km| over 7–8 h: 0.37 m.
    assert!(r.keep1_error_m < 1.0, "{r:?}");
    assert!(
        r.completed && (r.final_length_m - 2000.0).abs() < 0.01,
        "{r:?}"
    );
    // Least 1.4 mN (the paper's law alone: −1.0e-4 N in its start-up, docs/equations.md §16.6).
    assert!(taut(&r), "{r:?}");
}

#[test]
fn at_e_0_1_the_saturated_slew_hand_over_stays_taut() {
    // The flight scenario's timeline at the paper's slew rate (faster than this orbit's θ̇
    // allows): the slew saturates the rate at −15 m/s and hands over to a law asking for
    // +5.7 m/s. With θ̇² for μ/R³ the protection misjudged the free tension by 2.5 % and let
    // the hand-over's braking slacken the tether (−0.149 N at 16.24 h); the paper's law
    // alone: −1.48e3 N.
    let r = fly(
        &scenario("paper-eccentric.toml"),
        &["orbit.eccentricity=0.1", "stage2.slew_rate_radps=6.2932e-4"],
    );
    assert!(taut(&r), "{r:?}");
    assert!(r.keep1_error_m < 0.02 && r.keep2_error_m < 0.02, "{r:?}");
    assert!(r.completed, "{r:?}");
}

#[test]
fn at_e_0_3_the_flight_scenario_retrieves_to_the_2_km_keep_taut() {
    // scenarios/paper-eccentric.toml as it stands (e = 0.3, protection on): keeps within 1.2 cm
    // and 0.4 cm, least tension 0.70 mN. With θ̇² for μ/R³ the retrieval overshoots the 2 km
    // keep near apogee, the law faults, and the safe hold, on a stale free tension below T_min,
    // winds the tether in to docking (0.5 m).
    let r = fly(&scenario("paper-eccentric.toml"), &[]);
    assert_eq!(r.eccentricity, 0.3);
    assert!(r.keep1_error_m < 0.02, "{r:?}");
    assert!(r.keep2_error_m < 0.02, "{r:?}");
    assert!(
        r.completed && (r.final_length_m - 2000.0).abs() < 0.01,
        "{r:?}"
    );
    assert!(taut(&r), "{r:?}");
}

#[test]
fn on_the_papers_timeline_at_e_0_3_the_keeps_hold_within_the_stated_figures() {
    // On the paper's timeline the 30 km keep has not settled by 7 h at a = 10 000 km (the
    // orbit is 1.7 times slower, and the protection brakes the early pay-out): Table 1
    // 32.4 m and 0.89 m (the paper's law alone 7.2 m and 1.2 m, slack at 9.98 h; 4 762 m and
    // 578 m before the librating reference).
    let r = fly(
        &paper(),
        &[
            "orbit.eccentricity=0.3",
            "orbit.semi_major_axis_m=10000000",
            "protection.enabled=true",
        ],
    );
    assert!(r.table1_stage1_m < 35.0, "{r:?}");
    assert!(r.table1_stage2_m < 1.0, "{r:?}");
    assert!(
        r.completed && (r.final_length_m - 2000.0).abs() < 0.01,
        "{r:?}"
    );
    assert!(taut(&r), "{r:?}");
}

#[test]
fn given_time_to_settle_every_keep_holds_to_two_centimetres_taut_up_to_e_0_3() {
    // scenarios/paper-eccentric.toml: stage 2 at 16 h, 32 h in all, the protection on.
    for r in sweep(
        &scenario("paper-eccentric.toml"),
        &[],
        &[0.0, 0.05, 0.2, 0.25],
    )
    .unwrap()
    {
        assert!(r.keep1_error_m < 0.02, "{r:?}");
        assert!(r.keep2_error_m < 0.02, "{r:?}");
        assert!(r.completed, "{r:?}");
        assert!(taut(&r), "{r:?}");
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

/// `eccentric scenarios/paper-eccentric.toml` writes to out/paper-eccentric/eccentric (not
/// out/paper-eccentric-eccentric), and its table has no "Table 1 stage 2" column: the
/// scenario's stage 2 starts at 16 h, not at the paper's 8 h, so Table 1's stage-2 instants
/// (14–15 h) fall in the stage-1 keep and such a column would mean nothing.
#[test]
fn eccentric_writes_beside_the_scenario_s_runs_without_a_meaningless_column() {
    let tmp = tempfile::tempdir().unwrap();
    let out = Command::new(BIN)
        .args(["-q", "eccentric"])
        .arg(scenario("paper-eccentric.toml"))
        .args(["--eccentricity", "0"])
        .args(["--set", "simulation.duration_s=28800"])
        .current_dir(tmp.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let dir = tmp
        .path()
        .join("out/paper-eccentric+simulation.duration_s=28800/eccentric");
    let table = std::fs::read_to_string(dir.join("eccentric.txt")).unwrap();
    assert!(table.contains("Table 1 stage 1"), "{table}");
    assert!(!table.contains("stage 2"), "{table}");
    // With the paper's stage 2 (at 8 h) the column is there.
    let r = fly(&paper(), &["simulation.duration_s=54000"]);
    assert!(r.table1_stage2_m.is_finite(), "{r:?}");
    let r = fly(
        &paper(),
        &["simulation.duration_s=54000", "stage2.start_time_s=30000"],
    );
    assert!(r.table1_stage2_m.is_nan(), "{r:?}");
}
