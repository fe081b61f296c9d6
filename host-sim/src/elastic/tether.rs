//! The tether: beads joined by spring–dampers that pull only in extension, and the feeding rule
//! that adds and removes beads at the reel.
//!
//! ## Layout
//! Nodes, from the reel outward: 0 = the main satellite (with the deployer), 1…b = beads,
//! b + 1 = the sub-satellite. Segment s joins nodes s and s + 1. Segment 0, the *reel segment*,
//! has the variable unstretched length l_r; every other segment has the nominal length L_s. The
//! paid-out (unstretched) length is l_u = l_r + b·L_s, so l_r is derived from l_u and b.
//!
//! ## Masses (ρ carried by the beads)
//! Each segment's mass ρ·L is lumped half on each of its end nodes. The main satellite's own
//! mass is m1 = m01 − ρ l_u (the tether on the drum is part of it), so
//! node 0: m01 − ρ l_u + ½ρ l_r; bead 1: ½ρ(l_r + L_s); other beads: ρ L_s;
//! sub-satellite: m2 + ½ρ·(its segment's length). They sum to m01 + m2 whatever l_u and b.
//! As the reel pays out, mass ½ρ l̇ flows from node 0 to node 1 per second (the reel segment
//! grows): node 1 receives it at node 0's velocity (a momentum flux, see `mod.rs`).
//!
//! ## Feeding rule (insertion and removal at the reel)
//! Beads exist only when ρ > 0 (ρ = 0: a massless spring between the end bodies).
//! - **Insert** when l_r ≥ 2 L_s: a bead is placed on the reel segment where the unstretched
//!   length to node 1 is L_s, i.e. at the fraction f = (l_r − L_s)/l_r from node 0, its position
//!   interpolated at f and its velocity the *material's* there ([`material_velocity`]: the
//!   interpolated velocity plus (1 − f)(l̇/l_r)(p_1 − p_0), the paid-out tether's own motion,
//!   ≈ l̇/2 at an insertion). Its mass ½ρl_r comes ½ρ(l_r − L_s) from node 1, at node 1's
//!   velocity, and ½ρL_s from node 0, which also gives the momentum the material carries
//!   beyond the interpolation: the lumped reel segment held half its mass at node 0's velocity,
//!   and that half's motion outward was the reel end's. Mass, linear momentum and the centre of
//!   mass are conserved exactly; both new segments keep the old strain *and strain rate*, so
//!   every segment's tension (spring and damper) is continuous across the insertion but for
//!   node 0's recoil (bead mass/m_0 × l̇/2: 1e-4 m/s for paper-elastic at 10 m/s).
//! - **Remove** bead 1 when l_r < L_s (winding in): the reel segment becomes l_r + L_s < 2 L_s.
//!   Bead 1's mass goes ½ρL_s to node 0 and ½ρl_r to node 2, each with bead 1's velocity, a
//!   material point's (the receivers' velocities become the momentum-weighted means; the exact
//!   reverse of an insertion on a steadily moving tether): mass and linear momentum are
//!   conserved exactly; the centre of mass too when bead 1 lies on the chord between its
//!   neighbours (otherwise it moves by at most (bead mass)·(offset)/M).
//!
//! The band [L_s, 2 L_s) is a hysteresis of one full segment: no bead is inserted and removed
//! back and forth while the reel reverses. Once a bead exists the reel segment is never shorter
//! than L_s, so its stiffness EA/l_r stays below EA/L_s.
//!
//! ## Short reel segments
//! Before the first bead (and always when ρ = 0) the reel segment is the whole tether, starting
//! at l0 (1 m in the paper). Its spring is computed with the length max(l_r, l_k) in the
//! denominator (`min_stiffness_length_m` = l_k): a segment shorter than l_k is as compliant as
//! one of length l_k (as if l_k − l_r of tether lay between drum and exit). The extra stretch is
//! at most T·l_k/EA (≈ 0.5 mm for the paper-elastic tether at its early-deploy tensions, which
//! are below 0.1 N while l < l_k), and the highest frequency is √(EA/(l_k m)) instead of
//! growing without bound as l_r → 0. The step is chosen from the frequencies (see `mod.rs`).

use super::environment::Vec3;

