//! Processor-in-the-loop (PIL): the flight controller closes the loop with the `tss-sim` plant
//! over UART0, one frame pair per control period (`tss-sim run --pil`, `host-sim/src/pil.rs`).
//!
//! The firmware announces itself with a `Hello` frame (protocol version, the digest of its
//! built-in configuration `Config::flight()`, its period and sample timeout), then waits for the
//! plant's `Params` frame: the controller configuration to fly, as the parameter table
//! ([`tss_reel::link::ParamTable`]). It builds the controller from it, so the core's own
//! validation ([`Config::validate`]) judges the table, replaces the controller of its built-in
//! configuration by it whole, and answers with `Loaded`: the digest of
//! the configuration it now flies, or why it refused it (the word at fault and the core's rule;
//! a refused table changes nothing, and the firmware waits for another). Then, for every control
//! period: waits for the plant's `Sample` frame, steps the controller on it (the frame carries
//! the controller's whole `Input`, the optional readings included: α̇ for a controller that
//! flies on a rate sensor, the reel's rate, the tension), and sends the `Command` frame (the
//! whole controller output, so the plant side writes the same history as a host-linked run). An `End` frame
//! closes the run: the firmware answers with a `Report` (its link counters and the digest of
//! its commands), logs them, and exits with success.
//!
//! **Telecommands and telemetry.** Before a period's sample the plant may send the on-board
//! computer's telecommands, each a CCSDS/PUS packet in a `Packet` frame: the firmware hands
//! each to its PUS services ([`tss_reel::pus::Services`], the code the simulator's unit runs),
//! which verify it and execute it or hand it to the controller for the period boundary, and
//! sends every telemetry packet they produce back in a `Packet` frame at once: the verification
//! reports as the telecommand is taken, the completion reports and the events after the step
//! (before the `Command`), and the housekeeping of a period when the plant asks for it with a
//! `Collect` frame (it records that period). So the telemetry comes from the MCU, in the order
//! and with the contents of a host-linked run.
//!
//! **Time.** The plant is the clock: the tick number in the sample frame is the authority, and
//! the firmware never runs ahead of the plant, because it blocks (bounded) on each sample.
//! SysTick keeps running and serves as the timeout: a sample that has not arrived after
//! [`TIMEOUT_TICKS`] SysTick periods is missing. Under QEMU's instruction counting
//! (`-icount shift=5,align=off,sleep=off`) the wait is a busy poll, so emulated time advances
//! with the polls: the timeout is between one and two control periods of emulated time,
//! whatever the host's speed. (A WFI would let QEMU skip straight to the next SysTick, before
//! the plant has sent anything.) The log's timestamps are SysTick time since boot, not mission
//! time; every line names its tick.
//!
//! **Link faults.** A period whose sample frame is missing (timeout), corrupted (COBS, CRC,
//! version, … — see [`tss_reel::link`]) or reports no sample upstream is a lost sample
//! (`ErrorKind::NoSample` / `ErrorKind::Corrupted`): the controller steps without one
//! (`Controller::step_missing`), exactly as in a sensor dropout. Duplicated and late
//! (out-of-order) sample frames are discarded without using up the period, so the firmware
//! keeps waiting for the right one. Every fault is logged with its tick and counted
//! ([`tss_reel::link::LinkCounters`]); the counters are logged and reported at the end.

use embedded_io::Write as _;
use tss_reel::controller::{Config, Controller, Input, Output};
use tss_reel::hal::{ErrorKind, ErrorType, ReelDrive};
use tss_reel::link::{
    self, Command, FrameReader, Gate, Hello, LinkCounters, LinkError, LoadVerdict, Loaded, Message,
    Packet, ParamTable, Report, Sample, SampleGate, SampleStatus, MAX_WIRE_LEN, NO_PARAM,
    SAMPLE_VALID,
};
use tss_reel::pus::Services;

use super::clock::{self, ControlClock};
use super::exit;
use super::mission::CONTROL_PERIOD_MS;
use super::uart::{Uart, UartError};

