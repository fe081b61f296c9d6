//! The scalar type the physics is written in.
//!
//! The flight build evaluates everything in `f32` (the Cortex-M4F has a single-precision FPU);
//! the desk tools and the accuracy tests evaluate the *same* formulas in `f64`. Writing each
//! formula once, generic over [`Real`], means the two can only differ by rounding.

use core::fmt::Debug;
use core::ops::{Add, Div, Mul, Neg, Sub};

/// A real scalar (`f32` or `f64`) with the handful of functions the paper's equations need.
///
/// Transcendental functions come from `libm` (and, for f32 sine and cosine, from
/// [`crate::fastmath`], which stays in single precision), so results are identical on the host
/// and on the target (no dependence on the platform's C library).
pub trait Real:
    Copy
    + Debug
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The unsigned integer of the same width as the float.
    type Bits: Copy + Debug + Eq + Ord;
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// Converts an `f64` constant (rounding to nearest for `f32`).
    fn from_f64(x: f64) -> Self;
    /// Converts to `f64` (exact for both implementations).
    fn to_f64(self) -> f64;
    /// Converts a tick count (exact below 2²⁴ for `f32`).
    fn from_u32(x: u32) -> Self;
    /// Sine.
    fn sin(self) -> Self;
    /// Cosine.
    fn cos(self) -> Self;
    /// `e^x`.
    fn exp(self) -> Self;
    /// (e^x, 1 − e^x), the second to its own relative precision (not 1 minus the first: no
    /// cancellation where e^x ≈ 1).
    fn exp_and_complement(self) -> (Self, Self);
    /// (2^self, 1 − 2^self), each to its own relative precision.
    fn exp2_and_complement(self) -> (Self, Self);
    /// Square root (NaN for negative input).
    fn sqrt(self) -> Self;
    /// `(sin x, cos x)`, sharing the argument reduction where the implementation can.
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        (self.sin(), self.cos())
    }
    /// Absolute value.
    fn abs(self) -> Self;
    /// The largest integer not above `self`.
    fn floor(self) -> Self;
    /// Four-quadrant arctangent of `self / x`.
    fn atan2(self, x: Self) -> Self;
    /// Arcsine (NaN outside [-1, 1]).
    fn asin(self) -> Self;
    /// `true` unless NaN or infinite.
    fn is_finite(self) -> bool;
    /// The IEEE bit pattern (`u32` for `f32`, `u64` for `f64`; equal patterns ⇔ identical
    /// values).
    fn bits(self) -> Self::Bits;
    /// `self.bits() − base`, wrapping (the offset of this pattern from `base`'s; see
    /// [`PositiveInterval`]).
    fn bits_above(self, base: Self::Bits) -> Self::Bits;
    /// The bit pattern shifted left by one: the sign dropped, the rest in the order of |x|
    /// (see [`MagnitudeBound`]).
    fn magnitude_bits(self) -> Self::Bits;

    /// The smaller of two values (the non-NaN one if one is NaN).
    #[inline]
    fn min(self, other: Self) -> Self {
        if other < self || self.is_nan() {
            other
        } else {
            self
        }
    }
    /// The larger of two values (the non-NaN one if one is NaN).
    #[inline]
    fn max(self, other: Self) -> Self {
        if other > self || self.is_nan() {
            other
        } else {
            self
        }
    }
    /// `self` limited to `[lo, hi]` (`lo` if `self` is NaN).
    #[inline]
    fn clamp_to(self, lo: Self, hi: Self) -> Self {
        if self.is_nan() {
            lo
        } else {
            self.max(lo).min(hi)
        }
    }
    /// `self` limited to `[lo, hi]` for a `self` known not to be NaN (two plain comparisons;
    /// a NaN `self` comes back as NaN). The hot path's choice where NaN cannot occur.
    #[inline]
    fn clamp_finite(self, lo: Self, hi: Self) -> Self {
        if self < lo {
            lo
        } else if self > hi {
            hi
        } else {
            self
        }
    }
    /// `true` for NaN.
    #[inline]
    #[allow(clippy::eq_op)]
    fn is_nan(self) -> bool {
        self != self
    }
    /// The square, `self * self`.
    #[inline]
    fn sq(self) -> Self {
        self * self
    }
}

