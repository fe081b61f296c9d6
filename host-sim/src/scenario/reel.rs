//! `[reel]`: the physical reel drive (`crate::reel::Reel` flies it; `convert` turns this
//! section into its parameters).

use serde::{Deserialize, Serialize};

use tss_reel::reel_drive::{DriveConfigError, DriveRule};

use crate::elastic::reel_drum::DrumParams;
use crate::elastic::FlightParams;

use super::rules::{is_positive, num, Validator};

/// Which reel model flies the tether.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReelModelName {
    /// The ideal reel, or the lagging, saturating drive when `lag_s` or a limit is set
    /// (`crate::reel`).
    #[default]
    Drive,
    /// The drum and motor with a speed loop, friction, torque limit and brake
    /// (`crate::elastic::reel_drum`; elastic plant only).
    Motor,
    /// The same drum driven by the flight speed loop (`tss_reel::reel_drive::SpeedLoop`) at
    /// `inner_rate_hz` through a quantised encoder (`crate::elastic::reel_drum::FlightDrum`;
    /// elastic plant only).
    FlightDrive,
}

/// `[reel]`: the physical reel between the command and the tether. With `model = "drive"`
/// (default) its actual rate v follows the command u as a first-order lag,
/// dv/dt = (u − v)/lag_s, with its own rate and acceleration saturation (separate from the
/// controller's `[envelope]`); with `model = "motor"` (elastic plant) a drum of radius r and
/// inertia J follows u/r through a speed loop (the `drum_*`, `motor_*`, friction and brake keys;
/// defaults: a 0.1 m, 0.05 kg·m² drum with a 2 N·m motor and a 5 rad/s speed loop); with
/// `model = "flight_drive"` (elastic plant) the same drum is driven by the flight speed loop at
/// `inner_rate_hz` through an encoder of `encoder_counts_per_rev` (its gains the flight
/// drive's, `speed_bandwidth_radps` unused).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReelSection {
    /// `"drive"` (default), `"motor"` or `"flight_drive"`.
    #[serde(default)]
    pub model: ReelModelName,
    /// Hold the drum still: the tether neither pays out nor winds in, and the controller's
    /// commands are logged and ignored (free-dynamics runs).
    #[serde(default)]
    pub locked: bool,
    /// Time constant of the lag, s (0 = the rate follows the command at once).
    #[serde(default)]
    pub lag_s: f64,
    /// Largest rate the drive can reach, m/s (inf = no limit).
    #[serde(default = "infinity")]
    pub max_rate_mps: f64,
    /// Largest acceleration the drive can produce, m/s² (inf = no limit).
    #[serde(default = "infinity")]
    pub max_accel_mps2: f64,
    /// Motor: drum radius r, m.
    #[serde(default = "default_drum_radius_m")]
    pub drum_radius_m: f64,
    /// Motor: inertia of motor and drum referred to the drum, kg·m².
    #[serde(default = "default_drum_inertia_kgm2")]
    pub drum_inertia_kgm2: f64,
    /// Motor: viscous friction, N·m·s/rad.
    #[serde(default = "default_viscous_nms")]
    pub viscous_nms: f64,
    /// Motor: Coulomb (sliding) friction, N·m.
    #[serde(default = "default_coulomb_nm")]
    pub coulomb_nm: f64,
    /// Motor: static (breakaway) friction, N·m (≥ coulomb_nm).
    #[serde(default = "default_static_nm")]
    pub static_nm: f64,
    /// Motor: torque limit, N·m.
    #[serde(default = "default_motor_max_torque_nm")]
    pub motor_max_torque_nm: f64,
    /// Motor: holding brake torque, applied while the command is zero, N·m.
    #[serde(default = "default_brake_nm")]
    pub brake_nm: f64,
    /// Motor: speed-loop bandwidth (a double closed-loop pole at −ω_b), rad/s.
    #[serde(default = "default_speed_bandwidth_radps")]
    pub speed_bandwidth_radps: f64,
    /// Flight drive: the speed loop's inner rate, Hz (≥ 100; the plant substeps at it).
    #[serde(default = "default_inner_rate_hz")]
    pub inner_rate_hz: u32,
    /// Flight drive: encoder counts per drum revolution.
    #[serde(default = "default_encoder_counts_per_rev")]
    pub encoder_counts_per_rev: u32,
}

