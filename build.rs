//! Build script of the `tss-reel` package: makes the board's memory map visible to the linker.
//!
//! cortex-m-rt's `link.x` does `INCLUDE memory.x`; the linker looks for it on its search path,
//! so for a bare-metal firmware build we copy the board's map to `OUT_DIR` as `memory.x` and add
//! that directory to the path. Host builds (the library's tests, the simulator) and builds of
//! the library alone link nothing with it and skip this.

use std::env;
use std::fs;
use std::path::PathBuf;

/// The memory map of each board, by the package feature that builds its firmware. One board
/// today: QEMU's `mps2-an386` with the flight part's budget. A second board adds its feature
/// and its map here (cargo sets `CARGO_FEATURE_<NAME>` for each enabled feature).
const BOARDS: &[(&str, &str)] = &[("CARGO_FEATURE_FIRMWARE", "memory.x")];

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    for (_, map) in BOARDS {
        println!("cargo:rerun-if-changed={map}");
    }

    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    let Some((_, map)) = BOARDS
        .iter()
        .find(|(feature, _)| env::var_os(feature).is_some())
    else {
        return;
    };

    let out_dir = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest_dir =
        PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let memory_x = manifest_dir.join(map);
    fs::copy(&memory_x, out_dir.join("memory.x"))
        .unwrap_or_else(|e| panic!("cannot copy {} to OUT_DIR: {e}", memory_x.display()));
    println!("cargo:rustc-link-search={}", out_dir.display());
}
