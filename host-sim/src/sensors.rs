//! The sensors as they fly: what the reel MCU reads each control period, modelled in
//! f64 between the plant's truth and the controller.
//!
//! - [`SwingSensor`]: α from a deployer angle sensor or relative navigation: bias, noise,
//!   quantisation and a stuck window ([`SensorErrors`]), a latency of whole periods (the
//!   reading delivered now is the one measured `latency_periods` ago) and dropouts, random
//!   (a probability per period) and in windows: a dropout delivers no α (`None`), not a lost
//!   sample.
//! - [`RateSensor`]: an optional α̇ sensor (the paper's idealisation; off in flight).
//! - [`ReelEncoder`]: the paid-out length in whole encoder counts of 2π r / N (drum radius r,
//!   N counts per revolution) and the reel's rate from the count difference over the period.
//! - [`LoadCell`]: the tension at the reel with bias, noise, quantisation and a full scale at
//!   which it saturates; optional.
//!
//! Every model draws its noise from its own seeded [`Pcg32`] stream once per period, whether or
//! not the draw is used, so a run depends only on its scenario and switching one sensor's
//! error on does not change the noise another sensor sees.

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use crate::random::Pcg32;

/// One sensor's errors, in the sensor's own unit (m, rad, rad/s), applied in the order bias,
/// noise, quantisation, then a stuck window freezes the reading.
/// The default is a perfect sensor.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SensorErrors {
    /// Standard deviation of white Gaussian noise added every sample (0 = none).
    pub noise_std: f64,
    /// Constant offset added to every sample.
    pub bias: f64,
    /// Quantisation step: the reading is rounded to a multiple of it (0 = none).
    pub quantum: f64,
    /// While in this window the sensor repeats the reading it gave at its start (`None`:
    /// never stuck).
    pub stuck: Option<Window>,
}

impl SensorErrors {
    /// `true` if the sensor reads the truth.
    pub fn is_perfect(&self) -> bool {
        self.noise_std == 0.0 && self.bias == 0.0 && self.quantum == 0.0 && self.stuck.is_none()
    }
}

/// A quantity the controller reads: what a `[[faults.corrupt]]` entry's `sensor` names
/// (written in scenario files as [`SensedQuantity::as_str`] gives it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SensedQuantity {
    /// The tether length (encoder), m.
    Length,
    /// α, rad.
    Alpha,
    /// α̇, rad/s.
    AlphaRate,
    /// The orbit rate θ̇, rad/s.
    OrbitRate,
    /// The reel's rate from the encoder, m/s.
    ReelRate,
    /// The tension from the load cell, N.
    Tension,
}

impl SensedQuantity {
    /// The name as written in scenario files and messages.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Length => "length",
            Self::Alpha => "alpha",
            Self::AlphaRate => "alpha_rate",
            Self::OrbitRate => "orbit_rate",
            Self::ReelRate => "reel_rate",
            Self::Tension => "tension",
        }
    }
}

/// A time window [from_s, until_s) on the control ticks, s (until inf = to the end of the run).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    /// Start, s.
    pub from_s: f64,
    /// End (excluded), s.
    pub until_s: f64,
}

impl Window {
    /// `t_s` is inside the window.
    pub fn contains(&self, t_s: f64) -> bool {
        t_s >= self.from_s && t_s < self.until_s
    }
}

/// One sensor: bias, noise, quantisation, stuck window.
#[derive(Clone, Debug)]
pub(crate) struct Channel {
    cfg: SensorErrors,
    rng: Pcg32,
    held: Option<f64>,
}

impl Channel {
    pub(crate) fn new(cfg: &SensorErrors, seed: u64, stream: u64) -> Self {
        Self {
            cfg: cfg.clone(),
            rng: Pcg32::new(seed, stream),
            held: None,
        }
    }

