//! `[orbit]`, `[masses]`, `[tether]`: the physical system the controller flies (Eq. 5 of the
//! paper). The masses' and the tether's rules (positive masses, ρ ≥ 0, a tether lighter than
//! the main satellite) are the controller's (`core_rules.rs`); the orbit's perigee and the
//! elastic plant's tether keys are the scenario's.

use serde::{Deserialize, Serialize};

use super::rules::{num, Validator};

/// Equatorial radius of the Earth (WGS-84), m: altitudes are measured from it.
pub const EARTH_EQUATORIAL_RADIUS_M: f64 = 6_378_137.0;

/// The lowest perigee altitude a scenario may fly, m: 150 km. Below it the atmosphere
/// (2·10⁻⁹ kg/m³ at 150 km in `elastic::environment`'s table, 20 times that at 120 km) brings a
/// satellite down within about a day, faster than a mission of the paper's 20 h can be flown;
/// neither plant models the re-entry.
pub const MIN_PERIGEE_ALTITUDE_M: f64 = 150_000.0;

/// The radius of the Earth's Hill sphere, m: a⊕·(M⊕/3M☉)^(1/3) = 1.496·10¹¹ m × 0.01 ≈
/// 1.5·10⁹ m. Beyond it the Sun, not the Earth, holds a satellite: the apogee a(1 + e) must
/// lie inside it.
pub const EARTH_HILL_RADIUS_M: f64 = 1.5e9;

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
    /// θ(0) finite; the perigee a(1 − e) at least [`MIN_PERIGEE_ALTITUDE_M`] above the Earth
    /// and the apogee a(1 + e) inside its Hill sphere ([`EARTH_HILL_RADIUS_M`]); both blame
    /// the semi-major axis (a > 0 and the range of e are the controller's rules).
    pub(super) fn check(&self, v: &mut Validator) {
        let o = self;
        v.finite("orbit.initial_true_anomaly_rad", o.initial_true_anomaly_rad);
        if !(o.semi_major_axis_m.is_finite()
            && o.semi_major_axis_m > 0.0
            && (0.0..1.0).contains(&o.eccentricity))
        {
            return;
        }
        let (a, e) = (o.semi_major_axis_m, o.eccentricity);
        let perigee_m = a * (1.0 - e);
        let altitude_m = perigee_m - EARTH_EQUATORIAL_RADIUS_M;
        v.check(
            altitude_m >= MIN_PERIGEE_ALTITUDE_M,
            "orbit.semi_major_axis_m",
            num(a),
            &format!(
                "puts the perigee a(1 − e) = {} m (orbit.eccentricity = {}) at {} km of \
                 altitude, below the simulator's {} km (scenario::MIN_PERIGEE_ALTITUDE_M: the \
                 atmosphere brings it down within a day)",
                num(perigee_m),
                num(e),
                num((altitude_m / 1e3).round()),
                num(MIN_PERIGEE_ALTITUDE_M / 1e3)
            ),
        );
        let apogee_m = a * (1.0 + e);
        v.check(
            apogee_m <= EARTH_HILL_RADIUS_M,
            "orbit.semi_major_axis_m",
            num(a),
            &format!(
                "puts the apogee a(1 + e) = {} m beyond the Earth's Hill sphere ({} m, \
                 scenario::EARTH_HILL_RADIUS_M): the Sun, not the Earth, would hold the orbit",
                num(apogee_m),
                num(EARTH_HILL_RADIUS_M)
            ),
        );
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

/// `[tether]`. The rigid plant uses ρ only; the elastic plant all of it (the defaults are the
/// 0.5 mm Dyneema line of `scenarios/paper-elastic.toml`, massless unless ρ is given).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TetherSection {
    /// ρ, linear density, kg/m (0 = massless, the paper's run).
    #[serde(default)]
    pub density_kg_per_m: f64,
    /// EA, axial stiffness, N (elastic plant; default 10 kN).
    #[serde(default = "default_axial_stiffness_n")]
    pub axial_stiffness_n: f64,
    /// Structural (Kelvin–Voigt) damping C: force per unit strain rate, N·s (default 1000).
    #[serde(default = "default_damping_ns")]
    pub damping_ns: f64,
    /// Diameter for drag, m (default 0.5 mm).
    #[serde(default = "default_diameter_m")]
    pub diameter_m: f64,
    /// Drag coefficient in cross-flow (default 2.2, free-molecular flow on a cylinder).
    #[serde(default = "default_drag_coefficient")]
    pub drag_coefficient: f64,
    /// Unstretched length between beads L_s, m (default 1400 m: 20 beads at 30 km).
    #[serde(default = "default_segment_length_m")]
    pub segment_length_m: f64,
    /// A segment is never stiffer than EA over this length, m (default 50 m; ≤ L_s).
    #[serde(default = "default_min_stiffness_length_m")]
    pub min_stiffness_length_m: f64,
}

fn default_axial_stiffness_n() -> f64 {
    10_000.0
}
fn default_damping_ns() -> f64 {
    1_000.0
}
fn default_diameter_m() -> f64 {
    5e-4
}
fn default_drag_coefficient() -> f64 {
    2.2
}
fn default_segment_length_m() -> f64 {
    1_400.0
}
fn default_min_stiffness_length_m() -> f64 {
    50.0
}

impl Default for TetherSection {
    fn default() -> Self {
        Self {
            density_kg_per_m: 0.0,
            axial_stiffness_n: default_axial_stiffness_n(),
            damping_ns: default_damping_ns(),
            diameter_m: default_diameter_m(),
            drag_coefficient: default_drag_coefficient(),
            segment_length_m: default_segment_length_m(),
            min_stiffness_length_m: default_min_stiffness_length_m(),
        }
    }
}

impl TetherSection {
    /// The elastic plant's keys: EA > 0; C, d, C_d ≥ 0; 0 < l_k ≤ L_s. (ρ's rules are the
    /// controller's mass model's, `core_rules`.)
    pub(super) fn check(&self, v: &mut Validator) {
        v.positive("tether.axial_stiffness_n", self.axial_stiffness_n);
        v.non_negative("tether.damping_ns", self.damping_ns);
        v.non_negative("tether.diameter_m", self.diameter_m);
        v.non_negative("tether.drag_coefficient", self.drag_coefficient);
        let segment_ok = v.positive("tether.segment_length_m", self.segment_length_m);
        if v.positive("tether.min_stiffness_length_m", self.min_stiffness_length_m) && segment_ok {
            v.check(
                self.min_stiffness_length_m <= self.segment_length_m,
                "tether.min_stiffness_length_m",
                num(self.min_stiffness_length_m),
                &format!(
                    "must not exceed tether.segment_length_m = {}",
                    num(self.segment_length_m)
                ),
            );
        }
    }
}
