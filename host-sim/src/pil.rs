//! Processor-in-the-loop (PIL): the flight firmware, in QEMU's `mps2-an386`, flies the
//! simulator's plant over the emulated UART (`tss-sim run SCENARIO --pil`).
//!
//! [`PilLink`] starts QEMU with the firmware ELF (`-append pil` selects the firmware's PIL
//! mission), serial port 0 connected to a loopback TCP socket that `tss-sim` listens on, and the
//! semihosting output (the defmt log) piped through `defmt-print -e ELF` into `firmware.log`.
//! After the firmware's hello it loads the scenario's controller configuration into the
//! firmware as a parameter table ([`link::ParamTable`]): the firmware builds its controller from
//! it, so the core on the MCU validates it, and answers with the digest of what it flies (the
//! scenario's, or the run stops) or why it refused it. Any configuration the core accepts flies
//! in the loop: the paper's, the flight one on the estimator (`Config::flight`), with a tether
//! of any density, on the rigid or the elastic plant. It implements [`Stepper`]: each control period the plant's sample goes out as one `Sample`
//! frame and the firmware's `Command` frame comes back with the whole controller output, so
//! [`crate::sim::run_stepper`] writes the same history, figures and summaries as a host-linked
//! run. Frames are those of [`tss_reel::link`].
//!
//! **Telecommands and telemetry.** The on-board computer's telecommands (`crate::obc`, the
//! scenario's `[[telecommand]]`) go to the firmware as `Packet` frames before the period's
//! sample; the firmware's PUS services (the unit's code, on the MCU) answer with telemetry
//! packets in `Packet` frames: verification reports, events, and the housekeeping of each
//! period the plant records (asked for with a `Collect` frame). They are kept in the order
//! they arrive, as a host-linked unit's ([`Stepper::take_telemetry`]), so `telemetry.csv` of a
//! PIL run is that of a host-linked one.
//!
//! **Link faults.** The scenario's `[link]` section injects faults into the sample frames, each
//! frame meeting at most one: dropped (not sent; the firmware times out), corrupted (one byte
//! changed, never to the delimiter; the firmware rejects it), duplicated (sent twice; the
//! firmware discards the copy) or reordered (held back and sent late, just before the next
//! period's frame, or before `End`; the firmware times out, then discards it). Both sides
//! count: the injector here ([`Injected`]), the firmware in its `Report` and log.
//! [`PilReport::expected_firmware_counts`] says what the firmware must have seen, exactly,
//! whichever frames are lost: the firmware awaits tick 0 from the start (a lost first frame is
//! a timeout like any other), and the `End` frame's sequence number reveals frames lost at the
//! end. A run has at most [`link::MAX_TICKS`] periods ([`check_duration`]).
//!
//! **Time.** Lock-step: the firmware blocks on each sample, the plant on each command, and the
//! tick number in the frames is the authority. The firmware's sample timeout is counted in its
//! SysTick periods of emulated time, which under instruction counting advance only while it
//! polls; a host stalled for longer than that (about a second of wall time) would make the
//! firmware step without the sample. Such a *spurious* timeout is detected (the firmware reports
//! a timeout for a frame that was sent) and reported in [`PilReport`].

use std::collections::VecDeque;
use std::fmt::Write as _;
use std::fs::File;
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command as Process, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use tss_reel::controller::{Config, Controller, Input, Output};
use tss_reel::link::{
    self, Collect, Command, End, Frame, FrameReader, LinkCounters, LinkError, LoadVerdict, Loaded,
    Message, Packet, ParamTable, Report, Sample, SampleStatus, MAX_WIRE_LEN, NO_PARAM, PARAMS,
    SAMPLE_MISSING, SAMPLE_VALID,
};

use crate::faults::Pcg32;
use crate::history::History;
use crate::scenario::{LinkSection, Scenario};
use crate::sim::{self, SimError, Stepper};

/// Where `cargo fw-build` puts the flight firmware (relative to the repository root).
pub const DEFAULT_FIRMWARE: &str = "target/thumbv7em-none-eabihf/firmware/tss-reel";

/// The file in the output directory that receives the firmware's decoded defmt log.
pub const FIRMWARE_LOG: &str = "firmware.log";

/// How long QEMU may take to boot the firmware and say hello.
const START_TIMEOUT: Duration = Duration::from_secs(30);

