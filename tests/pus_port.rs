//! The unit's PUS interface over a byte stream (`tss_reel::pus::port`), as the NUCLEO-G474RE
//! board runs it on its UART: byte streams in (frames split across reads, garbage between
//! frames, a corrupted frame, line errors, a flood), the telemetry out, and the unit's answers
//! the same as the host's unit gives (`tss-sim`'s `obc.rs`, `Services` called directly).

use std::collections::VecDeque;

use proptest::prelude::*;
use tss_reel::controller::{Config, Controller, ModeCommand, Output};
use tss_reel::hal::{control_cycle, BytePort, Devices, ErrorKind, ErrorType, ReelDrive};
use tss_reel::link::{self, End, FrameReader, Message, Packet, DELIMITER};
use tss_reel::pus::port::{
    PacketPort, PortCounters, LINE_RATE_BAUD, MAX_FLOOD_REPORTS, TC_QUEUE, TX_QUEUE_BYTES,
};
use tss_reel::pus::{
    self, read_telemetry, RequestId, Services, Stage, Telecommand, Telemetry, TelemetryPacket,
    EVENT_LEN, MAX_REPORT_LEN, MAX_TC_LEN, MAX_TM_LEN, TM_OVERHEAD_LEN,
};
use tss_reel::recordings::replay::PERIOD_S;
use tss_reel::recordings::sensors::Replay;
use tss_reel::reel_drive::DriveFaults;

/// The line as the board's interrupt leaves it: received bytes (or a line error in their
/// place), and the transmit queue with its room.
struct Wire {
    rx: VecDeque<Result<u8, ErrorKind>>,
    tx: Vec<u8>,
    tx_room: usize,
}

impl Wire {
    fn new() -> Self {
        Self {
            rx: VecDeque::new(),
            tx: Vec::new(),
            tx_room: usize::MAX,
        }
    }

    fn put(&mut self, bytes: &[u8]) {
        self.rx.extend(bytes.iter().map(|&b| Ok(b)));
    }
}

impl ErrorType for Wire {
    type Error = ErrorKind;
}

impl BytePort for Wire {
    fn read_byte(&mut self) -> Result<Option<u8>, ErrorKind> {
        self.rx.pop_front().transpose()
    }

    fn send(&mut self, bytes: &[u8]) -> Result<(), ErrorKind> {
        if self.tx_room - self.tx.len() < bytes.len() {
            return Err(ErrorKind::Full);
        }
        self.tx.extend_from_slice(bytes);
        Ok(())
    }
}

/// The board's outer loop without the board: the flight controller on the replayed mission,
/// its services, the port.
struct Unit {
    controller: Controller<f32>,
    services: Services,
    port: PacketPort,
    devices: Devices<Replay, Replay, Replay, Latch, Replay>,
    period: u32,
}

struct Latch;

impl ErrorType for Latch {
    type Error = ErrorKind;
}

impl ReelDrive for Latch {
    fn command(&mut self, _: &Output<f32>) -> Result<(), ErrorKind> {
        Ok(())
    }
}

impl Unit {
    fn new() -> Self {
        Self {
            controller: Controller::new(Config::flight()).unwrap(),
            services: Services::new(),
            port: PacketPort::new(),
            devices: Devices {
                length: Replay,
                swing: Replay,
                orbit: Replay,
                reel: Latch,
                tension: Replay,
            },
            period: 0,
        }
    }

    /// One law period as the board's `Outer::control` runs it.
    fn period(&mut self, wire: &mut Wire) {
        self.port.receive(wire);
        self.port
            .deliver(wire, &mut self.services, &mut self.controller);
        let cycle = control_cycle(
            &mut self.controller,
            self.period,
            &mut self.devices,
            DriveFaults::NONE,
        );
        self.port.report(
            wire,
            &mut self.services,
            &mut self.controller,
            cycle.input.as_ref(),
        );
        self.period += 1;
    }
}

