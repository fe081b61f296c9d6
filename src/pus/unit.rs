//! The reel unit's PUS services around its controller: each telecommand judged and verified
//! (service 1), the mission-mode commands handed to the controller ([`Controller::command`]),
//! the parameter table loaded and the on-board time set; after each step, housekeeping
//! (service 3) and the controller's events (service 5) (docs/interface.md §3).
//!
//! The telemetry goes out through a sink (`emit`, one packet per call), so the unit keeps no
//! queue: a packet is written into a buffer on the stack and handed over at once.
//!
//! ```text
//!   telecommand ─ decode ─✗─▶ TM[1,2] (the decoder's reason; or a flood)
//!                    ✓ ─▶ TM[1,1] ─ judge ─✗─▶ TM[1,4] (refused: mode, table, too late)
//!                                       ✓ ─▶ TM[1,3] ─▶ TM[1,7] (mode: at its boundary;
//!                                                                time, table: at once)
//!   after a step ──▶ TM[1,7] of a mode command applied, TM[5,x] per event, TM[3,25]
//! ```

use spacepackets::ecss::tm::PusTmReader;
use spacepackets::CcsdsPacket;

use crate::controller::{
    Controller, Event, EventKind, Health, Input, Mode, RateSource, TensionLoopMode,
};
use crate::link::{
    fault_code, health_code, param_index, phase_code, rule_code, ParamTable, NO_PARAM,
};

use super::{
    decode, telemetry_packet, verification_report, Failure, RequestId, Stage, Telecommand, APID,
    TIME_LEN, TM_OVERHEAD_LEN,
};

/// The most telecommands the unit takes in one control period; any beyond are refused
/// ([`Failure::Flood`]) unread.
pub const MAX_TCS_PER_PERIOD: u8 = 4;

/// The housekeeping structure the unit reports each period (TM\[3,25\]'s structure id).
pub const HOUSEKEEPING_SID: u16 = 1;

/// Length of the housekeeping report's source data: structure id 2, tick 4, twelve f32, five
/// code bytes, flags 4, events dropped 4.
pub const HOUSEKEEPING_LEN: usize = 2 + 4 + 12 * 4 + 5 + 4 + 4;

/// Length of an event report's source data: event id 2, auxiliary data 4.
pub const EVENT_LEN: usize = 6;

/// The longest packet the unit sends: primary header 6, secondary header 7 + time, the
/// housekeeping data, packet error control 2.
pub const MAX_TM_LEN: usize = TM_OVERHEAD_LEN + HOUSEKEEPING_LEN;

/// One period's housekeeping (TM\[3,25\], structure [`HOUSEKEEPING_SID`]): the controller's
/// output and the swing and tension it flew on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Housekeeping {
    /// The controller's tick of the step.
    pub tick: u32,
    /// The length the controller works with, m.
    pub length_estimate_m: f32,
    /// Reel-rate command, m/s.
    pub rate_cmd_mps: f32,
    /// Commanded acceleration, m/s².
    pub accel_cmd_mps2: f32,
    /// The Eq. 27 value before the blend, m/s.
    pub law_rate_mps: f32,
    /// The Eq. 29 blend weight E.
    pub blend_weight: f32,
    /// α_r, rad.
    pub alpha_ref_rad: f32,
    /// δ, rad.
    pub delta_rad: f32,
    /// δ̇, rad/s.
    pub delta_rate_radps: f32,
    /// α̂ (flying on the estimator) or the sensed α, rad (`None`: none this period).
    pub alpha_rad: Option<f32>,
    /// α̇̂ or the sensed α̇, rad/s (`None`: none this period).
    pub alpha_rate_radps: Option<f32>,
    /// The load cell's tension, N (`None`: no reading this period).
    pub tension_n: Option<f32>,
    /// The Eq. 13 margin.
    pub equilibrium_margin: f32,
    /// [`crate::link::phase_code`].
    pub phase: u8,
    /// [`crate::link::health_code`].
    pub health: u8,
    /// [`mode_code`].
    pub mode: u8,
    /// [`crate::link::fault_code`].
    pub fault: u8,
    /// The controller's [`crate::controller::Flags`].
    pub flags: u32,
    /// Events the controller's queue dropped so far.
    pub events_dropped: u32,
}

