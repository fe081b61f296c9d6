//! The scenario's validation: every section's rules, the rules between sections, what an
//! elastic run will cost, then the flight controller's own rules ([`Scenario::problems`]).

use super::control::LawName;
use super::error::Problem;
use super::mission::Scenario;
use super::plant::PlantModel;
use super::reel::ReelModelName;
use super::rules::Validator;
use super::{core_rules, cost, dispersible, telecommand};

impl Scenario {
    /// Checks that the scenario makes physical sense; returns every failed rule (empty =
    /// valid): the scenario's own rules section by section, then the first rule of the flight
    /// controller's configuration (built in f32, as flown) that fails.
    pub fn problems(&self) -> Vec<Problem> {
        let mut v = Validator::default();
        let s = self;
        s.check_name(&mut v);
        s.orbit.check(&mut v);
        s.initial.check(&mut v);
        s.initial.check_within(&s.envelope, &mut v);
        s.controller.check(&mut v);
        s.stage1.check(&mut v);
        s.stage2.check(&s.stage1, s.controller.period_s, &mut v);
        s.simulation.check(s.controller.period_s, &mut v);
        dispersible::check(s, &mut v);
        s.sensors.check(&mut v);
        s.faults.check(&mut v);
        s.reel.check(&mut v);
        s.reel.check_flight_drive(s.controller.period_s, &mut v);
        s.monitor.check(&mut v);
        s.link.check(&mut v);
        s.tether.check(&mut v);
        s.plant.check(s.controller.period_s, &mut v);
        s.environment.check(&mut v);
        telecommand::check(&s.telecommand, s.controller.period_s, &mut v);
        v.check(
            s.telecommand.is_empty() || s.controller.law == LawName::Paper,
            "telecommand",
            format!("{} telecommand(s)", s.telecommand.len()),
            "only the paper's law (the flight controller) takes telecommands",
        );
        s.check_elastic_only(&mut v);
        cost::check(s, &mut v);
        // The flight controller's own rules, last (it reports the first it finds).
        core_rules::check(s, &mut v);
        v.problems
    }

    /// The motor reel, J2 and drag exist only in the elastic plant: asking the rigid one for
    /// them is an error, not a silent no-op. On the elastic plant a tension law needs the motor
    /// reel.
    fn check_elastic_only(&self, v: &mut Validator) {
        if self.plant.model == PlantModel::Elastic {
            // A tension law drives the drum's torque: the elastic plant needs the drum.
            v.check(
                !self.controller.law.commands_tension() || self.reel.model == ReelModelName::Motor,
                "controller.law",
                format!("{:?}", self.controller.law.as_str()),
                "needs reel.model = \"motor\" on the elastic plant (a tension law drives the drum)",
            );
            return;
        }
        let needs = "needs plant.model = \"elastic\" (the rigid plant has no such model)";
        v.check(
            self.reel.model != ReelModelName::Motor,
            "reel.model",
            "\"motor\"".to_string(),
            needs,
        );
        v.check(
            self.reel.model != ReelModelName::FlightDrive,
            "reel.model",
            "\"flight_drive\"".to_string(),
            needs,
        );
        v.check(
            !self.environment.j2,
            "environment.j2",
            "true".to_string(),
            needs,
        );
        v.check(
            !self.environment.drag,
            "environment.drag",
            "true".to_string(),
            needs,
        );
        // The loop's gain is scheduled on the tether's compliance (EA): on a rod infinitely
        // stiffer than it is told it is unstable (docs/equations.md §17.3).
        v.check(
            !self.tension_loop.enabled,
            "tension_loop.enabled",
            "true".to_string(),
            "needs plant.model = \"elastic\" (the loop damps an elastic tether's bounce; on the \
             rigid rod, infinitely stiff, it is unstable: docs/equations.md §17.3)",
        );
    }

    /// `name` names the default output directory: a non-empty file name.
    fn check_name(&self, v: &mut Validator) {
        let name = &self.name;
        let ok = !name.trim().is_empty()
            && name != "."
            && name != ".."
            && !name
                .chars()
                .any(|c| c == '/' || c == '\\' || c.is_control());
        v.check(
            ok,
            "name",
            format!("{name:?}"),
            "must be a non-empty file name (no '/', '\\' or control characters, not '.' or '..')",
        );
    }
}
