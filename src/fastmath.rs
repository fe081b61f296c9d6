//! Single-precision sine and cosine that never leave the FPU's precision.
//!
//! `libm::sinf` evaluates in f64, which the Cortex-M4F's single-precision FPU emulates in
//! software (about 1 200 instructions a call, docs/equations.md §8). The law needs sin 2α and cos 2α with
//! |2α| ≤ 2π, to a few f32 ulps. This module does it in f32 only, from a table:
//!
//! 1. x = k·h + r with h = 2π/128 and k = round(x/h), r = (x − k·H1) − k·H2 (Cody–Waite:
//!    H1 + H2 = h to 10⁻¹², H1 of 10 significant bits so that k·H1 and x − k·H1 are exact
//!    for |k| ≤ 512), so |r| ≤ h/2 ≈ 0.0245;
//! 2. sin(kh) and cos(kh) from a 160-entry table of sin(2πj/128), j = k mod 128 (one
//!    bit mask: the table covers the turn and a quarter, so cos kh = sin(kh + π/2) is entry
//!    j + 32), computed at compile time in f64 and rounded;
//! 3. sin x = sin kh·cos r + cos kh·sin r (and cos x alike), with sin r = r − r³/6 and
//!    cos r = 1 − r²/2, whose truncation errors (below 8·10⁻¹¹ and 1.5·10⁻⁸ relative) are
//!    under an f32 ulp at |r| ≤ h/2.
//!
//! Accuracy (proven by this module's tests against f64 `sin`/`cos` on every 64th f32 of
//! |x| ≤ 2π and at random up to [`FAST_RANGE`]): absolute error below 1.5e-7, about one f32
//! ulp of 1. Arguments beyond [`FAST_RANGE`] (never produced by the law: its 2α is within
//! ±2π, α being checked to |α| ≤ π), infinities and NaN fall back to `libm`.
//!
//! (The square root is the FPU's own VSQRT.F32 on the MCU: the `tss-fpu` crate.)
//!
//! [`exp_and_complement`] (e^x and 1 − e^x; [`exp`] is its first half) is the Cephes `expf`
//! scheme without libm's general-purpose special-casing: k = round(x/ln 2), r = x − k·ln 2 in
//! two parts, a degree-7 polynomial for e^r on |r| ≤ ln 2 / 2, and 2^k put into the exponent
//! bits, on the decay range −87 ≤ x ≤ −0. Within two ulps of the correctly rounded e^x there,
//! and so is 1 − e^x, to its own size (proven by this module's tests on every 32nd f32 of that
//! range); elsewhere, libm's answer. [`exp2_and_complement`] is the same for 2^t on
//! −126 ≤ t ≤ −0, where the reduction is exact (r = (t − round t)·ln 2): the Eq. 29 blend
//! weight E = e^{−cτ} = 2^{(−cΔt·log₂e)·k} and 1 − E, once per step, with −cΔt·log₂e prepared
//! once per stage. Outside that range it does without libm too (the same kernel, scaled; within
//! two ulps up to overflow and for subnormal results, tested), so the firmware links neither
//! `exp2f` nor `expm1f`.
//!
//! Rounding to an integer uses the classic `(v + 1.5·2²³) − 1.5·2²³`, which the FPU rounds to
//! nearest-even exactly as `rintf` does for |v| < 2²² (LLVM keeps the pair: no fast-math).

/// |x| up to which [`sin_cos`] takes the table (|k| < 512 steps of h = 2π/128, with a margin;
/// it covers the law's |2α| ≤ 2π four times over); beyond it `libm` is used.
pub const FAST_RANGE: f32 = 25.0;