/// The tether's material and discretisation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TetherParams {
    /// Linear density ρ, kg/m (0: a massless spring between the end bodies).
    pub density_kg_per_m: f64,
    /// Axial stiffness EA, N.
    pub axial_stiffness_n: f64,
    /// Structural damping C, N·s: the damping force is C·(strain rate) (Kelvin–Voigt).
    pub damping_ns: f64,
    /// Diameter, m (drag).
    pub diameter_m: f64,
    /// Drag coefficient of the tether in cross-flow.
    pub drag_coefficient: f64,
    /// Nominal unstretched segment length L_s, m (beads are L_s apart).
    pub segment_length_m: f64,
    /// l_k: a segment is never stiffer than EA/l_k, m (see the module doc).
    pub min_stiffness_length_m: f64,
}

impl TetherParams {
    /// `true` if the tether carries beads (ρ > 0).
    pub fn has_beads(&self) -> bool {
        self.density_kg_per_m > 0.0
    }

    /// Stiffness of a segment of unstretched length `length_m`, N/m.
    #[inline]
    pub fn stiffness_npm(&self, length_m: f64) -> f64 {
        self.axial_stiffness_n / length_m.max(self.min_stiffness_length_m)
    }

    /// Tension of a segment, N (≥ 0: a slack segment carries nothing).
    ///
    /// `chord_m` = distance between its ends, `chord_rate_mps` its rate of change,
    /// `length_m` = unstretched length L and `length_rate_mps` = L̇ (the reel rate for the reel
    /// segment, else 0). Spring EA(d − L)/L and damper C·d/dt((d − L)/L) ≈ C(ḋ − L̇ d/L)/L, with
    /// L replaced by max(L, l_k) in the denominators, acting only while d > L.
    #[inline]
    pub fn tension_n(
        &self,
        chord_m: f64,
        chord_rate_mps: f64,
        length_m: f64,
        length_rate_mps: f64,
    ) -> f64 {
        let stretch = chord_m - length_m;
        if stretch <= 0.0 {
            return 0.0;
        }
        let l_k = length_m.max(self.min_stiffness_length_m);
        let strain_rate_times_l = chord_rate_mps - length_rate_mps * chord_m / length_m;
        ((self.axial_stiffness_n * stretch + self.damping_ns * strain_rate_times_l) / l_k).max(0.0)
    }

    /// Elastic energy of a segment, J: ½ EA (d − L)²/max(L, l_k) while stretched.
    pub fn elastic_energy_j(&self, chord_m: f64, length_m: f64) -> f64 {
        let stretch = (chord_m - length_m).max(0.0);
        0.5 * self.stiffness_npm(length_m) * stretch * stretch
    }
}

/// Where the beads are: the count b and, from it and l_u, every segment's unstretched length
/// and every node's mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    /// Number of beads b.
    pub beads: usize,
}

impl Layout {
    /// The layout of a tether of `paid_out_m` paid out, as the feeding rule leaves it when the
    /// tether is paid out from zero: no beads below 2 L_s, else b = ⌊l_u/L_s⌋ − 1 so that
    /// l_r ∈ [L_s, 2 L_s).
    pub fn initial(tether: &TetherParams, paid_out_m: f64) -> Self {
        let ls = tether.segment_length_m;
        let beads = if tether.has_beads() && paid_out_m >= 2.0 * ls {
            (paid_out_m / ls).floor() as usize - 1
        } else {
            0
        };
        Self { beads }
    }

    /// Number of nodes (end bodies and beads).
    pub fn nodes(&self) -> usize {
        self.beads + 2
    }

    /// The reel segment's unstretched length l_r = l_u − b·L_s, m.
    #[inline]
    pub fn reel_segment_m(&self, tether: &TetherParams, paid_out_m: f64) -> f64 {
        paid_out_m - self.beads as f64 * tether.segment_length_m
    }

    /// Unstretched length of segment `s`, m.
    #[inline]
    pub fn segment_m(&self, tether: &TetherParams, paid_out_m: f64, s: usize) -> f64 {
        if s == 0 {
            self.reel_segment_m(tether, paid_out_m)
        } else {
            tether.segment_length_m
        }
    }

