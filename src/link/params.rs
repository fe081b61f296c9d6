//! The parameter table: a whole controller configuration ([`Config<f32>`]) as a fixed list of
//! [`PARAM_WORDS`] 32-bit words, the form in which it is loaded into the reel MCU (the PIL
//! link's `Params` frame; docs/interface.md lists the table).
//!
//! Each word is an `f32` bit pattern, an unsigned integer or a tag (0 or 1: whether an optional
//! part of the configuration follows), in the order of [`PARAMS`], whose names are the field
//! paths [`ConfigError::param`] uses. Decoding ([`ParamTable::to_config`]) checks the table's own
//! shape (tags, the words of an absent part all zero, integer ranges) and nothing else: whether
//! the numbers make a controller is [`Config::validate`]'s to say, when the controller is built
//! from them. Both sides of a load therefore judge a table by the same code.
//!
//! Every struct is destructured without `..`, as in [`super::config_digest`]: a new field
//! anywhere in the configuration does not compile until it has its word here.

use serde::de::{Error as _, SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::config::{ConfigError, RateSource, Rule, Stage1Config, Stage2Config};
use crate::controller::{Config, Envelope, MonitorConfig, ProtectionConfig, TensionLoopConfig};
use crate::estimator;
use crate::law::Gains;
use crate::mass::MassModel;
use crate::orbit::Orbit;
use crate::schedule::BandSchedule;

/// What one word of the table holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WordKind {
    /// An `f32`, as its IEEE-754 bit pattern.
    F32,
    /// An unsigned integer.
    U32,
    /// 0 or 1: whether the optional part named by the words after it is present.
    Tag,
}

/// Words in a table.
pub const PARAM_WORDS: usize = 70;

/// The table's words in order: the field path (as [`ConfigError::param`] names it) and kind.
pub const PARAMS: [(&str, WordKind); PARAM_WORDS] = {
    use WordKind::{Tag, F32, U32};
    [
        ("period_s", F32),
        ("orbit.semi_major_axis_m", F32),
        ("orbit.eccentricity", F32),
        ("orbit.mu_m3ps2", F32),
        ("masses.main_initial_kg", F32),
        ("masses.sub_kg", F32),
        ("masses.tether_density_kg_per_m", F32),
        ("gains.k1_per_s", F32),
        ("gains.k2_per_s2", F32),
        ("initial_rate_mps", F32),
        ("stage1.schedule.low_length_m", F32),
        ("stage1.schedule.low_angle_rad", F32),
        ("stage1.schedule.low_slope_rad_per_m", F32),
        ("stage1.schedule.high_length_m", F32),
        ("stage1.schedule.high_angle_rad", F32),
        ("stage1.schedule.high_slope_rad_per_m", F32),
        ("stage1.decay_rate_per_s", F32),
        ("stage2.schedule.low_length_m", F32),
        ("stage2.schedule.low_angle_rad", F32),
        ("stage2.schedule.low_slope_rad_per_m", F32),
        ("stage2.schedule.high_length_m", F32),
        ("stage2.schedule.high_angle_rad", F32),
        ("stage2.schedule.high_slope_rad_per_m", F32),
        ("stage2.slew_rate_radps", F32),
        ("stage2.decay_rate_per_s", F32),
        ("stage2.start_tick?", Tag),
        ("stage2.start_tick", U32),
        ("keep_capture_m", F32),
        ("envelope.max_rate_mps", F32),
        ("envelope.max_accel_mps2", F32),
        ("envelope.min_length_m", F32),
        ("envelope.max_length_m", F32),
        ("monitor.coast_ticks", U32),
        ("monitor.recovery_ticks", U32),
        ("monitor.length_jump_m", F32),
        ("monitor.alpha_jump_rad", F32),
        ("monitor.stuck_ticks", U32),
        ("monitor.stuck_motion_rad", F32),
        ("monitor.max_alpha_rate_radps", F32),
        ("monitor.min_orbit_rate_radps", F32),
        ("monitor.max_orbit_rate_radps", F32),
        ("monitor.good_samples_per_bad", U32),
        ("monitor.safe_hold_decel_mps2", F32),
        ("protection?", Tag),
        ("protection.min_tension_n", F32),
        ("protection.max_tension_n", F32),
        ("protection.tension_filter_s", F32),
        ("protection.drive_lag_s", F32),
        ("protection.rate_resolution_mps", F32),
        ("rate_source.estimator?", Tag),
        ("rate_source.estimator.period_s", F32),
        ("rate_source.estimator.alpha_noise_rad", F32),
        ("rate_source.estimator.alpha_quantum_rad", F32),
        ("rate_source.estimator.accel_noise_density", F32),
        ("rate_source.estimator.disturbance_drift_density", F32),
        ("rate_source.estimator.initial_rate_std_radps", F32),
        ("rate_source.estimator.initial_disturbance_std_radps2", F32),
        ("rate_source.estimator.gate_nis", F32),
        ("rate_source.estimator.max_rejections", U32),
        ("tension_loop?", Tag),
        ("tension_loop.axial_stiffness_n", F32),
        ("tension_loop.damping_ratio", F32),
        ("tension_loop.washout_s", F32),
        ("tension_loop.min_tension_n", F32),
        ("tension_loop.max_tension_n", F32),
        ("tension_loop.overshoot", F32),
        ("tension_loop.fallback_accel_mps2", F32),
        ("tension_loop.load_cell_timeout_ticks", U32),
        ("tension_loop.yield_from_rad", F32),
        ("tension_loop.yield_full_rad", F32),
    ]
};

