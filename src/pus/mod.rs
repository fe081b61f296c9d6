//! The reel unit's telecommands as the on-board computer sends them: CCSDS Space Packets
//! (CCSDS 133.0-B-2) carrying PUS-C telecommands (ECSS-E-ST-70-41C), read with the
//! `spacepackets` crate, and the service 1 verification reports that answer each of them.
//!
//! `no_std`, no allocation, no panics: [`decode`] takes any bytes and returns either a typed
//! [`Request`] or a [`Rejection`] with its [`Reason`] (and the request's identity when the
//! packet header was readable, so that the failure report names the telecommand it answers).
//! The property test `tests/pus.rs` feeds it arbitrary and damaged packets.
//!
//! # Telecommands (APID [`APID`], PUS-C, with the packet error control CRC-16)
//!
//! ```text
//! TC\[8,1\]    perform a function        app data: function id u16 (ModeCommand), 2 bytes
//! TC\[9,128\]  set the on-board time     app data: mission tick u32, 4 bytes
//! TC\[20,128\] load the parameter table  app data: PARAM_WORDS words u32, then their CRC-32
//!                                      (ISO-HDLC) u32: 4 × 70 + 4 = 284 bytes
//! ```
//!
//! Integers are big-endian, as CCSDS and PUS fields are. A telecommand's checks, in order:
//! length (≥ the smallest PUS-C TC, ≤ [`MAX_TC_LEN`]; the packet's own length field equals
//! the bytes received), packet error control, packet type and secondary header, APID, PUS
//! version, service, subtype, application data length, then its content (a known function, the
//! table's CRC-32). What the content asks (a mode legal in the phase, a table the core accepts)
//! is for the unit to judge when it starts the request, not for the decoder.

use arbitrary_int::{u11, u14};
use spacepackets::ecss::tc::PusTcReader;
use spacepackets::ecss::{CreatorConfig, MessageTypeId, PusPacket, PusVersion};
use spacepackets::{CcsdsPacket, PacketType, SpHeader};

pub use crate::controller::ModeCommand;
use crate::controller::Refusal;
use crate::link::{ParamTable, MAX_PACKET_LEN, PARAM_WORDS};

pub mod port;
mod unit;

pub use unit::{
    event_report, mode_code, read_telemetry, Counts, Housekeeping, Services, Severity, Telemetry,
    TelemetryPacket, EVENT_LEN, HOUSEKEEPING_LEN, HOUSEKEEPING_SID, MAX_TCS_PER_PERIOD, MAX_TM_LEN,
};

/// The reel unit's application process identifier (its telecommands and its telemetry).
pub const APID: u16 = 0x0A5;

/// Length of a PUS-C telecommand without application data: primary header 6, secondary
/// header 5, packet error control 2 (ECSS-E-ST-70-41C §7.4.1, §7.4.3.1).
pub const TC_OVERHEAD_LEN: usize = 6 + 5 + 2;

/// Application data of the parameter-table load: the words and their CRC-32.
pub const TABLE_LOAD_LEN: usize = 4 * PARAM_WORDS + 4;

/// The longest telecommand the unit accepts (the parameter-table load).
pub const MAX_TC_LEN: usize = TC_OVERHEAD_LEN + TABLE_LOAD_LEN;

// Every packet the unit accepts or sends fits the link's `Packet` frame.
const _: () = assert!(MAX_TC_LEN <= MAX_PACKET_LEN && MAX_TM_LEN <= MAX_PACKET_LEN);

/// CRC-32/ISO-HDLC of the parameter table's words (as in the PIL link's frames).
const TABLE_CRC: crc::Crc<u32, crc::NoTable> =
    crc::Crc::<u32, crc::NoTable>::new(&crc::CRC_32_ISO_HDLC);

/// What a valid telecommand asks.
// The table is held inline: there is no heap to box it on, and one request is held at a time.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Telecommand {
    /// TC\[8,1\]: change the mission mode.
    Mode(ModeCommand),
    /// TC\[9,128\]: the mission tick of the next control period.
    SetTime(u32),
    /// TC\[20,128\]: fly this configuration from the next period boundary on (if the core
    /// accepts it; else nothing changes).
    LoadParams(ParamTable),
}

