//! Processor-in-the-loop tests: the flight firmware ELF in QEMU flies the `tss-sim` plant over
//! the emulated UART (`tss_sim::pil`).
//!
//! - `pil_flies_the_flight_configuration_as_the_host_linked_core`: the first 30 simulated
//!   minutes of `scenarios/paper.toml` with the sensors that fly (α, the encoder, the load cell;
//!   no α̇), so the configuration loaded into the firmware is `Config::flight()` (the law on the
//!   onboard estimator), every tick compared with the host-linked run: commands, lengths and
//!   every other output bit for bit (the same f32 code on both sides).
//! - `pil_flies_the_flight_configuration_on_the_elastic_plant`: the same on the elastic truth
//!   model (`scenarios/paper-elastic.toml`: a tether of 0.19 g/m, whose density the loaded
//!   configuration carries), over its first 20 minutes.
//! - `a_refused_parameter_table_names_its_parameter_and_changes_nothing`: tables the core
//!   refuses (a negative gain) or that are not the shape of a configuration are refused on the
//!   MCU with the parameter named; the firmware then flies the good table it is sent next, as
//!   the host-linked core does.
//! - `link_faults_are_dropouts_counted_on_both_sides`: the same stretch with every kind of link
//!   fault injected; both ends count the same faults, the tether stays inside its envelope, and
//!   a host-linked run with sensor dropouts at exactly the ticks the firmware had no sample
//!   computes the same commands bit for bit.
//! - `a_lost_first_frame_does_not_stop_the_link` and
//!   `heavy_link_faults_at_the_start_and_the_end_are_counted_exactly`: short runs
//!   with every sample frame faulted (all four kinds, several seeds), the first and the last
//!   frames among them: the link starts, every period flies, and both ends agree exactly.
//! - `commanded_missions_fly_in_pil_as_on_the_host`: the commanded missions of `scenarios/`
//!   with the flight configuration, shortened, their telecommands moved early: the telecommands
//!   travel to the firmware as PUS packets and its PUS services answer over the link; history
//!   and telemetry equal the host-linked run's, and so do the packet counts.
//!
//! They need the firmware ELF (`cargo fw-build`, or `TSS_FIRMWARE_ELF`) and `qemu-system-arm`
//! and `defmt-print` on PATH. Without them each test prints why and passes, unless
//! `TSS_PIL_REQUIRED=1` (set by `scripts/test` and `scripts/pil-test`), which makes a missing
//! prerequisite a failure. The ELF is not rebuilt here: `scripts/pil-test` builds it first.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use tss_reel::config::RateSource;
use tss_reel::controller::{Config, Controller, Input, Output};
use tss_reel::link::{self, ParamTable, PARAMS};
use tss_reel::pus::{read_telemetry, Stage, Telemetry};
use tss_sim::history::History;
use tss_sim::pil::{self, Injected, PilError, PilLink, PilReport};
use tss_sim::scenario::Scenario;
use tss_sim::sim::{self, SimError, Stepper};

/// One QEMU at a time: two cores, and a stalled host would make the firmware time out.
static QEMU: Mutex<()> = Mutex::new(());

/// Link seeds of the heavy-fault runs: between them they lose a first and a last frame.
const SEEDS: [u64; 4] = [1, 2, 3, 4];

/// The simulated stretch: the first 30 minutes of the paper's mission (deployment).
const DURATION_S: &str = "simulation.duration_s=1800";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The firmware ELF, or `None` (with the reason printed) if PIL cannot run here.
fn firmware() -> Option<PathBuf> {
    let elf = std::env::var_os("TSS_FIRMWARE_ELF")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join(pil::DEFAULT_FIRMWARE));
    let mut missing = Vec::new();
    if !elf.is_file() {
        missing.push(format!(
            "the firmware ELF {} (build it with `cargo fw-build`)",
            elf.display()
        ));
    }
    for tool in ["qemu-system-arm", "defmt-print"] {
        let found = std::process::Command::new(tool)
            .arg("--version")
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .status()
            .is_ok();
        if !found {
            missing.push(format!("`{tool}` (scripts/setup installs it)"));
        }
    }
    if missing.is_empty() {
        return Some(elf);
    }
    let why = format!("PIL test skipped: missing {}", missing.join(" and "));
    if std::env::var("TSS_PIL_REQUIRED").is_ok_and(|v| v == "1") {
        panic!("{why}; TSS_PIL_REQUIRED=1 makes that a failure");
    }
    eprintln!("{why}");
    None
}

