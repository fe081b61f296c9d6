//! The vocabulary of validation rules: a [`Validator`] collects every failed rule as a
//! [`Problem`] (field, value, message), so that a user sees all of them at once. The rules
//! themselves live next to the section they check.

use super::error::Problem;

/// Relative tolerance when checking that one interval is a whole multiple of another
/// (e.g. the output interval of the control period): 1e-9 of the ratio.
const WHOLE_MULTIPLE_REL_TOL: f64 = 1e-9;

/// An f64 as messages write it: the shortest form that reads back exactly, `40000` for
/// 40000.0, in exponent form (`1e308`, `1e-50`) beyond 1e16 and below 1e-6 in magnitude.
pub(super) fn num(x: f64) -> String {
    let a = x.abs();
    if a.is_finite() && a != 0.0 && !(1e-6..1e16).contains(&a) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// A finite number above 0: the rule a value passed, for the rules that compare against it.
pub(super) fn is_positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

/// Collects the problems of a scenario, rule by rule, in the order the rules run.
#[derive(Default)]
pub(super) struct Validator {
    /// Every failed rule so far.
    pub(super) problems: Vec<Problem>,
}

impl Validator {
    /// Records a problem unless `ok`; returns `ok`.
    pub(super) fn check(&mut self, ok: bool, field: &str, value: String, message: &str) -> bool {
        if !ok {
            self.problems.push(Problem {
                field: field.to_string(),
                value,
                message: message.to_string(),
                from_override: false,
            });
        }
        ok
    }
    pub(super) fn finite(&mut self, field: &str, x: f64) -> bool {
        self.check(x.is_finite(), field, num(x), "must be a finite number")
    }
    pub(super) fn positive(&mut self, field: &str, x: f64) -> bool {
        self.finite(field, x) && self.check(x > 0.0, field, num(x), "must be above 0")
    }
    pub(super) fn non_negative(&mut self, field: &str, x: f64) -> bool {
        self.finite(field, x) && self.check(x >= 0.0, field, num(x), "must not be negative")
    }
    /// A saturation limit: above 0, `inf` meaning none (NaN is rejected).
    pub(super) fn limit(&mut self, field: &str, x: f64) -> bool {
        self.check(x > 0.0, field, num(x), "must be above 0 (inf = no limit)")
    }
    /// A window [from, until): `from` finite and ≥ 0 (or inf = never, when `never_ok`),
    /// `until` after `from` (inf = to the end of the run; equal to `from` only when both are
    /// inf).
    pub(super) fn window(
        &mut self,
        from_field: &str,
        from: f64,
        until_field: &str,
        until: f64,
        never_ok: bool,
    ) {
        let from_ok = if never_ok && from == f64::INFINITY {
            true
        } else {
            self.non_negative(from_field, from)
        };
        let until_ok = self.check(
            !until.is_nan(),
            until_field,
            num(until),
            "must be a number (inf = to the end of the run)",
        );
        if from_ok && until_ok && from.is_finite() {
            self.check(
                until > from,
                until_field,
                num(until),
                &format!("must be after {from_field} = {}", num(from)),
            );
        }
    }
    /// `x` must be `k · period` for a whole k (k ≥ 1, or k ≥ 0 when `zero_ok`).
    pub(super) fn whole_multiple_of_period(
        &mut self,
        field: &str,
        x: f64,
        period: f64,
        zero_ok: bool,
    ) {
        if !(period.is_finite() && period > 0.0) {
            return; // reported on controller.period_s
        }
        let ratio = x / period;
        let k = ratio.round();
        let whole = (ratio - k).abs() <= WHOLE_MULTIPLE_REL_TOL * ratio.abs().max(1.0);
        let ok = whole && (k >= 1.0 || (zero_ok && k == 0.0));
        let what = if zero_ok { "non-negative" } else { "positive" };
        self.check(
            ok,
            field,
            num(x),
            &format!(
                "must be a {what} whole multiple of controller.period_s = {}",
                num(period)
            ),
        );
    }
}
