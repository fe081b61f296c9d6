//! What an elastic run will cost, worked out from the scenario before it flies, and refused
//! beyond a stated bound: its memory (the nodes the tether can hold, the shapes it records)
//! and its time (node steps: nodes × RK4 substeps, summed over the run).
//!
//! The elastic plant (`crate::elastic`) chooses its substep each period so that (fastest
//! rate × step) ≤ `plant.courant`. The estimate here bounds that rate from above for every
//! configuration the run can reach, from the scenario's values alone (docs/truth-model.md,
//! "Integration"):
//!
//! - with beads (ρ > 0 and at least 2 L_s paid out), every segment is at least L_s long
//!   (interior ones exactly L_s, the reel segment in [L_s, 2 L_s)) and every bead weighs at
//!   least ρ L_s: ω ≤ √(EA/L_s · 1/m) and C/L_s · 1/m, with 1/m ≤ 2/(ρ L_s) + 1/m₁ + 1/m₂
//!   (+ r²/J through the drum on the reel segment);
//! - without beads the whole tether is one segment no stiffer than EA/l_k between the end
//!   bodies: ω ≤ √(EA/l_k · 1/m) and C/l_k · 1/m with 1/m ≤ 1/m₁ + 1/m₂ + r²/J;
//! - the drum's speed loop 2ω_b and its viscous rate b/J.
//!
//! m₁ is the main satellite with the whole spool paid out (m01 − ρ l_max), m₂ the
//! sub-satellite. The tether never outgrows the spool, `envelope.max_length_m` (the run stops
//! there: `crate::sim`), so the nodes are at most ⌊l_max/L_s⌋ + 1. Each control period takes
//! at most ⌈period·ω/courant⌉ substeps (the flight drive: that many per inner tick, at least
//! one per tick). The estimate is an upper bound: the shipped scenarios run below it.
//!
//! When a bound is passed, the key blamed is the one whose default would bring the run
//! closest to its bound (the dominant cause), named with its value and the figures.

use super::dispersible::nominal_value;
use super::mission::Scenario;
use super::plant::PlantModel;
use super::reel::{ReelModelName, ReelSection};
use super::rules::{is_positive, num, Validator};
use super::system::TetherSection;

/// The most nodes (end bodies and beads) the elastic plant may hold: 10⁵, about 50 MB of state
/// and integration workspace at [`BYTES_PER_NODE`].
pub const MAX_ELASTIC_NODES: f64 = 1e5;

/// Memory of one node in the elastic plant, bytes, rounded up: position and velocity, mass,
/// the four RK4 stages of both and the feeding rule's workspace (≈ 40 f64).
pub const BYTES_PER_NODE: f64 = 512.0;

/// The most node steps of an elastic run (nodes × RK4 substeps over the whole run): 10¹⁰,
/// about an hour of desk time at the few tenths of a microsecond a node step costs
/// (`tss-sim run scenarios/paper-elastic.toml`, 6·10⁶ node steps, flies in about 2 s), five
/// times the estimate of `scenarios/paper-drive.toml`, the costliest shipped scenario.
pub const MAX_ELASTIC_NODE_STEPS: f64 = 1e10;

/// The most tether-shape points an elastic run records (shapes × nodes): 10⁷, 240 MB of
/// 3-vectors.
pub const MAX_SHAPE_POINTS: f64 = 1e7;

/// The figures the estimate is made of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElasticCost {
    /// Most nodes the tether can hold.
    pub nodes: f64,
    /// The fastest rate any configuration of the run can reach, rad/s (or 1/s).
    pub fastest_radps: f64,
    /// RK4 substeps of the whole run, at most.
    pub steps: f64,
    /// Shapes recorded (`plant.shape_interval_s`), at most.
    pub shapes: f64,
}

impl ElasticCost {
    /// Nodes × steps.
    pub fn node_steps(&self) -> f64 {
        self.nodes * self.steps
    }

    /// Shapes × nodes.
    pub fn shape_points(&self) -> f64 {
        self.shapes * self.nodes
    }
}

/// The scenario's values the estimate reads, so that one of them can be set to its default.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Inputs {
    tether: Tether,
    reel: Drum,
    courant: f64,
    shape_interval_s: f64,
    period_s: f64,
    duration_s: f64,
    spool_m: f64,
    main_kg: f64,
    sub_kg: f64,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Tether {
    density_kg_per_m: f64,
    axial_stiffness_n: f64,
    damping_ns: f64,
    segment_length_m: f64,
    min_stiffness_length_m: f64,
}

impl From<&TetherSection> for Tether {
    fn from(t: &TetherSection) -> Self {
        Self {
            density_kg_per_m: t.density_kg_per_m,
            axial_stiffness_n: t.axial_stiffness_n,
            damping_ns: t.damping_ns,
            segment_length_m: t.segment_length_m,
            min_stiffness_length_m: t.min_stiffness_length_m,
        }
    }
}