fn scenario(overrides: &[&str]) -> Scenario {
    scenario_from("paper.toml", overrides)
}

/// `scenarios/FILE` over the first [`DURATION_S`], a history sample every period, then the
/// overrides.
fn scenario_from(file: &str, overrides: &[&str]) -> Scenario {
    let mut sets = vec![
        DURATION_S.to_string(),
        "simulation.output_interval_s=1".to_string(),
    ];
    sets.extend(overrides.iter().map(|s| s.to_string()));
    Scenario::load(root().join("scenarios").join(file), &sets).unwrap()
}

/// The sensors that fly: no α̇ sensor (the law flies the onboard estimator on α), a swing
/// sensor of σ_α = 1e-4 rad (what `Config::flight()`'s estimator is tuned for), the encoder and
/// the load cell (on by default).
const FLIGHT_SENSORS: [&str; 2] = [
    "sensors.alpha_rate.enabled=false",
    "sensors.alpha.noise_std=1e-4",
];

/// The firmware's log file for the test `name`.
fn log_path(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tss-pil-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join("firmware.log")
}

fn run_pil(sc: &Scenario, elf: &Path, name: &str) -> (History, PilReport) {
    let log = log_path(name);
    match pil::run(sc, elf, &log, &[], &mut |_| {}) {
        Ok(r) => r,
        Err(e) => {
            let log_text = std::fs::read_to_string(&log).unwrap_or_default();
            panic!("PIL run failed: {e:#?}\nfirmware log:\n{log_text}");
        }
    }
}

/// Largest |a − b| of one field over two histories of the same ticks.
fn max_diff(a: &History, b: &History, f: impl Fn(&tss_sim::history::Sample) -> f64) -> f64 {
    a.samples
        .iter()
        .zip(&b.samples)
        .map(|(x, y)| (f(x) - f(y)).abs())
        .fold(0.0, f64::max)
}

/// Every sample equal bit for bit (`{:?}` of f64 is exact and tells NaNs apart from numbers).
fn assert_identical(a: &History, b: &History) {
    assert_eq!(a.samples.len(), b.samples.len());
    for (x, y) in a.samples.iter().zip(&b.samples) {
        assert_eq!(
            format!("{x:?}"),
            format!("{y:?}"),
            "first difference at t = {} s",
            x.t_s
        );
    }
    assert_eq!(a.faults, b.faults, "fault summaries differ");
}

/// Flies `sc` on the host and in PIL; the link's report printed and consistent, with no
/// spurious timeout. Returns the host run, the PIL run and its report.
fn fly_host_and_pil(sc: &Scenario, elf: &Path, name: &str) -> (History, History, PilReport) {
    let host = sim::run(sc, &[], &mut |_| {}).unwrap();
    let (pil, report) = run_pil(sc, elf, name);
    eprint!("{}", report.render());
    assert_eq!(
        report.spurious_timeouts, 0,
        "the host stalled past the firmware's timeout"
    );
    assert!(report.consistent());
    (host, pil, report)
}

/// Flies `sc` on the host and in PIL and checks both bit for bit; returns the PIL report.
fn assert_pil_is_the_host(sc: &Scenario, elf: &Path, name: &str) -> PilReport {
    let (host, pil, report) = fly_host_and_pil(sc, elf, name);
    assert_eq!(report.ticks, pil.faults.ticks);
    assert_eq!(report.status.fresh, report.ticks);
    let d_cmd = max_diff(&host, &pil, |s| s.length_rate_mps);
    let d_len = max_diff(&host, &pil, |s| s.length_m);
    eprintln!(
        "PIL vs host-linked over {} ticks: max |Δ command| = {d_cmd:e} m/s, max |Δ length| = {d_len:e} m",
        pil.samples.len()
    );
    assert_identical(&host, &pil);
    report
}

