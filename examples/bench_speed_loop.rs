//! # bench_speed_loop: instructions per inner speed-loop step on the Cortex-M4F (QEMU)
//!
//! Flies `tss_reel::reel_drive::SpeedLoop` (the example reel, 1 kHz) against a small drum
//! model and prints, with defmt, how many instructions one [`SpeedLoop::step`] takes (median,
//! 99th percentile, worst, per brake state) against the ceiling of 250, and what a
//! [`SpeedLoop::set_command`] (once a law period) and a [`SpeedLoop::paid_out_m`] (telemetry)
//! cost. The inputs visit every branch of the step:
//!
//! 1. `mission`: brake release, the law's 0.5 m/s² ramp to 5 m/s, a hold, a stop and the
//!    brake engaging at rest (20 000 ticks);
//! 2. `faults`: a saturated 0.5 → 10 m/s step, a one-tick encoder jump, missing counts, bad
//!    tension readings, a load cell reading ten times the tension (dropped until the trip's
//!    clearing), a non-finite command, a jammed drum until its trip (`NoResponse`), a cleared
//!    trip, a counter that lost counts for good until the encoder trip;
//! 3. `worst`: every arm's worst path, the fault branches of one step together: encoder jumps
//!    (one tick in three) and an overload tension on a jammed drum, through the trip, the
//!    tripped state, a brake release, the brake's rest count while the stall and saturation
//!    counters run, a release on the jammed drum under the overload, and the encoder trip
//!    (6 000 ticks);
//! 4. `brake`: safe hold at rest under the tension, the brake weakened until it slips, the
//!    slip found and the motor holding the drum under the brake (5 000 ticks).
//!
//! Run it (after `scripts/setup`) with
//!
//! ```text
//! cargo build --profile firmware --target thumbv7em-none-eabihf --features firmware --example bench_speed_loop
//! TSS_QEMU_ICOUNT='shift=0,align=off,sleep=off' TSS_LOG_FORMAT='{L} {s}' \
//!   scripts/qemu-run target/thumbv7em-none-eabihf/firmware/examples/bench_speed_loop
//! ```
//!
//! Instructions are counted as in `examples/bench_step.rs` (whose module docs explain it):
//! QEMU's `-icount shift=0` makes one instruction one ns of virtual time, SysTick runs at 25 MHz
//! (40 instructions a count, checked at start against a delay loop of known length), each
//! measurement is `K` calls on `K` copies of the state behind `black_box`, the timing loop's
//! own cost subtracted. The meter is a copy of that file's (an example cannot import another's
//! items). The figures are instructions, not cycles (a VDIV takes 14 cycles on silicon).
//!
//! On the host this file compiles to an empty program.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

use tss_reel::firmware::exit;

mod bench {
    use core::hint::black_box;
    pub use tss_reel::firmware::bench::{Meter, Stats, K};
    use tss_reel::reel_drive::{Brake, DriveConfig, DriveInput, RateCommand, SpeedLoop};

    /// Built for `scripts/bench-target`'s execution trace (`TSS_BENCH_TRACED=1` at build time):
    /// each step is called once on one copy of the drive instead of timed on `K` copies, so
    /// that the trace (which counts every call exactly) runs 8 times faster; the meter's
    /// figures are then 0.
    const TRACED: bool = option_env!("TSS_BENCH_TRACED").is_some();

    /// The ceiling for one inner step, checked against the worst case.
    pub const CEILING_INSTRUCTIONS: u32 = 250;

    /// The meter's worst case carries up to this many instructions of SysTick quantisation and
    /// of the call's own cost (`scripts/bench-target`): one this close to the ceiling is judged
    /// on the exact count of the execution trace (`TSS_BENCH_EXACT=1`).
    pub const METER_MARGIN_INSTRUCTIONS: u32 = 10;

