//! Records the build of tss-sim for its campaign manifests (`TSS_SIM_BUILD`, read by
//! `montecarlo::cmd::BUILD`): the git commit it is built from, with `+dirty.` and an FNV-1a
//! digest of `git diff HEAD` over the sources that go into the binary when they have
//! uncommitted changes, or `unknown` outside a git checkout (or without git). `tss-sim merge`
//! refuses shards of different builds.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The sources whose uncommitted changes make a build dirty, relative to the workspace root:
/// the flight core, its square-root crate, the simulator and the manifests.
const SOURCES: [&str; 6] = [
    "src",
    "fpu",
    "host-sim/src",
    "Cargo.toml",
    "host-sim/Cargo.toml",
    "Cargo.lock",
];

fn git(root: &Path, args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .arg("-C")
        .arg(root)
        .args(args)
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).into_owned())
}

/// FNV-1a, 64 bit.
fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

fn main() {
    let manifest_dir = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default());
    let root = manifest_dir.parent().unwrap_or(&manifest_dir).to_path_buf();
    for source in SOURCES {
        let path = root.join(source);
        if path.exists() {
            println!("cargo:rerun-if-changed={}", path.display());
        }
    }
    let build = match git(&root, &["rev-parse", "HEAD"]) {
        Some(commit) => {
            // A new commit moves HEAD or the branch it points to.
            for name in ["HEAD", "packed-refs"] {
                watch_git_path(&root, name);
            }
            if let Some(branch) = git(&root, &["symbolic-ref", "-q", "HEAD"]) {
                watch_git_path(&root, branch.trim());
            }
            let mut diff_args = vec!["diff", "HEAD", "--"];
            diff_args.extend(SOURCES);
            match git(&root, &diff_args) {
                Some(diff) if !diff.is_empty() => {
                    format!("{}+dirty.{:016x}", commit.trim(), fnv1a64(diff.as_bytes()))
                }
                _ => commit.trim().to_string(),
            }
        }
        None => "unknown".to_string(),
    };
    println!("cargo:rustc-env=TSS_SIM_BUILD={build}");
}

/// Reruns this script when the git file `name` (`HEAD`, `refs/heads/main`, …) changes.
fn watch_git_path(root: &Path, name: &str) {
    if let Some(path) = git(root, &["rev-parse", "--git-path", name]) {
        let path = root.join(path.trim());
        if path.exists() {
            println!("cargo:rerun-if-changed={}", path.display());
        }
    }
}