/// The validity bits of [`Housekeeping`]'s optional values.
const VALID_ALPHA: u8 = 1 << 0;
const VALID_ALPHA_RATE: u8 = 1 << 1;
const VALID_TENSION: u8 = 1 << 2;

impl Housekeeping {
    /// The housekeeping of the step `ctl` just made on `sample`.
    pub fn of(ctl: &Controller<f32>, sample: Option<&Input<f32>>) -> Self {
        let out = ctl.output();
        let (alpha_rad, alpha_rate_radps) = match (&ctl.config().rate_source, ctl.estimate()) {
            (RateSource::Estimator(_), Some(e)) => (Some(e.alpha_rad), Some(e.alpha_rate_radps)),
            (RateSource::Estimator(_), None) => (None, None),
            (RateSource::Sensor, _) => (
                sample.and_then(|x| x.alpha_rad),
                sample.and_then(|x| x.alpha_rate_radps),
            ),
        };
        Self {
            tick: out.tick,
            length_estimate_m: out.length_estimate_m,
            rate_cmd_mps: out.rate_cmd_mps,
            accel_cmd_mps2: out.accel_cmd_mps2,
            law_rate_mps: out.law_rate_mps,
            blend_weight: out.blend_weight,
            alpha_ref_rad: out.alpha_ref_rad,
            delta_rad: out.delta_rad,
            delta_rate_radps: out.delta_rate_radps,
            alpha_rad,
            alpha_rate_radps,
            tension_n: sample.and_then(|x| x.tension_n),
            equilibrium_margin: out.equilibrium_margin,
            phase: phase_code(out.phase),
            health: health_code(out.health),
            mode: mode_code(ctl.mode()),
            fault: fault_code(out.fault),
            flags: out.flags.0,
            events_dropped: ctl.events_dropped(),
        }
    }

    /// The source data of its TM\[3,25\], big-endian.
    pub fn to_bytes(&self) -> [u8; HOUSEKEEPING_LEN] {
        let mut out = [0u8; HOUSEKEEPING_LEN];
        let mut w = Writer {
            out: &mut out,
            at: 0,
        };
        w.put(&HOUSEKEEPING_SID.to_be_bytes());
        w.put(&self.tick.to_be_bytes());
        let or_zero = |x: Option<f32>| x.unwrap_or(0.0);
        for x in [
            self.length_estimate_m,
            self.rate_cmd_mps,
            self.accel_cmd_mps2,
            self.law_rate_mps,
            self.blend_weight,
            self.alpha_ref_rad,
            self.delta_rad,
            self.delta_rate_radps,
            or_zero(self.alpha_rad),
            or_zero(self.alpha_rate_radps),
            or_zero(self.tension_n),
            self.equilibrium_margin,
        ] {
            w.put(&x.to_bits().to_be_bytes());
        }
        let mut valid = 0;
        for (present, bit) in [
            (self.alpha_rad.is_some(), VALID_ALPHA),
            (self.alpha_rate_radps.is_some(), VALID_ALPHA_RATE),
            (self.tension_n.is_some(), VALID_TENSION),
        ] {
            valid |= if present { bit } else { 0 };
        }
        w.put(&[self.phase, self.health, self.mode, self.fault, valid]);
        w.put(&self.flags.to_be_bytes());
        w.put(&self.events_dropped.to_be_bytes());
        out
    }