/// Table steps per turn.
const STEPS: u32 = 128;
/// Table length: a turn and a quarter, so that cos of step j is entry j + STEPS/4.
const TABLE_LEN: usize = STEPS as usize * 5 / 4;
/// sin(2πj/[`STEPS`]) for j = 0 … [`TABLE_LEN`] − 1, rounded to f32.
static SIN_TABLE: [f32; TABLE_LEN] = sin_table();
/// 1/h.
const STEPS_PER_RAD: f32 = (STEPS as f64 / core::f64::consts::TAU) as f32;
// h = H1 + H2 to 10⁻¹²: H1 = h rounded down to a multiple of 2⁻¹⁴ (804·2⁻¹⁴, 10 significant
// bits, so k·H1 is exact for |k| ≤ 512), H2 = h − H1 rounded to f32.
const H1: f32 = 804.0 / 16_384.0;
const H2: f32 = (core::f64::consts::TAU / STEPS as f64 - 804.0 / 16_384.0) as f32;
/// 2²³ + 512: x/h + this is 2²³ + 512 + round(x/h) for |x/h| < 512 (the ulp is 1 in
/// [2²³, 2²⁴)), whose bit pattern is 2²³'s plus 512 + k: one unsigned comparison tests the
/// range (NaN and ±∞ fail it), and the low bits are k mod 128.
const K_ROUNDER: f32 = 8_389_120.0;
const TWO_23_BITS: u32 = 8_388_608.0_f32.to_bits();
// The fast path's range test admits every |x| ≤ FAST_RANGE (|x/h| < 511), with the rounder
// as documented.
const _: () = assert!(FAST_RANGE * STEPS_PER_RAD < 511.0 && K_ROUNDER == 8_388_608.0 + 512.0);

/// 1.5·2²³: adding and subtracting it rounds an f32 of magnitude below 2²² to the nearest
/// integer (ties to even) in the FPU's default rounding mode.
const ROUNDER: f32 = 12_582_912.0;

/// `v` rounded to the nearest integer, ties to even, for |v| < 2²² (the callers guarantee it).
fn round_small(v: f32) -> f32 {
    (v + ROUNDER) - ROUNDER
}

/// `(sin x, cos x)` in single precision (see the module docs for the method and accuracy).
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    let rounded = x * STEPS_PER_RAD + K_ROUNDER;
    let bits = rounded.to_bits();
    if bits.wrapping_sub(TWO_23_BITS) >= 1024 {
        return (libm::sinf(x), libm::cosf(x));
    }
    let k = rounded - K_ROUNDER;
    let r = (x - k * H1) - k * H2;
    let j = (bits & (STEPS - 1)) as usize;
    let (sin_kh, cos_kh) = (SIN_TABLE[j], SIN_TABLE[j + STEPS as usize / 4]);
    let z = r * r;
    let sin_r = r + r * z * (-1.0 / 6.0);
    let cos_r_minus_1 = -0.5 * z;
    (
        sin_kh + (sin_kh * cos_r_minus_1 + cos_kh * sin_r),
        cos_kh + (cos_kh * cos_r_minus_1 - sin_kh * sin_r),
    )
}

/// (sin a, cos a) in f64 for 0 ≤ a < π/2 by their Taylor series (terms to a³⁹/39!, far below
/// an f64 ulp), at compile time.
const fn taylor_sin_cos(a: f64) -> (f64, f64) {
    let (mut sin, mut cos) = (0.0, 0.0);
    let (mut sin_term, mut cos_term) = (a, 1.0);
    let mut k = 0;
    while k < 40 {
        cos += cos_term;
        sin += sin_term;
        cos_term *= -a * a / ((k + 1) * (k + 2)) as f64;
        sin_term *= -a * a / ((k + 2) * (k + 3)) as f64;
        k += 2;
    }
    (sin, cos)
}

/// [`SIN_TABLE`]: each quadrant from the first one's sines and cosines.
const fn sin_table() -> [f32; TABLE_LEN] {
    let quarter = STEPS as usize / 4;
    let mut table = [0.0; TABLE_LEN];
    let mut j = 0;
    while j < TABLE_LEN {
        let a = (j % quarter) as f64 * (core::f64::consts::TAU / STEPS as f64);
        let (sin, cos) = taylor_sin_cos(a);
        table[j] = match (j / quarter) % 4 {
            0 => sin,
            1 => cos,
            2 => -sin,
            _ => -cos,
        } as f32;
        j += 1;
    }
    table
}

/// Smallest argument of the fast [`exp`]: e^x stays a normal f32 above it.
pub const EXP_FAST_MIN: f32 = -87.0;

/// Smallest argument of the fast [`exp2_and_complement`]: 2^t stays a normal f32 above it.
pub const EXP2_FAST_MIN: f32 = -126.0;

