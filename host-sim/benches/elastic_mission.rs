//! The whole 20-hour paper mission on the truth model (`scenarios/paper-elastic.toml`: 0.5 mm
//! Dyneema in 20 beads at 30 km, the motor reel, J2 and drag; 72 000 control periods of the
//! f32 flight controller), as `tss-sim run` computes it (`tss_sim::sim::run`), without writing
//! any output, at three steps side by side: the scenario's (`plant.courant = 2`), the former
//! default (`plant.courant = 1`) and a quarter of the scenario's (`plant.courant = 0.5`, the
//! convergence reference of docs/truth-model.md); and, for where the time goes, one control
//! period of the elastic plant alone at 30 km (20 beads) and at 2 km (no bead).
//!
//! The missions are timed in **processor time** (user and system, of this process:
//! `tss_sim::montecarlo::cmd::process_cpu_seconds`, 10-ms ticks against 0.3–1.5 s a mission),
//! the CPU-s a campaign pays per run, which other processes on a shared machine do not inflate
//! as they do the wall time; the plant periods (microseconds) in wall time.
//!
//! `cargo bench -p tss-sim --bench elastic_mission`. Figures only, no assertions.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;
use tss_sim::elastic::{ElasticParams, ElasticPlant, InitialConditions};
use tss_sim::montecarlo::cmd::process_cpu_seconds;
use tss_sim::scenario::Scenario;

fn bench(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper-elastic.toml");
    let sc = Scenario::load(&path, &[]).unwrap();
    let mut g = c.benchmark_group("elastic_mission");
    g.sample_size(10);
    for courant in [sc.plant.courant, 1.0, 0.5] {
        let sets = [format!("plant.courant={courant}")];
        let sc = Scenario::load(&path, &sets).unwrap();
        g.bench_function(format!("sim_run_20h_courant_{courant}"), |b| {
            b.iter_custom(|iters| {
                let start = process_cpu_seconds().expect("/proc/self/stat");
                for _ in 0..iters {
                    black_box(tss_sim::sim::run(&sc, &[], &mut |_| {}).unwrap());
                }
                Duration::from_secs_f64(process_cpu_seconds().unwrap() - start)
            })
        });
    }
    for length_m in [30_000.0, 2_000.0] {
        let plant = ElasticPlant::new(
            ElasticParams::from(&sc),
            InitialConditions {
                length_m,
                rate_mps: 0.0,
                alpha_rad: 0.0,
                alpha_rate_radps: 0.0,
                beta_rad: 0.0,
                beta_rate_radps: 0.0,
            },
        )
        .unwrap();
        let name = format!("plant_period_{}km", length_m / 1000.0);
        g.bench_function(&name, |b| {
            b.iter_batched_ref(
                || plant.clone(),
                |p| p.step(black_box(0.0), 1.0).unwrap(),
                criterion::BatchSize::SmallInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
