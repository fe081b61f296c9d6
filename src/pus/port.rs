//! The unit's PUS interface over a byte stream: the on-board computer's bytes in, frames
//! reassembled, telecommands handed to [`Services`] at the period boundary, and the telemetry
//! framed and sent back. The framing is the processor-in-the-loop link's (`crate::link`):
//! each space packet is the body of one `Packet` frame (COBS, a `0x00` delimiter, a CRC-32).
//!
//! Board-independent: the bytes come and go through a [`BytePort`] (a UART and its queues on
//! the board, a byte vector in the host tests `tests/pus_port.rs`), and the caller says when a
//! period ends. A period, as the host's unit runs it (`tss-sim`'s `obc.rs`):
//!
//! ```text
//!   any time        receive(): bytes → FrameReader → Packet frames → up to
//!                   MAX_TCS_PER_PERIOD telecommands kept whole, the identities of the
//!                   next MAX_FLOOD_REPORTS kept for their flood reports, the rest counted
//!   period boundary deliver(): the telecommands to Services (TM[1,x] back), then the step
//!   after the step  report():  TM[1,7] of an applied mode, TM[5,x] per event, TM[3,25]
//! ```
//!
//! Nothing is lost without a count: line errors ([`ErrorKind::Overrun`], [`ErrorKind::Framing`])
//! and the frames they fall in (dropped whatever their CRC says: a frame is only as good as
//! every byte of it), frames the link rejects (COBS, CRC), frames of another kind, telecommands
//! beyond the flood reports, telemetry that found the transmit queue full ([`PortCounters`]).
//! Telemetry goes out a whole frame or not at all ([`BytePort::send`]). The frame's sequence
//! number is not checked: a telecommand's identity, in its verification reports, is its
//! packet's sequence count.

use heapless::{Deque, Vec};

use crate::controller::{Controller, Input};
use crate::hal::{BytePort, Error, ErrorKind};
use crate::link::{self, FrameReader, LinkError, Message, Packet, DELIMITER, MAX_WIRE_LEN};

use super::{RequestId, Services, MAX_TCS_PER_PERIOD};

/// Telecommands kept whole for the next boundary: as many as [`Services`] takes in a period.
pub const TC_QUEUE: usize = MAX_TCS_PER_PERIOD as usize;

/// Telecommands beyond [`TC_QUEUE`] in one period whose identity is kept, so that each gets
/// its flood failure report (TM\[1,2\], code 18); any beyond these are only counted
/// ([`PortCounters::floods_unreported`]). Eight reports are 344 bytes on the wire, so a flood
/// cannot fill the transmit queue with its own answers.
pub const MAX_FLOOD_REPORTS: usize = 8;

/// Most bytes one [`PacketPort::receive`] reads (a bounded loop): the longest frame on the
/// wire, four times over. What is left waits in the port for the next call.
pub const RECEIVE_BUDGET_BYTES: usize = 4 * MAX_WIRE_LEN;

/// The line rate a board runs the port at, bit/s (8N1: 10 bits a byte, 11 520 bytes/s): the
/// ST-LINK virtual COM port's usual rate. A worst period's telemetry (every telecommand a
/// period takes completed, every flood report, a full event queue, housekeeping) takes under
/// a quarter of the 1 s law period on it, so the line is idle most of the time even then:
/// `tests/pus_port.rs` measures it (`the_worst_period_fits_the_transmit_queue_and_the_line`).
pub const LINE_RATE_BAUD: u32 = 115_200;

/// The transmit queue a board gives the port, bytes: a worst period's telemetry, with room
/// (the same test).
pub const TX_QUEUE_BYTES: usize = 2048;

/// The receive queue a board gives the port, bytes (or line errors in their place): what the
/// line brings in 89 ms at [`LINE_RATE_BAUD`], for the time the main loop spends in a period's
/// work without calling [`PacketPort::receive`] (the telecommands' checks, the controller step,
/// the telemetry's framing).
pub const RX_QUEUE_BYTES: usize = 1024;

