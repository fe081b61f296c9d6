extern crate std;
use super::codes::{LAW_FAULTS, SENSOR_FAULTS};
use super::*;
use crate::controller::Fault;
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
    feed(&[0x77; MAX_WIRE_LEN + 1], &mut r); // an overlong run…
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

/// Frames lost before the first that arrives and after the last are gaps too.
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
