//! # tss-reel firmware: the reel-MCU program (Cortex-M4F, `thumbv7em-none-eabihf`)
//!
//! A thin `#[entry]` around the library's firmware module ([`tss_reel::firmware`], feature
//! `firmware`). Two rates on one clock (SysTick, one interrupt per inner tick, 1 kHz):
//!
//! - every [`reel::OUTER_PERIOD_TICKS`] ticks (1 s, the law's period), first the outer step:
//!   one [`mission::Mission::step`] of the flight controller on the replayed sensors, whose
//!   rate command goes to the speed loop;
//! - every tick, the inner step: [`reel::Reel::tick`], the speed loop driving the simulated
//!   reel through the drive's hardware traits.
//!
//! Why this scheduler, not RTIC 2 or embassy: docs/porting.md. The run ends when the mission
//! reports that it has finished. All logging is defmt over ARM semihosting, decoded on the host
//! by `defmt-print` (see `scripts/qemu-run`). Build and run it with `cargo fw`; the modules are
//! documented in `tss_reel::firmware` (`cargo doc --target thumbv7em-none-eabihf --features
//! firmware`).
//!
//! In QEMU one SysTick interrupt is one inner period of mission time, and the idle time between
//! ticks is skipped (`-icount …,sleep=off` in `scripts/qemu-run`): mission time is accelerated and
//! deterministic, so logs are reproducible.
#![cfg_attr(target_os = "none", no_std, no_main)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

// Cargo builds this file only with the `firmware` feature (`required-features`); that feature
// is inert on the host, so a host build of it is a mistake worth a clear message.
#[cfg(not(target_os = "none"))]
compile_error!(
    "the tss-reel firmware runs on the reel MCU: build it for thumbv7em-none-eabihf \
     (`cargo fw` runs it in QEMU, `cargo fw-build` builds it)"
);

#[cfg(target_os = "none")]
use tss_reel::firmware::{self, clock::ControlClock, exit, mission, reel};
#[cfg(target_os = "none")]
use tss_reel::reel_drive::DriveFaults;

/// Reset entry: start the clock, run the two rates until the mission ends, exit.
///
/// The stack was painted by cortex-m-rt's reset handler (feature `paint-stack`) before this
/// runs, so the high-water mark logged at the end counts every frame since reset.
///
/// The loop is bounded by [`mission::MAX_TICKS`] law periods: a mission that does not finish
/// in time is a failure, never a hang.
#[cfg(target_os = "none")]
#[cortex_m_rt::entry]
fn main() -> ! {
    defmt::info!(
        "tss-reel firmware {=str}: law period {=u32} ms, inner loop {=u32} Hz",
        env!("CARGO_PKG_VERSION"),
        mission::CONTROL_PERIOD_MS,
        reel::INNER_RATE_HZ
    );

    let Some(core) = cortex_m::Peripherals::take() else {
        defmt::error!("core peripherals already taken");
        exit::failure();
    };
    // `-append pil`: processor-in-the-loop over UART0 (one tick per law period) instead of the
    // built-in replay.
    if firmware::cmdline::mode() == firmware::cmdline::Mode::Pil {
        firmware::pil::run(ControlClock::start(core.SYST, mission::CONTROL_PERIOD_MS));
    }
    replay(core.SYST)
}

/// The built-in replay: the flight controller on the replayed sensors at the law's rate, the
/// speed loop driving the simulated reel every inner tick, until the mission ends.
///
/// Not inlined into [`main`]: its state (the mission and the reel, about 4 KB of frame) would
/// otherwise be reserved on the stack under the processor-in-the-loop mission as well
/// (`scripts/size-check` measures both modes).
#[cfg(target_os = "none")]
#[inline(never)]
fn replay(syst: cortex_m::peripheral::SYST) -> ! {
    let mut clock = ControlClock::start(syst, reel::INNER_PERIOD_MS);
    let drum = core::cell::RefCell::new(reel::sim_drum());
    let mut reel = reel::Reel::new(&drum);
    let mut mission = mission::Mission::new();

    let max_ticks = mission::MAX_TICKS.saturating_mul(reel::OUTER_PERIOD_TICKS);
    for tick in 0..max_ticks {
        clock.wait_for_tick();
        if tick.is_multiple_of(reel::OUTER_PERIOD_TICKS) {
            let period = tick / reel::OUTER_PERIOD_TICKS;
            // The drive's faults over the period that ended reach the law's health.
            let drive_faults = if period > 0 {
                reel.log_period(period - 1, mission.output())
            } else {
                DriveFaults::NONE
            };
            match mission.step(period, drive_faults) {
                mission::Flow::Continue => reel.command(mission.output(), tick),
                mission::Flow::Finished => {
                    defmt::info!(
                        "mission finished after {=u32} law periods ({=u32} inner ticks); overruns: {=u32}",
                        period + 1,
                        tick,
                        clock.overruns()
                    );
                    firmware::stack::log_high_water();
                    exit::success();
                }
                mission::Flow::Failed => {
                    defmt::error!("mission failed at law period {=u32}", period);
                    exit::failure();
                }
            }
        }
        reel.tick(tick);
    }
    defmt::error!(
        "mission did not finish within {=u32} law periods",
        mission::MAX_TICKS
    );
    exit::failure()
}