impl Real for f32 {
    type Bits = u32;
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline]
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    #[inline]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    #[inline]
    fn from_u32(x: u32) -> Self {
        x as f32
    }
    #[inline]
    fn sin(self) -> Self {
        crate::fastmath::sin(self)
    }
    #[inline]
    fn cos(self) -> Self {
        crate::fastmath::cos(self)
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        crate::fastmath::sin_cos(self)
    }
    #[inline]
    fn exp(self) -> Self {
        crate::fastmath::exp(self)
    }
    #[inline]
    fn exp_and_complement(self) -> (Self, Self) {
        crate::fastmath::exp_and_complement(self)
    }
    #[inline]
    fn exp2_and_complement(self) -> (Self, Self) {
        crate::fastmath::exp2_and_complement(self)
    }
    #[inline]
    fn sqrt(self) -> Self {
        crate::fastmath::sqrt(self)
    }
    #[inline]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline]
    fn floor(self) -> Self {
        libm::floorf(self)
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        libm::atan2f(self, x)
    }
    #[inline]
    fn asin(self) -> Self {
        libm::asinf(self)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    #[inline]
    fn bits(self) -> u32 {
        self.to_bits()
    }
    #[inline]
    fn bits_above(self, base: u32) -> u32 {
        self.to_bits().wrapping_sub(base)
    }
    #[inline]
    fn magnitude_bits(self) -> u32 {
        self.to_bits() << 1
    }
}

impl Real for f64 {
    type Bits = u64;
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline]
    fn from_f64(x: f64) -> Self {
        x
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline]
    fn from_u32(x: u32) -> Self {
        f64::from(x)
    }
    #[inline]
    fn sin(self) -> Self {
        libm::sin(self)
    }
    #[inline]
    fn cos(self) -> Self {
        libm::cos(self)
    }
    #[inline]
    fn exp(self) -> Self {
        libm::exp(self)
    }
    #[inline]
    fn exp_and_complement(self) -> (Self, Self) {
        (libm::exp(self), -libm::expm1(self))
    }
    #[inline]
    fn exp2_and_complement(self) -> (Self, Self) {
        (
            libm::exp2(self),
            -libm::expm1(self * core::f64::consts::LN_2),
        )
    }
    #[inline]
    fn sqrt(self) -> Self {
        libm::sqrt(self)
    }
    #[inline]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline]
    fn floor(self) -> Self {
        libm::floor(self)
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        libm::atan2(self, x)
    }
    #[inline]
    fn asin(self) -> Self {
        libm::asin(self)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    #[inline]
    fn bits(self) -> u64 {
        self.to_bits()
    }
    #[inline]
    fn bits_above(self, base: u64) -> u64 {
        self.to_bits().wrapping_sub(base)
    }
    #[inline]
    fn magnitude_bits(self) -> u64 {
        self.to_bits() << 1
    }
}

/// A closed interval [lo, hi] of positive finite numbers, tested by one unsigned comparison
/// of bit patterns: the non-negative floats are ordered as their patterns are, so x ∈ [lo, hi]
/// exactly when `x.bits() − lo.bits()` (wrapping) ≤ `hi.bits() − lo.bits()`. Everything else
/// fails that comparison by the same arithmetic: values below lo wrap around to huge offsets,
/// and negative numbers (−0 included), +∞ and NaN have patterns above hi's. So
/// "finite and in range" costs one integer comparison (a float range check costs two
/// comparisons and a status-register transfer each).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PositiveInterval<T: Real> {
    lo_bits: T::Bits,
    span_bits: T::Bits,
}

impl<T: Real> PositiveInterval<T> {
    /// [lo, hi], or `None` unless 0 < lo ≤ hi < ∞.
    pub fn new(lo: T, hi: T) -> Option<Self> {
        if !(lo > T::ZERO && lo <= hi && hi.is_finite()) {
            return None;
        }
        Some(Self {
            lo_bits: lo.bits(),
            span_bits: hi.bits_above(lo.bits()),
        })
    }

    /// `true` if lo ≤ x ≤ hi (never for NaN or an infinity).
    #[inline(always)]
    pub fn contains(self, x: T) -> bool {
        x.bits_above(self.lo_bits) <= self.span_bits
    }
}

/// |x| ≤ max as one unsigned comparison of bit patterns: without the sign bit, the patterns
/// of the non-negative floats are in the order of their values, and those of ±∞ and NaN lie
/// above every finite one, so NaN and the infinities fail it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MagnitudeBound<T: Real> {
    max_bits: T::Bits,
}