    /// The housekeeping of TM\[3,25\] source data (`None`: not [`HOUSEKEEPING_LEN`] bytes of
    /// structure [`HOUSEKEEPING_SID`]).
    pub fn from_bytes(data: &[u8]) -> Option<Self> {
        let mut r = Reader { data, at: 0 };
        if data.len() != HOUSEKEEPING_LEN || r.u16()? != HOUSEKEEPING_SID {
            return None;
        }
        let tick = r.u32()?;
        let mut f = [0f32; 12];
        for x in &mut f {
            *x = f32::from_bits(r.u32()?);
        }
        let [phase, health, mode, fault, valid] = [r.u8()?, r.u8()?, r.u8()?, r.u8()?, r.u8()?];
        let [length_estimate_m, rate_cmd_mps, accel_cmd_mps2, law_rate_mps, blend_weight, alpha_ref_rad, delta_rad, delta_rate_radps, alpha, alpha_rate, tension, equilibrium_margin] =
            f;
        let when = |bit: u8, x: f32| (valid & bit != 0).then_some(x);
        Some(Self {
            tick,
            length_estimate_m,
            rate_cmd_mps,
            accel_cmd_mps2,
            law_rate_mps,
            blend_weight,
            alpha_ref_rad,
            delta_rad,
            delta_rate_radps,
            alpha_rad: when(VALID_ALPHA, alpha),
            alpha_rate_radps: when(VALID_ALPHA_RATE, alpha_rate),
            tension_n: when(VALID_TENSION, tension),
            equilibrium_margin,
            phase,
            health,
            mode,
            fault,
            flags: r.u32()?,
            events_dropped: r.u32()?,
        })
    }
}

/// Writes bytes in order into a buffer sized for them.
struct Writer<'a> {
    out: &'a mut [u8],
    at: usize,
}

impl Writer<'_> {
    fn put(&mut self, bytes: &[u8]) {
        if let Some(dst) = self.out.get_mut(self.at..self.at + bytes.len()) {
            dst.copy_from_slice(bytes);
        }
        self.at += bytes.len();
    }
}

/// Reads big-endian integers in order.
struct Reader<'a> {
    data: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let bytes = self.data.get(self.at..self.at + N)?;
        self.at += N;
        let mut out = [0u8; N];
        out.copy_from_slice(bytes);
        Some(out)
    }
    fn u8(&mut self) -> Option<u8> {
        self.take::<1>().map(|[b]| b)
    }
    fn u16(&mut self) -> Option<u16> {
        self.take().map(u16::from_be_bytes)
    }
    fn u32(&mut self) -> Option<u32> {
        self.take().map(u32::from_be_bytes)
    }
}

/// The wire code of a mode: 0 flying, 1 held, 2 aborted.
pub fn mode_code(m: Mode) -> u8 {
    match m {
        Mode::Flying => 0,
        Mode::Held { .. } => 1,
        Mode::Aborted => 2,
    }
}

/// The severity of an event report: its service 5 subtype.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Severity {
    /// TM\[5,1\] informative.
    Informative = 1,
    /// TM\[5,2\] low severity anomaly.
    Low = 2,
    /// TM\[5,3\] medium severity anomaly.
    Medium = 3,
    /// TM\[5,4\] high severity anomaly.
    High = 4,
}

