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
        tss_fpu::sqrt(self)
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
}

impl Real for f64 {
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
}

#[cfg(test)]
mod tests {
    use super::Real;

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
