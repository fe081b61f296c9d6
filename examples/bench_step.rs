//! # bench_step: instructions per controller step on the Cortex-M4F (QEMU `mps2-an386`)
//!
//! Flies `tss_reel::controller::Controller<f32>` over two recorded inputs and prints, with defmt,
//! how many instructions one [`Controller::step`] takes (median, 99th percentile, worst) and
//! where they go:
//!
//! 1. `replay`: the firmware's built-in input (`tss_reel::recordings::replay`): the first 720 s
//!    of the paper's mission, with the firmware's injected sensor dropout (ticks 400..450);
//! 2. `mission`: the whole 20-hour paper mission (`tss_reel::recordings::mission`: recorded
//!    every 5 s by `tests/bench_data.rs`, interpolated to 1 s): deploy, keep, slew, retrieve,
//!    keep, 72 001 steps.
//!
//! Both fly `Config::flight()` as the firmware does (the law on the onboard estimator, the
//! tension loop between the law and the limits), with a working load cell: each sample carries
//! the tension at the reel in the recorded state (`tss_reel::recordings::load_cell`: Eq. 5a
//! from the recorded l, α, α̇ and the length's differences), so the tension loop tracks it
//! (washout, tension window, admittance term) at every step that has one. The recordings
//! themselves carry no tension (the firmware's replay flies without a load cell, its loop
//! waiting for one), and a step without a reading is the cheaper path.
//!
//! Run it with `scripts/bench-target`.
//!
//! ## How instructions are counted
//!
//! QEMU's DWT cycle counter reads zero, so the clock is SysTick. QEMU runs with
//! `-icount shift=0`: every guest instruction advances virtual time by exactly 1 ns. SysTick is
//! clocked from the processor clock (CLKSOURCE = 1), which is 25 MHz on `mps2-an386`, so one
//! SysTick count is 40 ns = 40 instructions. The program checks that first (a loop of known
//! length, `cortex_m::asm::delay`), and stops if it is not so.
//!
//! To beat the 40-instruction resolution, each measurement runs the same call on `K` copies of
//! the same state (the controller is `Clone`; the pure functions get `K` copies of their
//! input), each behind `core::hint::black_box` so nothing is hoisted or shared between copies,
//! and divides by `K`. Each result is kept alive where the call left it (`Controller::step`
//! returns a reference to the output it keeps; a copy of the 60-byte `Output` would add
//! instructions that are the harness's, not the step's). The cost of the timing loop itself (measured with an empty body) is
//! subtracted. The figures are instructions, not cycles: on silicon a VDIV/VSQRT takes 14
//! cycles and a taken branch 2–4, so cycles exceed instructions.
//!
//! ## The parts of a step
//!
//! On a step where the law ran (health `Nominal`), the public pieces the controller calls are
//! timed separately, with the step's own arguments: the reference schedule (`PreparedBand::eval`
//! or the stage-2 `PreparedBand::eval_slewed`), the implicit law (`law::solve`) and its
//! acceleration (`law::acceleration`), the mass model (`MassModel::mu3_and_slope`), the
//! equilibrium-existence margin
//! (`ExistenceMonitor::whole_orbit_margin`) and the envelope (`Envelope::limit`). What is left of the
//! step is the sensor validation (the monitor's checks), the estimator, the sequencer (with the
//! Eq. 29 blend carried one period) and health state machine, dead reckoning and filling in the
//! output.
//!
//! Needs the `firmware` feature and the bare-metal target (`required-features` in Cargo.toml).
#![no_std]
#![no_main]
#![deny(unsafe_code)]

use tss_reel::firmware::exit;
/// The whole paper mission, recorded every 5 s, interpolated to 1 s.
use tss_reel::recordings::mission;
/// The firmware's built-in input: the first 720 s of the paper's mission.
use tss_reel::recordings::replay;

