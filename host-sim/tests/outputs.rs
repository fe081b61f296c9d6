//! `tss-sim run` writes history.csv, table1.csv, summary.txt, scenario.toml and Figs. 4–6
//! (PNG and SVG); the library writes the same from a synthetic history.

use std::path::{Path, PathBuf};
use std::process::Command;

use tss_sim::history::{History, PhaseLabel, Sample};
use tss_sim::output::{history_header, read_history_csv};
use tss_sim::run_cmd::{run_with, RunArgs};
use tss_sim::table1::{PAPER_TABLE1, PROBE_TIMES_S, TABLE1_CSV_HEADER};

const BIN: &str = env!("CARGO_BIN_EXE_tss-sim");
const HEADER: &str = "t_s,length_m,length_rate_mps,alpha_rad,alpha_ref_rad,delta_rad,\
                      delta_rate_radps,beta_rad,tension_n,phase,alpha_rate_radps,\
                      length_accel_mps2,law_rate_mps,blend_weight,flags";
const FIGURES: [&str; 6] = [
    "fig4_length_tension.png",
    "fig4_length_tension.svg",
    "fig5_angles_time.png",
    "fig5_angles_time.svg",
    "fig6_angles_length.png",
    "fig6_angles_length.svg",
];

fn paper() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml")
}

/// Checks every output file of a run in `dir`; returns the history.csv rows.
fn check_outputs(dir: &Path) -> Vec<csv::StringRecord> {
    for f in ["history.csv", "table1.csv", "summary.txt", "scenario.toml"] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    for f in FIGURES {
        let bytes = std::fs::read(dir.join(f)).unwrap();
        if f.ends_with(".png") {
            assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{f} is not a PNG");
            assert!(bytes.len() > 10_000, "{f} is suspiciously small");
        } else {
            let text = String::from_utf8(bytes).unwrap();
            assert!(text.contains("<svg") && (text.contains("t (h)") || text.contains("l (km)")));
        }
    }
    let mut reader = csv::Reader::from_path(dir.join("history.csv")).unwrap();
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(header.join(","), HEADER);
    reader.records().map(|r| r.unwrap()).collect()
}

#[test]
fn header_constant_matches_the_contract() {
    assert_eq!(history_header(), HEADER);
}