impl<T: Real> MagnitudeBound<T> {
    /// |x| ≤ `max`, or `None` unless 0 ≤ max < ∞.
    pub fn new(max: T) -> Option<Self> {
        if !(max >= T::ZERO && max.is_finite()) {
            return None;
        }
        Some(Self {
            max_bits: max.magnitude_bits(),
        })
    }

    /// `true` if |x| ≤ max (never for NaN or an infinity).
    #[inline(always)]
    pub fn contains(self, x: T) -> bool {
        x.magnitude_bits() <= self.max_bits
    }
}

#[cfg(test)]
mod tests {
    use super::{MagnitudeBound, PositiveInterval, Real};

    #[test]
    fn magnitude_bound_is_the_float_check() {
        let pi = core::f32::consts::PI;
        let b = MagnitudeBound::new(pi).unwrap();
        let check = |x: f32| assert_eq!(b.contains(x), x.abs() <= pi, "{x:e}");
        for x in [
            0.0,
            -0.0,
            pi,
            -pi,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
        ] {
            check(x);
        }
        check(f32::from_bits(pi.to_bits() + 1));
        check(-f32::from_bits(pi.to_bits() + 1));
        // Every 4099th pattern, both signs.
        for bits in (0..=u32::MAX).step_by(4099) {
            check(f32::from_bits(bits));
        }
        let b64 = MagnitudeBound::new(0.06_f64).unwrap();
        for x in [
            0.06,
            -0.06,
            0.060_000_000_1,
            -1e300,
            f64::NAN,
            f64::NEG_INFINITY,
            1e-300,
        ] {
            assert_eq!(b64.contains(x), x.abs() <= 0.06, "{x:e}");
        }
        assert!(MagnitudeBound::new(-1.0_f32).is_none());
        assert!(MagnitudeBound::new(f32::NAN).is_none());
        assert!(MagnitudeBound::new(f32::INFINITY).is_none());
    }

    #[test]
    fn positive_interval_is_the_float_range_check() {
        let r32 = PositiveInterval::new(1e-3_f32, 31_500.0).unwrap();
        let check = |x: f32| {
            let expected = (1e-3..=31_500.0).contains(&x);
            assert_eq!(r32.contains(x), expected, "{x:e}");
        };
        for x in [
            0.0,
            -0.0,
            f32::MIN_POSITIVE,
            1e-45,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            f32::MAX,
            f32::MIN,
        ] {
            check(x);
        }
        for e in [1e-3_f32, 0.5, 1.0, 31_500.0] {
            for x in [e, e.next_up(), e.next_down(), -e] {
                check(x);
            }
        }
        // Every 4099th pattern of the whole f32 range.
        for b in (0..=u32::MAX).step_by(4099) {
            check(f32::from_bits(b));
        }
        let r64 = PositiveInterval::new(1e-5_f64, 1e-2).unwrap();
        for x in [
            1e-5,
            1e-2,
            5e-3,
            0.0,
            -0.0,
            -5e-3,
            1e-2_f64.next_up(),
            f64::NAN,
            f64::INFINITY,
        ] {
            assert_eq!(r64.contains(x), (1e-5..=1e-2).contains(&x), "{x:e}");
        }
        assert!(PositiveInterval::new(0.0_f32, 1.0).is_none());
        assert!(PositiveInterval::new(2.0_f32, 1.0).is_none());
        assert!(PositiveInterval::new(1.0_f32, f32::INFINITY).is_none());
        assert!(PositiveInterval::new(f64::NAN, 1.0).is_none());
    }

    #[test]
    fn min_max_clamp_treat_nan_as_missing() {
        assert_eq!(Real::min(f32::NAN, 1.0), 1.0);
        assert_eq!(Real::max(2.0_f64, f64::NAN), 2.0);
        assert_eq!(f32::NAN.clamp_to(-1.0, 1.0), -1.0);
        assert_eq!(5.0_f32.clamp_to(-1.0, 1.0), 1.0);
        assert_eq!((-5.0_f64).clamp_to(-1.0, 1.0), -1.0);
    }

    #[test]
    fn f32_and_f64_agree_to_single_precision() {
        for &x in &[0.0, 0.3, 1.0, -2.5, 3.0] {
            assert!((Real::sin(x as f32).to_f64() - Real::sin(x)).abs() < 1e-6);
            assert!((Real::exp(x as f32).to_f64() - Real::exp(x)).abs() < 1e-5 * x.exp());
        }
    }
}
