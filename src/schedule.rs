//! Reference-angle schedules α_r(l) of Eqs. 34 and 35, with quintic Hermite transitions
//! (docs/equations.md §6), and the stage-2 slew.
//!
//! Both of the paper's schedules have the same shape: a straight piece below a transition band,
//! a straight piece above it, and a transition function f(l) inside it whose value, slope and
//! curvature match the neighbouring pieces at both ends (f″ = 0 there). [`BandSchedule`]
//! describes that shape once:
//!
//! ```text
//!   α_r(l) = low_angle  + low_slope  · (l − low_length)     l ≤ low_length
//!          = quintic Hermite f(l)                           low_length < l < high_length
//!          = high_angle + high_slope · (l − high_length)    l ≥ high_length
//! ```
//!
//! Eq. 34 (stage 1) is `low = (10 km, −π/4, 0)`, `high = (30 km, 0, π·10⁻⁵)`;
//! Eq. 35 (stage 2) is `low = (2 km, 0, 5π·10⁻⁵)`, `high = (5 km, π/10, 0)`.

use crate::law::OrbitForcing;
use crate::orbit::libration::{Libration, LibrationPoint};
use crate::orbit::{Orbit, OrbitAt, PreparedOrbit};
use crate::real::Real;

/// α_r and its first two derivatives with respect to tether length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefAngle<T> {
    /// α_r, rad.
    pub angle_rad: T,
    /// ∂α_r/∂l, rad/m (the `p` of docs/equations.md §5).
    pub slope_rad_per_m: T,
    /// ∂²α_r/∂l², rad/m² (needed by the Eq. 30 acceleration).
    pub curvature_rad_per_m2: T,
}

/// A reference-angle schedule of the Eq. 34 / Eq. 35 shape (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BandSchedule<T> {
    /// Lower end of the transition band, m.
    pub low_length_m: T,
    /// α_r at the lower end, rad.
    pub low_angle_rad: T,
    /// Slope of the straight piece below the band, rad/m.
    pub low_slope_rad_per_m: T,
    /// Upper end of the transition band, m.
    pub high_length_m: T,
    /// α_r at the upper end, rad.
    pub high_angle_rad: T,
    /// Slope of the straight piece above the band, rad/m.
    pub high_slope_rad_per_m: T,
}

impl<T: Real> BandSchedule<T> {
    /// Eq. 34 with the paper's numbers: −π/4 up to 10 km, a transition to 0 at 30 km, then
    /// k(l − 30 km) with k = π·10⁻⁵ rad/m.
    pub fn paper_stage1() -> Self {
        Self {
            low_length_m: T::from_f64(10_000.0),
            low_angle_rad: T::from_f64(-core::f64::consts::FRAC_PI_4),
            low_slope_rad_per_m: T::ZERO,
            high_length_m: T::from_f64(30_000.0),
            high_angle_rad: T::ZERO,
            high_slope_rad_per_m: T::from_f64(core::f64::consts::PI * 1e-5),
        }
    }

    /// Eq. 35 with the paper's numbers: k(l − 2 km) with k = 5π·10⁻⁵ rad/m up to 2 km, a
    /// transition to π/10 at 5 km, then π/10.
    pub fn paper_stage2() -> Self {
        Self {
            low_length_m: T::from_f64(2_000.0),
            low_angle_rad: T::ZERO,
            low_slope_rad_per_m: T::from_f64(5.0 * core::f64::consts::PI * 1e-5),
            high_length_m: T::from_f64(5_000.0),
            high_angle_rad: T::from_f64(core::f64::consts::PI / 10.0),
            high_slope_rad_per_m: T::ZERO,
        }
    }

    /// α_r(l), ∂α_r/∂l and ∂²α_r/∂l² at tether length `length_m` (Eqs. 34/35).
    ///
    /// Total for every input: a NaN length yields NaN outputs, which the controller's input
    /// validation rejects before calling this. Builds the [`PreparedBand`] each call; a caller
    /// that evaluates the schedule every period (the controller) prepares it once.
    pub fn eval(&self, length_m: T) -> RefAngle<T> {
        self.prepare().eval(length_m)
    }

