//! # tss-reel: the reel controller of a tethered satellite system
//!
//! A `no_std`, allocation-free, panic-free implementation of the range-rate control system of
//! He, Liang & Xu, "Study on the stability of Tethered Satellite System", *Acta Astronautica* 68
//! (2011) 1964–1972, with the corrections of this project's SPEC. Equation numbers in the docs
//! are the paper's.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod config;
pub mod controller;
pub mod envelope;
pub mod equilibrium;
pub mod fastmath;
pub mod hal;
pub mod law;
pub mod link;
pub mod mass;
pub mod monitor;
pub mod orbit;
pub mod real;
pub mod reel_drive;
pub mod schedule;
pub mod stability;

pub use real::Real;