/// A telecommand's packet.
fn tc(command: Telecommand, seq: u16) -> Vec<u8> {
    let mut buf = [0u8; MAX_TC_LEN];
    let n = pus::encode(&command, seq, &mut buf).unwrap();
    buf[..n].to_vec()
}

/// `packet` in a `Packet` frame, as it goes on the wire.
fn frame(seq: u32, packet: &[u8]) -> Vec<u8> {
    message_frame(seq, &Message::Packet(Packet::new(packet).unwrap()))
}

fn message_frame(seq: u32, message: &Message) -> Vec<u8> {
    let mut buf = [0u8; link::MAX_WIRE_LEN];
    let n = link::encode(seq, message, &mut buf).unwrap();
    buf[..n].to_vec()
}

/// The packets of the frames the port sent (every byte must belong to a valid `Packet` frame).
fn sent_packets(tx: &[u8]) -> Vec<Vec<u8>> {
    let mut reader = FrameReader::new();
    let mut packets = Vec::new();
    for &b in tx {
        if let Some(frame) = reader.push(b) {
            match frame.expect("the port sends valid frames only").message {
                Message::Packet(p) => packets.push(p.bytes().to_vec()),
                other => panic!("the port sent a {other:?}"),
            }
        }
    }
    assert!(!reader.in_frame(), "the port sent part of a frame");
    packets
}

fn telemetry(tx: &[u8]) -> Vec<TelemetryPacket> {
    sent_packets(tx)
        .iter()
        .map(|p| read_telemetry(p).expect("the unit's telemetry reads back"))
        .collect()
}

/// The verification reports in `tm`: (request sequence count, stage, failure code).
fn verifications(tm: &[TelemetryPacket]) -> Vec<(u16, Stage, Option<u16>)> {
    tm.iter()
        .filter_map(|p| match p.telemetry {
            Telemetry::Verification {
                request,
                stage,
                failure,
            } => Some((request.sequence & 0x3fff, stage, failure.map(|f| f.0))),
            _ => None,
        })
        .collect()
}

fn housekeeping_count(tm: &[TelemetryPacket]) -> usize {
    tm.iter()
        .filter(|p| matches!(p.telemetry, Telemetry::Housekeeping(_)))
        .count()
}

/// A frame's bytes fed one read at a time wait in the port whole, are handed over at the
/// boundary (acceptance, start), and the step that applies the hold completes it; the
/// housekeeping of every period follows, the last one held.
#[test]
fn a_telecommand_split_across_reads_is_verified_at_the_boundary() {
    let mut unit = Unit::new();
    let mut wire = Wire::new();
    for _ in 0..3 {
        unit.period(&mut wire);
    }
    let before = telemetry(&wire.tx).len();
    assert_eq!(housekeeping_count(&telemetry(&wire.tx)), 3);
    wire.tx.clear();

    let bytes = frame(0, &tc(Telecommand::Mode(ModeCommand::Hold), 7));
    for (i, &b) in bytes.iter().enumerate() {
        wire.put(&[b]);
        unit.port.receive(&mut wire);
        let whole = i + 1 == bytes.len();
        assert_eq!(unit.port.waiting(), usize::from(whole), "after byte {i}");
    }
    unit.period(&mut wire);
    let tm = telemetry(&wire.tx);
    assert_eq!(
        verifications(&tm),
        [
            (7, Stage::Acceptance, None),
            (7, Stage::Start, None),
            (7, Stage::Completion, None)
        ]
    );
    match tm.last().map(|p| p.telemetry) {
        Some(Telemetry::Housekeeping(h)) => assert_eq!(h.mode, 1, "held"),
        other => panic!("the period ends with its housekeeping, not {other:?}"),
    }
    let c = unit.port.counters();
    assert_eq!((c.telecommands, c.bytes_in), (1, bytes.len() as u32));
    assert_eq!(c.losses(), 0);
    assert_eq!(c.telemetry_sent as usize, before + tm.len());
}