/// Why a table is not the shape of a configuration (the word at fault, by its index in
/// [`PARAMS`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TableError {
    /// A tag word other than 0 or 1.
    Tag(u8),
    /// A word of an absent optional part that is not 0.
    NotZero(u8),
    /// An integer too large for its field.
    TooLarge(u8),
}

impl TableError {
    /// The index in [`PARAMS`] of the word at fault.
    pub fn index(&self) -> u8 {
        match *self {
            Self::Tag(i) | Self::NotZero(i) | Self::TooLarge(i) => i,
        }
    }
}

/// A controller configuration as the words of the parameter table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParamTable {
    /// The words, in the order of [`PARAMS`].
    pub words: [u32; PARAM_WORDS],
}

/// Appends words to a table, in order.
struct Writer {
    words: [u32; PARAM_WORDS],
    next: usize,
}

impl Writer {
    fn word(&mut self, w: u32) {
        if let Some(slot) = self.words.get_mut(self.next) {
            *slot = w;
        }
        self.next += 1;
    }

    fn f32s(&mut self, xs: &[f32]) {
        for &x in xs {
            self.word(x.to_bits());
        }
    }
}

/// Takes words from a table, in order.
struct Reader<'a> {
    words: &'a [u32; PARAM_WORDS],
    next: usize,
}

impl Reader<'_> {
    fn index(&self) -> u8 {
        u8::try_from(self.next).unwrap_or(u8::MAX)
    }

    fn word(&mut self) -> u32 {
        let w = self.words.get(self.next).copied().unwrap_or(0);
        self.next += 1;
        w
    }

    fn f32(&mut self) -> f32 {
        f32::from_bits(self.word())
    }

    fn tag(&mut self) -> Result<bool, TableError> {
        let at = self.index();
        match self.word() {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(TableError::Tag(at)),
        }
    }

    /// Skips `n` words of an absent part, which must be zero.
    fn zeros(&mut self, n: usize) -> Result<(), TableError> {
        for _ in 0..n {
            let at = self.index();
            if self.word() != 0 {
                return Err(TableError::NotZero(at));
            }
        }
        Ok(())
    }

    fn schedule(&mut self) -> BandSchedule<f32> {
        BandSchedule {
            low_length_m: self.f32(),
            low_angle_rad: self.f32(),
            low_slope_rad_per_m: self.f32(),
            high_length_m: self.f32(),
            high_angle_rad: self.f32(),
            high_slope_rad_per_m: self.f32(),
        }
    }
}

/// Words of the protection's part (after its tag).
const PROTECTION_WORDS: usize = 5;
/// Words of the estimator's part (after its tag).
const ESTIMATOR_WORDS: usize = 9;
/// Words of the tension loop's part (after its tag).
const TENSION_LOOP_WORDS: usize = 10;

