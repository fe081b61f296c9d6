//! The on-board computer's side of the reel unit's PUS interface (docs/interface.md §3): the
//! scenario's timed telecommands (`[[telecommand]]`) encoded as CCSDS/PUS packets
//! (`tss_reel::pus::encode`), the unit they go to (the flight controller with its PUS services,
//! `tss_reel::pus::Services`, the code the firmware links), and the telemetry that comes back,
//! decoded into `telemetry.csv`.

use std::io::{self, Write};

use tss_reel::controller::{Controller, Input, ModeCommand, Output};
use tss_reel::pus::{self, read_telemetry, Counts, Services, Telecommand, Telemetry};
use tss_reel::reel_drive::DriveFaults;

use crate::scenario::Scenario;
use crate::stepper::{ticks, SimError, Stepper};

/// The reel unit as the on-board computer sees it: the flight controller (f32) behind its PUS
/// services. Its telemetry is kept until [`Stepper::take_telemetry`], which asks for the
/// housekeeping of the last step only when it is kept (the closed loop keeps it at the output
/// interval: service 3's collection interval).
pub struct Unit {
    controller: Controller<f32>,
    services: Services,
    sent: Vec<Vec<u8>>,
    /// The last step's sample, for its housekeeping.
    last_input: Option<Input<f32>>,
}

impl Unit {
    /// The unit flying `controller`.
    pub fn new(controller: Controller<f32>) -> Self {
        Self {
            controller,
            services: Services::new(),
            sent: Vec::new(),
            last_input: None,
        }
    }

    /// After a step on `input`: the services' verification and events of it.
    fn report(&mut self, input: Option<&Input<f32>>) -> Output<f32> {
        let sent = &mut self.sent;
        self.services
            .report_events(&mut self.controller, &mut |p| sent.push(p.to_vec()));
        self.last_input = input.copied();
        *self.controller.output()
    }
}

impl Stepper<f32> for Unit {
    fn step(&mut self, tick: u32, input: Option<&Input<f32>>) -> Result<Output<f32>, SimError> {
        match input {
            Some(x) => self.controller.step(x),
            None => self.controller.step_missing(tick),
        };
        Ok(self.report(input))
    }

    fn step_with_drive(
        &mut self,
        tick: u32,
        input: Option<&Input<f32>>,
        drive: DriveFaults,
    ) -> Result<Output<f32>, SimError> {
        self.controller.step_with_drive(tick, input, drive);
        Ok(self.report(input))
    }

    fn telecommand(&mut self, raw: &[u8]) -> Result<(), SimError> {
        let sent = &mut self.sent;
        self.services
            .telecommand(raw, &mut self.controller, &mut |p| sent.push(p.to_vec()));
        Ok(())
    }

    fn take_telemetry(&mut self, housekeeping: bool) -> Result<Vec<Vec<u8>>, SimError> {
        if housekeeping {
            let sent = &mut self.sent;
            self.services.report_housekeeping(
                &self.controller,
                self.last_input.as_ref(),
                &mut |p| sent.push(p.to_vec()),
            );
        }
        Ok(std::mem::take(&mut self.sent))
    }
}

/// The on-board computer: the scenario's telecommands, by control tick, and its sequence count.
pub struct Obc {
    /// (tick, command), in the order they are sent.
    schedule: Vec<(u32, ModeCommand)>,
    next: usize,
    seq: u16,
}

impl Obc {
    /// The telecommands of `sc` (sorted by time; in file order at the same time).
    pub fn new(sc: &Scenario) -> Result<Self, SimError> {
        let mut schedule = Vec::with_capacity(sc.telecommand.len());
        for tc in &sc.telecommand {
            let tick = ticks("telecommand.at_s", tc.at_s, sc.controller.period_s)?;
            schedule.push((tick, tc.command.to_mode_command()));
        }
        schedule.sort_by_key(|&(tick, _)| tick);
        Ok(Self {
            schedule,
            next: 0,
            seq: 0,
        })
    }

