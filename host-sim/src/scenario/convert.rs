//! The scenario turned into the parameter types of the models it configures: the flight
//! controller's `Config`, the plant's mass model, the fault injector, the reel drive and the
//! fault summary. None of them reads the schema: each takes its own parameters, and the
//! conversions from the sections live here.

use tss_reel::controller::{
    Config, Envelope, MonitorConfig, RateSource, Stage1Config, Stage2Config,
};
use tss_reel::law::Gains;
use tss_reel::mass::MassModel;
use tss_reel::orbit::Orbit;
use tss_reel::schedule::BandSchedule;
use tss_reel::Real;

use tss_reel::estimator;

use crate::elastic::environment::Environment;
use crate::elastic::tether::TetherParams;
use crate::elastic::{
    BodyParams, ElasticParams, FlightParams, OrbitParams, ReelModel, ReelParams, Sensing,
};
use crate::faults::{
    Corruption, FaultSetup, Glitch, InjectionPlan, ReelMechanism, SensorErrors, Window,
};
use crate::reel::{Reel, ReelDrive};
use crate::sensors::{EncoderModel, LoadCellModel, SwingSensorModel};

use super::envelope::EnvelopeSection;
use super::mission::Scenario;
use super::monitor::MonitorSection;
use super::plant::SensedDirection;
use super::reel::{ReelModelName, ReelSection};
use super::sensors::{
    EncoderSection, LoadCellSection, RateSensorSection, SwingSensorSection, WindowSection,
};

/// The smallest α noise the estimator is told, rad (its `Config::validate` floor): an ideal
/// swing sensor is flown as one this good.
pub const MIN_ASSUMED_ALPHA_NOISE_RAD: f64 = 1e-6;

impl Scenario {
    /// The libration estimator's tuning for this scenario's swing sensor:
    /// `estimator::Config::paper()` at the control period, told the sensor's noise (at least
    /// the filter's floor of 1e-6 rad) and quantum. The filter then assumes what the sensor's
    /// data sheet would say; its bias, latency and dropouts are the filter's to cope with.
    pub fn estimator_config<T: Real>(&self) -> estimator::Config<T> {
        let a = &self.sensors.alpha;
        estimator::Config {
            period_s: T::from_f64(self.controller.period_s),
            alpha_noise_rad: T::from_f64(a.noise_std.max(MIN_ASSUMED_ALPHA_NOISE_RAD)),
            alpha_quantum_rad: T::from_f64(a.quantum),
            ..estimator::Config::paper()
        }
    }

    /// Where the law's α̇ comes from: the α̇ sensor if the scenario fits one
    /// (`sensors.alpha_rate.enabled`, the paper's idealisation), else the estimator on the
    /// swing sensor's α ([`Scenario::estimator_config`]), as in flight.
    pub fn rate_source<T: Real>(&self) -> RateSource<T> {
        if self.sensors.alpha_rate.enabled {
            RateSource::Sensor
        } else {
            RateSource::Estimator(self.estimator_config())
        }
    }

    /// The flight controller's configuration, in its scalar type `T` (f32 on the target): the
    /// numbers `Config::validate` judges. The stage-2 start is the nearest control tick.
    pub fn controller_config<T: Real>(&self) -> Config<T> {
        let f = T::from_f64;
        let sc = self;
        let period = sc.controller.period_s;
        let stage2_tick = (sc.stage2.start_time_s / period)
            .round()
            .clamp(0.0, f64::from(u32::MAX)) as u32;
        Config {
            period_s: f(period),
            orbit: Orbit::elliptic(f(sc.orbit.semi_major_axis_m), f(sc.orbit.eccentricity)),
            masses: sc.mass_model(),
            gains: Gains {
                k1_per_s: f(sc.controller.k1_per_s),
                k2_per_s2: f(sc.controller.k2_per_s2),
            },
            initial_rate_mps: f(sc.initial.length_rate_mps),
            stage1: Stage1Config {
                schedule: BandSchedule {
                    low_length_m: f(sc.stage1.band_start_m),
                    low_angle_rad: f(sc.stage1.deploy_angle_rad),
                    low_slope_rad_per_m: T::ZERO,
                    high_length_m: f(sc.stage1.keep_length_m),
                    high_angle_rad: T::ZERO,
                    high_slope_rad_per_m: f(sc.stage1.keep_slope_rad_per_m),
                },
                decay_rate_per_s: f(sc.stage1.decay_rate_per_s),
            },
            stage2: Stage2Config {
                schedule: BandSchedule {
                    low_length_m: f(sc.stage2.keep_length_m),
                    low_angle_rad: T::ZERO,
                    low_slope_rad_per_m: f(sc.stage2.keep_slope_rad_per_m),
                    high_length_m: f(sc.stage2.band_start_m),
                    high_angle_rad: f(sc.stage2.retrieve_angle_rad),
                    high_slope_rad_per_m: T::ZERO,
                },
                slew_rate_radps: f(sc.stage2.slew_rate_radps),
                decay_rate_per_s: f(sc.stage2.decay_rate_per_s),
                start_tick: Some(stage2_tick),
            },
            keep_capture_m: f(sc.controller.keep_capture_m),
            envelope: sc.envelope.to_envelope(),
            monitor: sc.monitor.to_monitor_config(),
            rate_source: sc.rate_source(),
            protection: sc
                .protection
                .to_protection_config(sc.encoder_rate_resolution_mps()),
            tension_loop: sc.tension_loop.to_tension_loop_config(),
        }
    }