impl ParamTable {
    /// The table of `cfg`.
    pub fn from_config(cfg: &Config<f32>) -> Self {
        let Config {
            period_s,
            orbit,
            masses,
            gains,
            initial_rate_mps,
            stage1,
            stage2,
            keep_capture_m,
            envelope,
            monitor,
            protection,
            rate_source,
            tension_loop,
        } = cfg;
        let Orbit {
            semi_major_axis_m,
            eccentricity,
            mu_m3ps2,
        } = orbit;
        let MassModel {
            main_initial_kg,
            sub_kg,
            tether_density_kg_per_m,
        } = masses;
        let Gains {
            k1_per_s,
            k2_per_s2,
        } = gains;
        let Stage1Config {
            schedule: s1,
            decay_rate_per_s: c1,
        } = stage1;
        let Stage2Config {
            schedule: s2,
            slew_rate_radps,
            decay_rate_per_s: c2,
            start_tick,
        } = stage2;
        let Envelope {
            max_rate_mps,
            max_accel_mps2,
            min_length_m,
            max_length_m,
        } = envelope;
        let MonitorConfig {
            coast_ticks,
            recovery_ticks,
            length_jump_m,
            alpha_jump_rad,
            stuck_ticks,
            stuck_motion_rad,
            max_alpha_rate_radps,
            min_orbit_rate_radps,
            max_orbit_rate_radps,
            good_samples_per_bad,
            safe_hold_decel_mps2,
        } = monitor;
        let schedule = |w: &mut Writer, s: &BandSchedule<f32>| {
            let BandSchedule {
                low_length_m,
                low_angle_rad,
                low_slope_rad_per_m,
                high_length_m,
                high_angle_rad,
                high_slope_rad_per_m,
            } = *s;
            w.f32s(&[
                low_length_m,
                low_angle_rad,
                low_slope_rad_per_m,
                high_length_m,
                high_angle_rad,
                high_slope_rad_per_m,
            ]);
        };

        let mut w = Writer {
            words: [0; PARAM_WORDS],
            next: 0,
        };
        w.f32s(&[
            *period_s,
            *semi_major_axis_m,
            *eccentricity,
            *mu_m3ps2,
            *main_initial_kg,
            *sub_kg,
            *tether_density_kg_per_m,
            *k1_per_s,
            *k2_per_s2,
            *initial_rate_mps,
        ]);
        schedule(&mut w, s1);
        w.f32s(&[*c1]);
        schedule(&mut w, s2);
        w.f32s(&[*slew_rate_radps, *c2]);
        match start_tick {
            Some(t) => {
                w.word(1);
                w.word(*t);
            }
            None => {
                w.word(0);
                w.word(0);
            }
        }
        w.f32s(&[
            *keep_capture_m,
            *max_rate_mps,
            *max_accel_mps2,
            *min_length_m,
            *max_length_m,
        ]);
        w.word(*coast_ticks);
        w.word(*recovery_ticks);
        w.f32s(&[*length_jump_m, *alpha_jump_rad]);
        w.word(*stuck_ticks);
        w.f32s(&[
            *stuck_motion_rad,
            *max_alpha_rate_radps,
            *min_orbit_rate_radps,
            *max_orbit_rate_radps,
        ]);
        w.word(*good_samples_per_bad);
        w.f32s(&[*safe_hold_decel_mps2]);
        match protection {
            Some(p) => {
                let ProtectionConfig {
                    min_tension_n,
                    max_tension_n,
                    tension_filter_s,
                    drive_lag_s,
                    rate_resolution_mps,
                } = p;
                w.word(1);
                w.f32s(&[
                    *min_tension_n,
                    *max_tension_n,
                    *tension_filter_s,
                    *drive_lag_s,
                    *rate_resolution_mps,
                ]);
            }
            None => {
                w.word(0);
                w.f32s(&[0.0; PROTECTION_WORDS]);
            }
        }
        match rate_source {
            RateSource::Estimator(est) => {
                let estimator::Config {
                    period_s,
                    alpha_noise_rad,
                    alpha_quantum_rad,
                    accel_noise_density,
                    disturbance_drift_density,
                    initial_rate_std_radps,
                    initial_disturbance_std_radps2,
                    gate_nis,
                    max_rejections,
                } = est;
                w.word(1);
                w.f32s(&[
                    *period_s,
                    *alpha_noise_rad,
                    *alpha_quantum_rad,
                    *accel_noise_density,
                    *disturbance_drift_density,
                    *initial_rate_std_radps,
                    *initial_disturbance_std_radps2,
                    *gate_nis,
                ]);
                w.word(u32::from(*max_rejections));
            }
            RateSource::Sensor => {
                w.word(0);
                for _ in 0..ESTIMATOR_WORDS {
                    w.word(0);
                }
            }
        }
        match tension_loop {
            Some(t) => {
                let TensionLoopConfig {
                    axial_stiffness_n,
                    damping_ratio,
                    washout_s,
                    min_tension_n,
                    max_tension_n,
                    overshoot,
                    fallback_accel_mps2,
                    load_cell_timeout_ticks,
                    yield_from_rad,
                    yield_full_rad,
                } = t;
                w.word(1);
                w.f32s(&[
                    *axial_stiffness_n,
                    *damping_ratio,
                    *washout_s,
                    *min_tension_n,
                    *max_tension_n,
                    *overshoot,
                    *fallback_accel_mps2,
                ]);
                w.word(*load_cell_timeout_ticks);
                w.f32s(&[*yield_from_rad, *yield_full_rad]);
            }
            None => {
                w.word(0);
                for _ in 0..TENSION_LOOP_WORDS {
                    w.word(0);
                }
            }
        }
        Self { words: w.words }
    }

