//! A sum of f64 values kept exactly, so that it does not depend on the order of its terms: the
//! campaign's NEES and NIS sums are the same whether the runs are added in run order, in the
//! order threads finish them, or shard by shard and merged.
//!
//! The sum is held as Shewchuk's non-overlapping partials (J. R. Shewchuk, "Adaptive precision
//! floating-point arithmetic and fast robust geometric predicates", Discrete & Computational
//! Geometry 18, 1997, §2: Grow-Expansion by Two-Sum), whose exact total is the exact sum of the
//! terms; [`ExactSum::value`] rounds that total once, to nearest with ties to even, as Python's
//! `math.fsum` does (R. Hettinger's recipe). The same terms in any order, or any grouping of
//! them into partial sums merged by [`ExactSum::merge`], give the same bits.
//!
//! Non-finite terms (NaN, ±∞) are summed apart: the sum is then that non-finite value (NaN if
//! both infinities occur), again whatever the order. Terms whose running total leaves f64's
//! range (about 1.8e308) make the sum infinite.

/// An exact sum of f64 values (equal when their sums are: [`ExactSum::to_text`]).
#[derive(Clone, Debug, Default)]
pub struct ExactSum {
    /// Non-overlapping partials, in increasing magnitude, none zero: their exact total is the
    /// sum of the finite terms.
    partials: Vec<f64>,
    /// The sum of the non-finite terms (and of a finite total that overflowed), if any.
    non_finite: Option<f64>,
}

impl ExactSum {
    /// Adds `x`, exactly.
    pub fn add(&mut self, x: f64) {
        if !x.is_finite() {
            self.add_non_finite(x);
            return;
        }
        // Grow-Expansion: Two-Sum of x with each partial, keeping the non-zero round-off.
        let mut x = x;
        let mut kept = 0;
        for k in 0..self.partials.len() {
            let mut y = self.partials[k];
            if x.abs() < y.abs() {
                std::mem::swap(&mut x, &mut y);
            }
            let hi = x + y;
            if !hi.is_finite() {
                // Beyond f64's range: the sum is infinite.
                self.partials.clear();
                self.add_non_finite(hi);
                return;
            }
            let lo = y - (hi - x);
            if lo != 0.0 {
                self.partials[kept] = lo;
                kept += 1;
            }
            x = hi;
        }
        self.partials.truncate(kept);
        if x != 0.0 {
            self.partials.push(x);
        }
    }

    fn add_non_finite(&mut self, x: f64) {
        self.non_finite = Some(self.non_finite.map_or(x, |s| s + x));
    }

    /// Adds every term of `other` (the result is the sum of both sets of terms).
    pub fn merge(&mut self, other: &ExactSum) {
        for &p in &other.partials {
            self.add(p);
        }
        if let Some(x) = other.non_finite {
            self.add_non_finite(x);
        }
    }

    /// The sum, rounded once to the nearest f64 (ties to even).
    pub fn value(&self) -> f64 {
        if let Some(x) = self.non_finite {
            return x;
        }
        let p = &self.partials;
        let Some(mut n) = p.len().checked_sub(1) else {
            return 0.0;
        };
        // From the largest partial down, while the additions are exact.
        let mut hi = p[n];
        let mut lo = 0.0;
        while n > 0 {
            n -= 1;
            let x = hi;
            let y = p[n];
            hi = x + y;
            lo = y - (hi - x);
            if lo != 0.0 {
                break;
            }
        }
        // hi + lo is exact, and the partials below have the sign of what they add: if lo is
        // exactly half an ulp of hi and the rest pushes the same way, round away from hi.
        if n > 0 && ((lo < 0.0 && p[n - 1] < 0.0) || (lo > 0.0 && p[n - 1] > 0.0)) {
            let y = lo * 2.0;
            let x = hi + y;
            if x - hi == y {
                hi = x;
            }
        }
        hi
    }

    /// The exact sum as f64s that add up to it, the same whatever the terms and their order:
    /// the sum rounded, then the rest rounded, and so on until nothing is left (each a
    /// fraction of an ulp of the one before; a sum of f64s is a multiple of 2⁻¹⁰⁷⁴, so the rest
    /// reaches zero). Empty for zero; the non-finite part is not included.
    pub fn canonical(&self) -> Vec<f64> {
        let mut rest = ExactSum {
            partials: self.partials.clone(),
            non_finite: None,
        };
        let mut parts = Vec::new();
        loop {
            let v = rest.value();
            if v == 0.0 {
                return parts;
            }
            parts.push(v);
            rest.add(-v);
        }
    }

    /// The sum as text: [`ExactSum::canonical`], `;`-separated in Rust's shortest round-trip
    /// form, and the non-finite sum after a `|` if any (`1.5;3.2e-17`, `|NaN`, empty for
    /// zero). Equal sums give equal texts.
    pub fn to_text(&self) -> String {
        let mut s: Vec<String> = self.canonical().iter().map(f64::to_string).collect();
        if let Some(x) = self.non_finite {
            s.push(format!("|{x}"));
        }
        s.join(";")
    }

    /// Parses [`ExactSum::to_text`].
    pub fn from_text(text: &str) -> Result<Self, String> {
        let mut sum = ExactSum::default();
        for part in text.split(';').filter(|p| !p.is_empty()) {
            match part.strip_prefix('|') {
                Some(x) => {
                    let x: f64 = x.parse().map_err(|_| format!("{x:?} is not a number"))?;
                    if x.is_finite() {
                        return Err(format!("{x} after `|` is finite"));
                    }
                    sum.add_non_finite(x);
                }
                None => {
                    let x: f64 = part
                        .parse()
                        .map_err(|_| format!("{part:?} is not a number"))?;
                    if !x.is_finite() || x == 0.0 {
                        return Err(format!("partial {part} is not a finite non-zero number"));
                    }
                    sum.add(x);
                }
            }
        }
        Ok(sum)
    }
}

