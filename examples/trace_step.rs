//! # trace_step: the paper mission's steps, one call each, for instruction traces
//!
//! Flies `Controller<f32>` over the whole 20-hour paper mission (`examples/bench_step/mission.rs`)
//! with one `Controller::step` call per tick and nothing else, so that an execution trace of
//! QEMU (`tools/trace_profile.py --mission-tick N`) can attribute the instructions of any
//! mission step, not only those of the firmware's 720-s replay. Prints nothing per step.
//!
//! On the host this file compiles to an empty program.
#![cfg_attr(target_os = "none", no_std, no_main)]
#![deny(unsafe_code)]

/// Host stub: the program runs only on the target.
#[cfg(not(target_os = "none"))]
fn main() {}

#[cfg(target_os = "none")]
use defmt_semihosting as _;
#[cfg(target_os = "none")]
use panic_probe as _;

/// The firmware's exits and fault handlers, shared file.
#[cfg(target_os = "none")]
#[path = "../src/firmware/exit.rs"]
mod exit;

/// The whole paper mission, recorded every 5 s, interpolated to 1 s.
#[cfg(target_os = "none")]
#[allow(dead_code)]
#[path = "bench_step/mission.rs"]
mod mission;

#[cfg(target_os = "none")]
#[cortex_m_rt::entry]
fn main() -> ! {
    use core::hint::black_box;
    use tss_reel::controller::{Config, Controller, Input};

    let Ok(mut ctl) = Controller::new(Config::<f32>::paper()) else {
        defmt::error!("the paper's configuration was rejected");
        exit::failure();
    };
    for tick in 0..mission::TICKS {
        let Some(s) = mission::sample(tick) else {
            black_box(ctl.step_missing(tick));
            continue;
        };
        let x = Input {
            tick,
            length_m: s[0],
            alpha_rad: s[1],
            alpha_rate_radps: s[2],
            orbit_rate_radps: mission::ORBIT_RATE_RADPS,
        };
        black_box(ctl.step(black_box(&x)));
    }
    defmt::info!("trace_step done: {=u32} steps", mission::TICKS);
    exit::success()
}