/// How long one command (or the final report) may take, wall time. The firmware's own sample
/// timeout costs about a second of wall time; this is only the backstop for a dead firmware.
const REPLY_TIMEOUT: Duration = Duration::from_secs(60);

/// How long QEMU may take to exit after its report.
const EXIT_TIMEOUT: Duration = Duration::from_secs(30);

/// Granularity of the socket reads (the deadlines above are checked between reads).
const POLL: Duration = Duration::from_millis(100);

/// Why a PIL run could not be done.
#[derive(Debug, thiserror::Error)]
pub enum PilError {
    /// The firmware ELF does not exist.
    #[error(
        "firmware ELF {0} not found: build it with `cargo fw-build` (from the repository root), \
         or name another with --firmware ELF"
    )]
    MissingFirmware(PathBuf),
    /// A program PIL needs is not installed.
    #[error("`{0}` not found on PATH: install it with scripts/setup")]
    MissingTool(&'static str),
    /// An operating-system call failed.
    #[error("{context}: {source}")]
    Io {
        /// What was being done.
        context: String,
        /// The failure.
        #[source]
        source: std::io::Error,
    },
    /// The firmware flies another controller configuration than the one loaded into it.
    #[error(
        "the firmware accepted the parameter table but flies controller configuration \
         {firmware:#010x}, the scenario describes {scenario:#010x} (is the ELF stale? rebuild it \
         with `cargo fw-build`)"
    )]
    ConfigMismatch {
        /// Digest the firmware sent.
        firmware: u32,
        /// Digest of the scenario's configuration.
        scenario: u32,
    },
    /// The core refuses the controller configuration (the scenario's, checked here before the
    /// firmware starts, or the table loaded into the firmware, refused there).
    #[error("{0}")]
    Refused(String),
    /// The scenario has more control periods than one PIL run may ([`link::MAX_TICKS`]).
    #[error(
        "simulation.duration_s = {duration_s} s is {ticks} control periods: a PIL run has at \
         most {max} (the firmware's bound, link::MAX_TICKS)"
    )]
    TooLong {
        /// The scenario's duration, s.
        duration_s: f64,
        /// Its control periods (ticks 0 ..= duration / period).
        ticks: f64,
        /// The bound.
        max: u32,
    },
    /// The firmware broke the protocol, stopped answering or failed.
    #[error("{0} (the firmware's log: {1})")]
    Firmware(String, PathBuf),
}

fn io(context: impl Into<String>) -> impl FnOnce(std::io::Error) -> PilError {
    let context = context.into();
    move |source| PilError::Io { context, source }
}

/// Faults the plant side injected into the sample frames.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Injected {
    /// Frames not sent.
    pub dropped: u32,
    /// Frames sent with one byte changed.
    pub corrupted: u32,
    /// Frames sent twice.
    pub duplicated: u32,
    /// Frames held back and sent after the next one.
    pub reordered: u32,
}

/// Per-period sample status as the firmware reported it in its commands.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StatusTally {
    /// A fresh sample.
    pub fresh: u32,
    /// No frame in time.
    pub timeout: u32,
    /// A rejected frame.
    pub corrupted: u32,
    /// The plant had no sample (a scenario dropout).
    pub no_sample: u32,
}

/// What a PIL run measured on both ends of the link.
#[derive(Clone, Debug, Default)]
pub struct PilReport {
    /// The firmware ELF.
    pub firmware: PathBuf,
    /// Control periods exchanged.
    pub ticks: u32,
    /// Sample frames written to the link (duplicates and late frames included).
    pub frames_sent: u32,
    /// Faults injected here.
    pub injected: Injected,
    /// The plant side's receive counters (command frames).
    pub plant_rx: LinkCounters,
    /// Sample status per period, from the commands.
    pub status: StatusTally,
    /// The ticks at which the firmware stepped without a sample (any status but fresh), in
    /// order: a host-linked run with dropouts at exactly these ticks computes the same commands.
    pub missing_ticks: Vec<u32>,
    /// Periods the firmware timed out on although the frame had been sent in time (host too
    /// slow for the firmware's timeout; such a period is not what a host-linked run computes).
    pub spurious_timeouts: u32,
    /// The firmware's `Report` (its receive counters, commands sent and their digest).
    pub firmware_report: Report,
    /// Telecommands sent to the firmware (`Packet` frames).
    pub telecommands: u32,
    /// Telemetry packets the firmware sent (`Packet` frames).
    pub telemetry_packets: u32,
    /// Digest of the firmware's built-in configuration (its hello).
    pub builtin_digest: u32,
    /// Digest of the configuration loaded into it and flown.
    pub config_digest: u32,
    /// FNV-1a over the rate commands received here (equals the firmware's digest).
    pub digest: u32,
    /// Wall time of the exchange (QEMU start to exit).
    pub wall: Duration,
}

