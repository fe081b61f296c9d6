//! Proof that bad input never becomes a bad command: property tests over the whole input space
//! of the step function.
//!
//! Every field of every sample is drawn from all 2³² f32 bit patterns (NaN with any payload,
//! ±inf, subnormals, ±0, huge values) or from a plausible physical range, in random sequences
//! with random tick gaps and dropouts. Whatever arrives, each output must be finite and inside
//! the envelope.

use proptest::prelude::*;
use tss_reel::controller::{
    Config, Controller, Envelope, Fault, Flags, Input, Output, RateSource, Sensor,
};
use tss_reel::estimator;
use tss_reel::orbit::Orbit;

/// A realistic reel: 10 m/s, 0.1 m/s², 0.5 m to 40 km (tighter than the paper's defaults, so
/// the limits are exercised).
fn config() -> Config<f32> {
    Config {
        envelope: Envelope {
            max_rate_mps: 10.0,
            max_accel_mps2: 0.1,
            min_length_m: 0.5,
            max_length_m: 40_000.0,
        },
        ..Config::paper()
    }
}

/// [`config`] flying the estimator (the flight's rate source) on an eccentric orbit (e = 0.1),
/// so that the sample's true anomaly, reel rate and every optional field reach the filter.
fn flight_config() -> Config<f32> {
    Config {
        rate_source: RateSource::Estimator(estimator::Config::paper()),
        orbit: Orbit::elliptic(7_078_000.0, 0.1),
        ..config()
    }
}

/// Any f32 at all, by bit pattern.
fn any_bits() -> impl Strategy<Value = f32> {
    any::<u32>().prop_map(f32::from_bits)
}

/// Half the time any bit pattern, half the time a value in a plausible range.
fn field(lo: f32, hi: f32) -> impl Strategy<Value = f32> {
    prop_oneof![any_bits(), lo..hi]
}

#[derive(Clone, Debug)]
enum Event {
    Sample {
        gap: u32,
        length_m: f32,
        alpha_rad: f32,
        alpha_rate_radps: f32,
        orbit_rate_radps: f32,
        /// The optional fields and the true anomaly, for the estimator (None: absent).
        extra: Extra,
    },
    Missing {
        gap: u32,
    },
    /// A tick from the past.
    Backwards {
        by: u32,
    },
}

/// α present or not, the reel's rate, the tension (each present or not, any bits or plausible)
/// and the true anomaly.
#[derive(Clone, Copy, Debug)]
struct Extra {
    alpha_present: bool,
    reel_rate_mps: Option<f32>,
    tension_n: Option<f32>,
    true_anomaly_rad: f32,
}

fn extra() -> impl Strategy<Value = Extra> {
    (
        prop_oneof![3 => Just(true), 1 => Just(false)],
        proptest::option::of(field(-10.0, 10.0)),
        proptest::option::of(field(0.0, 100.0)),
        field(-7.0, 7.0),
    )
        .prop_map(
            |(alpha_present, reel_rate_mps, tension_n, true_anomaly_rad)| Extra {
                alpha_present,
                reel_rate_mps,
                tension_n,
                true_anomaly_rad,
            },
        )
}

fn event() -> impl Strategy<Value = Event> {
    let gap = prop_oneof![Just(1u32), 0u32..5, any::<u32>()];
    prop_oneof![
        8 => (gap.clone(), field(0.0, 45_000.0), field(-3.2, 3.2), field(-0.07, 0.07), field(0.0, 0.012), extra())
            .prop_map(|(gap, length_m, alpha_rad, alpha_rate_radps, orbit_rate_radps, extra)| Event::Sample {
                gap, length_m, alpha_rad, alpha_rate_radps, orbit_rate_radps, extra
            }),
        1 => gap.prop_map(|gap| Event::Missing { gap }),
        1 => (1u32..100).prop_map(|by| Event::Backwards { by }),
    ]
}

/// Every output finite and inside the envelope: the rate within ±max; the command's change
/// since the previous call, and the commanded acceleration, within the acceleration limit
/// (a·Δt per call, whatever the pattern of calls: a gap does not allow more, a call whose
/// tick did not move allows nothing) unless a hard length limit had to act.
fn assert_output_sane(out: &Output<f32>, prev_rate: f32, env: &Envelope<f32>) {
    let fields = [
        out.rate_cmd_mps,
        out.accel_cmd_mps2,
        out.law_rate_mps,
        out.blend_weight,
        out.alpha_ref_rad,
        out.alpha_ref_rate_radps,
        out.delta_rad,
        out.delta_rate_radps,
        out.length_estimate_m,
        out.equilibrium_margin,
    ];
    // law_rate_mps may legitimately be any finite value; all must be finite.
    assert!(
        fields.iter().all(|v| v.is_finite()),
        "non-finite output {out:?}"
    );
    assert!(
        out.rate_cmd_mps.abs() <= env.max_rate_mps,
        "rate outside envelope: {out:?}"
    );
    assert!((0.0..=1.0).contains(&out.blend_weight));
    if !out.flags.contains(Flags::LENGTH_LIMITED) {
        let a = env.max_accel_mps2; // period 1 s
        assert!(
            (out.rate_cmd_mps - prev_rate).abs() <= a * (1.0 + 1e-5) + 1e-6,
            "acceleration limit broken: {prev_rate} -> {out:?}"
        );
        assert!(
            out.accel_cmd_mps2.abs() <= a * (1.0 + 1e-5) + 1e-6,
            "commanded acceleration outside the envelope: {out:?}"
        );
        if out.fault == Some(Fault::Sensor(Sensor::Tick)) {
            assert_eq!(out.rate_cmd_mps, prev_rate, "time did not move: {out:?}");
        }
    }
}

