//! Closed-loop tests of the paper's Section-6 mission (docs/equations.md §7): the flight controller core
//! (f32) flying the f64 plant of Eq. 5 in `tss-sim`.
//!
//! Each mission is simulated once per test binary and shared by the tests below.

use std::path::Path;
use std::sync::OnceLock;
use tss_reel::controller::Flags;
use tss_sim::history::{History, PhaseLabel, Sample};
use tss_sim::scenario::Scenario;
use tss_sim::sim;
use tss_sim::table1::{PAPER_TABLE1, PROBE_TIMES_S};

fn scenario(overrides: &[&str]) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/paper.toml");
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Scenario::load(&path, &overrides).expect("scenarios/paper.toml loads")
}

/// The paper's mission, output every 10 s, controller in f32.
fn paper() -> &'static History {
    static RUN: OnceLock<History> = OnceLock::new();
    RUN.get_or_init(|| sim::run(&scenario(&[]), &PROBE_TIMES_S, &mut |_| {}).expect("mission runs"))
}

/// The same mission with a thin massive tether, ρ = 1e-3 kg/m.
fn massive_tether() -> &'static History {
    static RUN: OnceLock<History> = OnceLock::new();
    RUN.get_or_init(|| {
        let sc = scenario(&["tether.density_kg_per_m=1e-3"]);
        sim::run(&sc, &PROBE_TIMES_S, &mut |_| {}).expect("mission runs")
    })
}

fn between(h: &History, from_h: f64, to_h: f64) -> impl Iterator<Item = &Sample> {
    h.samples
        .iter()
        .filter(move |s| s.t_s >= from_h * 3600.0 && s.t_s <= to_h * 3600.0)
}

#[test]
fn stage1_table1_lengths_within_6_cm_of_the_paper() {
    let h = paper();
    assert_eq!(h.probes.len(), PAPER_TABLE1.len());
    let mut worst: f64 = 0.0;
    for (p, (t, l)) in PAPER_TABLE1.iter().zip(&h.probes) {
        assert_eq!(p.t_s, *t);
        if p.stage == 1 {
            let d = l - p.length_m;
            worst = worst.max(d.abs());
            assert!(
                d.abs() <= 0.06,
                "t = {} h: simulated {l:.4} m, paper {} m",
                p.t_h,
                p.length_m
            );
        }
    }
    eprintln!("stage-1 Table 1: largest |difference| {worst:.4} m");
}

#[test]
fn stage2_table1_settles_on_2_km_below_the_papers_offset() {
    // docs/equations.md §7: the paper's stage-2 column settles about 0.11 m above 2000 m; an exact
    // implementation settles at 2000 m. Ours is below the paper at every instant, above 2 km,
    // and decreasing, like the paper's column.
    let h = paper();
    let stage2: Vec<_> = PAPER_TABLE1
        .iter()
        .zip(&h.probes)
        .filter(|(p, _)| p.stage == 2)
        .collect();
    assert_eq!(stage2.len(), 21);
    let mut prev = f64::INFINITY;
    for (p, (_, l)) in &stage2 {
        assert!(*l < p.length_m && *l > 2000.0, "t = {} h: {l}", p.t_h);
        assert!(*l < prev, "not decreasing at {} h", p.t_h);
        prev = *l;
    }
    let last = stage2[20].1 .1;
    assert!(last - 2000.0 < 0.05, "15 h: {last}");
}

#[test]
fn station_keeping_at_30_km_within_10_cm_from_7_to_8_h() {
    let worst = between(paper(), 7.0, 8.0)
        .map(|s| (s.length_m - 30_000.0).abs())
        .fold(0.0, f64::max);
    assert!(worst < 0.1, "largest |l − 30 km| = {worst} m");
}

#[test]
fn retrieval_is_monotone_toward_2_km() {
    let h = paper();
    let start = h
        .samples
        .iter()
        .position(|s| s.phase == PhaseLabel::Retrieve)
        .expect("retrieval begins");
    let tail = &h.samples[start..];
    for w in tail.windows(2) {
        assert!(
            w[1].length_m <= w[0].length_m + 1e-6,
            "l rises at t = {} s",
            w[1].t_s
        );
        assert!(
            w[1].length_m > 2000.0 - 1e-3,
            "below 2 km at t = {} s",
            w[1].t_s
        );
    }
    let last = h.samples.last().unwrap();
    assert!(
        (last.length_m - 2000.0).abs() < 0.01,
        "final length {}",
        last.length_m
    );
}

#[test]
fn alpha_follows_minus_45_degrees_in_early_deployment() {
    // While the Eq. 29 blend still holds the reel near l̇0 (E = e^{−t/1000 s}), the short
    // tether swings back to about −70° at 0.3 h (the paper's Figs. 5–6 reach toward −80°);
    // once the law dominates, α settles on α_r = −45° and stays there until the band starts
    // at 10 km (≈ 2.5 h).
    let h = paper();
    let early_min = between(h, 0.0, 1.0)
        .map(|s| s.alpha_rad.to_degrees())
        .fold(0.0, f64::min);
    assert!(
        (-80.0..-60.0).contains(&early_min),
        "early swing to {early_min}°"
    );
    let samples: Vec<_> = between(h, 1.0, 2.5).collect();
    assert!(samples.iter().all(|s| s.length_m < 10_000.0));
    let worst = samples
        .iter()
        .map(|s| (s.alpha_rad.to_degrees() + 45.0).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 1.0,
        "largest |α + 45°| from 1 h to 2.5 h = {worst}°"
    );
}

