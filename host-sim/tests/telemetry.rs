//! The on-board computer commands the reel unit over CCSDS/PUS (docs/interface.md §3): the
//! commanded missions of `scenarios/` (a hold at 5 h, its resume at 6 h, an abort) fly on the
//! rigid and the elastic plant, every telecommand is verified, and the telemetry that
//! `tss-sim run` writes decodes to the same figures as its `history.csv`.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use tss_reel::controller::{Config, Flags};
use tss_reel::pus::{read_telemetry, Stage, Telemetry};
use tss_reel::tension::admittance_gain_mps_per_n;
use tss_sim::history::{History, Sample};
use tss_sim::scenario::Scenario;

fn scenario_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../scenarios/{name}.toml"))
}

fn fly(name: &str) -> (Scenario, History) {
    let sc = Scenario::load(scenario_path(name), &[]).expect("the scenario loads");
    let h = tss_sim::sim::run(&sc, &[], &mut |_| {}).expect("the mission flies");
    (sc, h)
}

/// The verification reports of a run: (request sequence count, stage, failure code).
fn verification(h: &History) -> Vec<(u16, Stage, Option<u16>)> {
    h.telemetry
        .iter()
        .filter_map(|p| match read_telemetry(p)?.telemetry {
            Telemetry::Verification {
                request,
                stage,
                failure,
            } => Some((request.sequence & 0x3fff, stage, failure.map(|f| f.0))),
            _ => None,
        })
        .collect()
}

/// The samples from `from_s` to `until_s`.
fn between(h: &History, from_s: f64, until_s: f64) -> impl Iterator<Item = &Sample> {
    h.samples
        .iter()
        .filter(move |s| s.t_s >= from_s && s.t_s <= until_s)
}

const OK: Option<u16> = None;
const HOLD_S: f64 = 18_000.0;
const RESUME_S: f64 = 21_600.0;

/// How a controller keeps the reel at rest: exactly (no tension loop: l̇ = 0), or with the
/// tension loop's admittance term still damping the tether (docs/equations.md §17.8).
#[derive(Clone)]
enum Rest {
    Exact,
    /// The loop of this configuration (K(l) of (17.5)–(17.6), τ_w).
    Compliant(Box<Config<f64>>),
}

impl Rest {
    fn of(sc: &Scenario) -> Self {
        let cfg = sc.controller_config::<f64>();
        match cfg.tension_loop {
            None => Rest::Exact,
            Some(_) => Rest::Compliant(Box::new(cfg)),
        }
    }

    /// The reel at rest over `samples` (from the first one on): with the loop, the admittance
    /// term K·HP[x] moves it by at most K times the spread of the free tension x (the tension
    /// at rest) in rate, and by K·τ_w times that spread in length (17.10); exactly none without.
    fn assert_at_rest(&self, samples: &[&Sample]) {
        let spread_n = match self {
            Rest::Exact => 0.0,
            Rest::Compliant(_) => {
                let tension = samples.iter().map(|s| s.tension_n);
                tension.clone().fold(f64::MIN, f64::max) - tension.fold(f64::MAX, f64::min)
            }
        };
        let (gain, washout_s) = match self {
            Rest::Exact => (0.0, 0.0),
            Rest::Compliant(cfg) => {
                let t = cfg.tension_loop.expect("a loop");
                let radial_kg = cfg.masses.coefficients(samples[0].length_m).radial_kg;
                let gain = admittance_gain_mps_per_n(
                    samples[0].length_m,
                    t.axial_stiffness_n,
                    radial_kg,
                    t.damping_ratio,
                    cfg.period_s,
                );
                (gain, t.washout_s)
            }
        };
        for s in samples {
            assert!(
                s.length_rate_mps.abs() <= gain * spread_n,
                "at rest: {s:?} (K = {gain} m/s/N, spread {spread_n} N)"
            );
            assert!(
                (s.length_m - samples[0].length_m).abs() <= gain * washout_s * spread_n,
                "the length kept: {s:?} from {} m",
                samples[0].length_m
            );
        }
    }
}

