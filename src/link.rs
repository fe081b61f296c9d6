//! The processor-in-the-loop (PIL) link: the frames the plant (`tss-sim`) and the reel MCU's
//! firmware exchange over a UART, one pair per control period.
//!
//! `no_std`, no allocation, no panics: encoding writes into the caller's buffer and fails with
//! [`LinkError::BufferTooSmall`] if it does not fit; decoding accepts any byte stream and answers
//! every malformed frame with a typed [`LinkError`] (the property test `tests/link.rs` feeds it
//! arbitrary and mutated bytes).
//!
//! # Frame layout (version [`VERSION`] = 2)
//!
//! On the wire a frame is its COBS encoding (Cheshire & Baker 1999: no `0x00` inside) followed
//! by one `0x00` delimiter, so a receiver can resynchronise on the next `0x00` after any error.
//! Decoded, a frame is (offsets in bytes, integers little-endian, `f32` as IEEE-754 bit patterns
//! little-endian; this is the [postcard](https://postcard.jamesmunns.com/) encoding of
//! [`Frame`] with fixed-width integers):
//!
//! ```text
//! offset  size  field
//! 0       1     version            = VERSION; any other value is LinkError::Version
//! 1       4     seq      u32       sender's frame counter from 0, +1 per new frame (a repeat
//!                                  keeps it)
//! 5       1     kind     u8        0 Hello, 1 Sample, 2 Command, 3 End, 4 Report
//! 6       n     body               the kind's fields, in declaration order (below)
//! 6+n     4     crc      u32       CRC-32/ISO-HDLC over bytes 0 .. 6+n
//! ```
//!
//! Bodies (`n` bytes):
//!
//! ```text
//! Hello   (firmware → plant, once at start, n = 9)
//!         config_digest u32, period_ms u32, timeout_periods u8
//! Sample  (plant → firmware, once per period, n = 21 to 37)
//!         tick u32, status u8 (0 valid, 1 no sample), length_m f32, reel_rate_mps opt,
//!         tension_n opt, alpha_rad opt, alpha_rate_radps opt, orbit_rate_radps f32,
//!         true_anomaly_rad f32
//! Command (firmware → plant, once per period, n = 53 or 57)
//!         tick u32, sample u8 (SampleStatus: how this period's sample arrived),
//!         rate_cmd_mps f32, accel_cmd_mps2 f32, law_rate_mps f32, blend_weight f32,
//!         alpha_ref_rad f32, alpha_ref_rate_radps f32, delta_rad f32, delta_rate_radps f32,
//!         length_estimate_m f32, equilibrium_margin f32, nis opt,
//!         phase u8, health u8, fault u8 (see `fault_code`), flags u32
//! End     (plant → firmware, once at the end, n = 4)
//!         ticks u32 (control periods the plant ran); its seq follows the last sample's, so
//!         the firmware counts sample frames lost at the end as gaps
//! Report  (firmware → plant, the answer to End, n = 4 × 15)
//!         the firmware's LinkCounters, then commands u32 (sent), then digest u32 (FNV-1a over
//!         the bit patterns of every rate command, as the replay mission's)
//! ```
//!
//! `opt` is an optional f32 (postcard's `Option`): one byte 0 (absent), or 1 followed by the
//! f32 (any other tag byte is [`LinkError::Malformed`]). Version 1 had no options: a sample
//! carried α and α̇ always, and no reel rate, tension or true anomaly; a command no NIS.
//!
//! The largest frame (Report) is 6 + 60 + 4 = 70 bytes decoded, [`MAX_WIRE_LEN`] on the wire.
//!
//! # What the receiver checks, in order
//!
//! COBS structure ([`LinkError::Cobs`]), length ([`LinkError::Truncated`]: shorter than header
//! and CRC), CRC ([`LinkError::Crc`]), version ([`LinkError::Version`]), kind
//! ([`LinkError::UnknownKind`]), body length ([`LinkError::Truncated`] / [`LinkError::Malformed`]
//! for trailing bytes), field values (enumeration codes: [`LinkError::Malformed`]); a frame
//! longer than the receive buffer is [`LinkError::Overflow`]. A valid frame of another kind
//! than the receiver expects is [`LinkError::WrongKind`]. Sequence and tick checks (duplicate,
//! out of order, gap) belong to the receiving side ([`SampleGate`]); every outcome is counted
//! in [`LinkCounters`].

use serde::{Deserialize, Serialize};

use crate::controller::{Fault, Flags, Health, Output, Phase, Sensor};
use crate::law::LawFault;

/// Protocol version carried in byte 0 of every frame (see the module docs).
pub const VERSION: u8 = 2;

/// Decoded header length: version, seq, kind.
pub const HEADER_LEN: usize = 6;

/// Length of the CRC that closes every decoded frame.
pub const CRC_LEN: usize = 4;

/// Largest decoded frame (header, the largest body, CRC), bytes.
pub const MAX_FRAME_LEN: usize = 80;

/// Largest frame on the wire: COBS adds one byte per 254 (and one), plus the `0x00` delimiter.
pub const MAX_WIRE_LEN: usize = MAX_FRAME_LEN + MAX_FRAME_LEN / 254 + 2;

/// Most control periods of one PIL run (ticks 0 ..= `MAX_TICKS` − 1): the firmware ends a
/// longer run as a failure, and the plant refuses such a scenario before it starts. The
/// paper's 20-h mission is 72 001 ticks.
pub const MAX_TICKS: u32 = 200_000;

/// The wire delimiter between frames.
pub const DELIMITER: u8 = 0x00;

/// CRC-32/ISO-HDLC (the Ethernet/zlib CRC): poly 0x04C11DB7 reflected, init and xorout all ones.
/// Bitwise, without the 1 KiB lookup table: flash is tight, and a frame is at most 80 bytes.
const CRC32: crc::Crc<u32, crc::NoTable> =
    crc::Crc::<u32, crc::NoTable>::new(&crc::CRC_32_ISO_HDLC);

