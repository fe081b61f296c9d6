//! Confidence intervals on a campaign's pass rate: k of n runs passed, what does that say of
//! the probability p that a run passes?
//!
//! - Wilson's score interval (E. B. Wilson, "Probable inference, the law of succession, and
//!   statistical inference", JASA 22, 1927): the p whose score test at level z accepts k/n,
//!
//!   (p̂ + z²/2n ± z·√(p̂(1 − p̂)/n + z²/4n²)) / (1 + z²/n),  p̂ = k/n.
//!
//!   Its coverage is close to the nominal level on average (Brown, Cai & DasGupta,
//!   "Interval estimation for a binomial proportion", Statistical Science 16, 2001).
//! - Clopper–Pearson's exact interval (Biometrika 26, 1934): the p for which k or fewer
//!   (more) passes have probability α/2, by the binomial's link to the beta distribution
//!
//!   [B(α/2; k, n − k + 1), B(1 − α/2; k + 1, n − k)],  B the beta quantile,
//!
//!   0 (1) when k = 0 (k = n). Its coverage is at least the nominal level: the conservative
//!   figure to quote for a requirement ("p ≥ 0.999 with 95 % confidence").

use super::consistency::Z_975;

/// The confidence level of the intervals the campaign reports.
pub const CONFIDENCE: f64 = 0.95;

/// A confidence interval on a proportion, both ends in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Interval {
    /// Lower end.
    pub low: f64,
    /// Upper end.
    pub high: f64,
}

/// Wilson's 95 % score interval for `k` passes of `n` runs (`None` if n = 0).
pub fn wilson(k: u64, n: u64) -> Option<Interval> {
    if n == 0 || k > n {
        return None;
    }
    let (k, n) = (k as f64, n as f64);
    let z = Z_975;
    let p = k / n;
    let z2n = z * z / n;
    let centre = (p + z2n / 2.0) / (1.0 + z2n);
    let half = z / (1.0 + z2n) * (p * (1.0 - p) / n + z2n / (4.0 * n)).sqrt();
    Some(Interval {
        low: (centre - half).max(0.0),
        high: (centre + half).min(1.0),
    })
}

/// Clopper–Pearson's exact 95 % interval for `k` passes of `n` runs (`None` if n = 0).
pub fn clopper_pearson(k: u64, n: u64) -> Option<Interval> {
    if n == 0 || k > n {
        return None;
    }
    let alpha = 1.0 - CONFIDENCE;
    let nf = n as f64;
    // The ends in closed form where one beta parameter is 1: B(q; a, 1) = q^(1/a) and
    // B(q; 1, b) = 1 − (1 − q)^(1/b).
    let low = match k {
        0 => 0.0,
        _ if k == n => (alpha / 2.0).powf(1.0 / nf),
        _ => beta_quantile(alpha / 2.0, k as f64, (n - k + 1) as f64),
    };
    let high = match k {
        _ if k == n => 1.0,
        0 => 1.0 - (alpha / 2.0).powf(1.0 / nf),
        _ => beta_quantile(1.0 - alpha / 2.0, (k + 1) as f64, (n - k) as f64),
    };
    Some(Interval { low, high })
}