/// The TM\[5,x\] severity, event id and auxiliary data of a controller event
/// (docs/interface.md §3, event identifiers).
pub fn event_report(kind: EventKind) -> (Severity, u16, [u8; 4]) {
    use Severity::{High, Informative, Low, Medium};
    let one = |b: u8| [b, 0, 0, 0];
    match kind {
        EventKind::Health { from, to } => {
            let severity = match to {
                Health::Nominal => Informative,
                Health::Degraded => Low,
                Health::SafeHold => High,
            };
            (severity, 1, [health_code(from), health_code(to), 0, 0])
        }
        EventKind::Fault(f) => (Medium, 2, one(fault_code(Some(f)))),
        EventKind::Phase(p) => (Informative, 3, one(phase_code(p))),
        EventKind::BlendRestart => (Informative, 4, [0; 4]),
        EventKind::NoProgress(p) => (Low, 5, one(phase_code(p))),
        EventKind::EstimateRestarted => (Low, 6, [0; 4]),
        EventKind::EstimateLost => (Medium, 7, [0; 4]),
        EventKind::TensionLimited => (Low, 8, [0; 4]),
        EventKind::TensionLoop(m) => {
            let code = match m {
                TensionLoopMode::Waiting => 0,
                TensionLoopMode::Tracking => 1,
                TensionLoopMode::Coasting => 2,
                TensionLoopMode::Lost => 3,
            };
            let severity = if m == TensionLoopMode::Lost {
                Medium
            } else {
                Low
            };
            (severity, 9, one(code))
        }
        EventKind::Command(c) => (Informative, 10, one(c as u8)),
    }
}

/// What the unit sent, as the on-board computer reads it back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Telemetry {
    /// TM\[1,x\]: a verification report of `request` at `stage`; on failure its code and data.
    Verification {
        /// The telecommand it answers.
        request: RequestId,
        /// Acceptance, start or completion.
        stage: Stage,
        /// The failure code and its data (`None`: success).
        failure: Option<(u16, [u8; 4])>,
    },
    /// TM\[3,25\]: housekeeping.
    Housekeeping(Housekeeping),
    /// TM\[5,x\]: an event.
    Event {
        /// Its severity (the subtype).
        severity: Severity,
        /// Its identifier.
        id: u16,
        /// Its auxiliary data.
        aux: [u8; 4],
    },
}

/// A telemetry packet as read back: its on-board time and what it says.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TelemetryPacket {
    /// The on-board time of the packet (the time field), ticks.
    pub time: u32,
    /// Its sequence count.
    pub seq: u16,
    /// What it says.
    pub telemetry: Telemetry,
}

/// Reads one of the unit's telemetry packets (`None`: not one, or damaged).
pub fn read_telemetry(raw: &[u8]) -> Option<TelemetryPacket> {
    let tm = PusTmReader::new_checksum_no_table(raw, TIME_LEN).ok()?;
    if tm.apid().value() != APID {
        return None;
    }
    let mut stamp = [0u8; TIME_LEN];
    stamp.copy_from_slice(tm.timestamp());
    let data = tm.source_data();
    let mut r = Reader { data, at: 0 };
    let telemetry = match (tm.service_type_id(), tm.message_subtype_id()) {
        (1, subtype) => {
            let stage = match subtype {
                1 | 2 => Stage::Acceptance,
                3 | 4 => Stage::Start,
                7 | 8 => Stage::Completion,
                _ => return None,
            };
            let request = RequestId {
                packet_id: r.u16()?,
                sequence: r.u16()?,
            };
            let failure = if subtype % 2 == 0 {
                Some((r.u16()?, r.take::<4>()?))
            } else {
                None
            };
            Telemetry::Verification {
                request,
                stage,
                failure,
            }
        }
        (3, 25) => Telemetry::Housekeeping(Housekeeping::from_bytes(data)?),
        (5, subtype) => Telemetry::Event {
            severity: [
                Severity::Informative,
                Severity::Low,
                Severity::Medium,
                Severity::High,
            ]
            .into_iter()
            .find(|&s| s as u8 == subtype)?,
            id: r.u16()?,
            aux: r.take::<4>()?,
        },
        _ => return None,
    };
    Some(TelemetryPacket {
        time: u32::from_be_bytes(stamp),
        seq: tm.seq_count().value(),
        telemetry,
    })
}

