//! The `Packet` frame's body: one CCSDS space packet (CCSDS 133.0-B-2), a PUS telecommand from
//! the plant (the on-board computer's side) to the firmware, or a PUS telemetry packet back.
//!
//! The link carries the packet's bytes as they are and judges only their length; what they
//! say is for the unit's PUS services to check (`pus::decode`), so that a damaged
//! telecommand reaches the unit and earns its failure report, as on the spacecraft's bus.

use serde::de::{Error as _, SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::params::PARAM_WORDS;

/// The longest packet a `Packet` frame carries, bytes: the parameter-table load, the longest
/// packet either way (a PUS-C telecommand: 13 bytes of headers and error control, then the
/// table's words and their CRC-32). The unit's PUS services check at compile time that every
/// packet they accept or send fits (`pus::MAX_TC_LEN`, `pus::MAX_TM_LEN`).
pub const MAX_PACKET_LEN: usize = 13 + 4 * PARAM_WORDS + 4;

/// One space packet, 1 ..= [`MAX_PACKET_LEN`] bytes (on the wire: its length, u16
/// little-endian, then its bytes).
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct Packet {
    /// Bytes used in `bytes`.
    len: u16,
    /// The packet, zero beyond `len`.
    bytes: [u8; MAX_PACKET_LEN],
}

impl Packet {
    /// The packet `bytes` (`None` if it is empty or longer than [`MAX_PACKET_LEN`]).
    pub fn new(bytes: &[u8]) -> Option<Self> {
        if bytes.is_empty() {
            return None;
        }
        let mut p = Self {
            len: u16::try_from(bytes.len()).ok()?,
            bytes: [0; MAX_PACKET_LEN],
        };
        p.bytes.get_mut(..bytes.len())?.copy_from_slice(bytes);
        Some(p)
    }

    /// The packet's bytes.
    pub fn bytes(&self) -> &[u8] {
        self.bytes.get(..usize::from(self.len)).unwrap_or(&[])
    }
}

impl core::fmt::Debug for Packet {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_tuple("Packet").field(&self.bytes()).finish()
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Packet {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "Packet({=[u8]})", self.bytes());
    }
}

impl Serialize for Packet {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let bytes = self.bytes();
        let mut t = s.serialize_tuple(1 + bytes.len())?;
        t.serialize_element(&self.len.to_le_bytes())?;
        for b in bytes {
            t.serialize_element(b)?;
        }
        t.end()
    }
}

impl<'de> Deserialize<'de> for Packet {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Bytes;
        impl<'de> Visitor<'de> for Bytes {
            type Value = Packet;
            fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                write!(f, "a space packet of 1 to {MAX_PACKET_LEN} bytes")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Packet, A::Error> {
                let len: [u8; 2] = seq
                    .next_element()?
                    .ok_or_else(|| A::Error::invalid_length(0, &self))?;
                let len = u16::from_le_bytes(len);
                let mut p = Packet {
                    len,
                    bytes: [0; MAX_PACKET_LEN],
                };
                let used = p
                    .bytes
                    .get_mut(..usize::from(len))
                    .filter(|used| !used.is_empty())
                    .ok_or_else(|| A::Error::invalid_length(usize::from(len), &self))?;
                for (i, b) in used.iter_mut().enumerate() {
                    *b = seq
                        .next_element()?
                        .ok_or_else(|| A::Error::invalid_length(i, &self))?;
                }
                Ok(p)
            }
        }
        d.deserialize_tuple(1 + MAX_PACKET_LEN, Bytes)
    }
}