const LOG2_E: f32 = core::f32::consts::LOG2_E;
const LN_2: f32 = core::f32::consts::LN_2;
// ln 2 = L1 + L2 (Cephes: L1 = 0.693359375 has 9 significant bits, so k·L1 is exact).
const L1: f32 = 0.693_359_4;
const L2: f32 = -2.121_944_4e-4;
// Cephes expf: e^r ≈ 1 + r + r²(E0 + r(E1 + r(E2 + r(E3 + r(E4 + r E5))))) on |r| ≤ ln 2 / 2.
const E0: f32 = 0.5;
const E1: f32 = 1.666_666_5e-1;
const E2: f32 = 4.166_579_6e-2;
const E3: f32 = 8.333_452e-3;
const E4: f32 = 1.398_2e-3;
const E5: f32 = 1.987_569_1e-4;

/// e^x in single precision (see the module docs for the accuracy).
#[inline]
pub fn exp(x: f32) -> f32 {
    exp_and_complement(x).0
}

/// (e^x, 1 − e^x) in single precision, each within a few ulps of its own correctly rounded
/// value: the complement is not computed from the rounded e^x, so it keeps its relative
/// precision where e^x ≈ 1 (1 − fl(e^x) would lose it to cancellation: for x = −5·10⁻⁴ the
/// relative error of 1 − fl(e^x) is 6·10⁻⁵). The Eq. 29 blend needs both E = e^{−cτ} and
/// 1 − E, and right after the blend (re)starts E is that close to 1.
///
/// The fast path is the decay range [`EXP_FAST_MIN`] ≤ x ≤ −0 (the blend's argument −cτ is
/// always there), selected by one unsigned comparison of the bit pattern: the negative floats
/// from −0 to −87 are one contiguous range of patterns. Everything else (+0, positive
/// arguments, results below the normal range, infinities, NaN) is libm's.
#[inline]
pub fn exp_and_complement(x: f32) -> (f32, f32) {
    const NEG_ZERO: u32 = 0x8000_0000;
    const SPAN: u32 = EXP_FAST_MIN.to_bits() - NEG_ZERO;
    if x.to_bits().wrapping_sub(NEG_ZERO) > SPAN {
        return (libm::expf(x), -libm::expm1f(x));
    }
    // −126 < x/ln 2 ≤ 0: k is exact and −126 ≤ k ≤ 0, so 2^k is a normal f32.
    let k = round_small(x * LOG2_E);
    let r = (x - k * L1) - k * L2;
    two_to_k_times_exp(k, r)
}

/// (2^t, 1 − 2^t) in single precision, each within a few ulps of its own correctly rounded
/// value: [`exp_and_complement`] for an argument already in units of ln 2 (e^x = 2^t with
/// t = x·log₂e). A caller whose argument is a product with a constant — the Eq. 29 blend's
/// −cτ·log₂e = (−cΔt·log₂e)·k after k ticks — folds log₂e into the constant once, and the
/// reduction needs no two-part ln 2: the fraction t − round(t) is exact.
///
/// The fast path is [`EXP2_FAST_MIN`] ≤ t ≤ −0 (one unsigned comparison of the bit pattern);
/// everything else takes an out-of-line path without libm (`exp2_special`).
#[inline]
pub fn exp2_and_complement(t: f32) -> (f32, f32) {
    const NEG_ZERO: u32 = 0x8000_0000;
    const SPAN: u32 = EXP2_FAST_MIN.to_bits() - NEG_ZERO;
    if t.to_bits().wrapping_sub(NEG_ZERO) > SPAN {
        return exp2_special(t);
    }
    // −126 ≤ k ≤ 0; t − k is exact (|t − k| ≤ ½, and t and k are multiples of t's ulp).
    let k = round_small(t);
    let r = (t - k) * LN_2;
    two_to_k_times_exp(k, r)
}

