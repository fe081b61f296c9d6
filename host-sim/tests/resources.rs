//! Resource bounds of the simulator (issue 16 §5): memory grows with what is written, never
//! with what is asked.

use std::path::Path;

use tss_reel::controller::{Controller, Input, Output};
use tss_sim::scenario::Scenario;
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

/// A mission asked for 2³² − 1 s with a sample every second: on main the loop reserved room for
/// 4 294 967 297 samples (about 500 GB) before its first step and the process aborted; the
/// history now holds only the samples written before the stepper failed.
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
