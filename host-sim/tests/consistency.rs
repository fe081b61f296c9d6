//! The flight estimator's consistency over a small Monte Carlo campaign
//! (`tss-sim montecarlo --consistency`): NIS inside its two-sided 95 % χ² band, the NEES not
//! above its band (the filter is never over-confident), and an α bias the filter cannot observe
//! driving the (α, α̇) NEES out while α̇'s stays in. The filter judged is the controller's own, in
//! the loop; with an α̇ sensor flying the law, the same filter run beside it on the same
//! readings.
//!
//! The campaign: 20 runs of the paper mission's first 3 h (deployment, the band, reaching
//! 30 km), the swing sensor at σ_α = 1e-4 rad (the flight sensor's floor), the initial angle
//! dispersed. The rigid plant has none of the disturbances the filter's process noise stands
//! for (out-of-plane coupling, elasticity, orbit and reel errors), so its NEES sits below the
//! degrees of freedom: a conservative filter, which is the safe side; the NIS, dominated by the
//! sensor noise, is χ²(1).

use std::path::Path;

use tss_sim::montecarlo::consistency::{band, Summary};
use tss_sim::montecarlo::Campaign;
use tss_sim::scenario::Scenario;

const RUNS: u64 = 20;

fn summary(extra: &[&str]) -> Summary {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper-montecarlo.toml");
    let mut sets: Vec<String> = [
        "simulation.duration_s=10800",
        "sensors.alpha.noise_std=1e-4",
        "sensors.alpha.bias=0",
        "montecarlo.dispersion=[{ field = \"initial.delta_rad\", distribution = \"normal\", std = 0.0175 }]",
    ]
    .map(String::from)
    .to_vec();
    sets.extend(extra.iter().map(|s| s.to_string()));
    let sc = Scenario::load(&path, &sets).expect("the campaign loads");
    let campaign = Campaign::new(sc, 7, RUNS).expect("a campaign");
    let indices: Vec<u64> = (0..RUNS).collect();
    let (records, sums) = campaign
        .run_all_watched(&indices, 0, true, &|| {})
        .expect("the runs fly");
    assert!(
        records.iter().all(|r| r.outcome.is_some()),
        "every run completes"
    );
    let s = sums.expect("consistency sums").summary();
    eprintln!("{}", s.render(RUNS as usize));
    s
}

#[test]
fn nis_is_inside_its_band_and_nees_never_above_it() {
    let s = summary(&[]);
    // NIS: the run averages inside the 95 % band at ≥ 90 % of the instants (95 % expected,
    // less their correlation), the overall mean within 5 % of 1.
    assert!(s.nis.instants >= 140, "{}", s.nis.instants);
    assert!(s.nis.fraction_inside() >= 0.9, "{:?}", s.nis);
    assert!((s.nis.mean - 1.0).abs() <= 0.05, "{:?}", s.nis);
    // NEES: never over-confident: the mean at most the degrees of freedom and at most 5 % of
    // the instants' run averages above their band; not absurdly pessimistic either.
    for n in [&s.nees, &s.rate_nees] {
        assert!(n.mean <= n.dof, "{n:?}");
        assert!(n.mean >= 0.2 * n.dof, "{n:?}");
        assert!(n.above as f64 <= 0.05 * n.instants as f64, "{n:?}");
    }
}

#[test]
fn the_filter_beside_a_controller_on_the_rate_sensor_is_as_consistent() {
    let s = summary(&["sensors.alpha_rate.enabled=true"]);
    assert!(s.nis.fraction_inside() >= 0.9, "{:?}", s.nis);
    assert!((s.nis.mean - 1.0).abs() <= 0.05, "{:?}", s.nis);
    for n in [&s.nees, &s.rate_nees] {
        assert!(n.mean <= n.dof && n.mean >= 0.2 * n.dof, "{n:?}");
        assert!(n.above as f64 <= 0.05 * n.instants as f64, "{n:?}");
    }
}

#[test]
fn an_alpha_bias_the_filter_cannot_observe_leaves_the_nees_band_but_not_the_rates() {
    // 5e-5 rad: half the noise, unobservable from α alone (the estimator's module docs).
    let s = summary(&["sensors.alpha.bias=5e-5"]);
    let top = band(2.0, RUNS).1;
    assert!(s.nees.mean > 3.0 * top, "{:?}", s.nees);
    assert!(s.nees.fraction_inside() < 0.05, "{:?}", s.nees);
    // α̇ stays unbiased (d takes up the bias through the gravity-gradient stiffness).
    assert!(s.rate_nees.mean <= 1.0, "{:?}", s.rate_nees);
}
