//! `[plant]`: which plant the run flies (the rigid rod of Eq. 5 or the elastic truth model,
//! `crate::elastic`), and what the controller's angle sensor sees on the elastic one.

use serde::{Deserialize, Serialize};

use super::rules::{num, Validator};

/// The plant model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlantModel {
    /// The paper's Eq. 5: a rigid, straight tether (`crate::plant`).
    #[default]
    Rigid,
    /// The truth model: elastic 3-D bead tether, reel mechanism, J2 and drag (`crate::elastic`).
    Elastic,
}

/// The direction the controller's α (and β) describe on the elastic plant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SensedDirection {
    /// The line from the main satellite to the sub-satellite.
    #[default]
    Line,
    /// The tether's exit direction at the deployer.
    Exit,
}

/// `[plant]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlantSection {
    /// `"rigid"` (default, the paper's Eq. 5) or `"elastic"`.
    #[serde(default)]
    pub model: PlantModel,
    /// Elastic plant: what the angle sensor sees, `"line"` (default) or `"exit"`.
    #[serde(default)]
    pub sensing: SensedDirection,
    /// Elastic plant: the largest (rate × step) of its integration, in (0, 2] (default 1).
    #[serde(default = "one")]
    pub courant: f64,
    /// Elastic plant: record the tether's shape every this many seconds (a whole number of
    /// control periods; 0 = only at the end; default 3600).
    #[serde(default = "hour")]
    pub shape_interval_s: f64,
}

fn hour() -> f64 {
    3600.0
}

fn one() -> f64 {
    1.0
}

impl Default for PlantSection {
    fn default() -> Self {
        Self {
            model: PlantModel::Rigid,
            sensing: SensedDirection::Line,
            courant: 1.0,
            shape_interval_s: hour(),
        }
    }
}

impl PlantSection {
    /// The step factor in (0, 2] (RK4 is stable to 2.8 on the imaginary axis); a shape
    /// interval ≥ 0 of whole control periods.
    pub(super) fn check(&self, period_s: f64, v: &mut Validator) {
        if v.non_negative("plant.shape_interval_s", self.shape_interval_s)
            && self.shape_interval_s > 0.0
        {
            v.whole_multiple_of_period(
                "plant.shape_interval_s",
                self.shape_interval_s,
                period_s,
                false,
            );
        }
        if v.positive("plant.courant", self.courant) {
            v.check(
                self.courant <= 2.0,
                "plant.courant",
                num(self.courant),
                "must be at most 2 (RK4's stability limit is 2.8)",
            );
        }
    }
}
