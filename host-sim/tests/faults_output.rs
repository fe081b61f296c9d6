//! `tss-sim run` prints the fault summary after its report and writes it to `DIR/faults.txt`.

use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_tss-sim");

#[test]
fn run_prints_and_writes_the_fault_summary() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("faults");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml");
    let output = Command::new(BIN)
        .arg("run")
        .arg(&scenario)
        .arg("--out")
        .arg(&out)
        .args(["--set", "simulation.duration_s=900"])
        .args(["--set", "faults.dropout=[{ from_s = 100, until_s = 150 }]"])
        .args([
            "--set",
            "faults.length_glitch=[{ at_s = 600, size_m = 100 }]",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success() || stdout.contains("Faults, health and envelope"),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = std::fs::read_to_string(out.join("faults.txt")).unwrap();
    for needle in [
        "Faults, health and envelope of scenario `paper`",
        "dropout (no sample) 100–150 s",
        "length glitch 100 m at 600 s",
        "sensor Missing                   100 s       149 s      50",
        "sensor LengthJump",
        "degraded → safe hold (sensor Missing)",
        "outside [0.5, 40000] m for 0 s",
    ] {
        assert!(
            text.contains(needle),
            "{needle:?} not in faults.txt:\n{text}"
        );
    }
    assert!(stdout.contains(&text), "the summary is printed too");
}
