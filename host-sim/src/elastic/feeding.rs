//! The feeding rule: beads inserted and removed at the reel as the tether is paid out and
//! wound in (OrcaFlex's "line feeding" idea, with a mass-weighted split).
//!
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

use super::environment::Vec3;
use super::tether::{Layout, TetherParams};

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
}
