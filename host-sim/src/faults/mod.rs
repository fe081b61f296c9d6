//! Fault injection between the plant and the controller, and the fault summary of a run.
//!
//! [`Injector`] turns the plant's true state into what the controller reads: sensor bias,
//! white Gaussian noise, quantisation and stuck windows (`[sensors]`), dropouts, corrupted
//! readings and length-encoder glitches (`[faults]`). [`SummaryBuilder`] watches every control
//! tick of a run and produces the [`FaultSummary`] stored in `History::faults`;
//! [`render_fault_summary`] formats it for the terminal and `faults.txt`.
//!
//! The noise is reproducible: each sensor has its own [`Pcg32`] stream seeded from
//! `sensors.seed`, drawn once per control tick whether or not the reading is used. A run
//! therefore depends only on its scenario (never on threads or on other runs), and switching
//! one fault on does not change the noise another sensor sees.

mod plan;
mod report;
mod summary;

pub use crate::random::Pcg32;
use crate::sensors::{LoadCell, RateSensor, ReelEncoder, SwingSensor};
pub use crate::sensors::{SensedQuantity, SensorErrors, Window};
pub use plan::{Corruption, Glitch, InjectionPlan};
pub use report::{
    fault_name, injected_faults, render_fault_summary, FaultSetup, ReelMechanism, EVENTS_SHOWN,
};
pub use summary::{
    FaultEvent, FaultEventKind, FaultSummary, FaultTally, FlagTicks, SummaryBuilder, TautSummary,
    TickRecord, MAX_EVENTS, TUMBLE_ANGLE_RAD,
};

// ---- sensors ----------------------------------------------------------------------------------

/// The plant's true values of what the controller senses, in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Truth {
    /// Tether length, m.
    pub length_m: f64,
    /// The drum's actual rate over the last period, m/s.
    pub reel_rate_mps: f64,
    /// Tension at the reel at the end of the last period (under the command held over it), N.
    pub tension_n: f64,
    /// α, rad.
    pub alpha_rad: f64,
    /// α̇, rad/s.
    pub alpha_rate_radps: f64,
    /// Orbit rate θ̇, rad/s.
    pub orbit_rate_radps: f64,
    /// True anomaly θ, rad.
    pub true_anomaly_rad: f64,
}

/// What the controller reads at one tick: the `Input` fields in f64, with the same options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    /// Length from the reel encoder, m.
    pub length_m: f64,
    /// The reel's rate from the encoder, m/s (`None`: not measured this period).
    pub reel_rate_mps: Option<f64>,
    /// Tension from the load cell, N (`None`: no load cell).
    pub tension_n: Option<f64>,
    /// α from the swing sensor, rad (`None`: it gave nothing this period).
    pub alpha_rad: Option<f64>,
    /// α̇ from the rate sensor, rad/s (`None`: none fitted).
    pub alpha_rate_radps: Option<f64>,
    /// Orbit rate θ̇, rad/s.
    pub orbit_rate_radps: f64,
    /// True anomaly θ, rad.
    pub true_anomaly_rad: f64,
}

/// What the controller receives at one tick: a reading of every sensor, or nothing (dropout).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sensed {
    /// A sample (possibly wrong: noisy, biased, stuck, corrupted, glitched, or without α).
    Sample(Reading),
    /// No sample arrived (a `[[faults.dropout]]` window).
    Missing,
}

/// The noise streams of the sensors (`Pcg32` streams of `sensors.seed`): fixed, so that a
/// sensor's noise does not depend on which other sensors are modelled.
mod stream {
    pub const LENGTH: u64 = 1;
    pub const ALPHA: u64 = 2;
    pub const ALPHA_RATE: u64 = 3;
    pub const ALPHA_DROPOUT: u64 = 4;
    pub const LOAD_CELL: u64 = 5;
}