    /// Sends `unit` the telecommands due before the control period `tick`.
    pub fn send_due<T, S: Stepper<T> + ?Sized>(
        &mut self,
        tick: u32,
        unit: &mut S,
    ) -> Result<(), SimError> {
        while let Some(&(at, command)) = self.schedule.get(self.next) {
            if at > tick {
                break;
            }
            let mut buf = [0u8; pus::MAX_TC_LEN];
            let n = pus::encode(&Telecommand::Mode(command), self.seq, &mut buf)
                .expect("a mode telecommand fits MAX_TC_LEN");
            unit.telecommand(&buf[..n])?;
            self.seq = (self.seq + 1) & 0x3fff;
            self.next += 1;
        }
        Ok(())
    }
}

/// The packets of a run, by kind.
pub fn counts(packets: &[Vec<u8>]) -> Counts {
    let mut c = Counts::default();
    for p in packets {
        c.count(p);
    }
    c
}

/// The columns of `telemetry.csv`.
pub const TELEMETRY_COLUMNS: [&str; 30] = [
    "t_s",
    "time",
    "seq",
    "service",
    "subtype",
    "request_seq",
    "stage",
    "failure_code",
    "failure_data",
    "event_id",
    "event_aux",
    "tick",
    "length_estimate_m",
    "rate_cmd_mps",
    "accel_cmd_mps2",
    "law_rate_mps",
    "blend_weight",
    "alpha_ref_rad",
    "delta_rad",
    "delta_rate_radps",
    "alpha_rad",
    "alpha_rate_radps",
    "tension_n",
    "equilibrium_margin",
    "phase",
    "health",
    "mode",
    "fault",
    "flags",
    "events_dropped",
];

/// Writes `telemetry.csv`: one row per packet, decoded (`t_s` is the packet's on-board time
/// × `period_s`; the cells of another kind's fields are empty; an optional value the unit did
/// not have is empty too).
pub fn write_telemetry_csv<W: Write>(
    mut w: W,
    packets: &[Vec<u8>],
    period_s: f64,
) -> io::Result<()> {
    writeln!(w, "{}", TELEMETRY_COLUMNS.join(","))?;
    for raw in packets {
        let Some(p) = read_telemetry(raw) else {
            continue;
        };
        let t_s = f64::from(p.time) * period_s;
        let head =
            |service: u8, subtype: u8| format!("{t_s},{},{},{service},{subtype}", p.time, p.seq);
        let opt = |x: Option<f32>| x.map_or(String::new(), |v| f64::from(v).to_string());
        let row = match p.telemetry {
            Telemetry::Verification {
                request,
                stage,
                failure,
            } => {
                let stage_name = match stage {
                    pus::Stage::Acceptance => "acceptance",
                    pus::Stage::Start => "start",
                    pus::Stage::Completion => "completion",
                };
                let subtype = match (stage, failure.is_some()) {
                    (pus::Stage::Acceptance, ok) => 1 + u8::from(ok),
                    (pus::Stage::Start, ok) => 3 + u8::from(ok),
                    (pus::Stage::Completion, ok) => 7 + u8::from(ok),
                };
                let (code, data) = failure.map_or((String::new(), String::new()), |(c, d)| {
                    (c.to_string(), format!("{:08x}", u32::from_be_bytes(d)))
                });
                format!(
                    "{},{},{stage_name},{code},{data},,{}",
                    head(1, subtype),
                    request.sequence & 0x3fff,
                    ",".repeat(19)
                )
            }
            Telemetry::Event { severity, id, aux } => format!(
                "{},,,,,{id},{:08x}{}",
                head(5, severity as u8),
                u32::from_be_bytes(aux),
                ",".repeat(19)
            ),
            Telemetry::Housekeeping(h) => format!(
                "{},,,,,,,{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                head(3, 25),
                h.tick,
                f64::from(h.length_estimate_m),
                f64::from(h.rate_cmd_mps),
                f64::from(h.accel_cmd_mps2),
                f64::from(h.law_rate_mps),
                f64::from(h.blend_weight),
                f64::from(h.alpha_ref_rad),
                f64::from(h.delta_rad),
                f64::from(h.delta_rate_radps),
                opt(h.alpha_rad),
                opt(h.alpha_rate_radps),
                opt(h.tension_n),
                f64::from(h.equilibrium_margin),
                h.phase,
                h.health,
                h.mode,
                h.fault,
                h.flags,
                h.events_dropped,
            ),
        };
        writeln!(w, "{row}")?;
    }
    w.flush()
}