impl PartialEq for ExactSum {
    fn eq(&self, other: &Self) -> bool {
        self.to_text() == other.to_text()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn sum(xs: &[f64]) -> f64 {
        let mut s = ExactSum::default();
        for &x in xs {
            s.add(x);
        }
        s.value()
    }

    #[test]
    fn sums_that_naive_addition_gets_wrong() {
        // 1 + 1e100 + 1 − 1e100 = 2; naively 0.
        assert_eq!(sum(&[1.0, 1e100, 1.0, -1e100]), 2.0);
        // Ten tenths: exactly 10 × the double 0.1 = 1.0000000000000000555…, rounded: 1.
        assert_eq!(sum(&[0.1; 10]), 1.0);
        assert_eq!(sum(&[]), 0.0);
        // From Python's math.fsum tests (Lib/test/test_math.py): just below and just above a
        // tie.
        let two53 = 2.0f64.powi(53);
        assert_eq!(sum(&[two53, -0.5, -(2.0f64.powi(-54))]), two53 - 1.0);
        assert_eq!(sum(&[two53, 0.9999999999999999]), two53);
        // A running total beyond f64's range: infinite.
        assert_eq!(sum(&[1e308, 1e308, -1e308]), f64::INFINITY);
        assert_eq!(
            sum(&[1.7976931348623157e308, -1.7976931348623157e308 * 0.5, 1.0]),
            1.7976931348623157e308 * 0.5
        );
    }

    #[test]
    fn ties_round_to_even() {
        // 2⁵³ + 1 lies halfway between 2⁵³ and 2⁵³ + 2: to even, 2⁵³.
        let two53 = 2.0f64.powi(53);
        assert_eq!(sum(&[two53, 1.0]), two53);
        // 2⁵³ + 1 + 2⁻¹⁰⁰ is just above the tie: up.
        assert_eq!(sum(&[two53, 1.0, 2.0f64.powi(-100)]), two53 + 2.0);
        // 2⁵³ + 3 halfway between 2⁵³ + 2 and 2⁵³ + 4: to even, + 4.
        assert_eq!(sum(&[two53, 3.0]), two53 + 4.0);
    }

    #[test]
    fn non_finite_terms() {
        assert!(sum(&[1.0, f64::NAN, 2.0]).is_nan());
        assert_eq!(sum(&[1.0, f64::INFINITY, 2.0]), f64::INFINITY);
        assert!(sum(&[f64::INFINITY, 1.0, f64::NEG_INFINITY]).is_nan());
    }

    #[test]
    fn text_round_trips() {
        let mut s = ExactSum::default();
        for x in [1e100, 1.0, -1e100, 0.1, 3.0e-300] {
            s.add(x);
        }
        let back = ExactSum::from_text(&s.to_text()).unwrap();
        assert_eq!(back.value().to_bits(), s.value().to_bits());
        assert_eq!(back.to_text(), s.to_text());
        // The same sum reached another way writes the same text.
        let mut other = ExactSum::default();
        for x in [3.0e-300, 0.1, 1.0] {
            other.add(x);
        }
        assert_eq!(other.to_text(), s.to_text());
        assert_eq!(s.canonical()[0], s.value());
        s.add(f64::NAN);
        assert!(ExactSum::from_text(&s.to_text()).unwrap().value().is_nan());
        assert_eq!(ExactSum::from_text("").unwrap().value(), 0.0);
        assert!(ExactSum::from_text("x").is_err());
        assert!(ExactSum::from_text("0").is_err());
    }

    /// The exact sum of values with a common scale, by integers: each value is an integer
    /// multiple of 2⁻⁶⁰ below 2⁴⁰, so i128 holds the sum exactly.
    fn reference(xs: &[f64]) -> f64 {
        let scale = 2.0f64.powi(60);
        let total: i128 = xs.iter().map(|&x| (x * scale) as i128).sum();
        // One rounding: i128 → f64 is round-to-nearest-even, and the scale is a power of two.
        total as f64 / scale
    }

    proptest! {
        /// Any order and any split into merged parts gives the same bits, and those of the
        /// exact sum rounded once.
        #[test]
        fn order_and_grouping_do_not_matter(
            ints in prop::collection::vec(-(1i64 << 50)..(1i64 << 50), 1..60),
            exps in prop::collection::vec(-60i32..-10, 60),
            split in 0usize..60,
        ) {
            let xs: Vec<f64> = ints
                .iter()
                .zip(&exps)
                .map(|(&i, &e)| i as f64 * 2.0f64.powi(e))
                .collect();
            let forward = sum(&xs);
            let mut rev = xs.clone();
            rev.reverse();
            prop_assert_eq!(forward.to_bits(), sum(&rev).to_bits());
            let cut = split.min(xs.len());
            let (a, b) = xs.split_at(cut);
            let mut left = ExactSum::default();
            a.iter().for_each(|&x| left.add(x));
            let mut right = ExactSum::default();
            b.iter().for_each(|&x| right.add(x));
            right.merge(&left);
            prop_assert_eq!(forward.to_bits(), right.value().to_bits());
            let mut rev_sum = ExactSum::default();
            rev.iter().for_each(|&x| rev_sum.add(x));
            prop_assert_eq!(rev_sum.to_text(), right.to_text());
            prop_assert_eq!(forward.to_bits(), reference(&xs).to_bits());
        }
    }
}