    /// One count of `[sensors.length]`'s encoder per control period, m/s: the resolution of
    /// the reel rate it measures (0 for an encoder without counts).
    pub fn encoder_rate_resolution_mps(&self) -> f64 {
        let encoder = &self.sensors.length;
        if encoder.counts_per_rev == 0 {
            return 0.0;
        }
        std::f64::consts::TAU * encoder.drum_radius_m
            / f64::from(encoder.counts_per_rev)
            / self.controller.period_s
    }

    /// The masses of `[masses]` and `[tether]`, in scalar type `T`.
    pub fn mass_model<T: Real>(&self) -> MassModel<T> {
        MassModel {
            main_initial_kg: T::from_f64(self.masses.main_initial_kg),
            sub_kg: T::from_f64(self.masses.sub_kg),
            tether_density_kg_per_m: T::from_f64(self.tether.density_kg_per_m),
        }
    }
}

impl MonitorSection {
    /// The controller's sensor-monitor thresholds, in its scalar type `T`.
    pub fn to_monitor_config<T: Real>(&self) -> MonitorConfig<T> {
        let m = self;
        MonitorConfig {
            coast_ticks: m.coast_ticks,
            recovery_ticks: m.recovery_ticks,
            length_jump_m: T::from_f64(m.length_jump_m),
            alpha_jump_rad: T::from_f64(m.alpha_jump_rad),
            stuck_ticks: m.stuck_ticks,
            stuck_motion_rad: T::from_f64(m.stuck_motion_rad),
            max_alpha_rate_radps: T::from_f64(m.max_alpha_rate_radps),
            min_orbit_rate_radps: T::from_f64(m.min_orbit_rate_radps),
            max_orbit_rate_radps: T::from_f64(m.max_orbit_rate_radps),
            good_samples_per_bad: m.good_samples_per_bad,
            safe_hold_decel_mps2: T::from_f64(m.safe_hold_decel_mps2),
        }
    }
}

impl From<&EncoderSection> for EncoderModel {
    fn from(s: &EncoderSection) -> Self {
        Self {
            errors: s.errors(),
            counts_per_rev: s.counts_per_rev,
            drum_radius_m: s.drum_radius_m,
        }
    }
}

impl From<&RateSensorSection> for SensorErrors {
    fn from(s: &RateSensorSection) -> Self {
        s.errors()
    }
}

impl From<&LoadCellSection> for LoadCellModel {
    fn from(s: &LoadCellSection) -> Self {
        Self {
            enabled: s.enabled,
            errors: SensorErrors {
                noise_std: s.noise_std_n,
                bias: s.bias_n,
                quantum: s.quantum_n,
                stuck: None,
            },
            full_scale_n: s.full_scale_n,
        }
    }
}

/// The swing sensor of `[sensors.alpha]` with the α dropouts of `[[faults.alpha_dropout]]`.
fn swing_sensor(s: &SwingSensorSection, dropout: &[WindowSection]) -> SwingSensorModel {
    SwingSensorModel {
        errors: s.errors(),
        latency_periods: s.latency_periods,
        dropout_prob: s.dropout_prob,
        dropout: dropout.iter().map(Window::from).collect(),
    }
}

impl From<&WindowSection> for Window {
    fn from(w: &WindowSection) -> Self {
        Self {
            from_s: w.from_s,
            until_s: w.until_s,
        }
    }
}