/// SysTick periods the firmware waits for a sample frame before it steps without one. Two, so
/// the wait lasts at least one full control period wherever in a period it starts.
pub const TIMEOUT_TICKS: u32 = 2;

/// Hard bound on the control periods of one PIL run ([`link::MAX_TICKS`]: the paper's 20 h
/// mission, 72 001 ticks, with room to spare). A run still going then is a failure, never a
/// hang.
pub const MAX_TICKS: u32 = link::MAX_TICKS;

/// Timeouts in a row after which the plant is taken to be gone: the run ends with a failure.
pub const MAX_SILENT_PERIODS: u32 = 600;

/// Largest number of UART polls in one wait: a bound on the loop should SysTick stop.
const MAX_POLLS_PER_WAIT: u32 = 1 << 28;

/// Most telecommand and housekeeping-request frames taken while one period's sample is
/// awaited; beyond them the period is a timeout (the PUS flood limit,
/// `pus::MAX_TCS_PER_PERIOD`, refuses all but the first few telecommands long before).
const MAX_FRAMES_PER_PERIOD: u32 = 64;

/// What one wait on the link produced.
// The parameter table arrives once a run; there is no heap to box it in.
#[allow(clippy::large_enum_variant)]
enum Received {
    /// A sample frame for the awaited period (or a later one).
    Sample(Sample),
    /// No valid sample frame in time.
    Timeout,
    /// A frame that failed its checks.
    Corrupted(LinkError),
    /// The plant ended the run after this many periods (frames lost before its `End` are
    /// counted as sequence gaps).
    End(u32),
    /// A parameter table and its frame's sequence number (before the first period; later ones
    /// are counted as the wrong kind).
    Params(ParamTable, u32),
    /// A telecommand packet (after the table is loaded).
    Telecommand(Packet),
    /// The plant asks for the housekeeping of the period `tick`.
    Collect(u32),
}

/// The controller's input of a valid sample frame for `tick`, field by field.
fn input(tick: u32, s: &Sample) -> Input<f32> {
    Input {
        tick,
        length_m: s.length_m,
        reel_rate_mps: s.reel_rate_mps,
        tension_n: s.tension_n,
        alpha_rad: s.alpha_rad,
        alpha_rate_radps: s.alpha_rate_radps,
        orbit_rate_radps: s.orbit_rate_radps,
        true_anomaly_rad: s.true_anomaly_rad,
    }
}

/// The UART end of the link: frames in (with the sequence checks), frames out.
struct Link {
    uart: Uart,
    reader: FrameReader,
    gate: SampleGate,
    counters: LinkCounters,
    /// Sequence number of the next frame sent.
    seq: u32,
    /// Frames that could not be sent (encoding or UART failure).
    send_errors: u32,
}

impl Link {
    fn send(&mut self, message: &Message) -> Result<(), ErrorKind> {
        let mut wire = [0u8; MAX_WIRE_LEN];
        let sent = link::encode(self.seq, message, &mut wire)
            .map_err(|_| ErrorKind::Other)
            .and_then(|n| {
                let bytes = wire.get(..n).ok_or(ErrorKind::Other)?;
                self.uart.write_all(bytes).map_err(|_| ErrorKind::Device)
            });
        self.seq = self.seq.wrapping_add(1);
        if sent.is_err() {
            self.send_errors = self.send_errors.saturating_add(1);
        }
        sent
    }

    /// Sends the telemetry packet `tm` in a `Packet` frame (a failure is counted in
    /// `send_errors` and logged at the end).
    fn send_packet(&mut self, tm: &[u8]) {
        match Packet::new(tm) {
            Some(p) => {
                let _ = self.send(&Message::Packet(p));
            }
            None => self.send_errors = self.send_errors.saturating_add(1),
        }
    }