mod bench {
    use core::hint::black_box;
    use tss_reel::controller::{Config, Controller, Health, Input, Output, Phase};
    use tss_reel::equilibrium::ExistenceMonitor;
    pub use tss_reel::firmware::bench::{Meter, Stats, K};
    use tss_reel::law::{self, Blend, LawInput};
    use tss_reel::recordings::load_cell;
    use tss_reel::schedule::{PreparedBand, Reference};

    /// Whether this build also times the parts of each nominal step (`TSS_BENCH_PARTS` set at
    /// build time). Calling `law::solve` & co. from the benchmark makes LLVM keep them as
    /// functions of their own, where the flight build inlines them into the step, so the step's
    /// own count is taken from a build without the parts (see the crate docs).
    pub const TIME_PARTS: bool = matches!(option_env!("TSS_BENCH_PARTS"), Some(v) if !v.is_empty());

    /// The ceiling of one outer step's instructions, checked against the worst case
    /// (`scripts/bench-target` states it with the inner step's).
    pub const CEILING_INSTRUCTIONS: u32 = 1000;

    /// Mean and worst of one phase's steps.
    #[derive(Clone, Copy)]
    struct PhaseStats {
        n: u32,
        sum: u64,
        max: u32,
    }

    /// The pieces of a nominal step, in the order they are reported.
    #[derive(Clone, Copy, PartialEq, Eq, defmt::Format)]
    pub enum Part {
        /// Reference angle α_r and its derivatives (Eqs. 34/35, stage-2 slew).
        Schedule,
        /// `law::solve`: the implicit Eqs. 27 + 29 (with sin_cos 2α and √).
        LawSolve,
        /// `law::acceleration`: Eq. 30.
        LawAccel,
        /// μ3 and dμ3/dl: `MassModel::mu3_and_slope` (one comparison for a massless tether).
        MassModel,
        /// Eq. 13 existence margin: `ExistenceMonitor::whole_orbit_margin`.
        Existence,
        /// Rate/acceleration/length limits: `Envelope::limit` (with two √).
        Envelope,
    }

    const PARTS: [Part; 6] = [
        Part::Schedule,
        Part::LawSolve,
        Part::LawAccel,
        Part::MassModel,
        Part::Existence,
        Part::Envelope,
    ];

    /// Everything measured over one input sequence.
    struct Run {
        /// Every step.
        pub step: Stats<2048>,
        /// Steps where the law ran (health Nominal, no fault).
        pub nominal: Stats<2048>,
        /// The parts of the nominal steps.
        pub parts: [Stats<1024>; PARTS.len()],
        /// The rest of a nominal step: validation, sequencer, health, output.
        pub rest: Stats<1024>,
        phases: [PhaseStats; 5],
        health: [u32; 3],
    }

    fn phase_index(p: Phase) -> usize {
        match p {
            Phase::Deploy => 0,
            Phase::Keep1 => 1,
            Phase::Slew => 2,
            Phase::Retrieve => 3,
            Phase::Keep2 => 4,
        }
    }

    const PHASES: [Phase; 5] = [
        Phase::Deploy,
        Phase::Keep1,
        Phase::Slew,
        Phase::Retrieve,
        Phase::Keep2,
    ];

    impl Run {
        pub const fn new() -> Self {
            Self {
                step: Stats::new(),
                nominal: Stats::new(),
                parts: [const { Stats::new() }; PARTS.len()],
                rest: Stats::new(),
                phases: [PhaseStats {
                    n: 0,
                    sum: 0,
                    max: 0,
                }; 5],
                health: [0; 3],
            }
        }
    }

    /// The controller's stage-2 start (the paper's 8 h), for the reference's stage time.
    fn stage2_start_tick(cfg: &Config<f32>) -> u32 {
        cfg.stage2.start_tick.unwrap_or(u32::MAX)
    }

