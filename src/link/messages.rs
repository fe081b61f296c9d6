//! The link's messages: what each frame kind carries, field by field (the wire layout is in
//! the module docs of `link`; `codes.rs` converts a command to and from the controller's
//! output).

use serde::{Deserialize, Serialize};

#[cfg(doc)]
use super::digest::{config_digest, fnv1a_f32};
#[cfg(doc)]
use super::params::{rule_code, TableError, PARAMS};
#[cfg(doc)]
use crate::controller::Output;

use super::error::LinkError;
use super::packet::Packet;
use super::params::ParamTable;

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
    /// [`Output::phase`] ([`phase_code`](crate::link::phase_code)).
    pub phase: u8,
    /// [`Output::health`] ([`health_code`](crate::link::health_code)).
    pub health: u8,
    /// [`Output::fault`] ([`fault_code`](crate::link::fault_code)).
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

/// `Collect`: the plant records the period `tick` that the firmware has just answered, and
/// asks for its housekeeping (PUS TM\[3,25\] at the collection interval, the plant's output
/// interval); the firmware answers with that one telemetry packet in a `Packet` frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Collect {
    /// The period whose step the housekeeping reports (the last one the firmware answered).
    #[serde(with = "postcard::fixint::le")]
    pub tick: u32,
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
// The parameter table and a space packet are the large bodies; a no_std link has no heap to
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
    /// Kind 7, both ways: a PUS telecommand plant → firmware, a PUS telemetry packet
    /// firmware → plant.
    Packet(Packet),
    /// Kind 8, plant → firmware.
    Collect(Collect),
}

/// Number of message kinds (kind bytes `0 .. KINDS`).
pub const KINDS: u8 = 9;