/// Why a frame was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LinkError {
    /// The bytes between two delimiters are not a valid COBS encoding.
    Cobs,
    /// Too short for header and CRC, or the body ended early.
    Truncated,
    /// The CRC does not match the frame's bytes.
    Crc,
    /// Protocol version other than [`VERSION`] (the value received).
    Version(u8),
    /// A kind byte that no message has.
    UnknownKind(u8),
    /// Well framed and checksummed, but a field is invalid (trailing bytes, enumeration code).
    Malformed,
    /// A valid frame of another kind than the receiver expected.
    WrongKind,
    /// A frame longer than the receive buffer ([`MAX_WIRE_LEN`]); discarded up to the next
    /// delimiter.
    Overflow,
    /// The caller's output buffer cannot hold the encoded frame (encoding only).
    BufferTooSmall,
}

/// What arrived for one control period, as the firmware reports it back in each
/// [`Command::sample`] (and counts in [`LinkCounters`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SampleStatus {
    /// A valid sample frame for this tick.
    Fresh = 0,
    /// No valid frame before the timeout (dropped, delayed, or the link is down).
    Timeout = 1,
    /// A frame arrived but failed its checks (COBS, CRC, version, …).
    Corrupted = 2,
    /// A valid frame whose plant side reported no sample (a sensor dropout upstream).
    NoSample = 3,
}

impl SampleStatus {
    /// The status for a wire code (`None` for an unknown code).
    pub fn from_code(code: u8) -> Option<Self> {
        match code {
            0 => Some(Self::Fresh),
            1 => Some(Self::Timeout),
            2 => Some(Self::Corrupted),
            3 => Some(Self::NoSample),
            _ => None,
        }
    }
}

/// `Hello`: the firmware announces itself once, before the first sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Hello {
    /// [`config_digest`] of the controller configuration the firmware flies.
    #[serde(with = "postcard::fixint::le")]
    pub config_digest: u32,
    /// The firmware's control period, ms.
    #[serde(with = "postcard::fixint::le")]
    pub period_ms: u32,
    /// How many control periods the firmware waits for a sample frame before it steps without
    /// one.
    pub timeout_periods: u8,
}

/// `Sample.status`: the plant had a sample.
pub const SAMPLE_VALID: u8 = 0;
/// `Sample.status`: the plant side had no sample this period (upstream sensor dropout).
pub const SAMPLE_MISSING: u8 = 1;

/// `Sample`: one control period's sensor readings, plant → firmware.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// The control period this sample belongs to (the authority on time in PIL).
    #[serde(with = "postcard::fixint::le")]
    pub tick: u32,
    /// [`SAMPLE_VALID`] or [`SAMPLE_MISSING`] (then the readings are meaningless).
    pub status: u8,
    /// Tether length l from the reel encoder, m.
    pub length_m: f32,
    /// The reel's rate from its encoder, m/s.
    pub reel_rate_mps: Option<f32>,
    /// Tension at the reel from the load cell, N.
    pub tension_n: Option<f32>,
    /// In-plane angle α, rad.
    pub alpha_rad: Option<f32>,
    /// In-plane rate α̇ from the optional rate sensor, rad/s.
    pub alpha_rate_radps: Option<f32>,
    /// Orbit rate θ̇, rad/s.
    pub orbit_rate_radps: f32,
    /// True anomaly θ, rad.
    pub true_anomaly_rad: f32,
}

/// `Command`: the controller's output for one period, with its telemetry, firmware → plant.
///
/// It carries every field of [`Output<f32>`], so the plant side rebuilds the exact output
/// ([`Command::to_output`]) and writes the same history as a host-linked run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Command {
    /// The tick of the output.
    #[serde(with = "postcard::fixint::le")]
    pub tick: u32,
    /// How this period's sample arrived ([`SampleStatus`] code).
    pub sample: u8,
    /// [`Output::rate_cmd_mps`].
    pub rate_cmd_mps: f32,
    /// [`Output::accel_cmd_mps2`].
    pub accel_cmd_mps2: f32,
    /// [`Output::law_rate_mps`].
    pub law_rate_mps: f32,
    /// [`Output::blend_weight`].
    pub blend_weight: f32,
    /// [`Output::alpha_ref_rad`].
    pub alpha_ref_rad: f32,
    /// [`Output::alpha_ref_rate_radps`].
    pub alpha_ref_rate_radps: f32,
    /// [`Output::delta_rad`].
    pub delta_rad: f32,
    /// [`Output::delta_rate_radps`].
    pub delta_rate_radps: f32,
    /// [`Output::length_estimate_m`].
    pub length_estimate_m: f32,
    /// [`Output::equilibrium_margin`].
    pub equilibrium_margin: f32,
    /// [`Output::nis`].
    pub nis: Option<f32>,
    /// [`Output::phase`] ([`phase_code`]).
    pub phase: u8,
    /// [`Output::health`] ([`health_code`]).
    pub health: u8,
    /// [`Output::fault`] ([`fault_code`]).
    pub fault: u8,
    /// [`Output::flags`].
    #[serde(with = "postcard::fixint::le")]
    pub flags: u32,
}

/// `End`: the plant's mission is over; the firmware answers with a [`Report`] and stops.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct End {
    /// Control periods the plant ran.
    #[serde(with = "postcard::fixint::le")]
    pub ticks: u32,
}

