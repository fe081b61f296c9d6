//! The flight speed loop (`tss_reel::reel_drive::SpeedLoop`, f32) flying the truth model's reel
//! drum (`tss_sim::elastic::reel_drum::FlightDrum`: stick–slip, torque limit, spring brake) at
//! 1 kHz with its encoder quantised, under the paper mission's rate commands.
//!
//! The commands, their Eq. 30 accelerations and the tension at the reel are those of the
//! closed-loop paper mission (`scenarios/paper.toml`, rigid plant, every law period), flown
//! period by period with the tension held over each. The drum's deviation from the command is
//! not fed back to the tether here (it is millimetres per second against a law that moves the
//! tether by metres): the figures are the drive's, for the paper's mission.

use std::path::Path;

use tss_reel::reel_drive::{DriveFault, RateCommand};
use tss_sim::elastic::reel_drum::{DrumParams, FlightDrum};
use tss_sim::scenario::Scenario;

/// The paper's mission for `duration_s`, sampled every law period.
fn paper_commands(duration_s: f64) -> (Scenario, tss_sim::history::History) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml");
    let sc = Scenario::load(
        path,
        &[
            format!("simulation.duration_s={duration_s}"),
            "simulation.output_interval_s=1.0".to_string(),
        ],
    )
    .expect("the paper's scenario loads");
    let history = tss_sim::sim::run(&sc, &[], &mut |_| {}).expect("the paper's mission flies");
    (sc, history)
}

/// The scenario's motor drum (`[reel]`'s motor keys, their defaults in the paper's scenario).
fn drum(sc: &Scenario) -> DrumParams {
    let r = &sc.reel;
    DrumParams {
        radius_m: r.drum_radius_m,
        inertia_kgm2: r.drum_inertia_kgm2,
        viscous_nms: r.viscous_nms,
        coulomb_nm: r.coulomb_nm,
        static_nm: r.static_nm,
        max_torque_nm: r.motor_max_torque_nm,
        brake_nm: r.brake_nm,
        speed_bandwidth_radps: r.speed_bandwidth_radps,
    }
}

#[test]
fn the_flight_speed_loop_tracks_the_paper_deployment_at_1_khz() {
    // The first 30 min: the stage-1 deployment from 1 m.
    let (sc, history) = paper_commands(1800.0);
    let params = drum(&sc);
    let cfg = FlightDrum::drive_config(&params, 1000, sc.controller.period_s);
    let mut reel = FlightDrum::new(params, cfg).expect("the drive configuration is valid");
    let ticks = cfg.outer_period_ticks;
    let rest_mps = f64::from(cfg.brake.rest_speed_mps);
    // The tether the law paid out at rates the drive counts as rest (brake engaged).
    let mut at_rest_m = 0.0;
    for s in &history.samples {
        if s.length_rate_mps.abs() <= rest_mps {
            at_rest_m += s.length_rate_mps * sc.controller.period_s;
        }
        let cmd = RateCommand {
            rate_mps: s.length_rate_mps as f32,
            accel_mps2: s.length_accel_mps2 as f32,
            safe_hold: false,
        };
        let _ = reel.period(cmd, s.tension_n, ticks);
    }
    let f = *reel.figures();
    eprintln!(
        "paper deployment, {} periods at {} Hz: tracking RMS {:.2e} m/s, max {:.2e} m/s (released ticks {}), period-end max {:.2e} m/s; duty saturated {} ticks ({:.3} %); tension at the reel {:.3e}..{:.3e} N; faults {:#x}",
        history.samples.len(),
        cfg.inner_rate_hz,
        f.rms_error_mps(),
        f.max_error_mps,
        f.released_ticks,
        f.max_period_end_error_mps,
        f.saturated_ticks,
        100.0 * f.saturated_fraction(),
        f.tension_range_n.0,
        f.tension_range_n.1,
        f.fault_bits
    );
    // The drum turned, and followed its reference within the encoder's resolution (one count
    // over the 8-tick window: 1.9 mm/s) plus the loop's error.
    assert!(f.released_ticks > 1_000_000, "{f:?}");
    assert!(f.rms_error_mps() < 2e-3, "{f:?}");
    assert!(f.max_error_mps < 1e-2, "{f:?}");
    // No trip, no encoder fault.
    for fault in [
        DriveFault::EncoderJump,
        DriveFault::EncoderMissing,
        DriveFault::MotorStall,
        DriveFault::Actuator,
    ] {
        assert_eq!(f.fault_bits & (1 << fault as u16), 0, "{fault:?}: {f:?}");
    }
    // The drum paid out the tether the law asked for above the brake's rest speed (5 mm/s:
    // below it the brake holds the drum), to half a metre of 30 (the brake's release and
    // engage delays, the ramps between commands).
    let drum_m = f64::from(reel.speed_loop().paid_out_m());
    let tether_m = history.samples.last().unwrap().length_m - history.samples[0].length_m;
    eprintln!(
        "paid out: drum {drum_m:.3} m, tether {tether_m:.3} m, of which {at_rest_m:.3} m at rates below the rest speed"
    );
    assert!(
        (drum_m - (tether_m - at_rest_m)).abs() < 0.5,
        "{drum_m} {tether_m} {at_rest_m}"
    );
}