    /// Times the public pieces of a nominal step at this sample, with the arguments the
    /// controller gives them (see the crate docs). Returns each part's instructions.
    fn time_parts(
        m: &Meter,
        cfg: &Config<f32>,
        existence: &ExistenceMonitor<f32>,
        bands: &(PreparedBand<f32>, PreparedBand<f32>),
        x: &Input<f32>,
        out: &Output<f32>,
        previous_rate_mps: f32,
    ) -> [u32; PARTS.len()] {
        let l = x.length_m;
        let stage2 = matches!(out.phase, Phase::Slew | Phase::Retrieve | Phase::Keep2);
        let stage_start = if stage2 { stage2_start_tick(cfg) } else { 0 };
        let tau_s = x.tick.saturating_sub(stage_start) as f32 * cfg.period_s;
        let (stage1, stage2_band) = bands;
        let slew = cfg.stage2.slew_rate_radps;
        let schedule = if stage2 {
            m.pure((tau_s, l), |&(t, l)| stage2_band.eval_slewed(slew, t, l))
        } else {
            m.pure(l, |&l| stage1.eval(l))
        };
        let reference = if stage2 {
            stage2_band.eval_slewed(slew, tau_s, l)
        } else {
            Reference {
                angle: stage1.eval(l),
                time_rate_radps: 0.0,
                slewing: false,
                orbit: None,
            }
        };
        let (decay, initial) = if stage2 {
            (cfg.stage2.decay_rate_per_s, previous_rate_mps)
        } else {
            (cfg.stage1.decay_rate_per_s, cfg.initial_rate_mps)
        };
        let masses = cfg.masses;
        // The α and α̇ the step flew (α_r + δ, α̇_r + δ̇: the sensed ones, or the estimate).
        let law_in = LawInput {
            length_m: l,
            alpha_rad: out.alpha_ref_rad + out.delta_rad,
            alpha_rate_radps: out.alpha_ref_rate_radps + out.delta_rate_radps,
            orbit_rate_radps: x.orbit_rate_radps,
            orbit: None,
            ref_angle_rad: reference.angle.angle_rad,
            ref_slope_rad_per_m: reference.angle.slope_rad_per_m,
            ref_curvature_rad_per_m2: reference.angle.curvature_rad_per_m2,
            ref_time_rate_radps: reference.time_rate_radps,
            mu3: masses.mu3_and_slope(l).0,
            mu3_per_m: masses.mu3_and_slope(l).1,
            blend: Blend::decayed(-libm::fabsf(libm::logf(
                out.blend_weight.max(f32::MIN_POSITIVE),
            ))),
            decay_rate_per_s: decay,
            initial_rate_mps: initial,
            gains: cfg.gains,
        };
        let solve = m.pure(law_in, law::solve);
        let solution = law::solve(&law_in);
        let accel = match &solution {
            Ok(s) => m.pure((law_in, *s), |(i, s)| law::acceleration(i, s)),
            Err(_) => 0,
        };
        let mass = m.pure(l, |&l| masses.mu3_and_slope(l));
        let mu3 = law_in.mu3;
        let rate = out.rate_cmd_mps;
        let exist = m.pure((mu3, l, rate), |&(mu3, l, y)| {
            existence.whole_orbit_margin(mu3, l, y)
        });
        let env = cfg.envelope;
        let requested = solution.map(|s| s.rate_mps).unwrap_or(rate);
        let envelope = m.pure((requested, previous_rate_mps, l), |&(y, p, l)| {
            env.limit(y, p, l, cfg.period_s)
        });
        [schedule, solve, accel, mass, exist, envelope]
    }