    pub(crate) fn read(&mut self, truth: f64, t_s: f64) -> f64 {
        let c = &self.cfg;
        // Drawn every tick, used or not, so that the noise sequence is tied to time.
        let noise = if c.noise_std > 0.0 {
            c.noise_std * self.rng.normal()
        } else {
            0.0
        };
        let mut v = truth;
        if c.bias != 0.0 {
            v += c.bias;
        }
        if noise != 0.0 {
            v += noise;
        }
        if c.quantum > 0.0 {
            v = (v / c.quantum).round() * c.quantum;
        }
        if c.stuck.is_some_and(|w| w.contains(t_s)) {
            *self.held.get_or_insert(v)
        } else {
            self.held = None;
            v
        }
    }
}

/// The swing sensor's parameters (`[sensors.alpha]`, `[[faults.alpha_dropout]]`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SwingSensorModel {
    /// Bias, noise, quantum (rad) and stuck window of each measurement.
    pub errors: SensorErrors,
    /// Whole control periods between a measurement and its delivery.
    pub latency_periods: u16,
    /// Probability that a period delivers no α.
    pub dropout_prob: f64,
    /// Windows (on the delivery time) without α.
    pub dropout: Vec<Window>,
}

impl SwingSensorModel {
    /// `true` if the sensor delivers the true α of this period, every period.
    pub fn is_perfect(&self) -> bool {
        self.errors.is_perfect()
            && self.latency_periods == 0
            && self.dropout_prob == 0.0
            && self.dropout.is_empty()
    }
}

/// The swing sensor in flight: measurements in the pipeline of its latency, and its dropouts.
#[derive(Clone, Debug)]
pub struct SwingSensor {
    channel: Channel,
    dropout_rng: Pcg32,
    latency_periods: usize,
    dropout_prob: f64,
    dropout: Vec<Window>,
    /// Measurements not yet delivered, oldest first.
    pipeline: VecDeque<f64>,
}

impl SwingSensor {
    /// The sensor of `model`, its noise from stream `stream` of `seed` and its dropouts from
    /// stream `dropout_stream`.
    pub fn new(model: &SwingSensorModel, seed: u64, stream: u64, dropout_stream: u64) -> Self {
        let latency_periods = usize::from(model.latency_periods);
        Self {
            channel: Channel::new(&model.errors, seed, stream),
            dropout_rng: Pcg32::new(seed, dropout_stream),
            latency_periods,
            dropout_prob: model.dropout_prob,
            dropout: model.dropout.clone(),
            pipeline: VecDeque::with_capacity(latency_periods + 1),
        }
    }

    /// Measures `alpha_rad` at mission time `t_s` and delivers the measurement of
    /// `latency_periods` ago, or `None`: a dropout (random or in a window), or no measurement
    /// old enough yet (the first `latency_periods` periods).
    pub fn read(&mut self, alpha_rad: f64, t_s: f64) -> Option<f64> {
        self.pipeline.push_back(self.channel.read(alpha_rad, t_s));
        // Drawn every period, used or not, so that the dropouts are tied to time.
        let u = self.dropout_rng.uniform_open();
        let delivered = if self.pipeline.len() > self.latency_periods {
            self.pipeline.pop_front()
        } else {
            None
        };
        let dropped = u < self.dropout_prob || self.dropout.iter().any(|w| w.contains(t_s));
        delivered.filter(|_| !dropped)
    }
}

/// The optional α̇ sensor: `None` when it is not fitted.
#[derive(Clone, Debug)]
pub struct RateSensor(Option<Channel>);

impl RateSensor {
    /// The sensor with `errors` if `enabled`, its noise from stream `stream` of `seed`.
    pub fn new(enabled: bool, errors: &SensorErrors, seed: u64, stream: u64) -> Self {
        Self(enabled.then(|| Channel::new(errors, seed, stream)))
    }

    /// Its reading of `alpha_rate_radps` at `t_s` (`None`: not fitted).
    pub fn read(&mut self, alpha_rate_radps: f64, t_s: f64) -> Option<f64> {
        self.0.as_mut().map(|c| c.read(alpha_rate_radps, t_s))
    }
}