/// A hold at 5 h: the reel at rest within `rest_s` and the length kept until the resume at
/// 6 h, held and flagged throughout; then the law again (no safe action); stage 2 one hour
/// late, at 9 h.
fn assert_held_and_resumed(h: &History, rest: &Rest, rest_s: f64) {
    let held: Vec<&Sample> = between(h, HOLD_S + rest_s, RESUME_S - 10.0).collect();
    assert!(held.len() > 300);
    rest.assert_at_rest(&held);
    for s in between(h, HOLD_S, RESUME_S - 10.0) {
        assert!(
            Flags(s.flags).contains(Flags::HELD | Flags::SAFE_ACTION),
            "{s:?}"
        );
    }
    for s in between(h, RESUME_S + 10.0, 32_390.0) {
        assert_eq!(s.flags & (Flags::HELD | Flags::SAFE_ACTION), 0, "{s:?}");
        assert_eq!(s.phase.as_str(), "keep1");
    }
    let slew = h.samples.iter().find(|s| s.phase.as_str() == "slew");
    assert_eq!(slew.map(|s| s.t_s), Some(32_400.0), "stage 2 at 9 h");
}

#[test]
fn the_paper_mission_holds_resumes_and_refuses_a_resume_it_cannot_take() {
    let (sc, h) = fly("paper-commanded");
    // −0.013 m/s at 5 h, ramped down at 0.01 m/s² (monitor.safe_hold_decel_mps2): at rest
    // from the second period of the hold, exactly (no tension loop).
    assert_held_and_resumed(&h, &Rest::of(&sc), 10.0);
    assert_eq!(
        verification(&h),
        [
            (0, Stage::Acceptance, OK),
            (0, Stage::Start, OK),
            (0, Stage::Completion, OK),
            (1, Stage::Acceptance, OK),
            (1, Stage::Start, OK),
            (1, Stage::Completion, OK),
            (2, Stage::Acceptance, OK),
            (2, Stage::Start, Some(14)),
        ]
    );
    assert_eq!(h.faults.slack_s, 0.0, "taut throughout");
}

#[test]
fn the_elastic_mission_holds_resumes_and_aborts_to_rest_taut() {
    let (sc, h) = fly("paper-elastic-commanded");
    let rest = Rest::of(&sc);
    assert!(matches!(rest, Rest::Compliant(_)));
    assert_held_and_resumed(&h, &rest, 100.0);
    // The abort at 11 h, retrieving at 0.36 m/s at 2.4 km: braked no faster than the tension
    // window allows (0.73 N of free tension carries 0.0047 m/s², not the ramp's 0.01) but at
    // least a quarter of the ramp's 0.01 m/s², so at rest within 4 × 36 s; then kept.
    let abort_s = 39_600.0;
    let at_rest: Vec<&Sample> = between(&h, abort_s + 150.0, 72_000.0).collect();
    assert_eq!(at_rest.last().map(|s| s.t_s), Some(72_000.0));
    rest.assert_at_rest(&at_rest);
    for s in between(&h, abort_s + 10.0, 72_000.0) {
        assert!(Flags(s.flags).contains(Flags::ABORTED | Flags::SAFE_ACTION));
    }
    assert_eq!(
        verification(&h)
            .iter()
            .filter(|(_, stage, f)| *stage == Stage::Completion && f.is_none())
            .count(),
        3
    );
    // Held, resumed and aborted, the elastic tether stays taut from 3 km on: the loop damps the
    // bounce the stop excites and the window keeps the braking within the free tension
    // (docs/equations.md §17.8).
    eprintln!(
        "elastic abort at 11 h: slack {} episodes, {} s in all; least tension after the abort \
         {:.3} N",
        h.faults.slack_events,
        h.faults.slack_s,
        between(&h, abort_s, 72_000.0)
            .map(|s| s.tension_n)
            .fold(f64::MAX, f64::min)
    );
    assert_eq!(h.faults.slack_events, 0, "{:?}", h.faults.slack_episodes);
}