impl Default for ReelSection {
    fn default() -> Self {
        Self {
            model: ReelModelName::Drive,
            locked: false,
            lag_s: 0.0,
            max_rate_mps: f64::INFINITY,
            max_accel_mps2: f64::INFINITY,
            drum_radius_m: default_drum_radius_m(),
            drum_inertia_kgm2: default_drum_inertia_kgm2(),
            viscous_nms: default_viscous_nms(),
            coulomb_nm: default_coulomb_nm(),
            static_nm: default_static_nm(),
            motor_max_torque_nm: default_motor_max_torque_nm(),
            brake_nm: default_brake_nm(),
            speed_bandwidth_radps: default_speed_bandwidth_radps(),
            inner_rate_hz: default_inner_rate_hz(),
            encoder_counts_per_rev: default_encoder_counts_per_rev(),
        }
    }
}

fn infinity() -> f64 {
    f64::INFINITY
}
fn default_drum_radius_m() -> f64 {
    0.1
}
fn default_drum_inertia_kgm2() -> f64 {
    0.05
}
fn default_viscous_nms() -> f64 {
    1e-3
}
fn default_coulomb_nm() -> f64 {
    0.05
}
fn default_static_nm() -> f64 {
    0.08
}
fn default_motor_max_torque_nm() -> f64 {
    2.0
}
fn default_brake_nm() -> f64 {
    1.0
}
fn default_speed_bandwidth_radps() -> f64 {
    5.0
}
fn default_inner_rate_hz() -> u32 {
    1000
}
fn default_encoder_counts_per_rev() -> u32 {
    // The reference reel's: 4096 counts a motor turn through a 10:1 gearbox.
    40_960
}

impl ReelSection {
    /// A lag ≥ 0; saturations above 0 (inf = none); a drum of positive radius, inertia,
    /// torque and bandwidth, frictions ≥ 0 with the static one at least the Coulomb one.
    pub(super) fn check(&self, v: &mut Validator) {
        v.non_negative("reel.lag_s", self.lag_s);
        v.limit("reel.max_rate_mps", self.max_rate_mps);
        v.limit("reel.max_accel_mps2", self.max_accel_mps2);
        v.positive("reel.drum_radius_m", self.drum_radius_m);
        v.positive("reel.drum_inertia_kgm2", self.drum_inertia_kgm2);
        v.non_negative("reel.viscous_nms", self.viscous_nms);
        let coulomb_ok = v.non_negative("reel.coulomb_nm", self.coulomb_nm);
        if v.non_negative("reel.static_nm", self.static_nm) && coulomb_ok {
            v.check(
                self.static_nm >= self.coulomb_nm,
                "reel.static_nm",
                num(self.static_nm),
                &format!(
                    "must be at least reel.coulomb_nm = {}",
                    num(self.coulomb_nm)
                ),
            );
        }
        v.positive("reel.motor_max_torque_nm", self.motor_max_torque_nm);
        v.non_negative("reel.brake_nm", self.brake_nm);
        v.positive("reel.speed_bandwidth_radps", self.speed_bandwidth_radps);
        v.check(
            self.inner_rate_hz >= 100,
            "reel.inner_rate_hz",
            num(f64::from(self.inner_rate_hz)),
            "must be at least 100 Hz",
        );
        v.check(
            self.encoder_counts_per_rev > 0,
            "reel.encoder_counts_per_rev",
            num(f64::from(self.encoder_counts_per_rev)),
            "must be positive",
        );
    }
}

impl ReelSection {
    /// The drum of the motor and flight reels, as the elastic plant takes it.
    pub(super) fn drum_params(&self) -> DrumParams {
        DrumParams {
            radius_m: self.drum_radius_m,
            inertia_kgm2: self.drum_inertia_kgm2,
            viscous_nms: self.viscous_nms,
            coulomb_nm: self.coulomb_nm,
            static_nm: self.static_nm,
            max_torque_nm: self.motor_max_torque_nm,
            brake_nm: self.brake_nm,
            speed_bandwidth_radps: self.speed_bandwidth_radps,
        }
    }