/// Garbage between frames (anything up to a delimiter) is one rejected frame each; the frames
/// after it are taken. A leading run of delimiters is idle line.
#[test]
fn garbage_between_frames_is_skipped_and_counted() {
    let mut unit = Unit::new();
    let mut wire = Wire::new();
    wire.put(&[DELIMITER; 3]);
    wire.put(&[0x17, 0xff, 0x42, DELIMITER]);
    wire.put(&frame(0, &tc(Telecommand::SetTime(1_000), 1)));
    wire.put(&[0x01, DELIMITER]);
    wire.put(&[0xa5; 40]);
    wire.put(&[DELIMITER]);
    wire.put(&frame(1, &tc(Telecommand::SetTime(2_000), 2)));
    unit.period(&mut wire);
    let seqs: Vec<u16> = verifications(&telemetry(&wire.tx))
        .iter()
        .filter(|v| v.1 == Stage::Acceptance)
        .map(|v| v.0)
        .collect();
    assert_eq!(seqs, [1, 2]);
    let c = unit.port.counters();
    assert_eq!((c.telecommands, c.bad_frames), (2, 3));
    assert!(c.last_rejection.is_some());
}

/// A frame with a changed byte fails the link's checks and is dropped (counted, with why); the
/// telecommand in it gets no report, as it never arrived; the next frame is taken.
#[test]
fn a_corrupted_frame_is_dropped_and_the_next_one_taken() {
    let mut unit = Unit::new();
    let mut wire = Wire::new();
    let mut bad = frame(0, &tc(Telecommand::Mode(ModeCommand::Hold), 1));
    bad[10] = if bad[10] == 0x5a { 0x5b } else { 0x5a };
    wire.put(&bad);
    wire.put(&frame(1, &tc(Telecommand::SetTime(5), 2)));
    unit.period(&mut wire);
    let acc: Vec<_> = verifications(&telemetry(&wire.tx))
        .into_iter()
        .filter(|v| v.1 == Stage::Acceptance)
        .collect();
    assert_eq!(acc, [(2, Stage::Acceptance, None)]);
    let c = unit.port.counters();
    assert_eq!((c.telecommands, c.bad_frames), (1, 1));
    assert!(c.last_rejection.is_some());
}

/// A packet the link carries whole but whose PUS checksum is wrong reaches the services and is
/// answered with its failure report (code 3), as on the spacecraft's bus.
#[test]
fn a_damaged_telecommand_in_a_good_frame_gets_its_failure_report() {
    let mut unit = Unit::new();
    let mut wire = Wire::new();
    let mut packet = tc(Telecommand::Mode(ModeCommand::Hold), 9);
    let n = packet.len();
    packet[n - 1] ^= 0x10;
    wire.put(&frame(0, &packet));
    unit.period(&mut wire);
    assert_eq!(
        verifications(&telemetry(&wire.tx)),
        [(9, Stage::Acceptance, Some(3))]
    );
}

/// A line error inside a frame drops the frame even when the bytes that did arrive make a valid
/// one (here no byte is lost around the error, so the CRC alone would pass it); an error on an
/// idle line before a delimiter costs nothing.
#[test]
fn a_line_error_drops_the_frame_it_falls_in() {
    for error in [ErrorKind::Overrun, ErrorKind::Framing] {
        let mut unit = Unit::new();
        let mut wire = Wire::new();
        let first = frame(0, &tc(Telecommand::SetTime(10), 1));
        wire.put(&first[..5]);
        wire.rx.push_back(Err(error));
        wire.put(&first[5..]);
        wire.rx.push_back(Err(error));
        wire.put(&[DELIMITER]);
        wire.put(&frame(1, &tc(Telecommand::SetTime(20), 2)));
        unit.period(&mut wire);
        let acc: Vec<_> = verifications(&telemetry(&wire.tx))
            .into_iter()
            .filter(|v| v.1 == Stage::Acceptance)
            .map(|v| v.0)
            .collect();
        assert_eq!(acc, [2], "{error:?}");
        let c = unit.port.counters();
        assert_eq!(c.damaged_frames, 1, "{error:?}");
        assert_eq!(c.bad_frames, 0, "{error:?}");
        let errors = match error {
            ErrorKind::Overrun => c.overruns,
            _ => c.framing_errors,
        };
        assert_eq!(errors, 2, "{error:?}");
        assert_eq!(c.telecommands, 1, "{error:?}");
    }
}

