//! Stack high-water mark: the unused stack is painted with a pattern at boot, and at the end of
//! a run the deepest word that no longer holds the pattern says how much stack the firmware used.
//!
//! With flip-link the stack sits at the bottom of RAM: it grows down from `_stack_start` (just
//! below `.data`/`.bss`) toward `_stack_end` (the start of RAM); both symbols come from
//! cortex-m-rt's `link.x`. [`paint`] fills `_stack_end` up to a little below the current stack
//! pointer with [`PAINT`]; [`high_water_bytes`] scans up from `_stack_end` for the first word that
//! was overwritten. The guard left unpainted just below `main`'s frame ([`GUARD_BYTES`]) only
//! makes the figure an over-estimate when the stack never grows past it.
//!
//! `scripts/size-check` reads the line [`log_high_water`] prints and holds static RAM plus this
//! figure to the budget in `expected/size-budget.toml`.
//!
//! Wiring (three lines): `pub mod stack;` in `firmware/mod.rs`; `firmware::stack::paint();` first
//! thing in `main`, before the clock starts; `firmware::stack::log_high_water();` when the mission
//! has finished, before the exit.
#![deny(unsafe_code)]

use core::ptr::addr_of;

/// The fill pattern (the one cortex-m-rt's `paint-stack` feature uses).
pub const PAINT: u32 = 0xCCCC_CCCC;

/// Bytes right below the stack pointer of [`paint`] that are left unpainted, so that nothing
/// [`paint`] itself pushes (in any build profile) can be overwritten while in use.
pub const GUARD_BYTES: usize = 256;

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

/// Paints the stack below the caller with [`PAINT`]: every word from `_stack_end` up to
/// [`GUARD_BYTES`] below this function's stack pointer. Call it once, first thing in `main`,
/// before any interrupt is enabled.
#[inline(never)]
pub fn paint() {
    let (bottom, top) = region();
    let sp = cortex_m::register::msp::read() as usize;
    let end = sp.saturating_sub(GUARD_BYTES).min(top) & !3;
    let mut addr = bottom;
    while addr < end {
        #[allow(unsafe_code)]
        // SAFETY: `addr` is word-aligned (`_stack_end` is 4-aligned, link.x asserts it) and lies
        // in `[_stack_end, sp − GUARD_BYTES)`: RAM reserved for the stack that is below the
        // stack pointer, so no live frame, static or other Rust object is there (Arm has no red
        // zone, and the loop calls nothing that could push a frame that deep). Writing it cannot
        // change any value the program uses.
        unsafe {
            core::ptr::write_volatile(addr as *mut u32, PAINT)
        };
        addr += 4;
    }
}

/// Bytes of stack used so far: from `_stack_start` down to the deepest word that no longer
/// holds [`PAINT`] (the whole stack if even the lowest word was overwritten).
pub fn high_water_bytes() -> u32 {
    let (bottom, top) = region();
    let mut addr = bottom;
    while addr < top {
        #[allow(unsafe_code)]
        // SAFETY: `addr` is word-aligned and inside the stack region `[_stack_end, _stack_start)`,
        // which is RAM; a volatile read of it has no side effect. Words above the stack pointer
        // may belong to live frames: they are only read, never formed into references.
        let word = unsafe { core::ptr::read_volatile(addr as *const u32) };
        if word != PAINT {
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
