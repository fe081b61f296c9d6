//! # tss-reel firmware: the reel-MCU program (Cortex-M4F, `thumbv7em-none-eabihf`)
//!
//! A thin `#[entry]` around the library's firmware module ([`tss_reel::firmware`], feature
//! `firmware`): it starts the control clock (SysTick, one interrupt per control period), then
//! runs one [`mission::Mission::step`] per tick until the mission reports that it has finished,
//! and exits. All logging is defmt over ARM semihosting, decoded on the host by `defmt-print`
//! (see `scripts/qemu-run`). Build and run it with `cargo fw`; the modules are documented in
//! `tss_reel::firmware` (`cargo doc --target thumbv7em-none-eabihf --features firmware`).
//!
//! In QEMU one SysTick interrupt is one control period of mission time, and the idle time between
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
use tss_reel::firmware::{self, clock::ControlClock, exit, mission};

/// Reset entry: start the clock, run the mission one step per control tick, exit.
///
/// The stack was painted by cortex-m-rt's reset handler (feature `paint-stack`) before this
/// runs, so the high-water mark logged at the end counts every frame since reset.
///
/// The loop is bounded by [`mission::MAX_TICKS`]: a mission that does not finish in time is a
/// failure, never a hang.
#[cfg(target_os = "none")]
#[cortex_m_rt::entry]
fn main() -> ! {
    defmt::info!(
        "tss-reel firmware {=str}: control period {=u32} ms",
        env!("CARGO_PKG_VERSION"),
        mission::CONTROL_PERIOD_MS
    );

    let Some(core) = cortex_m::Peripherals::take() else {
        defmt::error!("core peripherals already taken");
        exit::failure();
    };
    let mut clock = ControlClock::start(core.SYST, mission::CONTROL_PERIOD_MS);
    // `-append pil`: processor-in-the-loop over UART0 instead of the built-in replay.
    if firmware::cmdline::mode() == firmware::cmdline::Mode::Pil {
        firmware::pil::run(clock);
    }
    let mut mission = mission::Mission::new();

    for tick in 0..mission::MAX_TICKS {
        clock.wait_for_tick();
        match mission.step(tick) {
            mission::Flow::Continue => {}
            mission::Flow::Finished => {
                defmt::info!(
                    "mission finished after {=u32} ticks; overruns: {=u32}",
                    tick + 1,
                    clock.overruns()
                );
                firmware::stack::log_high_water();
                exit::success();
            }
            mission::Flow::Failed => {
                defmt::error!("mission failed at tick {=u32}", tick);
                exit::failure();
            }
        }
    }
    defmt::error!(
        "mission did not finish within {=u32} ticks",
        mission::MAX_TICKS
    );
    exit::failure()
}