/// The unit's services: its telemetry counter, the on-board time, the telecommands of this
/// period, and the mode command that waits for its boundary.
#[derive(Clone, Debug, Default)]
pub struct Services {
    /// The telemetry sequence count of the next packet (14 bits on the wire).
    tm_seq: u16,
    /// On-board time = controller tick + this (wrapping; TC\[9,128\]).
    time_offset: u32,
    /// Telecommands taken since the last step.
    tcs_this_period: u8,
    /// The mode command taken and not yet applied.
    awaiting: Option<RequestId>,
    /// The controller has stepped (a parameter table is loaded only before).
    started: bool,
    /// The last controller tick (the time of reports between steps).
    last_tick: u32,
}

/// Telemetry packets the unit sent, by kind (for the report of a run).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// TM\[1,x\] success reports.
    pub verified: u32,
    /// TM\[1,x\] failure reports.
    pub failed: u32,
    /// TM\[3,25\].
    pub housekeeping: u32,
    /// TM\[5,x\].
    pub events: u32,
}

impl Services {
    /// The services before the first telecommand: on-board time = the controller's tick.
    pub const fn new() -> Self {
        Self {
            tm_seq: 0,
            time_offset: 0,
            tcs_this_period: 0,
            awaiting: None,
            started: false,
            last_tick: 0,
        }
    }

    /// The on-board time of the controller tick `tick`.
    pub fn time_of(&self, tick: u32) -> u32 {
        tick.wrapping_add(self.time_offset)
    }

    /// A telecommand `raw` arrived between two steps: it is verified and, if it is legal,
    /// executed or handed to `ctl` for the next period boundary. Its reports go to `emit`.
    pub fn telecommand(
        &mut self,
        raw: &[u8],
        ctl: &mut Controller<f32>,
        emit: &mut dyn FnMut(&[u8]),
    ) {
        self.tcs_this_period = self.tcs_this_period.saturating_add(1);
        if self.tcs_this_period > MAX_TCS_PER_PERIOD {
            if let Some(id) = RequestId::of(raw) {
                self.report(id, Stage::Acceptance, Some(Failure::Flood), emit);
            }
            return;
        }
        let request = match decode(raw) {
            Ok(r) => r,
            Err(rejection) => {
                // Fewer than four bytes have no identity to report against.
                if let Some(id) = rejection.id {
                    let failure = Failure::Decode(rejection.reason);
                    self.report(id, Stage::Acceptance, Some(failure), emit);
                }
                return;
            }
        };
        let id = request.id;
        self.report(id, Stage::Acceptance, None, emit);
        let started = match request.command {
            Telecommand::Mode(m) => ctl.command(m).map_err(Failure::Mode).map(|()| {
                self.awaiting = Some(id);
                false
            }),
            Telecommand::SetTime(t) => {
                // The next period's tick is the last one plus one.
                let next = if self.started {
                    self.last_tick.wrapping_add(1)
                } else {
                    0
                };
                self.time_offset = t.wrapping_sub(next);
                Ok(true)
            }
            Telecommand::LoadParams(table) if !self.started => {
                load_table(&table, ctl).map(|()| true)
            }
            Telecommand::LoadParams(_) => Err(Failure::TooLate),
        };
        match started {
            Ok(done) => {
                self.report(id, Stage::Start, None, emit);
                if done {
                    self.report(id, Stage::Completion, None, emit);
                }
            }
            Err(failure) => self.report(id, Stage::Start, Some(failure), emit),
        }
    }

    /// After a step of `ctl` on `sample`: the completion of a mode command it applied, its
    /// events (TM\[5,x\]) and its housekeeping (TM\[3,25\]), to `emit`.
    pub fn after_step(
        &mut self,
        ctl: &mut Controller<f32>,
        sample: Option<&Input<f32>>,
        emit: &mut dyn FnMut(&[u8]),
    ) {
        self.report_events(ctl, emit);
        self.report_housekeeping(ctl, sample, emit);
    }