#[test]
fn an_abort_after_a_fault_brings_the_reel_to_rest_for_good() {
    let (_, h) = fly("faults-commanded");
    // Retrieving at 0.25 m/s after the orbit-rate fault at 40 000 s; aborted at 40 010 s and
    // brought to rest at 0.01 m/s² (the command in 26 s; the reel, with its 1 s lag, within a
    // minute).
    let rest: Vec<&Sample> = between(&h, 40_010.0 + 60.0, 72_000.0).collect();
    for s in &rest {
        assert_eq!(s.length_rate_mps, 0.0, "{s:?}");
        assert_eq!(s.length_m, rest[0].length_m, "{s:?}");
        assert!(Flags(s.flags).contains(Flags::ABORTED));
    }
    let libration = rest.iter().map(|s| s.alpha_rad.abs()).fold(0.0, f64::max);
    assert!(libration < 0.1, "a free swing of {libration} rad at rest");
    assert_eq!(verification(&h).len(), 9);
}

/// A CSV file as rows of named cells.
fn read_csv(path: &Path) -> Vec<HashMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            assert_eq!(cells.len(), header.len(), "{l}");
            header
                .iter()
                .cloned()
                .zip(cells.iter().map(|c| c.to_string()))
                .collect()
        })
        .collect()
}

#[test]
fn the_telemetry_run_writes_decodes_to_the_figures_of_its_history() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let status = Command::new(env!("CARGO_BIN_EXE_tss-sim"))
        .args(["-q", "run"])
        .arg(scenario_path("paper-commanded"))
        .arg("-o")
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let history = read_csv(&out.join("history.csv"));
    let telemetry = read_csv(&out.join("telemetry.csv"));
    let housekeeping: HashMap<&str, &HashMap<String, String>> = telemetry
        .iter()
        .filter(|r| r["service"] == "3")
        .map(|r| (r["tick"].as_str(), r))
        .collect();
    // One housekeeping report per history row (1 s period: the tick is t_s).
    assert_eq!(housekeeping.len(), history.len());
    let phases = ["deploy", "keep1", "slew", "retrieve", "keep2"];
    let number = |s: &str| s.parse::<f64>().unwrap();
    for row in &history {
        let hk = housekeeping[row["t_s"].as_str()];
        for (h, t) in [
            ("length_rate_mps", "rate_cmd_mps"),
            ("length_accel_mps2", "accel_cmd_mps2"),
            ("law_rate_mps", "law_rate_mps"),
            ("blend_weight", "blend_weight"),
            ("alpha_ref_rad", "alpha_ref_rad"),
            ("delta_rad", "delta_rad"),
            ("delta_rate_radps", "delta_rate_radps"),
        ] {
            assert_eq!(number(&row[h]), number(&hk[t]), "{h} at {}", row["t_s"]);
        }
        assert_eq!(row["flags"], hk["flags"]);
        assert_eq!(row["phase"], phases[hk["phase"].parse::<usize>().unwrap()]);
        // The paper's sensors are exact: the sensed α is the plant's, rounded to f32.
        let alpha = number(&row["alpha_rad"]) as f32;
        assert_eq!(number(&hk["alpha_rad"]), f64::from(alpha));
    }
    // Every verification report and event of the run is there, with its time.
    let reports: Vec<(&str, &str, &str)> = telemetry
        .iter()
        .filter(|r| r["service"] == "1")
        .map(|r| {
            (
                r["t_s"].as_str(),
                r["subtype"].as_str(),
                r["failure_code"].as_str(),
            )
        })
        .collect();
    assert_eq!(
        reports,
        [
            ("17999", "1", ""),
            ("17999", "3", ""),
            ("18000", "7", ""),
            ("21599", "1", ""),
            ("21599", "3", ""),
            ("21600", "7", ""),
            ("25199", "1", ""),
            ("25199", "4", "14"),
        ]
    );
}