#[test]
fn pil_flies_the_flight_configuration_as_the_host_linked_core() {
    let Some(elf) = firmware() else { return };
    let _one = QEMU.lock().unwrap_or_else(|e| e.into_inner());
    let sc = scenario(&FLIGHT_SENSORS);
    let report = assert_pil_is_the_host(&sc, &elf, "agreement");
    assert_eq!(report.ticks, 1801);
    // What was loaded and flown is the flight configuration (the firmware's built-in one) less
    // its tension loop, which a rigid rod cannot fly (docs/equations.md §17.3).
    let rigid_flight = Config {
        tension_loop: None,
        ..Config::flight()
    };
    assert_eq!(sim::controller_config::<f32>(&sc).unwrap(), rigid_flight);
    assert_eq!(report.config_digest, link::config_digest(&rigid_flight));
    assert_eq!(
        report.builtin_digest,
        link::config_digest(&Config::flight())
    );
}

#[test]
fn pil_flies_the_flight_configuration_on_the_elastic_plant() {
    let Some(elf) = firmware() else { return };
    let _one = QEMU.lock().unwrap_or_else(|e| e.into_inner());
    let sc = scenario_from(
        "paper-elastic.toml",
        &[&FLIGHT_SENSORS[..], &["simulation.duration_s=1200"]].concat(),
    );
    let cfg = sim::controller_config::<f32>(&sc).unwrap();
    assert!(matches!(cfg.rate_source, RateSource::Estimator(_)));
    assert!(cfg.masses.tether_density_kg_per_m > 0.0);
    assert!(
        cfg.tension_loop.is_some(),
        "the elastic mission flies the tension loop"
    );
    let report = assert_pil_is_the_host(&sc, &elf, "elastic");
    assert_eq!(report.config_digest, link::config_digest(&cfg));
    assert_ne!(report.config_digest, report.builtin_digest);
}

#[test]
fn a_refused_parameter_table_names_its_parameter_and_changes_nothing() {
    let Some(elf) = firmware() else { return };
    let _one = QEMU.lock().unwrap_or_else(|e| e.into_inner());
    let sc = scenario(&[&FLIGHT_SENSORS[..], &["simulation.duration_s=20"]].concat());
    let cfg = sim::controller_config::<f32>(&sc).unwrap();
    let log = log_path("refused");
    let mut link = PilLink::boot(&sc, &elf, &log).unwrap();

    let mut bad = cfg;
    bad.gains.k1_per_s = -1.0;
    match link.load_table(&ParamTable::from_config(&bad)) {
        Err(PilError::Refused(m)) => {
            eprintln!("{m}");
            assert!(
                m.contains("gains.k1_per_s") && m.contains("NotPositive"),
                "{m}"
            );
        }
        other => panic!("a negative gain was not refused: {other:?}"),
    }
    let tag = PARAMS
        .iter()
        .position(|(n, _)| *n == "protection?")
        .unwrap();
    let mut shapeless = ParamTable::from_config(&cfg);
    shapeless.words[tag] = 7;
    match link.load_table(&shapeless) {
        Err(PilError::Refused(m)) => {
            eprintln!("{m}");
            assert!(m.contains("protection?"), "{m}");
        }
        other => panic!("a tag of 7 was not refused: {other:?}"),
    }

    // Nothing of the refused tables remains: the good one flies as on the host.
    link.load(&cfg).unwrap();
    let pil = sim::run_stepper::<f32, _>(&sc, &mut link, &[], &mut |_| {}).unwrap();
    let report = link.finish(pil.faults.ticks).unwrap();
    assert!(report.consistent());
    let host = sim::run(&sc, &[], &mut |_| {}).unwrap();
    assert_identical(&host, &pil);
    let text = std::fs::read_to_string(&log).unwrap();
    assert_eq!(text.matches("parameter table refused").count(), 2, "{text}");
}

/// The host-linked core, with a dropout forced at the given ticks (those the firmware had no
/// sample for).
struct DropoutsAt<'a> {
    core: Controller<f32>,
    ticks: &'a [u32],
}

