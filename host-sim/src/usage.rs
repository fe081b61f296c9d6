//! Command-line mistakes (exit code 2) and the `--quiet` switch, shared by every command.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::scenario::ScenarioError;
use crate::sim::SimError;

/// A command-line mistake found before any work (exit code 2): a bad argument, scenario file,
/// `--set` override or output path.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// Is `err` (or its cause) the user's mistake — a bad scenario, override or output path, or
/// scenario values the simulation refuses before its first step (a controller configuration
/// the core rejects, a time that is not a whole number of periods) — so that the process should
/// exit with code 2 rather than 1?
pub fn is_usage_error(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.is::<ScenarioError>()
            || e.is::<UsageError>()
            || e.downcast_ref::<SimError>()
                .is_some_and(|s| matches!(s, SimError::Config(_) | SimError::Timing { .. }))
    })
}

static QUIET: AtomicBool = AtomicBool::new(false);

/// `--quiet`: the commands print nothing on stdout and draw no progress bar (errors still go to
/// stderr, and the files are written as usual).
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// Is `--quiet` in force?
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}