    /// Every node's mass, kg, into `masses` (resized to [`Layout::nodes`]).
    pub fn masses(
        &self,
        tether: &TetherParams,
        main_initial_kg: f64,
        sub_kg: f64,
        paid_out_m: f64,
        masses: &mut Vec<f64>,
    ) {
        let rho = tether.density_kg_per_m;
        let ls = tether.segment_length_m;
        let lr = self.reel_segment_m(tether, paid_out_m);
        masses.clear();
        masses.push(main_initial_kg - rho * paid_out_m + 0.5 * rho * lr);
        if self.beads == 0 {
            masses.push(sub_kg + 0.5 * rho * lr);
            return;
        }
        masses.push(0.5 * rho * (lr + ls));
        for _ in 1..self.beads {
            masses.push(rho * ls);
        }
        masses.push(sub_kg + 0.5 * rho * ls);
    }
}

/// What the feeding rule did at one check.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feed {
    /// Nothing: l_r is inside its band.
    Nothing,
    /// A bead was inserted at the reel.
    Inserted,
    /// The bead next to the reel was removed.
    Removed,
}

/// Applies the feeding rule once (see the module doc) to the nodes' positions and velocities
/// (`pos`, `vel`, relative to any common reference) with the paid-out length `paid_out_m`, the
/// reel paying out at `reel_rate_mps`, the nodes' masses `masses` before it acts.
pub fn feed(
    tether: &TetherParams,
    layout: &mut Layout,
    paid_out_m: f64,
    reel_rate_mps: f64,
    masses: &[f64],
    pos: &mut Vec<Vec3>,
    vel: &mut Vec<Vec3>,
) -> Feed {
    if !tether.has_beads() {
        return Feed::Nothing;
    }
    let rho = tether.density_kg_per_m;
    let ls = tether.segment_length_m;
    let lr = layout.reel_segment_m(tether, paid_out_m);
    if lr >= 2.0 * ls {
        let f = (lr - ls) / lr;
        let chord = pos[1] - pos[0];
        let v = material_velocity(pos, vel, lr, reel_rate_mps, f);
        // The bead's ½ρl_r: ½ρ(l_r − L_s) from node 1 at node 1's velocity; the reel end gives
        // ½ρL_s and the rest of the bead's momentum.
        let bead_kg = 0.5 * rho * lr;
        let interpolated = vel[0] + (vel[1] - vel[0]) * f;
        let main_kg = masses[0] - 0.5 * rho * ls;
        vel[0] -= (v - interpolated) * (bead_kg / main_kg);
        pos.insert(1, pos[0] + chord * f);
        vel.insert(1, v);
        layout.beads += 1;
        return Feed::Inserted;
    }
    if layout.beads > 0 && lr < ls {
        let (to_main, to_next) = (0.5 * rho * ls, 0.5 * rho * lr);
        let v1 = vel[1];
        vel[0] = (vel[0] * masses[0] + v1 * to_main) / (masses[0] + to_main);
        vel[2] = (vel[2] * masses[2] + v1 * to_next) / (masses[2] + to_next);
        pos.remove(1);
        vel.remove(1);
        layout.beads -= 1;
        return Feed::Removed;
    }
    Feed::Nothing
}

