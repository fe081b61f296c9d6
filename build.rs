//! Build script of the `tss-reel` package: makes the board's memory map visible to the linker.
//!
//! cortex-m-rt's `link.x` does `INCLUDE memory.x`, and the package root's `memory.x` does
//! `INCLUDE board-memory.x`: for a bare-metal firmware build we copy the board's map
//! (`memory-<board>.x`) to `OUT_DIR` as `board-memory.x` and add that directory to the linker's
//! search path. (The linker runs in the package root and looks in its working directory first,
//! which is why the boards' maps have names of their own.) Host builds (the library's tests, the
//! simulator) and builds of the library alone link nothing with it and skip this.

use std::env;
use std::fs;
use std::path::PathBuf;

/// The memory map of each board, by the package feature that builds its firmware (cargo sets
/// `CARGO_FEATURE_<NAME>` for each enabled feature): QEMU's `mps2-an386` with the flight part's
/// budget, and the NUCLEO-G474RE board (STM32G474RE). Another board adds its feature and its map
/// here (docs/porting.md).
const BOARDS: &[(&str, &str)] = &[
    ("CARGO_FEATURE_FIRMWARE", "memory-mps2-an386.x"),
    ("CARGO_FEATURE_NUCLEO_G474RE", "memory-nucleo-g474re.x"),
];

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");
    for (_, map) in BOARDS {
        println!("cargo:rerun-if-changed={map}");
    }

    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    let mut enabled = BOARDS
        .iter()
        .filter(|(feature, _)| env::var_os(feature).is_some());
    let Some((feature, map)) = enabled.next() else {
        return;
    };
    // One firmware per build: two boards would link two memory maps, runtimes and loggers.
    if let Some((other, _)) = enabled.next() {
        panic!(
            "two board features enabled ({} and {}): build one board at a time",
            feature_name(feature),
            feature_name(other)
        );
    }

    let out_dir = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest_dir =
        PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let memory_x = manifest_dir.join(map);
    fs::copy(&memory_x, out_dir.join("board-memory.x"))
        .unwrap_or_else(|e| panic!("cannot copy {} to OUT_DIR: {e}", memory_x.display()));
    println!("cargo:rustc-link-search={}", out_dir.display());
}

/// The package feature behind a `CARGO_FEATURE_*` variable, as written in Cargo.toml.
fn feature_name(var: &str) -> String {
    var.trim_start_matches("CARGO_FEATURE_")
        .to_ascii_lowercase()
        .replace('_', "-")
}
