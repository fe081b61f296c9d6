//! The processor-in-the-loop (PIL) link: the frames the plant (`tss-sim`) and the reel MCU's
//! firmware exchange over a UART, one pair per control period.
//!
//! `no_std`, no allocation, no panics: encoding writes into the caller's buffer and fails with
//! [`LinkError::BufferTooSmall`] if it does not fit; decoding accepts any byte stream and answers
//! every malformed frame with a typed [`LinkError`] (the property test `tests/link.rs` feeds it
//! arbitrary and mutated bytes).
//!
//! # Frame layout (version [`VERSION`] = 4)
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
//!                                  6 Loaded, 7 Packet, 8 Collect
//! 6       n     body               the kind's fields, in declaration order (`messages.rs`)
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
//! Packet  (both ways, n = 2 + len, len = 1 ..= MAX_PACKET_LEN = 297)
//!         len u16, then one CCSDS space packet's len bytes as they are: plant → firmware a
//!         PUS telecommand (before the period's Sample), firmware → plant a PUS telemetry
//!         packet (before the period's Command); len 0 or beyond MAX_PACKET_LEN is
//!         LinkError::Malformed, fewer bytes than len LinkError::Truncated
//! Collect (plant → firmware, after a period's Command when the plant records that period,
//!         n = 4)
//!         tick u32 (the period just answered); the firmware answers with one Packet, the
//!         housekeeping TM[3,25] of that period's step
//! ```
//!
//! A period with telecommands is, on the wire: plant → firmware the telecommands' `Packet`
//! frames, then the `Sample`; firmware → plant each telecommand's verification reports as it
//! takes it, then after its step the completion reports and events, then the `Command`; and,
//! if the plant records the period, plant → firmware `Collect` and firmware → plant the
//! housekeeping. Every frame the plant sends carries the next number of its one sequence, so
//! the receiver's [`SampleGate`] counts a lost frame of any kind as a gap.
//!
//! `opt` is an optional f32 (postcard's `Option`): one byte 0 (absent), or 1 followed by the
//! f32 (any other tag byte is [`LinkError::Malformed`]). Version 1 had no options: a sample
//! carried α and α̇ always, and no reel rate, tension or true anomaly; a command no NIS.
//! Version 2 had no `Params` and `Loaded`: the firmware flew its built-in configuration.
//! Version 3 had no `Packet` and `Collect`: nobody could command the firmware.
//!
//! The largest frame (a Packet with the longest telecommand, the parameter-table load) is
//! 6 + 2 + 297 + 4 = 309 bytes decoded, [`MAX_WIRE_LEN`] on the wire.
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
pub const VERSION: u8 = 4;

/// Decoded header length: version, seq, kind.
pub const HEADER_LEN: usize = 6;

/// Length of the CRC that closes every decoded frame.
pub const CRC_LEN: usize = 4;

/// Largest decoded frame (header, the largest body, CRC), bytes: a `Packet` frame with the
/// longest packet, or the `Params` frame, whichever is longer.
pub const MAX_FRAME_LEN: usize = HEADER_LEN + max(2 + MAX_PACKET_LEN, 4 * PARAM_WORDS) + CRC_LEN;

/// The larger of `a` and `b`, for the constants above (`Ord::max` is not `const`).
const fn max(a: usize, b: usize) -> usize {
    if a > b {
        a
    } else {
        b
    }
}

/// Largest frame on the wire: COBS adds one byte per 254 (and one), plus the `0x00` delimiter.
pub const MAX_WIRE_LEN: usize = MAX_FRAME_LEN + MAX_FRAME_LEN / 254 + 2;

/// Most control periods of one PIL run (ticks 0 ..= `MAX_TICKS` − 1): the firmware ends a
/// longer run as a failure, and the plant refuses such a scenario before it starts. The
/// paper's 20-h mission is 72 001 ticks.
pub const MAX_TICKS: u32 = 200_000;

/// The wire delimiter between frames.
pub const DELIMITER: u8 = 0x00;

/// CRC-32/ISO-HDLC (the Ethernet/zlib CRC): poly 0x04C11DB7 reflected, init and xorout all ones.
/// Bitwise, without the 1 KiB lookup table: flash is tight, and a frame is at most `MAX_FRAME_LEN` (309) bytes.
const CRC32: crc::Crc<u32, crc::NoTable> =
    crc::Crc::<u32, crc::NoTable>::new(&crc::CRC_32_ISO_HDLC);

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
mod error;
mod gate;
mod messages;
mod packet;
mod params;

pub use codes::{
    fault_code, fault_from_code, health_code, health_from_code, phase_code, phase_from_code,
};
pub use digest::{config_digest, fnv1a, fnv1a_f32, fnv1a_start};
pub use error::LinkError;
pub use gate::{Gate, SampleGate};
pub use messages::{
    Collect, Command, End, Hello, LinkCounters, LoadVerdict, Loaded, Message, Report, Sample,
    SampleStatus, KINDS, NO_PARAM, SAMPLE_MISSING, SAMPLE_VALID,
};
pub use packet::{Packet, MAX_PACKET_LEN};
pub use params::{
    param_index, rule_code, rule_from_code, ParamTable, TableError, WordKind, PARAMS, PARAM_WORDS,
};

#[cfg(test)]
mod tests;