    /// The schedule with its quintic's coefficients worked out (in f64, rounded once to `T`).
    pub fn prepare(&self) -> PreparedBand<T> {
        let f = |x: T| x.to_f64();
        let (lo, hi) = (f(self.low_length_m), f(self.high_length_m));
        let h = hi - lo;
        let end = |length: T, angle: T, slope: T, far_angle: T, far_slope: T, dir: f64| {
            // The quintic written around this end (docs/equations.md §6): in u = distance from this end in
            // band widths (du/dl = dir/h), g(0) = f_e, g'(0) = dir·h·k_e, g'(1) = dir·h·k_far,
            // g''(0) = g''(1) = 0:  g = f_e + g1 u + u³(c3 + u(c4 + u c5)).
            let g1 = dir * h * f(slope);
            let delta = f(far_angle) - f(angle) - g1;
            let d = dir * h * (f(far_slope) - f(slope));
            let c3 = 10.0 * delta - 4.0 * d;
            let c4 = -15.0 * delta + 7.0 * d;
            let c5 = 6.0 * delta - 3.0 * d;
            let t = T::from_f64;
            BandEnd {
                length_m: length,
                u_per_m: t(dir / h),
                angle_rad: angle,
                slope_rad_per_m: slope,
                g1_rad: t(g1),
                c3_rad: t(c3),
                c4_rad: t(c4),
                c5_rad: t(c5),
                // ∂α_r/∂l = (dir/h) g'(u) = k_e + u²(s3 + u(s4 + u s5)).
                s3_rad_per_m: t(dir * 3.0 * c3 / h),
                s4_rad_per_m: t(dir * 4.0 * c4 / h),
                s5_rad_per_m: t(dir * 5.0 * c5 / h),
                // ∂²α_r/∂l² = g''(u)/h² = u(q6 + u(q12 + u q20)).
                q6_rad_per_m2: t(6.0 * c3 / (h * h)),
                q12_rad_per_m2: t(12.0 * c4 / (h * h)),
                q20_rad_per_m2: t(20.0 * c5 / (h * h)),
            }
        };
        PreparedBand {
            low: end(
                self.low_length_m,
                self.low_angle_rad,
                self.low_slope_rad_per_m,
                self.high_angle_rad,
                self.high_slope_rad_per_m,
                1.0,
            ),
            high: end(
                self.high_length_m,
                self.high_angle_rad,
                self.high_slope_rad_per_m,
                self.low_angle_rad,
                self.low_slope_rad_per_m,
                -1.0,
            ),
            mid_length_m: T::from_f64(lo + 0.5 * h),
        }
    }
}

/// One end of a [`PreparedBand`]: the straight piece beyond it and the quintic written around it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct BandEnd<T> {
    length_m: T,
    /// du/dl: +1/h at the low end, −1/h at the high end, 1/m.
    u_per_m: T,
    angle_rad: T,
    slope_rad_per_m: T,
    g1_rad: T,
    c3_rad: T,
    c4_rad: T,
    c5_rad: T,
    s3_rad_per_m: T,
    s4_rad_per_m: T,
    s5_rad_per_m: T,
    q6_rad_per_m2: T,
    q12_rad_per_m2: T,
    q20_rad_per_m2: T,
}

/// A [`BandSchedule`] ready to evaluate every period: the transition quintic of docs/equations.md §6 written
/// around each end of the band, its coefficients computed once (in f64) by
/// [`BandSchedule::prepare`].
///
/// Inside the band the half nearer to `l` is used, with u the distance from that end in band
/// widths (0 ≤ u ≤ ½): near an end (station keeping sits at them) f32 keeps the precision of
/// the straight piece instead of losing ~1e-6 rad to cancellation among the Hermite basis
/// functions. A step costs one multiplication for u and three short Horner chains.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedBand<T> {
    low: BandEnd<T>,
    high: BandEnd<T>,
    mid_length_m: T,
}

