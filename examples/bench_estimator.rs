//! # bench_estimator: instructions per libration-estimator step on the Cortex-M4F (QEMU)
//!
//! Runs `tss_reel::estimator::Estimator<f32>` over the whole 20-hour paper mission
//! (`examples/bench_step/mission.rs`, the benchmarks' recording: 72 001 ticks at 1 s) and
//! prints, with defmt, the instructions of one [`Estimator::step`]: median, 99th percentile,
//! worst and mean, for steps with a sample, and for a dropout (prediction only) and a gated
//! outlier. The swing sensor's α is the recording's plus a pseudo-random 1e-4 rad of noise; the
//! drive is the recorded length at the previous tick and the length's change over the period
//! (the reel rate), as the controller will give it.
//!
//! For comparison it also times nalgebra's general 3×3 forms of the two covariance products the
//! filter writes out on its structure (`Φ P Φᵀ + Q` and the Joseph update), which is why the
//! filter uses plain scalars.
//!
//! Build and run it (in the style of `scripts/bench-target`, which times `bench_step`):
//!
//! ```text
//! cargo build --profile firmware --target thumbv7em-none-eabihf --features firmware --example bench_estimator
//! TSS_LOG_FORMAT='{L} {s}' TSS_QEMU_ICOUNT='shift=0,align=off,sleep=off' TSS_QEMU_TIMEOUT=900 \
//!   scripts/qemu-run target/thumbv7em-none-eabihf/firmware/examples/bench_estimator
//! ```
//!
//! Counting: as in `examples/bench_step.rs`, QEMU runs with `-icount shift=0` (one instruction
//! per ns of virtual time), SysTick counts the 25 MHz processor clock (40 instructions a count),
//! each measurement runs the call on `K` copies of the same state behind
//! `core::hint::black_box` and divides by `K`, and the timing loop's own cost is subtracted.
//! Instructions, not cycles (a VDIV takes 14 cycles on silicon).
//!
//! On the host this file compiles to an empty program.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

use tss_reel::firmware::exit;
/// The whole paper mission, recorded every 5 s, interpolated to 1 s.
use tss_reel::recordings::mission;

mod bench {
    use core::hint::black_box;
    use nalgebra::{Matrix3, Vector3};
    use tss_reel::estimator::{Config, Drive, Estimator, Measurement, OrbitTerms};
    pub use tss_reel::firmware::bench::{Meter, Stats, K};

    /// Logs the distribution of one kind of step.
    pub fn report<const BINS: usize>(s: &Stats<BINS>, what: &str) {
        defmt::info!(
            "{=str}: {=u32} steps: median {=u32}, p99 {=u32}, worst {=u32} (tick {=u32}), mean {=u32} instructions",
            what,
            s.n,
            s.median(),
            s.quantile(990),
            s.max.0,
            s.max.1,
            s.mean()
        );
    }

    /// A small deterministic noise source (xorshift32), uniform in ±√3 σ (σ = 1e-4 rad).
    struct Noise(u32);

    impl Noise {
        fn next(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 17;
            self.0 ^= self.0 << 5;
            let unit = (self.0 >> 8) as f32 / (1u32 << 24) as f32; // [0, 1)
            (unit - 0.5) * 2.0 * 1.732e-4
        }
    }

    /// The drive of the period that ends at `tick` (the recording's length before it and its
    /// change over the period).
    fn drive(tick: u32) -> Option<Drive<f32>> {
        let before = crate::mission::sample(tick.checked_sub(1)?)?;
        let now = crate::mission::sample(tick)?;
        Some(Drive {
            length_m: before[0],
            rate_mps: now[0] - before[0],
            accel_mps2: 0.0,
            orbit: OrbitTerms::circular(crate::mission::ORBIT_RATE_RADPS).ok()?,
            mu3: 0.0,
        })
    }

    /// Times every step of the mission (with a sample), and on every 97th tick the same step
    /// without its sample (a dropout) and with an outlier instead (gated).
    #[inline(never)]
    pub fn mission(m: &Meter) {
        let Ok(mut est) = Estimator::new(Config::<f32>::paper()) else {
            defmt::error!("the paper's estimator configuration was rejected");
            crate::exit::failure();
        };
        let mut noise = Noise(0x1234_5678);
        let mut with_sample = Stats::<1024>::new();
        let mut dropout = Stats::<1024>::new();
        let mut gated = Stats::<1024>::new();
        let mut outcomes = [0_u32; 3]; // accepted, gated, other
        for tick in 1..crate::mission::TICKS {
            let (Some(d), Some(s)) = (drive(tick), crate::mission::sample(tick)) else {
                break;
            };
            let z = s[1] + noise.next();
            let mut copies = [est; K];
            with_sample.add(
                m.per_call(&mut copies, |e| e.step(black_box(&d), black_box(Some(z)))),
                tick,
            );
            if tick % 97 == 0 {
                let mut copies = [est; K];
                dropout.add(
                    m.per_call(&mut copies, |e| e.step(black_box(&d), black_box(None))),
                    tick,
                );
                let mut copies = [est; K];
                gated.add(
                    m.per_call(&mut copies, |e| {
                        e.step(black_box(&d), black_box(Some(z + 0.05)))
                    }),
                    tick,
                );
            }
            let out = est.step(&d, Some(z));
            let i = match out.measurement {
                Measurement::Accepted(_) => 0,
                Measurement::Gated(_) => 1,
                _ => 2,
            };
            outcomes[i] += 1;
        }
        report(
            &with_sample,
            "Estimator::step, sample accepted or gated (every tick)",
        );
        report(
            &dropout,
            "Estimator::step, dropout (prediction only, every 97th tick)",
        );
        report(
            &gated,
            "Estimator::step, 0.05 rad outlier gated (every 97th tick)",
        );
        defmt::info!(
            "mission outcomes: {=u32} accepted, {=u32} gated, {=u32} other",
            outcomes[0],
            outcomes[1],
            outcomes[2]
        );
    }

    /// nalgebra's general 3×3 forms of the filter's covariance products, for comparison.
    pub fn nalgebra_forms(m: &Meter) {
        let phi = Matrix3::new(1.0_f32, 0.999, 0.4995, -3.3e-6, 0.998, 0.999, 0.0, 0.0, 1.0);
        let p = Matrix3::new(
            1e-9_f32, 2e-12, 3e-15, 2e-12, 4e-15, 5e-18, 3e-15, 5e-18, 1e-19,
        );
        let q = Matrix3::from_diagonal(&Vector3::new(1e-19_f32, 1e-18, 1e-22));
        let predict = m.per_call(&mut [(phi, p, q); K], |(f, p, q)| {
            *f * *p * f.transpose() + *q
        });
        let k = Vector3::new(0.09_f32, 2e-4, 3e-7);
        let h = Vector3::new(1.0_f32, 0.0, 0.0);
        let joseph = m.per_call(&mut [(k, h, p); K], |(k, h, p)| {
            let i_kh = Matrix3::identity() - *k * h.transpose();
            i_kh * *p * i_kh.transpose() + *k * 1e-8 * k.transpose()
        });
        defmt::info!(
            "nalgebra general forms (instructions): Phi P Phi^T + Q {=u32}; Joseph (I - K H) P (I - K H)^T + K R K^T {=u32}",
            predict,
            joseph
        );
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let meter = tss_reel::firmware::bench::start_checked();
    bench::nalgebra_forms(&meter);
    bench::mission(&meter);
    defmt::info!("bench done");
    exit::success()
}
