//! A saturated tension law with an explicit positive-tension constraint, tracking a length-rate
//! schedule through Eq. 5a (docs/equations.md §15.2).
//!
//! **Schedule** l̇_ref(l): deploying (l < l_f) the exponential deployment of Modi & Misra
//! (Acta Astronautica 6, 1979: l̇ = kΩl keeps l̇/l, hence the Eq. 7 equilibrium angle,
//! constant) plus a start rate v0, tapered to 0 at l_f; beyond l_f (retrieving, or an
//! overshoot) a rate proportional to the distance:
//!
//!   l̇_ref = (v0 + kΩ l)(1 − l/l_f)   (l < l_f),      l̇_ref = k_in Ω (l_f − l)   (l ≥ l_f)
//!
//! so |l̇_ref/(Ωl)| ≤ k + v0/(Ωl) deploying and ≤ k_in winding in: with k, k_in ≤ 0.75 both stay
//! inside the Eq. 13 extent (|2 l̇/(Ωl)| ≤ 1.5) once v0/(Ωl) has faded. Retrieval is unstable in
//! libration (Eq. 18: the α damping term changes sign) and this law has no libration feedback,
//! so k_in is smaller (0.3: with 0.5 the paper's retrieval tumbles over at 2 km).
//!
//! **Tension**: Eq. 5a inverted about the local vertical (α = 0, α̇ = 0: the feed-forward does
//! not cancel the libration's coupling, which is what damps the libration, as in Rupp's law),
//! with a rate-error feedback κΩ:
//!
//!   T_c = m_r [3μ2Ω² l − μ1 l̇²/l − l̈_ref + κΩ (l̇ − l̇_ref)],  l̈_ref = (dl̇_ref/dl) l̇
//!
//! saturated in [T_min, T_max] with T_min > 0: the tether is never commanded slack (the explicit
//! positive-tension constraint of saturated tension laws; the structure — a reference profile
//! tracked through the tension by feedback on the rate error — is that of SEDS-2's closed-loop
//! deployment, Lorenzini, Bortolami, Rupp & Angrilli, J. Guidance 19(5), 1996; the schedule and
//! the gains here are this simulator's).
//!
//! Linearised about l = l_f on the vertical (τ = Ωt, λ = l/l_f − 1): λ'' = 2α' − (k + κ)λ' − κkλ
//! and α'' + 2λ' + 3α = 0 (k the schedule's slope there: k_in, or k + v0/(Ωl_f) from below),
//! so s⁴ + (k+κ)s³ + (κk + 7)s² + 3(k+κ)s + 3κk: stable for every k, κ > 0 (Routh–Hurwitz).

use tss_reel::mass::MassModel;

use super::sensed::Sensed;

/// The schedule's and the loop's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackingParams {
    /// k, the schedule's exponential rate in units of Ω (deploying).
    pub schedule_rate: f64,
    /// k_in, its rate beyond l_f (winding in), in units of Ω.
    pub retrieve_schedule_rate: f64,
    /// v0, the schedule's rate at l = 0 while deploying, m/s.
    pub start_rate_mps: f64,
    /// κ, the rate-error gain in units of Ω.
    pub rate_gain: f64,
    /// T_min > 0, N.
    pub min_tension_n: f64,
    /// T_max, N (inf = none).
    pub max_tension_n: f64,
}

/// The tracking law for one system.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tracking {
    /// Its parameters.
    pub params: TrackingParams,
    /// The system's masses (m_r, μ1, μ2 at the sensed length).
    pub masses: MassModel<f64>,
}

impl Tracking {
    /// The schedule at `l` toward `l_f`: (l̇_ref m/s, dl̇_ref/dl 1/s), with the orbit rate `w`.
    pub fn schedule(&self, l: f64, target_m: f64, w: f64) -> (f64, f64) {
        if l < target_m {
            let k = self.params.schedule_rate * w;
            let grow = self.params.start_rate_mps + k * l;
            let taper = 1.0 - l / target_m;
            (grow * taper, k * taper - grow / target_m)
        } else {
            let k = self.params.retrieve_schedule_rate * w;
            (k * (target_m - l), -k)
        }
    }

    /// T_c before the saturation, N (see the module doc).
    pub fn tension_n(&self, s: &Sensed, target_m: f64) -> f64 {
        let (l, v, w) = (s.length_m, s.rate_mps, s.orbit_rate_radps);
        let c = self.masses.coefficients(l);
        let (rate_ref, slope) = self.schedule(l, target_m, w);
        let vertical = 3.0 * c.mu2 * w * w * l - c.mu1 * v * v / l;
        let accel_ref = slope * v;
        c.radial_kg * (vertical - accel_ref + self.params.rate_gain * w * (v - rate_ref))
    }

    /// [`Tracking::tension_n`] inside [T_min, T_max].
    pub fn saturated_tension_n(&self, s: &Sensed, target_m: f64) -> f64 {
        let p = &self.params;
        self.tension_n(s, target_m)
            .clamp(p.min_tension_n, p.max_tension_n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law() -> Tracking {
        Tracking {
            params: TrackingParams {
                schedule_rate: 0.5,
                retrieve_schedule_rate: 0.3,
                start_rate_mps: 0.2,
                rate_gain: 2.0,
                min_tension_n: 0.01,
                max_tension_n: 50.0,
            },
            masses: MassModel::paper(),
        }
    }

    #[test]
    fn the_schedule_is_continuous_ends_at_the_target_and_its_slope_is_its_derivative() {
        let t = law();
        let w = 1.06e-3;
        let lf = 30_000.0;
        assert_eq!(t.schedule(lf, lf, w).0, 0.0);
        assert!((t.schedule(lf - 1e-6, lf, w).0).abs() < 1e-8);
        for l in [1.0, 500.0, 12_000.0, 29_000.0, 31_000.0, 45_000.0] {
            let (r, d) = t.schedule(l, lf, w);
            let h = 1e-3;
            let fd = (t.schedule(l + h, lf, w).0 - t.schedule(l - h, lf, w).0) / (2.0 * h);
            assert!((d - fd).abs() < 1e-9, "{l}: {d} vs {fd}");
            // Toward the target: out below it, in above it.
            assert!(r * (lf - l) > 0.0, "{l}: {r}");
        }
    }

    #[test]
    fn on_the_schedule_at_the_target_it_holds_the_vertical_tension() {
        let t = law();
        let w = 1.06e-3;
        let s = Sensed {
            length_m: 30_000.0,
            rate_mps: 0.0,
            alpha_rad: Some(0.3),
            alpha_rate_radps: None,
            orbit_rate_radps: w,
        };
        let m = MassModel::<f64>::paper().coefficients(30_000.0).radial_kg;
        let expect = 3.0 * m * w * w * 30_000.0;
        assert!((t.tension_n(&s, 30_000.0) - expect).abs() < 1e-12 * expect);
    }

    #[test]
    fn the_command_never_leaves_its_bounds() {
        let t = law();
        for (l, v) in [
            (1.0, 5.0),
            (1.0, -5.0),
            (30_000.0, -40.0),
            (30_000.0, 40.0),
            (10.0, 0.0),
        ] {
            let s = Sensed {
                length_m: l,
                rate_mps: v,
                alpha_rad: None,
                alpha_rate_radps: None,
                orbit_rate_radps: 1.06e-3,
            };
            let c = t.saturated_tension_n(&s, 30_000.0);
            assert!((0.01..=50.0).contains(&c), "{l} {v}: {c}");
        }
    }
}