impl Stepper<f32> for DropoutsAt<'_> {
    fn step(&mut self, tick: u32, input: Option<&Input<f32>>) -> Result<Output<f32>, SimError> {
        let input = input.filter(|_| self.ticks.binary_search(&tick).is_err());
        Stepper::step(&mut self.core, tick, input)
    }
}

#[test]
fn link_faults_are_dropouts_counted_on_both_sides() {
    let Some(elf) = firmware() else { return };
    let _one = QEMU.lock().unwrap_or_else(|e| e.into_inner());
    // Cheap faults (corrupted, duplicated) often; those that cost the firmware a timeout
    // (dropped, reordered: about 1.6 s of wall time each) rarely.
    let sc = scenario(&[
        "link.seed=2011",
        "link.corrupt_prob=0.03",
        "link.duplicate_prob=0.03",
        "link.drop_prob=0.005",
        "link.reorder_prob=0.005",
    ]);
    let (pil, report) = run_pil(&sc, &elf, "faults");
    eprint!("{}", report.render());
    let i = report.injected;
    assert!(
        i.dropped > 0 && i.corrupted > 0 && i.duplicated > 0 && i.reordered > 0,
        "every kind of fault injected: {i:?}"
    );
    assert_eq!(
        report.spurious_timeouts, 0,
        "the host stalled past the firmware's timeout"
    );
    assert_eq!(
        report.firmware_counts(),
        report.expected_firmware_counts(),
        "the firmware counted what the plant injected"
    );
    assert!(report.consistent());
    assert_eq!(
        report.missing_ticks.len() as u32,
        i.dropped + i.corrupted + i.reordered
    );
    assert_eq!(report.status.timeout, i.dropped + i.reordered);
    assert_eq!(report.status.corrupted, i.corrupted);

    let f = &pil.faults;
    assert_eq!(f.outside_envelope_s, 0.0, "the tether left its envelope");
    assert_eq!(f.rate_exceeded_ticks, 0);
    assert_eq!(f.accel_exceeded_ticks, 0);

    // A link fault is exactly a sensor dropout: the core, with dropouts at the same ticks,
    // computes the same mission bit for bit.
    let core = Controller::new(sim::controller_config::<f32>(&sc).unwrap()).unwrap();
    let mut replay = DropoutsAt {
        core,
        ticks: &report.missing_ticks,
    };
    let host = sim::run_stepper(&sc, &mut replay, &[], &mut |_| {}).unwrap();
    let d_cmd = max_diff(&host, &pil, |s| s.length_rate_mps);
    eprintln!("PIL with link faults vs host-linked with the same dropouts: max |Δ command| = {d_cmd:e} m/s");
    let mut pil_faults = pil.faults.clone();
    // The host-linked run counts its dropouts as missing ticks; the PIL plant sent samples.
    pil_faults.missing_ticks = host.faults.missing_ticks;
    assert_eq!(pil.samples.len(), host.samples.len());
    for (x, y) in host.samples.iter().zip(&pil.samples) {
        assert_eq!(
            format!("{x:?}"),
            format!("{y:?}"),
            "first difference at t = {} s",
            x.t_s
        );
    }
    assert_eq!(host.faults, pil_faults);
}

/// Runs `sc` in PIL and checks that every period flew and both ends agree on every count.
fn assert_exact_accounting(sc: &Scenario, elf: &Path, name: &str) -> PilReport {
    let (pil, report) = run_pil(sc, elf, name);
    eprint!("{}", report.render());
    let ticks = pil.faults.ticks;
    assert_eq!(report.ticks, ticks, "every period flew");
    assert_eq!(
        report.firmware_counts(),
        report.expected_firmware_counts(),
        "the firmware counted what the plant injected"
    );
    assert!(report.consistent());
    report
}

/// With the first sample frame corrupted (seed 3, half the frames corrupted) the
/// firmware used to wait for a first good frame while the plant waited for the command of tick
/// 0: a 60 s deadlock, then "no command for tick 0".
#[test]
fn a_lost_first_frame_does_not_stop_the_link() {
    let Some(elf) = firmware() else { return };
    let _one = QEMU.lock().unwrap_or_else(|e| e.into_inner());
    let sc = scenario(&[
        "simulation.duration_s=5",
        "link.seed=3",
        "link.corrupt_prob=0.5",
    ]);
    let report = assert_exact_accounting(&sc, &elf, "start");
    assert_eq!(
        report.missing_ticks.first(),
        Some(&0),
        "the first frame was lost"
    );
    assert_eq!(report.ticks, 6);
}