    /// Waits for the sample of period `awaited` (or, `loading`, a parameter table), at most
    /// [`TIMEOUT_TICKS`] SysTick periods.
    fn receive(&mut self, awaited: u32, loading: bool) -> Received {
        let start = clock::ticks();
        for _ in 0..MAX_POLLS_PER_WAIT {
            let byte = match self.uart.try_read_byte() {
                Ok(Some(b)) => b,
                Ok(None) => {
                    if clock::ticks().wrapping_sub(start) >= TIMEOUT_TICKS {
                        break;
                    }
                    continue;
                }
                Err(UartError::Overrun) => {
                    defmt::warn!("link: UART receive overrun (a byte was lost)");
                    continue;
                }
                Err(UartError::TimedOut) => continue,
            };
            let Some(decoded) = self.reader.push(byte) else {
                continue;
            };
            let frame = match decoded {
                Ok(f) => f,
                Err(e) => {
                    self.counters.count_error(e);
                    return Received::Corrupted(e);
                }
            };
            match frame.message {
                Message::Sample(s) if !loading => {
                    match self.gate.check(frame.seq, s, awaited, &mut self.counters) {
                        Gate::Accept(s) => return Received::Sample(s),
                        Gate::Duplicate => defmt::warn!(
                            "link: duplicate sample frame seq={=u32} t={=u32} discarded",
                            frame.seq,
                            s.tick
                        ),
                        Gate::OutOfOrder => defmt::warn!(
                            "link: late sample frame seq={=u32} t={=u32} discarded",
                            frame.seq,
                            s.tick
                        ),
                    }
                }
                Message::End(e) => {
                    self.gate.close(frame.seq, &mut self.counters);
                    return Received::End(e.ticks);
                }
                Message::Params(table) if loading => return Received::Params(table, frame.seq),
                Message::Packet(p) if !loading => {
                    self.gate.other(frame.seq, &mut self.counters);
                    return Received::Telecommand(p);
                }
                Message::Collect(c) if !loading => {
                    self.gate.other(frame.seq, &mut self.counters);
                    return Received::Collect(c.tick);
                }
                Message::Sample(_)
                | Message::Hello(_)
                | Message::Command(_)
                | Message::Report(_)
                | Message::Params(_)
                | Message::Loaded(_)
                | Message::Packet(_)
                | Message::Collect(_) => {
                    self.counters.count_error(LinkError::WrongKind);
                    defmt::warn!(
                        "link: unexpected frame kind discarded (seq={=u32})",
                        frame.seq
                    );
                }
            }
        }
        self.counters.timeouts = self.counters.timeouts.saturating_add(1);
        Received::Timeout
    }
}

/// The reel unit: the flight controller behind its PUS services, as the simulator's
/// (`host-sim/src/obc.rs`), its telemetry going out over the link.
struct Unit {
    controller: Controller<f32>,
    services: Services,
    /// The last step's sample, for its housekeeping.
    last_input: Option<Input<f32>>,
}

impl Unit {
    /// Waits for the sample of period `awaited` ([`Link::receive`]), taking the telecommands
    /// and housekeeping requests that come before it (at most [`MAX_FRAMES_PER_PERIOD`]).
    ///
    /// Not inlined into [`run`]: the frames it receives would otherwise stay reserved in
    /// `run`'s frame under the parameter-table load as well (the PIL-mode stack).
    #[inline(never)]
    fn await_sample(&mut self, link: &mut Link, awaited: u32) -> Received {
        for _ in 0..MAX_FRAMES_PER_PERIOD {
            match link.receive(awaited, false) {
                Received::Telecommand(tc) => self.telecommand(link, &tc),
                Received::Collect(tick) => {
                    let last = self.controller.output().tick;
                    if tick != last {
                        defmt::warn!(
                            "t={=u32} link: housekeeping asked for tick {=u32}",
                            last,
                            tick
                        );
                    }
                    self.services.report_housekeeping(
                        &self.controller,
                        self.last_input.as_ref(),
                        &mut |tm| link.send_packet(tm),
                    );
                }
                other => return other,
            }
        }
        defmt::warn!(
            "t={=u32} link: more than {=u32} frames before the sample",
            awaited,
            MAX_FRAMES_PER_PERIOD
        );
        link.counters.timeouts = link.counters.timeouts.saturating_add(1);
        Received::Timeout
    }