    /// The configuration this table describes, if it has the shape of one (tags, absent parts
    /// and integer ranges; the values themselves are [`Config::validate`]'s to judge).
    pub fn to_config(&self) -> Result<Config<f32>, TableError> {
        let mut r = Reader {
            words: &self.words,
            next: 0,
        };
        let period_s = r.f32();
        let orbit = Orbit {
            semi_major_axis_m: r.f32(),
            eccentricity: r.f32(),
            mu_m3ps2: r.f32(),
        };
        let masses = MassModel {
            main_initial_kg: r.f32(),
            sub_kg: r.f32(),
            tether_density_kg_per_m: r.f32(),
        };
        let gains = Gains {
            k1_per_s: r.f32(),
            k2_per_s2: r.f32(),
        };
        let initial_rate_mps = r.f32();
        let stage1 = Stage1Config {
            schedule: r.schedule(),
            decay_rate_per_s: r.f32(),
        };
        let schedule = r.schedule();
        let slew_rate_radps = r.f32();
        let decay_rate_per_s = r.f32();
        let start_tick = if r.tag()? {
            Some(r.word())
        } else {
            r.zeros(1)?;
            None
        };
        let stage2 = Stage2Config {
            schedule,
            slew_rate_radps,
            decay_rate_per_s,
            start_tick,
        };
        let keep_capture_m = r.f32();
        let envelope = Envelope {
            max_rate_mps: r.f32(),
            max_accel_mps2: r.f32(),
            min_length_m: r.f32(),
            max_length_m: r.f32(),
        };
        let monitor = MonitorConfig {
            coast_ticks: r.word(),
            recovery_ticks: r.word(),
            length_jump_m: r.f32(),
            alpha_jump_rad: r.f32(),
            stuck_ticks: r.word(),
            stuck_motion_rad: r.f32(),
            max_alpha_rate_radps: r.f32(),
            min_orbit_rate_radps: r.f32(),
            max_orbit_rate_radps: r.f32(),
            good_samples_per_bad: r.word(),
            safe_hold_decel_mps2: r.f32(),
        };
        let protection = if r.tag()? {
            Some(ProtectionConfig {
                min_tension_n: r.f32(),
                max_tension_n: r.f32(),
                tension_filter_s: r.f32(),
                drive_lag_s: r.f32(),
                rate_resolution_mps: r.f32(),
            })
        } else {
            r.zeros(PROTECTION_WORDS)?;
            None
        };
        let rate_source = if r.tag()? {
            let est_period_s = r.f32();
            let alpha_noise_rad = r.f32();
            let alpha_quantum_rad = r.f32();
            let accel_noise_density = r.f32();
            let disturbance_drift_density = r.f32();
            let initial_rate_std_radps = r.f32();
            let initial_disturbance_std_radps2 = r.f32();
            let gate_nis = r.f32();
            let at = r.index();
            let max_rejections = u16::try_from(r.word()).map_err(|_| TableError::TooLarge(at))?;
            RateSource::Estimator(estimator::Config {
                period_s: est_period_s,
                alpha_noise_rad,
                alpha_quantum_rad,
                accel_noise_density,
                disturbance_drift_density,
                initial_rate_std_radps,
                initial_disturbance_std_radps2,
                gate_nis,
                max_rejections,
            })
        } else {
            r.zeros(ESTIMATOR_WORDS)?;
            RateSource::Sensor
        };
        let tension_loop = if r.tag()? {
            Some(TensionLoopConfig {
                axial_stiffness_n: r.f32(),
                damping_ratio: r.f32(),
                washout_s: r.f32(),
                min_tension_n: r.f32(),
                max_tension_n: r.f32(),
                overshoot: r.f32(),
                fallback_accel_mps2: r.f32(),
                load_cell_timeout_ticks: r.word(),
                yield_from_rad: r.f32(),
                yield_full_rad: r.f32(),
            })
        } else {
            r.zeros(TENSION_LOOP_WORDS)?;
            None
        };
        Ok(Config {
            period_s,
            orbit,
            masses,
            gains,
            initial_rate_mps,
            stage1,
            stage2,
            keep_capture_m,
            envelope,
            monitor,
            protection,
            rate_source,
            tension_loop,
        })
    }
}