#[test]
fn milestones_match_the_papers_description() {
    // docs/equations.md §7: 10 km near 2.5 h, 30 km near 3.3 h with an overshoot.
    let h = paper();
    let first =
        |pred: &dyn Fn(&Sample) -> bool| h.samples.iter().find(|s| pred(s)).map(|s| s.t_s / 3600.0);
    let t10 = first(&|s| s.length_m >= 10_000.0).unwrap();
    let t30 = first(&|s| s.length_m >= 30_000.0).unwrap();
    assert!((2.2..2.8).contains(&t10), "10 km at {t10} h");
    assert!((3.0..3.6).contains(&t30), "30 km at {t30} h");
    let overshoot = between(h, 0.0, 8.0).map(|s| s.length_m).fold(0.0, f64::max) - 30_000.0;
    assert!(
        overshoot > 0.0 && overshoot < 3_000.0,
        "overshoot {overshoot} m"
    );
}

#[test]
fn tension_stays_positive_throughout() {
    for h in [paper(), massive_tether()] {
        let min = h
            .samples
            .iter()
            .map(|s| s.tension_n)
            .fold(f64::INFINITY, f64::min);
        assert!(min > 0.0, "slack tether: min tension {min} N");
    }
}

#[test]
fn phases_occur_in_order_without_faults_or_saturation() {
    let h = paper();
    let mut seen = vec![h.samples[0].phase];
    for s in &h.samples {
        if *seen.last().unwrap() != s.phase {
            seen.push(s.phase);
        }
        let bad = Flags::RATE_SATURATED
            | Flags::ACCEL_SATURATED
            | Flags::LENGTH_LIMITED
            | Flags::SAFE_ACTION;
        assert_eq!(s.flags & bad, 0, "flags {:#b} at t = {} s", s.flags, s.t_s);
    }
    use PhaseLabel::*;
    assert_eq!(seen, vec![Deploy, Keep1, Slew, Retrieve, Keep2]);
}

#[test]
fn massive_tether_mission_is_well_behaved() {
    // ρ = 1e-3 kg/m: 40 kg of tether at 40 km, μ1, μ3 ≠ 0 and μ2 < 1 (docs/equations.md §1).
    let h = massive_tether();
    let keep = between(h, 7.0, 8.0)
        .map(|s| (s.length_m - 30_000.0).abs())
        .fold(0.0, f64::max);
    assert!(keep < 0.5, "station keeping within {keep} m");
    let last = h.samples.last().unwrap();
    assert!(
        (last.length_m - 2000.0).abs() < 0.05,
        "final length {}",
        last.length_m
    );
    assert!(h.samples.iter().all(|s| s.flags & Flags::SAFE_ACTION == 0));
    // The same early swing as the massless run (the tether weighs grams then), never past 80°.
    let max_abs_alpha = h
        .samples
        .iter()
        .map(|s| s.alpha_rad.abs())
        .fold(0.0, f64::max);
    assert!(
        max_abs_alpha.to_degrees() < 80.0,
        "max |α| {}°",
        max_abs_alpha.to_degrees()
    );
    // Outside the stage-2 slew (α lags the 500 s ramp of α_r by up to 13°), δ stays small.
    let tracking = between(h, 1.5, 8.0)
        .chain(between(h, 9.0, 20.0))
        .map(|s| s.delta_rad.abs())
        .fold(0.0, f64::max);
    assert!(
        tracking.to_degrees() < 5.0,
        "max |δ| off the slew: {}°",
        tracking.to_degrees()
    );
}

#[test]
fn f32_core_matches_f64_evaluation_of_the_same_law() {
    // The flight core (f32) against the same law evaluated in f64, both flying the f64 plant.
    let h32 = paper();
    let h64 = sim::run_with::<f64>(&scenario(&[]), &PROBE_TIMES_S, &mut |_| {}).unwrap();
    let mut worst_rate: f64 = 0.0;
    let mut worst_len: f64 = 0.0;
    for (a, b) in h32.samples.iter().zip(&h64.samples) {
        worst_rate = worst_rate.max((a.length_rate_mps - b.length_rate_mps).abs());
        worst_len = worst_len.max((a.length_m - b.length_m).abs());
    }
    eprintln!("f32 vs f64 controller: largest difference in command {worst_rate:.3e} m/s, in length {worst_len:.3e} m");
    assert!(worst_len < 0.05, "length differs by {worst_len} m");
    assert!(worst_rate < 5e-3, "command differs by {worst_rate} m/s");
}
