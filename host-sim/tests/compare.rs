//! The classic laws beside the paper's: `[controller] law`, the tension laws in the closed loop
//! on both plants, and `tss-sim compare`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use tss_sim::history::History;
use tss_sim::scenario::{LawName, Scenario};
use tss_sim::sim;

const BIN: &str = env!("CARGO_BIN_EXE_tss-sim");

fn scenario_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../scenarios/{name}.toml"))
}

fn load(name: &str, set: &[&str]) -> Scenario {
    let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    Scenario::load(scenario_path(name), &set).unwrap()
}

fn fly(sc: &Scenario) -> History {
    sim::run(sc, &[], &mut |_| {}).unwrap()
}

fn tss_sim(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("tss-sim runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// The first time l ≥ `level`, s.
fn first_at_least(h: &History, level: f64) -> Option<f64> {
    h.samples
        .iter()
        .find(|x| x.length_m >= level)
        .map(|x| x.t_s)
}

/// Rupp's law started on the local vertical (the TM's subject) with a push (α(0) = 0, 10 m at
/// 3 m/s), deploys to 30 km and holds it; the tension never goes below its floor.
#[test]
fn rupps_law_deploys_from_a_vertical_start_and_keeps() {
    let sc = load(
        "paper",
        &[
            r#"controller.law="rupp""#,
            "initial.delta_rad=0.7853981633974483",
            "initial.length_m=10",
            "initial.length_rate_mps=3",
            "simulation.duration_s=28800",
        ],
    );
    let h = fly(&sc);
    let reached = first_at_least(&h, 29_999.5).expect("reaches 30 km");
    assert!(reached < 2.0 * 3600.0, "{reached}");
    // The keep: within 3 m of 30 km over the last hour (7–8 h).
    let worst = h
        .samples
        .iter()
        .filter(|x| x.t_s >= 7.0 * 3600.0)
        .map(|x| (x.length_m - 30_000.0).abs())
        .fold(0.0, f64::max);
    assert!(worst < 3.0, "{worst}");
    assert!(h.faults.min_tension_n.0 >= 0.0);
    assert!(h.samples.iter().all(|x| x.tension_n >= 0.0));
}

/// From the paper's start (1 m at 0.1 m/s, 10° off α_r) Rupp's law commands no tension
/// (T_c < 0 until l̇ > Ω l_f (a − c)/b ≈ 16 m/s), and the free sub-satellite, turned by the
/// Coriolis force, never gets beyond 5 km in stage 1: the paper's law is what deploys it.
#[test]
fn rupps_law_does_not_deploy_from_the_papers_start() {
    let sc = load(
        "paper",
        &[r#"controller.law="rupp""#, "simulation.duration_s=28800"],
    );
    let h = fly(&sc);
    let max_l = h.samples.iter().map(|x| x.length_m).fold(0.0, f64::max);
    assert!(max_l < 5_000.0, "{max_l}");
    let paper = fly(&load("paper", &["simulation.duration_s=28800"]));
    assert!(first_at_least(&paper, 29_999.5).is_some());
}

/// The tracking law flies the paper's whole mission without ever commanding slack (its floor
/// 0.01 N is the smallest tension), reaches 30 km and ends at 2 km.
#[test]
fn the_tracking_law_flies_the_papers_mission_taut() {
    let sc = load("paper", &[r#"controller.law="tracking""#]);
    let h = fly(&sc);
    assert!(
        h.faults.min_tension_n.0 >= 0.01 - 1e-12,
        "{:?}",
        h.faults.min_tension_n
    );
    assert_eq!(h.faults.slack_events, 0);
    let reached = first_at_least(&h, 29_999.5).expect("reaches 30 km");
    assert!(reached < 7.0 * 3600.0, "{reached}");
    let last = h.samples.last().unwrap();
    assert!((last.length_m - 2_000.0).abs() < 1.0, "{}", last.length_m);
}

/// Sensor faults reach a tension law as they reach the paper's: a dropout holds the last
/// tension (health Degraded), corrupted (NaN) readings are held over too, and noise changes
/// the run.
#[test]
fn faults_reach_the_tension_laws() {
    let faults = [
        r#"controller.law="tracking""#,
        "simulation.duration_s=7200",
        "simulation.output_interval_s=1",
    ];
    let clean = fly(&load("paper", &faults));
    let mut with_faults = faults.map(String::from).to_vec();
    with_faults.extend([
        "faults.dropout=[{from_s=3000.0, until_s=3060.0}]".to_string(),
        r#"faults.corrupt=[{sensor="length", from_s=4000.0, until_s=4005.0, value=nan}]"#
            .to_string(),
    ]);
    let sc = Scenario::load(scenario_path("paper"), &with_faults).unwrap();
    let h = fly(&sc);
    let held = |from: f64, until: f64| {
        let t: Vec<f64> = h
            .samples
            .iter()
            .filter(|x| x.t_s >= from && x.t_s < until)
            .map(|x| x.tension_n)
            .collect();
        assert!(t.len() > 3);
        assert!(t.iter().all(|&v| v == t[0]), "{from}: {t:?}");
    };
    held(3000.0, 3060.0);
    held(4000.0, 4005.0);
    assert!(h.faults.degraded_s >= 65.0, "{}", h.faults.degraded_s);
    assert!(h.samples.iter().all(|x| x.tension_n.is_finite()));
    let noisy = fly(&load(
        "paper",
        &[&faults[..], &["sensors.length.noise_std=0.01"]].concat(),
    ));
    let differ = clean
        .samples
        .iter()
        .zip(&noisy.samples)
        .any(|(a, b)| a.tension_n != b.tension_n);
    assert!(differ);
}

/// On the elastic truth model a tension law drives the drum motor's torque (friction
/// compensated, breakaway included): the tether pays out under the gravity gradient over the
/// first hour of the paper's mission, on another path than the paper's rate command; without
/// the breakaway compensation the drum sticks in the first minutes (0.8 N of breakaway at the
/// tether against 0.01 N of gravity-gradient tension near 30 m).
#[test]
fn a_tension_law_drives_the_elastic_plants_drum() {
    let sc = load(
        "paper-elastic",
        &[r#"controller.law="tracking""#, "simulation.duration_s=3600"],
    );
    let h = fly(&sc);
    let last = h.samples.last().unwrap();
    assert!(last.length_m > 50.0, "{}", last.length_m);
    assert!(h.samples.iter().all(|x| x.tension_n.is_finite()));
    let paper = fly(&load("paper-elastic", &["simulation.duration_s=3600"]));
    assert_ne!(paper.samples.last().unwrap().length_m, last.length_m);
}

/// A tension law on the elastic plant needs the drum motor; the scenario says so.
#[test]
fn a_tension_law_on_the_elastic_plant_needs_the_motor_reel() {
    let set = [
        r#"controller.law="rupp""#.to_string(),
        r#"reel.model="drive""#.to_string(),
    ];
    let e = Scenario::load(scenario_path("paper-elastic"), &set).unwrap_err();
    assert!(e.to_string().contains("controller.law"), "{e}");
    // Gains outside the linear loop's stability are refused.
    let e = Scenario::load(
        scenario_path("paper"),
        &["controller.rupp.length_gain=2.5".to_string()],
    )
    .unwrap_err();
    assert!(e.to_string().contains("controller.rupp.length_gain"), "{e}");
}

#[test]
fn compare_writes_one_table_and_the_figure() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("c");
    let o = tss_sim(&[
        "compare",
        scenario_path("seds2").to_str().unwrap(),
        "--laws",
        "paper,rupp,tracking",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let table = text(&o.stdout);
    for law in ["paper", "rupp", "tracking"] {
        assert!(table.contains(law), "{table}");
    }
    for f in ["compare.txt", "compare.csv", "compare.png", "compare.svg"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    assert!(!out.join("compare_runs.csv").exists());
    let csv = std::fs::read_to_string(out.join("compare.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 4, "{csv}");
    assert!(rows[0].starts_with("law,set,t_target_h,overshoot_m,max_libration_deg"));
    // The paper's law on SEDS-2: at the keep within 2.5 h, libration after arrival below 4°.
    let paper: Vec<&str> = rows[1].split(',').collect();
    assert_eq!(&paper[..2], &["paper", "nominal"]);
    let t_h: f64 = paper[2].parse().unwrap();
    let after_deg: f64 = paper[5].parse().unwrap();
    assert!(t_h > 2.0 && t_h < 2.5, "{t_h}");
    assert!(after_deg < 4.0, "{after_deg}");
    // The same scenario flown by `run` with the law set gives the same nominal history.
    let run_out = tmp.path().join("r");
    let o = tss_sim(&[
        "run",
        scenario_path("seds2").to_str().unwrap(),
        "-q",
        "-o",
        run_out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
}

#[test]
fn compare_with_runs_flies_every_law_on_the_same_campaign() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("m");
    let o = tss_sim(&[
        "compare",
        scenario_path("paper-montecarlo").to_str().unwrap(),
        "--laws",
        "paper,tracking",
        "--runs",
        "3",
        "--seed",
        "7",
        "-q",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "simulation.duration_s=3600",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(o.stdout.is_empty());
    let runs = std::fs::read_to_string(out.join("compare_runs.csv")).unwrap();
    let lines: Vec<&str> = runs.lines().skip(1).collect();
    assert_eq!(lines.len(), 6, "{runs}");
    for (law, first) in [("paper", 0), ("tracking", 3)] {
        for i in 0..3 {
            assert!(
                lines[first + i].starts_with(&format!("{law},{i},true,")),
                "{}",
                lines[first + i]
            );
        }
    }
    let table = std::fs::read_to_string(out.join("compare.csv")).unwrap();
    assert!(table.contains("paper,median,") && table.contains("tracking,median,"));
}

#[test]
fn compare_refuses_bad_arguments_with_exit_code_2() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("x");
    let seds2 = scenario_path("seds2");
    let cases: [(&[&str], &str); 4] = [
        (&["--laws", "paper,kissel"], "unknown law"),
        (&["--runs", "0"], "--runs"),
        (&["--runs", "2"], "no [[montecarlo.dispersion]]"),
        (&["--set", "controller.rupp.rate_gain=-1"], "rate_gain"),
    ];
    for (extra, expect) in cases {
        let mut args = vec![
            "compare",
            seds2.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = tss_sim(&args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", text(&o.stderr));
        assert!(
            text(&o.stderr).contains(expect),
            "{extra:?}: {}",
            text(&o.stderr)
        );
        assert!(!out.join("compare.csv").exists());
    }
    let o = tss_sim(&["compare", "no/such/scenario.toml"]);
    assert_eq!(o.status.code(), Some(2));
    // A tension law on the elastic plant without the drum motor: refused before any run.
    let o = tss_sim(&[
        "compare",
        scenario_path("paper-elastic").to_str().unwrap(),
        "--laws",
        "paper,rupp",
        "--set",
        r#"reel.model="drive""#,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("motor"), "{}", text(&o.stderr));
}

/// `law` names round-trip and the default is the paper's.
#[test]
fn the_default_law_is_the_papers() {
    assert_eq!(load("paper", &[]).controller.law, LawName::Paper);
    for l in LawName::ALL {
        assert_eq!(LawName::parse(l.as_str()), Some(l));
    }
}

/// `run --pil` flies the flight firmware, whose law is the paper's: a simulator law is refused
/// before QEMU starts (exit 2).
#[test]
fn pil_refuses_a_simulator_law() {
    let tmp = tempfile::tempdir().unwrap();
    let elf = tmp.path().join("fw.elf");
    std::fs::write(&elf, b"not run").unwrap();
    let o = tss_sim(&[
        "run",
        scenario_path("paper").to_str().unwrap(),
        "--pil",
        "--firmware",
        elf.to_str().unwrap(),
        "--set",
        r#"controller.law="rupp""#,
        "-o",
        tmp.path().join("o").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("controller.law"),
        "{}",
        text(&o.stderr)
    );
}

/// `tss-sim montecarlo` flies the scenario's law: the same campaign with the tracking law has
/// the tracking law's outcomes (never slack: its floor), where the paper's law's differ.
#[test]
fn montecarlo_flies_the_scenarios_law() {
    let tmp = tempfile::tempdir().unwrap();
    let sc = scenario_path("paper-montecarlo");
    let run = |law: &str, dir: &Path| {
        let set = format!("controller.law=\"{law}\"");
        let o = tss_sim(&[
            "montecarlo",
            sc.to_str().unwrap(),
            "--runs",
            "2",
            "--seed",
            "3",
            "--no-figures",
            "-q",
            "--out",
            dir.to_str().unwrap(),
            "--set",
            "simulation.duration_s=7200",
            "--set",
            &set,
        ]);
        assert!(o.status.success(), "{law}: {}", text(&o.stderr));
        std::fs::read_to_string(dir.join("runs.csv")).unwrap()
    };
    let tracking = run("tracking", &tmp.path().join("t"));
    let paper = run("paper", &tmp.path().join("p"));
    assert_ne!(tracking, paper);
    let header: Vec<&str> = tracking.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "min_tension_n").unwrap();
    for row in tracking.lines().skip(1) {
        let t: f64 = row.split(',').nth(col).unwrap().parse().unwrap();
        assert!(t >= 0.01 - 1e-12, "{row}");
    }
}

/// Rupp's keep against its linear analysis (docs/equations.md §15.1): from 100 m beyond 30 km at
/// rest on the local vertical, the length error decays at the slowest root of
/// s⁴ + b s³ + (a + 4) s² + 3b s + 3(a − 3) (in units of the orbit rate n), to within 25 %
/// (a least-squares fit of ln max|l − l_f| over 3000 s windows from 3000 to 18 000 s; the
/// faster pair of roots and the windows' sampling of the oscillation make up the rest).
#[test]
fn rupps_keep_decays_at_its_linear_loops_slowest_root() {
    let (a, b) = (4.0, 2.0);
    // The roots: eigenvalues of the companion matrix.
    let companion = nalgebra::Matrix4::new(
        0.0,
        1.0,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
        -3.0 * (a - 3.0),
        -3.0 * b,
        -(a + 4.0),
        -b,
    );
    let slowest = companion
        .complex_eigenvalues()
        .iter()
        .map(|z| z.re)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(slowest < 0.0);
    let sc = load(
        "paper",
        &[
            r#"controller.law="rupp""#,
            "initial.delta_rad=-0.0031415926535897933", // α(0) = 0
            "initial.length_m=30100",
            "initial.length_rate_mps=0",
            "simulation.duration_s=18000",
            "stage2.start_time_s=30000",
        ],
    );
    let n = tss_reel::orbit::Orbit::<f64>::circular(sc.orbit.semi_major_axis_m).mean_motion_radps();
    let h = fly(&sc);
    let windows: Vec<(f64, f64)> = (1..6)
        .map(|w| {
            let (t0, t1) = (3000.0 * f64::from(w), 3000.0 * f64::from(w + 1));
            let worst = h
                .samples
                .iter()
                .filter(|x| x.t_s >= t0 && x.t_s < t1)
                .map(|x| (x.length_m - 30_000.0).abs())
                .fold(0.0, f64::max);
            (t0, worst.ln())
        })
        .collect();
    let k = windows.len() as f64;
    let (mx, my) = (
        windows.iter().map(|p| p.0).sum::<f64>() / k,
        windows.iter().map(|p| p.1).sum::<f64>() / k,
    );
    let slope = windows.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / windows.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    let expect = slowest * n;
    assert!(
        (slope / expect - 1.0).abs() < 0.25,
        "decay {slope:e}/s, linear analysis {expect:e}/s"
    );
}

/// On the elastic plant a tension the drum motor cannot hold (T·r beyond its torque limit) is
/// reported as the reel's saturation, as a rate the speed loop cannot follow is; the speed
/// loop's demand is not (it does not run under a tension command).
#[test]
fn a_tension_beyond_the_motors_torque_is_reported_as_saturation() {
    let fly_with = |torque: &str| {
        let sc = load(
            "paper-elastic",
            &[
                r#"controller.law="tracking""#,
                "simulation.duration_s=600",
                &format!("reel.motor_max_torque_nm={torque}"),
            ],
        );
        fly(&sc).faults.reel_accel_saturated_ticks
    };
    // The floor 0.01 N on a 0.1 m drum needs 0.001 N·m; the first 600 s need well below
    // 0.02 N·m (the speed loop's friction hold, 0.051 N·m, is not what a tension law asks).
    assert!(fly_with("0.0005") > 500);
    assert_eq!(fly_with("0.02"), 0);
    assert_eq!(fly_with("2.0"), 0);
}
