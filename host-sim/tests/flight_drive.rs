//! The flight speed loop in the elastic closed loop: `reel.model =
//! "flight_drive"` flies `tss_reel::reel_drive::SpeedLoop` at 1 kHz against the truth model's
//! drum, the tether loaded by the drum's actual motion; the summary reports its tracking,
//! saturation, faults and the tension at the reel. A short window of the paper's mission
//! (`scenarios/paper-drive.toml`), the first two minutes of deployment.

use std::path::Path;

use tss_sim::plant::DriveFigures;
use tss_sim::report::summarize;
use tss_sim::scenario::Scenario;

/// The first `duration_s` of the paper's mission with the flight drive, with `set` overrides:
/// the summary's text and the drive's figures.
fn fly(duration_s: f64, set: &[&str]) -> (String, DriveFigures, Scenario) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper-drive.toml");
    let mut sets = vec![format!("simulation.duration_s={duration_s}")];
    sets.extend(set.iter().map(|s| s.to_string()));
    let sc = Scenario::load(path, &sets).expect("paper-drive loads");
    let history = tss_sim::sim::run(&sc, &[], &mut |_| {}).expect("the mission flies");
    let summary = summarize(&sc, &history);
    let drive = summary.drive.expect("the flight drive reports its figures");
    (summary.render(), drive, sc)
}

#[test]
fn the_summary_reports_the_flight_drive() {
    let (text, d, _) = fly(120.0, &[]);
    for line in [
        "flight drive tracking error: RMS",
        "flight drive duty saturation:",
        "flight drive faults seen: none",
        "flight drive tension at the reel (N): min",
    ] {
        assert!(text.contains(line), "missing {line:?} in\n{text}");
    }
    // 1 kHz for 120 s, the brake lifting in the first ticks.
    assert_eq!(d.ticks, 120_000);
    assert!(d.released_ticks > 119_000, "{d:?}");
}

/// Inside the motor's torque (r·T_max = 0.1 m × 0.04 N of the 2 N·m motor) the loop tracks
/// its reference to well under a millimetre per second and never saturates; a motor weaker
/// than the drum's breakaway friction (0.06 N·m < 0.08 N·m) cannot spin it up: the drive stalls
/// (`MotorStall`, tripped: brake on, motor off) before the mission starts and never releases.
#[test]
fn tracking_and_saturation_follow_the_motor_torque() {
    let (_, strong, sc) = fly(120.0, &[]);
    let r = sc.reel.drum_radius_m;
    assert!(r * strong.tension_range_n.1 < sc.reel.motor_max_torque_nm);
    assert_eq!(strong.saturated_ticks, 0, "{strong:?}");
    assert!(strong.rms_error_mps() < 5e-4, "{strong:?}");
    assert!(strong.max_error_mps < 5e-3, "{strong:?}");
    assert_eq!(strong.fault_bits, 0);

    let (_, weak, sc) = fly(120.0, &["reel.motor_max_torque_nm=0.06"]);
    assert!(sc.reel.motor_max_torque_nm < sc.reel.static_nm);
    let stall = tss_reel::reel_drive::DriveFault::MotorStall as u16;
    assert_eq!(weak.fault_bits, 1 << stall, "{weak:?}");
    assert_eq!(weak.released_ticks, 0, "{weak:?}");
}

/// A drive trip reaches the outer controller's health, as on the board: the controller goes
/// to safe hold in the period after the trip and stays there (the trip is never cleared), and
/// the summary names the fault.
#[test]
fn a_drive_trip_puts_the_outer_controller_in_safe_hold() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper-drive.toml");
    let sets = [
        "simulation.duration_s=60".to_string(),
        "reel.motor_max_torque_nm=0.06".to_string(),
    ];
    let sc = Scenario::load(path, &sets).expect("paper-drive loads");
    let h = tss_sim::sim::run(&sc, &[], &mut |_| {}).expect("the mission flies");
    let f = &h.faults;
    assert_eq!(
        f.final_health,
        Some(tss_reel::controller::Health::SafeHold),
        "{f:?}"
    );
    assert!(f.safe_hold_s >= 55.0, "{} s of safe hold", f.safe_hold_s);
    let text = summarize(&sc, &h).render();
    assert!(!text.contains("faults raised: none"), "{text}");
}