impl<T: Real> PreparedBand<T> {
    /// α_r(l), ∂α_r/∂l and ∂²α_r/∂l² (Eqs. 34/35); see [`BandSchedule::eval`].
    #[inline]
    pub fn eval(&self, length_m: T) -> RefAngle<T> {
        let straight = |e: &BandEnd<T>| RefAngle {
            angle_rad: e.angle_rad + e.slope_rad_per_m * (length_m - e.length_m),
            slope_rad_per_m: e.slope_rad_per_m,
            curvature_rad_per_m2: T::ZERO,
        };
        if length_m <= self.low.length_m {
            return straight(&self.low);
        }
        if length_m >= self.high.length_m {
            return straight(&self.high);
        }
        let e = if length_m <= self.mid_length_m {
            &self.low
        } else {
            &self.high
        };
        let u = (length_m - e.length_m) * e.u_per_m;
        let u2 = u * u;
        RefAngle {
            angle_rad: e.angle_rad
                + e.g1_rad * u
                + u2 * u * (e.c3_rad + u * (e.c4_rad + u * e.c5_rad)),
            slope_rad_per_m: e.slope_rad_per_m
                + u2 * (e.s3_rad_per_m + u * (e.s4_rad_per_m + u * e.s5_rad_per_m)),
            curvature_rad_per_m2: u
                * (e.q6_rad_per_m2 + u * (e.q12_rad_per_m2 + u * e.q20_rad_per_m2)),
        }
    }

    /// The stage-2 reference on this schedule (see [`SlewedSchedule`]).
    #[inline]
    pub fn eval_slewed(&self, slew_rate_radps: T, tau_s: T, length_m: T) -> Reference<T> {
        let scheduled = self.eval(length_m);
        let ramp = slew_rate_radps * tau_s;
        if ramp < scheduled.angle_rad {
            Reference {
                angle: RefAngle {
                    angle_rad: ramp,
                    slope_rad_per_m: T::ZERO,
                    curvature_rad_per_m2: T::ZERO,
                },
                time_rate_radps: slew_rate_radps,
                slewing: true,
                orbit: None,
            }
        } else {
            Reference {
                angle: scheduled,
                time_rate_radps: T::ZERO,
                slewing: false,
                orbit: None,
            }
        }
    }
}

/// The stage-2 reference: α_r slews from 0 at `slew_rate_radps` until it meets the Eq. 35
/// schedule, which it then follows (docs/equations.md §6: "from 0 to 18° in 500 s along the slope of
/// 6.2932e-4", clamped at the plateau, i.e. 499.2 s).
///
/// Written as α_r = min(ramp(τ), A(l)) for a positive plateau, so the hand-over is continuous
/// and happens exactly when the ramp reaches the schedule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlewedSchedule<T> {
    /// The Eq. 35 schedule followed after the slew.
    pub schedule: BandSchedule<T>,
    /// Slew rate of α_r, rad/s (> 0).
    pub slew_rate_radps: T,
}

/// α_r with its length derivatives and its explicit time derivative ∂α_r/∂t.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference<T> {
    /// α_r and its length derivatives.
    pub angle: RefAngle<T>,
    /// ∂α_r/∂t at fixed l, rad/s (the `r` of docs/equations.md §5; non-zero only during a slew).
    pub time_rate_radps: T,
    /// `true` while the slew is still below the schedule.
    pub slewing: bool,
    /// On an eccentric orbit, the orbit's terms and the reference's higher time derivatives
    /// that the law needs ([`LibratingReference`], docs/equations.md §16); `None` on a
    /// circular orbit.
    pub orbit: Option<OrbitForcing<T>>,
}

impl<T: Real> SlewedSchedule<T> {
    /// The reference at stage time `tau_s` and tether length `length_m`.
    pub fn eval(&self, tau_s: T, length_m: T) -> Reference<T> {
        self.schedule
            .prepare()
            .eval_slewed(self.slew_rate_radps, tau_s, length_m)
    }
}

