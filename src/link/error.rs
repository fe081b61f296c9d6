//! Why a frame was rejected, in the order the receiver checks (see the module docs of
//! `link`).

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
    /// Protocol version other than [`VERSION`](crate::link::VERSION) (the value received).
    Version(u8),
    /// A kind byte that no message has.
    UnknownKind(u8),
    /// Well framed and checksummed, but a field is invalid (trailing bytes, enumeration code).
    Malformed,
    /// A valid frame of another kind than the receiver expected.
    WrongKind,
    /// A frame longer than the receive buffer ([`MAX_WIRE_LEN`](crate::link::MAX_WIRE_LEN)); discarded up to the next
    /// delimiter.
    Overflow,
    /// The caller's output buffer cannot hold the encoded frame (encoding only).
    BufferTooSmall,
}