/// The identity of a telecommand, as the verification reports repeat it (ECSS-E-ST-70-41C
/// §5.4.11: the packet's version, type, secondary header flag and APID, then its sequence
/// flags and count, the first four bytes of its primary header).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RequestId {
    /// Packet version, type, secondary header flag, APID.
    pub packet_id: u16,
    /// Sequence flags and sequence count.
    pub sequence: u16,
}

impl RequestId {
    /// The identity of the packet whose first bytes are `raw` (`None` if fewer than four).
    pub fn of(raw: &[u8]) -> Option<Self> {
        match raw {
            [a, b, c, d, ..] => Some(Self {
                packet_id: u16::from_be_bytes([*a, *b]),
                sequence: u16::from_be_bytes([*c, *d]),
            }),
            _ => None,
        }
    }
}

/// A valid telecommand and its identity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Request {
    /// Its identity, for its verification reports.
    pub id: RequestId,
    /// What it asks.
    pub command: Telecommand,
}

/// Why the decoder rejected a telecommand: the failure code of its TM\[1,2\] report
/// (docs/interface.md, failure codes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reason {
    /// Shorter than a telecommand or than its length field says.
    Truncated = 1,
    /// Longer than [`MAX_TC_LEN`] or than its length field says.
    Oversized = 2,
    /// The packet error control (CRC-16) does not match.
    Checksum = 3,
    /// Not a telecommand with a PUS secondary header.
    NotTelecommand = 4,
    /// Another unit's APID.
    WrongApid = 5,
    /// Not PUS-C.
    PusVersion = 6,
    /// A service the unit does not provide.
    UnknownService = 7,
    /// A subtype its service does not have.
    UnknownSubtype = 8,
    /// Application data of the wrong length for its subtype.
    AppDataLength = 9,
    /// A function identifier that is no mission mode.
    UnknownFunction = 10,
    /// The parameter table's CRC-32 does not match its words.
    TableChecksum = 11,
}

/// Why a telecommand failed a verification step: its failure code and 4 bytes of failure data
/// (docs/interface.md §3, failure codes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Failure {
    /// The decoder rejected it (codes 1–11).
    Decode(Reason),
    /// The mode command is not legal in the current mode and phase (codes 12–17).
    Mode(Refusal),
    /// More than [`MAX_TCS_PER_PERIOD`] telecommands in one period (code 18).
    Flood,
    /// The parameter table is not the shape of a configuration: the word at fault (code 19).
    TableShape(u8),
    /// The core refused the table's configuration (`Config::validate`): the word it names
    /// (`link::NO_PARAM` for a group) and the rule (`link::rule_code`) (code 20).
    TableRefused {
        /// The word at fault.
        word: u8,
        /// The rule code.
        rule: u8,
    },
    /// A parameter table after the mission began (code 21): it is loaded only before the
    /// first step.
    TooLate,
}

impl Failure {
    /// The failure code and failure data of its report.
    pub fn code_and_data(self) -> (u16, [u8; 4]) {
        match self {
            Self::Decode(r) => (r as u16, [0; 4]),
            Self::Mode(r) => (r as u16, [0; 4]),
            Self::Flood => (18, [MAX_TCS_PER_PERIOD, 0, 0, 0]),
            Self::TableShape(word) => (19, [word, 0, 0, 0]),
            Self::TableRefused { word, rule } => (20, [word, rule, 0, 0]),
            Self::TooLate => (21, [0; 4]),
        }
    }
}

/// A rejected telecommand: why, and its identity if its header could be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Rejection {
    /// Its identity (`None`: fewer than four bytes arrived).
    pub id: Option<RequestId>,
    /// Why.
    pub reason: Reason,
}

/// Service 8, function management; subtype 1, perform a function.
const ST_FUNCTION: u8 = 8;
/// Service 9, time management; private subtype 128, set the on-board time.
const ST_TIME: u8 = 9;
/// Service 20, on-board parameter management; private subtype 128, load the whole table.
const ST_PARAMETERS: u8 = 20;
/// The private subtype of the unit's time and table telecommands.
const PRIVATE_SUBTYPE: u8 = 128;

