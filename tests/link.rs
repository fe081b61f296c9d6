//! The PIL frame codec (`tss_reel::link`) never panics and never accepts garbage, whatever the
//! bytes: property tests over arbitrary byte streams and over valid frames with random damage.
//!
//! Each property runs [`CASES`] cases (proptest's own shrinking and regression file apply).
//! A panic anywhere in `decode` or `FrameReader::push` fails the test.

use proptest::prelude::*;
use tss_reel::link::{
    decode, encode, Collect, Command, End, Frame, FrameReader, Gate, Hello, LinkCounters,
    LinkError, LoadVerdict, Loaded, Message, Packet, ParamTable, Report, Sample, SampleGate,
    DELIMITER, MAX_FRAME_LEN, MAX_PACKET_LEN, MAX_WIRE_LEN, PARAM_WORDS, SAMPLE_MISSING,
    SAMPLE_VALID, VERSION,
};
use tss_reel::pus::{self, ModeCommand, Telecommand, MAX_TC_LEN, MAX_TM_LEN};

/// Cases per property: the issue asks for at least 100 000 on the decoder. `TSS_LINK_CASES`
/// asks for more (a longer fuzzing run by hand).
const CASES: u32 = 100_000;

fn config() -> ProptestConfig {
    let cases = std::env::var("TSS_LINK_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .map_or(CASES, |n: u32| n.max(CASES));
    ProptestConfig {
        cases,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// Any f32 bit pattern (NaNs, infinities, subnormals included).
fn any_f32() -> impl Strategy<Value = f32> {
    any::<u32>().prop_map(f32::from_bits)
}

/// An optional reading: absent, or any f32 bit pattern.
fn any_opt_f32() -> impl Strategy<Value = Option<f32>> {
    proptest::option::of(any_f32())
}

fn sample() -> impl Strategy<Value = Sample> {
    (
        (any::<u32>(), 0..=SAMPLE_MISSING, any_f32()),
        (any_opt_f32(), any_opt_f32(), any_opt_f32(), any_opt_f32()),
        (any_f32(), any_f32()),
    )
        .prop_map(|((tick, status, l), (v, t, a, ad), (n, theta))| Sample {
            tick,
            status,
            length_m: l,
            reel_rate_mps: v,
            tension_n: t,
            alpha_rad: a,
            alpha_rate_radps: ad,
            orbit_rate_radps: n,
            true_anomaly_rad: theta,
        })
}

fn command() -> impl Strategy<Value = Command> {
    (
        any::<u32>(),
        0u8..4,
        proptest::array::uniform10(any_f32()),
        0u8..5,
        0u8..3,
        prop_oneof![Just(0u8), 0x10u8..0x1b, 0x20u8..0x24],
        (any::<u32>(), any_opt_f32()),
    )
        .prop_map(
            |(tick, sample, f, phase, health, fault, (flags, nis))| Command {
                tick,
                sample,
                rate_cmd_mps: f[0],
                accel_cmd_mps2: f[1],
                law_rate_mps: f[2],
                blend_weight: f[3],
                alpha_ref_rad: f[4],
                alpha_ref_rate_radps: f[5],
                delta_rad: f[6],
                delta_rate_radps: f[7],
                length_estimate_m: f[8],
                equilibrium_margin: f[9],
                nis,
                phase,
                health,
                fault,
                flags,
            },
        )
}

fn message() -> impl Strategy<Value = Message> {
    prop_oneof![
        sample().prop_map(Message::Sample),
        command().prop_map(Message::Command),
        (any::<u32>(), any::<u32>(), any::<u8>()).prop_map(|(d, p, t)| Message::Hello(Hello {
            config_digest: d,
            period_ms: p,
            timeout_periods: t,
        })),
        any::<u32>().prop_map(|ticks| Message::End(End { ticks })),
        proptest::collection::vec(any::<u32>(), PARAM_WORDS).prop_map(|v| {
            let mut words = [0u32; PARAM_WORDS];
            words.copy_from_slice(&v);
            Message::Params(ParamTable { words })
        }),
        (
            any::<u32>(),
            0..=LoadVerdict::Refused as u8,
            any::<u8>(),
            any::<u8>()
        )
            .prop_map(
                |(config_digest, verdict, param, rule)| Message::Loaded(Loaded {
                    config_digest,
                    verdict,
                    param,
                    rule,
                })
            ),
        proptest::collection::vec(any::<u8>(), 1..=MAX_PACKET_LEN)
            .prop_map(|b| Message::Packet(Packet::new(&b).expect("1 ..= MAX_PACKET_LEN bytes"))),
        any::<u32>().prop_map(|tick| Message::Collect(Collect { tick })),
        (
            proptest::array::uniform13(any::<u32>()),
            any::<u32>(),
            any::<u32>()
        )
            .prop_map(|(c, commands, digest)| Message::Report(Report {
                counters: LinkCounters {
                    frames_ok: c[0],
                    timeouts: c[1],
                    cobs_errors: c[2],
                    truncated: c[3],
                    crc_errors: c[4],
                    version_errors: c[5],
                    unknown_kind: c[6],
                    malformed: c[7],
                    wrong_kind: c[8],
                    overflows: c[9],
                    duplicates: c[10],
                    out_of_order: c[11],
                    seq_gaps: c[12],
                },
                commands,
                digest,
            })),
    ]
}

fn wire(seq: u32, m: &Message) -> Vec<u8> {
    let mut buf = [0u8; MAX_WIRE_LEN];
    let n = encode(seq, m, &mut buf).expect("every message fits MAX_WIRE_LEN");
    buf[..n].to_vec()
}

/// Bit-exact equality (NaN payloads included), which `PartialEq` on f32 fields is not.
fn same(a: &Frame, b: &Frame) -> bool {
    format!("{a:?}") == format!("{b:?}") && wire(a.seq, &a.message) == wire(b.seq, &b.message)
}

/// Every frame the reader gets out of `bytes`.
fn read_all(bytes: &[u8]) -> Vec<Result<Frame, LinkError>> {
    let mut r = FrameReader::new();
    bytes.iter().filter_map(|&b| r.push(b)).collect()
}

proptest! {
    #![proptest_config(config())]

    /// Arbitrary bytes (of any length up to twice the largest frame): `decode` returns, and the
    /// reader splits them at the delimiters without panicking.
    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2 * MAX_WIRE_LEN)) {
        let _ = decode(&bytes);
        let frames = read_all(&bytes);
        prop_assert!(frames.len() <= bytes.iter().filter(|&&b| b == DELIMITER).count());
    }

    /// Every message survives encode → reader → decode bit for bit.
    #[test]
    fn valid_frames_roundtrip(seq in any::<u32>(), m in message()) {
        let w = wire(seq, &m);
        prop_assert!(w.len() <= MAX_WIRE_LEN);
        let frames = read_all(&w);
        prop_assert_eq!(frames.len(), 1);
        let f = frames[0].expect("a valid frame decodes");
        let expected = Frame { version: tss_reel::link::VERSION, seq, message: m };
        prop_assert!(same(&f, &expected));
    }

    /// A valid frame with 1..4 random byte changes, deletions or insertions (delimiters kept
    /// out of the body so that it stays one frame): never a panic, and whatever decodes is a
    /// valid frame again (the CRC lets a random change through with probability 2⁻³²).
    #[test]
    fn mutated_frames_are_rejected(
        seq in any::<u32>(),
        m in message(),
        edits in proptest::collection::vec((0u8..3, any::<prop::sample::Index>(), 1u8..=255), 1..4),
    ) {
        let w = wire(seq, &m);
        let mut body = w[..w.len() - 1].to_vec();
        for (op, at, byte) in edits {
            match op {
                0 if !body.is_empty() => {
                    let i = at.index(body.len());
                    body[i] = if body[i] == byte { byte.wrapping_add(1).max(1) } else { byte };
                }
                1 if !body.is_empty() => {
                    body.remove(at.index(body.len()));
                }
                _ => body.insert(at.index(body.len() + 1), byte),
            }
        }
        let changed = body != w[..w.len() - 1];
        let mut framed = body.clone();
        framed.push(DELIMITER);
        let frames = read_all(&framed);
        prop_assert!(frames.len() <= 1);
        if changed {
            if let Some(Ok(f)) = frames.first() {
                // Only a CRC collision could get here; the frame is then still well formed.
                prop_assert_eq!(f.version, tss_reel::link::VERSION);
            }
        }
        let _ = decode(&body);
    }

    /// A stream of valid frames and garbage: every valid frame after a delimiter is recovered.
    #[test]
    fn the_reader_resynchronises(
        parts in proptest::collection::vec(
            prop_oneof![
                (any::<u32>(), message()).prop_map(|(s, m)| (true, wire(s, &m))),
                proptest::collection::vec(any::<u8>(), 0..40).prop_map(|g| (false, g)),
            ],
            1..6,
        ),
    ) {
        let mut stream = Vec::new();
        let mut valid = 0;
        for (is_frame, bytes) in &parts {
            if *is_frame {
                // Garbage before it may lack a closing delimiter: a leading one resynchronises.
                stream.push(DELIMITER);
                valid += 1;
            }
            stream.extend_from_slice(bytes);
        }
        let ok = read_all(&stream).into_iter().filter(|r| r.is_ok()).count();
        prop_assert!(ok >= valid);
    }
}

/// A decoded frame's bytes `raw` (header and body) closed by their CRC and COBS-encoded, as
/// a sender that does not follow the layout would put them on the wire.
fn forge(raw: &[u8]) -> Vec<u8> {
    const CRC32: crc::Crc<u32, crc::NoTable> =
        crc::Crc::<u32, crc::NoTable>::new(&crc::CRC_32_ISO_HDLC);
    let mut v = raw.to_vec();
    v.extend_from_slice(&CRC32.checksum(raw).to_le_bytes());
    let mut out = vec![0u8; v.len() + v.len() / 254 + 2];
    let n = cobs::try_encode(&v, &mut out).unwrap();
    out.truncate(n);
    out
}

/// The header and body of a `Packet` frame (kind 7) that declares `len` bytes and carries
/// `bytes`.
fn packet_frame(len: u16, bytes: &[u8]) -> Vec<u8> {
    let mut raw = vec![VERSION, 9, 0, 0, 0, 7];
    raw.extend_from_slice(&len.to_le_bytes());
    raw.extend_from_slice(bytes);
    raw
}

/// The longest telecommand (the parameter-table load) and telemetry packet (housekeeping)
/// each travel in one `Packet` frame and come out byte for byte, in the documented layout.
#[test]
fn packets_roundtrip_in_the_documented_layout() {
    assert_eq!(MAX_PACKET_LEN, MAX_TC_LEN.max(MAX_TM_LEN));
    let table = ParamTable::from_config(&tss_reel::controller::Config::flight());
    let mut tc = [0u8; MAX_TC_LEN];
    let n = pus::encode(&Telecommand::LoadParams(table), 5, &mut tc).unwrap();
    assert_eq!(n, MAX_TC_LEN);
    let mut hold = [0u8; MAX_TC_LEN];
    let short = pus::encode(&Telecommand::Mode(ModeCommand::Hold), 6, &mut hold).unwrap();
    for bytes in [
        &tc[..n],
        &hold[..short],
        &[0u8; MAX_TM_LEN][..],
        &[0x18][..],
    ] {
        let m = Message::Packet(Packet::new(bytes).unwrap());
        let w = wire(9, &m);
        assert!(w.len() <= MAX_WIRE_LEN);
        let f = decode(&w).unwrap();
        assert_eq!(f.message, m);
        let Message::Packet(p) = f.message else {
            unreachable!()
        };
        assert_eq!(p.bytes(), bytes);
        // Kind 7, its length u16 little-endian, its bytes: the same as a frame forged by hand.
        assert_eq!(
            w[..w.len() - 1],
            forge(&packet_frame(bytes.len() as u16, bytes))[..]
        );
    }
    // The longest packet makes the longest frame (header, length, packet, CRC).
    assert_eq!(MAX_FRAME_LEN, packet_frame(0, &tc[..n]).len() + 4);
}

/// A packet cut short (fewer bytes than its length says, or not even its length) is
/// truncated; an empty one, or one longer than the longest telecommand or telemetry packet
/// (declared or carried), is malformed; neither is ever handed on.
#[test]
fn truncated_empty_and_oversized_packets_are_rejected() {
    let bytes = [0x18u8; MAX_PACKET_LEN + 1];
    assert!(decode(&forge(&packet_frame(20, &bytes[..20]))).is_ok());
    assert_eq!(
        decode(&forge(&packet_frame(20, &bytes[..19]))),
        Err(LinkError::Truncated)
    );
    assert_eq!(
        decode(&forge(&packet_frame(
            MAX_PACKET_LEN as u16,
            &bytes[..MAX_PACKET_LEN - 1]
        ))),
        Err(LinkError::Truncated)
    );
    assert_eq!(
        decode(&forge(&[VERSION, 9, 0, 0, 0, 7, 20])),
        Err(LinkError::Truncated)
    );
    assert_eq!(
        decode(&forge(&packet_frame(0, &[]))),
        Err(LinkError::Malformed)
    );
    assert_eq!(
        decode(&forge(&packet_frame(20, &bytes[..21]))),
        Err(LinkError::Malformed),
        "bytes beyond the declared length"
    );
    // Declared longer than the longest packet, with the bytes to match or without them.
    assert_eq!(
        decode(&forge(&packet_frame(MAX_PACKET_LEN as u16 + 1, &bytes))),
        Err(LinkError::Overflow),
        "a frame longer than the longest one overflows the receiver first"
    );
    assert_eq!(
        decode(&forge(&packet_frame(
            MAX_PACKET_LEN as u16 + 1,
            &bytes[..4]
        ))),
        Err(LinkError::Malformed)
    );
    assert_eq!(
        decode(&forge(&packet_frame(u16::MAX, &bytes[..4]))),
        Err(LinkError::Malformed)
    );
    // The sender cannot make one either.
    assert_eq!(Packet::new(&[]), None);
    assert_eq!(Packet::new(&bytes), None);
    assert!(Packet::new(&bytes[..MAX_PACKET_LEN]).is_some());
}

/// What the plant's injector does to one sample frame (`host-sim/src/pil.rs`).
#[derive(Clone, Copy, Debug)]
enum Fault {
    None,
    /// Not sent.
    Drop,
    /// Sent damaged: the decoder rejects it, the gate never sees it.
    Corrupt,
    /// Sent twice.
    Duplicate,
    /// Held back and sent just before the next frame (or before `End`).
    Reorder,
}

fn fault() -> impl Strategy<Value = Fault> {
    prop_oneof![
        Just(Fault::None),
        Just(Fault::Drop),
        Just(Fault::Corrupt),
        Just(Fault::Duplicate),
        Just(Fault::Reorder),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 10_000, ..config() })]

    /// The end-of-run accounting is exact whatever the loss pattern, lost first
    /// and last frames included: the gate, fed what the firmware would receive period by
    /// period and closed by `End`, counts exactly the faults the plant injected. Telecommand
    /// packets before a period's sample and housekeeping requests after its command are
    /// numbered in the same sequence (a held sample goes out before them): they are no gaps.
    #[test]
    fn the_gate_counts_exactly_under_any_loss_pattern(
        periods in proptest::collection::vec((fault(), 0..3u32, any::<bool>()), 0..300),
    ) {
        let sample = |tick| Sample {
            tick,
            status: SAMPLE_VALID,
            length_m: 1.0,
            reel_rate_mps: None,
            tension_n: None,
            alpha_rad: Some(0.0),
            alpha_rate_radps: None,
            orbit_rate_radps: 1e-3,
            true_anomaly_rad: 0.0,
        };
        let mut gate = SampleGate::new();
        let mut c = LinkCounters::default();
        // The held sample frame: its number and tick.
        let mut held: Option<(u32, u32)> = None;
        let mut seq = 0u32;
        let (mut lost, mut duplicated, mut reordered, mut accepted) = (0u32, 0u32, 0u32, 0u32);
        // A late sample arrives while the firmware awaits the period after it.
        let late = |gate: &mut SampleGate, c: &mut LinkCounters, held: &mut Option<(u32, u32)>| {
            match held.take() {
                Some((n, tick)) => {
                    prop_assert_eq!(gate.check(n, sample(tick), tick + 1, c), Gate::OutOfOrder);
                    Ok(())
                }
                None => Ok(()),
            }
        };
        for (tick, &(f, telecommands, collect)) in (0u32..).zip(&periods) {
            late(&mut gate, &mut c, &mut held)?;
            for _ in 0..telecommands {
                gate.other(seq, &mut c);
                seq += 1;
            }
            let n = seq;
            seq += 1;
            let mut arrive = |gate: &mut SampleGate, c: &mut LinkCounters| {
                match gate.check(n, sample(tick), tick, c) {
                    Gate::Accept(s) => {
                        prop_assert_eq!(s.tick, tick);
                        accepted += 1;
                        Ok(())
                    }
                    Gate::Duplicate | Gate::OutOfOrder => Ok(()),
                }
            };
            match f {
                Fault::None => arrive(&mut gate, &mut c)?,
                Fault::Drop | Fault::Corrupt => lost += 1,
                Fault::Duplicate => {
                    duplicated += 1;
                    arrive(&mut gate, &mut c)?;
                    arrive(&mut gate, &mut c)?;
                }
                Fault::Reorder => {
                    reordered += 1;
                    held = Some((n, tick));
                }
            }
            if collect {
                late(&mut gate, &mut c, &mut held)?;
                gate.other(seq, &mut c);
                seq += 1;
            }
        }
        late(&mut gate, &mut c, &mut held)?;
        gate.close(seq, &mut c);
        prop_assert_eq!(c.seq_gaps, lost);
        prop_assert_eq!(c.duplicates, duplicated);
        prop_assert_eq!(c.out_of_order, reordered);
        prop_assert_eq!(c.frames_ok, accepted);
        prop_assert_eq!(accepted + lost + reordered, periods.len() as u32);
    }
}