/// The index in [`PARAMS`] of the word a [`ConfigError`] names (`None` for an error that names
/// a group, such as `stage1.schedule`).
pub fn param_index(e: &ConfigError) -> Option<u8> {
    PARAMS
        .iter()
        .position(|(name, _)| *name == e.param)
        .and_then(|i| u8::try_from(i).ok())
}

/// The wire code of a validation rule (docs/interface.md, reason codes).
pub fn rule_code(r: Rule) -> u8 {
    match r {
        Rule::NotFinite => 1,
        Rule::NotPositive => 2,
        Rule::Negative => 3,
        Rule::BandInverted => 4,
        Rule::OutsideEnvelope => 5,
        Rule::WrongQuadrant => 6,
        Rule::TetherHeavierThanSatellite => 7,
        Rule::NoEquilibrium => 8,
        Rule::BelowMinimum => 9,
        Rule::TooFastForPeriod => 10,
        Rule::OutOfRange => 11,
        Rule::NotThePeriod => 12,
        Rule::TooLarge => 13,
    }
}

/// The rule of a wire code (`None` for an unknown code).
pub fn rule_from_code(c: u8) -> Option<Rule> {
    [
        Rule::NotFinite,
        Rule::NotPositive,
        Rule::Negative,
        Rule::BandInverted,
        Rule::OutsideEnvelope,
        Rule::WrongQuadrant,
        Rule::TetherHeavierThanSatellite,
        Rule::NoEquilibrium,
        Rule::BelowMinimum,
        Rule::TooFastForPeriod,
        Rule::OutOfRange,
        Rule::NotThePeriod,
        Rule::TooLarge,
    ]
    .into_iter()
    .find(|&r| rule_code(r) == c)
}

// On the wire the table is its words, each 4 bytes little-endian (a postcard tuple of fixed
// length: no length prefix, no varints).
impl Serialize for ParamTable {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(PARAM_WORDS)?;
        for w in &self.words {
            t.serialize_element(&w.to_le_bytes())?;
        }
        t.end()
    }
}

impl<'de> Deserialize<'de> for ParamTable {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Words;
        impl<'de> Visitor<'de> for Words {
            type Value = ParamTable;
            fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str("the parameter table's words")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<ParamTable, A::Error> {
                let mut words = [0u32; PARAM_WORDS];
                for (i, w) in words.iter_mut().enumerate() {
                    let bytes: [u8; 4] = seq
                        .next_element()?
                        .ok_or_else(|| A::Error::invalid_length(i, &self))?;
                    *w = u32::from_le_bytes(bytes);
                }
                Ok(ParamTable { words })
            }
        }
        d.deserialize_tuple(PARAM_WORDS, Words)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    fn roundtrip(cfg: Config<f32>) {
        let t = ParamTable::from_config(&cfg);
        assert_eq!(t.to_config(), Ok(cfg));
    }