impl PilReport {
    /// The firmware counters the injected faults imply: (timeouts, decode errors, duplicates,
    /// late frames, sequence gaps).
    pub fn expected_firmware_counts(&self) -> (u32, u32, u32, u32, u32) {
        let i = &self.injected;
        (
            i.dropped + i.reordered + self.spurious_timeouts,
            i.corrupted,
            i.duplicated,
            i.reordered + self.spurious_timeouts,
            i.dropped + i.corrupted,
        )
    }

    /// The firmware's counters in the order of [`Self::expected_firmware_counts`].
    pub fn firmware_counts(&self) -> (u32, u32, u32, u32, u32) {
        let c = &self.firmware_report.counters;
        (
            c.timeouts,
            c.decode_errors(),
            c.duplicates,
            c.out_of_order,
            c.seq_gaps,
        )
    }

    /// `true` if both sides agree: the firmware saw exactly the injected faults, its digest is
    /// the plant's, and no command frame was damaged.
    pub fn consistent(&self) -> bool {
        self.expected_firmware_counts() == self.firmware_counts()
            && self.firmware_report.digest == self.digest
            && self.firmware_report.commands == self.ticks
            && self.plant_rx.decode_errors() == 0
    }

    /// The report as text (`pil.txt`).
    pub fn render(&self) -> String {
        let mut o = String::new();
        let secs = self.wall.as_secs_f64();
        let _ = writeln!(
            o,
            "Processor-in-the-loop: {} in QEMU mps2-an386, link v{} over UART0",
            self.firmware.display(),
            link::VERSION
        );
        let _ = writeln!(
            o,
            "  controller configuration loaded as a parameter table: digest {:#010x} (built-in {:#010x})",
            self.config_digest, self.builtin_digest
        );
        let _ = writeln!(
            o,
            "  {} control periods in {:.1} s wall time ({:.0} periods/s); {} sample frames sent, {} frames received",
            self.ticks,
            secs,
            f64::from(self.ticks) / secs.max(1e-9),
            self.frames_sent,
            self.plant_rx.frames_ok
        );
        let _ = writeln!(
            o,
            "  PUS: {} telecommands sent, {} telemetry packets received",
            self.telecommands, self.telemetry_packets
        );
        let i = &self.injected;
        let _ = writeln!(
            o,
            "  injected on the sample frames: {} dropped, {} corrupted, {} duplicated, {} reordered",
            i.dropped, i.corrupted, i.duplicated, i.reordered
        );
        let c = &self.firmware_report.counters;
        let _ = writeln!(
            o,
            "  firmware saw: {} timeouts, {} rejected (crc {}, cobs {}, truncated {}, version {}, kind {}, malformed {}, overflow {}), {} duplicates, {} late, {} sequence gaps",
            c.timeouts,
            c.decode_errors(),
            c.crc_errors,
            c.cobs_errors,
            c.truncated,
            c.version_errors,
            c.unknown_kind,
            c.malformed,
            c.overflows,
            c.duplicates,
            c.out_of_order,
            c.seq_gaps
        );
        let s = &self.status;
        let _ = writeln!(
            o,
            "  periods by sample status (from the commands): {} fresh, {} timeout, {} corrupted, {} no sample upstream",
            s.fresh, s.timeout, s.corrupted, s.no_sample
        );
        let _ = writeln!(
            o,
            "  plant side: {} command frames rejected; spurious firmware timeouts: {}",
            self.plant_rx.decode_errors(),
            self.spurious_timeouts
        );
        let _ = writeln!(
            o,
            "  commands: firmware sent {} (digest {:#010x}), plant received digest {:#010x}",
            self.firmware_report.commands, self.firmware_report.digest, self.digest
        );
        let _ = writeln!(
            o,
            "  both sides agree: {}",
            if self.consistent() {
                "yes".to_string()
            } else {
                format!(
                    "NO: expected firmware counts (timeouts, rejected, duplicates, late, gaps) {:?}, got {:?}",
                    self.expected_firmware_counts(),
                    self.firmware_counts()
                )
            }
        );
        o
    }
}

