//! The scenario turned into the parameter types of the models it configures. The models (the
//! fault injector, the reel drive, the fault summary) never read the schema: each takes its own
//! parameters, and the conversions from the sections live here.

use tss_reel::controller::Envelope;
use tss_reel::Real;

use crate::faults::{
    Corruption, FaultSetup, Glitch, InjectionPlan, SensedQuantity, SensorErrors, Window,
};
use crate::reel::ReelDrive;

use super::{EnvelopeSection, ReelSection, Scenario, SensorName, SensorSection, WindowSection};

impl From<&SensorSection> for SensorErrors {
    fn from(s: &SensorSection) -> Self {
        Self {
            noise_std: s.noise_std,
            bias: s.bias,
            quantum: s.quantum,
            stuck_from_s: s.stuck_from_s,
            stuck_until_s: s.stuck_until_s,
        }
    }
}

impl From<SensorName> for SensedQuantity {
    fn from(s: SensorName) -> Self {
        match s {
            SensorName::Length => Self::Length,
            SensorName::Alpha => Self::Alpha,
            SensorName::AlphaRate => Self::AlphaRate,
            SensorName::OrbitRate => Self::OrbitRate,
        }
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
            alpha: (&s.alpha).into(),
            alpha_rate: (&s.alpha_rate).into(),
            dropout: f.dropout.iter().map(Window::from).collect(),
            corrupt: f
                .corrupt
                .iter()
                .map(|c| Corruption {
                    sensor: c.sensor.into(),
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
            envelope: sc.envelope.to_envelope(),
        }
    }
}
