//! On-target tests (placeholder until the platform lands).
fn main() {}