/// What a receiver saw on the link (each field a count of frames or periods).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkCounters {
    /// Valid frames of the expected kind that were used.
    #[serde(with = "postcard::fixint::le")]
    pub frames_ok: u32,
    /// Periods with no valid frame before the timeout.
    #[serde(with = "postcard::fixint::le")]
    pub timeouts: u32,
    /// Frames with a bad COBS encoding.
    #[serde(with = "postcard::fixint::le")]
    pub cobs_errors: u32,
    /// Frames too short for their header, CRC or body.
    #[serde(with = "postcard::fixint::le")]
    pub truncated: u32,
    /// Frames whose CRC did not match.
    #[serde(with = "postcard::fixint::le")]
    pub crc_errors: u32,
    /// Frames of another protocol version.
    #[serde(with = "postcard::fixint::le")]
    pub version_errors: u32,
    /// Frames with an unknown kind byte.
    #[serde(with = "postcard::fixint::le")]
    pub unknown_kind: u32,
    /// Frames with an invalid field or trailing bytes.
    #[serde(with = "postcard::fixint::le")]
    pub malformed: u32,
    /// Valid frames of a kind the receiver did not expect.
    #[serde(with = "postcard::fixint::le")]
    pub wrong_kind: u32,
    /// Frames longer than the receive buffer.
    #[serde(with = "postcard::fixint::le")]
    pub overflows: u32,
    /// Valid frames that repeat the last accepted one (same sequence number).
    #[serde(with = "postcard::fixint::le")]
    pub duplicates: u32,
    /// Valid frames older than the last accepted one (late: out of order).
    #[serde(with = "postcard::fixint::le")]
    pub out_of_order: u32,
    /// Frames never seen, from gaps in the sequence numbers.
    #[serde(with = "postcard::fixint::le")]
    pub seq_gaps: u32,
}

impl LinkCounters {
    /// Counts one rejected frame under its error.
    pub fn count_error(&mut self, e: LinkError) {
        let c = match e {
            LinkError::Cobs => &mut self.cobs_errors,
            LinkError::Truncated => &mut self.truncated,
            LinkError::Crc => &mut self.crc_errors,
            LinkError::Version(_) => &mut self.version_errors,
            LinkError::UnknownKind(_) => &mut self.unknown_kind,
            LinkError::Malformed | LinkError::BufferTooSmall => &mut self.malformed,
            LinkError::WrongKind => &mut self.wrong_kind,
            LinkError::Overflow => &mut self.overflows,
        };
        *c = c.saturating_add(1);
    }

    /// Frames rejected by the decoder (every error but duplicates, reordering and gaps).
    pub fn decode_errors(&self) -> u32 {
        [
            self.cobs_errors,
            self.truncated,
            self.crc_errors,
            self.version_errors,
            self.unknown_kind,
            self.malformed,
            self.wrong_kind,
            self.overflows,
        ]
        .iter()
        .fold(0u32, |a, &b| a.saturating_add(b))
    }
}

/// `Report`: the firmware's link counters and command digest, its answer to [`End`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Report {
    /// The firmware's receive-side counters.
    pub counters: LinkCounters,
    /// Command frames sent.
    #[serde(with = "postcard::fixint::le")]
    pub commands: u32,
    /// FNV-1a over the bit patterns of every rate command sent ([`fnv1a_f32`]).
    #[serde(with = "postcard::fixint::le")]
    pub digest: u32,
}

/// One message: the frame's kind and body.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Message {
    /// Kind 0, firmware → plant.
    Hello(Hello),
    /// Kind 1, plant → firmware.
    Sample(Sample),
    /// Kind 2, firmware → plant.
    Command(Command),
    /// Kind 3, plant → firmware.
    End(End),
    /// Kind 4, firmware → plant.
    Report(Report),
}

/// Number of message kinds (kind bytes `0 .. KINDS`).
pub const KINDS: u8 = 5;

/// A decoded frame: header and message (the CRC is checked and dropped).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frame {
    /// Protocol version ([`VERSION`]).
    pub version: u8,
    /// Sender's sequence number.
    #[serde(with = "postcard::fixint::le")]
    pub seq: u32,
    /// Kind and body.
    pub message: Message,
}

/// Encodes `message` with sequence number `seq` into `out` as it goes on the wire (COBS and
/// the closing delimiter included); returns the number of bytes written.
pub fn encode(seq: u32, message: &Message, out: &mut [u8]) -> Result<usize, LinkError> {
    let frame = Frame {
        version: VERSION,
        seq,
        message: *message,
    };
    let mut raw = [0u8; MAX_FRAME_LEN];
    let body_len = postcard::to_slice(&frame, &mut raw)
        .map_err(|_| LinkError::BufferTooSmall)?
        .len();
    let crc = CRC32.checksum(raw.get(..body_len).ok_or(LinkError::BufferTooSmall)?);
    let total = body_len + CRC_LEN;
    raw.get_mut(body_len..total)
        .ok_or(LinkError::BufferTooSmall)?
        .copy_from_slice(&crc.to_le_bytes());
    let src = raw.get(..total).ok_or(LinkError::BufferTooSmall)?;
    let n = cobs::try_encode(src, out).map_err(|_| LinkError::BufferTooSmall)?;
    *out.get_mut(n).ok_or(LinkError::BufferTooSmall)? = DELIMITER;
    Ok(n + 1)
}

