//! The whole 20-hour paper mission (`scenarios/paper.toml`: 72 000 control periods of the f32
//! flight controller flying the f64 plant, RK4 at 1 s, history every 10 s), as
//! `tss-sim run` computes it (`tss_sim::sim::run`), without writing any output.
//!
//! The scenario is loaded once, outside the timing. Compare with the scipy `solve_ivp`
//! simulation of the same closed loop (`tools/scipy_reference.py`).
//!
//! `cargo bench -p tss-sim --bench paper_mission`. Figures only, no assertions.

use criterion::{criterion_group, criterion_main, Criterion};
use std::path::Path;
use tss_sim::scenario::Scenario;

fn bench(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml");
    let sc = Scenario::load(&path, &[]).unwrap();
    let mut g = c.benchmark_group("paper_mission");
    g.sample_size(20);
    g.bench_function("sim_run_20h", |b| {
        b.iter(|| tss_sim::sim::run(&sc, &[], &mut |_| {}).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