/// What the port has seen and done since start (saturating counts).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PortCounters {
    /// Bytes received.
    pub bytes_in: u32,
    /// Line errors: bytes lost ([`ErrorKind::Overrun`]).
    pub overruns: u32,
    /// Line errors: bytes damaged ([`ErrorKind::Framing`]).
    pub framing_errors: u32,
    /// Any other error the port reported on receive.
    pub port_errors: u32,
    /// Frames that held a line error (or followed one before their first byte): dropped.
    pub damaged_frames: u32,
    /// Frames the link rejected (COBS, CRC, version, kind, length, overflow): each a frame
    /// lost, whatever it carried.
    pub bad_frames: u32,
    /// The last of those rejections.
    pub last_rejection: Option<LinkError>,
    /// Valid frames of a kind other than `Packet` (ignored).
    pub wrong_kind: u32,
    /// Telecommands received (valid `Packet` frames).
    pub telecommands: u32,
    /// Telecommands beyond [`TC_QUEUE`] + [`MAX_FLOOD_REPORTS`] in one period: refused
    /// without a report.
    pub floods_unreported: u32,
    /// Telecommands shorter than their identity (4 bytes): handed over, but no report can
    /// name them.
    pub unidentified: u32,
    /// Telemetry packets queued for sending.
    pub telemetry_sent: u32,
    /// Telemetry packets dropped: the transmit queue had no room for the whole frame.
    pub telemetry_dropped: u32,
}

/// The link's side of the unit: the frame being reassembled, the telecommands waiting for the
/// boundary, the telemetry's frame counter, the counts.
#[derive(Clone, Debug)]
pub struct PacketPort {
    reader: FrameReader,
    /// A line error came since the last delimiter: the frame that delimiter closes is damaged.
    line_error_in_frame: bool,
    /// Telecommands received since the last boundary, in order of arrival.
    received: Deque<Packet, TC_QUEUE>,
    /// The identities of the telecommands beyond those, in order of arrival.
    flooded: Vec<RequestId, MAX_FLOOD_REPORTS>,
    sender: Sender,
    counters: PortCounters,
}

/// Frames the telemetry and queues it on the port.
#[derive(Clone, Debug)]
struct Sender {
    /// Sequence number of the next frame.
    seq: u32,
    sent: u32,
    dropped: u32,
}

impl Default for PacketPort {
    fn default() -> Self {
        Self::new()
    }
}

impl PortCounters {
    /// Everything lost or refused without a report so far: line errors, rejected frames,
    /// frames of another kind, unreported floods and unidentified telecommands, dropped
    /// telemetry (a sum that grows whenever one of them does).
    pub fn losses(&self) -> u32 {
        [
            self.overruns,
            self.framing_errors,
            self.port_errors,
            self.damaged_frames,
            self.bad_frames,
            self.wrong_kind,
            self.floods_unreported,
            self.unidentified,
            self.telemetry_dropped,
        ]
        .iter()
        .fold(0, |sum, &n| sum.saturating_add(n))
    }
}

impl PacketPort {
    /// A port that has received nothing.
    pub const fn new() -> Self {
        Self {
            reader: FrameReader::new(),
            line_error_in_frame: false,
            received: Deque::new(),
            flooded: Vec::new(),
            sender: Sender {
                seq: 0,
                sent: 0,
                dropped: 0,
            },
            counters: PortCounters {
                bytes_in: 0,
                overruns: 0,
                framing_errors: 0,
                port_errors: 0,
                damaged_frames: 0,
                bad_frames: 0,
                last_rejection: None,
                wrong_kind: 0,
                telecommands: 0,
                floods_unreported: 0,
                unidentified: 0,
                telemetry_sent: 0,
                telemetry_dropped: 0,
            },
        }
    }

    /// The counts so far.
    pub fn counters(&self) -> PortCounters {
        PortCounters {
            telemetry_sent: self.sender.sent,
            telemetry_dropped: self.sender.dropped,
            ..self.counters
        }
    }

    /// Telecommands waiting for the next boundary (whole, and for a flood report).
    pub fn waiting(&self) -> usize {
        self.received.len() + self.flooded.len()
    }

