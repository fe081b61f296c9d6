//! One flight-controller step (`Controller<f32>`, the paper's configuration) on the desk.
//!
//! - `controller_step/deploy_band`: one nominal step in the stage-1 transition band (the
//!   mission at t = 3000 s), on a fresh copy of the controller's state each time;
//! - `controller_step/mission_72001_steps`: the whole 20-hour paper mission, replayed at 1 s
//!   from the benchmarks' recording (`tss_reel::recordings::mission`); divide by 72 001 for
//!   the mean step.
//!
//! `cargo bench -p tss-sim --bench controller_step`. Figures only, no assertions.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use std::hint::black_box;
use tss_reel::controller::{Config, Controller, Input};

use tss_reel::recordings::mission;

fn input(tick: u32) -> Input<f32> {
    let s = mission::sample(tick).expect("tick within the mission");
    Input {
        tick,
        length_m: s[0],
        reel_rate_mps: None,
        tension_n: None,
        alpha_rad: Some(s[1]),
        alpha_rate_radps: Some(s[2]),
        orbit_rate_radps: mission::ORBIT_RATE_RADPS,
        true_anomaly_rad: 0.0,
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("controller_step");

    // The controller as it is at t = 3000 s of the mission (deploying, in the Eq. 34 band).
    const AT: u32 = 3_000;
    let mut ctl = Controller::new(Config::<f32>::paper()).unwrap();
    for tick in 0..AT {
        ctl.step(&input(tick));
    }
    let x = input(AT);
    g.throughput(Throughput::Elements(1));
    g.bench_function("deploy_band", |b| {
        b.iter_batched_ref(
            || ctl.clone(),
            |c| *c.step(black_box(&x)),
            BatchSize::SmallInput,
        )
    });

    let inputs: Vec<Input<f32>> = (0..mission::TICKS).map(input).collect();
    g.throughput(Throughput::Elements(u64::from(mission::TICKS)));
    g.sample_size(20);
    g.bench_function("mission_72001_steps", |b| {
        b.iter(|| {
            let mut c = Controller::new(Config::<f32>::paper()).unwrap();
            let mut acc = 0.0_f32;
            for x in &inputs {
                acc += c.step(black_box(x)).rate_cmd_mps;
            }
            acc
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
