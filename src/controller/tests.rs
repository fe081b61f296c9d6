//! Tests of the controller's step that need its private parts.

use super::*;

/// The paper's stage 1 at `tick` with the load cell reading `tension_n`.
fn sample(tick: u32, tension_n: Option<f64>) -> Input<f64> {
    Input {
        tick,
        length_m: 1.0 + 0.1 * f64::from(tick),
        reel_rate_mps: None,
        tension_n,
        alpha_rad: Some(-35.0_f64.to_radians()),
        alpha_rate_radps: Some(0.0),
        orbit_rate_radps: 1.0602e-3,
        true_anomaly_rad: 0.0,
    }
}

#[test]
fn the_tension_limit_is_an_event_each_time_it_begins() {
    // A load cell the protection follows within a period, and a low tension limit.
    let protection = ProtectionConfig {
        max_tension_n: 0.5,
        tension_filter_s: 1.0,
        ..ProtectionConfig::default_for_period()
    };
    let cfg = Config {
        protection: Some(protection),
        ..Config::<f64>::paper()
    };
    let mut ctl = Controller::new(cfg).unwrap();
    // Inside the window, above it (limited), no reading (no tension bound), above it again.
    let (ok, over) = (Some(0.1), Some(5.0));
    let tensions = [ok, ok, over, over, over, None, None, over, over];
    let mut limited = [false; 9];
    let mut began = [false; 9];
    for (tick, &t) in (0u32..).zip(&tensions) {
        let out = ctl.step(&sample(tick, t));
        limited[tick as usize] = out.flags.contains(Flags::TENSION_LIMITED);
        while let Some(e) = ctl.pop_event() {
            began[tick as usize] |= e.kind == EventKind::TensionLimited;
        }
    }
    let (f, t) = (false, true);
    assert_eq!(limited, [f, f, t, t, t, f, f, t, t]);
    assert_eq!(began, [f, f, t, f, f, f, f, t, f]);
}