/// [`exp2_and_complement`] outside its fast range: NaN gives NaN; below −150, (0, 1); from
/// −150 to −126, where 2^t is subnormal, 2^{t+64}·2⁻⁶⁴ (t + 64 is exact, the scaling rounds
/// once) with the complement 1; from +0 up, the same kernel with 2^k up to 2¹²⁷ (2¹²⁸ as
/// 2·2¹²⁷), overflowing to +∞ at 128. Without libm: it keeps libm's `exp2f` and `expm1f`
/// out of the firmware.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(t >= …)` is meant: it is true for NaN.
fn exp2_special(t: f32) -> (f32, f32) {
    const TWO_TO_MINUS_64: f32 = 1.0 / 18_446_744_073_709_551_616.0;
    if !(t >= -150.0) {
        return if t.is_nan() { (t, t) } else { (0.0, 1.0) };
    }
    if t < EXP2_FAST_MIN {
        return (exp2_and_complement(t + 64.0).0 * TWO_TO_MINUS_64, 1.0);
    }
    if t >= 128.0 {
        return (f32::INFINITY, f32::NEG_INFINITY);
    }
    // +0 ≤ t < 128: 0 ≤ k ≤ 128, t − k exact as in the fast path.
    let k = round_small(t);
    let r = (t - k) * LN_2;
    if k > 127.0 {
        let e = 2.0 * two_to_k_times_exp(127.0, r).0;
        return (e, 1.0 - e);
    }
    two_to_k_times_exp(k, r)
}

/// (2^k e^r, 1 − 2^k e^r) for an integer −126 ≤ k ≤ 0 and |r| ≤ ln 2 / 2 (plus rounding): the
/// shared end of [`exp_and_complement`] and [`exp2_and_complement`].
fn two_to_k_times_exp(k: f32, r: f32) -> (f32, f32) {
    // q = e^r − 1, |q| < 0.42.
    let q = r + r * r * (E0 + r * (E1 + r * (E2 + r * (E3 + r * (E4 + r * E5)))));
    let two_to_k = f32::from_bits(((k as i32).wrapping_add(127) as u32) << 23);
    // e^x = 2^k + 2^k q and 1 − e^x = (1 − 2^k) − 2^k q: 2^k q is exact, 1 − 2^k is exact for
    // k ≥ −24 (and rounds to 1 below, where 2^k is below half an ulp of the result), so each
    // is one rounding from its value. For k = 0 the complement is −q: no cancellation.
    let scaled_q = two_to_k * q;
    (two_to_k + scaled_q, (1.0 - two_to_k) - scaled_q)
}

/// sin x in single precision.
#[inline]
pub fn sin(x: f32) -> f32 {
    sin_cos(x).0
}

