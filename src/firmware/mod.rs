//! The reel-MCU firmware for QEMU's `mps2-an386` (Cortex-M4F), feature `firmware`, bare metal
//! only: the hardware side (clock, exits and faults, UART, semihosting command line, stack
//! figure) and the per-tick mission bodies (the built-in replay; processor-in-the-loop over the
//! UART). The `tss-reel` bin (`src/main.rs`) is the thin `#[entry]` over it; the on-target tests
//! and the examples link the same runtime, so a panic or fault ends each of them the same way.
//!
//! - [`clock`]: SysTick set-up, the tick counter, the WFI wait, the defmt timestamp;
//! - [`exit`]: how a run ends (semihosting exit, HardFault and default handlers);
//! - [`mission`]: what is done on each tick with the built-in replay
//!   ([`crate::recordings::replay`]): **the part to replace** with the real sensors and drive;
//!   the main loop does not change when it is;
//! - [`reel`](mod@reel): the inner loop, the speed loop driving a simulated reel at 1 kHz under
//!   the mission's law periods;
//! - [`pil`]: the processor-in-the-loop mission over UART0 ([`uart`]), selected by `pil` on the
//!   semihosting command line ([`cmdline`]; QEMU `-append pil`);
//! - [`stack`]: the stack high-water mark (the stack is painted by cortex-m-rt at reset);
//! - [`bench`](mod@bench): instruction counting for the on-target benchmarks (`scripts/bench-target`).
//!
//! This module also links the two runtime crates that have no API to call:
//! - `defmt-semihosting` is the global defmt logger (frames go out through semihosting stdout);
//! - `panic-probe` (feature `print-defmt`) is the panic handler: it logs the panic with defmt,
//!   then executes `udf`, which escalates to HardFault, whose handler ([`exit`]) ends the run with
//!   a failing exit code. A panic therefore fails fast; it never hangs.

use defmt_semihosting as _;
use panic_probe as _;

pub mod bench;
pub mod clock;
pub mod cmdline;
pub mod exit;
pub mod mission;
pub mod pil;
pub mod reel;
pub mod stack;
pub mod uart;
