//! The `extent` and `stability` subcommands of the built `tss-sim` binary: CSV headers and
//! values, files written, and exit code 2 with a message naming the argument for bad input.

use std::process::{Command, Output};

fn tss_sim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tss-sim"))
        .args(args)
        .output()
        .expect("run tss-sim")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Parses CSV text into (header, rows).
fn parse_csv(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = text.lines();
    let header = lines
        .next()
        .expect("header")
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect();
    (header, rows)
}

fn column(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

#[test]
fn extent_csv_has_header_and_fig3_values() {
    let o = tss_sim(&[
        "extent",
        "--format",
        "csv",
        "--eccentricity",
        "0,0.3,0.6,0.75",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, rows) = parse_csv(&stdout(&o));
    assert_eq!(
        h,
        [
            "eccentricity",
            "min_depl",
            "theta_star_depl_rad",
            "theta_star_depl_deg",
            "max_retr",
            "theta_star_retr_rad",
            "theta_star_retr_deg",
            "iterations",
            "exists_whole_orbit"
        ]
    );
    assert_eq!(rows.len(), 4);
    let v = |r: usize, c: &str| rows[r][column(&h, c)].parse::<f64>().unwrap();
    assert_eq!(v(0, "min_depl"), 1.5);
    assert_eq!(v(0, "max_retr"), -1.5);
    assert!((v(1, "min_depl") - 0.959_960).abs() < 1e-6);
    assert!((v(2, "min_depl") - 0.556_784).abs() < 1e-6);
    assert!(v(3, "min_depl").abs() < 1e-12);
    assert!((v(3, "theta_star_depl_deg") + 90.0).abs() < 1e-6);
    for r in 0..4 {
        assert_eq!(v(r, "max_retr"), -v(r, "min_depl"));
    }
}

#[test]
fn extent_default_grid_spans_zero_to_three_quarters() {
    let o = tss_sim(&["extent", "--format", "csv"]);
    assert!(o.status.success());
    let (h, rows) = parse_csv(&stdout(&o));
    let e = column(&h, "eccentricity");
    assert_eq!(rows.first().unwrap()[e], "0.0");
    assert_eq!(rows.last().unwrap()[e], "0.75");
    assert_eq!(rows.len(), 31);
}

#[test]
fn extent_text_table_is_printed() {
    let o = tss_sim(&["extent", "--eccentricity", "0.3"]);
    assert!(o.status.success());
    let s = stdout(&o);
    assert!(s.contains("min Depl") && s.contains("0.959960"), "{s}");
}

#[test]
fn extent_out_writes_csvs_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("extent");
    let o = tss_sim(&[
        "extent",
        "--eccentricity",
        "0,0.25,0.5",
        "--theta-points",
        "73",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for f in [
        "fig3_extent.csv",
        "fig2_surfaces.csv",
        "fig3_extent.png",
        "fig3_extent.svg",
        "fig2_depl_retr.png",
        "fig2_depl_retr.svg",
    ] {
        let p = out.join(f);
        assert!(
            p.metadata().map(|m| m.len() > 100).unwrap_or(false),
            "{f} missing or empty"
        );
    }
    let (h, rows) = parse_csv(&std::fs::read_to_string(out.join("fig2_surfaces.csv")).unwrap());
    assert_eq!(
        h,
        [
            "eccentricity",
            "true_anomaly_rad",
            "true_anomaly_deg",
            "depl",
            "retr"
        ]
    );
    assert_eq!(rows.len(), 3 * 73);
    // e = 0: Depl ≡ 1.5, Retr ≡ −1.5.
    assert_eq!(rows[0][column(&h, "depl")], "1.5");
    let png = std::fs::read(out.join("fig3_extent.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn stability_csv_reports_roots_verdicts_and_cross_check() {
    let o = tss_sim(&[
        "stability",
        "--format",
        "csv",
        "--length-m",
        "10000",
        "--rate-mps",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, rows) = parse_csv(&stdout(&o));
    assert_eq!(rows.len(), 1);
    let get = |c: &str| rows[0][column(&h, c)].clone();
    let f = |c: &str| get(c).parse::<f64>().unwrap();
    assert_eq!(get("verdict"), "stable");
    assert_eq!(get("at_equilibrium"), "true");
    // Deploying at l̇/l = 2e-4 1/s with μ3 = 0: Re λ = −(1 + μ3/2) l̇/l = −2e-4.
    assert!((f("lambda1_re") + 2e-4).abs() < 1e-15);
    assert!(f("d1_per_s2") < 0.0 && f("d2_per_s2") < 0.0);
    assert!(f("max_rel_mismatch") < 1e-9);
    // Hand value: D1 = (2e-4)² − 3n² cos2α_e with sin2α_e = −(2/3)·0.4e-3/n.
    let n = f("anomaly_rate_radps");
    let s = -(2.0 / 3.0) * 0.4e-3 / n;
    let d1 = 4e-8 - 3.0 * n * n * (1.0 - s * s).sqrt();
    assert!(
        (f("d1_per_s2") - d1).abs() < 1e-18,
        "{} vs {d1}",
        f("d1_per_s2")
    );
}

#[test]
fn stability_verdicts_of_the_three_regimes() {
    for (rate, verdict) in [("2", "stable"), ("-2", "unstable"), ("0", "marginal")] {
        let o = tss_sim(&["stability", "--format", "csv", "--rate-mps", rate]);
        assert!(o.status.success(), "{}", stderr(&o));
        let (h, rows) = parse_csv(&stdout(&o));
        assert_eq!(rows[0][column(&h, "verdict")], verdict, "l̇ = {rate}");
    }
}

#[test]
fn stability_text_shows_roots_and_eigenvalues() {
    let o = tss_sim(&[
        "stability",
        "--rate-mps",
        "1",
        "--eccentricity",
        "0.1",
        "--anomaly-deg",
        "30",
        "--density-kg-per-m",
        "0.001",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = stdout(&o);
    for needle in [
        "D1 =",
        "D2 =",
        "Verdict",
        "nalgebra",
        "max |closed form - eigenvalue|",
    ] {
        assert!(s.contains(needle), "missing {needle:?} in\n{s}");
    }
}

#[test]
fn impossible_input_exits_2_naming_the_argument() {
    for (args, flag) in [
        (vec!["stability", "--length-m", "0"], "--length-m"),
        (vec!["stability", "--length-m", "-5"], "--length-m"),
        (vec!["stability", "--eccentricity", "1"], "--eccentricity"),
        (
            vec!["stability", "--eccentricity", "-0.1"],
            "--eccentricity",
        ),
        (vec!["stability", "--rate-mps", "nan"], "--rate-mps"),
        (vec!["stability", "--sub-mass-kg", "0"], "--sub-mass-kg"),
        (vec!["stability", "--main-mass-kg", "-1"], "--main-mass-kg"),
        (
            vec!["stability", "--density-kg-per-m", "-1e-3"],
            "--density-kg-per-m",
        ),
        (
            vec!["stability", "--semi-major-axis-m", "inf"],
            "--semi-major-axis-m",
        ),
        (vec!["stability", "--rate-mps", "100"], "--rate-mps"),
        (
            vec!["extent", "--eccentricity", "0.2,1.5"],
            "--eccentricity",
        ),
        (vec!["extent", "--eccentricity", "nan"], "--eccentricity"),
        (vec!["extent", "--step", "0"], "--step"),
        (vec!["extent", "--theta-points", "2"], "--theta-points"),
    ] {
        let o = tss_sim(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(flag), "{args:?}: {}", stderr(&o));
        assert!(stdout(&o).is_empty(), "{args:?} printed {}", stdout(&o));
    }
}

#[test]
fn unwritable_output_exits_2_before_printing() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let o = tss_sim(&["extent", "--out", file.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stdout(&o).is_empty());
}