    /// Hands the telecommand `tc` to the PUS services and sends their reports.
    ///
    /// Not inlined into [`Unit::await_sample`]: the decoded telecommand (a parameter table, at
    /// most) would otherwise stay reserved on the stack under every frame received (the
    /// PIL-mode stack, `scripts/size-check`).
    #[inline(never)]
    fn telecommand(&mut self, link: &mut Link, tc: &Packet) {
        self.services
            .telecommand(tc.bytes(), &mut self.controller, &mut |tm| {
                link.send_packet(tm)
            });
    }

    /// Steps the controller for `tick` on `reading` (or without a sample) and sends the
    /// step's telemetry: the completion of a mode command it applied, and its events.
    fn step(&mut self, link: &mut Link, tick: u32, reading: Option<&Sample>) -> Output<f32> {
        self.last_input = reading.map(|s| input(tick, s));
        let output = match &self.last_input {
            Some(x) => *self.controller.step(x),
            None => *self.controller.step_missing(tick),
        };
        self.services
            .report_events(&mut self.controller, &mut |tm| link.send_packet(tm));
        output
    }
}

/// The reel drive of PIL: each command goes out as a `Command` frame.
struct CommandLink<'a> {
    link: &'a mut Link,
    /// How this period's sample arrived (reported with the command).
    status: SampleStatus,
    /// Commands sent, and the FNV-1a digest of their rate bit patterns.
    count: u32,
    digest: u32,
}

impl ErrorType for CommandLink<'_> {
    type Error = ErrorKind;
}

impl ReelDrive for CommandLink<'_> {
    fn command(&mut self, output: &Output<f32>) -> Result<(), ErrorKind> {
        self.link
            .send(&Message::Command(Command::from_output(output, self.status)))?;
        self.count = self.count.saturating_add(1);
        self.digest = link::fnv1a_f32(self.digest, output.rate_cmd_mps);
        Ok(())
    }
}