/// Decodes one frame from its wire bytes between two delimiters (`encoded` holds no `0x00`;
/// a trailing delimiter is tolerated). Never panics, whatever the bytes.
pub fn decode(encoded: &[u8]) -> Result<Frame, LinkError> {
    let encoded = match encoded.split_last() {
        Some((&DELIMITER, rest)) => rest,
        _ => encoded,
    };
    if encoded.len() > MAX_WIRE_LEN {
        return Err(LinkError::Overflow);
    }
    if encoded.is_empty() {
        return Err(LinkError::Truncated);
    }
    let mut raw = [0u8; MAX_FRAME_LEN];
    let n = cobs::decode(encoded, &mut raw)
        .map_err(|e| match e {
            cobs::DecodeError::TargetBufTooSmall => LinkError::Overflow,
            _ => LinkError::Cobs,
        })?
        .frame_size();
    let raw = raw.get(..n).ok_or(LinkError::Overflow)?;
    if raw.len() < HEADER_LEN + CRC_LEN {
        return Err(LinkError::Truncated);
    }
    let (body, crc) = raw.split_at(raw.len() - CRC_LEN);
    let mut crc_bytes = [0u8; CRC_LEN];
    crc_bytes.copy_from_slice(crc);
    if CRC32.checksum(body) != u32::from_le_bytes(crc_bytes) {
        return Err(LinkError::Crc);
    }
    match body.first() {
        Some(&VERSION) => {}
        Some(&v) => return Err(LinkError::Version(v)),
        None => return Err(LinkError::Truncated),
    }
    match body.get(HEADER_LEN - 1) {
        Some(&k) if k < KINDS => {}
        Some(&k) => return Err(LinkError::UnknownKind(k)),
        None => return Err(LinkError::Truncated),
    }
    let (frame, rest) = postcard::take_from_bytes::<Frame>(body).map_err(|e| match e {
        postcard::Error::DeserializeUnexpectedEnd => LinkError::Truncated,
        _ => LinkError::Malformed,
    })?;
    if !rest.is_empty() {
        return Err(LinkError::Malformed);
    }
    // Enumeration codes must be known ones, so that a frame that decodes is a usable one.
    if let Message::Command(c) = &frame.message {
        c.to_output()?;
    }
    if let Message::Sample(s) = &frame.message {
        if s.status > SAMPLE_MISSING {
            return Err(LinkError::Malformed);
        }
    }
    Ok(frame)
}

/// Splits a byte stream into frames at the delimiters and decodes them. Holds at most one
/// frame ([`MAX_WIRE_LEN`] bytes); a longer run of bytes is [`LinkError::Overflow`], reported
/// at its delimiter. Runs of delimiters (empty frames) are idle line and ignored.
#[derive(Clone, Debug)]
pub struct FrameReader {
    buf: [u8; MAX_WIRE_LEN],
    len: usize,
    overflow: bool,
}

impl Default for FrameReader {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameReader {
    /// An empty reader.
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_WIRE_LEN],
            len: 0,
            overflow: false,
        }
    }

    /// Feeds one byte; returns the decoded frame (or why it was rejected) when `byte` closes one.
    pub fn push(&mut self, byte: u8) -> Option<Result<Frame, LinkError>> {
        if byte != DELIMITER {
            match self.buf.get_mut(self.len) {
                Some(slot) => {
                    *slot = byte;
                    self.len += 1;
                }
                None => self.overflow = true,
            }
            return None;
        }
        let (len, overflow) = (self.len, self.overflow);
        self.len = 0;
        self.overflow = false;
        if overflow {
            return Some(Err(LinkError::Overflow));
        }
        if len == 0 {
            return None;
        }
        Some(self.buf.get(..len).map_or(Err(LinkError::Overflow), decode))
    }

    /// `true` if part of a frame has been received (bytes since the last delimiter).
    pub fn in_frame(&self) -> bool {
        self.len > 0 || self.overflow
    }
}

/// What a [`SampleGate`] made of one valid sample frame.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Gate {
    /// The sample for the awaited tick (or a later one: the frame's tick is the authority).
    Accept(Sample),
    /// The same sequence number as the last accepted frame: a duplicate, discarded.
    Duplicate,
    /// Older than the last accepted frame (sequence or tick): late, discarded.
    OutOfOrder,
}

/// The receiving side's sequence and tick checks on sample frames, with the counts in
/// [`LinkCounters`]. A discarded frame does not use up the period: the receiver keeps waiting
/// for the right one (so a repeated frame cannot push the receiver ahead of the sender).
///
/// The sender numbers its frames from 0 and its [`End`] frame carries the number after its last
/// sample, so frames lost before the first one that arrives and after the last one are counted
/// as gaps too ([`SampleGate::close`]): the count is exact whichever frames are lost.
#[derive(Clone, Copy, Debug, Default)]
pub struct SampleGate {
    /// Sequence number and tick of the newest sample frame seen (`None`: none yet).
    last: Option<(u32, u32)>,
}

impl SampleGate {
    /// A gate that has seen nothing yet (the next frame is expected to be number 0).
    pub const fn new() -> Self {
        Self { last: None }
    }

    /// The sequence number the next new frame should carry.
    fn expected_seq(&self) -> u32 {
        self.last.map_or(0, |(seq, _)| seq.saturating_add(1))
    }

    /// Judges a valid sample frame `seq`/`sample` while the receiver waits for tick `awaited`;
    /// counts duplicates, late frames and sequence gaps.
    pub fn check(
        &mut self,
        seq: u32,
        sample: Sample,
        awaited: u32,
        counters: &mut LinkCounters,
    ) -> Gate {
        if let Some((last_seq, last_tick)) = self.last {
            if seq == last_seq {
                counters.duplicates = counters.duplicates.saturating_add(1);
                return Gate::Duplicate;
            }
            if seq < last_seq || sample.tick <= last_tick {
                counters.out_of_order = counters.out_of_order.saturating_add(1);
                return Gate::OutOfOrder;
            }
        }
        let gap = seq.saturating_sub(self.expected_seq());
        counters.seq_gaps = counters.seq_gaps.saturating_add(gap);
        // Seen, so it is no gap, whether or not it is used.
        self.last = Some((seq, sample.tick));
        if sample.tick < awaited {
            counters.out_of_order = counters.out_of_order.saturating_add(1);
            return Gate::OutOfOrder;
        }
        counters.frames_ok = counters.frames_ok.saturating_add(1);
        Gate::Accept(sample)
    }

    /// The sender's [`End`] frame, number `end_seq`, closed the run: counts the frames lost
    /// after the last one seen (all of them if none arrived).
    pub fn close(&mut self, end_seq: u32, counters: &mut LinkCounters) {
        let gap = end_seq.saturating_sub(self.expected_seq());
        counters.seq_gaps = counters.seq_gaps.saturating_add(gap);
    }
}

