//! How a run ends: a semihosting exit with success or failure, and the fault handlers that turn
//! every fault (and so every panic, through panic-probe's `udf`) into a failing exit.
//!
//! In QEMU (`-semihosting-config enable=on,target=native`) the exit ends the emulator with code 0
//! for [`success`] and 1 for [`failure`], which `scripts/qemu-run` passes on to cargo. On the
//! flight MCU, with no debugger attached, these are where a reset into safe mode would go.
//!
//! The handlers are linked into every program built with the `firmware` feature: the firmware,
//! the on-target test suite and the examples end on a fault the same way.

use cortex_m_rt::{exception, ExceptionFrame};
use cortex_m_semihosting::debug::{self, EXIT_FAILURE, EXIT_SUCCESS};

/// Ends the run successfully (QEMU exits with 0).
pub fn success() -> ! {
    debug::exit(EXIT_SUCCESS);
    park()
}

/// Ends the run with a failure (QEMU exits with 1).
pub fn failure() -> ! {
    debug::exit(EXIT_FAILURE);
    park()
}

/// Where execution stops if no debugger or emulator acts on the semihosting exit.
fn park() -> ! {
    loop {
        cortex_m::asm::wfi();
    }
}

/// HardFault: log where it happened and end the run with a failure.
///
/// Panics arrive here too: panic-probe logs the message, then executes `udf`.
#[allow(unsafe_code)] // cortex-m-rt requires `unsafe fn` for the HardFault handler.
#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    defmt::error!(
        "HardFault: pc = {=u32:#010x}, lr = {=u32:#010x}, xpsr = {=u32:#010x}",
        frame.pc(),
        frame.lr(),
        frame.xpsr()
    );
    failure()
}

/// Any exception or interrupt that has no handler of its own: log it and fail.
///
/// cortex-m-rt's default would loop forever, which in QEMU is a hang.
#[allow(unsafe_code)] // cortex-m-rt requires `unsafe fn` for the default handler.
#[exception]
unsafe fn DefaultHandler(irqn: i16) -> ! {
    defmt::error!("unhandled exception or interrupt: IRQn = {=i16}", irqn);
    failure()
}
