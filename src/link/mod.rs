//! The processor-in-the-loop (PIL) link: the frames the plant (`tss-sim`) and the reel MCU's
//! firmware exchange over a UART, one pair per control period.
//!
//! `no_std`, no allocation, no panics: encoding writes into the caller's buffer and fails with
//! [`LinkError::BufferTooSmall`] if it does not fit; decoding accepts any byte stream and answers
//! every malformed frame with a typed [`LinkError`] (the property test `tests/link.rs` feeds it
//! arbitrary and mutated bytes).
//!
//! # Frame layout (version [`VERSION`] = 3)
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
//! 5       1     kind     u8        0 Hello, 1 Sample, 2 Command, 3 End, 4 Report, 5 Params,
//!                                  6 Loaded
//! 6       n     body               the kind's fields, in declaration order (below)
//! 6+n     4     crc      u32       CRC-32/ISO-HDLC over bytes 0 .. 6+n
//! ```
//!
//! Bodies (`n` bytes):
//!
//! ```text
//! Hello   (firmware → plant, once at start, n = 9)
//!         config_digest u32 (of its built-in configuration, Config::flight), period_ms u32,
//!         timeout_periods u8
//! Params  (plant → firmware, once, after Hello, n = 4 × PARAM_WORDS = 280)
//!         the controller configuration to fly, as the parameter table (params.rs): its
//!         words, u32 each
//! Loaded  (firmware → plant, the answer to Params, n = 7)
//!         config_digest u32 (of the configuration now flown; 0 if refused), verdict u8
//!         (LoadVerdict), param u8 (the index of the word at fault, 0xff: none or a group),
//!         rule u8 (rule_code of the core's refusal, 0 otherwise)
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
//! Version 2 had no `Params` and `Loaded`: the firmware flew its built-in configuration.
//!
//! The largest frame (Params) is 6 + 280 + 4 = 290 bytes decoded, [`MAX_WIRE_LEN`] on the wire.
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

#[cfg(doc)]
use crate::controller::Output;

/// Protocol version carried in byte 0 of every frame (see the module docs).
pub const VERSION: u8 = 3;

/// Decoded header length: version, seq, kind.
pub const HEADER_LEN: usize = 6;

/// Length of the CRC that closes every decoded frame.
pub const CRC_LEN: usize = 4;

/// Largest decoded frame (header, the largest body, CRC), bytes: the `Params` frame's.
pub const MAX_FRAME_LEN: usize = HEADER_LEN + 4 * PARAM_WORDS + CRC_LEN;

/// Largest frame on the wire: COBS adds one byte per 254 (and one), plus the `0x00` delimiter.
pub const MAX_WIRE_LEN: usize = MAX_FRAME_LEN + MAX_FRAME_LEN / 254 + 2;

/// Most control periods of one PIL run (ticks 0 ..= `MAX_TICKS` − 1): the firmware ends a
/// longer run as a failure, and the plant refuses such a scenario before it starts. The
/// paper's 20-h mission is 72 001 ticks.
pub const MAX_TICKS: u32 = 200_000;

/// The wire delimiter between frames.
pub const DELIMITER: u8 = 0x00;

/// CRC-32/ISO-HDLC (the Ethernet/zlib CRC): poly 0x04C11DB7 reflected, init and xorout all ones.
/// Bitwise, without the 1 KiB lookup table: flash is tight, and a frame is at most `MAX_FRAME_LEN` (290) bytes.
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

/// How the firmware judged a [`Message::Params`] table ([`Loaded::verdict`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LoadVerdict {
    /// The configuration is flown from the next period on.
    Accepted = 0,
    /// The table is not the shape of a configuration ([`TableError`]).
    BadTable = 1,
    /// The core refused the configuration ([`crate::config::Config::validate`]).
    Refused = 2,
}

impl LoadVerdict {
    /// The verdict of a wire code (`None` for an unknown code).
    pub fn from_code(code: u8) -> Option<Self> {
        match code {
            0 => Some(Self::Accepted),
            1 => Some(Self::BadTable),
            2 => Some(Self::Refused),
            _ => None,
        }
    }
}

/// `Loaded`: the firmware's answer to a [`Message::Params`] table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Loaded {
    /// [`config_digest`] of the configuration the firmware now flies (0 if refused).
    #[serde(with = "postcard::fixint::le")]
    pub config_digest: u32,
    /// [`LoadVerdict`] code.
    pub verdict: u8,
    /// Index in [`PARAMS`] of the word at fault ([`NO_PARAM`]: none, or a group of words).
    pub param: u8,
    /// [`rule_code`] of the core's refusal (0 unless the verdict is `Refused`).
    pub rule: u8,
}

/// [`Loaded::param`] when no single word is at fault.
pub const NO_PARAM: u8 = 0xff;

/// One message: the frame's kind and body.
// The parameter table is the one large body, sent once a run; a no_std link has no heap to
// box it in, and a message lives in one receive slot whatever its kind.
#[allow(clippy::large_enum_variant)]
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
    /// Kind 5, plant → firmware.
    Params(ParamTable),
    /// Kind 6, firmware → plant.
    Loaded(Loaded),
}

/// Number of message kinds (kind bytes `0 .. KINDS`).
pub const KINDS: u8 = 7;

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
    if let Message::Loaded(l) = &frame.message {
        LoadVerdict::from_code(l.verdict).ok_or(LinkError::Malformed)?;
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

mod codes;
mod digest;
mod gate;
mod params;

pub use codes::{
    fault_code, fault_from_code, health_code, health_from_code, phase_code, phase_from_code,
};
pub use digest::{config_digest, fnv1a, fnv1a_f32, fnv1a_start};
pub use gate::{Gate, SampleGate};
pub use params::{
    param_index, rule_code, rule_from_code, ParamTable, TableError, WordKind, PARAMS, PARAM_WORDS,
};

#[cfg(test)]
mod tests;