/// The plant's end of the PIL link: QEMU running the firmware, and the socket to its UART.
pub struct PilLink {
    qemu: Child,
    decoder: Child,
    stream: TcpStream,
    reader: FrameReader,
    frames: VecDeque<Result<Frame, LinkError>>,
    log: PathBuf,
    seq: u32,
    faults: LinkSection,
    rng: Pcg32,
    /// A reordered frame, sent after the next one.
    held: Option<Vec<u8>>,
    /// Telemetry packets received and not yet taken ([`Stepper::take_telemetry`]).
    telemetry: Vec<Vec<u8>>,
    /// The last period the firmware answered.
    last_tick: u32,
    /// The tick whose frame went out intact and on time (for spurious-timeout detection).
    on_time: bool,
    started: Instant,
    report: PilReport,
}

impl Drop for PilLink {
    fn drop(&mut self) {
        // Normally both have exited already (see `finish`); on an error, stop QEMU here.
        if matches!(self.qemu.try_wait(), Ok(None)) {
            let _ = self.qemu.kill();
        }
        let _ = self.qemu.wait();
        let _ = self.decoder.wait();
    }
}

fn spawn_error(tool: &'static str) -> impl FnOnce(std::io::Error) -> PilError {
    move |e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            PilError::MissingTool(tool)
        } else {
            PilError::Io {
                context: format!("starting {tool}"),
                source: e,
            }
        }
    }
}

impl PilLink {
    /// Boots `firmware` in QEMU in PIL mode, its log going to `log`, waits for its hello and
    /// loads `sc`'s controller configuration into it ([`Self::load`]). Fails if the core
    /// refuses the configuration, here or on the MCU, or the firmware flies another one.
    pub fn start(sc: &Scenario, firmware: &Path, log: &Path) -> Result<Self, PilError> {
        let cfg = match sim::controller_config::<f32>(sc) {
            Ok(cfg) => cfg,
            Err(e) => {
                return Err(PilError::Firmware(
                    format!("the scenario's controller configuration is invalid: {e}"),
                    log.to_path_buf(),
                ))
            }
        };
        // The same core judges it on the MCU; refusing it here names the parameter at once.
        if let Err(e) = Controller::new(cfg) {
            return Err(PilError::Refused(format!(
                "the core refuses the scenario's controller configuration: {e}"
            )));
        }
        let mut link = Self::boot(sc, firmware, log)?;
        link.load(&cfg)?;
        Ok(link)
    }

