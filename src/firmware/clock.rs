//! The control clock: SysTick fires once per control period, the main loop sleeps (WFI) between
//! ticks, and defmt log lines are stamped with mission time.
//!
//! One SysTick interrupt is one control period of mission time. On the flight MCU that is real
//! time; in QEMU the idle time between ticks is skipped (see `scripts/qemu-run`), so a mission
//! of hours replays in seconds, and its log is the same from run to run.

use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::exception;

/// Frequency of the clock SysTick counts, Hz: the board's 1 MHz reference clock (SysTick
/// CLKSOURCE = external; QEMU's mps2 machines feed SysTick a fixed 1 MHz REFCLK). With a 24-bit
/// counter that allows control periods of 1 ms to 16.7 s; the 25 MHz processor clock would stop
/// at 671 ms, short of the paper's 1 s period.
pub const SYSTICK_CLOCK_HZ: u32 = 1_000_000;

/// Largest SysTick reload value (the counter is 24 bits wide; Armv7-M ARM, B3.3).
const SYST_RELOAD_MAX: u32 = 0x00FF_FFFF;

/// SysTick reload value for a period of `period_ms` milliseconds, or `None` if the period is
/// zero or too long for the 24-bit counter.
pub const fn reload_for(period_ms: u32) -> Option<u32> {
    let counts_per_ms = SYSTICK_CLOCK_HZ / 1_000;
    match period_ms.checked_mul(counts_per_ms) {
        Some(counts) if counts >= 2 && counts - 1 <= SYST_RELOAD_MAX => Some(counts - 1),
        _ => None,
    }
}

/// Ticks since [`ControlClock::start`], incremented by the SysTick handler. It wraps after 2³²
/// ticks (136 years at 1 Hz).
static TICKS: AtomicU32 = AtomicU32::new(0);

/// The control period in ms, kept for the log timestamp.
static PERIOD_MS: AtomicU32 = AtomicU32::new(0);

/// SysTick: one control period has elapsed.
#[exception]
fn SysTick() {
    TICKS.fetch_add(1, Ordering::Release);
}

/// Ticks since the clock was started.
pub fn ticks() -> u32 {
    TICKS.load(Ordering::Acquire)
}

/// Mission time since the clock was started, ms (ticks × control period).
pub fn mission_time_ms() -> u64 {
    u64::from(ticks()) * u64::from(PERIOD_MS.load(Ordering::Relaxed))
}

// Every defmt log line carries the mission time, shown as hh:mm:ss.mmm.
defmt::timestamp!("{=u64:tms}", mission_time_ms());

/// The running SysTick timer and the main loop's view of it.
pub struct ControlClock {
    /// Owned so that nothing else reprograms the timer.
    _syst: SYST,
    /// The tick count at the previous return of [`ControlClock::wait_for_tick`].
    seen: u32,
    /// Control periods that went by without a step (a step took longer than a period).
    overruns: u32,
}

impl ControlClock {
    /// Starts SysTick on the reference clock with one interrupt every `period_ms`.
    ///
    /// A period that SysTick cannot produce (see [`reload_for`]) is a configuration error: it is
    /// logged and the run ends with a failure.
    pub fn start(mut syst: SYST, period_ms: u32) -> Self {
        let Some(reload) = reload_for(period_ms) else {
            defmt::error!("control period {=u32} ms does not fit SysTick", period_ms);
            super::exit::failure();
        };
        PERIOD_MS.store(period_ms, Ordering::Relaxed);
        syst.set_clock_source(SystClkSource::External);
        syst.set_reload(reload);
        syst.clear_current();
        syst.enable_interrupt();
        syst.enable_counter();
        Self {
            _syst: syst,
            seen: ticks(),
            overruns: 0,
        }
    }

    /// Sleeps (WFI) until the next tick, and returns the tick count.
    ///
    /// The check and the sleep run with interrupts masked, so a tick that lands between them
    /// still wakes the core (a pending interrupt ends WFI even when masked) and is handled as
    /// soon as the mask is lifted: no tick is slept through. If more than one tick went by since
    /// the previous call, the missed periods are counted as overruns (see [`Self::overruns`]).
    pub fn wait_for_tick(&mut self) -> u32 {
        loop {
            cortex_m::interrupt::free(|_| {
                if ticks() == self.seen {
                    cortex_m::asm::wfi();
                }
            });
            let now = ticks();
            if now != self.seen {
                let elapsed = now.wrapping_sub(self.seen);
                self.overruns = self.overruns.saturating_add(elapsed - 1);
                self.seen = now;
                return now;
            }
        }
    }

    /// Control periods skipped so far because a step overran its period.
    pub fn overruns(&self) -> u32 {
        self.overruns
    }
}