/// The reference on an eccentric orbit (docs/equations.md §16.2): the schedule's α_r(l) (or the
/// slew's α_r(t)) plus the forced periodic libration P(θ) of [`Libration`], weighted by
/// cos 2α_r,
///
/// ```text
///   α_ref(l, θ) = α_r + cos(2α_r) · P(θ)
/// ```
///
/// so that it is P itself at the keeps (α_r → 0: keeping a length does not fight the orbit's
/// forcing) and α_r itself on the −45° deployment plateau (where the reel holds α_r exactly,
/// inside the Eq. 13 extent), and in between the rate the reference asks for keeps the sign of
/// its stage all orbit long (to first order in e, for e ≤ 0.6: §16.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LibratingReference<T> {
    orbit: PreparedOrbit<T>,
    libration: Libration<T>,
}

impl<T: Real> LibratingReference<T> {
    /// The reference for `orbit`, or `None` on a circular one (e = 0: the paper's reference
    /// and law, unchanged). Beyond the eccentricities [`Libration::new`] solves
    /// ([`crate::orbit::libration::MAX_ECCENTRICITY`]) P ≡ 0: the law still takes the orbit's
    /// θ̈ and μ/R³, and the reference is α_r.
    pub fn new(orbit: &Orbit<T>) -> Option<Self> {
        if orbit.eccentricity == T::ZERO {
            return None;
        }
        let libration = Libration::new(orbit.eccentricity).unwrap_or(Libration::NONE);
        Some(Self {
            orbit: orbit.prepare(),
            libration,
        })
    }

    /// The periodic libration P this reference adds.
    pub fn libration(&self) -> &Libration<T> {
        &self.libration
    }

    /// The reference when θ is not finite: the schedule's α_r with every orbit term NaN, so
    /// that the law cannot run on it ([`crate::law::LawFault::NotFinite`], the controller's
    /// safe action) while α_r is still reported (docs/equations.md §16.6).
    pub fn without_anomaly(base: Reference<T>) -> Reference<T> {
        let nan = T::from_f64(f64::NAN);
        Reference {
            orbit: Some(OrbitForcing {
                gradient_per_s2: nan,
                gradient_rate_per_s3: nan,
                orbit_accel_radps2: nan,
                orbit_jerk_radps3: nan,
                ref_time_accel_radps2: nan,
                ref_time_jerk_radps3: nan,
                ref_slope_rate_rad_per_m_s: nan,
                ref_time_accel_slope_rad_per_m_s2: nan,
            }),
            ..base
        }
    }

    /// The reference at true anomaly θ (rad) from the circular one `base` (α_r, ∂α_r/∂l,
    /// ∂²α_r/∂l², ∂α_r/∂t): every partial derivative the law needs (§16.2; it assumes, as both
    /// schedules give, that ∂α_r/∂l does not depend on t nor ∂α_r/∂t on l).
    pub fn eval(&self, base: Reference<T>, true_anomaly_rad: T) -> Reference<T> {
        let (sin_theta, cos_theta) = true_anomaly_rad.sin_cos();
        let o = self.orbit.at_sin_cos(sin_theta, cos_theta);
        let p = self.libration.eval_sin_cos(sin_theta, cos_theta);
        compose(base, &o, &p)
    }
}

