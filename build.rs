//! Build script of the `tss-reel` package: makes `memory.x` visible to the linker.
//!
//! cortex-m-rt's `link.x` does `INCLUDE memory.x`; the linker looks for it on its search path,
//! so for bare-metal targets we copy it to `OUT_DIR` and add that directory to the path. Host
//! builds (the library's tests, the simulator) have no linker script and skip this.

use std::env;
use std::fs;
use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");

    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }

    let out_dir = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest_dir =
        PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let memory_x = manifest_dir.join("memory.x");
    fs::copy(&memory_x, out_dir.join("memory.x"))
        .unwrap_or_else(|e| panic!("cannot copy {} to OUT_DIR: {e}", memory_x.display()));
    println!("cargo:rustc-link-search={}", out_dir.display());
}