/// Reads one telecommand from `raw` (exactly one packet). Never panics, whatever the bytes.
pub fn decode(raw: &[u8]) -> Result<Request, Rejection> {
    let id = RequestId::of(raw);
    let reject = |reason| Rejection { id, reason };
    if raw.len() > MAX_TC_LEN {
        return Err(reject(Reason::Oversized));
    }
    if raw.len() < TC_OVERHEAD_LEN {
        return Err(reject(Reason::Truncated));
    }
    let tc = PusTcReader::new_checksum_no_table(raw).map_err(|e| match e {
        spacepackets::ecss::PusError::ChecksumFailure(_) => reject(Reason::Checksum),
        _ => reject(Reason::Truncated),
    })?;
    if tc.len_packed() != raw.len() {
        return Err(reject(Reason::Oversized));
    }
    if tc.packet_type() != PacketType::Tc || !tc.sec_header_flag() {
        return Err(reject(Reason::NotTelecommand));
    }
    if tc.apid().value() != APID {
        return Err(reject(Reason::WrongApid));
    }
    if tc.pus_version() != Ok(PusVersion::PusC) {
        return Err(reject(Reason::PusVersion));
    }
    let data = tc.app_data();
    let command = match (tc.service_type_id(), tc.message_subtype_id()) {
        (ST_FUNCTION, 1) => {
            let [a, b] = *data else {
                return Err(reject(Reason::AppDataLength));
            };
            let mode = ModeCommand::from_id(u16::from_be_bytes([a, b]))
                .ok_or(reject(Reason::UnknownFunction))?;
            Telecommand::Mode(mode)
        }
        (ST_TIME, PRIVATE_SUBTYPE) => {
            let [a, b, c, d] = *data else {
                return Err(reject(Reason::AppDataLength));
            };
            Telecommand::SetTime(u32::from_be_bytes([a, b, c, d]))
        }
        (ST_PARAMETERS, PRIVATE_SUBTYPE) => {
            if data.len() != TABLE_LOAD_LEN {
                return Err(reject(Reason::AppDataLength));
            }
            let (words, crc) = data.split_at(4 * PARAM_WORDS);
            let mut crc_bytes = [0u8; 4];
            crc_bytes.copy_from_slice(crc);
            if TABLE_CRC.checksum(words) != u32::from_be_bytes(crc_bytes) {
                return Err(reject(Reason::TableChecksum));
            }
            let mut table = ParamTable {
                words: [0; PARAM_WORDS],
            };
            for (w, b) in table.words.iter_mut().zip(words.chunks_exact(4)) {
                let mut be = [0u8; 4];
                be.copy_from_slice(b);
                *w = u32::from_be_bytes(be);
            }
            Telecommand::LoadParams(table)
        }
        (ST_FUNCTION | ST_TIME | ST_PARAMETERS, _) => return Err(reject(Reason::UnknownSubtype)),
        _ => return Err(reject(Reason::UnknownService)),
    };
    // `RequestId::of` reads the four bytes a valid packet has.
    let id = id.ok_or(reject(Reason::Truncated))?;
    Ok(Request { id, command })
}

/// Writes the telecommand `command` with sequence count `seq` into `out` (the on-board
/// computer's side, and the tests'); returns its length.
pub fn encode(command: &Telecommand, seq: u16, out: &mut [u8]) -> Option<usize> {
    let mut data = [0u8; TABLE_LOAD_LEN];
    let (service, subtype, len) = match command {
        Telecommand::Mode(m) => {
            data.get_mut(..2)?
                .copy_from_slice(&(*m as u16).to_be_bytes());
            (ST_FUNCTION, 1, 2)
        }
        Telecommand::SetTime(t) => {
            data.get_mut(..4)?.copy_from_slice(&t.to_be_bytes());
            (ST_TIME, PRIVATE_SUBTYPE, 4)
        }
        Telecommand::LoadParams(table) => {
            for (b, w) in data.chunks_exact_mut(4).zip(&table.words) {
                b.copy_from_slice(&w.to_be_bytes());
            }
            let crc = TABLE_CRC.checksum(data.get(..4 * PARAM_WORDS)?);
            data.get_mut(4 * PARAM_WORDS..)?
                .copy_from_slice(&crc.to_be_bytes());
            (ST_PARAMETERS, PRIVATE_SUBTYPE, TABLE_LOAD_LEN)
        }
    };
    let sp = SpHeader::new_for_unseg_tc(u11::new(APID), u14::new(seq & 0x3fff), 0);
    let tc = spacepackets::ecss::tc::PusTcCreator::new(
        sp,
        spacepackets::ecss::tc::PusTcSecondaryHeader::new_simple(MessageTypeId::new(
            service, subtype,
        )),
        data.get(..len)?,
        CreatorConfig::default(),
    );
    tc.write_to_slice_crc_no_table(out).ok()
}