/// Applies an [`InjectionPlan`] (a scenario's `[sensors]` and `[faults]`) to the plant's truth,
/// tick by tick: the sensor models of [`crate::sensors`], then the injected faults.
#[derive(Clone, Debug)]
pub struct Injector {
    encoder: ReelEncoder,
    swing: SwingSensor,
    rate: RateSensor,
    load_cell: LoadCell,
    dropout: Vec<Window>,
    corrupt: Vec<Corruption>,
    /// (tick, size) of each length glitch.
    glitches: Vec<(u32, f64)>,
}

impl Injector {
    /// The injector of `plan` on control period `period_s`.
    pub fn new(plan: &InjectionPlan, period_s: f64) -> Self {
        let seed = plan.seed;
        Self {
            encoder: ReelEncoder::new(&plan.length, period_s, seed, stream::LENGTH),
            swing: SwingSensor::new(&plan.alpha, seed, stream::ALPHA, stream::ALPHA_DROPOUT),
            rate: RateSensor::new(
                plan.alpha_rate_enabled,
                &plan.alpha_rate,
                seed,
                stream::ALPHA_RATE,
            ),
            load_cell: LoadCell::new(&plan.load_cell, seed, stream::LOAD_CELL),
            dropout: plan.dropout.clone(),
            corrupt: plan.corrupt.clone(),
            glitches: plan
                .length_glitch
                .iter()
                .map(|g| (first_tick_at(g.at_s, period_s), g.size_m))
                .collect(),
        }
    }

    /// What the controller reads at `tick` (mission time `t_s`). Every sensor measures every
    /// tick, a dropout's included (its noise stays tied to time).
    pub fn sense(&mut self, tick: u32, t_s: f64, truth: &Truth) -> Sensed {
        let encoder = self.encoder.read(truth.length_m, truth.reel_rate_mps, t_s);
        let mut r = Reading {
            length_m: encoder.length_m,
            reel_rate_mps: encoder.rate_mps,
            tension_n: self.load_cell.read(truth.tension_n, t_s),
            alpha_rad: self.swing.read(truth.alpha_rad, t_s),
            alpha_rate_radps: self.rate.read(truth.alpha_rate_radps, t_s),
            orbit_rate_radps: truth.orbit_rate_radps,
            true_anomaly_rad: truth.true_anomaly_rad,
        };
        if self.dropout.iter().any(|w| w.contains(t_s)) {
            return Sensed::Missing;
        }
        for &(at, size) in &self.glitches {
            if at == tick {
                r.length_m += size;
            }
        }
        for c in &self.corrupt {
            if c.window.contains(t_s) {
                match c.sensor {
                    SensedQuantity::Length => r.length_m = c.value,
                    SensedQuantity::Alpha => r.alpha_rad = Some(c.value),
                    SensedQuantity::AlphaRate => r.alpha_rate_radps = Some(c.value),
                    SensedQuantity::OrbitRate => r.orbit_rate_radps = c.value,
                    SensedQuantity::ReelRate => r.reel_rate_mps = Some(c.value),
                    SensedQuantity::Tension => r.tension_n = Some(c.value),
                }
            }
        }
        Sensed::Sample(r)
    }
}