/// α_ref = α_r + cos(2α_r) P and its partial derivatives (docs/equations.md §16.2).
pub fn compose<T: Real>(
    base: Reference<T>,
    o: &OrbitAt<T>,
    lib: &LibrationPoint<T>,
) -> Reference<T> {
    let f = T::from_f64;
    let a = base.angle;
    let (pr, qr, rs) = (
        a.slope_rad_per_m,
        a.curvature_rad_per_m2,
        base.time_rate_radps,
    );
    let wt = Weight::at(a.angle_rad);
    let (w, w1, w2, w3) = (wt.value, wt.first, wt.second, wt.third);
    let (rate, rate2, accel) = (o.rate_radps, o.rate_radps * o.rate_radps, o.accel_radps2);
    // P and its time derivatives at fixed l: θ̇ P′, θ̇² P″ + θ̈ P′, θ̇³ P‴ + 3θ̇θ̈ P″ + θ⃛ P′.
    let p0 = lib.angle_rad;
    let p1 = rate * lib.slope;
    let p2 = rate2 * lib.curvature + accel * lib.slope;
    let p3 = rate2 * rate * lib.third
        + f(3.0) * rate * accel * lib.curvature
        + o.jerk_radps3 * lib.slope;
    // ∂α_ref/∂α_r = 1 + w′P.
    let k = T::ONE + w1 * p0;
    let rs2 = rs * rs;
    Reference {
        angle: RefAngle {
            angle_rad: a.angle_rad + w * p0,
            slope_rad_per_m: pr * k,
            curvature_rad_per_m2: qr * k + w2 * p0 * pr * pr,
        },
        time_rate_radps: rs * k + w * p1,
        slewing: base.slewing,
        orbit: Some(OrbitForcing {
            gradient_per_s2: f(1.5) * o.gravity_gradient_per_s2,
            gradient_rate_per_s3: f(1.5) * o.gravity_gradient_rate_per_s3,
            orbit_accel_radps2: o.accel_radps2,
            orbit_jerk_radps3: o.jerk_radps3,
            ref_time_accel_radps2: w2 * rs2 * p0 + f(2.0) * w1 * rs * p1 + w * p2,
            ref_time_jerk_radps3: w3 * rs2 * rs * p0
                + f(3.0) * (w2 * rs2 * p1 + w1 * rs * p2)
                + w * p3,
            ref_slope_rate_rad_per_m_s: pr * (w2 * rs * p0 + w1 * p1),
            ref_time_accel_slope_rad_per_m_s2: pr
                * (w3 * rs2 * p0 + f(2.0) * w2 * rs * p1 + w1 * p2),
        }),
    }
}

/// The libration's weight w(α_r) = cos 2α_r and its first three derivatives with respect to
/// α_r (docs/equations.md §16.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weight<T> {
    /// w.
    pub value: T,
    /// dw/dα_r, 1/rad.
    pub first: T,
    /// d²w/dα_r², 1/rad².
    pub second: T,
    /// d³w/dα_r³, 1/rad³.
    pub third: T,
}