// ---- enumeration codes ------------------------------------------------------------------------

/// The wire code of a phase.
pub fn phase_code(p: Phase) -> u8 {
    match p {
        Phase::Deploy => 0,
        Phase::Keep1 => 1,
        Phase::Slew => 2,
        Phase::Retrieve => 3,
        Phase::Keep2 => 4,
    }
}

/// The phase of a wire code.
pub fn phase_from_code(c: u8) -> Option<Phase> {
    [
        Phase::Deploy,
        Phase::Keep1,
        Phase::Slew,
        Phase::Retrieve,
        Phase::Keep2,
    ]
    .into_iter()
    .find(|&p| phase_code(p) == c)
}

/// The wire code of a health state.
pub fn health_code(h: Health) -> u8 {
    match h {
        Health::Nominal => 0,
        Health::Degraded => 1,
        Health::SafeHold => 2,
    }
}

/// The health state of a wire code.
pub fn health_from_code(c: u8) -> Option<Health> {
    [Health::Nominal, Health::Degraded, Health::SafeHold]
        .into_iter()
        .find(|&h| health_code(h) == c)
}

const SENSOR_FAULTS: [Sensor; 11] = [
    Sensor::Missing,
    Sensor::Tick,
    Sensor::Length,
    Sensor::LengthJump,
    Sensor::Alpha,
    Sensor::AlphaJump,
    Sensor::AlphaStuck,
    Sensor::AlphaRate,
    Sensor::OrbitRate,
    Sensor::AlphaGated,
    Sensor::AlphaLost,
];

const LAW_FAULTS: [LawFault; 4] = [
    LawFault::SingularDenominator,
    LawFault::NoRealSolution,
    LawFault::AccelerationSingular,
    LawFault::NotFinite,
];

/// The wire code of a fault: 0 none, `0x10 + n` sensor fault n, `0x20 + n` law fault n (n in
/// declaration order).
pub fn fault_code(f: Option<Fault>) -> u8 {
    match f {
        None => 0,
        Some(Fault::Sensor(s)) => {
            0x10 + match s {
                Sensor::Missing => 0,
                Sensor::Tick => 1,
                Sensor::Length => 2,
                Sensor::LengthJump => 3,
                Sensor::Alpha => 4,
                Sensor::AlphaJump => 5,
                Sensor::AlphaStuck => 6,
                Sensor::AlphaRate => 7,
                Sensor::OrbitRate => 8,
                Sensor::AlphaGated => 9,
                Sensor::AlphaLost => 10,
            }
        }
        Some(Fault::Law(l)) => {
            0x20 + match l {
                LawFault::SingularDenominator => 0,
                LawFault::NoRealSolution => 1,
                LawFault::AccelerationSingular => 2,
                LawFault::NotFinite => 3,
            }
        }
    }
}

/// The fault of a wire code (`Err` for an unknown code).
pub fn fault_from_code(c: u8) -> Result<Option<Fault>, LinkError> {
    if c == 0 {
        return Ok(None);
    }
    let sensor = SENSOR_FAULTS.into_iter().map(Fault::Sensor);
    let law = LAW_FAULTS.into_iter().map(Fault::Law);
    sensor
        .chain(law)
        .find(|&f| fault_code(Some(f)) == c)
        .map(Some)
        .ok_or(LinkError::Malformed)
}

impl Command {
    /// The command frame of a controller output, with the status of the period's sample.
    pub fn from_output(o: &Output<f32>, sample: SampleStatus) -> Self {
        Self {
            tick: o.tick,
            sample: sample as u8,
            rate_cmd_mps: o.rate_cmd_mps,
            accel_cmd_mps2: o.accel_cmd_mps2,
            law_rate_mps: o.law_rate_mps,
            blend_weight: o.blend_weight,
            alpha_ref_rad: o.alpha_ref_rad,
            alpha_ref_rate_radps: o.alpha_ref_rate_radps,
            delta_rad: o.delta_rad,
            delta_rate_radps: o.delta_rate_radps,
            length_estimate_m: o.length_estimate_m,
            equilibrium_margin: o.equilibrium_margin,
            nis: o.nis,
            phase: phase_code(o.phase),
            health: health_code(o.health),
            fault: fault_code(o.fault),
            flags: o.flags.0,
        }
    }

    /// The controller output this frame carries (bit for bit), or [`LinkError::Malformed`]
    /// for an unknown enumeration code.
    pub fn to_output(&self) -> Result<Output<f32>, LinkError> {
        SampleStatus::from_code(self.sample).ok_or(LinkError::Malformed)?;
        Ok(Output {
            tick: self.tick,
            phase: phase_from_code(self.phase).ok_or(LinkError::Malformed)?,
            health: health_from_code(self.health).ok_or(LinkError::Malformed)?,
            rate_cmd_mps: self.rate_cmd_mps,
            accel_cmd_mps2: self.accel_cmd_mps2,
            law_rate_mps: self.law_rate_mps,
            blend_weight: self.blend_weight,
            alpha_ref_rad: self.alpha_ref_rad,
            alpha_ref_rate_radps: self.alpha_ref_rate_radps,
            delta_rad: self.delta_rad,
            delta_rate_radps: self.delta_rate_radps,
            length_estimate_m: self.length_estimate_m,
            equilibrium_margin: self.equilibrium_margin,
            nis: self.nis,
            flags: Flags(self.flags),
            fault: fault_from_code(self.fault)?,
        })
    }
}

// ---- fingerprints -----------------------------------------------------------------------------

const FNV_OFFSET: u32 = 0x811c_9dc5;
const FNV_PRIME: u32 = 0x0100_0193;

/// FNV-1a (32-bit) of `bytes`, continuing from `hash` (start with [`fnv1a_start`]).
pub fn fnv1a(hash: u32, bytes: &[u8]) -> u32 {
    bytes
        .iter()
        .fold(hash, |h, &b| (h ^ u32::from(b)).wrapping_mul(FNV_PRIME))
}