/// The drum, when the reel has one turning (`None`: an ideal, lagging or locked reel).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Drum {
    turning: bool,
    radius_m: f64,
    inertia_kgm2: f64,
    viscous_nms: f64,
    speed_bandwidth_radps: f64,
    /// The flight drive's inner rate, Hz (`None`: the motor reel's own loop, or no drum).
    inner_rate_hz: Option<f64>,
}

impl Drum {
    fn of(r: &ReelSection) -> Self {
        Self {
            turning: !r.locked && r.model != ReelModelName::Drive,
            radius_m: r.drum_radius_m,
            inertia_kgm2: r.drum_inertia_kgm2,
            viscous_nms: r.viscous_nms,
            speed_bandwidth_radps: r.speed_bandwidth_radps,
            inner_rate_hz: (!r.locked && r.model == ReelModelName::FlightDrive)
                .then_some(f64::from(r.inner_rate_hz)),
        }
    }
}

impl Inputs {
    fn of(sc: &Scenario) -> Self {
        Self {
            tether: (&sc.tether).into(),
            reel: Drum::of(&sc.reel),
            courant: sc.plant.courant,
            shape_interval_s: sc.plant.shape_interval_s,
            period_s: sc.controller.period_s,
            duration_s: sc.simulation.duration_s,
            spool_m: sc.envelope.max_length_m,
            main_kg: sc.masses.main_initial_kg,
            sub_kg: sc.masses.sub_kg,
        }
    }

    /// Every value the estimate divides by or takes a root of passed its own rules.
    fn valid(&self) -> bool {
        let t = &self.tether;
        let d = &self.reel;
        [
            t.axial_stiffness_n,
            t.segment_length_m,
            t.min_stiffness_length_m,
            self.courant,
            self.period_s,
            self.duration_s,
            self.spool_m,
            self.main_kg,
            self.sub_kg,
            d.radius_m,
            d.inertia_kgm2,
        ]
        .into_iter()
        .all(is_positive)
            && [
                t.density_kg_per_m,
                t.damping_ns,
                d.viscous_nms,
                d.speed_bandwidth_radps,
            ]
            .into_iter()
            .all(|x| x.is_finite() && x >= 0.0)
            && self.shape_interval_s.is_finite()
            && self.shape_interval_s >= 0.0
            && self.main_kg > t.density_kg_per_m * self.spool_m
    }

    fn cost(&self) -> ElasticCost {
        let t = &self.tether;
        let d = &self.reel;
        let ls = t.segment_length_m;
        let beads = if t.density_kg_per_m > 0.0 && self.spool_m >= 2.0 * ls {
            (self.spool_m / ls).floor() - 1.0
        } else {
            0.0
        };
        let drum_inv_kg = if d.turning {
            d.radius_m * d.radius_m / d.inertia_kgm2
        } else {
            0.0
        };
        let ends_inv_kg = 1.0 / (self.main_kg - t.density_kg_per_m * self.spool_m)
            + 1.0 / self.sub_kg
            + drum_inv_kg;
        // One segment between the end bodies, never stiffer than EA/l_k.
        let segment = |length_m: f64, inv_kg: f64| {
            (t.axial_stiffness_n / length_m * inv_kg)
                .sqrt()
                .max(t.damping_ns / length_m * inv_kg)
        };
        let mut fastest = segment(t.min_stiffness_length_m, ends_inv_kg);
        if beads > 0.0 {
            let bead_inv_kg = 2.0 / (t.density_kg_per_m * ls) + ends_inv_kg;
            fastest = fastest.max(segment(ls, bead_inv_kg));
        }
        if d.turning {
            fastest = fastest
                .max(2.0 * d.speed_bandwidth_radps)
                .max(d.viscous_nms / d.inertia_kgm2);
        }
        let periods = (self.duration_s / self.period_s).round();
        // ⌈x⌉ ≤ x + 1 per step of the plant's own choice; the flight drive takes at least one
        // substep per inner tick.
        let per_period = self.period_s * fastest / self.courant
            + d.inner_rate_hz
                .map_or(1.0, |hz| (self.period_s * hz).round().max(1.0));
        let shapes = if self.shape_interval_s > 0.0 {
            (self.duration_s / self.shape_interval_s).floor() + 2.0
        } else {
            1.0
        };
        ElasticCost {
            nodes: beads + 2.0,
            fastest_radps: fastest,
            steps: periods * per_period,
            shapes,
        }
    }
}

/// The elastic run's cost estimate (`None`: not the elastic plant, or a value it reads failed
/// its own rule, reported there).
pub fn elastic_cost(sc: &Scenario) -> Option<ElasticCost> {
    let inputs = Inputs::of(sc);
    (sc.plant.model == PlantModel::Elastic && inputs.valid()).then(|| inputs.cost())
}

