//! # trace_step: the paper mission's steps, one call each, for instruction traces
//!
//! Flies `Controller<f32>` (`Config::flight`: the law on the onboard estimator) over the whole 20-hour paper mission (`tss_reel::recordings::mission`)
//! with one `Controller::step` call per tick and nothing else (the load cell reading the
//! recorded state's tension, `tss_reel::recordings::load_cell`, as in `examples/bench_step.rs`), so that an execution trace of
//! QEMU (`tools/trace_profile.py --mission-tick N`) can attribute the instructions of any
//! mission step, not only those of the firmware's 720-s replay. Prints nothing per step.
//!
//! Needs the `firmware` feature and the bare-metal target (`required-features` in Cargo.toml):
//! `cargo build --profile firmware --target thumbv7em-none-eabihf --features firmware --example
//! trace_step`.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

use tss_reel::firmware::exit;
/// The whole paper mission, recorded every 5 s, interpolated to 1 s.
use tss_reel::recordings::mission;

#[cortex_m_rt::entry]
fn main() -> ! {
    use core::hint::black_box;
    use tss_reel::controller::{Config, Controller, Input};
    use tss_reel::recordings::load_cell;

    // The flight configuration (the law on the onboard estimator), as bench_step's figures.
    let Ok(mut ctl) = Controller::new(Config::<f32>::flight()) else {
        defmt::error!("the flight configuration was rejected");
        exit::failure();
    };
    let cfg = *ctl.config();
    for tick in 0..mission::TICKS {
        let Some(s) = mission::sample(tick) else {
            black_box(ctl.step_missing(tick));
            continue;
        };
        let x = Input {
            tick,
            length_m: s[0],
            reel_rate_mps: None,
            tension_n: load_cell::tension_n(
                mission::sample,
                tick,
                cfg.period_s,
                &cfg.masses,
                mission::ORBIT_RATE_RADPS,
            ),
            alpha_rad: Some(s[1]),
            alpha_rate_radps: Some(s[2]),
            orbit_rate_radps: mission::ORBIT_RATE_RADPS,
            true_anomaly_rad: 0.0,
        };
        black_box(ctl.step(black_box(&x)));
    }
    defmt::info!("trace_step done: {=u32} steps", mission::TICKS);
    exit::success()
}
