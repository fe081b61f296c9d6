//! The tether: beads joined by spring–dampers that pull only in extension, and the feeding rule
//! that adds and removes beads at the reel (`feeding.rs`).
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
//! ## Feeding rule
//! Beads enter and leave at the reel by the rule of [`super::feeding`].
//!
//! ## Short reel segments
//! Before the first bead (and always when ρ = 0) the reel segment is the whole tether, starting
//! at l0 (1 m in the paper). Its spring is computed with the length max(l_r, l_k) in the
//! denominator (`min_stiffness_length_m` = l_k): a segment shorter than l_k is as compliant as
//! one of length l_k (as if l_k − l_r of tether lay between drum and exit). The extra stretch is
//! at most T·l_k/EA (≈ 0.5 mm for the paper-elastic tether at its early-deploy tensions, which
//! are below 0.1 N while l < l_k), and the highest frequency is √(EA/(l_k m)) instead of
//! growing without bound as l_r → 0. The step is chosen from the frequencies (see `mod.rs`).

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
        let n = self.nodes();
        masses.clear();
        masses.resize(n, rho * ls);
        masses[0] = main_initial_kg - rho * paid_out_m + 0.5 * rho * lr;
        if self.beads == 0 {
            masses[1] = sub_kg + 0.5 * rho * lr;
        } else {
            masses[1] = 0.5 * rho * (lr + ls);
            masses[n - 1] = sub_kg + 0.5 * rho * ls;
        }
    }
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
