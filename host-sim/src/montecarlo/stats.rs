//! Summary statistics of a campaign and the text of `summary.txt`.
//!
//! The summary depends only on the scenario, the campaign's seed and size, the shard and the
//! records (never on timing or threads), so a campaign run whole and the merge of its shards
//! write the same bytes.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::campaign::{Criterion, Metric, RunRecord, WorstHealth};
use super::consistency;
use super::interval::{clopper_pearson, wilson, Interval, CONFIDENCE};
use super::shard::Shard;
use crate::scenario::{DispersionSection, Distribution, MonteCarloSection, Scenario};

/// How many failed runs the summary lists by index.
pub const FAILED_RUNS_LISTED: usize = 20;

/// Statistics of one column over the runs where it is a finite number.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Stats {
    /// Runs with a finite value.
    pub n: usize,
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation (n − 1; 0 for one value).
    pub std: f64,
    /// Smallest value.
    pub min: f64,
    /// 5th percentile.
    pub p5: f64,
    /// Median.
    pub p50: f64,
    /// 95th percentile.
    pub p95: f64,
    /// Largest value.
    pub max: f64,
}

impl Stats {
    /// Statistics of the finite `values` (`None` if there are none).
    pub fn of(values: impl Iterator<Item = f64>) -> Option<Self> {
        let mut v: Vec<f64> = values.filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let mean = v.iter().sum::<f64>() / n as f64;
        let std = if n > 1 {
            (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
        } else {
            0.0
        };
        Some(Self {
            n,
            mean,
            std,
            min: v[0],
            p5: percentile(&v, 0.05),
            p50: percentile(&v, 0.50),
            p95: percentile(&v, 0.95),
            max: v[n - 1],
        })
    }
}

/// The `q` quantile of sorted `v` (non-empty), linear between the closest ranks (Hyndman & Fan
/// type 7, as numpy's default).
pub fn percentile(v: &[f64], q: f64) -> f64 {
    let pos = q * (v.len() - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = pos.ceil() as usize;
    v[lo] + (v[hi] - v[lo]) * (pos - lo as f64)
}

/// A number in at most 6 significant digits, fixed-point for ordinary magnitudes.
pub fn sig(x: f64) -> String {
    if x == 0.0 {
        return "0".to_string();
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    let mag = x.abs().log10().floor();
    if (-3.0..6.0).contains(&mag) {
        let decimals = (5.0 - mag).max(0.0) as usize;
        let s = format!("{x:.decimals$}");
        // Trailing zeros after the point say nothing.
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        // 2.50000e-5 → 2.5e-5
        let s = format!("{x:.5e}");
        match s.split_once('e') {
            Some((mantissa, exp)) if mantissa.contains('.') => {
                let m = mantissa.trim_end_matches('0').trim_end_matches('.');
                format!("{m}e{exp}")
            }
            _ => s,
        }
    }
}

/// What a campaign is, for the summary's heading.
#[derive(Clone, Debug)]
pub struct CampaignInfo<'a> {
    /// The scenario as loaded.
    pub scenario: &'a Scenario,
    /// Its fingerprint (`manifest::fingerprint`).
    pub fingerprint: &'a str,
    /// The seed.
    pub seed: u64,
    /// Runs of the whole campaign.
    pub runs: u64,
    /// The shard these records are.
    pub shard: Shard,
    /// The build that flew them (`Manifest::build`).
    pub build: &'a str,
}

fn describe_dispersion(d: &DispersionSection, nominal: Option<f64>) -> String {
    let nom = nominal.map_or_else(|| "?".to_string(), sig);
    match (d.distribution, d.relative) {
        (Distribution::Normal, false) => match d.mean {
            Some(m) => format!("normal, mean {}, std {}", sig(m), sig(d.std.unwrap_or(0.0))),
            None => format!(
                "normal, mean {nom} (nominal), std {}",
                sig(d.std.unwrap_or(0.0))
            ),
        },
        (Distribution::Normal, true) => format!(
            "{nom} × (1 + N(mean {}, std {}))",
            sig(d.mean.unwrap_or(0.0)),
            sig(d.std.unwrap_or(0.0))
        ),
        (Distribution::Uniform, false) => format!(
            "uniform on [{}, {}] (nominal {nom})",
            sig(d.min.unwrap_or(0.0)),
            sig(d.max.unwrap_or(0.0))
        ),
        (Distribution::Uniform, true) => format!(
            "{nom} × (1 + U[{}, {}])",
            sig(d.min.unwrap_or(0.0)),
            sig(d.max.unwrap_or(0.0))
        ),
    }
}

/// The declared criteria as text, one per line (empty: none declared).
pub fn describe_criteria(sc: &Scenario) -> Vec<(Criterion, String)> {
    let c = &sc.montecarlo.criteria;
    let keep1 = sig(sc.stage1.keep_length_m);
    let mut v = Vec::new();
    if c.max_keep1_error_m < f64::INFINITY {
        v.push((
            Criterion::Keep1Error,
            format!(
                "max |l − {keep1} m| over {}–{} s ≤ {} m",
                sig(c.keep1_from_s),
                sig(c.keep1_until_s),
                sig(c.max_keep1_error_m)
            ),
        ));
    }
    if c.max_time_to_keep1_s < f64::INFINITY {
        v.push((
            Criterion::TimeToKeep1,
            format!("reaches {keep1} m within {} s", sig(c.max_time_to_keep1_s)),
        ));
    }
    if c.max_overshoot_m < f64::INFINITY {
        v.push((
            Criterion::Overshoot,
            format!("overshoot above {keep1} m ≤ {} m", sig(c.max_overshoot_m)),
        ));
    }
    if c.min_tension_n > f64::NEG_INFINITY {
        v.push((
            Criterion::MinTension,
            format!("tension ≥ {} N at every tick", sig(c.min_tension_n)),
        ));
    }
    if c.no_slack {
        v.push((
            Criterion::NoSlack,
            "the tether never goes slack".to_string(),
        ));
    }
    if c.max_final_error_m < f64::INFINITY {
        v.push((
            Criterion::FinalError,
            format!(
                "final length within {} m of {} m",
                sig(c.max_final_error_m),
                sig(sc.stage2.keep_length_m)
            ),
        ));
    }
    if c.no_safe_hold {
        v.push((Criterion::NoSafeHold, "never in safe hold".to_string()));
    }
    v
}

fn stats_row(o: &mut String, name: &str, s: Option<Stats>) {
    match s {
        Some(s) => {
            let _ = writeln!(
                o,
                "  {name:<28} {:>5} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12}",
                s.n,
                sig(s.mean),
                sig(s.std),
                sig(s.min),
                sig(s.p5),
                sig(s.p50),
                sig(s.p95),
                sig(s.max)
            );
        }
        None => {
            let _ = writeln!(o, "  {name:<28} {:>5}", 0);
        }
    }
}

/// The text of `summary.txt` (also printed on the terminal).
pub fn render(info: &CampaignInfo<'_>, records: &[RunRecord]) -> String {
    let sc = info.scenario;
    let mc: &MonteCarloSection = &sc.montecarlo;
    let mut o = String::new();
    let _ = writeln!(
        o,
        "Monte Carlo campaign on scenario `{}` (fingerprint {})",
        sc.name, info.fingerprint
    );
    let _ = writeln!(
        o,
        "  {} runs, seed {}: run i draws its inputs and sensor noise from (seed, i) only",
        info.runs, info.seed
    );
    if info.shard != Shard::WHOLE {
        let _ = writeln!(
            o,
            "  shard {}: the runs i with i mod {} = {} ({} of {})",
            info.shard,
            info.shard.count,
            info.shard.index - 1,
            records.len(),
            info.runs
        );
    }
    let _ = writeln!(
        o,
        "Dispersions ({}, drawn in this order):",
        mc.dispersion.len()
    );
    let nominal = super::campaign::Campaign::new(sc.clone(), info.seed, info.runs)
        .map(|c| c.nominal)
        .unwrap_or_default();
    for (i, d) in mc.dispersion.iter().enumerate() {
        let _ = writeln!(
            o,
            "  {:<28} {}",
            d.field,
            describe_dispersion(d, nominal.get(i).copied())
        );
    }
    let criteria = describe_criteria(sc);
    let _ = writeln!(o, "Criteria ({}):", criteria.len());
    if criteria.is_empty() {
        let _ = writeln!(o, "  none declared: a run passes if it completes");
    }
    for (c, text) in &criteria {
        let _ = writeln!(o, "  {:<16} {text}", c.name());
    }
    let n = records.len();
    let passed = records.iter().filter(|r| r.passed()).count();
    let rate = if n > 0 {
        100.0 * passed as f64 / n as f64
    } else {
        0.0
    };
    let _ = writeln!(o, "Result: {passed} of {n} runs pass ({rate:.1} %)");
    if let (Some(w), Some(cp)) = (
        wilson(passed as u64, n as u64),
        clopper_pearson(passed as u64, n as u64),
    ) {
        let _ = writeln!(
            o,
            "  pass rate, {:.0} % confidence: Wilson [{:.3}, {:.3}] %, Clopper–Pearson \
             [{:.3}, {:.3}] %",
            100.0 * CONFIDENCE,
            100.0 * w.low,
            100.0 * w.high,
            100.0 * cp.low,
            100.0 * cp.high
        );
    }
    let failed: Vec<&RunRecord> = records.iter().filter(|r| !r.passed()).collect();
    if !failed.is_empty() {
        let by: Vec<String> = Criterion::ALL
            .iter()
            .filter_map(|&c| {
                let k = failed.iter().filter(|r| r.failed.contains(&c)).count();
                (k > 0).then(|| format!("{} {k}", c.name()))
            })
            .collect();
        let _ = writeln!(
            o,
            "  failures by criterion (a run can fail several): {}",
            by.join(", ")
        );
        let shown: Vec<String> = failed
            .iter()
            .take(FAILED_RUNS_LISTED)
            .map(|r| {
                let names: Vec<&str> = r.failed.iter().map(|c| c.name()).collect();
                format!("{} [{}]", r.run, names.join(", "))
            })
            .collect();
        let _ = writeln!(
            o,
            "  failed runs ({} of {} listed): {}",
            shown.len(),
            failed.len(),
            shown.join(", ")
        );
        if let Some(r) = failed.iter().find(|r| !r.error.is_empty()) {
            let _ = writeln!(
                o,
                "  first run that did not complete: {}: {}",
                r.run, r.error
            );
        }
    }
    let health: Vec<String> = WorstHealth::ALL
        .iter()
        .map(|&h| {
            let k = records
                .iter()
                .filter(|r| r.outcome.as_ref().is_some_and(|o| o.worst_health == h))
                .count();
            format!("{} {k}", h.as_str())
        })
        .collect();
    let _ = writeln!(o, "  worst health (runs): {}", health.join(", "));
    let head = format!(
        "  {:<28} {:>5} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12}",
        "", "n", "mean", "std", "min", "p5", "p50", "p95", "max"
    );
    let _ = writeln!(o, "Outcomes (over the runs where defined):");
    let _ = writeln!(o, "{}", head.trim_end());
    for m in Metric::ALL {
        let s = Stats::of(
            records
                .iter()
                .filter_map(|r| r.outcome.as_ref().and_then(|o| o.get(m))),
        );
        stats_row(&mut o, m.name(), s);
    }
    if !mc.dispersion.is_empty() {
        let _ = writeln!(o, "Dispersed inputs:");
        let _ = writeln!(o, "{}", head.trim_end());
        for (i, d) in mc.dispersion.iter().enumerate() {
            stats_row(
                &mut o,
                &d.field,
                Stats::of(records.iter().map(|r| r.inputs[i])),
            );
        }
    }
    o
}

/// `summary.json`: what `summary.txt` says, for programs (a batch pipeline, a dashboard). Like
/// the text, it depends only on the campaign and its records, so a campaign flown whole and the
/// merge of its shards write the same bytes.
#[derive(Debug, serde::Serialize)]
pub struct SummaryJson<'a> {
    /// The scenario's name.
    pub scenario: &'a str,
    /// Its fingerprint.
    pub scenario_fingerprint: &'a str,
    /// The build that flew the runs.
    pub build: &'a str,
    /// The seed.
    pub seed: u64,
    /// Runs of the whole campaign.
    pub runs: u64,
    /// The shard, `K/N` (`1/1`: the whole campaign).
    pub shard: String,
    /// Runs in this summary (the shard's).
    pub flown: usize,
    /// Runs that passed every criterion.
    pub passed: usize,
    /// passed / flown (`null` if none was flown).
    pub pass_rate: Option<f64>,
    /// The confidence level of the intervals below.
    pub confidence: f64,
    /// Wilson's score interval on the pass rate.
    pub pass_rate_wilson: Option<Interval>,
    /// Clopper–Pearson's exact interval on the pass rate.
    pub pass_rate_clopper_pearson: Option<Interval>,
    /// Each declared criterion, its rule and how many runs fail it.
    pub criteria: Vec<CriterionJson>,
    /// Runs that did not complete.
    pub did_not_complete: usize,
    /// The failed runs' indices, in order.
    pub failed_runs: Vec<u64>,
    /// Runs by worst controller health.
    pub worst_health: BTreeMap<&'static str, usize>,
    /// Statistics of each outcome over the runs where it is defined (`null`: nowhere).
    pub outcomes: BTreeMap<&'static str, Option<Stats>>,
    /// Statistics of each dispersed input.
    pub inputs: BTreeMap<&'a str, Option<Stats>>,
    /// The estimator's consistency (`--consistency`), from 30 min on.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub consistency: Option<consistency::Summary>,
}

/// A criterion in `summary.json`.
#[derive(Debug, serde::Serialize)]
pub struct CriterionJson {
    /// Its name (`runs.csv`'s `failed` column).
    pub name: &'static str,
    /// What it requires.
    pub rule: String,
    /// Runs that fail it.
    pub failed: usize,
}

impl<'a> SummaryJson<'a> {
    /// The summary of `records` (sorted by run index) of the campaign `info`.
    pub fn of(
        info: &CampaignInfo<'a>,
        records: &[RunRecord],
        consistency: Option<consistency::Summary>,
    ) -> Self {
        let sc = info.scenario;
        let n = records.len();
        let passed = records.iter().filter(|r| r.passed()).count();
        let failing = |c: Criterion| records.iter().filter(|r| r.failed.contains(&c)).count();
        let stats_of = |m: Metric| {
            Stats::of(
                records
                    .iter()
                    .filter_map(|r| r.outcome.as_ref().and_then(|o| o.get(m))),
            )
        };
        Self {
            scenario: &sc.name,
            scenario_fingerprint: info.fingerprint,
            build: info.build,
            seed: info.seed,
            runs: info.runs,
            shard: info.shard.to_string(),
            flown: n,
            passed,
            pass_rate: (n > 0).then(|| passed as f64 / n as f64),
            confidence: CONFIDENCE,
            pass_rate_wilson: wilson(passed as u64, n as u64),
            pass_rate_clopper_pearson: clopper_pearson(passed as u64, n as u64),
            criteria: describe_criteria(sc)
                .into_iter()
                .map(|(c, rule)| CriterionJson {
                    name: c.name(),
                    rule,
                    failed: failing(c),
                })
                .collect(),
            did_not_complete: failing(Criterion::Completed),
            failed_runs: records
                .iter()
                .filter(|r| !r.passed())
                .map(|r| r.run)
                .collect(),
            worst_health: WorstHealth::ALL
                .iter()
                .map(|&h| {
                    let k = records
                        .iter()
                        .filter(|r| r.outcome.as_ref().is_some_and(|o| o.worst_health == h))
                        .count();
                    (h.as_str(), k)
                })
                .collect(),
            outcomes: Metric::ALL
                .iter()
                .map(|&m| (m.name(), stats_of(m)))
                .collect(),
            inputs: sc
                .montecarlo
                .dispersion
                .iter()
                .enumerate()
                .map(|(i, d)| {
                    (
                        d.field.as_str(),
                        Stats::of(records.iter().map(|r| r.inputs[i])),
                    )
                })
                .collect(),
            consistency,
        }
    }