/// Every sample frame meets a fault (a quarter each of dropped, corrupted,
/// duplicated, reordered), over several seeds; among them runs whose first and whose last
/// frames are lost. Every period flies and the end-of-run counts agree exactly (on main the
/// gaps of frames lost after the last one that arrived were not counted).
#[test]
fn heavy_link_faults_at_the_start_and_the_end_are_counted_exactly() {
    let Some(elf) = firmware() else { return };
    let _one = QEMU.lock().unwrap_or_else(|e| e.into_inner());
    let (mut start_lost, mut end_lost) = (false, false);
    let mut total = Injected::default();
    for seed in SEEDS {
        let seed = format!("link.seed={seed}");
        let sc = scenario(&[
            "simulation.duration_s=8",
            &seed,
            "link.drop_prob=0.25",
            "link.corrupt_prob=0.25",
            "link.duplicate_prob=0.25",
            "link.reorder_prob=0.25",
        ]);
        let report = assert_exact_accounting(&sc, &elf, &format!("heavy-{seed}"));
        let last = report.ticks - 1;
        start_lost |= report.missing_ticks.first() == Some(&0);
        end_lost |= report.missing_ticks.last() == Some(&last);
        let i = report.injected;
        total.dropped += i.dropped;
        total.corrupted += i.corrupted;
        total.duplicated += i.duplicated;
        total.reordered += i.reordered;
    }
    assert!(
        start_lost && end_lost,
        "the seeds lose a first and a last frame"
    );
    assert!(
        total.dropped > 0 && total.corrupted > 0 && total.duplicated > 0 && total.reordered > 0,
        "every kind of fault injected: {total:?}"
    );
}

/// The telemetry packets of a run by PUS service and subtype, in order of first appearance.
fn packet_counts(h: &History) -> Vec<((u8, u8), u32)> {
    let mut counts: Vec<((u8, u8), u32)> = Vec::new();
    for raw in &h.telemetry {
        let kind = match read_telemetry(raw)
            .expect("the unit's packets decode")
            .telemetry
        {
            Telemetry::Verification { stage, failure, .. } => {
                let base = match stage {
                    Stage::Acceptance => 1,
                    Stage::Start => 3,
                    Stage::Completion => 7,
                };
                (1, base + u8::from(failure.is_some()))
            }
            Telemetry::Housekeeping(_) => (3, 25),
            Telemetry::Event { severity, .. } => (5, severity as u8),
        };
        match counts.iter_mut().find(|(k, _)| *k == kind) {
            Some((_, n)) => *n += 1,
            None => counts.push((kind, 1)),
        }
    }
    counts
}

/// Flies the commanded `sc` on the host and in PIL: the histories bit for bit, and the
/// telemetry packet for packet, byte for byte (the firmware's PUS services are the host
/// unit's). Returns the PIL run.
fn assert_commanded_pil_is_the_host(sc: &Scenario, elf: &Path, name: &str) -> History {
    let (host, pil, report) = fly_host_and_pil(sc, elf, name);
    assert_identical(&host, &pil);
    let counts = packet_counts(&pil);
    eprintln!(
        "{name}: {} telecommands, {} telemetry packets by (service, subtype): {counts:?}",
        report.telecommands, report.telemetry_packets
    );
    assert_eq!(report.telecommands as usize, sc.telecommand.len());
    assert_eq!(report.telemetry_packets as usize, pil.telemetry.len());
    assert_eq!(counts, packet_counts(&host));
    assert_eq!(pil.telemetry.len(), host.telemetry.len());
    for (i, (p, h)) in pil.telemetry.iter().zip(&host.telemetry).enumerate() {
        assert_eq!(
            p,
            h,
            "telemetry packet {i} differs: {:?}",
            read_telemetry(p)
        );
    }
    // A housekeeping packet for every recorded period, as history.csv has a row.
    let hk = counts.iter().find(|(k, _)| *k == (3, 25)).map(|(_, n)| *n);
    assert_eq!(hk, Some(pil.samples.len() as u32));
    pil
}