    /// Boots `firmware` in QEMU in PIL mode, its log going to `log`, and waits for its hello;
    /// the firmware then waits for its parameter table ([`Self::load`], [`Self::load_table`]).
    /// `sc` gives the link's fault injection.
    pub fn boot(sc: &Scenario, firmware: &Path, log: &Path) -> Result<Self, PilError> {
        if !firmware.is_file() {
            return Err(PilError::MissingFirmware(firmware.to_path_buf()));
        }
        let listener = TcpListener::bind("127.0.0.1:0").map_err(io("binding a loopback port"))?;
        let port = listener
            .local_addr()
            .map_err(io("reading the port"))?
            .port();
        let log_file = File::create(log).map_err(io(format!("creating {}", log.display())))?;

        let started = Instant::now();
        let mut qemu = Process::new("qemu-system-arm")
            .args([
                "-M",
                "mps2-an386",
                "-cpu",
                "cortex-m4",
                "-nodefaults",
                "-display",
                "none",
            ])
            .arg("-chardev")
            .arg(format!(
                "socket,id=link,host=127.0.0.1,port={port},nodelay=on"
            ))
            .args(["-serial", "chardev:link"])
            .args(["-semihosting-config", "enable=on,target=native"])
            .args(["-icount", "shift=5,align=off,sleep=off"])
            .arg("-kernel")
            .arg(firmware)
            .args(["-append", "pil"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(spawn_error("qemu-system-arm"))?;
        if let Some(stderr) = qemu.stderr.take() {
            // QEMU's messages reach the terminal, but for the board's Ethernet controller, which
            // the firmware does not use and which has no network here.
            std::thread::spawn(move || {
                use std::io::BufRead as _;
                for line in std::io::BufReader::new(stderr)
                    .lines()
                    .map_while(Result::ok)
                {
                    if !line.contains("lan9118.0 has no peer") {
                        eprintln!("{line}");
                    }
                }
            });
        }
        let semihosting = qemu.stdout.take();
        let decoder = Process::new("defmt-print")
            .arg("-e")
            .arg(firmware)
            .stdin(semihosting.map_or_else(Stdio::null, Stdio::from))
            .stdout(log_file)
            .spawn();
        let decoder = match decoder {
            Ok(d) => d,
            Err(e) => {
                let _ = qemu.kill();
                let _ = qemu.wait();
                return Err(spawn_error("defmt-print")(e));
            }
        };
        let stream = match accept(&listener, &mut qemu, log) {
            Ok(s) => s,
            Err(e) => {
                let _ = qemu.kill();
                let _ = qemu.wait();
                return Err(e);
            }
        };
        let mut link = Self {
            qemu,
            decoder,
            stream,
            reader: FrameReader::new(),
            frames: VecDeque::new(),
            log: log.to_path_buf(),
            seq: 0,
            faults: sc.link.clone(),
            rng: Pcg32::new(sc.link.seed, 0x6c69_6e6b), // stream "link"
            held: None,
            telemetry: Vec::new(),
            last_tick: 0,
            on_time: false,
            started,
            report: PilReport {
                firmware: firmware.to_path_buf(),
                digest: link::fnv1a_start(),
                ..PilReport::default()
            },
        };
        let hello = link.receive(START_TIMEOUT, "hello frame", |m| match m {
            Message::Hello(h) => Some(*h),
            _ => None,
        })?;
        link.report.builtin_digest = hello.config_digest;
        Ok(link)
    }

    /// Loads `cfg` into the firmware as a parameter table; `Ok` once the firmware flies it
    /// (the digest it answers is `cfg`'s).
    pub fn load(&mut self, cfg: &Config<f32>) -> Result<(), PilError> {
        let loaded = self.load_table(&ParamTable::from_config(cfg))?;
        let expected = link::config_digest(cfg);
        if loaded.config_digest != expected {
            return Err(PilError::ConfigMismatch {
                firmware: loaded.config_digest,
                scenario: expected,
            });
        }
        self.report.config_digest = expected;
        Ok(())
    }

    /// Sends `table` and returns the firmware's `Loaded` answer if it accepted it; a refusal
    /// is [`PilError::Refused`], naming the word at fault and the core's rule (the firmware
    /// then still waits for a table).
    pub fn load_table(&mut self, table: &ParamTable) -> Result<Loaded, PilError> {
        let mut wire = [0u8; MAX_WIRE_LEN];
        let n = link::encode(self.seq, &Message::Params(*table), &mut wire)
            .map_err(|e| self.fail(format!("encoding the parameter table: {e:?}")))?;
        self.seq = self.seq.wrapping_add(1);
        self.stream
            .write_all(&wire[..n])
            .map_err(io("writing to the firmware's UART"))?;
        let loaded = self.receive(REPLY_TIMEOUT, "load verdict", |m| match m {
            Message::Loaded(l) => Some(*l),
            _ => None,
        })?;
        let name = PARAMS
            .get(usize::from(loaded.param))
            .filter(|_| loaded.param != NO_PARAM)
            .map_or("(a group of parameters)", |(name, _)| name);
        match LoadVerdict::from_code(loaded.verdict) {
            Some(LoadVerdict::Accepted) => Ok(loaded),
            Some(LoadVerdict::BadTable) => Err(PilError::Refused(format!(
                "the firmware refused the parameter table: word {} ({name}) is not the shape of \
                 a configuration",
                loaded.param
            ))),
            Some(LoadVerdict::Refused) | None => {
                let rule = link::rule_from_code(loaded.rule).map_or_else(
                    || format!("rule code {}", loaded.rule),
                    |r| format!("{r:?}"),
                );
                Err(PilError::Refused(format!(
                    "the firmware's core refused the parameter table: {name} breaks rule {rule}"
                )))
            }
        }
    }

    fn fail(&self, message: String) -> PilError {
        PilError::Firmware(message, self.log.clone())
    }

    fn write(&mut self, bytes: &[u8]) -> Result<(), PilError> {
        self.report.frames_sent += 1;
        self.stream
            .write_all(bytes)
            .map_err(io("writing to the firmware's UART"))
    }

    /// Sends `message`, a frame of another kind than a sample (a telecommand, a housekeeping
    /// request, the end), in the one sequence of the plant's frames. A reordered sample
    /// frame held back goes first, so the frames stay in sequence on the wire.
    fn send(&mut self, message: &Message, what: &str) -> Result<(), PilError> {
        if let Some(late) = self.held.take() {
            self.write(&late)?;
        }
        let mut wire = [0u8; MAX_WIRE_LEN];
        let n = link::encode(self.seq, message, &mut wire)
            .map_err(|e| self.fail(format!("encoding the {what}: {e:?}")))?;
        self.seq = self.seq.wrapping_add(1);
        self.stream
            .write_all(&wire[..n])
            .map_err(io("writing to the firmware's UART"))
    }

    /// Reads frames until `pick` accepts one, keeping the telemetry packets and counting the
    /// other frames, for at most `timeout`.
    fn receive<T>(
        &mut self,
        timeout: Duration,
        what: &str,
        mut pick: impl FnMut(&Message) -> Option<T>,
    ) -> Result<T, PilError> {
        let deadline = Instant::now() + timeout;
        let mut buf = [0u8; 4 * MAX_WIRE_LEN];
        loop {
            while let Some(f) = self.frames.pop_front() {
                match f {
                    Ok(frame) => {
                        if let Some(x) = pick(&frame.message) {
                            self.report.plant_rx.frames_ok += 1;
                            return Ok(x);
                        }
                        if let Message::Packet(p) = &frame.message {
                            self.report.plant_rx.frames_ok += 1;
                            self.keep(p);
                        } else {
                            self.report.plant_rx.count_error(LinkError::WrongKind);
                        }
                    }
                    Err(LinkError::Version(v)) => {
                        return Err(self.fail(format!(
                            "the firmware speaks link version {v}, tss-sim version {}: rebuild one \
                             of them (`cargo fw-build`)",
                            link::VERSION
                        )))
                    }
                    Err(e) => self.report.plant_rx.count_error(e),
                }
            }
            if Instant::now() >= deadline {
                let status = self.qemu.try_wait().ok().flatten();
                return Err(self.fail(format!(
                    "no {what} from the firmware within {} s{}",
                    timeout.as_secs(),
                    status.map_or(String::new(), |s| format!(" (QEMU exited: {s})"))
                )));
            }
            match self.stream.read(&mut buf) {
                Ok(0) => {
                    let status = wait_exit(&mut self.qemu, EXIT_TIMEOUT);
                    return Err(self.fail(format!(
                        "the firmware closed the link while the plant waited for a {what} \
                         (QEMU: {})",
                        status.map_or("still running".into(), |s| s.to_string())
                    )));
                }
                Ok(n) => {
                    for &b in &buf[..n] {
                        if let Some(f) = self.reader.push(b) {
                            self.frames.push_back(f);
                        }
                    }
                }
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                    ) => {}
                Err(e) => return Err(io("reading the firmware's UART")(e)),
            }
        }
    }

    /// Sends the sample of `tick` (with the scenario's link faults) and returns the firmware's
    /// command for it.
    fn exchange(&mut self, tick: u32, input: Option<&Input<f32>>) -> Result<Output<f32>, PilError> {
        let sample = match input {
            Some(x) => Sample {
                tick,
                status: SAMPLE_VALID,
                length_m: x.length_m,
                reel_rate_mps: x.reel_rate_mps,
                tension_n: x.tension_n,
                alpha_rad: x.alpha_rad,
                alpha_rate_radps: x.alpha_rate_radps,
                orbit_rate_radps: x.orbit_rate_radps,
                true_anomaly_rad: x.true_anomaly_rad,
            },
            None => Sample {
                tick,
                status: SAMPLE_MISSING,
                length_m: 0.0,
                reel_rate_mps: None,
                tension_n: None,
                alpha_rad: None,
                alpha_rate_radps: None,
                orbit_rate_radps: 0.0,
                true_anomaly_rad: 0.0,
            },
        };
        let mut wire = [0u8; MAX_WIRE_LEN];
        let n = link::encode(self.seq, &Message::Sample(sample), &mut wire)
            .map_err(|e| self.fail(format!("encoding the sample of tick {tick}: {e:?}")))?;
        self.seq = self.seq.wrapping_add(1);
        let frame = wire[..n].to_vec();

        if let Some(late) = self.held.take() {
            self.write(&late)?;
        }
        self.on_time = false;
        match self.draw() {
            Fault::None => {
                self.write(&frame)?;
                self.on_time = true;
            }
            Fault::Drop => self.report.injected.dropped += 1,
            Fault::Corrupt => {
                self.report.injected.corrupted += 1;
                let bad = self.corrupt(frame);
                self.write(&bad)?;
            }
            Fault::Duplicate => {
                self.report.injected.duplicated += 1;
                self.write(&frame)?;
                self.write(&frame)?;
                self.on_time = true;
            }
            Fault::Reorder => {
                self.report.injected.reordered += 1;
                self.held = Some(frame);
            }
        }

        let what = format!("command for tick {tick}");
        let command = self.receive(REPLY_TIMEOUT, &what, |m| match m {
            Message::Command(c) => Some(*c),
            _ => None,
        })?;
        self.accept_command(tick, &command)
    }

    /// Keeps the telemetry packet `p`.
    fn keep(&mut self, p: &Packet) {
        self.report.telemetry_packets += 1;
        self.telemetry.push(p.bytes().to_vec());
    }

    fn accept_command(&mut self, tick: u32, c: &Command) -> Result<Output<f32>, PilError> {
        if c.tick != tick {
            return Err(self.fail(format!(
                "the firmware answered tick {tick} with the command of tick {}",
                c.tick
            )));
        }
        let out = c
            .to_output()
            .map_err(|e| self.fail(format!("command of tick {tick}: {e:?}")))?;
        if c.sample != SampleStatus::Fresh as u8 {
            self.report.missing_ticks.push(tick);
        }
        let s = &mut self.report.status;
        match SampleStatus::from_code(c.sample) {
            Some(SampleStatus::Fresh) => s.fresh += 1,
            Some(SampleStatus::Timeout) => {
                s.timeout += 1;
                if self.on_time {
                    self.report.spurious_timeouts += 1;
                }
            }
            Some(SampleStatus::Corrupted) => s.corrupted += 1,
            Some(SampleStatus::NoSample) | None => s.no_sample += 1,
        }
        self.report.ticks += 1;
        self.last_tick = tick;
        self.report.digest = link::fnv1a_f32(self.report.digest, out.rate_cmd_mps);
        Ok(out)
    }

    fn draw(&mut self) -> Fault {
        let f = &self.faults;
        if f.is_clean() {
            return Fault::None;
        }
        let u = self.rng.uniform_open();
        let mut edge = 0.0;
        for (p, fault) in [
            (f.drop_prob, Fault::Drop),
            (f.corrupt_prob, Fault::Corrupt),
            (f.duplicate_prob, Fault::Duplicate),
            (f.reorder_prob, Fault::Reorder),
        ] {
            edge += p;
            if u < edge {
                return fault;
            }
        }
        Fault::None
    }

    /// The frame with one byte (not the delimiter) changed to another non-zero value, so that
    /// it stays exactly one frame on the wire.
    fn corrupt(&mut self, mut frame: Vec<u8>) -> Vec<u8> {
        let body = frame.len().saturating_sub(1).max(1);
        let i = (self.rng.next_u32() as usize) % body;
        let old = frame[i];
        // 255 choices of a new non-zero value other than `old`.
        let mut new = (self.rng.next_u32() % 254) as u8 + 1;
        if new >= old && old != 0 {
            new += 1;
        }
        frame[i] = new;
        frame
    }

    /// Ends the run after `ticks` periods: sends a held frame and `End`, reads the firmware's
    /// `Report`, and waits for QEMU and the log decoder to exit.
    pub fn finish(mut self, ticks: u32) -> Result<PilReport, PilError> {
        self.send(&Message::End(End { ticks }), "end frame")?;
        let report = self.receive(REPLY_TIMEOUT, "report frame", |m| match m {
            Message::Report(r) => Some(*r),
            _ => None,
        })?;
        self.report.firmware_report = report;
        let status = wait_exit(&mut self.qemu, EXIT_TIMEOUT);
        match status {
            Some(s) if s.success() => {}
            Some(s) => return Err(self.fail(format!("QEMU exited with {s} after the report"))),
            None => return Err(self.fail("QEMU did not exit after the report".into())),
        }
        let _ = self.decoder.wait();
        self.report.wall = self.started.elapsed();
        Ok(std::mem::take(&mut self.report))
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Fault {
    None,
    Drop,
    Corrupt,
    Duplicate,
    Reorder,
}

impl Stepper<f32> for PilLink {
    fn step(&mut self, tick: u32, input: Option<&Input<f32>>) -> Result<Output<f32>, SimError> {
        self.exchange(tick, input)
            .map_err(|e| SimError::Link(Box::new(e)))
    }

    /// Sends the telecommand `raw` in a `Packet` frame; its verification reports come back
    /// with the period's command.
    fn telecommand(&mut self, raw: &[u8]) -> Result<(), SimError> {
        let packet = Packet::new(raw).ok_or_else(|| {
            SimError::Link(
                format!(
                    "a telecommand of {} bytes does not fit a link packet (1 to {})",
                    raw.len(),
                    link::MAX_PACKET_LEN
                )
                .into(),
            )
        })?;
        self.send(&Message::Packet(packet), "telecommand")
            .map_err(|e| SimError::Link(Box::new(e)))?;
        self.report.telecommands += 1;
        Ok(())
    }

    /// The telemetry received since the last call; with `housekeeping`, the firmware is asked
    /// for the housekeeping of the period it last answered (a `Collect` frame), and its
    /// packet awaited.
    fn take_telemetry(&mut self, housekeeping: bool) -> Result<Vec<Vec<u8>>, SimError> {
        if housekeeping {
            let tick = self.last_tick;
            let link = |e: PilError| SimError::Link(Box::new(e));
            self.send(&Message::Collect(Collect { tick }), "housekeeping request")
                .map_err(link)?;
            let hk = self
                .receive(REPLY_TIMEOUT, "housekeeping packet", |m| match m {
                    Message::Packet(p) => Some(*p),
                    _ => None,
                })
                .map_err(link)?;
            self.keep(&hk);
        }
        Ok(std::mem::take(&mut self.telemetry))
    }
}

/// Waits until QEMU connects to `listener` (or exits, or [`START_TIMEOUT`] passes).
fn accept(listener: &TcpListener, qemu: &mut Child, log: &Path) -> Result<TcpStream, PilError> {
    listener
        .set_nonblocking(true)
        .map_err(io("configuring the listener"))?;
    let deadline = Instant::now() + START_TIMEOUT;
    loop {
        match listener.accept() {
            Ok((stream, _)) => {
                stream
                    .set_nonblocking(false)
                    .and_then(|()| stream.set_nodelay(true))
                    .and_then(|()| stream.set_read_timeout(Some(POLL)))
                    .map_err(io("configuring the link socket"))?;
                return Ok(stream);
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
            Err(e) => return Err(io("accepting QEMU's connection")(e)),
        }
        if let Ok(Some(status)) = qemu.try_wait() {
            return Err(PilError::Firmware(
                format!("QEMU exited ({status}) before connecting its serial port"),
                log.to_path_buf(),
            ));
        }
        if Instant::now() >= deadline {
            return Err(PilError::Firmware(
                format!(
                    "QEMU did not connect its serial port within {} s",
                    START_TIMEOUT.as_secs()
                ),
                log.to_path_buf(),
            ));
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn wait_exit(child: &mut Child, timeout: Duration) -> Option<ExitStatus> {
    let deadline = Instant::now() + timeout;
    loop {
        match child.try_wait() {
            Ok(Some(s)) => return Some(s),
            Ok(None) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(10)),
            _ => return None,
        }
    }
}

/// Checks that `sc` fits in one PIL run ([`link::MAX_TICKS`] control periods).
pub fn check_duration(sc: &Scenario) -> Result<(), PilError> {
    let ticks = (sc.simulation.duration_s / sc.controller.period_s).round() + 1.0;
    if ticks <= f64::from(link::MAX_TICKS) {
        Ok(())
    } else {
        Err(PilError::TooLong {
            duration_s: sc.simulation.duration_s,
            ticks,
            max: link::MAX_TICKS,
        })
    }
}

/// Runs `sc` with the firmware `firmware` in the loop (QEMU), its log written to `log`:
/// the same history as [`sim::run`], and the link's report.
pub fn run(
    sc: &Scenario,
    firmware: &Path,
    log: &Path,
    probe_times_s: &[f64],
    progress: &mut dyn FnMut(f64),
) -> Result<(History, PilReport), SimError> {
    let wrap = |e: PilError| SimError::Link(Box::new(e));
    check_duration(sc).map_err(wrap)?;
    let mut link = PilLink::start(sc, firmware, log).map_err(wrap)?;
    let history = sim::run_stepper::<f32, _>(sc, &mut link, probe_times_s, progress)?;
    let ticks = history.faults.ticks;
    let report = link.finish(ticks).map_err(wrap)?;
    Ok((history, report))
}
