//! Stack high-water mark: cortex-m-rt's reset handler paints the whole stack with
//! [`cortex_m_rt::STACK_PAINT_VALUE`] before `main` (its `paint-stack` feature, enabled in
//! Cargo.toml), and at the end of a run the deepest word that no longer holds the paint says how
//! much stack the firmware used since reset.
//!
//! With flip-link the stack sits at the bottom of RAM: it grows down from `_stack_start` (just
//! below `.data`/`.bss`) toward `_stack_end` (the start of RAM); both symbols come from
//! cortex-m-rt's `link.x`, which paints exactly `[_stack_end, _stack_start)`.
//! [`high_water_bytes`] scans up from `_stack_end` for the first word that was overwritten.
//!
//! `scripts/size-check` reads the line [`log_high_water`] prints and holds static RAM plus this
//! figure to the budget in `expected/size-budget.toml`.
#![deny(unsafe_code)]

use core::ptr::addr_of;
use cortex_m_rt::STACK_PAINT_VALUE;

extern "C" {
    /// The initial stack pointer: the top of the stack (cortex-m-rt `link.x`, moved by flip-link).
    static _stack_start: u32;
    /// The lowest address the stack may use (cortex-m-rt `link.x`).
    static _stack_end: u32;
}

/// The stack region `[bottom, top)` as addresses.
fn region() -> (usize, usize) {
    (
        addr_of!(_stack_end) as usize,
        addr_of!(_stack_start) as usize,
    )
}

/// The stack's size, bytes (`_stack_start − _stack_end`).
pub fn size_bytes() -> u32 {
    let (bottom, top) = region();
    (top - bottom) as u32
}

/// Bytes of stack used so far: from `_stack_start` down to the deepest word that no longer
/// holds [`STACK_PAINT_VALUE`] (the whole stack if even the lowest word was overwritten).
pub fn high_water_bytes() -> u32 {
    let (bottom, top) = region();
    let mut addr = bottom;
    while addr < top {
        #[allow(unsafe_code)]
        // SAFETY: `addr` is word-aligned (`_stack_end` is 4-aligned, link.x asserts it) and
        // inside the stack region `[_stack_end, _stack_start)`, which is RAM; a volatile read of
        // it has no side effect. Words above the stack pointer may belong to live frames: they
        // are only read, never formed into references.
        let word = unsafe { core::ptr::read_volatile(addr as *const u32) };
        if word != STACK_PAINT_VALUE {
            break;
        }
        addr += 4;
    }
    (top - addr) as u32
}

/// Logs the high-water mark (the line `scripts/size-check` parses):
/// `stack high-water mark: N bytes of M`.
pub fn log_high_water() {
    defmt::info!(
        "stack high-water mark: {=u32} bytes of {=u32}",
        high_water_bytes(),
        size_bytes()
    );
}
