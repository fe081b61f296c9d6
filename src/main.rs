//! # tss-reel firmware: the reel-MCU program (Cortex-M4F, `thumbv7em-none-eabihf`)
//!
//! A thin `#[entry]` around the `no_std` library: it starts the control clock (SysTick, one
//! interrupt per control period), then runs one [`firmware::mission::Mission::step`] per tick
//! until the mission reports that it has finished, and exits. All logging is defmt over ARM
//! semihosting, decoded on the host by `defmt-print` (see `scripts/qemu-run`).
//!
//! Where things live (`src/firmware/`):
//! - [`firmware::clock`]: SysTick set-up, the tick counter, the WFI wait, the defmt timestamp;
//! - [`firmware::exit`]: how a run ends (semihosting exit, HardFault and default handlers);
//! - [`firmware::mission`]: what is done on each tick: **the part to replace** with the real
//!   controller; this loop does not change when it is.
//! - [`firmware::pil`]: the processor-in-the-loop mission over UART0 ([`firmware::uart`]),
//!   selected by `pil` on the semihosting command line ([`firmware::cmdline`]; QEMU `-append pil`).
//!
//! In QEMU one SysTick interrupt is one control period of mission time, and the idle time between
//! ticks is skipped (`-icount …,sleep=off` in `scripts/qemu-run`): mission time is accelerated and
//! deterministic, so logs are reproducible.
//!
//! On the host (`cargo build`, `cargo test --workspace`) this file compiles to an empty `main`:
//! the firmware only exists for the bare-metal target, and the host must still build the
//! workspace's `[[bin]]` entries.
#![cfg_attr(target_os = "none", no_std, no_main)]
// `unsafe` is allowed only where cortex-m-rt demands it: the `unsafe fn` signatures of the
// HardFault and default handlers (src/firmware/exit.rs), each with an `#[allow]` that says so;
// and where hardware demands it: the UART's volatile register access (src/firmware/uart.rs) and
// the semihosting command-line call (src/firmware/cmdline.rs), each with a SAFETY comment.
#![deny(unsafe_code)]
#![warn(missing_docs)]

#[cfg(target_os = "none")]
mod firmware;

/// Host stub: the firmware exists only for the bare-metal target (see the crate docs).
#[cfg(not(target_os = "none"))]
fn main() {}

/// Reset entry: start the clock, run the mission one step per control tick, exit.
///
/// The loop is bounded by [`firmware::mission::MAX_TICKS`]: a mission that does not finish in
/// time is a failure, never a hang.
#[cfg(target_os = "none")]
#[cortex_m_rt::entry]
fn main() -> ! {
    use firmware::{clock::ControlClock, exit, mission};
    // Fill the unused stack with a pattern, so the high-water mark can be read at the end.
    firmware::stack::paint();

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