/// cos x in single precision.
#[inline]
pub fn cos(x: f32) -> f32 {
    sin_cos(x).1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn worst_error(xs: impl Iterator<Item = f32>) -> (f64, f32) {
        let mut worst = (0.0, 0.0);
        for x in xs {
            let (s, c) = sin_cos(x);
            let xd = f64::from(x);
            let e = (f64::from(s) - libm::sin(xd))
                .abs()
                .max((f64::from(c) - libm::cos(xd)).abs());
            if e > worst.0 {
                worst = (e, x);
            }
        }
        worst
    }

    #[test]
    fn accurate_over_the_laws_range() {
        // Every 64th f32 in [−2π, 2π] (about 34 million arguments).
        let hi = (2.0 * core::f32::consts::PI).to_bits();
        let xs = (0..=hi).step_by(64).flat_map(|b| {
            let x = f32::from_bits(b);
            [x, -x]
        });
        let (e, at) = worst_error(xs);
        assert!(e < 1.5e-7, "max error {e:e} at x = {at}");
    }

    #[test]
    fn accurate_up_to_the_fast_range() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let xs = (0..2_000_000).map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            ((seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) as f32 * FAST_RANGE
        });
        let (e, at) = worst_error(xs);
        assert!(e < 1.5e-7, "max error {e:e} at x = {at}");
    }

    /// Distance in ulps between `got` and the correctly rounded `exact` (same sign, finite).
    fn ulps(got: f32, exact: f64) -> i64 {
        (got.to_bits() as i64 - (exact as f32).to_bits() as i64).abs()
    }

    #[test]
    fn exp_is_within_two_ulps_over_its_fast_range() {
        // Every 32nd f32 in [−87, −0] (≈ 34 million arguments), against f64 e^x rounded, and
        // every 64th positive one up to 88 (libm's path).
        let mut worst = (0, 0.0_f32);
        let bottom = EXP_FAST_MIN.to_bits();
        let neg = (0x8000_0000..=bottom).step_by(32);
        let pos = (0..=88.0_f32.to_bits()).step_by(64);
        for bits in neg.chain(pos) {
            let x = f32::from_bits(bits);
            let u = ulps(exp(x), libm::exp(f64::from(x)));
            if u > worst.0 {
                worst = (u, x);
            }
        }
        assert!(worst.0 <= 2, "{} ulps at x = {:e}", worst.0, worst.1);
    }

    #[test]
    fn complement_is_within_a_few_ulps_of_one_minus_exp() {
        // Every 32nd f32 in [−87, −0]: 1 − e^x against the f64 value, in ulps of its own size
        // (it is never 0 there: the smallest, at x = −2⁻¹⁴⁹, is 2⁻¹⁴⁹ itself).
        let mut worst = (0, 0.0_f32);
        for bits in (0x8000_0000..=EXP_FAST_MIN.to_bits()).step_by(32) {
            let x = f32::from_bits(bits);
            let (e, c) = exp_and_complement(x);
            let u = ulps(c, -libm::expm1(f64::from(x)));
            if u > worst.0 {
                worst = (u, x);
            }
            assert_eq!(e.to_bits(), exp(x).to_bits());
        }
        assert!(worst.0 <= 2, "{} ulps at x = {:e}", worst.0, worst.1);
        // The case of the blend restart: e^x ≈ 1.
        let x = -5.0e-4_f32;
        let c = exp_and_complement(x).1;
        let exact = -libm::expm1(f64::from(x));
        assert!(
            (f64::from(c) - exact).abs() <= 1e-7 * exact,
            "{c} vs {exact}"
        );
        // Outside the fast range: libm's pair.
        for x in [0.0_f32, 1.0, -90.0, f32::NEG_INFINITY] {
            let (e, c) = exp_and_complement(x);
            assert_eq!(e.to_bits(), libm::expf(x).to_bits(), "{x}");
            assert_eq!(c.to_bits(), (-libm::expm1f(x)).to_bits(), "{x}");
        }
    }

    #[test]
    fn exp2_and_its_complement_are_within_two_ulps_over_the_fast_range() {
        // Every 32nd f32 in [−126, −0] (≈ 34 million arguments): 2^t and 1 − 2^t against the
        // f64 values, each in ulps of its own size.
        let (mut worst_e, mut worst_c) = ((0, 0.0_f32), (0, 0.0_f32));
        for bits in (0x8000_0000..=EXP2_FAST_MIN.to_bits()).step_by(32) {
            let t = f32::from_bits(bits);
            let (e, c) = exp2_and_complement(t);
            let td = f64::from(t);
            let ue = ulps(e, libm::exp2(td));
            let uc = ulps(c, -libm::expm1(td * core::f64::consts::LN_2));
            if ue > worst_e.0 {
                worst_e = (ue, t);
            }
            if uc > worst_c.0 {
                worst_c = (uc, t);
            }
        }
        assert!(
            worst_e.0 <= 2,
            "2^t: {} ulps at t = {:e}",
            worst_e.0,
            worst_e.1
        );
        assert!(
            worst_c.0 <= 2,
            "1 − 2^t: {} ulps at t = {:e}",
            worst_c.0,
            worst_c.1
        );
        // Both ends of the fast range, and the integers (exact powers of two).
        assert_eq!(exp2_and_complement(-0.0), (1.0, 0.0));
        for k in 0..=126 {
            let t = -(k as f32);
            assert_eq!(exp2_and_complement(t).0, libm::exp2f(t), "{t}");
        }
        assert!(exp2_and_complement(f32::NAN).0.is_nan());
        assert!(exp2_and_complement(f32::NAN).1.is_nan());
    }

    #[test]
    fn exp2_outside_the_fast_range_is_within_two_ulps() {
        // Every 16th f32 of [−150, −126) (subnormal results: within 1 ulp of the subnormal)
        // and of [+0, 128) (normal results up to overflow).
        let below = (EXP2_FAST_MIN.to_bits() + 1..=(-150.0_f32).to_bits()).step_by(16);
        let above = (0..128.0_f32.to_bits()).step_by(16);
        for bits in below.chain(above) {
            let t = f32::from_bits(bits);
            let (e, c) = exp2_and_complement(t);
            let td = f64::from(t);
            assert!(ulps(e, libm::exp2(td)) <= 2, "2^{t:e} = {e:e}");
            let exact_c = -libm::expm1(td * core::f64::consts::LN_2);
            // (±0 compare equal: 1 − 2^{+0} is +0 here, −expm1(+0) is −0.)
            assert!(
                c == exact_c as f32 || ulps(c, exact_c) <= 2,
                "1 − 2^{t:e} = {c:e}"
            );
        }
        for (t, e, c) in [
            (0.0_f32, 1.0_f32, 0.0_f32),
            (1.0, 2.0, -1.0),
            (127.0, 1.701_411_8e38, -1.701_411_8e38),
            (128.0, f32::INFINITY, f32::NEG_INFINITY),
            (f32::INFINITY, f32::INFINITY, f32::NEG_INFINITY),
            (-150.000_02, 0.0, 1.0),
            (f32::NEG_INFINITY, 0.0, 1.0),
        ] {
            assert_eq!(exp2_and_complement(t), (e, c), "{t}");
        }
        assert_eq!(exp2_and_complement(-149.0).0, f32::from_bits(1));
    }

    #[test]
    fn exp_special_values_are_libms() {
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-0.0), 1.0);
        for x in [
            0.0_f32,
            1.0,
            -87.000_01,
            -100.0,
            -104.0,
            88.000_01,
            88.7,
            89.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            f32::MIN,
        ] {
            assert_eq!(exp(x).to_bits(), libm::expf(x).to_bits(), "{x}");
        }
        assert!(exp(f32::NAN).is_nan());
        // Just inside the fast range at both ends: normal results, within two ulps.
        for x in [EXP_FAST_MIN, -0.0, -f32::MIN_POSITIVE, -1e-30] {
            assert!(exp(x).is_normal());
            assert!(ulps(exp(x), libm::exp(f64::from(x))) <= 2, "{x}");
        }
    }

    #[test]
    fn round_small_is_rintf() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        for _ in 0..1_000_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let v = ((seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) as f32 * 4.0e6;
            assert_eq!(round_small(v), libm::rintf(v), "{v}");
        }
        for v in [
            0.5_f32,
            1.5,
            2.5,
            -0.5,
            -1.5,
            -2.5,
            4_194_303.5,
            -4_194_303.5,
        ] {
            assert_eq!(round_small(v), libm::rintf(v), "{v}");
        }
    }

    #[test]
    fn reduction_constants_and_table_are_as_documented() {
        let h = core::f64::consts::TAU / f64::from(STEPS);
        assert_eq!(f64::from(H1), libm::floor(h * 16_384.0) / 16_384.0);
        assert_eq!(H2, (h - f64::from(H1)) as f32);
        assert!((h - f64::from(H1) - f64::from(H2)).abs() < 1e-12);
        // k·H1 exact for every k of the fast path.
        for k in -512..=512 {
            let k = k as f32;
            assert_eq!(f64::from(k * H1), f64::from(k) * f64::from(H1));
        }
        // The compile-time table is f64's sine, rounded (its zeros exact: f64's sin(jh) is
        // about 1e-16 there, from the rounding of jh).
        for (j, &v) in SIN_TABLE.iter().enumerate() {
            let exact = libm::sin(j as f64 * h);
            assert!(
                v == exact as f32 || (v == 0.0 && exact.abs() < 1e-15),
                "entry {j}: {v:e}, f64 {exact:e}"
            );
        }
    }

    #[test]
    fn quadrant_boundaries_and_special_values() {
        for k in -20..=20 {
            let x = k as f32 * core::f32::consts::FRAC_PI_2;
            let (s, c) = sin_cos(x);
            assert!((f64::from(s) - libm::sin(f64::from(x))).abs() < 1.5e-7);
            assert!((f64::from(c) - libm::cos(f64::from(x))).abs() < 1.5e-7);
        }
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        assert!(sin(f32::NAN).is_nan() && cos(f32::INFINITY).is_nan());
        assert_eq!(sin(1e20), libm::sinf(1e20));
    }
}