/// The FNV-1a offset basis, the digest of nothing.
pub const fn fnv1a_start() -> u32 {
    FNV_OFFSET
}

/// FNV-1a continued over the bit pattern of `x` (little-endian).
pub fn fnv1a_f32(hash: u32, x: f32) -> u32 {
    fnv1a(hash, &x.to_bits().to_le_bytes())
}

/// A fingerprint of a controller configuration: FNV-1a over the bit pattern of every field, in
/// declaration order. The firmware sends it in [`Hello`]; the plant compares it with the
/// configuration its scenario describes, so a PIL run cannot fly a different controller than the
/// host-linked run it is compared with. Every struct is destructured without `..`: a new field
/// anywhere in the configuration does not compile until it is added here.
pub fn config_digest(cfg: &crate::controller::Config<f32>) -> u32 {
    use crate::config::{RateSource, Stage1Config, Stage2Config};
    use crate::controller::{Config, Envelope, MonitorConfig};
    use crate::estimator;
    use crate::law::Gains;
    use crate::mass::MassModel;
    use crate::orbit::Orbit;
    use crate::schedule::BandSchedule;

    let Config {
        period_s,
        orbit,
        masses,
        gains,
        initial_rate_mps,
        stage1,
        stage2,
        keep_capture_m,
        envelope,
        monitor,
        protection,
        rate_source,
    } = cfg;
    let Orbit {
        semi_major_axis_m,
        eccentricity,
        mu_m3ps2,
    } = orbit;
    let MassModel {
        main_initial_kg,
        sub_kg,
        tether_density_kg_per_m,
    } = masses;
    let Gains {
        k1_per_s,
        k2_per_s2,
    } = gains;
    let Stage1Config {
        schedule: s1,
        decay_rate_per_s: c1,
    } = stage1;
    let Stage2Config {
        schedule: s2,
        slew_rate_radps,
        decay_rate_per_s: c2,
        start_tick,
    } = stage2;
    let Envelope {
        max_rate_mps,
        max_accel_mps2,
        min_length_m,
        max_length_m,
    } = envelope;
    let MonitorConfig {
        coast_ticks,
        recovery_ticks,
        length_jump_m,
        alpha_jump_rad,
        stuck_ticks,
        stuck_motion_rad,
        max_alpha_rate_radps,
        min_orbit_rate_radps,
        max_orbit_rate_radps,
        good_samples_per_bad,
        safe_hold_decel_mps2,
    } = monitor;
    let schedule = |h: u32, s: &BandSchedule<f32>| {
        let BandSchedule {
            low_length_m,
            low_angle_rad,
            low_slope_rad_per_m,
            high_length_m,
            high_angle_rad,
            high_slope_rad_per_m,
        } = s;
        [
            low_length_m,
            low_angle_rad,
            low_slope_rad_per_m,
            high_length_m,
            high_angle_rad,
            high_slope_rad_per_m,
        ]
        .into_iter()
        .fold(h, |h, &x| fnv1a_f32(h, x))
    };
    let mut h = [
        period_s,
        semi_major_axis_m,
        eccentricity,
        mu_m3ps2,
        main_initial_kg,
        sub_kg,
        tether_density_kg_per_m,
        k1_per_s,
        k2_per_s2,
        initial_rate_mps,
        c1,
        slew_rate_radps,
        c2,
        keep_capture_m,
        max_rate_mps,
        max_accel_mps2,
        min_length_m,
        max_length_m,
        length_jump_m,
        alpha_jump_rad,
        stuck_motion_rad,
        max_alpha_rate_radps,
        min_orbit_rate_radps,
        max_orbit_rate_radps,
        safe_hold_decel_mps2,
    ]
    .into_iter()
    .fold(fnv1a_start(), |h, &x| fnv1a_f32(h, x));
    h = schedule(h, s1);
    h = schedule(h, s2);
    let start = start_tick.map_or([0u8; 5], |t| {
        let b = t.to_le_bytes();
        [1, b[0], b[1], b[2], b[3]]
    });
    h = fnv1a(h, &start);
    for n in [
        coast_ticks,
        recovery_ticks,
        stuck_ticks,
        good_samples_per_bad,
    ] {
        h = fnv1a(h, &n.to_le_bytes());
    }
    // The rate source: nothing for the rate sensor (the digest of a configuration from before
    // there was a choice is unchanged), a tag and the estimator's parameters otherwise.
    match rate_source {
        RateSource::Sensor => {}
        RateSource::Estimator(est) => {
            let estimator::Config {
                period_s,
                alpha_noise_rad,
                alpha_quantum_rad,
                accel_noise_density,
                disturbance_drift_density,
                initial_rate_std_radps,
                initial_disturbance_std_radps2,
                gate_nis,
                max_rejections,
            } = est;
            h = fnv1a(h, &[1]);
            h = [
                period_s,
                alpha_noise_rad,
                alpha_quantum_rad,
                accel_noise_density,
                disturbance_drift_density,
                initial_rate_std_radps,
                initial_disturbance_std_radps2,
                gate_nis,
            ]
            .into_iter()
            .fold(h, |h, &x| fnv1a_f32(h, x));
            h = fnv1a(h, &max_rejections.to_le_bytes());
        }
    }
    // The protection, when configured (an unprotected configuration's digest is unchanged).
    if let Some(p) = protection {
        let crate::controller::ProtectionConfig {
            min_tension_n,
            max_tension_n,
            tension_filter_s,
            drive_lag_s,
            rate_resolution_mps,
        } = p;
        h = fnv1a(h, &[2]);
        for x in [
            min_tension_n,
            max_tension_n,
            tension_filter_s,
            drive_lag_s,
            rate_resolution_mps,
        ] {
            h = fnv1a_f32(h, *x);
        }
    }
    h
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec;

    fn roundtrip(m: Message) {
        let mut wire = [0u8; MAX_WIRE_LEN];
        let n = encode(7, &m, &mut wire).unwrap();
        assert!(n <= MAX_WIRE_LEN);
        assert_eq!(wire[n - 1], DELIMITER);
        assert!(!wire[..n - 1].contains(&DELIMITER));
        let f = decode(&wire[..n - 1]).unwrap();
        assert_eq!(f.seq, 7);
        assert_eq!(f.version, VERSION);
        assert_eq!(f.message, m);
    }

    fn command() -> Command {
        Command {
            tick: 123_456,
            sample: SampleStatus::Corrupted as u8,
            rate_cmd_mps: -1.5,
            accel_cmd_mps2: 1e-3,
            law_rate_mps: f32::MIN_POSITIVE,
            blend_weight: 0.25,
            alpha_ref_rad: -0.7,
            alpha_ref_rate_radps: 1e-6,
            delta_rad: 0.1,
            delta_rate_radps: -0.0,
            length_estimate_m: 30_000.0,
            equilibrium_margin: -1e6,
            nis: Some(2.5),
            phase: 3,
            health: 2,
            fault: 0x21,
            flags: 0xff,
        }
    }

    #[test]
    fn every_message_roundtrips_and_the_layout_is_as_documented() {
        let sample = Sample {
            tick: 42,
            status: SAMPLE_VALID,
            length_m: 1.0,
            reel_rate_mps: Some(0.1),
            tension_n: Some(3e-5),
            alpha_rad: Some(-0.61),
            alpha_rate_radps: Some(0.0),
            orbit_rate_radps: 1.06e-3,
            true_anomaly_rad: 3.1,
        };
        roundtrip(Message::Sample(sample));
        let flight = Sample {
            reel_rate_mps: None,
            tension_n: None,
            alpha_rad: None,
            alpha_rate_radps: None,
            ..sample
        };
        roundtrip(Message::Sample(flight));
        roundtrip(Message::Command(command()));
        roundtrip(Message::Hello(Hello {
            config_digest: 0xdead_beef,
            period_ms: 1000,
            timeout_periods: 2,
        }));
        roundtrip(Message::End(End { ticks: 72_001 }));
        let report = Report {
            counters: LinkCounters {
                frames_ok: u32::MAX,
                seq_gaps: 3,
                ..LinkCounters::default()
            },
            commands: 9,
            digest: 1,
        };
        roundtrip(Message::Report(report));

        // Decoded sizes: header 6 + body + CRC 4 (module docs).
        let raw_len = |m: &Message| {
            let f = Frame {
                version: VERSION,
                seq: 0,
                message: *m,
            };
            let mut b = [0u8; MAX_FRAME_LEN];
            postcard::to_slice(&f, &mut b).unwrap().len() + CRC_LEN
        };
        assert_eq!(raw_len(&Message::Sample(sample)), 6 + 37 + 4);
        assert_eq!(raw_len(&Message::Sample(flight)), 6 + 21 + 4);
        assert_eq!(raw_len(&Message::Command(command())), 6 + 57 + 4);
        let no_nis = Command {
            nis: None,
            ..command()
        };
        assert_eq!(raw_len(&Message::Command(no_nis)), 6 + 53 + 4);
        assert_eq!(raw_len(&Message::End(End { ticks: 1 })), 6 + 4 + 4);
        assert_eq!(raw_len(&Message::Report(report)), 6 + 60 + 4);
        assert!(raw_len(&Message::Report(report)) <= MAX_FRAME_LEN);

        // Byte 0 version, bytes 1..5 seq LE, byte 5 kind.
        let f = Frame {
            version: VERSION,
            seq: 0x0403_0201,
            message: Message::End(End { ticks: 0x0807_0605 }),
        };
        let mut b = [0u8; MAX_FRAME_LEN];
        let raw = postcard::to_slice(&f, &mut b).unwrap();
        assert_eq!(raw, &[VERSION, 1, 2, 3, 4, 3, 5, 6, 7, 8]);
    }

    #[test]
    fn each_check_has_its_error() {
        let mut wire = [0u8; MAX_WIRE_LEN];
        let n = encode(1, &Message::Command(command()), &mut wire).unwrap();
        let good = &wire[..n - 1];

        // A flipped payload bit: CRC.
        let mut bad = good.to_vec();
        bad[10] ^= 0x40;
        if bad[10] == 0 {
            bad[10] = 0x40;
        }
        assert!(matches!(
            decode(&bad),
            Err(LinkError::Crc | LinkError::Cobs)
        ));

        // A frame cut short: COBS or truncated.
        assert!(matches!(
            decode(&good[..5]),
            Err(LinkError::Cobs | LinkError::Truncated | LinkError::Crc)
        ));
        assert_eq!(decode(&[]), Err(LinkError::Truncated));
        assert_eq!(decode(&[0x55; MAX_WIRE_LEN + 1]), Err(LinkError::Overflow));

        // Re-encode a raw frame with a CRC that matches but another version / kind / tail.
        let reframe = |raw: &[u8]| {
            let mut v = raw.to_vec();
            v.extend_from_slice(&CRC32.checksum(raw).to_le_bytes());
            let mut out = [0u8; 200];
            let n = cobs::try_encode(&v, &mut out).unwrap();
            out[..n].to_vec()
        };
        let mut raw = vec![VERSION, 1, 0, 0, 0, 3, 1, 0, 0, 0];
        assert!(decode(&reframe(&raw)).is_ok());
        raw[0] = 1; // the version before the optional readings
        assert_eq!(decode(&reframe(&raw)), Err(LinkError::Version(1)));
        raw[0] = VERSION;
        raw[5] = KINDS;
        assert_eq!(decode(&reframe(&raw)), Err(LinkError::UnknownKind(KINDS)));
        raw[5] = 3;
        raw.push(9);
        assert_eq!(decode(&reframe(&raw)), Err(LinkError::Malformed));
        raw.truncate(8);
        assert_eq!(decode(&reframe(&raw)), Err(LinkError::Truncated));

        // An optional reading whose tag is neither 0 (absent) nor 1 (present).
        let sample = Sample {
            tick: 0,
            status: SAMPLE_VALID,
            length_m: 1.0,
            reel_rate_mps: None,
            tension_n: None,
            alpha_rad: None,
            alpha_rate_radps: None,
            orbit_rate_radps: 1e-3,
            true_anomaly_rad: 0.0,
        };
        let mut raw = [0u8; MAX_FRAME_LEN];
        let frame = Frame {
            version: VERSION,
            seq: 0,
            message: Message::Sample(sample),
        };
        let len = postcard::to_slice(&frame, &mut raw).unwrap().len();
        // version, seq, kind, tick, status, length: the reel rate's tag is byte 6 + 9.
        assert_eq!(raw[HEADER_LEN + 9], 0);
        raw[HEADER_LEN + 9] = 2;
        assert_eq!(decode(&reframe(&raw[..len])), Err(LinkError::Malformed));

        // An unknown enumeration code in a Command.
        let mut c = command();
        c.phase = 9;
        let n = encode(1, &Message::Command(c), &mut wire).unwrap();
        assert_eq!(decode(&wire[..n - 1]), Err(LinkError::Malformed));
    }

    #[test]
    fn the_reader_resynchronises_after_garbage_and_overflow() {
        let mut r = FrameReader::new();
        let mut wire = [0u8; MAX_WIRE_LEN];
        let n = encode(5, &Message::End(End { ticks: 3 }), &mut wire).unwrap();
        let mut got = heapless::Vec::<Result<Frame, LinkError>, 8>::new();
        let mut feed = |bytes: &[u8], r: &mut FrameReader| {
            for &b in bytes {
                if let Some(x) = r.push(b) {
                    got.push(x).unwrap();
                }
            }
        };
        feed(&[0, 0, 1, 2, 3, 0], &mut r); // idle, then garbage
        feed(&[0x77; 300], &mut r); // an overlong run…
        feed(&[0], &mut r); // … ends at its delimiter
        feed(&wire[..n], &mut r);
        assert_eq!(got.len(), 3);
        assert!(got[0].is_err());
        assert_eq!(got[1], Err(LinkError::Overflow));
        assert_eq!(got[2].unwrap().seq, 5);
    }

    #[test]
    fn the_gate_drops_duplicates_and_late_frames_and_counts_gaps() {
        let mut g = SampleGate::new();
        let mut c = LinkCounters::default();
        assert_eq!(g.check(0, s(0), 0, &mut c), Gate::Accept(s(0)));
        assert_eq!(g.check(0, s(0), 1, &mut c), Gate::Duplicate);
        assert_eq!(g.check(2, s(2), 1, &mut c), Gate::Accept(s(2)));
        assert_eq!(g.check(1, s(1), 3, &mut c), Gate::OutOfOrder);
        assert_eq!(g.check(3, s(3), 3, &mut c), Gate::Accept(s(3)));
        g.close(4, &mut c);
        assert_eq!(
            (c.frames_ok, c.duplicates, c.out_of_order, c.seq_gaps),
            (3, 1, 1, 1)
        );
    }

    /// Issue 16 §4: frames lost before the first that arrives and after the last are gaps too.
    #[test]
    fn the_gate_counts_frames_lost_at_the_start_and_the_end() {
        let mut g = SampleGate::new();
        let mut c = LinkCounters::default();
        // Frames 0 and 1 (ticks 0 and 1) lost; the first to arrive is number 2.
        assert_eq!(g.check(2, s(2), 0, &mut c), Gate::Accept(s(2)));
        assert_eq!(c.seq_gaps, 2);
        assert_eq!(g.check(3, s(3), 3, &mut c), Gate::Accept(s(3)));
        // Frames 4 and 5 lost; End is number 6.
        g.close(6, &mut c);
        assert_eq!(c.seq_gaps, 4);

        // Nothing arrives at all: every frame before End is a gap.
        let mut g = SampleGate::new();
        let mut c = LinkCounters::default();
        g.close(7, &mut c);
        assert_eq!(c.seq_gaps, 7);
    }

    fn s(tick: u32) -> Sample {
        Sample {
            tick,
            status: SAMPLE_VALID,
            length_m: 1.0,
            reel_rate_mps: None,
            tension_n: None,
            alpha_rad: Some(0.0),
            alpha_rate_radps: None,
            orbit_rate_radps: 1e-3,
            true_anomaly_rad: 0.0,
        }
    }

    #[test]
    fn every_fault_code_roundtrips() {
        for f in SENSOR_FAULTS
            .into_iter()
            .map(Fault::Sensor)
            .chain(LAW_FAULTS.into_iter().map(Fault::Law))
        {
            assert_eq!(fault_from_code(fault_code(Some(f))), Ok(Some(f)));
        }
        assert_eq!(fault_from_code(0), Ok(None));
        assert_eq!(fault_from_code(0x1f), Err(LinkError::Malformed));
    }

    #[test]
    fn the_config_digest_sees_every_field() {
        let base = crate::controller::Config::<f32>::paper();
        let d = config_digest(&base);
        let mut c = base;
        c.monitor.coast_ticks += 1;
        assert_ne!(config_digest(&c), d);
        let mut c = base;
        c.stage2.start_tick = None;
        assert_ne!(config_digest(&c), d);
        let mut c = base;
        c.stage2.schedule.high_angle_rad =
            f32::from_bits(c.stage2.schedule.high_angle_rad.to_bits() ^ 1);
        assert_ne!(config_digest(&c), d);
        assert_eq!(config_digest(&base), d);
    }
}