/// The first tick at or after `t_s` (a time within 1e-9 periods of a tick is that tick).
fn first_tick_at(t_s: f64, period_s: f64) -> u32 {
    let k = t_s / period_s;
    let n = if (k - k.round()).abs() <= 1e-9 * k.abs().max(1.0) {
        k.round()
    } else {
        k.ceil()
    };
    n.clamp(0.0, f64::from(u32::MAX)) as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sensors::{EncoderModel, SwingSensorModel};

    fn truth(t_s: f64) -> Truth {
        Truth {
            length_m: 100.0 + 2.0 * t_s,
            reel_rate_mps: 2.0,
            tension_n: 0.5,
            alpha_rad: -0.7,
            alpha_rate_radps: 1e-4,
            orbit_rate_radps: 1.06e-3,
            true_anomaly_rad: 1.06e-3 * t_s,
        }
    }

    fn sample(s: Sensed) -> Reading {
        match s {
            Sensed::Sample(r) => r,
            Sensed::Missing => panic!("no sample"),
        }
    }

    #[test]
    fn by_default_every_sensor_but_the_rate_sensor_reads_the_truth() {
        let mut inj = Injector::new(&InjectionPlan::default(), 1.0);
        let t = truth(3.0);
        assert_eq!(
            sample(inj.sense(3, 3.0, &t)),
            Reading {
                length_m: t.length_m,
                reel_rate_mps: Some(2.0),
                tension_n: Some(0.5),
                alpha_rad: Some(-0.7),
                alpha_rate_radps: None,
                orbit_rate_radps: t.orbit_rate_radps,
                true_anomaly_rad: t.true_anomaly_rad,
            }
        );
        let mut ideal = Injector::new(
            &InjectionPlan {
                alpha_rate_enabled: true,
                ..InjectionPlan::default()
            },
            1.0,
        );
        assert_eq!(sample(ideal.sense(3, 3.0, &t)).alpha_rate_radps, Some(1e-4));
    }

    #[test]
    fn an_alpha_dropout_keeps_the_sample_and_a_sample_dropout_loses_it() {
        let window = Window {
            from_s: 10.0,
            until_s: 12.0,
        };
        let mut inj = Injector::new(
            &InjectionPlan {
                alpha: SwingSensorModel {
                    dropout: vec![window],
                    ..SwingSensorModel::default()
                },
                dropout: vec![Window {
                    from_s: 20.0,
                    until_s: 21.0,
                }],
                ..InjectionPlan::default()
            },
            1.0,
        );
        for k in 0..25 {
            let t_s = f64::from(k);
            let s = inj.sense(k, t_s, &truth(t_s));
            match k {
                10 | 11 => {
                    let r = sample(s);
                    assert_eq!(r.alpha_rad, None);
                    assert_eq!(r.length_m, truth(t_s).length_m);
                }
                20 => assert_eq!(s, Sensed::Missing),
                _ => assert_eq!(sample(s).alpha_rad, Some(-0.7)),
            }
        }
    }

    #[test]
    fn the_encoder_s_rate_is_its_count_difference_and_corruptions_reach_every_reading() {
        let mut inj = Injector::new(
            &InjectionPlan {
                length: EncoderModel {
                    counts_per_rev: 1000,
                    drum_radius_m: 0.1,
                    ..EncoderModel::default()
                },
                corrupt: vec![
                    Corruption {
                        sensor: SensedQuantity::Tension,
                        window: Window {
                            from_s: 2.0,
                            until_s: 3.0,
                        },
                        value: f64::NAN,
                    },
                    Corruption {
                        sensor: SensedQuantity::ReelRate,
                        window: Window {
                            from_s: 2.0,
                            until_s: 3.0,
                        },
                        value: 99.0,
                    },
                ],
                ..InjectionPlan::default()
            },
            1.0,
        );
        let q = std::f64::consts::TAU * 0.1 / 1000.0;
        let first = sample(inj.sense(0, 0.0, &truth(0.0)));
        assert_eq!(first.reel_rate_mps, None);
        assert_eq!(first.length_m, (100.0 / q).floor() * q);
        let second = sample(inj.sense(1, 1.0, &truth(1.0)));
        let counts = (102.0 / q).floor() - (100.0 / q).floor();
        assert_eq!(second.reel_rate_mps, Some(counts * q));
        let third = sample(inj.sense(2, 2.0, &truth(2.0)));
        assert!(third.tension_n.is_some_and(f64::is_nan));
        assert_eq!(third.reel_rate_mps, Some(99.0));
    }

    #[test]
    fn glitch_tick_rounding() {
        assert_eq!(first_tick_at(100.0, 1.0), 100);
        assert_eq!(first_tick_at(100.2, 1.0), 101);
        assert_eq!(first_tick_at(0.3, 0.1), 3);
    }
}