#[test]
fn a_short_mission_writes_every_file() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("short");
    let o = Command::new(BIN)
        .args([
            "run",
            paper().to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .args(["--set", "simulation.duration_s=600", "--set", "name=short"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "stdout {stdout}\nstderr {stderr}");
    // No progress bar when stderr is not a terminal.
    assert!(stderr.is_empty(), "stderr: {stderr}");
    assert!(stdout.contains("fig4_length_tension.png"), "{stdout}");
    assert!(stdout.contains("Summary of scenario `short`"), "{stdout}");
    // Every file written is listed, faults.txt too.
    for f in [
        "history.csv",
        "table1.csv",
        "summary.txt",
        "faults.txt",
        "scenario.toml",
    ] {
        let listed = out.join(f).display().to_string();
        assert!(stdout.contains(&listed), "{listed} not listed: {stdout}");
    }
    let leftovers: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".partial"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");

    let rows = check_outputs(&out);
    assert_eq!(rows.len(), 61, "0..600 s every 10 s");
    let mut last_t = -1.0;
    for r in &rows {
        let t: f64 = r[0].parse().unwrap();
        assert!(t > last_t);
        last_t = t;
        for (i, cell) in r.iter().enumerate() {
            if i == 9 {
                assert!(["deploy", "keep1", "slew", "retrieve", "keep2"].contains(&cell));
            } else if i == 14 {
                cell.parse::<u32>().unwrap();
            } else {
                cell.parse::<f64>().unwrap();
            }
        }
    }
    assert_eq!(last_t, 600.0);
    assert_eq!(&rows[0][9], "deploy");
    assert_eq!(rows[0][1].parse::<f64>().unwrap(), 1.0, "l(0) = 1 m");

    let table = std::fs::read_to_string(out.join("table1.csv")).unwrap();
    let lines: Vec<&str> = table.lines().collect();
    assert_eq!(lines[0], TABLE1_CSV_HEADER);
    assert_eq!(lines.len(), 43);
    assert_eq!(lines[1], "1,7.00,25200,29999.965,,", "not reached in 600 s");
    let scenario = std::fs::read_to_string(out.join("scenario.toml")).unwrap();
    assert!(scenario.contains("duration_s = 600.0"), "{scenario}");
}

#[test]
fn the_paper_mission_fills_table_1() {
    let tmp = tempfile::tempdir().unwrap();
    // Default output directory: out/<scenario name>, relative to the working directory.
    let o = Command::new(BIN)
        .args(["run", paper().to_str().unwrap()])
        .current_dir(tmp.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = tmp.path().join("out/paper");
    let rows = check_outputs(&out);
    assert_eq!(rows.len(), 7201, "0..20 h every 10 s");
    let mut reader = csv::Reader::from_path(out.join("table1.csv")).unwrap();
    let table: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    assert_eq!(table.len(), 42);
    for (row, paper) in table.iter().zip(PAPER_TABLE1.iter()) {
        let sim: f64 = row[4].parse().unwrap();
        let diff: f64 = row[5].parse().unwrap();
        assert_eq!(row[3].parse::<f64>().unwrap(), paper.length_m);
        assert!((sim - paper.length_m - diff).abs() < 1e-9);
    }
    let stdout = String::from_utf8_lossy(&o.stdout);
    for text in [
        "deploy passes 10 km",
        "retrieval reaches 2 km",
        "stage 1: max |simulated − paper|",
        "stage 2: max |simulated − paper|",
    ] {
        assert!(stdout.contains(text), "{text}: {stdout}");
    }
    let summary = std::fs::read_to_string(out.join("summary.txt")).unwrap();
    assert!(stdout.contains(&summary));
}

fn synthetic(n: usize) -> History {
    let phases = [
        PhaseLabel::Deploy,
        PhaseLabel::Keep1,
        PhaseLabel::Slew,
        PhaseLabel::Retrieve,
        PhaseLabel::Keep2,
    ];
    let samples = (0..n)
        .map(|i| {
            let t = i as f64 * 10.0;
            Sample {
                t_s: t,
                length_m: 1.0 + 0.1 * t + 1e-7 / 3.0,
                length_rate_mps: 0.1,
                alpha_rad: -0.6 + 1e-3 * (t / 100.0).sin(),
                alpha_rate_radps: 1e-5,
                alpha_ref_rad: -std::f64::consts::FRAC_PI_4,
                delta_rad: 0.1,
                delta_rate_radps: 0.0,
                beta_rad: 0.0,
                tension_n: 0.01 * t,
                length_accel_mps2: 0.0,
                law_rate_mps: 0.1,
                blend_weight: (-1e-3 * t).exp(),
                phase: phases[i * phases.len() / n],
                flags: (i % 3) as u32,
            }
        })
        .collect();
    History {
        samples,
        probes: PROBE_TIMES_S
            .iter()
            .map(|&t| (t, 30_000.0 + t * 1e-6))
            .collect(),
        ..History::default()
    }
}

#[test]
fn synthetic_history_round_trips_through_the_outputs() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("synthetic");
    let args = RunArgs {
        scenario: paper(),
        out: Some(out.clone()),
        set: vec![],
        pil: Default::default(),
    };
    let history = synthetic(500);
    let expected = history.samples.clone();
    let mut probe_times = Vec::new();
    let outcome = run_with(&args, |_, probes, _, progress| {
        probe_times = probes.to_vec();
        progress(0.0);
        Ok::<_, std::io::Error>(history)
    })
    .unwrap();
    assert_eq!(probe_times, PROBE_TIMES_S.to_vec());
    assert_eq!(outcome.figures.len(), 6);
    check_outputs(&out);
    let file = std::io::BufReader::new(std::fs::File::open(out.join("history.csv")).unwrap());
    assert_eq!(
        read_history_csv(file).unwrap(),
        expected,
        "bit-exact round trip"
    );
    assert!(outcome.report.contains("stage 1: max |simulated − paper|"));
}

#[test]
fn a_failed_simulation_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("never");
    let args = RunArgs {
        scenario: paper(),
        out: Some(out.clone()),
        set: vec![],
        pil: Default::default(),
    };
    let e = run_with(&args, |_, _, _, _| {
        Err::<History, _>(std::io::Error::other("diverged"))
    })
    .unwrap_err();
    assert!(format!("{e:#}").contains("diverged"));
    assert!(!out.exists());
    assert!(!tss_sim::usage::is_usage_error(&e));
}

#[test]
fn without_a_font_the_other_outputs_are_written_and_the_error_names_the_package() {
    let tmp = tempfile::tempdir().unwrap();
    // A fontconfig configuration with no font directories: no font can be found.
    let conf = tmp.path().join("fonts.conf");
    std::fs::write(&conf, "<?xml version=\"1.0\"?><fontconfig></fontconfig>").unwrap();
    let out = tmp.path().join("nofont");
    let o = Command::new(BIN)
        .args([
            "run",
            paper().to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .args(["--set", "simulation.duration_s=60"])
        .env("FONTCONFIG_FILE", &conf)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("fonts-dejavu-core"), "{stderr}");
    for f in ["history.csv", "table1.csv", "summary.txt", "scenario.toml"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    assert!(!out.join("fig4_length_tension.png").exists());
}

fn args_into(out: &Path) -> RunArgs {
    RunArgs {
        scenario: paper(),
        out: Some(out.to_path_buf()),
        set: vec![],
        pil: Default::default(),
    }
}

/// The names of the files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// An output directory that cannot be written is a usage error (exit 2) found before the
/// simulation starts, not a failure (exit 1) after the whole simulation.
#[test]
fn an_unwritable_output_is_found_before_the_simulation() {
    let tmp = tempfile::tempdir().unwrap();
    // Cannot be created, even by root.
    let unwritable = Path::new("/proc/tss-sim-test/out");
    // A directory where a result file goes (the rename at the end would fail).
    let blocked = tmp.path().join("blocked");
    std::fs::create_dir_all(blocked.join("history.csv")).unwrap();
    for out in [unwritable, blocked.as_path()] {
        let mut simulated = false;
        let e = run_with(&args_into(out), |_, _, _, _| {
            simulated = true;
            Err::<History, _>(std::io::Error::other("not to be reached"))
        })
        .unwrap_err();
        assert!(!simulated, "{}: simulated before checking", out.display());
        assert!(tss_sim::usage::is_usage_error(&e), "{e:#}");
        assert!(format!("{e:#}").contains("--out"), "{e:#}");
    }
    assert_eq!(listing(&blocked), ["history.csv"]);

    let o = Command::new(BIN)
        .args(["run", paper().to_str().unwrap(), "-o"])
        .arg(unwritable)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// A failed run leaves an earlier run's results as they were (no file of the failed run, no
/// temporary file); a successful one replaces them and removes the files of the set it did not
/// write (an earlier PIL run's pil.txt and firmware.log).
#[test]
fn a_failed_run_leaves_the_earlier_results_and_a_new_one_replaces_them_all() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    std::fs::create_dir_all(&out).unwrap();
    for f in [
        "history.csv",
        "summary.txt",
        "pil.txt",
        "firmware.log",
        "notes.md",
    ] {
        std::fs::write(out.join(f), "earlier run").unwrap();
    }
    let before = listing(&out);
    let e = run_with(&args_into(&out), |_, _, _, _| {
        Err::<History, _>(std::io::Error::other("diverged"))
    })
    .unwrap_err();
    assert!(format!("{e:#}").contains("diverged"));
    assert_eq!(listing(&out), before);
    assert_eq!(
        std::fs::read_to_string(out.join("history.csv")).unwrap(),
        "earlier run"
    );

    run_with(&args_into(&out), |_, _, _, _| {
        Ok::<_, std::io::Error>(synthetic(50))
    })
    .unwrap();
    let after = listing(&out);
    assert!(!after.contains(&"pil.txt".to_string()), "{after:?}");
    assert!(!after.contains(&"firmware.log".to_string()), "{after:?}");
    assert!(after.contains(&"notes.md".to_string()), "not ours: kept");
    assert!(after.iter().all(|n| !n.contains(".partial")), "{after:?}");
    assert_ne!(
        std::fs::read_to_string(out.join("history.csv")).unwrap(),
        "earlier run"
    );
    check_outputs(&out);
}

fn paper_elastic() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper-elastic.toml")
}

/// A figure of the tether's shape at chosen times: an elastic run draws `tether_shape.png`/`.svg`
/// (one curve per recorded shape, in the orbit plane) and lists it; a rigid run has no shape to
/// draw, and run into the same directory it removes the earlier one.
#[test]
fn an_elastic_run_draws_the_tethers_shape_and_a_rigid_one_does_not() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("shape");
    let run = |scenario: &Path| {
        let o = Command::new(BIN)
            .args(["run", scenario.to_str().unwrap(), "--out"])
            .arg(&out)
            .args(["--set", "simulation.duration_s=1800"])
            .args(["--set", "plant.shape_interval_s=600"])
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
        assert!(
            o.status.success(),
            "{stdout}\n{}",
            String::from_utf8_lossy(&o.stderr)
        );
        stdout
    };
    let stdout = run(&paper_elastic());
    for f in ["tether_shape.png", "tether_shape.svg"] {
        assert!(
            stdout.contains(&format!("{f}\n")),
            "{f} not listed: {stdout}"
        );
    }
    let png = std::fs::read(out.join("tether_shape.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let svg = std::fs::read_to_string(out.join("tether_shape.svg")).unwrap();
    assert!(svg.contains("along-track e_θ (km)") && svg.contains("radial e_r (km)"));
    // Shapes at 0, 600, 1200 and 1800 s: a curve (and legend entry) each.
    for t in ["t = 0.00 h", "t = 0.17 h", "t = 0.33 h", "t = 0.50 h"] {
        assert!(svg.contains(t), "{t} not in the legend");
    }
    for f in FIGURES {
        assert!(out.join(f).is_file(), "{f}");
    }

    // Shape files are in the run's set: a rigid run into the same directory removes them.
    let rigid = run(&paper());
    assert!(!rigid.contains("tether_shape"), "{rigid}");
    assert!(!out.join("tether_shape.png").exists());
    assert!(!out.join("tether_shape.svg").exists());
    assert!(out.join("fig4_length_tension.png").is_file());
}