    #[test]
    fn every_configuration_shape_roundtrips_bit_for_bit() {
        roundtrip(Config::paper());
        roundtrip(Config::flight());
        let mut c = Config::<f32>::flight();
        c.stage2.start_tick = None;
        c.protection = Some(ProtectionConfig::default_for_period());
        c.masses.tether_density_kg_per_m = 1.9e-4;
        c.gains.k1_per_s = f32::from_bits(c.gains.k1_per_s.to_bits() ^ 1);
        roundtrip(c);
    }

    #[test]
    fn the_table_is_as_documented() {
        let t = ParamTable::from_config(&Config::flight());
        let at = |name: &str| PARAMS.iter().position(|(n, _)| *n == name).unwrap();
        assert_eq!(t.words[at("period_s")], 1.0f32.to_bits());
        assert_eq!(t.words[at("stage2.start_tick?")], 1);
        assert_eq!(t.words[at("stage2.start_tick")], 8 * 3600);
        assert_eq!(t.words[at("protection?")], 0);
        assert_eq!(t.words[at("rate_source.estimator?")], 1);
        let crate::config::RateSource::Estimator(est) = Config::<f32>::flight().rate_source else {
            panic!("the flight configuration flies the estimator");
        };
        let max_rejections = at("rate_source.estimator.max_rejections");
        assert_eq!(t.words[max_rejections], u32::from(est.max_rejections));
        assert_eq!(t.words[at("tension_loop?")], 1);
        let loop_cfg = Config::<f32>::flight()
            .tension_loop
            .expect("the flight loop");
        assert_eq!(
            t.words[at("tension_loop.load_cell_timeout_ticks")],
            loop_cfg.load_cell_timeout_ticks
        );
        for (i, (_, kind)) in PARAMS.iter().enumerate() {
            if *kind == WordKind::Tag {
                assert!(t.words[i] <= 1);
            }
        }
    }

    #[test]
    fn a_table_of_the_wrong_shape_names_its_word() {
        let good = ParamTable::from_config(&Config::paper());
        let tag = PARAMS
            .iter()
            .position(|(n, _)| *n == "protection?")
            .unwrap();
        let mut t = good;
        t.words[tag] = 2;
        assert_eq!(t.to_config(), Err(TableError::Tag(tag as u8)));
        let mut t = good;
        t.words[tag + 3] = 1;
        assert_eq!(t.to_config(), Err(TableError::NotZero((tag + 3) as u8)));
        let max_rejections = PARAMS
            .iter()
            .position(|(n, _)| *n == "rate_source.estimator.max_rejections")
            .unwrap();
        let mut t = ParamTable::from_config(&Config::flight());
        t.words[max_rejections] = 70_000;
        assert_eq!(
            t.to_config(),
            Err(TableError::TooLarge(max_rejections as u8))
        );
    }

    /// docs/interface.md lists the table word by word, in order, with each word's kind.
    #[test]
    fn the_interface_document_lists_the_table() {
        let doc = include_str!("../../docs/interface.md");
        let mut from = 0;
        for (i, (name, kind)) in PARAMS.iter().enumerate() {
            let kind = match kind {
                WordKind::F32 => "f32",
                WordKind::U32 => "u32",
                WordKind::Tag => "tag (0/1)",
            };
            let row = std::format!("| {i} | `{name}` | {kind} |");
            let at = doc[from..]
                .find(&row)
                .unwrap_or_else(|| panic!("docs/interface.md lacks the row {row}"));
            from += at + row.len();
        }
    }

    #[test]
    fn a_validation_error_names_its_word_and_rule() {
        let mut c = Config::<f32>::flight();
        c.gains.k1_per_s = -1.0;
        let e = c.validate().unwrap_err();
        let i = param_index(&e).unwrap();
        assert_eq!(PARAMS[usize::from(i)].0, "gains.k1_per_s");
        assert_eq!(rule_from_code(rule_code(e.rule)), Some(e.rule));
        assert_eq!(rule_from_code(0), None);
    }
}