/// Runs the PIL mission until the plant ends it; never returns.
///
/// It owns the running control clock: SysTick is the sample timeout's time base.
pub fn run(_clock: ControlClock) -> ! {
    let mut link = Link {
        uart: Uart::uart0(),
        reader: FrameReader::new(),
        gate: SampleGate::new(),
        counters: LinkCounters::default(),
        seq: 0,
        send_errors: 0,
    };
    let builtin = link::config_digest(&Config::flight());
    defmt::info!(
        "PIL: link v{=u8} on UART0, built-in config digest {=u32:#010x}, sample timeout {=u32} periods",
        link::VERSION,
        builtin,
        TIMEOUT_TICKS
    );
    let hello = Hello {
        config_digest: builtin,
        period_ms: CONTROL_PERIOD_MS,
        timeout_periods: TIMEOUT_TICKS as u8,
    };
    if link.send(&Message::Hello(hello)).is_err() {
        defmt::error!("PIL: could not send the hello frame");
        exit::failure();
    }
    let mut unit = Unit {
        controller: builtin_controller(),
        services: Services::new(),
        last_input: None,
    };
    load(&mut link, &mut unit.controller);

    // The plant's first sample is that of tick 0: a lost first frame is a missing sample like
    // any other (the firmware times out and steps without it), never a wait for ever.
    let mut awaited = 0u32;
    let mut silent = 0u32;
    let mut count = 0u32;
    let mut digest = link::fnv1a_start();
    let mut dropouts = 0u32;
    for _ in 0..MAX_TICKS {
        let (tick, status, reading) = match unit.await_sample(&mut link, awaited) {
            Received::End(ticks) => finish(&mut link, ticks, count, digest, dropouts),
            // Not asked for: `receive` counts a late table as the wrong kind; `await_sample`
            // takes the telecommands and housekeeping requests.
            Received::Params(..) | Received::Telecommand(_) | Received::Collect(_) => continue,
            Received::Sample(s) => {
                silent = 0;
                if s.tick > awaited {
                    defmt::warn!(
                        "t={=u32} link: jumped from awaited tick {=u32}",
                        s.tick,
                        awaited
                    );
                }
                if s.status == SAMPLE_VALID {
                    (s.tick, SampleStatus::Fresh, Ok(s))
                } else {
                    (s.tick, SampleStatus::NoSample, Err(ErrorKind::NoSample))
                }
            }
            lost @ (Received::Timeout | Received::Corrupted(_)) => {
                silent = silent.saturating_add(1);
                if silent > MAX_SILENT_PERIODS {
                    defmt::error!("PIL: no sample for {=u32} periods: link lost", silent);
                    log_counters(&link, count, digest, dropouts);
                    exit::failure();
                }
                if let Received::Corrupted(e) = lost {
                    defmt::warn!("t={=u32} link: corrupted sample frame: {}", awaited, e);
                    (awaited, SampleStatus::Corrupted, Err(ErrorKind::Corrupted))
                } else {
                    defmt::warn!("t={=u32} link: no sample frame (timeout)", awaited);
                    (awaited, SampleStatus::Timeout, Err(ErrorKind::NoSample))
                }
            }
        };
        if reading.is_err() {
            dropouts = dropouts.saturating_add(1);
        }
        let output = unit.step(&mut link, tick, reading.as_ref().ok());
        let mut reel = CommandLink {
            link: &mut link,
            status,
            count,
            digest,
        };
        let sent = reel.command(&output);
        count = reel.count;
        digest = reel.digest;
        if let Err(e) = sent {
            defmt::error!("t={=u32} the command frame could not be sent: {}", tick, e);
            exit::failure();
        }
        awaited = tick.saturating_add(1);
    }
    defmt::error!(
        "PIL: the plant did not end the run within {=u32} periods",
        MAX_TICKS
    );
    log_counters(&link, count, digest, dropouts);
    exit::failure()
}

/// Waits for the plant's parameter table and replaces `controller` by the one built from it,
/// answering each table with `Loaded`; a refused table changes nothing and the next one is
/// awaited. The plant gone silent for [`MAX_SILENT_PERIODS`], or ending the run before a table
/// was accepted, ends the run. The plant's first sample frame is the one after the accepted
/// table.
///
/// Not inlined into [`run`], and the table judged in [`judge`]: the controller a table builds
/// is on the stack only while it is judged, not under every wait for a frame (the PIL-mode
/// stack, `scripts/size-check`).
#[inline(never)]
fn load(link: &mut Link, controller: &mut Controller<f32>) {
    let mut silent = 0u32;
    loop {
        let received = link.receive(0, true);
        let (table, seq) = match &received {
            Received::Params(t, seq) => (t, *seq),
            Received::End(ticks) => finish(link, *ticks, 0, link::fnv1a_start(), 0),
            // (`receive` returns no sample, telecommand or housekeeping request while loading:
            // it counts them as the wrong kind.)
            Received::Timeout
            | Received::Corrupted(_)
            | Received::Sample(_)
            | Received::Telecommand(_)
            | Received::Collect(_) => {
                silent = silent.saturating_add(1);
                if silent > MAX_SILENT_PERIODS {
                    defmt::error!("PIL: no parameter table for {=u32} periods", silent);
                    exit::failure();
                }
                continue;
            }
        };
        let verdict = judge(table, controller);
        send_verdict(link, verdict);
        if verdict.verdict == LoadVerdict::Accepted as u8 {
            link.gate = SampleGate::from_seq(seq.wrapping_add(1));
            return;
        }
    }
}

