//! Instruction counting for the on-target benchmarks (`examples/bench_step.rs`,
//! `bench_estimator.rs`, `bench_speed_loop.rs`; `scripts/bench-target`), in QEMU's `mps2-an386`.
//!
//! QEMU's DWT cycle counter reads zero, so the clock is SysTick, free-running on the processor
//! clock (25 MHz on `mps2-an386`). QEMU runs with `-icount shift=0`: every guest instruction
//! advances virtual time by exactly 1 ns, so one SysTick count is 40 instructions
//! ([`INSTRUCTIONS_PER_COUNT`]; [`Meter::instructions_of_delay`] lets a benchmark check it).
//! To beat that resolution each measurement runs the same call on [`K`] copies of the same
//! state, each behind `core::hint::black_box`, and divides by [`K`]; the loop's own cost,
//! measured with an empty body, is subtracted. The figures are instructions, not cycles.

use core::hint::black_box;
use cortex_m::peripheral::{syst::SystClkSource, SYST};

/// Copies of the state each measurement runs on; the result is divided by this.
pub const K: usize = 16;

/// The processor clock of `mps2-an386` (QEMU's `SYSCLK_FRQ`), Hz.
const CORE_CLOCK_HZ: u32 = 25_000_000;

/// Virtual nanoseconds per instruction under `-icount shift=0` (2⁰).
const NS_PER_INSTRUCTION: u32 = 1;

/// Instructions per SysTick count: 40 at 25 MHz.
pub const INSTRUCTIONS_PER_COUNT: u32 = 1_000_000_000 / CORE_CLOCK_HZ / NS_PER_INSTRUCTION;

/// SysTick's reload value: the full 24-bit range (period 2²⁴ counts, 671 ms of virtual time).
const RELOAD: u32 = 0x00FF_FFFF;

/// The free-running SysTick (no interrupt), counting processor clocks.
pub struct Meter {
    _syst: SYST,
    /// Instructions of the timing loop itself for `K` iterations (subtracted).
    overhead_instructions: u32,
}

impl Meter {
    /// Starts SysTick on the processor clock and calibrates the loop overhead.
    pub fn start(mut syst: SYST) -> Self {
        syst.disable_interrupt();
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(RELOAD);
        syst.clear_current();
        syst.enable_counter();
        let mut m = Self {
            _syst: syst,
            overhead_instructions: 0,
        };
        let mut empty = [0_u32; K];
        // The smallest of a few runs: the loop's own cost.
        let mut least = u32::MAX;
        for _ in 0..8 {
            least = least.min(m.raw(&mut empty, |_| ()));
        }
        m.overhead_instructions = least;
        m
    }

    /// The loop overhead that is subtracted, instructions per `K` iterations.
    pub fn overhead(&self) -> u32 {
        self.overhead_instructions
    }

    /// SysTick counts between two readings of the down-counter (at most one wrap).
    fn counts(start: u32, end: u32) -> u32 {
        start.wrapping_sub(end) & RELOAD
    }

    /// Instructions of `K` calls of `f`, one per state, loop included. Out of line, so that
    /// the timed loop is the same code for every measurement.
    #[inline(never)]
    fn raw<S, R>(&self, states: &mut [S; K], mut f: impl FnMut(&mut S) -> R) -> u32 {
        let t0 = SYST::get_current();
        for s in states.iter_mut() {
            // The result stays where the call wrote it (its return slot): kept alive by
            // reference, not copied, as a caller that uses it in place does.
            let r = f(black_box(s));
            black_box(&r);
        }
        let t1 = SYST::get_current();
        Self::counts(t0, t1) * INSTRUCTIONS_PER_COUNT
    }

    /// Instructions of one call of `f`: `K` calls on `K` copies, loop subtracted, ÷ `K`
    /// (rounded to nearest; resolution 40/`K` instructions).
    pub fn per_call<S, R>(&self, states: &mut [S; K], f: impl FnMut(&mut S) -> R) -> u32 {
        let total = self
            .raw(states, f)
            .saturating_sub(self.overhead_instructions);
        (total + K as u32 / 2) / K as u32
    }