/// More telecommands in a period than the services take: the first [`TC_QUEUE`] are executed,
/// the next [`MAX_FLOOD_REPORTS`] each get a flood failure report (code 18) naming them, the
/// rest are counted; the next period takes telecommands again.
#[test]
fn a_flood_gets_its_reports_and_the_rest_is_counted() {
    let mut unit = Unit::new();
    let mut wire = Wire::new();
    let extra = 5;
    let n = TC_QUEUE + MAX_FLOOD_REPORTS + extra;
    for seq in 0..n as u16 {
        wire.put(&frame(
            u32::from(seq),
            &tc(Telecommand::SetTime(u32::from(seq)), seq),
        ));
    }
    unit.period(&mut wire);
    let v = verifications(&telemetry(&wire.tx));
    let executed: Vec<u16> = v
        .iter()
        .filter(|r| r.1 == Stage::Completion)
        .map(|r| r.0)
        .collect();
    let flooded: Vec<u16> = v.iter().filter(|r| r.2 == Some(18)).map(|r| r.0).collect();
    assert_eq!(executed, (0..TC_QUEUE as u16).collect::<Vec<_>>());
    assert_eq!(
        flooded,
        (TC_QUEUE as u16..(TC_QUEUE + MAX_FLOOD_REPORTS) as u16).collect::<Vec<_>>()
    );
    let c = unit.port.counters();
    assert_eq!(c.telecommands as usize, n);
    assert_eq!(c.floods_unreported as usize, extra);
    assert_eq!(unit.port.waiting(), 0);

    wire.tx.clear();
    wire.put(&frame(99, &tc(Telecommand::SetTime(0), 100)));
    unit.period(&mut wire);
    assert_eq!(
        verifications(&telemetry(&wire.tx)),
        [
            (100, Stage::Acceptance, None),
            (100, Stage::Start, None),
            (100, Stage::Completion, None)
        ]
    );
}

/// A valid frame of another kind (the PIL's `End`) is not a telecommand: counted, ignored.
#[test]
fn a_frame_of_another_kind_is_counted_and_ignored() {
    let mut unit = Unit::new();
    let mut wire = Wire::new();
    wire.put(&message_frame(0, &Message::End(End { ticks: 3 })));
    unit.period(&mut wire);
    let c = unit.port.counters();
    assert_eq!((c.wrong_kind, c.telecommands), (1, 0));
    assert!(verifications(&telemetry(&wire.tx)).is_empty());
}

/// With the transmit queue short of room, telemetry is dropped whole frames at a time and
/// counted: what is sent is whole frames only, and sent + dropped is everything the unit said.
#[test]
fn telemetry_is_dropped_whole_and_counted_when_the_queue_is_full() {
    let mut said = 0;
    for tx_room in [usize::MAX, 150] {
        let mut unit = Unit::new();
        let mut wire = Wire::new();
        wire.tx_room = tx_room;
        for seq in 0..4 {
            wire.put(&frame(u32::from(seq), &tc(Telecommand::SetTime(7), seq)));
        }
        unit.period(&mut wire);
        let sent = sent_packets(&wire.tx).len();
        let c = unit.port.counters();
        assert_eq!(c.telemetry_sent as usize, sent);
        assert_eq!(c.losses(), c.telemetry_dropped);
        if tx_room == usize::MAX {
            // Twelve reports (three per time telecommand), the events, the housekeeping.
            assert!(sent > 4 * 3);
            assert_eq!(c.telemetry_dropped, 0);
            said = sent;
        } else {
            assert!(c.telemetry_dropped > 0);
            assert_eq!((c.telemetry_sent + c.telemetry_dropped) as usize, said);
        }
    }
}

/// Bytes on the wire of a telemetry packet of `len` bytes, framed.
fn framed_len(len: usize) -> usize {
    frame(0, &vec![0x55; len]).len()
}