/// The controller of the built-in configuration (`Config::flight`), flown until the plant's
/// table replaces it ([`load`]).
///
/// Not inlined into [`run`]: the controller is built in this frame and moved into `run`'s;
/// inlined, both would stay reserved for the whole mission (the PIL-mode stack).
#[inline(never)]
fn builtin_controller() -> Controller<f32> {
    match Controller::new(Config::flight()) {
        Ok(c) => c,
        Err(e) => {
            defmt::error!("PIL: the core refuses the built-in configuration: {}", e);
            exit::failure()
        }
    }
}

/// Judges `table` by the core's validation (`Controller::new`): accepted, the controller built
/// from it replaces `controller` whole; refused, nothing changes. Returns the answer.
#[inline(never)]
fn judge(table: &ParamTable, controller: &mut Controller<f32>) -> Loaded {
    let cfg = match table.to_config() {
        Ok(cfg) => cfg,
        Err(e) => {
            defmt::warn!("PIL: parameter table refused: {}", e);
            return Loaded {
                config_digest: 0,
                verdict: LoadVerdict::BadTable as u8,
                param: e.index(),
                rule: 0,
            };
        }
    };
    match Controller::new(cfg) {
        Ok(c) => {
            *controller = c;
            let digest = link::config_digest(controller.config());
            defmt::info!(
                "PIL: parameter table loaded, config digest {=u32:#010x}",
                digest
            );
            Loaded {
                config_digest: digest,
                verdict: LoadVerdict::Accepted as u8,
                param: NO_PARAM,
                rule: 0,
            }
        }
        Err(e) => {
            defmt::warn!("PIL: parameter table refused: {}", e);
            Loaded {
                config_digest: 0,
                verdict: LoadVerdict::Refused as u8,
                param: link::param_index(&e).unwrap_or(NO_PARAM),
                rule: link::rule_code(e.rule),
            }
        }
    }
}

/// Sends the `Loaded` answer to a parameter table; the run ends if it cannot be sent.
fn send_verdict(link: &mut Link, verdict: Loaded) {
    if link.send(&Message::Loaded(verdict)).is_err() {
        defmt::error!("PIL: could not send the load verdict");
        exit::failure();
    }
}

/// Answers the plant's `End` with the `Report`, logs the counters and exits with success.
fn finish(link: &mut Link, ticks: u32, commands: u32, digest: u32, dropouts: u32) -> ! {
    defmt::info!(
        "PIL: plant ended the run after {=u32} periods; {=u32} commands sent",
        ticks,
        commands
    );
    let report = Report {
        counters: link.counters,
        commands,
        digest,
    };
    let sent = link.send(&Message::Report(report));
    let flushed = link.uart.flush();
    log_counters(link, commands, digest, dropouts);
    super::stack::log_high_water();
    if sent.is_err() || flushed.is_err() {
        defmt::error!("PIL: the report frame could not be sent");
        exit::failure();
    }
    exit::success()
}

fn log_counters(link: &Link, commands: u32, digest: u32, dropouts: u32) {
    let c = &link.counters;
    defmt::info!(
        "PIL link: {=u32} samples used, {=u32} commands (digest {=u32:#010x}), {=u32} periods without a sample",
        c.frames_ok,
        commands,
        digest,
        dropouts
    );
    defmt::info!(
        "PIL link faults: timeouts={=u32} decode errors={=u32} (crc={=u32} cobs={=u32} truncated={=u32} version={=u32} kind={=u32} malformed={=u32} wrong-kind={=u32} overflow={=u32}) duplicates={=u32} late={=u32} seq gaps={=u32} uart overruns={=u32} send errors={=u32}",
        c.timeouts,
        c.decode_errors(),
        c.crc_errors,
        c.cobs_errors,
        c.truncated,
        c.version_errors,
        c.unknown_kind,
        c.malformed,
        c.wrong_kind,
        c.overflows,
        c.duplicates,
        c.out_of_order,
        c.seq_gaps,
        link.uart.overruns(),
        link.send_errors
    );
}
