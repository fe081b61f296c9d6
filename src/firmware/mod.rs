//! Firmware-only modules: the hardware side of the reel MCU (clock, exits, faults, UART) and the
//! per-tick mission bodies (the built-in replay; processor-in-the-loop over the UART). Declared
//! from `main.rs` for the bare-metal target only.
//!
//! This module also links the two runtime crates that have no API to call:
//! - `defmt-semihosting` is the global defmt logger (frames go out through semihosting stdout);
//! - `panic-probe` (feature `print-defmt`) is the panic handler: it logs the panic with defmt,
//!   then executes `udf`, which escalates to HardFault, whose handler ([`exit`]) ends the run with
//!   a failing exit code. A panic therefore fails fast; it never hangs.

use defmt_semihosting as _;
use panic_probe as _;

pub mod clock;
pub mod cmdline;
pub mod exit;
pub mod mission;
pub mod pil;
pub mod replay_data;
pub mod stack;
pub mod uart;