/// `[sensors]` and `[faults]`.
impl From<&Scenario> for InjectionPlan {
    fn from(sc: &Scenario) -> Self {
        let (s, f) = (&sc.sensors, &sc.faults);
        Self {
            seed: s.seed,
            length: (&s.length).into(),
            alpha: swing_sensor(&s.alpha, &f.alpha_dropout),
            alpha_rate_enabled: s.alpha_rate.enabled,
            alpha_rate: (&s.alpha_rate).into(),
            load_cell: (&s.load_cell).into(),
            dropout: f.dropout.iter().map(Window::from).collect(),
            corrupt: f
                .corrupt
                .iter()
                .map(|c| Corruption {
                    sensor: c.sensor,
                    window: Window {
                        from_s: c.from_s,
                        until_s: c.until_s,
                    },
                    value: c.value,
                })
                .collect(),
            length_glitch: f
                .length_glitch
                .iter()
                .map(|g| Glitch {
                    at_s: g.at_s,
                    size_m: g.size_m,
                })
                .collect(),
        }
    }
}

impl From<&ReelSection> for ReelDrive {
    fn from(r: &ReelSection) -> Self {
        Self {
            lag_s: r.lag_s,
            max_rate_mps: r.max_rate_mps,
            max_accel_mps2: r.max_accel_mps2,
        }
    }
}

impl EnvelopeSection {
    /// The controller's envelope, in its scalar type `T`.
    pub fn to_envelope<T: Real>(&self) -> Envelope<T> {
        Envelope {
            max_rate_mps: T::from_f64(self.max_rate_mps),
            max_accel_mps2: T::from_f64(self.max_accel_mps2),
            min_length_m: T::from_f64(self.min_length_m),
            max_length_m: T::from_f64(self.max_length_m),
        }
    }
}

/// What the fault summary of a run of `sc` describes.
impl From<&Scenario> for FaultSetup {
    fn from(sc: &Scenario) -> Self {
        Self {
            name: sc.name.clone(),
            injection: sc.into(),
            reel: (&sc.reel).into(),
            mechanism: match sc.reel.model {
                ReelModelName::Drive => ReelMechanism::Drive,
                ReelModelName::Motor => ReelMechanism::Motor,
                ReelModelName::FlightDrive => ReelMechanism::FlightDrive {
                    inner_rate_hz: sc.reel.inner_rate_hz,
                },
            },
            locked: sc.reel.locked,
            envelope: sc.envelope.to_envelope(),
        }
    }
}

/// `[orbit]`, `[masses]`, `[tether]`, `[reel]`, `[environment]` and `[plant]`: the elastic
/// plant's parameters.
impl From<&Scenario> for ElasticParams {
    fn from(sc: &Scenario) -> Self {
        let (t, r, e) = (&sc.tether, &sc.reel, &sc.environment);
        let orbit = Orbit::elliptic(sc.orbit.semi_major_axis_m, sc.orbit.eccentricity);
        let drum = r.drum_params();
        let model = match r.model {
            ReelModelName::Motor => ReelModel::Motor(drum),
            ReelModelName::FlightDrive => ReelModel::Flight(FlightParams {
                drum,
                inner_rate_hz: r.inner_rate_hz,
                counts_per_rev: r.encoder_counts_per_rev,
                period_s: sc.controller.period_s,
            }),
            ReelModelName::Drive => {
                let drive = ReelDrive::from(r);
                if drive.is_ideal() {
                    ReelModel::Ideal
                } else {
                    ReelModel::Lag(Reel::new(&drive, sc.initial.length_rate_mps))
                }
            }
        };
        Self {
            orbit: OrbitParams {
                orbit,
                initial_true_anomaly_rad: sc.orbit.initial_true_anomaly_rad,
                inclination_rad: e.inclination_rad,
            },
            bodies: BodyParams {
                main_initial_kg: sc.masses.main_initial_kg,
                sub_kg: sc.masses.sub_kg,
                main_drag_area_m2: e.main_drag_area_m2,
                sub_drag_area_m2: e.sub_drag_area_m2,
            },
            tether: TetherParams {
                density_kg_per_m: t.density_kg_per_m,
                axial_stiffness_n: t.axial_stiffness_n,
                damping_ns: t.damping_ns,
                diameter_m: t.diameter_m,
                drag_coefficient: t.drag_coefficient,
                segment_length_m: t.segment_length_m,
                min_stiffness_length_m: t.min_stiffness_length_m,
            },
            reel: ReelParams {
                model,
                locked: r.locked,
            },
            environment: Environment {
                mu_m3ps2: orbit.mu_m3ps2,
                j2: e.j2,
                drag: e.drag,
                linear_gradient: false,
            },
            sensing: match sc.plant.sensing {
                SensedDirection::Line => Sensing::Line,
                SensedDirection::Exit => Sensing::Exit,
            },
            courant: sc.plant.courant,
        }
    }
}