/// The worst period's telemetry, bounded from the packets' longest forms: every telecommand a
/// period takes answered three times (acceptance, start, completion) with the longest report,
/// a mode command's completion after the step, every flood report, a full event queue
/// (`EVENT_CAPACITY`), the housekeeping. It fits the transmit queue, and the line carries it in
/// under a quarter of the law's period. A flooded period run for real stays inside the bound.
#[test]
fn the_worst_period_fits_the_transmit_queue_and_the_line() {
    let report = framed_len(MAX_REPORT_LEN);
    let event = framed_len(TM_OVERHEAD_LEN + EVENT_LEN);
    let housekeeping = framed_len(MAX_TM_LEN);
    let events = tss_reel::controller::EVENT_CAPACITY;
    let worst = (3 * TC_QUEUE + 1 + MAX_FLOOD_REPORTS) * report + events * event + housekeeping;
    let line_bytes_per_s = f64::from(LINE_RATE_BAUD) / 10.0;
    let line_s = worst as f64 / line_bytes_per_s;
    eprintln!(
        "worst period's telemetry: {worst} B on the wire ({} reports of {report} B, {events} \
         events of {event} B, housekeeping {housekeeping} B): transmit queue {TX_QUEUE_BYTES} B, \
         {:.0} ms of the line at {LINE_RATE_BAUD} Bd",
        3 * TC_QUEUE + 1 + MAX_FLOOD_REPORTS,
        line_s * 1e3
    );
    assert!(worst <= TX_QUEUE_BYTES);
    assert!(line_s < f64::from(PERIOD_S) / 4.0);

    let mut unit = Unit::new();
    let mut wire = Wire::new();
    wire.tx_room = TX_QUEUE_BYTES;
    unit.period(&mut wire);
    let mut seq = 0;
    for command in [ModeCommand::Hold, ModeCommand::Resume] {
        wire.tx.clear();
        wire.put(&frame(seq, &tc(Telecommand::Mode(command), seq as u16)));
        for k in 1..(TC_QUEUE + MAX_FLOOD_REPORTS + 3) as u32 {
            wire.put(&frame(
                seq + k,
                &tc(Telecommand::SetTime(k), (seq + k) as u16),
            ));
        }
        seq += 100;
        unit.period(&mut wire);
        assert!(wire.tx.len() <= worst, "{} B", wire.tx.len());
        let mode_seq = (seq - 100) as u16;
        assert!(verifications(&telemetry(&wire.tx)).contains(&(mode_seq, Stage::Completion, None)));
    }
    assert_eq!(unit.port.counters().telemetry_dropped, 0);
}

/// What arrives in one period: telecommands and how they come.
#[derive(Clone, Debug)]
enum Piece {
    /// A telecommand in a frame.
    Tc(Telecommand),
    /// Arbitrary packet bytes in a valid frame (the services judge them).
    Raw(Vec<u8>),
    /// Arbitrary bytes without a delimiter, then one.
    Junk(Vec<u8>),
    /// A telecommand in a frame with a line error inside.
    Damaged(Telecommand, usize, bool),
}

fn telecommand() -> impl Strategy<Value = Telecommand> {
    prop_oneof![
        (1u16..=5).prop_map(|i| Telecommand::Mode(ModeCommand::from_id(i).unwrap())),
        any::<u32>().prop_map(Telecommand::SetTime),
    ]
}

fn piece() -> impl Strategy<Value = Piece> {
    prop_oneof![
        4 => telecommand().prop_map(Piece::Tc),
        1 => proptest::collection::vec(any::<u8>(), 1..40).prop_map(Piece::Raw),
        1 => proptest::collection::vec(1u8..=255, 0..80).prop_map(Piece::Junk),
        1 => (telecommand(), any::<usize>(), any::<bool>())
            .prop_map(|(c, at, overrun)| Piece::Damaged(c, at, overrun)),
    ]
}

