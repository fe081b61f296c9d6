//! Mass model of the main satellite, sub-satellite and tether (docs/equations.md §1, the paper's
//! nomenclature and Eq. 2).
//!
//! The tether (linear density ρ) is paid out of the main satellite, so m1 = m01 − ρl while the
//! system mass M = m1 + m2 + m_t = m01 + m2 stays constant. With ρ = 0 (the paper's Section 6)
//! μ1 = μ3 = 0 and μ2 = 1.

use crate::real::Real;

/// The masses that define the system: main satellite at release, sub-satellite, tether density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassModel<T> {
    /// m01, the main satellite's mass with the whole tether still on its reel, kg.
    pub main_initial_kg: T,
    /// m2, the sub-satellite's mass, kg.
    pub sub_kg: T,
    /// ρ, the tether's linear density, kg/m (0 for a massless tether).
    pub tether_density_kg_per_m: T,
}

/// The length-dependent coefficients of Eqs. 2 and 5, evaluated at one tether length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassCoefficients<T> {
    /// m1 = m01 − ρl, kg.
    pub main_kg: T,
    /// m_t = ρl, kg.
    pub tether_kg: T,
    /// M = m1 + m2 + m_t, kg.
    pub total_kg: T,
    /// M* = (m1 + m_t/2)(m2 + m_t/2)/M − m_t/6, kg (Eq. 2: T ∋ ½M*l²[β̇² + (θ̇+α̇)²cos²β]).
    pub reduced_kg: T,
    /// m_r = m1(m2 + m_t)/M, kg (the l̇² coefficient of T; tension T_t = m_r × (…) in Eq. 5a).
    pub radial_kg: T,
    /// μ1 = (2m1 − M) m_t / [2 m1 (m2 + m_t)] (Eq. 5a).
    pub mu1: T,
    /// μ2 = (m2 + m_t/2)/(m2 + m_t) (Eq. 5a).
    pub mu2: T,
    /// μ3 = 2[m1(m2 + m_t/2)/(M M*) − 1] = l·(dM*/dl)/M* (Eqs. 5b, 5c; docs/equations.md §9.1).
    pub mu3: T,
}

impl<T: Real> MassModel<T> {
    /// The paper's Section-6 masses: m01 = 10 000 kg, m2 = 100 kg, massless tether.
    pub fn paper() -> Self {
        Self {
            main_initial_kg: T::from_f64(10_000.0),
            sub_kg: T::from_f64(100.0),
            tether_density_kg_per_m: T::ZERO,
        }
    }

    /// The coefficients of Eqs. 2 and 5 at tether length `length_m`.
    pub fn coefficients(&self, length_m: T) -> MassCoefficients<T> {
        let two = T::from_f64(2.0);
        let six = T::from_f64(6.0);
        let m2 = self.sub_kg;
        let mt = self.tether_density_kg_per_m * length_m;
        let m1 = self.main_initial_kg - mt;
        let total = m1 + m2 + mt;
        let half_mt = mt / two;
        let reduced = (m1 + half_mt) * (m2 + half_mt) / total - mt / six;
        MassCoefficients {
            main_kg: m1,
            tether_kg: mt,
            total_kg: total,
            reduced_kg: reduced,
            radial_kg: m1 * (m2 + mt) / total,
            mu1: (two * m1 - total) * mt / (two * m1 * (m2 + mt)),
            mu2: (m2 + half_mt) / (m2 + mt),
            mu3: two * (m1 * (m2 + half_mt) / (total * reduced) - T::ONE),
        }
    }

    /// (μ3, dμ3/dl) at `length_m`: what the law needs, from one evaluation of the
    /// coefficients (both 0 for a massless tether, without any arithmetic).
    #[inline]
    pub fn mu3_and_slope(&self, length_m: T) -> (T, T) {
        if self.tether_density_kg_per_m == T::ZERO {
            return (T::ZERO, T::ZERO);
        }
        (
            self.coefficients(length_m).mu3,
            self.mu3_rate_per_s(length_m, T::ONE),
        )
    }