/// The reel encoder's parameters (`[sensors.length]`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EncoderModel {
    /// Bias, noise, quantum (m) and stuck window of the length.
    pub errors: SensorErrors,
    /// Counts per drum revolution (0: the length is not counted, it is continuous).
    pub counts_per_rev: u32,
    /// Drum radius, m.
    pub drum_radius_m: f64,
}

impl EncoderModel {
    /// The tether length of one count, m (`None` when the encoder does not count).
    pub fn count_m(&self) -> Option<f64> {
        (self.counts_per_rev > 0)
            .then(|| std::f64::consts::TAU * self.drum_radius_m / f64::from(self.counts_per_rev))
    }

    /// `true` if the encoder reads the true length and rate.
    pub fn is_perfect(&self) -> bool {
        self.errors.is_perfect() && self.counts_per_rev == 0
    }
}

/// One period's reading of the reel encoder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EncoderReading {
    /// The paid-out length, m.
    pub length_m: f64,
    /// The reel's rate over the period that just ended, m/s (`None` at the first period of a
    /// counting or imperfect encoder: no difference yet).
    pub rate_mps: Option<f64>,
}

/// The reel encoder in flight.
#[derive(Clone, Debug)]
pub struct ReelEncoder {
    channel: Channel,
    count_m: Option<f64>,
    perfect: bool,
    period_s: f64,
    /// The previous period's reading: whole counts, or the length when not counting.
    last: Option<Count>,
}

/// A length as the encoder holds it.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Count {
    /// Whole counts of `count_m`.
    Counts(i64),
    /// A continuous length, m.
    Length(f64),
}

impl ReelEncoder {
    /// The encoder of `model` on control period `period_s`, its noise from stream `stream` of
    /// `seed`.
    pub fn new(model: &EncoderModel, period_s: f64, seed: u64, stream: u64) -> Self {
        Self {
            channel: Channel::new(&model.errors, seed, stream),
            count_m: model.count_m(),
            perfect: model.is_perfect(),
            period_s,
            last: None,
        }
    }

    /// The reading at `t_s` of a reel that has paid out `length_m` and moved at `rate_mps` over
    /// the last period. The length with its errors is counted down to a whole count (an
    /// incremental encoder counts whole steps: a mean error of half a count); the rate is the
    /// count difference over the period. A perfect encoder reads the truth, rate included.
    pub fn read(&mut self, length_m: f64, rate_mps: f64, t_s: f64) -> EncoderReading {
        let sensed_m = self.channel.read(length_m, t_s);
        if self.perfect {
            return EncoderReading {
                length_m: sensed_m,
                rate_mps: Some(rate_mps),
            };
        }
        let now = match self.count_m {
            // `as` saturates: a length of 2⁶³ counts is not a tether.
            Some(q) => Count::Counts((sensed_m / q).floor() as i64),
            None => Count::Length(sensed_m),
        };
        let h = self.period_s;
        let rate_mps = match (self.last, now, self.count_m) {
            (Some(Count::Counts(a)), Count::Counts(b), Some(q)) => {
                Some(b.saturating_sub(a) as f64 * q / h)
            }
            (Some(Count::Length(a)), Count::Length(b), _) => Some((b - a) / h),
            _ => None,
        };
        self.last = Some(now);
        EncoderReading {
            length_m: match (now, self.count_m) {
                (Count::Counts(n), Some(q)) => n as f64 * q,
                _ => sensed_m,
            },
            rate_mps,
        }
    }
}

/// The load cell's parameters (`[sensors.load_cell]`).
#[derive(Clone, Debug, PartialEq)]
pub struct LoadCellModel {
    /// Fitted and read.
    pub enabled: bool,
    /// Bias, noise and quantum, N (no stuck window).
    pub errors: SensorErrors,
    /// The largest |tension| it reads, N (inf: none).
    pub full_scale_n: f64,
}

impl Default for LoadCellModel {
    /// An ideal load cell.
    fn default() -> Self {
        Self {
            enabled: true,
            errors: SensorErrors::default(),
            full_scale_n: f64::INFINITY,
        }
    }
}