/// A key the estimate reads, with how to set it to its default.
type Reset = (&'static str, fn(&mut Inputs));

/// The keys that can make the elastic plant's steps many, and their defaults.
const STEP_KEYS: [Reset; 9] = [
    ("tether.axial_stiffness_n", |x| {
        x.tether.axial_stiffness_n = TetherSection::default().axial_stiffness_n
    }),
    ("tether.damping_ns", |x| {
        x.tether.damping_ns = TetherSection::default().damping_ns
    }),
    ("tether.segment_length_m", |x| {
        x.tether.segment_length_m = TetherSection::default().segment_length_m
    }),
    ("tether.min_stiffness_length_m", |x| {
        x.tether.min_stiffness_length_m = TetherSection::default().min_stiffness_length_m
    }),
    ("plant.courant", |x| x.courant = 1.0),
    ("reel.drum_inertia_kgm2", |x| {
        x.reel.inertia_kgm2 = ReelSection::default().drum_inertia_kgm2
    }),
    ("reel.drum_radius_m", |x| {
        x.reel.radius_m = ReelSection::default().drum_radius_m
    }),
    ("reel.viscous_nms", |x| {
        x.reel.viscous_nms = ReelSection::default().viscous_nms
    }),
    ("reel.inner_rate_hz", |x| {
        if x.reel.inner_rate_hz.is_some() {
            x.reel.inner_rate_hz = Some(f64::from(ReelSection::default().inner_rate_hz));
        }
    }),
];

/// The key of `keys` whose default lowers `measure` most (`None`: none lowers it).
fn dominant(
    inputs: &Inputs,
    keys: &[Reset],
    measure: fn(&ElasticCost) -> f64,
) -> Option<&'static str> {
    let now = measure(&inputs.cost());
    keys.iter()
        .map(|(key, reset)| {
            let mut x = *inputs;
            reset(&mut x);
            (*key, measure(&x.cost()))
        })
        .filter(|(_, m)| *m < now)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(key, _)| key)
}

/// Refuses an elastic run whose memory or time passes its bound ([`MAX_ELASTIC_NODES`],
/// [`MAX_SHAPE_POINTS`], [`MAX_ELASTIC_NODE_STEPS`]), naming the key that causes it.
pub(super) fn check(sc: &Scenario, v: &mut Validator) {
    let Some(cost) = elastic_cost(sc) else {
        return;
    };
    let value = |key: &str| nominal_value(sc, key).map_or_else(|| "?".to_string(), num);
    let nodes_ok = v.check(
        cost.nodes <= MAX_ELASTIC_NODES,
        "tether.segment_length_m",
        value("tether.segment_length_m"),
        &format!(
            "makes {} nodes on the spool's envelope.max_length_m = {} m, more than the \
             simulator's {} (scenario::MAX_ELASTIC_NODES, {:.0} MB; about {:.1} GB asked)",
            num(cost.nodes),
            num(sc.envelope.max_length_m),
            num(MAX_ELASTIC_NODES),
            MAX_ELASTIC_NODES * BYTES_PER_NODE / 1e6,
            cost.nodes * BYTES_PER_NODE / 1e9
        ),
    );
    if !nodes_ok {
        return;
    }
    v.check(
        cost.shape_points() <= MAX_SHAPE_POINTS,
        "plant.shape_interval_s",
        value("plant.shape_interval_s"),
        &format!(
            "records {} shapes of {} nodes over simulation.duration_s = {}, more than the \
             simulator's {} points (scenario::MAX_SHAPE_POINTS)",
            num(cost.shapes),
            num(cost.nodes),
            num(sc.simulation.duration_s),
            num(MAX_SHAPE_POINTS)
        ),
    );
    if cost.node_steps() <= MAX_ELASTIC_NODE_STEPS {
        return;
    }
    let inputs = Inputs::of(sc);
    let key =
        dominant(&inputs, &STEP_KEYS, ElasticCost::node_steps).unwrap_or("simulation.duration_s");
    v.check(
        false,
        key,
        value(key),
        &format!(
            "makes the elastic plant's run about {:.1e} node steps ({} nodes × {:.1e} RK4 \
             substeps: its fastest rate {:.3e} rad/s at plant.courant = {}), more than the \
             simulator's {:.0e} (scenario::MAX_ELASTIC_NODE_STEPS)",
            cost.node_steps(),
            num(cost.nodes),
            cost.steps,
            cost.fastest_radps,
            num(sc.plant.courant),
            MAX_ELASTIC_NODE_STEPS
        ),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper_elastic() -> Scenario {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../scenarios/paper-elastic.toml"
        );
        Scenario::load(path, &[]).unwrap()
    }

    /// The paper's elastic mission: 29 nodes at most, its fastest rate the speed loop's 2ω_b
    /// = 10 rad/s (the bead segments' √(EA/L_s · 2/(ρL_s)) ≈ 7.4 rad/s, the whole tether
    /// before the first bead √(EA/l_k · r²/J) ≈ 6.5 rad/s).
    #[test]
    fn the_paper_s_elastic_mission_costs_what_its_modes_say() {
        let c = elastic_cost(&paper_elastic()).unwrap();
        assert_eq!(c.nodes, 29.0);
        assert!((c.fastest_radps - 10.0).abs() < 1e-12, "{c:?}");
        // 72 000 periods of at most 5 + 1 substeps (paper-elastic flies at courant 2).
        assert_eq!(c.steps, 72_000.0 * 6.0);
        assert!(c.node_steps() < MAX_ELASTIC_NODE_STEPS * 1e-2);
    }
}