    /// Flies a fresh controller in the flight configuration (`Config::flight`: the paper's
    /// mission on the estimator, with the tension loop) over `ticks` samples (`None`: a
    /// dropout) and measures every step, and the parts of every nominal one. A sample gives the
    /// controller l, α, the encoder's rate (the recorded length's change since the previous
    /// sample) and the load cell's tension (Eq. 5a in the recorded state), not α̇.
    fn run(
        m: &Meter,
        r: &mut Run,
        ticks: u32,
        orbit_rate_radps: f32,
        sample: impl Fn(u32) -> Option<[f32; 3]>,
    ) {
        let Ok(mut ctl) = Controller::new(Config::<f32>::flight()) else {
            defmt::error!("the flight configuration was rejected");
            crate::exit::failure();
        };
        let cfg = *ctl.config();
        let Ok(existence) = ExistenceMonitor::from_orbit(&cfg.orbit) else {
            defmt::error!("no existence monitor for the paper's orbit");
            crate::exit::failure();
        };
        let bands = (cfg.stage1.schedule.prepare(), cfg.stage2.schedule.prepare());
        let mut previous_rate = cfg.initial_rate_mps;
        let mut previous_length: Option<f32> = None;
        for tick in 0..ticks {
            let input = sample(tick).map(|s| Input {
                tick,
                length_m: s[0],
                reel_rate_mps: previous_length.map(|l| (s[0] - l) / cfg.period_s),
                tension_n: load_cell::tension_n(
                    &sample,
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
            let mut copies: [Controller<f32>; K] = core::array::from_fn(|_| ctl.clone());
            let cost = match &input {
                Some(x) => m.per_call(&mut copies, |c| {
                    let out = c.step(black_box(x));
                    black_box(&out);
                }),
                None => m.per_call(&mut copies, |c| {
                    let out = c.step_missing(black_box(tick));
                    black_box(&out);
                }),
            };
            let out = match &input {
                Some(x) => *ctl.step(x),
                None => *ctl.step_missing(tick),
            };
            // The events read every period, as the firmware reads them: each step's own events
            // go into a queue with room (a full one drops them, the cheaper path).
            while ctl.pop_event().is_some() {}
            r.step.add(cost, tick);
            let p = &mut r.phases[phase_index(out.phase)];
            p.n += 1;
            p.sum += u64::from(cost);
            p.max = p.max.max(cost);
            r.health[out.health as usize] += 1;
            if let (Some(x), Health::Nominal, None) = (&input, out.health, out.fault) {
                r.nominal.add(cost, tick);
                if !TIME_PARTS {
                    previous_rate = out.rate_cmd_mps;
                    continue;
                }
                let parts = time_parts(m, &cfg, &existence, &bands, x, &out, previous_rate);
                let mut sum = 0;
                for (s, &v) in r.parts.iter_mut().zip(&parts) {
                    s.add(v, tick);
                    sum += v;
                }
                r.rest.add(cost.saturating_sub(sum), tick);
            }
            previous_rate = out.rate_cmd_mps;
        }
    }

    /// Measures one input sequence (see [`run`]) and prints its figures. The figures live in
    /// this function's frame only (about 50 KB of histograms), one sequence at a time.
    #[inline(never)]
    pub fn measure(
        m: &Meter,
        name: &str,
        ticks: u32,
        orbit_rate_radps: f32,
        sample: impl Fn(u32) -> Option<[f32; 3]>,
    ) {
        let mut r = Run::new();
        run(m, &mut r, ticks, orbit_rate_radps, sample);
        report(name, &r);
    }

    /// Prints one run's figures (the lines `scripts/bench-target` shows and checks).
    fn report(name: &str, r: &Run) {
        let s = &r.step;
        if TIME_PARTS {
            defmt::info!(
                "{=str}: parts build: one step takes {=u32} instructions (median; more than in the step-only build because the timed parts are not inlined into it)",
                name,
                s.median()
            );
        } else {
            report_steps(name, r);
        }
        let n = &r.nominal;
        if !TIME_PARTS || n.n == 0 {
            return;
        }
        let total = r.parts.iter().map(Stats::sum).sum::<u64>() + r.rest.sum();
        let total = total.max(1);
        for (part, st) in PARTS.iter().zip(&r.parts) {
            defmt::info!(
                "{=str}: part {}: median {=u32}, worst {=u32}, mean {=u32}, share {=u32}.{=u32} %",
                name,
                part,
                st.median(),
                st.max.0,
                st.mean(),
                (st.sum() * 100 / total) as u32,
                (st.sum() * 1000 / total % 10) as u32
            );
        }
        let st = &r.rest;
        defmt::info!(
            "{=str}: part Rest (validation, estimator, sequencer, tension loop, health, output): median {=u32}, worst {=u32}, mean {=u32}, share {=u32}.{=u32} %",
            name,
            st.median(),
            st.max.0,
            st.mean(),
            (st.sum() * 100 / total) as u32,
            (st.sum() * 1000 / total % 10) as u32
        );
    }

    /// The step figures of a run (step-only build).
    fn report_steps(name: &str, r: &Run) {
        let s = &r.step;
        defmt::info!(
            "{=str}: step instructions over {=u32} steps: median {=u32}, p99 {=u32}, worst {=u32} (tick {=u32}), mean {=u32}; ceiling {=u32}: {=str}",
            name,
            s.n,
            s.median(),
            s.quantile(990),
            s.max.0,
            s.max.1,
            s.mean(),
            CEILING_INSTRUCTIONS,
            if s.max.0 <= CEILING_INSTRUCTIONS { "holds" } else { "EXCEEDED" }
        );
        defmt::info!(
            "{=str}: health Nominal {=u32}, Degraded {=u32}, SafeHold {=u32} steps",
            name,
            r.health[0],
            r.health[1],
            r.health[2]
        );
        for (i, p) in r.phases.iter().enumerate() {
            if p.n > 0 {
                defmt::info!(
                    "{=str}: phase {}: {=u32} steps, mean {=u32}, worst {=u32}",
                    name,
                    PHASES[i],
                    p.n,
                    (p.sum / u64::from(p.n)) as u32,
                    p.max
                );
            }
        }
        let n = &r.nominal;
        if n.n > 0 {
            defmt::info!(
                "{=str}: nominal steps (law ran): {=u32}: median {=u32}, worst {=u32} (tick {=u32}), mean {=u32}",
                name,
                n.n,
                n.median(),
                n.max.0,
                n.max.1,
                n.mean()
            );
        }
    }

    /// Per-call instructions of the math primitives the step uses, at typical arguments.
    pub fn primitives(m: &Meter) {
        let sc = m.pure(-1.3_f32, |&x| tss_reel::fastmath::sin_cos(x));
        let fexp = m.pure(-3.2_f32, |&t| tss_reel::fastmath::exp2_and_complement(t));
        let fsqrt = m.pure(1.7e-7_f32, |&x| tss_fpu::sqrt(x));
        let exp = m.pure(-3.2_f32, |&x| libm::expf(x));
        let sqrt = m.pure(1.7e-7_f32, |&x| libm::sqrtf(x));
        let div = m.pure((1.7e-7_f32, 3.1_f32), |&(a, b)| a / b);
        defmt::info!(
            "primitives (instructions per call): fastmath::sin_cos {=u32}, fastmath::exp2_and_complement {=u32}, tss_fpu::sqrt (VSQRT.F32) {=u32}; libm::expf {=u32}, libm::sqrtf {=u32}; f32 division {=u32}",
            sc,
            fexp,
            fsqrt,
            exp,
            sqrt,
            div
        );
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let meter = tss_reel::firmware::bench::start_checked();
    bench::primitives(&meter);

    bench::measure(
        &meter,
        "replay",
        replay::SAMPLES.len() as u32,
        replay::ORBIT_RATE_RADPS,
        |tick| {
            if (replay::DROPOUT_FROM_TICK..replay::DROPOUT_UNTIL_TICK).contains(&tick) {
                None
            } else {
                replay::SAMPLES.get(tick as usize).copied()
            }
        },
    );
    bench::measure(
        &meter,
        "mission",
        mission::TICKS,
        mission::ORBIT_RATE_RADPS,
        mission::sample,
    );

    defmt::info!("bench done");
    exit::success()
}