    /// μ̇3 = ρ l̇ [−m01(m2 + m_t/2)² + ⅓M(m01 m2 + m_t²/2)]/(M M*)², 1/s (the paper's
    /// expression after Eq. 30; docs/equations.md §1). Zero for a massless tether.
    pub fn mu3_rate_per_s(&self, length_m: T, length_rate_mps: T) -> T {
        let c = self.coefficients(length_m);
        let two = T::from_f64(2.0);
        let three = T::from_f64(3.0);
        let m01 = self.main_initial_kg;
        let m2 = self.sub_kg;
        let mt = c.tether_kg;
        let num = -m01 * (m2 + mt / two).sq() + c.total_kg * (m01 * m2 + mt.sq() / two) / three;
        self.tether_density_kg_per_m * length_rate_mps * num / (c.total_kg * c.reduced_kg).sq()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn thin_tether() -> MassModel<f64> {
        MassModel {
            tether_density_kg_per_m: 1e-3,
            ..MassModel::paper()
        }
    }

    #[test]
    fn massless_tether_reduces_to_dumbbell() {
        let c = MassModel::<f64>::paper().coefficients(30_000.0);
        // M* = m1 m2 / M = 1e6/10100.
        assert!((c.reduced_kg - 99.009_900_990_099_01).abs() < 1e-12);
        assert!((c.radial_kg - c.reduced_kg).abs() < 1e-12);
        assert_eq!(c.mu1, 0.0);
        assert_eq!(c.mu2, 1.0);
        assert!(c.mu3.abs() < 1e-15);
        assert_eq!(MassModel::<f64>::paper().mu3_rate_per_s(30_000.0, 2.0), 0.0);
    }

    #[test]
    fn thin_tether_at_30_km_matches_hand_values() {
        // ρ = 1e-3 kg/m, l = 30 km: m_t = 30 kg, m1 = 9970 kg, M = 10100 kg (worked by hand
        // from docs/equations.md §1).
        let c = thin_tether().coefficients(30_000.0);
        assert!((c.tether_kg - 30.0).abs() < 1e-12);
        assert!((c.main_kg - 9970.0).abs() < 1e-12);
        assert!((c.total_kg - 10_100.0).abs() < 1e-12);
        assert!((c.reduced_kg - 108.690_594_059_405_94).abs() < 1e-9);
        assert!((c.radial_kg - 128.326_732_673_267_32).abs() < 1e-9);
        assert!((c.mu1 - 0.113_880_101_843_993_53).abs() < 1e-12);
        assert!((c.mu2 - 0.884_615_384_615_384_6).abs() < 1e-12);
        assert!((c.mu3 - 0.088_861_560_884_516_24).abs() < 1e-12);
    }

    #[test]
    fn mu3_is_log_derivative_of_reduced_mass() {
        // μ3 = l (dM*/dl) / M*  (docs/equations.md §1).
        let m = thin_tether();
        for &l in &[10.0, 2_000.0, 30_000.0, 100_000.0] {
            let h = 1e-3 * l;
            let d =
                (m.coefficients(l + h).reduced_kg - m.coefficients(l - h).reduced_kg) / (2.0 * h);
            let c = m.coefficients(l);
            assert!((c.mu3 - l * d / c.reduced_kg).abs() < 1e-8, "l = {l}");
        }
    }

    #[test]
    fn mu3_and_slope_is_mu3_and_its_length_derivative() {
        let m = thin_tether();
        let (mu3, slope) = m.mu3_and_slope(12_000.0);
        assert_eq!(mu3, m.coefficients(12_000.0).mu3);
        assert_eq!(slope, m.mu3_rate_per_s(12_000.0, 1.0));
        assert_eq!(
            MassModel::<f64>::paper().mu3_and_slope(12_000.0),
            (0.0, 0.0)
        );
    }

    #[test]
    fn mu3_rate_is_chain_rule_derivative() {
        let m = thin_tether();
        let (l, ld) = (12_000.0, 1.7);
        let h = 1e-2;
        let fd = (m.coefficients(l + h).mu3 - m.coefficients(l - h).mu3) / (2.0 * h) * ld;
        assert!(
            (m.mu3_rate_per_s(l, ld) - fd).abs() < 1e-12,
            "{} vs {fd}",
            m.mu3_rate_per_s(l, ld)
        );
    }
}