/// The velocity of the tether's material at the fraction `f` of the reel segment from node 0,
/// the segment of unstretched length `reel_segment_m` paying out at `reel_rate_mps`: the
/// segment is uniformly strained, x(σ) = p_0 + (σ/l_r)(p_1 − p_0) at the material coordinate σ
/// from the reel, and every paid-out material point's σ grows at l̇ (new tether enters at
/// σ = 0), so at f = σ/l_r
///
///   v(f) = v_0 + f (v_1 − v_0) + (1 − f)(l̇/l_r)(p_1 − p_0).
///
/// The last term is what linear interpolation of the end velocities misses (≈ l̇/2 at an
/// insertion): with it, both parts of a split segment keep the old segment's strain rate.
pub fn material_velocity(
    pos: &[Vec3],
    vel: &[Vec3],
    reel_segment_m: f64,
    reel_rate_mps: f64,
    f: f64,
) -> Vec3 {
    let chord = pos[1] - pos[0];
    vel[0] + (vel[1] - vel[0]) * f + chord * ((1.0 - f) * reel_rate_mps / reel_segment_m)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tether() -> TetherParams {
        TetherParams {
            density_kg_per_m: 0.2,
            axial_stiffness_n: 1e4,
            damping_ns: 10.0,
            diameter_m: 5e-4,
            drag_coefficient: 1.2,
            segment_length_m: 100.0,
            min_stiffness_length_m: 10.0,
        }
    }

    fn momentum(m: &[f64], v: &[Vec3]) -> Vec3 {
        m.iter().zip(v).map(|(m, v)| v * *m).sum()
    }

    fn centre(m: &[f64], p: &[Vec3]) -> Vec3 {
        m.iter().zip(p).map(|(m, p)| p * *m).sum::<Vec3>() / m.iter().sum::<f64>()
    }

    #[test]
    fn masses_sum_to_the_system_mass_for_every_layout() {
        let t = tether();
        let mut m = Vec::new();
        for lu in [1.0, 150.0, 199.9, 200.0, 950.0, 3_000.0] {
            let layout = Layout::initial(&t, lu);
            layout.masses(&t, 10_000.0, 100.0, lu, &mut m);
            assert_eq!(m.len(), layout.nodes());
            let total: f64 = m.iter().sum();
            assert!((total - 10_100.0).abs() < 1e-9, "{lu}: {total}");
            let lr = layout.reel_segment_m(&t, lu);
            assert!(
                layout.beads == 0 || (100.0..200.0).contains(&lr),
                "{lu}: {lr}"
            );
        }
    }

    #[test]
    fn insertion_conserves_momentum_and_the_centre_of_mass() {
        let t = tether();
        let mut layout = Layout { beads: 1 };
        let lu = 320.0; // l_r = 220 ≥ 2 L_s
        let mut pos = vec![
            Vec3::zeros(),
            Vec3::new(10.0, 219.0, 3.0),
            Vec3::new(20.0, 320.0, 5.0),
        ];
        let mut vel = vec![
            Vec3::new(0.1, 0.0, 0.0),
            Vec3::new(0.0, 2.0, -1.0),
            Vec3::new(0.5, 2.5, 0.0),
        ];
        let mut m = Vec::new();
        layout.masses(&t, 10_000.0, 100.0, lu, &mut m);
        let (p0, c0) = (momentum(&m, &vel), centre(&m, &pos));
        assert_eq!(
            feed(&t, &mut layout, lu, 2.0, &m, &mut pos, &mut vel),
            Feed::Inserted
        );
        layout.masses(&t, 10_000.0, 100.0, lu, &mut m);
        assert_eq!(m.len(), 4);
        assert!((momentum(&m, &vel) - p0).norm() < 1e-10);
        assert!((centre(&m, &pos) - c0).norm() < 1e-10);
        // The new reel segment is l_r − L_s; the new bead is L_s (unstretched) from node 2.
        assert_eq!(layout.reel_segment_m(&t, lu), 120.0);
        let f = 120.0 / 220.0;
        assert!((pos[1] - pos[0] * (1.0 - f) - pos[2] * f).norm() < 1e-12);
        assert_eq!(
            feed(&t, &mut layout, lu, 0.0, &m, &mut pos, &mut vel),
            Feed::Nothing
        );
    }

    /// Every segment's tension, N, with the reel paying out at `rate`.
    fn tensions(
        t: &TetherParams,
        layout: &Layout,
        lu: f64,
        rate: f64,
        p: &[Vec3],
        v: &[Vec3],
    ) -> Vec<f64> {
        (0..p.len() - 1)
            .map(|s| {
                let d = p[s + 1] - p[s];
                let chord_rate = (v[s + 1] - v[s]).dot(&d) / d.norm();
                let l_rate = if s == 0 { rate } else { 0.0 };
                t.tension_n(d.norm(), chord_rate, layout.segment_m(t, lu, s), l_rate)
            })
            .collect()
    }

    /// A tether paying out steadily (uniform strain ε, every paid-out node moving out at
    /// l̇(1 + ε), node 0 at rest): the material moves as one, so the new bead moves with node 1
    /// and no segment's tension changes (interpolating the end velocities gave the bead l̇/2
    /// too little and a damper dip on the reel segment).
    #[test]
    fn insertion_on_a_steady_pay_out_keeps_every_tension() {
        let t = tether();
        let (strain, rate) = (1e-3, 3.0);
        let mut layout = Layout { beads: 1 };
        let lu = 320.0;
        let along = Vec3::new(0.0, 1.0, 0.0);
        let mut pos = vec![
            Vec3::zeros(),
            along * 220.0 * (1.0 + strain),
            along * 320.0 * (1.0 + strain),
        ];
        let mut vel = vec![
            Vec3::zeros(),
            along * rate * (1.0 + strain),
            along * rate * (1.0 + strain),
        ];
        let before = tensions(&t, &layout, lu, rate, &pos, &vel);
        let mut m = Vec::new();
        layout.masses(&t, 10_000.0, 100.0, lu, &mut m);
        assert_eq!(
            feed(&t, &mut layout, lu, rate, &m, &mut pos, &mut vel),
            Feed::Inserted
        );
        let after = tensions(&t, &layout, lu, rate, &pos, &vel);
        assert!((vel[1] - vel[2]).norm() < 1e-12, "{:?}", vel);
        assert!((before[0] - 1e4 * strain).abs() < 1e-9);
        // The reel end recoils by (bead mass/m_0')(1 − f) l̇(1 + ε) (3 mm/s here: 22 kg of
        // bead on 9.9 t), which the reel segment's damper sees as C·(that)/l_r'.
        let recoil = 0.5 * 0.2 * 220.0 / (m[0] - 0.5 * 0.2 * 100.0)
            * (100.0 / 220.0)
            * rate
            * (1.0 + strain);
        let expect = 10.0 * recoil / 120.0;
        assert!(
            (after[0] - before[0] - expect).abs() < 1e-9,
            "{before:?} → {after:?}, recoil {expect}"
        );
        for s in 1..after.len() {
            assert!(
                (after[s] - before[0]).abs() < 1e-9 * before[0],
                "{before:?} → {after:?}"
            );
        }
    }

    #[test]
    fn removal_conserves_momentum_and_mass() {
        let t = tether();
        let mut layout = Layout { beads: 2 };
        let lu = 290.0; // l_r = 90 < L_s
        let mut pos = vec![
            Vec3::zeros(),
            Vec3::new(3.0, 90.0, 0.0),
            Vec3::new(4.0, 190.0, 1.0),
            Vec3::new(5.0, 290.0, 2.0),
        ];
        let mut vel = vec![
            Vec3::new(0.1, 0.0, 0.0),
            Vec3::new(0.3, -2.0, 0.7),
            Vec3::new(0.0, -2.1, 0.0),
            Vec3::new(0.5, -2.5, 0.0),
        ];
        let mut m = Vec::new();
        layout.masses(&t, 10_000.0, 100.0, lu, &mut m);
        let p0 = momentum(&m, &vel);
        assert_eq!(
            feed(&t, &mut layout, lu, 0.0, &m, &mut pos, &mut vel),
            Feed::Removed
        );
        layout.masses(&t, 10_000.0, 100.0, lu, &mut m);
        assert_eq!((m.len(), pos.len(), vel.len()), (3, 3, 3));
        assert!((m.iter().sum::<f64>() - 10_100.0).abs() < 1e-9);
        assert!((momentum(&m, &vel) - p0).norm() < 1e-10);
        assert_eq!(layout.reel_segment_m(&t, lu), 190.0);
    }

    #[test]
    fn a_slack_segment_carries_nothing_and_damping_never_pushes() {
        let t = tether();
        assert_eq!(t.tension_n(99.0, 5.0, 100.0, 0.0), 0.0);
        assert_eq!(t.tension_n(100.0, 5.0, 100.0, 0.0), 0.0);
        // Stretched but closing fast: the damper would push; the segment carries nothing.
        assert_eq!(t.tension_n(100.001, -100.0, 100.0, 0.0), 0.0);
        let f = t.tension_n(100.01, 0.0, 100.0, 0.0);
        assert!((f - 1e4 * 0.01 / 100.0).abs() < 1e-9);
        // Short segments are no stiffer than EA/l_k.
        assert!((t.tension_n(1.001, 0.0, 1.0, 0.0) - 1e4 * 0.001 / 10.0).abs() < 1e-9);
    }
}