/// The steps of a telecommand's verification (service 1 subtypes: success, failure).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Stage {
    /// Acceptance: TM\[1,1\] success, TM\[1,2\] failure.
    Acceptance,
    /// Start of execution: TM\[1,3\], TM\[1,4\].
    Start,
    /// Completion of execution: TM\[1,7\], TM\[1,8\].
    Completion,
}

/// Length of a verification report's time field: the mission tick, u32.
pub const TIME_LEN: usize = 4;

/// The longest verification report: primary header 6, secondary header 7 + time, request id
/// 4, failure code 2 and data 4, packet error control 2.
pub const MAX_REPORT_LEN: usize = 6 + 7 + TIME_LEN + 4 + 2 + 4 + 2;

/// Writes the TM\[1,x\] report of `request` at `stage` (`failure`: why, as its code and 4
/// bytes of data, e.g. the refused word and rule) into `out`; returns its length. `seq` is the unit's
/// telemetry sequence count, `tick` the mission tick of the report.
pub fn verification_report(
    request: RequestId,
    stage: Stage,
    failure: Option<Failure>,
    seq: u16,
    tick: u32,
    out: &mut [u8],
) -> Option<usize> {
    let subtype = match (stage, failure.is_some()) {
        (Stage::Acceptance, false) => 1,
        (Stage::Acceptance, true) => 2,
        (Stage::Start, false) => 3,
        (Stage::Start, true) => 4,
        (Stage::Completion, false) => 7,
        (Stage::Completion, true) => 8,
    };
    let [p0, p1] = request.packet_id.to_be_bytes();
    let [s0, s1] = request.sequence.to_be_bytes();
    let mut data = [p0, p1, s0, s1, 0, 0, 0, 0, 0, 0];
    let len = match failure.map(Failure::code_and_data) {
        Some((code, [d0, d1, d2, d3])) => {
            let [c0, c1] = code.to_be_bytes();
            data[4..].copy_from_slice(&[c0, c1, d0, d1, d2, d3]);
            10
        }
        None => 4,
    };
    telemetry_packet(1, subtype, seq, tick, data.get(..len)?, out)
}

/// Length of the CCSDS primary header (CCSDS 133.0-B-2 §4.1.3).
const PRIMARY_HEADER_LEN: usize = 6;

/// Length of a telemetry packet of the unit without its source data: the primary header, the
/// PUS-C TM secondary header (7 bytes) and its time field, the packet error control
/// (ECSS-E-ST-70-41C §7.4.3.2, §7.4.4).
pub const TM_OVERHEAD_LEN: usize = PRIMARY_HEADER_LEN + 7 + TIME_LEN + 2;

/// The packet error control's CRC-16/CCITT-FALSE (ECSS-E-ST-70-41C §B.1), without a table.
const PACKET_CRC: crc::Crc<u16, crc::NoTable> =
    crc::Crc::<u16, crc::NoTable>::new(&crc::CRC_16_IBM_3740);