    /// Whether the meter's `worst` says the ceiling holds.
    pub fn verdict(worst: u32) -> &'static str {
        if worst + METER_MARGIN_INSTRUCTIONS <= CEILING_INSTRUCTIONS {
            "holds"
        } else if worst > CEILING_INSTRUCTIONS + METER_MARGIN_INSTRUCTIONS {
            "EXCEEDED"
        } else {
            "within the meter's margin, judged on the exact count"
        }
    }

    /// The test drum of `tests/reel_drive.rs`, in f32 with an f64 angle (outside the timing):
    /// J 10 % and friction 20/25 % above the loop's model, 20 N of tension.
    struct Drum {
        rate_radps: f32,
        angle_counts: f64,
        jammed: bool,
        /// The engaged brake holds 1 N m only (the tension's 2 N m makes it slip).
        weak_brake: bool,
    }

    const COUNTS_PER_RAD: f64 = 40_960.0 / core::f64::consts::TAU;
    const DT_S: f32 = 1e-3;

    impl Drum {
        fn advance(&mut self, duty: f32, released: bool, tension_n: f32) {
            if self.jammed || (!released && !self.weak_brake) {
                self.rate_radps = 0.0;
                return;
            }
            let friction = if released { 0.25 } else { 1.25 };
            let w = self.rate_radps;
            let drive = 5.0 * duty + 0.1 * tension_n - 0.012 * w;
            let next = if w == 0.0 && libm::fabsf(drive) <= friction {
                0.0
            } else {
                let sign = if w != 0.0 { w } else { drive };
                let coulomb = if sign > 0.0 { friction } else { -friction };
                let n = w + (drive - coulomb) / 0.055 * DT_S;
                if w != 0.0 && (n > 0.0) != (w > 0.0) {
                    0.0
                } else {
                    n
                }
            };
            self.angle_counts += f64::from(0.5 * (w + next) * DT_S) * COUNTS_PER_RAD;
            self.rate_radps = next;
        }

        fn raw_count(&self) -> u32 {
            (libm::floor(self.angle_counts) as i64 as u32) & 0xFFFF
        }
    }

    /// Per-brake-state worst and mean.
    #[derive(Clone, Copy)]
    struct StateStats {
        n: u32,
        sum: u64,
        max: u32,
    }

    /// Everything measured over one scenario.
    pub struct Run {
        pub step: Stats<1024>,
        states: [StateStats; 5],
        pub command: Stats<1024>,
    }

    const STATES: [&str; 5] = ["Engaged", "Releasing", "Released", "MotorHold", "Tripped"];

    fn state_index(b: Brake) -> usize {
        match b {
            Brake::Engaged => 0,
            Brake::Releasing { .. } => 1,
            Brake::Released { .. } => 2,
            Brake::MotorHold => 3,
            Brake::Tripped(_) => 4,
        }
    }

    /// What a scenario does at one tick besides stepping.
    pub enum Action {
        None,
        Command(f32, f32),
        /// A command in safe hold (rate, acceleration).
        Hold(f32, f32),
        /// The brake becomes one that slips under the tension.
        WeakenBrake,
        Jam,
        /// Jams the drum and commands (rate, acceleration) in the same tick.
        JamAndCommand(f32, f32),
        ClearTrip,
    }

    /// What a scenario feeds the loop at one tick: the action, and how the readings are spoiled.
    pub struct Tick {
        pub action: Action,
        pub count_offset: u32,
        pub count_missing: bool,
        pub tension_n: Option<f32>,
    }

    /// Flies a fresh speed loop over `ticks` ticks of `scenario`, timing every step and command.
    fn run(m: &Meter, r: &mut Run, ticks: u32, mut scenario: impl FnMut(u32) -> Tick) {
        let Ok(mut drive) = SpeedLoop::new(DriveConfig::example()) else {
            defmt::error!("the example drive configuration was rejected");
            crate::exit::failure();
        };
        let mut drum = Drum {
            rate_radps: 0.0,
            angle_counts: 0.0,
            jammed: false,
            weak_brake: false,
        };
        for tick in 0..ticks {
            let t = scenario(tick);
            let action = match t.action {
                Action::JamAndCommand(rate_mps, accel_mps2) => {
                    drum.jammed = true;
                    Action::Command(rate_mps, accel_mps2)
                }
                other => other,
            };
            match action {
                Action::None | Action::JamAndCommand(..) => {}
                Action::Command(rate_mps, accel_mps2) | Action::Hold(rate_mps, accel_mps2) => {
                    let cmd = RateCommand {
                        rate_mps,
                        accel_mps2,
                        safe_hold: matches!(action, Action::Hold(..)),
                    };
                    let mut copies: [SpeedLoop; K] = core::array::from_fn(|_| drive.clone());
                    let cost = m.per_call(&mut copies, |d| d.set_command(black_box(cmd), tick));
                    r.command.add(cost, tick);
                    let _ = drive.set_command(cmd, tick);
                }
                Action::Jam => drum.jammed = true,
                Action::WeakenBrake => drum.weak_brake = true,
                Action::ClearTrip => {
                    drive.clear_trip();
                    drum.jammed = false;
                }
            }
            let input = DriveInput {
                tick,
                encoder_count: (!t.count_missing)
                    .then(|| drum.raw_count().wrapping_add(t.count_offset)),
                tension_n: t.tension_n,
            };
            let cost = if TRACED {
                // One call on one copy (a second call site, as the meter's, keeps the step out
                // of line): the trace counts it exactly.
                let mut copy = drive.clone();
                black_box(black_box(&mut copy).step(black_box(&input)));
                0
            } else {
                let mut copies: [SpeedLoop; K] = core::array::from_fn(|_| drive.clone());
                m.per_call(&mut copies, |d| {
                    black_box(d.step(black_box(&input)));
                })
            };
            drive.step(&input);
            let out = drive.motor();
            r.step.add(cost, tick);
            let s = &mut r.states[state_index(out.brake)];
            s.n += 1;
            s.sum += u64::from(cost);
            s.max = s.max.max(cost);
            drum.advance(out.duty, out.brake.brake_released(), 20.0);
        }
    }

    /// Measures one scenario and prints its figures.
    #[inline(never)]
    pub fn measure(m: &Meter, name: &str, ticks: u32, scenario: impl FnMut(u32) -> Tick) {
        let mut r = Run {
            step: Stats::new(),
            states: [StateStats {
                n: 0,
                sum: 0,
                max: 0,
            }; 5],
            command: Stats::new(),
        };
        run(m, &mut r, ticks, scenario);
        let s = &r.step;
        defmt::info!(
            "{=str}: SpeedLoop::step instructions over {=u32} steps: median {=u32}, p99 {=u32}, worst {=u32} (tick {=u32}), mean {=u32}; ceiling {=u32}: {=str}",
            name,
            s.n,
            s.quantile(500),
            s.quantile(990),
            s.max.0,
            s.max.1,
            s.mean(),
            CEILING_INSTRUCTIONS,
            verdict(s.max.0)
        );
        for (i, st) in r.states.iter().enumerate() {
            if st.n > 0 {
                defmt::info!(
                    "{=str}: brake {=str}: {=u32} steps, mean {=u32}, worst {=u32}",
                    name,
                    STATES[i],
                    st.n,
                    (st.sum / u64::from(st.n)) as u32,
                    st.max
                );
            }
        }
        let c = &r.command;
        if c.n > 0 {
            defmt::info!(
                "{=str}: SpeedLoop::set_command over {=u32} commands: median {=u32}, worst {=u32}",
                name,
                c.n,
                c.quantile(500),
                c.max.0
            );
        }
    }

    /// The cost of the telemetry length (an i64 → f32 conversion and a product).
    pub fn paid_out(m: &Meter) {
        let mut drive = SpeedLoop::new(DriveConfig::example()).ok();
        if let Some(d) = drive.as_mut() {
            d.step(&DriveInput {
                tick: 0,
                encoder_count: Some(0),
                tension_n: Some(20.0),
            });
            d.step(&DriveInput {
                tick: 1,
                encoder_count: Some(1234),
                tension_n: Some(20.0),
            });
        }
        let Some(d) = drive else {
            crate::exit::failure();
        };
        let mut copies: [SpeedLoop; K] = core::array::from_fn(|_| d.clone());
        let cost = m.per_call(&mut copies, |d| d.paid_out_m());
        defmt::info!("SpeedLoop::paid_out_m: {=u32} instructions", cost);
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    use bench::{Action, Tick};

    let meter = tss_reel::firmware::bench::start_checked();

    let quiet = |action| Tick {
        action,
        count_offset: 0,
        count_missing: false,
        tension_n: Some(20.0),
    };
    // The law's ramp once a second: 0.5 m/s² to 5 m/s, hold, stop, brake.
    bench::measure(&meter, "mission", 20_000, |tick| {
        let action = match (tick % 1000, tick / 1000) {
            (0, s) if s < 13 => {
                let rate = (0.5 * (s + 1) as f32).min(5.0);
                Action::Command(rate, if rate < 5.0 { 0.5 } else { 0.0 })
            }
            (0, 15) => Action::Command(0.0, -5.0),
            _ => Action::None,
        };
        quiet(action)
    });
    // Faults, each for a while: see the crate docs.
    bench::measure(&meter, "faults", 12_000, |tick| {
        let mut t = quiet(match tick {
            0 => Action::Command(0.5, 0.0),
            1000 => Action::Command(10.0, 5.0),
            4000 => Action::Command(2.0, -5.0),
            6000 => Action::Command(f32::NAN, 0.0),
            7000 => Action::Command(1.0, 1.0),
            8000 => Action::Jam,
            9500 => Action::ClearTrip,
            _ => Action::None,
        });
        match tick {
            5000 => t.count_offset = 20_000,
            5100..=5109 => t.count_missing = true,
            5200 => t.tension_n = Some(f32::NAN),
            5201 => t.tension_n = None,
            5202 => t.tension_n = Some(1e6),
            5203 => t.tension_n = Some(-1e6),
            // A load cell reading ten times the tension: dropped (until the trip's clearing).
            5300..=5799 => t.tension_n = Some(199.0),
            // A counter that lost counts for good: jumps until the encoder trip.
            11_000.. => t.count_offset = 20_000,
            _ => {}
        }
        t
    });
    // Every arm's worst path: the fault branches of one step combined. A jammed drum under an
    // overload (the reading clamped into range, a fault) and an encoder jump every third tick
    // (rejected, its total predicted, no trip): a moving command until the stall trips (then
    // tripped, with the same faults); cleared, back to normal tension; then a rest command on
    // the jammed drum, so the brake counts its rest ticks while the stall and saturation
    // counters run; cleared again; a moving command on the jammed drum under the overload, so
    // that the brake's release (the reference at rest, inside the Coulomb band) comes with the
    // stall's count and the saturation's, until the stall trips; cleared again; a counter that
    // lost counts for good until the encoder trip, under the overload.
    bench::measure(&meter, "worst", 6_000, |tick| {
        let mut t = quiet(match tick {
            0 => Action::Command(0.5, 0.0),
            1000 => Action::Jam,
            3000 => Action::JamAndCommand(0.0, -5.0),
            4100 => Action::JamAndCommand(0.5, 0.0),
            2000 | 4000 | 4900 => Action::ClearTrip,
            _ => Action::None,
        });
        // (A slack reading, below the range, while the drum is first jammed: the tension's
        // longest arm, with the stall's count and the saturation's the other way.)
        if (1000..2000).contains(&tick) {
            t.tension_n = Some(-1e6);
        }
        let overload = (3000..4000).contains(&tick) || (4100..4900).contains(&tick) || tick >= 5000;
        if overload {
            t.tension_n = Some(1e6);
        }
        if (1000..4000).contains(&tick) && tick % 3 == 0 {
            t.count_offset = 20_000;
        }
        if tick >= 5000 {
            t.count_offset = 20_000;
        }
        t
    });
    // A brake that slips: safe hold at rest under the tension, the slip found, the motor
    // holding the drum under the brake.
    bench::measure(&meter, "brake", 5_000, |tick| {
        quiet(match tick {
            0 => Action::Command(1.0, 1.0),
            1000 => Action::Hold(0.0, -1.0),
            1500 => Action::WeakenBrake,
            _ => Action::None,
        })
    });
    bench::paid_out(&meter);

    defmt::info!("bench done");
    exit::success()
}