impl LoadCellModel {
    /// `true` if it reads the true tension.
    pub fn is_perfect(&self) -> bool {
        self.enabled && self.errors.is_perfect() && self.full_scale_n == f64::INFINITY
    }
}

/// The load cell in flight: `None` when it is not fitted.
#[derive(Clone, Debug)]
pub struct LoadCell(Option<(Channel, f64)>);

impl LoadCell {
    /// The load cell of `model`, its noise from stream `stream` of `seed`.
    pub fn new(model: &LoadCellModel, seed: u64, stream: u64) -> Self {
        Self(model.enabled.then(|| {
            (
                Channel::new(&model.errors, seed, stream),
                model.full_scale_n,
            )
        }))
    }

    /// Its reading of `tension_n` at `t_s`: the tension with its errors, held within ±full
    /// scale (`None`: not fitted).
    pub fn read(&mut self, tension_n: f64, t_s: f64) -> Option<f64> {
        self.0.as_mut().map(|(c, full_scale_n)| {
            let t = c.read(tension_n, t_s);
            if t.abs() > *full_scale_n {
                full_scale_n.copysign(t)
            } else {
                t
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(cfg: SensorErrors) -> Channel {
        Channel::new(&cfg, 1, 1)
    }

    #[test]
    fn bias_quantum_and_stuck_window() {
        let mut c = channel(SensorErrors {
            bias: 0.3,
            quantum: 0.25,
            stuck: Some(Window {
                from_s: 2.0,
                until_s: 4.0,
            }),
            ..SensorErrors::default()
        });
        assert_eq!(c.read(1.0, 0.0), 1.25); // 1.3 → 1.25
        assert_eq!(c.read(1.2, 1.0), 1.5);
        assert_eq!(c.read(2.0, 2.0), 2.25); // stuck from here
        assert_eq!(c.read(3.0, 3.0), 2.25);
        assert_eq!(c.read(4.0, 4.0), 4.25); // released
    }

    #[test]
    fn noise_has_the_stated_deviation() {
        let mut c = channel(SensorErrors {
            noise_std: 0.01,
            ..SensorErrors::default()
        });
        let n = 20_000;
        let rms = ((0..n)
            .map(|i| c.read(5.0, f64::from(i)) - 5.0)
            .map(|e| e * e)
            .sum::<f64>()
            / f64::from(n))
        .sqrt();
        assert!((rms - 0.01).abs() < 5e-4, "{rms}");
    }

    fn swing(model: SwingSensorModel) -> SwingSensor {
        SwingSensor::new(&model, 7, 2, 4)
    }

    #[test]
    fn an_ideal_swing_sensor_reads_the_truth_every_period() {
        let mut s = swing(SwingSensorModel::default());
        for k in 0..100 {
            let a = 0.01 * f64::from(k);
            assert_eq!(s.read(a, f64::from(k)), Some(a));
        }
    }

    #[test]
    fn latency_delivers_the_measurement_of_k_periods_ago() {
        let mut s = swing(SwingSensorModel {
            latency_periods: 3,
            ..SwingSensorModel::default()
        });
        let got: Vec<Option<f64>> = (0..6).map(|k| s.read(f64::from(k), f64::from(k))).collect();
        assert_eq!(got, [None, None, None, Some(0.0), Some(1.0), Some(2.0)]);
    }

    #[test]
    fn dropouts_come_at_their_rate_and_in_their_windows() {
        let mut s = swing(SwingSensorModel {
            dropout_prob: 0.1,
            dropout: vec![Window {
                from_s: 100.0,
                until_s: 200.0,
            }],
            ..SwingSensorModel::default()
        });
        let n = 20_000;
        let got: Vec<Option<f64>> = (0..n).map(|k| s.read(0.5, f64::from(k))).collect();
        assert!(got[100..200].iter().all(Option::is_none));
        let outside = got.len() - 100;
        let dropped = got.iter().filter(|r| r.is_none()).count() - 100;
        let rate = dropped as f64 / outside as f64;
        // 5σ of a binomial proportion of 0.1 over ~20 000 draws: 0.011.
        assert!((rate - 0.1).abs() < 0.011, "{rate}");
        assert!(got.iter().flatten().all(|&a| a == 0.5));
        // Reproducible: the same seed gives the same dropouts.
        let mut again = swing(SwingSensorModel {
            dropout_prob: 0.1,
            ..SwingSensorModel::default()
        });
        let first: Vec<bool> = (0..100)
            .map(|k| again.read(0.5, f64::from(k)).is_none())
            .collect();
        assert_eq!(
            first,
            got[..100].iter().map(Option::is_none).collect::<Vec<_>>()
        );
    }

    #[test]
    fn an_absent_rate_sensor_reads_nothing() {
        let e = SensorErrors::default();
        assert_eq!(RateSensor::new(false, &e, 1, 3).read(1e-3, 0.0), None);
        assert_eq!(RateSensor::new(true, &e, 1, 3).read(1e-3, 0.0), Some(1e-3));
    }

    #[test]
    fn the_encoder_counts_whole_counts_and_its_rate_is_their_difference() {
        let model = EncoderModel {
            counts_per_rev: 4096,
            drum_radius_m: 0.1,
            ..EncoderModel::default()
        };
        let q = model.count_m().unwrap();
        assert!((q - 1.533_980_787_885_641e-4).abs() < 1e-15, "{q}");
        let mut e = ReelEncoder::new(&model, 1.0, 1, 1);
        let first = e.read(10.0, 2.0, 0.0);
        assert_eq!(first.rate_mps, None);
        let n0 = (10.0 / q).floor();
        assert_eq!(first.length_m, n0 * q);
        assert!(10.0 - first.length_m >= 0.0 && 10.0 - first.length_m < q);
        let second = e.read(12.0, 2.0, 1.0);
        let n1 = (12.0 / q).floor();
        assert_eq!(second.length_m, n1 * q);
        assert_eq!(second.rate_mps, Some((n1 - n0) * q));
        // Over many periods the rate errs by at most a count per period, and its mean is the
        // true rate (the count errors telescope).
        let mut sum = 0.0;
        for k in 2..1_002 {
            let l = 10.0 + 2.0 * f64::from(k) + 1e-3 * f64::from(k).sin();
            let r = e.read(l, 2.0, f64::from(k)).rate_mps.unwrap();
            assert!((r - 2.0).abs() < q + 2e-3, "{r}");
            sum += r;
        }
        assert!((sum / 1_000.0 - 2.0).abs() < 2.0 * q / 1_000.0 + 2e-6);
    }

    #[test]
    fn a_perfect_encoder_reads_the_true_length_and_rate() {
        let mut e = ReelEncoder::new(&EncoderModel::default(), 1.0, 1, 1);
        assert_eq!(
            e.read(123.456, 0.789, 0.0),
            EncoderReading {
                length_m: 123.456,
                rate_mps: Some(0.789)
            }
        );
    }

    #[test]
    fn the_load_cell_saturates_at_its_full_scale_and_is_optional() {
        let model = LoadCellModel {
            errors: SensorErrors {
                bias: 0.5,
                quantum: 0.25,
                ..SensorErrors::default()
            },
            full_scale_n: 100.0,
            ..LoadCellModel::default()
        };
        let mut c = LoadCell::new(&model, 1, 5);
        assert_eq!(c.read(10.0, 0.0), Some(10.5));
        assert_eq!(c.read(10.1, 1.0), Some(10.5)); // 10.6 → 10.5
        assert_eq!(c.read(1e6, 2.0), Some(100.0));
        assert_eq!(c.read(-1e6, 3.0), Some(-100.0));
        let mut none = LoadCell::new(
            &LoadCellModel {
                enabled: false,
                ..model
            },
            1,
            5,
        );
        assert_eq!(none.read(10.0, 0.0), None);
    }
}
