//! Firmware placeholder until the platform lands.
fn main() {}
