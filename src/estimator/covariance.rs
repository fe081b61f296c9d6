//! The filter's covariance: a symmetric 3×3 matrix over (α, α̇, d) and the operations of a
//! period on it (propagation, rounding load, caps, the update).

use crate::real::Real;

/// ε, the relative growth of each variance per period that stands for the rounding of the
/// covariance propagation (see `Sym3::rounding_loaded`): 2⁻²², four f32 roundings.
pub const ROUNDING_LOAD: f64 = 1.0 / 4_194_304.0;

/// `v` above `cap`, or NaN: not `v ≤ cap`, in one comparison.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN is meant to count as above
pub(super) fn above_or_nan<T: Real>(v: T, cap: T) -> bool {
    !(v <= cap)
}

/// A symmetric 3×3 matrix over (α, α̇, d), by its upper triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Sym3<T> {
    pub(super) aa: T,
    pub(super) aw: T,
    pub(super) ad: T,
    pub(super) ww: T,
    pub(super) wd: T,
    pub(super) dd: T,
}

impl<T: Real> Sym3<T> {
    /// Φ P Φᵀ for Φ whose α and α̇ rows are `phi` and whose d row is e₃ᵀ.
    pub(super) fn propagated(&self, phi: &[[T; 3]; 2]) -> Self {
        let p = self;
        let [f0, f1] = phi;
        // M = Φ P, its first two rows (its third is P's).
        let m0 = [
            f0[0] * p.aa + f0[1] * p.aw + f0[2] * p.ad,
            f0[0] * p.aw + f0[1] * p.ww + f0[2] * p.wd,
            f0[0] * p.ad + f0[1] * p.wd + f0[2] * p.dd,
        ];
        let m1 = [
            f1[0] * p.aa + f1[1] * p.aw + f1[2] * p.ad,
            f1[0] * p.aw + f1[1] * p.ww + f1[2] * p.wd,
            f1[0] * p.ad + f1[1] * p.wd + f1[2] * p.dd,
        ];
        // (M Φᵀ)_ij = M_i · Φ_j; Φ's d row is e₃ᵀ, so (M Φᵀ)_i2 = M_i2.
        let dot = |m: &[T; 3], f: &[T; 3]| m[0] * f[0] + m[1] * f[1] + m[2] * f[2];
        Self {
            aa: dot(&m0, f0),
            aw: dot(&m0, f1),
            ad: m0[2],
            ww: dot(&m1, f1),
            wd: m1[2],
            dd: p.dd,
        }
    }

    /// The rounding noise of the period: each variance grown by [`ROUNDING_LOAD`] of itself.
    ///
    /// P + ε diag(P) lifts the smallest eigenvalue of P's correlation matrix by about ε each
    /// period. Without it, a long dropout (d's growing uncertainty drives α and α̇ alike, so P
    /// tends to rank one: correlations of 0.9999 and beyond) meets the f32 rounding of each
    /// period (6e-8) and P turns indefinite within a day
    /// (`tests/estimator/model_and_faults.rs::a_dropout_of_days_stays_bounded_in_f32`).
    pub(super) fn rounding_loaded(&self) -> Self {
        let grow = T::ONE + T::from_f64(ROUNDING_LOAD);
        Self {
            aa: self.aa * grow,
            ww: self.ww * grow,
            dd: self.dd * grow,
            ..*self
        }
    }

    /// The sum of two symmetric matrices.
    pub(super) fn plus(&self, q: &Self) -> Self {
        Self {
            aa: self.aa + q.aa,
            aw: self.aw + q.aw,
            ad: self.ad + q.ad,
            ww: self.ww + q.ww,
            wd: self.wd + q.wd,
            dd: self.dd + q.dd,
        }
    }

    /// Each variance above its cap brought to the cap, its covariances scaled by r = cap/var
    /// (no square root): the result is D P D with D = diag(r) (1 where not capped) plus the
    /// non-negative diagonal that lifts each capped variance from r²·var back to the cap, so
    /// it stays positive semidefinite, and the capped state's correlations shrink by √r. A NaN
    /// variance becomes its cap (its covariances unscaled).
    pub(super) fn cap(&mut self, caps: &[T; 3]) {
        let p = self;
        if p.aa <= caps[0] && p.ww <= caps[1] && p.dd <= caps[2] {
            return;
        }
        if above_or_nan(p.aa, caps[0]) {
            if p.aa > caps[0] {
                let r = caps[0] / p.aa;
                p.aw = p.aw * r;
                p.ad = p.ad * r;
            }
            p.aa = caps[0];
        }
        if above_or_nan(p.ww, caps[1]) {
            if p.ww > caps[1] {
                let r = caps[1] / p.ww;
                p.aw = p.aw * r;
                p.wd = p.wd * r;
            }
            p.ww = caps[1];
        }
        if above_or_nan(p.dd, caps[2]) {
            if p.dd > caps[2] {
                let r = caps[2] / p.dd;
                p.ad = p.ad * r;
                p.wd = p.wd * r;
            }
            p.dd = caps[2];
        }
    }

    /// The covariance after a sample, P − K pᵀ for the gain K = p/S worked out from this P
    /// (p = P e₁, P's α column; S = P_αα + r), by its upper triangle (module docs,
    /// *Covariance*: for this gain it is the Joseph form, to f32's resolution).
    ///
    /// α's row is r K, what p − P_αα K equals (p(1 − P_αα/S) = r p/S): evaluated as written,
    /// that difference cancels to r/S of p, and where P_αα ≫ r (the first sample after a
    /// dropout) it lost every digit (to 0 in f32 at P_αα = 10⁸ r); r K is within two roundings.
    /// The (α̇, d) block is P_ij − p_i K_j. A negative rounding residue on the diagonal becomes
    /// its magnitude (module docs).
    pub(super) fn posterior(&self, k: &[T; 3], r: T) -> Self {
        let p = self;
        Self {
            aa: (r * k[0]).abs(),
            aw: r * k[1],
            ad: r * k[2],
            ww: (p.ww - p.aw * k[1]).abs(),
            wd: p.wd - p.aw * k[2],
            dd: (p.dd - p.ad * k[2]).abs(),
        }
    }
}