/// The pieces of several periods, put on the wire with `chunk` bytes per read.
fn stream() -> impl Strategy<Value = (Vec<Vec<Piece>>, usize)> {
    (
        proptest::collection::vec(proptest::collection::vec(piece(), 0..20), 1..6),
        1usize..64,
    )
}

/// The same periods through the port and straight to the services (the host's unit): the
/// same telemetry, byte for byte; every telecommand that arrived whole is answered once at
/// acceptance or counted; every damaged frame counted.
fn run_both(periods: &[Vec<Piece>], chunk: usize) -> Result<(), TestCaseError> {
    let mut unit = Unit::new();
    let mut wire = Wire::new();
    let mut direct = Unit::new();
    let mut direct_tm: Vec<Vec<u8>> = Vec::new();
    let (mut seq, mut frame_seq) = (0u16, 0u32);
    let (mut whole, mut damaged, mut junk) = (0u32, 0u32, 0u32);
    for pieces in periods {
        let mut bytes = Vec::new();
        // What the port hands the services in a period: a period's worth whole, then the
        // identified ones for their flood reports.
        let (mut taken, mut flood_reports) = (0, 0);
        for p in pieces {
            seq = (seq + 1) & 0x3fff;
            frame_seq += 1;
            let packet = match p {
                Piece::Tc(c) => tc(*c, seq),
                Piece::Raw(raw) => raw.clone(),
                Piece::Junk(j) => {
                    junk += u32::from(!j.is_empty());
                    bytes.extend(j.iter().map(|&b| Ok(b)));
                    bytes.push(Ok(DELIMITER));
                    continue;
                }
                Piece::Damaged(c, at, overrun) => {
                    damaged += 1;
                    let f = frame(frame_seq, &tc(*c, seq));
                    let at = at % f.len();
                    bytes.extend(f[..at].iter().map(|&b| Ok(b)));
                    bytes.push(Err(if *overrun {
                        ErrorKind::Overrun
                    } else {
                        ErrorKind::Framing
                    }));
                    bytes.extend(f[at..].iter().map(|&b| Ok(b)));
                    continue;
                }
            };
            whole += 1;
            bytes.extend(frame(frame_seq, &packet).into_iter().map(Ok));
            if taken < TC_QUEUE {
                taken += 1;
            } else if RequestId::of(&packet).is_some() && flood_reports < MAX_FLOOD_REPORTS {
                flood_reports += 1;
            } else {
                continue;
            }
            direct
                .services
                .telecommand(&packet, &mut direct.controller, &mut |p| {
                    direct_tm.push(p.to_vec())
                });
        }
        for part in bytes.chunks(chunk) {
            wire.rx.extend(part.iter().copied());
            unit.port.receive(&mut wire);
        }
        unit.period(&mut wire);
        let cycle = control_cycle(
            &mut direct.controller,
            direct.period,
            &mut direct.devices,
            DriveFaults::NONE,
        );
        direct
            .services
            .after_step(&mut direct.controller, cycle.input.as_ref(), &mut |p| {
                direct_tm.push(p.to_vec())
            });
        direct.period += 1;
    }
    prop_assert_eq!(sent_packets(&wire.tx), direct_tm);
    let c: PortCounters = unit.port.counters();
    prop_assert_eq!(c.telecommands, whole);
    prop_assert_eq!(c.damaged_frames, damaged);
    prop_assert_eq!(c.bad_frames, junk);
    let acceptance = verifications(&telemetry(&wire.tx))
        .iter()
        .filter(|v| v.1 == Stage::Acceptance)
        .count() as u32;
    prop_assert_eq!(acceptance + c.floods_unreported + c.unidentified, whole);
    prop_assert_eq!(c.telemetry_dropped, 0);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, failure_persistence: None, ..ProptestConfig::default() })]

    /// Any mix of telecommands, arbitrary packets, junk and line errors, read in any chunks:
    /// no panic, the host unit's answers, nothing lost without a report or a count.
    #[test]
    fn any_stream_is_answered_as_the_host_unit_answers(
        (periods, chunk) in stream()
    ) {
        run_both(&periods, chunk)?;
    }
}
