//! `[environment]`: J2, atmospheric drag and the orbit's inclination, for the elastic plant
//! (the rigid plant flies the paper's Keplerian orbit and ignores them).

use serde::{Deserialize, Serialize};

use super::rules::Validator;

/// `[environment]`
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSection {
    /// Add Earth's J2 to the gravity (default false).
    #[serde(default)]
    pub j2: bool,
    /// Apply drag in the shipped exponential atmosphere (default false).
    #[serde(default)]
    pub drag: bool,
    /// Inclination of the orbit plane to the equator, rad (default 0).
    #[serde(default)]
    pub inclination_rad: f64,
    /// Main satellite's drag coefficient × area C_d·A, m² (default 0).
    #[serde(default)]
    pub main_drag_area_m2: f64,
    /// Sub-satellite's C_d·A, m² (default 0).
    #[serde(default)]
    pub sub_drag_area_m2: f64,
}

impl EnvironmentSection {
    /// A finite inclination; drag areas ≥ 0.
    pub(super) fn check(&self, v: &mut Validator) {
        v.finite("environment.inclination_rad", self.inclination_rad);
        v.non_negative("environment.main_drag_area_m2", self.main_drag_area_m2);
        v.non_negative("environment.sub_drag_area_m2", self.sub_drag_area_m2);
    }
}
