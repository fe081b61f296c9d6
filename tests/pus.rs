//! The telecommand decoder (`tss_reel::pus`) never panics and never accepts garbage, whatever
//! the bytes: property tests over arbitrary byte strings and over valid telecommands with random
//! damage.
//!
//! Each property runs [`CASES`] cases; `TSS_PUS_CASES` asks for more (the 1e6 packets:
//! `TSS_PUS_CASES=1000000 cargo test --release --test pus -- --nocapture` prints the figures).
//! A panic anywhere in `decode` fails the test.

use proptest::prelude::*;
use tss_reel::link::{ParamTable, PARAM_WORDS};
use tss_reel::pus::{decode, encode, ModeCommand, Reason, RequestId, Telecommand, MAX_TC_LEN};

/// Cases per property in CI.
const CASES: u32 = 20_000;

fn cases() -> u32 {
    std::env::var("TSS_PUS_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .map_or(CASES, |n: u32| n.max(CASES))
}

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: cases(),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

fn telecommand() -> impl Strategy<Value = Telecommand> {
    prop_oneof![
        (1u16..=5).prop_map(|i| Telecommand::Mode(ModeCommand::from_id(i).unwrap())),
        any::<u32>().prop_map(Telecommand::SetTime),
        proptest::collection::vec(any::<u32>(), PARAM_WORDS).prop_map(|v| {
            let mut words = [0u32; PARAM_WORDS];
            words.copy_from_slice(&v);
            Telecommand::LoadParams(ParamTable { words })
        }),
    ]
}

/// A valid telecommand's bytes.
fn packet(c: &Telecommand, seq: u16) -> Vec<u8> {
    let mut buf = [0u8; MAX_TC_LEN];
    let n = encode(c, seq, &mut buf).expect("every telecommand fits MAX_TC_LEN");
    buf[..n].to_vec()
}

proptest! {
    #![proptest_config(config())]

    /// Arbitrary bytes: never a panic; a rejection names the packet by its first four bytes.
    #[test]
    fn arbitrary_bytes_are_rejected_or_decoded_never_a_panic(
        bytes in proptest::collection::vec(any::<u8>(), 0..=MAX_TC_LEN + 16)
    ) {
        match decode(&bytes) {
            Ok(r) => {
                // Whatever decodes is a telecommand that encodes back to these very bytes.
                prop_assert_eq!(Some(r.id), RequestId::of(&bytes));
                prop_assert_eq!(packet(&r.command, r.id.sequence), bytes);
            }
            Err(e) => prop_assert_eq!(e.id, RequestId::of(&bytes)),
        }
    }

    /// A valid telecommand decodes to itself; with one byte changed, cut short or extended it is
    /// rejected (the CRC-16 catches every single-byte change).
    #[test]
    fn damaged_telecommands_are_rejected(
        c in telecommand(),
        seq in 0u16..0x4000,
        at in any::<prop::sample::Index>(),
        flip in 1u8..=255,
        cut in any::<prop::sample::Index>(),
        extra in proptest::collection::vec(any::<u8>(), 1..8),
    ) {
        let good = packet(&c, seq);
        prop_assert_eq!(decode(&good).map(|r| r.command), Ok(c));

        let mut bad = good.clone();
        let i = at.index(bad.len());
        bad[i] ^= flip;
        let e = decode(&bad);
        prop_assert!(e.is_err(), "a changed byte {} was accepted: {:?}", i, e);

        let short = &good[..cut.index(good.len())];
        prop_assert_eq!(decode(short).map_err(|e| e.reason), Err(Reason::Truncated));

        let mut long = good.clone();
        long.extend_from_slice(&extra);
        prop_assert_eq!(decode(&long).map_err(|e| e.reason), Err(Reason::Oversized));
    }
}

/// The decoder's figures: packets decoded per second over arbitrary bytes (printed, not
/// asserted: the machines are shared).
#[test]
fn decoder_throughput() {
    let n = cases() * 10;
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        rng
    };
    let good = packet(&Telecommand::Mode(ModeCommand::Hold), 1);
    let started = std::time::Instant::now();
    let (mut accepted, mut rejected) = (0u64, 0u64);
    for k in 0..n {
        // Half arbitrary packets of any length, half a valid one with one byte changed.
        let bytes: Vec<u8> = if k % 2 == 0 {
            let len = (next() % (MAX_TC_LEN as u64 + 16)) as usize;
            (0..len).map(|_| next() as u8).collect()
        } else {
            let mut b = good.clone();
            let i = (next() % b.len() as u64) as usize;
            b[i] ^= (next() % 255 + 1) as u8;
            b
        };
        match decode(&bytes) {
            Ok(_) => accepted += 1,
            Err(_) => rejected += 1,
        }
    }
    let secs = started.elapsed().as_secs_f64();
    eprintln!(
        "pus decoder: {n} packets in {secs:.2} s ({:.0} per second): {accepted} accepted, {rejected} rejected",
        f64::from(n) / secs
    );
    assert_eq!(accepted + rejected, u64::from(n));
}