    /// Instructions of one call of a pure function of `x`, timed on `K` copies of it.
    pub fn pure<X: Copy, R>(&self, x: X, mut f: impl FnMut(&X) -> R) -> u32 {
        let mut xs = [x; K];
        self.per_call(&mut xs, |x| f(x))
    }

    /// Instructions measured around `asm::delay(n)`, which runs a two-instruction loop
    /// (`subs`, `bne`) n + 1 times (cortex-m 0.7.10): 2n + 2 instructions, plus the reads.
    pub fn instructions_of_delay(&self, n: u32) -> u32 {
        let t0 = SYST::get_current();
        cortex_m::asm::delay(n);
        let t1 = SYST::get_current();
        Self::counts(t0, t1) * INSTRUCTIONS_PER_COUNT
    }
}

/// Distribution of per-step instruction counts: exact up to `BINS - 1`, then lumped.
pub struct Stats<const BINS: usize> {
    hist: [u32; BINS],
    /// Steps counted.
    pub n: u32,
    sum: u64,
    /// The largest count and the tick it was seen at.
    pub max: (u32, u32),
}

impl<const BINS: usize> Stats<BINS> {
    /// No steps yet.
    pub const fn new() -> Self {
        Self {
            hist: [0; BINS],
            n: 0,
            sum: 0,
            max: (0, 0),
        }
    }

    /// Counts one step of `v` instructions at `tick`.
    pub fn add(&mut self, v: u32, tick: u32) {
        self.hist[(v as usize).min(BINS - 1)] += 1;
        self.n += 1;
        self.sum += u64::from(v);
        if v > self.max.0 || self.n == 1 {
            self.max = (v, tick);
        }
    }

    /// The smallest value with at least `per_mille`‰ of the counts at or below it.
    pub fn quantile(&self, per_mille: u32) -> u32 {
        let need = (u64::from(self.n) * u64::from(per_mille))
            .div_ceil(1000)
            .max(1);
        let mut acc = 0_u64;
        for (v, &c) in self.hist.iter().enumerate() {
            acc += u64::from(c);
            if acc >= need {
                return v as u32;
            }
        }
        BINS as u32 - 1
    }

    /// The median.
    pub fn median(&self) -> u32 {
        self.quantile(500)
    }

    /// The sum of all counts.
    pub fn sum(&self) -> u64 {
        self.sum
    }

    /// The mean (0 before the first step).
    pub fn mean(&self) -> u32 {
        if self.n == 0 {
            0
        } else {
            (self.sum / u64::from(self.n)) as u32
        }
    }
}

impl<const BINS: usize> Default for Stats<BINS> {
    fn default() -> Self {
        Self::new()
    }
}

/// Takes the core peripherals, starts the [`Meter`] and checks the clock: a delay loop of
/// 400 000 instructions must read 400 000 (± 400), else QEMU is not counting one instruction
/// per ns (`-icount shift=0`, as `scripts/bench-target` runs it) and the run ends with a
/// failing exit. Logs the clock line every benchmark starts with.
pub fn start_checked() -> Meter {
    let Some(core) = cortex_m::Peripherals::take() else {
        defmt::error!("core peripherals already taken");
        super::exit::failure();
    };
    let meter = Meter::start(core.SYST);
    let delay = meter.instructions_of_delay(200_000);
    defmt::info!(
        "clock: {=u32} instructions per SysTick count (checked: a 400000-instruction delay loop reads {=u32}), K = {=usize} copies per measurement, loop overhead {=u32} instructions per {=usize} calls",
        INSTRUCTIONS_PER_COUNT,
        delay,
        K,
        meter.overhead(),
        K
    );
    if delay.abs_diff(400_000) > 400 {
        defmt::error!(
            "the clock is not 1 instruction per ns: run QEMU with -icount shift=0 (scripts/bench-target)"
        );
        super::exit::failure();
    }
    meter
}
