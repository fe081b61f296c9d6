//! # tss-reel: the reel controller of a tethered satellite system
//!
//! A `no_std`, allocation-free, panic-free implementation of the range-rate control system of
//! He, Liang & Xu, "Study on the stability of Tethered Satellite System", *Acta Astronautica* 68
//! (2011) 1964–1972, with the corrections of this project's SPEC. Equation numbers in the docs
//! are the paper's.
#![no_std]
// The core never uses `unsafe`: forbidden in every build without the firmware. The firmware
// module (`firmware` feature, bare metal only) needs it for registers, semihosting and the
// cortex-m-rt handlers, each under a local `#[allow]` with a SAFETY comment; there the crate is
// `deny`, so an `unsafe` anywhere else still fails, and the host build (forbid) rejects any
// `#[allow(unsafe_code)]` outside the firmware.
#![cfg_attr(
    not(all(feature = "firmware", target_os = "none")),
    forbid(unsafe_code)
)]
#![cfg_attr(all(feature = "firmware", target_os = "none"), deny(unsafe_code))]
#![warn(missing_docs)]
//!
//! ## Cargo features
//!
//! - `recordings` (default): [`recordings`], the paper mission recorded from the simulator as the
//!   reel MCU senses it: the firmware's built-in replay and the benchmarks' 20-hour mission. Data
//!   only; the linker keeps none of it unless it is used.
//! - `defmt`: `defmt::Format` on the types a firmware logs (as `heapless` and `embedded-hal` do).
//! - `firmware`: the reel-MCU firmware for QEMU's `mps2-an386` (Cortex-M4F,
//!   `thumbv7em-none-eabihf` only): runtime, logger, panic and fault handling, the control clock
//!   and the per-tick missions. It brings the firmware's dependencies (cortex-m with its
//!   single-core critical section, cortex-m-rt, panic-probe, defmt over semihosting); without it
//!   the library depends on none of them. `cargo fw`, `cargo tt` and the examples enable it.

// The firmware's modules name the library as `tss_reel::…`, as a downstream firmware would.
#[cfg(all(feature = "firmware", target_os = "none"))]
extern crate self as tss_reel;

pub mod config;
pub mod controller;
pub mod envelope;
pub mod equilibrium;
pub mod fastmath;
#[cfg(all(feature = "firmware", target_os = "none"))]
pub mod firmware;
pub mod hal;
pub mod law;
pub mod link;
pub mod mass;
pub mod monitor;
pub mod orbit;
pub mod real;
#[cfg(feature = "recordings")]
pub mod recordings;
pub mod schedule;
pub mod stability;

pub use real::Real;