impl<T: Real> Weight<T> {
    /// w = cos 2α_r at α_r (rad): 1 at the keeps, 0 on the −45° plateau.
    pub fn at(ref_angle_rad: T) -> Self {
        let f = T::from_f64;
        let (s2, c2) = (f(2.0) * ref_angle_rad).sin_cos();
        Self {
            value: c2,
            first: -f(2.0) * s2,
            second: -f(4.0) * c2,
            third: f(8.0) * s2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    /// The six boundary conditions of a quintic: value, slope and curvature at both ends.
    fn check_six_conditions(s: &BandSchedule<f64>) {
        let lo = s.eval(s.low_length_m + 1e-9);
        let hi = s.eval(s.high_length_m - 1e-9);
        let h = s.high_length_m - s.low_length_m;
        assert!(close(lo.angle_rad, s.low_angle_rad, 1e-12));
        assert!(close(lo.slope_rad_per_m, s.low_slope_rad_per_m, 1e-12));
        assert!(close(lo.curvature_rad_per_m2, 0.0, 1e-12 / h));
        assert!(close(hi.angle_rad, s.high_angle_rad, 1e-12));
        assert!(close(hi.slope_rad_per_m, s.high_slope_rad_per_m, 1e-12));
        assert!(close(hi.curvature_rad_per_m2, 0.0, 1e-12 / h));
    }

    #[test]
    fn stage1_quintic_meets_its_six_conditions() {
        check_six_conditions(&BandSchedule::paper_stage1());
    }

    #[test]
    fn stage2_quintic_meets_its_six_conditions() {
        check_six_conditions(&BandSchedule::paper_stage2());
    }

    #[test]
    fn straight_pieces_match_eq34_and_eq35() {
        let s1 = BandSchedule::<f64>::paper_stage1();
        assert_eq!(s1.eval(1.0).angle_rad, -PI / 4.0);
        assert_eq!(s1.eval(1.0).slope_rad_per_m, 0.0);
        assert!(close(
            s1.eval(31_000.0).angle_rad,
            PI * 1e-5 * 1_000.0,
            1e-15
        ));
        let s2 = BandSchedule::<f64>::paper_stage2();
        assert_eq!(s2.eval(20_000.0).angle_rad, PI / 10.0);
        assert!(close(
            s2.eval(1_900.0).angle_rad,
            -5.0 * PI * 1e-5 * 100.0,
            1e-15
        ));
    }

    #[test]
    fn stage1_midpoint_by_hand() {
        // s = 1/2: H0 = H5 = 1/2, H1 = 1/2 − 6/8 + 8/16 − 3/32 = 5/32, H4 = −4/8 + 7/16 − 3/32
        // = −5/32. f = −π/8 + h k (−5/32) with h = 20 km, k = π·10⁻⁵.
        let f = BandSchedule::<f64>::paper_stage1().eval(20_000.0).angle_rad;
        let expect = -PI / 8.0 - 20_000.0 * PI * 1e-5 * 5.0 / 32.0;
        assert!(close(f, expect, 1e-14), "{f} vs {expect}");
    }

    #[test]
    fn derivatives_agree_with_finite_differences() {
        for s in [
            BandSchedule::<f64>::paper_stage1(),
            BandSchedule::paper_stage2(),
        ] {
            let (a, b) = (s.low_length_m, s.high_length_m);
            for i in 1..20 {
                let l = a + (b - a) * f64::from(i) / 20.0;
                let dl = 1e-2;
                let (m, c, p) = (s.eval(l - dl), s.eval(l), s.eval(l + dl));
                let d1 = (p.angle_rad - m.angle_rad) / (2.0 * dl);
                let d2 = (p.slope_rad_per_m - m.slope_rad_per_m) / (2.0 * dl);
                assert!(close(c.slope_rad_per_m, d1, 1e-10), "slope at {l}");
                assert!(close(c.curvature_rad_per_m2, d2, 1e-12), "curvature at {l}");
            }
        }
    }

    #[test]
    fn schedules_are_monotone_across_the_band() {
        let s1 = BandSchedule::<f64>::paper_stage1();
        let s2 = BandSchedule::<f64>::paper_stage2();
        let mut prev1 = f64::NEG_INFINITY;
        let mut prev2 = f64::NEG_INFINITY;
        for i in 0..=1000 {
            let l = 1_000.0 + 40.0 * f64::from(i);
            let (a1, a2) = (s1.eval(l).angle_rad, s2.eval(l).angle_rad);
            assert!(a1 >= prev1 && a2 >= prev2, "not monotone at {l}");
            prev1 = a1;
            prev2 = a2;
        }
    }

    #[test]
    fn slew_reaches_the_plateau_after_499_2_s() {
        let sl = SlewedSchedule {
            schedule: BandSchedule::<f64>::paper_stage2(),
            slew_rate_radps: 6.2932e-4,
        };
        let r = sl.eval(100.0, 29_000.0);
        assert!(r.slewing && close(r.angle.angle_rad, 0.062_932, 1e-12));
        assert_eq!(r.time_rate_radps, 6.2932e-4);
        let t_end = (PI / 10.0) / 6.2932e-4;
        assert!(close(t_end, 499.2, 0.05), "{t_end}");
        assert!(sl.eval(t_end - 0.01, 29_000.0).slewing);
        let after = sl.eval(t_end + 0.01, 29_000.0);
        assert!(!after.slewing && after.angle.angle_rad == PI / 10.0);
        assert_eq!(after.time_rate_radps, 0.0);
    }
}