    /// With `model = "flight_drive"`: the flight speed loop's own configuration
    /// (`tss_reel::reel_drive::DriveConfig::validate`, built as the elastic plant builds it at
    /// control period `period_s`) accepts this drum, encoder and inner rate. Its first broken
    /// rule is named by the scenario key it comes from, here and not when the run starts.
    pub(super) fn check_flight_drive(&self, period_s: f64, v: &mut Validator) {
        let drum_ok = [
            self.drum_radius_m,
            self.drum_inertia_kgm2,
            self.motor_max_torque_nm,
        ]
        .into_iter()
        .all(is_positive);
        if self.model != ReelModelName::FlightDrive
            || !drum_ok
            || !is_positive(period_s)
            || self.inner_rate_hz < 100
            || self.encoder_counts_per_rev == 0
        {
            return; // not flown, or reported by the rules above
        }
        let flight = FlightParams {
            drum: self.drum_params(),
            inner_rate_hz: self.inner_rate_hz,
            counts_per_rev: self.encoder_counts_per_rev,
            period_s,
        };
        if let Err(e) = flight.drive_config().validate() {
            let (key, value) = self.flight_drive_key(&e);
            v.check(false, key, value, &flight_drive_rule(&e));
        }
    }

    /// The scenario key a rejected drive parameter comes from, and its value as written.
    fn flight_drive_key(&self, e: &DriveConfigError) -> (&'static str, String) {
        let hz = || ("reel.inner_rate_hz", num(f64::from(self.inner_rate_hz)));
        match e.param {
            "geometry.counts_per_motor_rev" | "geometry.gear_ratio" => (
                "reel.encoder_counts_per_rev",
                num(f64::from(self.encoder_counts_per_rev)),
            ),
            "geometry.drum_radius_m" => ("reel.drum_radius_m", num(self.drum_radius_m)),
            "drum.inertia_kgm2" => ("reel.drum_inertia_kgm2", num(self.drum_inertia_kgm2)),
            "drum.viscous_nm_per_radps" => ("reel.viscous_nms", num(self.viscous_nms)),
            "drum.coulomb_nm" => ("reel.coulomb_nm", num(self.coulomb_nm)),
            "max_torque_nm" => ("reel.motor_max_torque_nm", num(self.motor_max_torque_nm)),
            // The rates, tick counts and counter checks follow from the inner rate.
            _ => hz(),
        }
    }
}

/// The flight drive's rule `e` breaks, in words, naming its parameter.
fn flight_drive_rule(e: &DriveConfigError) -> String {
    let rule = match e.rule {
        DriveRule::NotFinite => "is not finite".to_string(),
        DriveRule::NotPositive => "must be above 0".to_string(),
        DriveRule::Negative => "must not be negative".to_string(),
        DriveRule::BandInverted => "must be above its lower bound".to_string(),
        DriveRule::OutOfRange => "is outside its documented range".to_string(),
        DriveRule::BelowMinimum => format!(
            "is below the speed loop's {} Hz",
            tss_reel::reel_drive::config::MIN_INNER_RATE_HZ
        ),
        DriveRule::TooManyCounts => format!(
            "makes more than {} counts per drum revolution",
            tss_reel::reel_drive::config::MAX_COUNTS_PER_DRUM_REV
        ),
        DriveRule::BelowMaxSpeed => {
            "is below the drive's top speed: normal motion would read as a jump".to_string()
        }
        DriveRule::CounterAmbiguous => "lets the encoder's counter wrap within the gap the \
                                        encoder check bridges at the drive's top speed, so a \
                                        count change could not be told from a wrap"
            .to_string(),
        #[allow(unreachable_patterns)]
        other => format!("breaks the rule {other:?}"),
    };
    format!(
        "is refused by the flight speed loop: its {} = {} {rule} \
         (tss_reel::reel_drive::DriveConfig::validate)",
        e.param,
        num(e.value)
    )
}