/// The verification reports of a run: (request sequence count, subtype).
fn verification(h: &History) -> Vec<(u16, u8)> {
    h.telemetry
        .iter()
        .filter_map(|raw| match read_telemetry(raw)?.telemetry {
            Telemetry::Verification {
                request,
                stage,
                failure,
            } => {
                let base = match stage {
                    Stage::Acceptance => 1,
                    Stage::Start => 3,
                    Stage::Completion => 7,
                };
                Some((
                    request.sequence & 0x3fff,
                    base + u8::from(failure.is_some()),
                ))
            }
            _ => None,
        })
        .collect()
}

/// The commanded missions of `scenarios/` with the flight configuration, their commands moved
/// early: `paper-commanded.toml` (hold, resume, a refused resume) and `faults-commanded.toml`
/// (a hold and its resume, a sensor dropout, the orbit-rate fault and an abort after it) on
/// the rigid plant, `paper-elastic-commanded.toml` (hold, resume, abort) on the elastic one.
/// The telecommands travel to the firmware as PUS packets over the link and its PUS services
/// answer: history and telemetry as the host-linked unit's, bit for bit.
#[test]
fn commanded_missions_fly_in_pil_as_on_the_host() {
    let Some(elf) = firmware() else { return };
    let _one = QEMU.lock().unwrap_or_else(|e| e.into_inner());
    const HOLD_RESUME: &str =
        r#"telecommand=[{ at_s = 60.0, command = "hold" }, { at_s = 150.0, command = "resume" }"#;

    let refused = format!(r#"{HOLD_RESUME}, {{ at_s = 200.0, command = "resume" }}]"#);
    let sc = scenario_from(
        "paper-commanded.toml",
        &[
            &FLIGHT_SENSORS[..],
            &["simulation.duration_s=300", &refused],
        ]
        .concat(),
    );
    let pil = assert_commanded_pil_is_the_host(&sc, &elf, "paper-commanded");
    let held = pil.samples.iter().filter(|s| s.t_s > 70.0 && s.t_s < 150.0);
    assert!(
        held.clone().all(|s| s.length_rate_mps == 0.0),
        "held at rest"
    );
    assert_eq!(
        verification(&pil),
        [
            (0, 1),
            (0, 3),
            (0, 7),
            (1, 1),
            (1, 3),
            (1, 7),
            (2, 1),
            (2, 4)
        ],
        "hold and resume completed, the second resume refused (not held)"
    );

    let aborted = format!(r#"{HOLD_RESUME}, {{ at_s = 210.0, command = "abort" }}]"#);
    let sc = scenario_from(
        "faults-commanded.toml",
        &[
            &FLIGHT_SENSORS[..],
            &[
                "simulation.duration_s=300",
                "faults.dropout=[{ from_s = 100.0, until_s = 110.0 }]",
                r#"faults.corrupt=[{ sensor = "orbit_rate", from_s = 200.0, until_s = 202.0, value = inf }]"#,
                &aborted,
            ],
        ]
        .concat(),
    );
    let pil = assert_commanded_pil_is_the_host(&sc, &elf, "faults-commanded");
    assert_eq!(pil.faults.missing_ticks, 10, "the dropout flew");
    assert_eq!(verification(&pil).iter().filter(|v| v.1 == 7).count(), 3);
    let end = pil.samples.last().unwrap();
    assert_eq!(end.length_rate_mps, 0.0, "aborted to rest: {end:?}");

    let sc = scenario_from(
        "paper-elastic-commanded.toml",
        &[
            &FLIGHT_SENSORS[..],
            &["simulation.duration_s=240", &aborted],
        ]
        .concat(),
    );
    assert!(sim::controller_config::<f32>(&sc)
        .unwrap()
        .tension_loop
        .is_some());
    let pil = assert_commanded_pil_is_the_host(&sc, &elf, "paper-elastic-commanded");
    assert_eq!(verification(&pil).iter().filter(|v| v.1 == 7).count(), 3);
}
