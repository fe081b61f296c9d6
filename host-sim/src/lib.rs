//! tss-sim: the desktop simulator of the tss-reel controller.
#![warn(missing_docs)]

pub mod analysis;
pub mod compare;
pub mod eccentric;
pub mod elastic;
pub mod faults;
pub mod history;
pub mod laws;
pub mod montecarlo;
pub mod obc;
pub mod output;
pub mod pil;
pub mod plant;
pub mod plots;
pub mod random;
pub mod reel;
pub mod report;
pub mod run_cmd;
pub mod scenario;
pub mod sensors;
pub mod sim;
pub mod stepper;
pub mod table1;
pub mod usage;
pub mod verdict;