    /// Reads what `port` has received, at most [`RECEIVE_BUDGET_BYTES`], and keeps the
    /// telecommands of the frames it completes for the next [`PacketPort::deliver`].
    pub fn receive<P: BytePort>(&mut self, port: &mut P) {
        for _ in 0..RECEIVE_BUDGET_BYTES {
            let byte = match port.read_byte() {
                Ok(Some(b)) => b,
                Ok(None) => return,
                Err(e) => {
                    let c = &mut self.counters;
                    let count = match e.kind() {
                        ErrorKind::Overrun => &mut c.overruns,
                        ErrorKind::Framing => &mut c.framing_errors,
                        _ => &mut c.port_errors,
                    };
                    *count = count.saturating_add(1);
                    self.line_error_in_frame = true;
                    continue;
                }
            };
            self.counters.bytes_in = self.counters.bytes_in.saturating_add(1);
            let closed = self.reader.push(byte);
            let damaged = byte == DELIMITER && core::mem::take(&mut self.line_error_in_frame);
            let c = &mut self.counters;
            match closed {
                None => {}
                Some(_) if damaged => c.damaged_frames = c.damaged_frames.saturating_add(1),
                Some(Ok(frame)) => match frame.message {
                    Message::Packet(packet) => self.keep(packet),
                    _ => c.wrong_kind = c.wrong_kind.saturating_add(1),
                },
                Some(Err(e)) => {
                    c.bad_frames = c.bad_frames.saturating_add(1);
                    c.last_rejection = Some(e);
                }
            }
        }
    }

    /// Keeps one received telecommand: whole while [`Services`] will take it this period,
    /// then its identity for a flood report, then only a count.
    fn keep(&mut self, packet: Packet) {
        let c = &mut self.counters;
        c.telecommands = c.telecommands.saturating_add(1);
        if RequestId::of(packet.bytes()).is_none() {
            c.unidentified = c.unidentified.saturating_add(1);
        }
        let Err(packet) = self.received.push_back(packet) else {
            return;
        };
        if let Some(id) = RequestId::of(packet.bytes()) {
            if self.flooded.push(id).is_err() {
                c.floods_unreported = c.floods_unreported.saturating_add(1);
            }
        }
    }

    /// At the period boundary, before the step: the telecommands received since the last one,
    /// in order, to `services` (and through it to `ctl`), their verification reports to
    /// `port`. Those beyond what a period takes get their flood report.
    pub fn deliver<P: BytePort>(
        &mut self,
        port: &mut P,
        services: &mut Services,
        ctl: &mut Controller<f32>,
    ) {
        let sender = &mut self.sender;
        let mut emit = |packet: &[u8]| sender.send(port, packet);
        while let Some(tc) = self.received.pop_front() {
            services.telecommand(tc.bytes(), ctl, &mut emit);
        }
        // The queue above held a period's worth, so `Services` refuses these unread, by the
        // identity alone.
        for id in &self.flooded {
            let mut head = [0u8; 4];
            head[..2].copy_from_slice(&id.packet_id.to_be_bytes());
            head[2..].copy_from_slice(&id.sequence.to_be_bytes());
            services.telecommand(&head, ctl, &mut emit);
        }
        self.flooded.clear();
    }

    /// After the step of `ctl` on `sample`: the completion of a mode command it applied, its
    /// events and its housekeeping ([`Services::after_step`]), to `port`.
    pub fn report<P: BytePort>(
        &mut self,
        port: &mut P,
        services: &mut Services,
        ctl: &mut Controller<f32>,
        sample: Option<&Input<f32>>,
    ) {
        let sender = &mut self.sender;
        services.after_step(ctl, sample, &mut |packet| sender.send(port, packet));
    }
}

impl Sender {
    /// Frames one telemetry packet and queues it whole, or counts it dropped.
    fn send<P: BytePort>(&mut self, port: &mut P, packet: &[u8]) {
        let mut wire = [0u8; MAX_WIRE_LEN];
        let queued = Packet::new(packet)
            .and_then(|p| link::encode(self.seq, &Message::Packet(p), &mut wire).ok())
            .and_then(|n| wire.get(..n))
            .is_some_and(|frame| port.send(frame).is_ok());
        if queued {
            self.seq = self.seq.wrapping_add(1);
            self.sent = self.sent.saturating_add(1);
        } else {
            self.dropped = self.dropped.saturating_add(1);
        }
    }
}
