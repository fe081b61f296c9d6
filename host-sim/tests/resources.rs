//! Resource bounds of the simulator: memory grows with what is written, never
//! with what is asked.

use std::path::Path;

use tss_reel::controller::{Controller, Input, Output};
use tss_sim::scenario::{Scenario, ScenarioError};
use tss_sim::sim::{self, SimError, Stepper};

/// The core linked in, failing after a few periods (as a PIL link that dies would).
struct FailAfter {
    core: Controller<f32>,
    periods_left: u32,
}

impl Stepper<f32> for FailAfter {
    fn step(&mut self, tick: u32, input: Option<&Input<f32>>) -> Result<Output<f32>, SimError> {
        if self.periods_left == 0 {
            return Err(SimError::Link(Box::new(std::io::Error::other(
                "stopped by the test",
            ))));
        }
        self.periods_left -= 1;
        Stepper::step(&mut self.core, tick, input)
    }
}

/// A mission asked for 2³² − 1 s with a sample every second: the history holds only the samples
/// written before the stepper failed. Reserved from the asked duration, it would be room for
/// 4 294 967 297 samples (about 500 GB) before the first step, and the process would abort.
#[test]
fn the_history_is_not_reserved_from_the_asked_duration() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml");
    let mut sc = Scenario::load(path, &[]).unwrap();
    // Set after loading: the scenario's own bound on the duration is not what is tested here.
    sc.simulation.duration_s = f64::from(u32::MAX) * sc.controller.period_s;
    sc.simulation.output_interval_s = sc.controller.period_s;
    let core = Controller::new(sim::controller_config::<f32>(&sc).unwrap()).unwrap();
    let mut stepper = FailAfter {
        core,
        periods_left: 100,
    };
    let result = sim::run_stepper(&sc, &mut stepper, &[], &mut |_| {});
    assert!(matches!(result, Err(SimError::Link(_))), "{result:?}");
}

fn scenario_path(file: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(file)
}

/// The fields a scenario's validation blames, or none when it loads.
fn blamed(file: &str, sets: &[&str]) -> Vec<String> {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    match Scenario::load(scenario_path(file), &sets) {
        Ok(_) => Vec::new(),
        Err(ScenarioError::Invalid { problems, .. }) => {
            problems.into_iter().map(|p| p.field).collect()
        }
        Err(e) => panic!("{file} {sets:?}: {e}"),
    }
}

/// The elastic plant refuses work it cannot finish, when the scenario loads, naming the key.
/// Unchecked, EA = 1e18 runs at 73 s per simulated second (60 days for the mission); EA 1e20,
/// C = 1e9, 1 m segments, courant 1e-9, J = 1e-30 and a 1 GHz inner rate hang with no output;
/// 1 mm segments abort on a 1.6 GB allocation.
#[test]
fn the_elastic_plant_refuses_work_it_cannot_finish() {
    let cases: &[(&str, &[&str], &str)] = &[
        (
            "paper-elastic.toml",
            &["tether.axial_stiffness_n=1e18"],
            "tether.axial_stiffness_n",
        ),
        (
            "paper-elastic.toml",
            &["tether.axial_stiffness_n=1e20"],
            "tether.axial_stiffness_n",
        ),
        (
            "paper-elastic.toml",
            &["tether.damping_ns=1e9"],
            "tether.damping_ns",
        ),
        (
            "paper-elastic.toml",
            &[
                "tether.segment_length_m=1",
                "tether.min_stiffness_length_m=1",
            ],
            "tether.segment_length_m",
        ),
        (
            "paper-elastic.toml",
            &[
                "tether.segment_length_m=0.001",
                "tether.min_stiffness_length_m=0.001",
            ],
            "tether.segment_length_m",
        ),
        (
            "paper-elastic.toml",
            &["plant.courant=1e-9"],
            "plant.courant",
        ),
        (
            "paper-elastic.toml",
            &["reel.drum_inertia_kgm2=1e-30"],
            "reel.drum_inertia_kgm2",
        ),
        (
            "paper-drive.toml",
            &["reel.inner_rate_hz=1000000000"],
            "reel.inner_rate_hz",
        ),
    ];
    for (file, sets, key) in cases {
        let fields = blamed(file, sets);
        assert!(
            fields.iter().any(|f| f == key),
            "{file} {sets:?}: {fields:?}"
        );
    }
}

/// The estimate bounds what the plant does: the shipped elastic scenarios are within it, and
/// a run of paper-elastic's first minutes takes no more substeps than it says.
#[test]
fn the_shipped_elastic_scenarios_are_within_the_bounds() {
    for file in [
        "paper-elastic.toml",
        "paper-drive.toml",
        "paper-montecarlo-elastic.toml",
    ] {
        assert_eq!(blamed(file, &[]), Vec::<String>::new(), "{file}");
        let sc = Scenario::load(scenario_path(file), &[]).unwrap();
        let cost = tss_sim::scenario::elastic_cost(&sc).unwrap();
        assert!(
            cost.node_steps() < tss_sim::scenario::MAX_ELASTIC_NODE_STEPS,
            "{file}: {cost:?}"
        );
    }
}

/// The estimate is an upper bound of the plant's own step choice: paper-elastic flown from its
/// release (no beads) and from 20 km (13 beads) never takes more substeps in a period than the
/// estimate allows, nor holds more nodes.
#[test]
fn the_elastic_plant_steps_within_its_estimate() {
    let sc = Scenario::load(scenario_path("paper-elastic.toml"), &[]).unwrap();
    let cost = tss_sim::scenario::elastic_cost(&sc).unwrap();
    let periods = (sc.simulation.duration_s / sc.controller.period_s).round();
    let per_period = cost.steps / periods;
    let cfg = sim::controller_config::<f32>(&sc).unwrap();
    for length_m in [sc.initial.length_m, 20_000.0] {
        let mut init = sim::elastic_initial(&sc, &cfg);
        init.length_m = length_m;
        let mut plant =
            tss_sim::elastic::ElasticPlant::new(tss_sim::elastic::ElasticParams::from(&sc), init)
                .unwrap();
        let mut most = 0;
        for _ in 0..300 {
            plant.step(2.0, sc.controller.period_s).unwrap();
            most = most.max(plant.substeps_last());
        }
        assert!(
            f64::from(most) <= per_period,
            "{length_m} m: {most} > {per_period}"
        );
        assert!(
            plant.shape_orbit_frame().len() as f64 <= cost.nodes,
            "{length_m} m"
        );
    }
}