/// Writes the unit's telemetry packet TM\[`service`,`subtype`\] with source data `data` into
/// `out`; returns its length (`None`: `out` is too short). `seq` is both its sequence count (14
/// bits) and its message type counter, `time` its time field (the on-board time, ticks).
///
/// The layout is `spacepackets`' `PusTmCreator`'s (unsegmented, destination 0, time reference
/// status 0; the unit tests prove the bytes identical), written by hand because that writer
/// indexes slices it has checked but the compiler cannot prove in range: panic paths that
/// `scripts/panic-check` refuses in a firmware's control path.
///
/// ```text
/// primary header   0x0800 | APID, 0xC000 | seq (14 bits), packet length − 7      u16 × 3
/// TM header        0x20 (PUS-C), service, subtype, seq u16, destination 0 u16
/// time             TIME_LEN bytes, big-endian
/// source data      data
/// error control    CRC-16/CCITT-FALSE over all of the above, u16
/// ```
pub fn telemetry_packet(
    service: u8,
    subtype: u8,
    seq: u16,
    time: u32,
    data: &[u8],
    out: &mut [u8],
) -> Option<usize> {
    let len = TM_OVERHEAD_LEN.checked_add(data.len())?;
    let data_length = u16::try_from(len - PRIMARY_HEADER_LEN - 1).ok()?;
    let (body, error_control) = out.get_mut(..len)?.split_last_chunk_mut::<2>()?;
    let [a0, a1] = (0x0800 | APID).to_be_bytes();
    let [q0, q1] = (0xc000 | (seq & 0x3fff)).to_be_bytes();
    let [l0, l1] = data_length.to_be_bytes();
    let [c0, c1] = seq.to_be_bytes();
    let [t0, t1, t2, t3] = time.to_be_bytes();
    let head = [
        a0, a1, q0, q1, l0, l1, 0x20, service, subtype, c0, c1, 0, 0, t0, t1, t2, t3,
    ];
    // Byte by byte (zip): no length to mismatch.
    for (dst, src) in body.iter_mut().zip(head.iter().chain(data)) {
        *dst = *src;
    }
    *error_control = PACKET_CRC.checksum(body).to_be_bytes();
    Some(len)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controller::Config;

    fn roundtrip(c: Telecommand) {
        let mut buf = [0u8; MAX_TC_LEN];
        let n = encode(&c, 42, &mut buf).unwrap();
        let r = decode(&buf[..n]).unwrap();
        assert_eq!(r.command, c);
        assert_eq!(r.id.sequence & 0x3fff, 42);
    }

    #[test]
    fn every_telecommand_roundtrips() {
        for m in [1, 2, 3, 4, 5].map(|i| ModeCommand::from_id(i).unwrap()) {
            roundtrip(Telecommand::Mode(m));
        }
        roundtrip(Telecommand::SetTime(18_000));
        roundtrip(Telecommand::LoadParams(ParamTable::from_config(
            &Config::flight(),
        )));
    }

    #[test]
    fn each_check_has_its_reason() {
        let mut buf = [0u8; MAX_TC_LEN + 8];
        let n = encode(&Telecommand::Mode(ModeCommand::Hold), 1, &mut buf).unwrap();
        let good = buf[..n].to_vec();
        let reason = |b: &[u8]| decode(b).unwrap_err().reason;
        assert_eq!(reason(&good[..n - 1]), Reason::Truncated);
        assert_eq!(reason(&[0; 3]), Reason::Truncated);
        assert_eq!(decode(&[0; 3]).unwrap_err().id, None);
        let mut long = good.clone();
        long.push(0);
        assert_eq!(reason(&long), Reason::Oversized);
        assert_eq!(reason(&[0x18; MAX_TC_LEN + 1]), Reason::Oversized);
        let mut bad = good.clone();
        bad[n - 3] ^= 1;
        assert_eq!(reason(&bad), Reason::Checksum);
        assert_eq!(decode(&bad).unwrap_err().id, RequestId::of(&good));

        // Re-encode with a valid CRC but another field.
        let with = |service: u8, subtype: u8, data: &[u8], apid: u16| {
            let sp = SpHeader::new_for_unseg_tc(u11::new(apid), u14::new(1), 0);
            let tc = spacepackets::ecss::tc::PusTcCreator::new(
                sp,
                spacepackets::ecss::tc::PusTcSecondaryHeader::new_simple(MessageTypeId::new(
                    service, subtype,
                )),
                data,
                CreatorConfig::default(),
            );
            let mut out = [0u8; 300];
            let n = tc.write_to_slice(&mut out).unwrap();
            out[..n].to_vec()
        };
        assert_eq!(reason(&with(8, 1, &[0, 2], APID + 1)), Reason::WrongApid);
        assert_eq!(reason(&with(17, 1, &[], APID)), Reason::UnknownService);
        assert_eq!(reason(&with(8, 2, &[0, 2], APID)), Reason::UnknownSubtype);
        assert_eq!(reason(&with(8, 1, &[0, 2, 0], APID)), Reason::AppDataLength);
        assert_eq!(reason(&with(8, 1, &[0, 9], APID)), Reason::UnknownFunction);
        assert_eq!(
            reason(&with(9, 128, &[1, 2, 3], APID)),
            Reason::AppDataLength
        );
        let mut table = [0u8; TABLE_LOAD_LEN];
        table[0] = 1;
        assert_eq!(reason(&with(20, 128, &table, APID)), Reason::TableChecksum);
        assert_eq!(
            decode(&with(8, 1, &[0, 5], APID)).unwrap().command,
            Telecommand::Mode(ModeCommand::Abort)
        );
    }

    /// The hand-written telemetry packet is `spacepackets`' `PusTmCreator`'s, byte for byte,
    /// for every length of source data the unit sends and more, and any sequence count.
    #[test]
    fn telemetry_packets_are_spacepackets_own() {
        use spacepackets::ecss::tm::{PusTmCreator, PusTmSecondaryHeader};
        let source: [u8; 100] = core::array::from_fn(|i| (i as u8).wrapping_mul(37) ^ 0x5a);
        for (len, seq, time) in [
            (0, 0, 0),
            (4, 1, 7),
            (10, 0x3fff, u32::MAX),
            (67, 0x1234, 18_000),
        ]
        .into_iter()
        .chain((0..=source.len()).map(|n| (n, n as u16 * 331, n as u32 * 997)))
        {
            let (service, subtype) = (3, 25);
            let stamp = time.to_be_bytes();
            let sp = SpHeader::new_for_unseg_tm(u11::new(APID), u14::new(seq & 0x3fff), 0);
            let sec =
                PusTmSecondaryHeader::new(MessageTypeId::new(service, subtype), seq, 0, &stamp);
            let tm = PusTmCreator::new(sp, sec, &source[..len], CreatorConfig::default());
            let mut theirs = [0u8; 200];
            let n = tm.write_to_slice_crc_no_table(&mut theirs).unwrap();
            let mut ours = [0u8; 200];
            let m = telemetry_packet(service, subtype, seq, time, &source[..len], &mut ours);
            assert_eq!(m, Some(n), "length {len}");
            assert_eq!(ours[..n], theirs[..n], "length {len}");
            assert_eq!(m, Some(TM_OVERHEAD_LEN + len));
            assert_eq!(
                telemetry_packet(
                    service,
                    subtype,
                    seq,
                    time,
                    &source[..len],
                    &mut ours[..n - 1]
                ),
                None
            );
        }
    }

    #[test]
    fn verification_reports_name_their_request() {
        let id = RequestId {
            packet_id: 0x18a5,
            sequence: 0xc001,
        };
        let mut out = [0u8; MAX_REPORT_LEN];
        let n = verification_report(id, Stage::Acceptance, None, 3, 7, &mut out).unwrap();
        let tm = spacepackets::ecss::tm::PusTmReader::new(&out[..n], TIME_LEN).unwrap();
        assert_eq!((tm.service_type_id(), tm.message_subtype_id()), (1, 1));
        assert_eq!(tm.source_data(), &[0x18, 0xa5, 0xc0, 0x01]);
        let n = verification_report(
            id,
            Stage::Completion,
            Some(Failure::TableRefused { word: 7, rule: 2 }),
            4,
            7,
            &mut out,
        )
        .unwrap();
        assert_eq!(n, MAX_REPORT_LEN);
        let tm = spacepackets::ecss::tm::PusTmReader::new(&out[..n], TIME_LEN).unwrap();
        assert_eq!((tm.service_type_id(), tm.message_subtype_id()), (1, 8));
        assert_eq!(&tm.source_data()[4..], &[0, 20, 7, 2, 0, 0]);
    }
}