/// The reel pays out at l̇(0) when the sub-satellite leaves (the drive spun up before t = 0,
/// `FlightDrum::spin_up`), so the tether stays taut: the separation follows the paid-out
/// length and the tension stays positive. (Started braked, the drum held the tether for the
/// brake's release and the ramp from rest: 7.4 N at the reel within the first second sent the
/// sub-satellite back, and the tether was slack from t = 2 s on.)
#[test]
fn the_reel_pays_out_at_the_initial_rate_and_the_tether_stays_taut() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper-drive.toml");
    let sets = ["simulation.duration_s=120".to_string()];
    let sc = Scenario::load(path, &sets).expect("paper-drive loads");
    let h = tss_sim::sim::run(&sc, &[], &mut |_| {}).expect("the mission flies");
    assert_eq!(h.samples.len(), h.elastic.len());
    for (s, e) in h.samples.iter().zip(&h.elastic).skip(1) {
        assert!(s.tension_n > 0.0, "slack at {} s: {s:?}", s.t_s);
        assert!(
            (e.range_m - s.length_m).abs() < 1e-3 * s.length_m,
            "at {} s: range {} m, length {} m",
            s.t_s,
            e.range_m,
            s.length_m
        );
    }
    let first = &h.elastic[0];
    assert!(
        (first.reel_rate_mps - sc.initial.length_rate_mps).abs() < 2e-3,
        "{first:?}"
    );
}

/// The drum's motion acts on the tether: the same window with the drive's motor weakened pays
/// out a different length (not only a side computation).
#[test]
fn the_drum_motion_reaches_the_tether() {
    let length = |set: &[&str]| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper-drive.toml");
        let mut sets = vec!["simulation.duration_s=120".to_string()];
        sets.extend(set.iter().map(|s| s.to_string()));
        let sc = Scenario::load(path, &sets).expect("paper-drive loads");
        let h = tss_sim::sim::run(&sc, &[], &mut |_| {}).expect("the mission flies");
        h.samples.last().expect("samples").length_m
    };
    let nominal = length(&[]);
    let weak = length(&["reel.motor_max_torque_nm=0.06"]);
    assert!((nominal - weak).abs() > 0.1, "{nominal} vs {weak}");
}

#[test]
fn the_inner_rate_is_validated() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper-drive.toml");
    let err = Scenario::load(path, &["reel.inner_rate_hz=50".to_string()])
        .expect_err("50 Hz is below the 100 Hz floor");
    assert!(format!("{err:#}").contains("reel.inner_rate_hz"), "{err:#}");
}

/// `tss-sim run` on paper-drive writes the drive's summary lines and its figure (drum rate vs
/// command, duty) with the run's others.
#[test]
fn a_run_writes_the_drive_figure_and_summary() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("drive");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper-drive.toml");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_tss-sim"))
        .args(["run", "-q", scenario.to_str().unwrap(), "--out"])
        .arg(&out)
        .args(["--set", "simulation.duration_s=60"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["flight_drive.png", "flight_drive.svg"] {
        assert!(out.join(f).metadata().unwrap().len() > 1000, "{f}");
    }
    let svg = std::fs::read_to_string(out.join("flight_drive.svg")).unwrap();
    assert!(svg.contains("speed-loop duty"), "the duty panel");
    let summary = std::fs::read_to_string(out.join("summary.txt")).unwrap();
    assert!(
        summary.contains("flight drive duty saturation: 0 ticks"),
        "{summary}"
    );
}