    /// The first half of [`Services::after_step`]: the completion of a mode command the step
    /// applied and the step's events. A caller that collects housekeeping at a longer interval
    /// than the period calls this each period and [`Services::report_housekeeping`] when due.
    pub fn report_events(&mut self, ctl: &mut Controller<f32>, emit: &mut dyn FnMut(&[u8])) {
        self.started = true;
        self.last_tick = ctl.output().tick;
        self.tcs_this_period = 0;
        while let Some(Event { kind, .. }) = ctl.pop_event() {
            if let (EventKind::Command(_), Some(id)) = (kind, self.awaiting) {
                self.awaiting = None;
                self.report(id, Stage::Completion, None, emit);
            }
            let (severity, id, aux) = event_report(kind);
            let mut data = [0u8; EVENT_LEN];
            data[..2].copy_from_slice(&id.to_be_bytes());
            data[2..].copy_from_slice(&aux);
            self.send(5, severity as u8, &data, emit);
        }
    }

    /// The second half of [`Services::after_step`]: the housekeeping of the last step of
    /// `ctl`, on `sample`.
    pub fn report_housekeeping(
        &mut self,
        ctl: &Controller<f32>,
        sample: Option<&Input<f32>>,
        emit: &mut dyn FnMut(&[u8]),
    ) {
        let hk = Housekeeping::of(ctl, sample).to_bytes();
        self.send(3, 25, &hk, emit);
    }

    /// Sends the TM\[1,x\] report of `id` at `stage`.
    fn report(
        &mut self,
        id: RequestId,
        stage: Stage,
        failure: Option<Failure>,
        emit: &mut dyn FnMut(&[u8]),
    ) {
        let mut out = [0u8; MAX_TM_LEN];
        let time = self.time_of(self.last_tick);
        if let Some(n) = verification_report(id, stage, failure, self.tm_seq, time, &mut out) {
            self.tm_seq = self.tm_seq.wrapping_add(1) & 0x3fff;
            emit(out.get(..n).unwrap_or(&[]));
        }
    }

    /// Sends TM\[`service`,`subtype`\] with `data`.
    fn send(&mut self, service: u8, subtype: u8, data: &[u8], emit: &mut dyn FnMut(&[u8])) {
        let mut out = [0u8; MAX_TM_LEN];
        let time = self.time_of(self.last_tick);
        if let Some(n) = telemetry_packet(service, subtype, self.tm_seq, time, data, &mut out) {
            self.tm_seq = self.tm_seq.wrapping_add(1) & 0x3fff;
            emit(out.get(..n).unwrap_or(&[]));
        }
    }
}

/// The parameter-table load: `table` judged by the core's validation (`Controller::new`)
/// and, accepted, the controller built from it replaces `ctl` whole; refused, nothing changes.
///
/// Not inlined into [`Services::telecommand`]: the controller it builds would otherwise be
/// reserved on the stack under every telecommand's reports (on the reel MCU, the frames that
/// send them over the link), not only under a table load.
#[inline(never)]
fn load_table(table: &ParamTable, ctl: &mut Controller<f32>) -> Result<(), Failure> {
    let cfg = table
        .to_config()
        .map_err(|e| Failure::TableShape(e.index()))?;
    match Controller::new(cfg) {
        Ok(new) => {
            *ctl = new;
            Ok(())
        }
        Err(e) => Err(Failure::TableRefused {
            word: param_index(&e).unwrap_or(NO_PARAM),
            rule: rule_code(e.rule),
        }),
    }
}

impl Counts {
    /// Counts the packet `raw` (one the unit sent).
    pub fn count(&mut self, raw: &[u8]) {
        match read_telemetry(raw).map(|p| p.telemetry) {
            Some(Telemetry::Verification { failure: None, .. }) => self.verified += 1,
            Some(Telemetry::Verification { .. }) => self.failed += 1,
            Some(Telemetry::Housekeeping(_)) => self.housekeeping += 1,
            Some(Telemetry::Event { .. }) => self.events += 1,
            None => {}
        }
    }
}
