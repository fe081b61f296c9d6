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

// ---- The unit: every telecommand verified, a bad one changes nothing ----

use tss_reel::controller::{Config, Controller, Flags, Input, Mode};
use tss_reel::pus::{read_telemetry, Housekeeping, Services, Stage, Telemetry, MAX_TCS_PER_PERIOD};

const N_RADPS: f32 = 1.060_237_2e-3;

fn sample(tick: u32, length_m: f32) -> Input<f32> {
    Input {
        tick,
        length_m,
        reel_rate_mps: None,
        tension_n: Some(3.0),
        alpha_rad: Some(-0.6),
        alpha_rate_radps: Some(0.0),
        orbit_rate_radps: N_RADPS,
        true_anomaly_rad: 0.0,
    }
}

/// The paper's controller after `ticks` periods on a kinematic reel, its services, and the
/// length it reached.
fn flown(ticks: u32) -> (Controller<f32>, Services, f32) {
    let mut ctl = Controller::new(Config::paper()).unwrap();
    let mut services = Services::new();
    let mut l = 1.0;
    for tick in 0..ticks {
        let x = sample(tick, l);
        let rate = ctl.step(&x).rate_cmd_mps;
        services.after_step(&mut ctl, Some(&x), &mut |_| {});
        l += rate;
    }
    (ctl, services, l)
}

/// The periods flown before the fuzzed telecommand arrives: none (a table may still be
/// loaded), one, and 200 (paying out).
const FLOWN_TICKS: [u32; 3] = [0, 1, 200];

/// [`flown`] at one of [`FLOWN_TICKS`], flown once per test binary.
fn in_flight(ticks: u32) -> &'static (Controller<f32>, Services, f32) {
    static FLOWN: std::sync::OnceLock<Vec<(Controller<f32>, Services, f32)>> =
        std::sync::OnceLock::new();
    let all = FLOWN.get_or_init(|| FLOWN_TICKS.map(flown).into_iter().collect());
    &all[FLOWN_TICKS.iter().position(|&t| t == ticks).unwrap()]
}

/// The unit's answer to one telecommand `bytes`: its telemetry, read back.
fn answer(services: &mut Services, ctl: &mut Controller<f32>, bytes: &[u8]) -> Vec<Telemetry> {
    let mut sent = Vec::new();
    services.telecommand(bytes, ctl, &mut |p| sent.push(p.to_vec()));
    sent.iter()
        .map(|p| {
            read_telemetry(p)
                .expect("the unit's own packets read back")
                .telemetry
        })
        .collect()
}

/// The verification reports in `tm`: (stage, failure code).
fn verification(tm: &[Telemetry]) -> Vec<(Stage, Option<u16>)> {
    tm.iter()
        .filter_map(|t| match t {
            Telemetry::Verification { stage, failure, .. } => Some((*stage, failure.map(|f| f.0))),
            _ => None,
        })
        .collect()
}

/// Arbitrary bytes, a valid telecommand with one byte changed, or a valid telecommand.
fn any_packet() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        proptest::collection::vec(any::<u8>(), 0..=MAX_TC_LEN + 16),
        (
            telecommand(),
            0u16..0x4000,
            any::<prop::sample::Index>(),
            1u8..=255
        )
            .prop_map(|(c, seq, at, flip)| {
                let mut b = packet(&c, seq);
                let i = at.index(b.len());
                b[i] ^= flip;
                b
            }),
        (telecommand(), 0u16..0x4000).prop_map(|(c, seq)| packet(&c, seq)),
    ]
}

proptest! {
    #![proptest_config(config())]

    /// Any packet to a unit in flight: every one with an identity (four bytes) is answered by
    /// service 1 reports naming it, acceptance first; a failure at any stage leaves the
    /// controller as it was (its next step is the one it would have made without the packet).
    #[test]
    fn every_telecommand_is_verified_and_a_failed_one_changes_nothing(
        bytes in any_packet(),
        at_tick in prop::sample::select(FLOWN_TICKS.to_vec()),
    ) {
        let (ctl0, services0, l) = in_flight(at_tick);
        let (mut ctl, mut services) = (ctl0.clone(), services0.clone());
        let tm = answer(&mut services, &mut ctl, &bytes);
        let reports = verification(&tm);
        match RequestId::of(&bytes) {
            None => prop_assert!(reports.is_empty()),
            Some(id) => {
                prop_assert!(!reports.is_empty());
                prop_assert_eq!(reports[0].0, Stage::Acceptance);
                for t in &tm {
                    if let Telemetry::Verification { request, .. } = t {
                        prop_assert_eq!(*request, id);
                    }
                }
            }
        }
        if reports.iter().any(|(_, f)| f.is_some()) {
            let x = sample(at_tick, *l);
            let mut twin = ctl0.clone();
            prop_assert_eq!(ctl.mode(), twin.mode());
            prop_assert_eq!(*ctl.step(&x), *twin.step(&x));
        }
    }
}

