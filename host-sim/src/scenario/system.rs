//! `[orbit]`, `[masses]`, `[tether]`: the physical system the controller flies (Eq. 5 of the
//! paper). The masses' and the tether's rules (positive masses, ρ ≥ 0, a tether lighter than
//! the main satellite) are the controller's (`core_rules.rs`); the orbit's perigee is the
//! scenario's.

use serde::{Deserialize, Serialize};

use super::rules::{num, Validator};

/// Equatorial radius of the Earth (WGS-84), m: the orbit's perigee must lie above it.
pub const EARTH_EQUATORIAL_RADIUS_M: f64 = 6_378_137.0;

/// `[orbit]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrbitSection {
    /// Semi-major axis a (the radius of a circular orbit), m.
    pub semi_major_axis_m: f64,
    /// Eccentricity e, in [0, 1).
    #[serde(default)]
    pub eccentricity: f64,
    /// True anomaly θ at t = 0, rad.
    #[serde(default)]
    pub initial_true_anomaly_rad: f64,
}

impl OrbitSection {
    /// θ(0) finite, and the perigee a(1 − e) above the Earth's surface (a > 0 and the range
    /// of e are the controller's rules).
    pub(super) fn check(&self, v: &mut Validator) {
        let o = self;
        v.finite("orbit.initial_true_anomaly_rad", o.initial_true_anomaly_rad);
        if o.semi_major_axis_m.is_finite()
            && o.semi_major_axis_m > 0.0
            && (0.0..1.0).contains(&o.eccentricity)
        {
            let perigee_m = o.semi_major_axis_m * (1.0 - o.eccentricity);
            v.check(
                perigee_m > EARTH_EQUATORIAL_RADIUS_M,
                "orbit.semi_major_axis_m",
                num(o.semi_major_axis_m),
                &format!(
                    "puts the perigee a(1 − e) = {} m (orbit.eccentricity = {}) inside the Earth \
                     (radius {EARTH_EQUATORIAL_RADIUS_M} m)",
                    num(perigee_m),
                    num(o.eccentricity)
                ),
            );
        }
    }
}

/// `[masses]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassesSection {
    /// m01, main satellite with the whole tether on the reel, kg.
    pub main_initial_kg: f64,
    /// m2, sub-satellite, kg.
    pub sub_kg: f64,
}

/// `[tether]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TetherSection {
    /// ρ, linear density, kg/m (0 = massless, the paper's run).
    #[serde(default)]
    pub density_kg_per_m: f64,
}