/// The x in (0, 1) where the regularized incomplete beta function I_x(a, b) equals `q`, by
/// bisection (I_x increases with x): to f64's resolution of x.
fn beta_quantile(q: f64, a: f64, b: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    // 1100 halvings reach the smallest subnormal; the loop ends when the midpoint stops moving.
    for _ in 0..1100 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if regularized_beta(mid, a, b) < q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The regularized incomplete beta function I_x(a, b), by its continued fraction (Numerical
/// Recipes, 3rd ed., §6.4, with the modified Lentz method; the symmetry
/// I_x(a, b) = 1 − I_{1−x}(b, a) where the fraction converges slowly).
pub fn regularized_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = a * x.ln() + b * (1.0 - x).ln() - ln_beta(a, b);
    if x < (a + 1.0) / (a + b + 2.0) {
        ln_front.exp() * beta_fraction(x, a, b) / a
    } else {
        1.0 - ln_front.exp() * beta_fraction(1.0 - x, b, a) / b
    }
}

/// ln B(a, b) = ln Γ(a) + ln Γ(b) − ln Γ(a + b).
fn ln_beta(a: f64, b: f64) -> f64 {
    libm::lgamma(a) + libm::lgamma(b) - libm::lgamma(a + b)
}

/// The continued fraction of I_x(a, b) (Numerical Recipes' `betacf`), for x below
/// (a + 1)/(a + b + 2), where it converges in O(√max(a, b)) terms.
fn beta_fraction(x: f64, a: f64, b: f64) -> f64 {
    const TINY: f64 = 1e-300;
    const MAX_TERMS: u32 = 100_000;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < TINY {
        d = TINY;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..=MAX_TERMS {
        let m = f64::from(m);
        let m2 = 2.0 * m;
        // The even step.
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        if d.abs() < TINY {
            d = TINY;
        }
        c = 1.0 + aa / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        h *= d * c;
        // The odd step.
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        if d.abs() < TINY {
            d = TINY;
        }
        c = 1.0 + aa / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let step = d * c;
        h *= step;
        if (step - 1.0).abs() <= f64::EPSILON {
            break;
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// P(X ≤ k) for X binomial (n, p), by summing the probabilities (in logs): a computation
    /// independent of the beta function's.
    fn binomial_cdf(k: u64, n: u64, p: f64) -> f64 {
        let ln_choose = |i: u64| {
            libm::lgamma(n as f64 + 1.0)
                - libm::lgamma(i as f64 + 1.0)
                - libm::lgamma((n - i) as f64 + 1.0)
        };
        (0..=k)
            .map(|i| (ln_choose(i) + i as f64 * p.ln() + (n - i) as f64 * (1.0 - p).ln()).exp())
            .sum()
    }

    #[test]
    fn textbook_values() {
        // 5 of 10: Wilson [0.2366, 0.7634] (R's prop.test(5, 10, correct = FALSE)),
        // Clopper–Pearson [0.1871, 0.8129] (R's binom.test(5, 10)).
        let w = wilson(5, 10).unwrap();
        assert!(
            (w.low - 0.236_593).abs() < 1e-6 && (w.high - 0.763_407).abs() < 1e-6,
            "{w:?}"
        );
        let cp = clopper_pearson(5, 10).unwrap();
        assert!(
            (cp.low - 0.187_086).abs() < 1e-6 && (cp.high - 0.812_914).abs() < 1e-6,
            "{cp:?}"
        );
        // 0 of 4: Wilson's upper end z²/(n + z²) = 0.48990; Clopper–Pearson's 1 − 0.025^(1/4).
        let w = wilson(0, 4).unwrap();
        assert_eq!(w.low, 0.0);
        assert!((w.high - 0.489_891).abs() < 1e-6, "{w:?}");
        let cp = clopper_pearson(0, 4).unwrap();
        assert!((cp.high - 0.602_364_6).abs() < 1e-6, "{cp:?}");
        // 999 of 1000: R's binom.test(999, 1000) gives [0.9944411, 0.9999747].
        let cp = clopper_pearson(999, 1000).unwrap();
        assert!(
            (cp.low - 0.994_441_1).abs() < 1e-7 && (cp.high - 0.999_974_7).abs() < 1e-7,
            "{cp:?}"
        );
        assert_eq!(wilson(0, 0), None);
        assert_eq!(clopper_pearson(3, 0), None);
    }

    #[test]
    fn clopper_pearson_ends_have_tail_probability_alpha_over_two() {
        for (k, n) in [
            (1, 2),
            (3, 7),
            (17, 20),
            (50, 100),
            (990, 1000),
            (9_990, 10_000),
        ] {
            let cp = clopper_pearson(k, n).unwrap();
            // At the upper end, k or fewer passes have probability α/2; at the lower end, k or
            // more.
            let upper_tail = binomial_cdf(k, n, cp.high);
            let lower_tail = 1.0 - binomial_cdf(k - 1, n, cp.low);
            assert!((upper_tail - 0.025).abs() < 1e-9, "{k}/{n}: {upper_tail}");
            assert!((lower_tail - 0.025).abs() < 1e-9, "{k}/{n}: {lower_tail}");
            // Both hold k/n.
            let w = wilson(k, n).unwrap();
            let p = k as f64 / n as f64;
            assert!(cp.low < p && p < cp.high, "{k}/{n}: {cp:?}");
            assert!(w.low < p && p < w.high, "{k}/{n}: {w:?}");
        }
    }

    /// The example of docs/campaigns.md: 9 990 passes of 10 000.
    #[test]
    fn the_documented_example() {
        let percent = |i: Interval| format!("[{:.3}, {:.3}]", 100.0 * i.low, 100.0 * i.high);
        assert_eq!(percent(wilson(9_990, 10_000).unwrap()), "[99.816, 99.946]");
        assert_eq!(
            percent(clopper_pearson(9_990, 10_000).unwrap()),
            "[99.816, 99.952]"
        );
    }

    #[test]
    fn wilson_solves_its_score_equation() {
        // The ends are the p with |p̂ − p| = z √(p(1 − p)/n).
        for (k, n) in [(1u64, 3u64), (40, 50), (9_990, 10_000)] {
            let w = wilson(k, n).unwrap();
            let p_hat = k as f64 / n as f64;
            for p in [w.low, w.high] {
                let score = (p_hat - p).abs() / (p * (1.0 - p) / n as f64).sqrt();
                assert!((score - Z_975).abs() < 1e-9, "{k}/{n}: {score}");
            }
        }
    }
}
