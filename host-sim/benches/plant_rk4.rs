//! One RK4 step of the plant (Eq. 5 in f64, `tss_sim::plant::RigidModel::rk4_step`), the paper's
//! orbit and masses, 1 s step at the mission's initial state with the reel at 0.1 m/s.
//!
//! `cargo bench -p tss-sim --bench plant_rk4`. Figures only, no assertions.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use std::path::Path;
use tss_sim::scenario::Scenario;

fn bench(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml");
    let sc = Scenario::load(&path, &[]).unwrap();
    let cfg = tss_sim::sim::controller_config::<f64>(&sc).unwrap();
    let plant = tss_sim::sim::plant(&sc);
    let x = tss_sim::sim::initial_state(&sc, &cfg);
    let mut g = c.benchmark_group("plant");
    g.throughput(Throughput::Elements(1));
    g.bench_function("rk4_step", |b| {
        b.iter(|| plant.rk4_step(black_box(&x), black_box(0.1), black_box(1.0)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