    /// The JSON text, pretty-printed, with a final newline.
    pub fn render(&self) -> serde_json::Result<String> {
        let mut text = serde_json::to_string_pretty(self)?;
        text.push('\n');
        Ok(text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_a_small_sample() {
        let s = Stats::of([4.0, 1.0, f64::NAN, 3.0, 2.0, f64::INFINITY].into_iter()).unwrap();
        assert_eq!(s.n, 4);
        assert_eq!((s.min, s.max, s.mean), (1.0, 4.0, 2.5));
        assert!((s.std - (5.0f64 / 3.0).sqrt()).abs() < 1e-15);
        assert_eq!(s.p50, 2.5);
        assert!((s.p5 - 1.15).abs() < 1e-12 && (s.p95 - 3.85).abs() < 1e-12);
        assert_eq!(Stats::of([f64::NAN].into_iter()), None);
    }

    #[test]
    fn significant_digits() {
        assert_eq!(sig(11_802.345_678), "11802.3");
        assert_eq!(sig(0.049_012_3), "0.0490123");
        assert_eq!(sig(3.3e-5), "3.3e-5");
        assert_eq!(sig(-2.0e-4), "-2e-4");
        assert_eq!(sig(1.234567e-7), "1.23457e-7");
        assert_eq!(sig(2.0), "2");
        assert_eq!(sig(-1308.6591), "-1308.66");
        assert_eq!(sig(1.0e7), "1e7");
    }
}