/// Flies `events` from tick `start` on both rate sources (the rate sensor, and the estimator
/// on an eccentric orbit) and checks every output.
fn fly(start: u32, events: Vec<Event>) {
    fly_on(config(), start, &events);
    fly_on(flight_config(), start, &events);
}

fn fly_on(cfg: Config<f32>, start: u32, events: &[Event]) {
    let env = cfg.envelope;
    let mut ctl = Controller::new(cfg).unwrap();
    let mut tick = start;
    let mut prev_rate = cfg.initial_rate_mps;
    for ev in events.iter().cloned() {
        let out = match ev {
            Event::Sample {
                gap,
                length_m,
                alpha_rad,
                alpha_rate_radps,
                orbit_rate_radps,
                extra,
            } => {
                tick = tick.wrapping_add(gap);
                ctl.step(&Input {
                    tick,
                    length_m,
                    reel_rate_mps: extra.reel_rate_mps,
                    tension_n: extra.tension_n,
                    alpha_rad: extra.alpha_present.then_some(alpha_rad),
                    alpha_rate_radps: Some(alpha_rate_radps),
                    orbit_rate_radps,
                    true_anomaly_rad: extra.true_anomaly_rad,
                })
            }
            Event::Missing { gap } => {
                tick = tick.wrapping_add(gap);
                ctl.step_missing(tick)
            }
            Event::Backwards { by } => ctl.step_missing(tick.wrapping_sub(by)),
        };
        assert_output_sane(out, prev_rate, &env);
        prev_rate = out.rate_cmd_mps;
    }
}

/// A plausible sample (a slow random walk is not needed: the monitor's consistency checks
/// reject most of these, which is the point) with a call pattern: the next tick (most often),
/// the same tick again (a repeat, or a burst of calls in one period), a gap, or a stale tick.
fn patterned_event() -> impl Strategy<Value = Event> {
    let gap = prop_oneof![8 => Just(1u32), 2 => Just(0u32), 1 => 2u32..40];
    prop_oneof![
        12 => (gap.clone(), 1_000.0f32..1_010.0, -0.8f32..-0.6, -1e-3f32..1e-3, 1.0e-3f32..1.1e-3, extra())
            .prop_map(|(gap, length_m, alpha_rad, alpha_rate_radps, orbit_rate_radps, extra)| Event::Sample {
                gap, length_m, alpha_rad, alpha_rate_radps, orbit_rate_radps, extra
            }),
        2 => gap.prop_map(|gap| Event::Missing { gap }),
        1 => (1u32..100).prop_map(|by| Event::Backwards { by }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 100_000, ..ProptestConfig::default() })]

    /// Any sequence of any inputs: every output finite, the rate within ±max, the change per
    /// call and the commanded acceleration within the acceleration limit unless a hard length
    /// limit had to act.
    #[test]
    fn command_always_finite_and_in_envelope(start in any::<u32>(), events in prop::collection::vec(event(), 1..8)) {
        fly(start, events);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1_000, ..ProptestConfig::default() })]

    /// Long sequences (hundreds of calls) of any inputs and of plausible ones, with random
    /// call patterns (repeats, bursts, gaps, stale ticks, dropouts) from any start tick
    /// (through the u32 wrap): the same bounds at every call.
    #[test]
    fn long_call_patterns_keep_the_envelope(
        start in any::<u32>(),
        events in prop::collection::vec(prop_oneof![1 => event(), 4 => patterned_event()], 200..600),
    ) {
        fly(start, events);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2_000, ..ProptestConfig::default() })]

    /// Plausible random walks of α and α̇ with the length following the command exactly: the
    /// tether never leaves [l_min, l_max], whatever the law asks.
    #[test]
    fn tether_stays_inside_length_limits(
        l0 in 0.6f32..39_999.0,
        alpha0 in -1.5f32..1.5,
        steps in prop::collection::vec((-0.02f32..0.02, -1e-3f32..1e-3), 50..400),
    ) {
        let cfg = config();
        let env = cfg.envelope;
        let mut ctl = Controller::new(cfg).unwrap();
        let mut l = f64::from(l0);
        let mut alpha = alpha0;
        for (tick, (dalpha, rate)) in steps.into_iter().enumerate() {
            alpha = (alpha + dalpha).clamp(-1.5, 1.5);
            let out = ctl.step(&Input {
                tick: tick as u32,
                length_m: l as f32,
                reel_rate_mps: None,
                tension_n: None,
                alpha_rad: Some(alpha),
                alpha_rate_radps: Some(rate),
                orbit_rate_radps: 1.06e-3,
                true_anomaly_rad: 0.0,
            });
            l += f64::from(out.rate_cmd_mps);
            prop_assert!(l >= f64::from(env.min_length_m) - 1e-3 && l <= f64::from(env.max_length_m) + 1e-2,
                "l = {l} after {out:?}");
        }
    }
}