#[test]
fn a_mode_command_completes_at_its_boundary_and_the_rest_is_reported() {
    let (mut ctl, mut services, l) = flown(100);
    // An illegal mode: accepted, then refused at its start (code 14: not held).
    let tm = answer(
        &mut services,
        &mut ctl,
        &packet(&Telecommand::Mode(ModeCommand::Resume), 1),
    );
    assert_eq!(
        verification(&tm),
        [(Stage::Acceptance, None), (Stage::Start, Some(14))]
    );
    // Hold: accepted and started now, completed after the step that applied it.
    let tm = answer(
        &mut services,
        &mut ctl,
        &packet(&Telecommand::Mode(ModeCommand::Hold), 2),
    );
    assert_eq!(
        verification(&tm),
        [(Stage::Acceptance, None), (Stage::Start, None)]
    );
    let x = sample(100, l);
    ctl.step(&x);
    let mut sent = Vec::new();
    services.after_step(&mut ctl, Some(&x), &mut |p| sent.push(p.to_vec()));
    let tm: Vec<Telemetry> = sent
        .iter()
        .map(|p| read_telemetry(p).unwrap().telemetry)
        .collect();
    assert_eq!(verification(&tm), [(Stage::Completion, None)]);
    assert!(tm.iter().any(|t| matches!(
        t,
        Telemetry::Event {
            id: 10,
            aux: [2, 0, 0, 0],
            ..
        }
    )));
    let Some(Telemetry::Housekeeping(hk)) = tm.last() else {
        panic!("housekeeping last: {tm:?}");
    };
    assert_eq!(*hk, Housekeeping::of(&ctl, Some(&x)));
    assert_eq!(ctl.mode(), Mode::Held { since_tick: 100 });
    assert!(Flags(hk.flags).contains(Flags::HELD));
    assert_eq!(
        (hk.mode, hk.tension_n, hk.alpha_rad),
        (1, Some(3.0), Some(-0.6))
    );

    // A table after the start: too late (21). Time: completed at once, the stamps move.
    let table = ParamTable::from_config(&Config::paper());
    let tm = answer(
        &mut services,
        &mut ctl,
        &packet(&Telecommand::LoadParams(table), 3),
    );
    assert_eq!(
        verification(&tm),
        [(Stage::Acceptance, None), (Stage::Start, Some(21))]
    );
    let mut sent = Vec::new();
    services.telecommand(
        &packet(&Telecommand::SetTime(50_000), 4),
        &mut ctl,
        &mut |p| sent.push(p.to_vec()),
    );
    assert_eq!(sent.len(), 3);
    let x = sample(101, l);
    ctl.step(&x);
    let mut stamps = Vec::new();
    services.after_step(&mut ctl, Some(&x), &mut |p| {
        stamps.push(read_telemetry(p).unwrap().time)
    });
    assert_eq!(stamps, [50_000]);

    // A flood: the fifth telecommand of a period is refused unread (18).
    let codes: Vec<_> = (0..MAX_TCS_PER_PERIOD + 1)
        .map(|k| {
            let tm = answer(
                &mut services,
                &mut ctl,
                &packet(&Telecommand::SetTime(7), u16::from(k)),
            );
            verification(&tm)[0]
        })
        .collect();
    assert_eq!(codes.last(), Some(&(Stage::Acceptance, Some(18))));
    assert!(codes[..MAX_TCS_PER_PERIOD as usize]
        .iter()
        .all(|c| c.1.is_none()));
}

#[test]
fn a_table_is_loaded_before_the_mission_or_refused_with_its_rule() {
    let mut ctl = Controller::new(Config::paper()).unwrap();
    let mut services = Services::new();
    let mut bad = Config::flight();
    bad.gains.k1_per_s = -1.0;
    let tm = answer(
        &mut services,
        &mut ctl,
        &packet(&Telecommand::LoadParams(ParamTable::from_config(&bad)), 1),
    );
    let Some(Telemetry::Verification {
        failure: Some((20, [7, 2, 0, 0])),
        ..
    }) = tm.last()
    else {
        panic!("refused: word 7 (gains.k1_per_s), rule 2 (not positive): {tm:?}");
    };
    assert_eq!(ctl.config(), &Config::paper());
    let flight = ParamTable::from_config(&Config::flight());
    let tm = answer(
        &mut services,
        &mut ctl,
        &packet(&Telecommand::LoadParams(flight), 2),
    );
    assert_eq!(
        verification(&tm),
        [
            (Stage::Acceptance, None),
            (Stage::Start, None),
            (Stage::Completion, None)
        ]
    );
    assert_eq!(ctl.config(), &Config::flight());
}
