//! Rupp's tension law (C. C. Rupp, "A tether tension control law for tethered subsatellites
//! deployed along local vertical", NASA TM X-64963, 1975; patented with R. R. Kissel,
//! "Tetherline system for orbiting satellites", 1976–78), docs/equations.md §15.1:
//!
//!   T_c = m_e Ω² [a (l − l_f) + b l̇/Ω + c l_f]
//!
//! with m_e the system's radial mass (m_r of Eq. 5a; the reduced mass m1m2/M for a massless
//! tether), Ω the orbit rate, l_f the length the stage heads for (the keep length) and a, b, c
//! dimensionless gains. The reel holds T_c (through its torque, not its rate); a tether can
//! only pull, so the command is floored at 0 ([`super::LawStepper`]).
//!
//! Why it works (linearised about l = l_f on the local vertical, massless tether, circular
//! orbit; τ = Ωt, λ = l/l_f − 1): Eq. 5a gives λ'' − 2α' − 3λ = −a λ − b λ' + (3 − c), so
//! c = 3 makes l_f the equilibrium, and with Eq. 5b (α'' + 2λ' + 3α = 0) the loop's
//! characteristic polynomial is s⁴ + b s³ + (a + 4) s² + 3b s + 3(a − 3): by Routh–Hurwitz
//! stable iff a > 3 and b > 0. The libration is damped only through the Coriolis coupling
//! (the 2α' and 2λ' terms), which is why the law's keep is slow to settle.

use tss_reel::mass::MassModel;

use super::sensed::Sensed;

/// The gains of [`Rupp`] (dimensionless).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RuppGains {
    /// a, on the length error l − l_f.
    pub length: f64,
    /// b, on the rate l̇/Ω.
    pub rate: f64,
    /// c, on the target l_f (3 holds l_f on the local vertical).
    pub bias: f64,
}

/// Rupp's tension law for one system.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rupp {
    /// The gains.
    pub gains: RuppGains,
    /// The system's masses (m_e = m_r at the sensed length).
    pub masses: MassModel<f64>,
}

impl Rupp {
    /// T_c = m_e Ω² [a (l − l_f) + b l̇/Ω + c l_f], N (before the floor at 0).
    pub fn tension_n(&self, s: &Sensed, target_m: f64) -> f64 {
        let RuppGains { length, rate, bias } = self.gains;
        let m_e = self.masses.coefficients(s.length_m).radial_kg;
        let w = s.orbit_rate_radps;
        m_e * w * w * (length * (s.length_m - target_m) + rate * s.rate_mps / w + bias * target_m)
    }

    /// The roots' real parts of the linearised loop's characteristic polynomial
    /// s⁴ + b s³ + (a + 4) s² + 3b s + 3(a − 3) (s in units of Ω), from its Hurwitz
    /// determinants: `true` iff every root is in the open left half-plane.
    pub fn linear_loop_is_stable(&self) -> bool {
        let RuppGains {
            length: a, rate: b, ..
        } = self.gains;
        let (a1, a2, a3, a4) = (b, a + 4.0, 3.0 * b, 3.0 * (a - 3.0));
        a1 > 0.0 && a1 * a2 - a3 > 0.0 && a3 * (a1 * a2 - a3) - a1 * a1 * a4 > 0.0 && a4 > 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rupp(a: f64, b: f64, c: f64) -> Rupp {
        Rupp {
            gains: RuppGains {
                length: a,
                rate: b,
                bias: c,
            },
            masses: MassModel::paper(),
        }
    }

    fn at(l: f64, v: f64) -> Sensed {
        Sensed {
            length_m: l,
            rate_mps: v,
            alpha_rad: Some(0.0),
            alpha_rate_radps: None,
            orbit_rate_radps: 1.06e-3,
        }
    }

    #[test]
    fn at_the_target_at_rest_it_holds_the_vertical_tension() {
        // c = 3: T = 3 m_e Ω² l_f, the tension of a tether hanging on the local vertical.
        let r = rupp(4.0, 2.0, 3.0);
        let m_e = MassModel::<f64>::paper().coefficients(30_000.0).radial_kg;
        let t = r.tension_n(&at(30_000.0, 0.0), 30_000.0);
        let expect = 3.0 * m_e * 1.06e-3 * 1.06e-3 * 30_000.0;
        assert!((t - expect).abs() < 1e-12 * expect, "{t} {expect}");
        // Short of the target and at rest it pulls less than the vertical tension (so the
        // gravity gradient pays tether out), beyond it more.
        assert!(
            r.tension_n(&at(20_000.0, 0.0), 30_000.0) < 3.0 * m_e * 1.06e-3f64.powi(2) * 20_000.0
        );
        assert!(
            r.tension_n(&at(31_000.0, 0.0), 30_000.0) > 3.0 * m_e * 1.06e-3f64.powi(2) * 31_000.0
        );
        // Paying out adds tension (damping).
        assert!(r.tension_n(&at(30_000.0, 1.0), 30_000.0) > t);
    }

    #[test]
    fn the_linear_loop_is_stable_exactly_for_a_above_3_and_b_above_0() {
        assert!(rupp(4.0, 2.0, 3.0).linear_loop_is_stable());
        assert!(rupp(3.01, 0.01, 3.0).linear_loop_is_stable());
        assert!(!rupp(3.0, 2.0, 3.0).linear_loop_is_stable());
        assert!(!rupp(2.5, 2.0, 3.0).linear_loop_is_stable());
        assert!(!rupp(4.0, 0.0, 3.0).linear_loop_is_stable());
        assert!(!rupp(4.0, -1.0, 3.0).linear_loop_is_stable());
    }
}
