//! # trace_step: the benchmark's steps, one call each, for instruction traces
//!
//! Flies `Controller<f32>` (`Config::flight`: the law on the onboard estimator) over the same
//! inputs as `examples/bench_step.rs`, with one `Controller::step` (or `step_missing`) call per
//! tick and its events read, so that an execution trace of QEMU (`tools/trace_profile.py
//! --mission-tick N`) can attribute the instructions of any step the benchmark times:
//!
//! - by default the whole 20-hour paper mission (`tss_reel::recordings::mission`);
//! - built with `TSS_TRACE_REPLAY=1`, the firmware's 720-s replay (`tss_reel::recordings::replay`)
//!   with its sensor dropout.
//!
//! Each sample carries, as in the benchmark, the encoder's rate (the recorded length's change
//! over the period), the load cell's tension in the recorded state
//! (`tss_reel::recordings::load_cell`) and α without α̇. Prints nothing per step.
//!
//! Needs the `firmware` feature and the bare-metal target (`required-features` in Cargo.toml):
//! `[TSS_TRACE_REPLAY=1] cargo build --profile firmware --target thumbv7em-none-eabihf --features
//! firmware --example trace_step`.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

use tss_reel::firmware::exit;
/// The whole paper mission, recorded every 5 s, interpolated to 1 s.
use tss_reel::recordings::mission;
/// The firmware's built-in input: the first 720 s of the paper's mission.
use tss_reel::recordings::replay;

/// A recording: its sample ([l, α, α̇]) at a tick, `None` where it has none.
type Recording = fn(u32) -> Option<[f32; 3]>;

/// Whether this build flies the replay (`TSS_TRACE_REPLAY` set at build time).
const REPLAY: bool = matches!(option_env!("TSS_TRACE_REPLAY"), Some(v) if !v.is_empty());

/// The replay's sample at `tick`, `None` in its dropout.
fn replay_sample(tick: u32) -> Option<[f32; 3]> {
    if (replay::DROPOUT_FROM_TICK..replay::DROPOUT_UNTIL_TICK).contains(&tick) {
        None
    } else {
        replay::SAMPLES.get(tick as usize).copied()
    }
}

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
    let (ticks, orbit_rate_radps, sample): (u32, f32, Recording) = if REPLAY {
        (
            replay::SAMPLES.len() as u32,
            replay::ORBIT_RATE_RADPS,
            replay_sample,
        )
    } else {
        (mission::TICKS, mission::ORBIT_RATE_RADPS, mission::sample)
    };
    let mut previous_length: Option<f32> = None;
    for tick in 0..ticks {
        let input = sample(tick).map(|s| Input {
            tick,
            length_m: s[0],
            reel_rate_mps: previous_length.map(|l| (s[0] - l) / cfg.period_s),
            tension_n: load_cell::tension_n(
                sample,
                tick,
                cfg.period_s,
                &cfg.masses,
                orbit_rate_radps,
            ),
            alpha_rad: Some(s[1]),
            alpha_rate_radps: None,
            orbit_rate_radps,
            true_anomaly_rad: 0.0,
        });
        previous_length = input.map(|x| x.length_m);
        match &input {
            Some(x) => black_box(ctl.step(black_box(x))),
            None => black_box(ctl.step_missing(black_box(tick))),
        };
        // The events read every period, as the firmware and the benchmark read them.
        while ctl.pop_event().is_some() {}
    }
    defmt::info!("trace_step done: {=u32} steps", ticks);
    exit::success()
}
