//! # tss-reel: the reel controller of a tethered satellite system
//!
//! Flight software for the reel that pays out and hauls in the tether between a main satellite
//! and a sub-satellite on a circular orbit: the range-rate control system of He, Liang & Xu,
//! "Study on the stability of Tethered Satellite System", *Acta Astronautica* 68 (2011)
//! 1964–1972, which deploys the sub-satellite, keeps it on station and retrieves it while keeping
//! the tether's in-plane swing α stable around a reference angle α_r.
//!
//! The crate is `no_std`, allocation-free, panic-free and `#![forbid(unsafe_code)]`. It runs in
//! f32 on the reel MCU (a Cortex-M4F) and every formula also evaluates in f64 through the [`Real`]
//! trait. One [`controller::Controller::step`] per control period turns a sensed sample (tick,
//! tether length l, swing angle α and rate α̇, orbit rate n) into a reel-rate command inside the
//! reel's envelope, with everything it was made of (phase, health, δ, the law's value, the blend
//! weight, the Eq. 13 margin, flags, the fault behind a safe action). Bad input never becomes a
//! bad command: every sample is checked before use and every parameter when the controller is
//! built.
//!
//! ```
//! use tss_reel::controller::{Config, ConfigError, Controller, EventKind, Health, Input, Phase};
//!
//! fn main() -> Result<(), ConfigError> {
//!     // The paper's mission (Section 6): every parameter is validated here, once.
//!     let mut ctl = Controller::new(Config::<f32>::paper())?;
//!
//!     // One call per control period (1 s), with the sensed sample of this tick. The step
//!     // returns its output by reference (the one kept in the controller); copy it out to keep it
//!     // while the controller is used again.
//!     let out = *ctl.step(&Input {
//!         tick: 0,                          // whole control periods since the start
//!         length_m: 1.0,                    // l, m
//!         reel_rate_mps: None,              // l̇ from the reel's encoder, m/s (not used here)
//!         tension_n: None,                  // tension from the load cell, N (not used here)
//!         alpha_rad: Some(-35f32.to_radians()), // α, rad (deploying: behind the main satellite)
//!         alpha_rate_radps: Some(0.0),      // α̇, rad/s (the paper's measured α̇)
//!         orbit_rate_radps: 1.0602e-3,      // n, rad/s (circular orbit, R = 7078 km)
//!         true_anomaly_rad: 0.0,            // θ, rad (used on an eccentric orbit only)
//!     });
//!     // Phase and health changes, faults and blend restarts, each queued once: read them every
//!     // period (here: stage 1's blend starts).
//!     while let Some(event) = ctl.pop_event() {
//!         if let EventKind::Phase(phase) = event.kind {
//!             let _ = (event.tick, phase); // e.g. tell the ground
//!         }
//!     }
//!     // `out` is the step's output: send it to the reel.
//!     assert_eq!(out.phase, Phase::Deploy);
//!     assert!((out.rate_cmd_mps - 0.1).abs() < 1e-6); // the Eq. 29 blend starts from l̇0 = 0.1 m/s
//!     assert!(out.fault.is_none());
//!     // Also: out.accel_cmd_mps2 (Eq. 30), out.law_rate_mps (Eq. 27), out.blend_weight (Eq. 29),
//!     // out.alpha_ref_rad, out.delta_rad, out.delta_rate_radps, out.equilibrium_margin (Eq. 13),
//!     // out.health, out.flags.
//!
//!     // A period without a sample (a dropout): the reel coasts on its last command.
//!     let out = ctl.step_missing(1);
//!     assert_eq!(out.health, Health::Degraded);
//!     assert!(out.fault.is_some());
//!     assert!((out.rate_cmd_mps - 0.1).abs() < 1e-6);
//!     Ok(())
//! }
//! ```
//!
//! Time is an integer tick count (one tick = one control period); nothing accumulates time in
//! floating point.
//!
//! # The modules and the paper's equations
//!
//! Equation numbers (Eq. n) in these docs are the paper's. The equations themselves, rebuilt
//! from the paper's Lagrangian with its errata corrected, the choices the paper leaves open, the
//! implicit solve of Eqs. 27–29 and the derivation of the Eq. 30 acceleration, are in
//! `docs/equations.md` in the repository (its §n are cited in the code).
//!
//! | Module | Paper | What | equations.md |
//! | --- | --- | --- | --- |
//! | [`orbit`] | §2 | R(θ), θ̇, θ̈, mean motion ω | §0 |
//! | [`mass`] | Eq. 2, Eq. 5 | M*, m_r, μ1, μ2, μ3, μ̇3 with m1 = m01 − ρl | §1 |
//! | [`equilibrium`] | Eqs. 6–15 | existence of the swing equilibria, the whole-orbit extent (Fig. 3) | §3, §11 |
//! | [`stability`] | Eqs. 16–19, 28 | characteristic roots and verdicts, the 4×4 Jacobian, the closed loop | §4 |
//! | [`law`] | Eqs. 26–30 | the range-rate law solved implicitly with the Eq. 29 blend; the Eq. 30 acceleration | §5 |
//! | [`schedule`] | Eqs. 34, 35 | α_r(l) with quintic Hermite transitions; the stage-2 slew | §6 |
//! | [`config`] | §6 | the parameters, the paper's scenario, validation | §7 |
//! | [`tension`] | — | the tension loop: admittance gain, washout, tension window | §17 |
//! | [`controller`] | — | the step: sequencer, health, safe actions, events, output | §12 |
//! | [`monitor`] | — | sensor checks (range, jumps, stuck) | §12 |
//! | [`envelope`] | — | rate, acceleration and length limits (a discrete braking staircase) | §10 |
//! | [`fastmath`], [`real`] | — | f32 sin/cos, 2^x, sqrt for the M4F; the [`Real`] trait | §8 |
//! | [`hal`] | — | sensor and reel traits (embedded-hal style), [`hal::control_cycle`] | — |
//! | [`link`] | — | the processor-in-the-loop frames (postcard, CRC-32, COBS) | — |
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
pub mod estimator;
pub mod fastmath;
#[cfg(all(feature = "firmware", target_os = "none"))]
pub mod firmware;
pub mod hal;
pub mod law;
pub mod link;
pub mod mass;
pub mod monitor;
pub mod orbit;
pub mod pus;
pub mod real;
#[cfg(feature = "recordings")]
pub mod recordings;
pub mod reel_drive;
pub mod schedule;
pub mod stability;
pub mod tension;

pub use real::Real;

/// The README's Rust examples, compiled and run as doctests (`cargo test --doc`), so that the
/// README cannot drift from the API.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
