//! tss-sim: the desktop simulator of the tss-reel controller.
#![warn(missing_docs)]
