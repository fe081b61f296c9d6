//! One campaign: the dispersed scenario of each run, the run, its outcomes and its verdict.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;

use rayon::prelude::*;

use tss_reel::controller::{Controller, Flags};

use super::consistency::{ConsistencySums, RunConsistency, Watched};
use crate::faults::Pcg32;
use crate::history::History;
use crate::report::summarize;
use crate::scenario::{nominal_in, Distribution, MonteCarloSection, Scenario};
use crate::table1::probe_times_for;
use crate::table1::Table1Comparison;

/// Stream of [`run_seed`] that seeds a run's dispersion draws.
pub const DISPERSION_STREAM: u64 = 0;
/// Stream of [`run_seed`] that becomes a run's `sensors.seed` (the fault injection's noise).
pub const SENSOR_STREAM: u64 = 1;

/// SplitMix64's output function (Steele, Lea & Flood, "Fast splittable pseudorandom number
/// generators", OOPSLA 2014): a bijection of u64 that scrambles every input bit.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The seed of stream `stream` of run `index` of a campaign seeded with `seed`: a function of
/// these three numbers only (distinct runs get distinct seeds), so a run is the same whatever
/// thread, shard or machine flies it.
///
/// ```
/// use tss_sim::montecarlo::{run_seed, DISPERSION_STREAM, SENSOR_STREAM};
/// assert_eq!(run_seed(42, 7, SENSOR_STREAM), run_seed(42, 7, SENSOR_STREAM));
/// assert_ne!(run_seed(42, 7, SENSOR_STREAM), run_seed(42, 8, SENSOR_STREAM));
/// assert_ne!(run_seed(42, 7, SENSOR_STREAM), run_seed(42, 7, DISPERSION_STREAM));
/// ```
pub fn run_seed(seed: u64, index: u64, stream: u64) -> u64 {
    splitmix64(splitmix64(splitmix64(seed) ^ index) ^ stream)
}

/// An outcome of a run, a column of `runs.csv`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Metric {
    /// First time l ≥ stage1.keep_length_m − 0.5 m, s (interpolated between samples).
    TimeToKeep1,
    /// Largest stage-1 length above stage1.keep_length_m, m (sampled; not defined if the keep
    /// length is never reached).
    Overshoot,
    /// Max |l − stage1.keep_length_m| over the criteria's keep window (7–8 h), m (sampled).
    Keep1Error,
    /// Max |simulated − paper| over the paper's Table 1, stage 1 (7–8 h), m.
    Table1Stage1,
    /// Max |simulated − paper| over the paper's Table 1, stage 2 (14–15 h), m.
    Table1Stage2,
    /// Smallest tether tension over every control tick, N.
    MinTension,
    /// Times the tether went slack (tension ≤ 0).
    SlackEvents,
    /// Time slack, s.
    Slack,
    /// Length at the end of the run, m.
    FinalLength,
    /// |final length − stage2.keep_length_m|, m.
    FinalError,
    /// Distinct faults the controller reported.
    Faults,
    /// Control ticks with a fault reported.
    FaultTicks,
    /// Time in safe hold, s.
    SafeHold,
    /// Largest |α the law flew − true α| from [`SETTLED_S`] on, rad (sampled, at the steps the
    /// law ran: not while the controller coasts or holds): the estimate's error on the
    /// estimator, the sensor's on the α̇ sensor (α_r + δ of the output).
    AlphaError,
}

/// The law's α error counts from here, s: 30 min, after the release transient and the
/// estimator's prior.
pub const SETTLED_S: f64 = 1_800.0;

impl Metric {
    /// Every metric, in `runs.csv` column order.
    pub const ALL: [Metric; 14] = [
        Metric::TimeToKeep1,
        Metric::Overshoot,
        Metric::Keep1Error,
        Metric::Table1Stage1,
        Metric::Table1Stage2,
        Metric::MinTension,
        Metric::SlackEvents,
        Metric::Slack,
        Metric::FinalLength,
        Metric::FinalError,
        Metric::Faults,
        Metric::FaultTicks,
        Metric::SafeHold,
        Metric::AlphaError,
    ];

    /// The column name in `runs.csv`.
    pub fn name(self) -> &'static str {
        match self {
            Metric::TimeToKeep1 => "time_to_keep1_s",
            Metric::Overshoot => "overshoot_m",
            Metric::Keep1Error => "keep1_max_error_m",
            Metric::Table1Stage1 => "table1_stage1_max_error_m",
            Metric::Table1Stage2 => "table1_stage2_max_error_m",
            Metric::MinTension => "min_tension_n",
            Metric::SlackEvents => "slack_events",
            Metric::Slack => "slack_s",
            Metric::FinalLength => "final_length_m",
            Metric::FinalError => "final_error_m",
            Metric::Faults => "faults",
            Metric::FaultTicks => "fault_ticks",
            Metric::SafeHold => "safe_hold_s",
            Metric::AlphaError => "alpha_error_rad",
        }
    }

    /// What it is, for figure captions and the summary.
    pub fn label(self) -> &'static str {
        match self {
            Metric::TimeToKeep1 => "time to reach the stage-1 keep length (s)",
            Metric::Overshoot => "stage-1 overshoot above the keep length (m)",
            Metric::Keep1Error => "max |l − keep length| in the keep window (m)",
            Metric::Table1Stage1 => "Table 1 stage 1: max |sim − paper| (m)",
            Metric::Table1Stage2 => "Table 1 stage 2: max |sim − paper| (m)",
            Metric::MinTension => "minimum tension (N)",
            Metric::SlackEvents => "slack events",
            Metric::Slack => "time slack (s)",
            Metric::FinalLength => "final length (m)",
            Metric::FinalError => "|final length − stage-2 keep length| (m)",
            Metric::Faults => "distinct faults raised",
            Metric::FaultTicks => "ticks with a fault",
            Metric::SafeHold => "time in safe hold (s)",
            Metric::AlphaError => "max |α flown − α| after 30 min (rad)",
        }
    }
}

/// The worst controller health of a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum WorstHealth {
    /// Nominal throughout.
    Nominal,
    /// Degraded (coasting) at some tick, never in safe hold.
    Degraded,
    /// In safe hold at some tick.
    SafeHold,
}

impl WorstHealth {
    /// Every level, best first.
    pub const ALL: [WorstHealth; 3] = [Self::Nominal, Self::Degraded, Self::SafeHold];

    /// The name in `runs.csv`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Nominal => "nominal",
            Self::Degraded => "degraded",
            Self::SafeHold => "safe_hold",
        }
    }

    /// The level named `s`.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|h| h.as_str() == s)
    }
}

/// A pass/fail criterion of `[montecarlo.criteria]`, or the failure to complete a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Criterion {
    /// The run did not complete (an invalid dispersed scenario, or the plant diverged).
    Completed,
    /// `max_keep1_error_m`.
    Keep1Error,
    /// `max_time_to_keep1_s`.
    TimeToKeep1,
    /// `max_overshoot_m`.
    Overshoot,
    /// `min_tension_n`.
    MinTension,
    /// `no_slack`.
    NoSlack,
    /// `max_final_error_m`.
    FinalError,
    /// `no_safe_hold`.
    NoSafeHold,
}

impl Criterion {
    /// Every criterion, in the order `runs.csv` lists failures.
    pub const ALL: [Criterion; 8] = [
        Criterion::Completed,
        Criterion::Keep1Error,
        Criterion::TimeToKeep1,
        Criterion::Overshoot,
        Criterion::MinTension,
        Criterion::NoSlack,
        Criterion::FinalError,
        Criterion::NoSafeHold,
    ];

    /// The name in `runs.csv`'s `failed` column.
    pub fn name(self) -> &'static str {
        match self {
            Criterion::Completed => "did_not_complete",
            Criterion::Keep1Error => "keep1_error",
            Criterion::TimeToKeep1 => "time_to_keep1",
            Criterion::Overshoot => "overshoot",
            Criterion::MinTension => "min_tension",
            Criterion::NoSlack => "slack",
            Criterion::FinalError => "final_error",
            Criterion::NoSafeHold => "safe_hold",
        }
    }

    /// The criterion named `s`.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == s)
    }
}

/// The outcomes of a completed run.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// One value per [`Metric::ALL`] entry (`None`: not defined for this run, e.g. the keep
    /// length was never reached or the run ended before the keep window).
    pub values: [Option<f64>; Metric::ALL.len()],
    /// The worst health the controller was in.
    pub worst_health: WorstHealth,
}

impl Outcome {
    /// The value of `m`.
    pub fn get(&self, m: Metric) -> Option<f64> {
        self.values[m as usize]
    }

    /// The outcomes of a run of `sc` (a history of `sim::run` with `probe_times_for(sc)`).
    pub fn of(sc: &Scenario, h: &History) -> Self {
        let s = summarize(sc, h);
        let keep1 = sc.stage1.keep_length_m;
        let crit = &sc.montecarlo.criteria;
        let keep1_error = h
            .samples
            .iter()
            .filter(|x| x.t_s >= crit.keep1_from_s && x.t_s <= crit.keep1_until_s)
            .map(|x| (x.length_m - keep1).abs())
            .fold(None, |m: Option<f64>, e| {
                // NaN, once met, is the worst error.
                Some(match m {
                    Some(m) if m.is_nan() || m >= e => m,
                    _ => e,
                })
            });
        let table = Table1Comparison::new(&h.probes);
        let table1 = |stage| {
            table
                .max_abs_difference(stage)
                .map(|d| d.difference_m.abs())
        };
        let f = &h.faults;
        let final_length = h.samples.last().map(|x| x.length_m);
        let mut values = [None; Metric::ALL.len()];
        let mut set = |m: Metric, v: Option<f64>| values[m as usize] = v;
        let reached = s.landmarks.get(1).and_then(|l| l.t_s);
        set(Metric::TimeToKeep1, reached);
        // An overshoot only once the keep length was reached.
        set(
            Metric::Overshoot,
            s.stage1_max
                .filter(|_| reached.is_some())
                .map(|(l, _)| l - keep1),
        );
        set(Metric::Keep1Error, keep1_error);
        set(Metric::Table1Stage1, table1(1));
        set(Metric::Table1Stage2, table1(2));
        // Tension and slack from the point the tether must be taut on
        // (`simulation.taut_from_length_m`; from the start by default).
        let taut = &f.taut;
        set(
            Metric::MinTension,
            taut.from_s.map(|_| taut.min_tension_n.0),
        );
        set(Metric::SlackEvents, Some(f64::from(taut.slack_events)));
        set(Metric::Slack, Some(taut.slack_s));
        set(Metric::FinalLength, final_length);
        set(
            Metric::FinalError,
            final_length.map(|l| (l - sc.stage2.keep_length_m).abs()),
        );
        set(Metric::Faults, Some(f.faults.len() as f64));
        set(
            Metric::FaultTicks,
            Some(f.faults.iter().map(|t| u64::from(t.ticks)).sum::<u64>() as f64),
        );
        set(Metric::SafeHold, Some(f.safe_hold_s));
        let alpha_error = h
            .samples
            .iter()
            .filter(|x| x.t_s >= SETTLED_S && x.flags & Flags::SAFE_ACTION == 0)
            .map(|x| (x.alpha_ref_rad + x.delta_rad - x.alpha_rad).abs())
            .fold(None, |m: Option<f64>, e| {
                Some(match m {
                    Some(m) if m.is_nan() || m >= e => m,
                    _ => e,
                })
            });
        set(Metric::AlphaError, alpha_error);
        let worst_health = if f.safe_hold_s > 0.0 {
            WorstHealth::SafeHold
        } else if f.degraded_s > 0.0 {
            WorstHealth::Degraded
        } else {
            WorstHealth::Nominal
        };
        Self {
            values,
            worst_health,
        }
    }

    /// The criteria of `sc.montecarlo.criteria` this outcome fails, in [`Criterion::ALL`]
    /// order. A value that is not defined (`None`) or NaN fails the criterion on it.
    pub fn failed(&self, mc: &MonteCarloSection) -> Vec<Criterion> {
        let c = &mc.criteria;
        let at_most = |m: Metric, limit: f64| -> bool {
            limit == f64::INFINITY || self.get(m).is_some_and(|v| v <= limit)
        };
        let mut failed = Vec::new();
        let checks = [
            (
                Criterion::Keep1Error,
                at_most(Metric::Keep1Error, c.max_keep1_error_m),
            ),
            (
                Criterion::TimeToKeep1,
                at_most(Metric::TimeToKeep1, c.max_time_to_keep1_s),
            ),
            (
                Criterion::Overshoot,
                at_most(Metric::Overshoot, c.max_overshoot_m),
            ),
            (
                Criterion::MinTension,
                c.min_tension_n == f64::NEG_INFINITY
                    || self
                        .get(Metric::MinTension)
                        .is_some_and(|v| v >= c.min_tension_n),
            ),
            (
                Criterion::NoSlack,
                !c.no_slack || self.get(Metric::SlackEvents) == Some(0.0),
            ),
            (
                Criterion::FinalError,
                at_most(Metric::FinalError, c.max_final_error_m),
            ),
            (
                Criterion::NoSafeHold,
                !c.no_safe_hold || self.worst_health != WorstHealth::SafeHold,
            ),
        ];
        for (criterion, ok) in checks {
            if !ok {
                failed.push(criterion);
            }
        }
        failed
    }
}

/// One run of a campaign: what was drawn, what happened, the verdict.
#[derive(Clone, Debug, PartialEq)]
pub struct RunRecord {
    /// Run index, 0-based.
    pub run: u64,
    /// The run's `sensors.seed` (`run_seed(seed, run, SENSOR_STREAM)`).
    pub sensor_seed: u64,
    /// The dispersed values, one per `[[montecarlo.dispersion]]`, in declaration order.
    pub inputs: Vec<f64>,
    /// The outcomes (`None`: the run did not complete; see `error`).
    pub outcome: Option<Outcome>,
    /// The criteria failed, in [`Criterion::ALL`] order (empty: the run passes).
    pub failed: Vec<Criterion>,
    /// Why the run did not complete (empty if it did).
    pub error: String,
}

impl RunRecord {
    /// Did the run pass every criterion?
    pub fn passed(&self) -> bool {
        self.failed.is_empty()
    }
}

/// A campaign: the resolved scenario, its seed and size.
#[derive(Clone, Debug)]
pub struct Campaign {
    /// The scenario as loaded (file and `--set`), with its `[montecarlo]` section.
    pub scenario: Scenario,
    /// The campaign's seed.
    pub seed: u64,
    /// Number of runs of the whole campaign.
    pub runs: u64,
    /// The nominal value of each dispersed field.
    pub nominal: Vec<f64>,
    /// The scenario without `[montecarlo]`, as a TOML table: each run's starting point.
    base: toml::Table,
}

impl Campaign {
    /// The campaign of `scenario` (valid, as `Scenario::load` returns it).
    pub fn new(scenario: Scenario, seed: u64, runs: u64) -> anyhow::Result<Self> {
        let mut bare = scenario.clone();
        bare.montecarlo = MonteCarloSection::default();
        let base = toml::Table::try_from(&bare)?;
        let nominal = scenario
            .montecarlo
            .dispersion
            .iter()
            .map(|d| {
                nominal_in(&base, &d.field)
                    .ok_or_else(|| anyhow::anyhow!("{} is not a number field", d.field))
            })
            .collect::<anyhow::Result<Vec<f64>>>()?;
        Ok(Self {
            scenario,
            seed,
            runs,
            nominal,
            base,
        })
    }

    /// The dotted fields dispersed, in order.
    pub fn fields(&self) -> Vec<&str> {
        self.scenario
            .montecarlo
            .dispersion
            .iter()
            .map(|d| d.field.as_str())
            .collect()
    }

    /// The values run `index` draws, one per dispersion.
    pub fn draw(&self, index: u64) -> Vec<f64> {
        let mut rng = Pcg32::new(run_seed(self.seed, index, DISPERSION_STREAM), 0);
        self.scenario
            .montecarlo
            .dispersion
            .iter()
            .zip(&self.nominal)
            .map(|(d, &nominal)| {
                let x = match d.distribution {
                    Distribution::Normal => {
                        let mean = d.mean.unwrap_or(if d.relative { 0.0 } else { nominal });
                        mean + d.std.unwrap_or(0.0) * rng.normal()
                    }
                    Distribution::Uniform => {
                        let (lo, hi) = (d.min.unwrap_or(0.0), d.max.unwrap_or(0.0));
                        lo + (hi - lo) * rng.uniform_open()
                    }
                };
                if d.relative {
                    nominal * (1.0 + x)
                } else {
                    x
                }
            })
            .collect()
    }

    /// The scenario of run `index` with the values `inputs` set (as [`Campaign::draw`] gives
    /// them), its `sensors.seed` from [`run_seed`], and no `[montecarlo]` section; or every
    /// rule the dispersed values break.
    pub fn scenario_for(&self, index: u64, inputs: &[f64]) -> Result<Scenario, String> {
        let mut table = self.base.clone();
        for (field, &value) in self.fields().iter().zip(inputs) {
            set_dotted(&mut table, field, value);
        }
        let mut sc: Scenario = toml::Value::Table(table)
            .try_into()
            .map_err(|e: toml::de::Error| e.message().to_string())?;
        sc.sensors.seed = run_seed(self.seed, index, SENSOR_STREAM);
        let problems = sc.problems();
        if problems.is_empty() {
            Ok(sc)
        } else {
            let lines: Vec<String> = problems.iter().map(ToString::to_string).collect();
            Err(format!("invalid dispersed scenario: {}", lines.join("; ")))
        }
    }

    /// Flies run `index` and judges it.
    pub fn run(&self, index: u64) -> RunRecord {
        self.fly(index, false).0
    }

    /// Flies run `index` and judges it; with `watch`, the flight filter flies beside the
    /// controller and the run's NEES and NIS come back too (`None` if the run did not
    /// complete).
    pub fn fly(&self, index: u64, watch: bool) -> (RunRecord, Option<RunConsistency>) {
        let inputs = self.draw(index);
        let sensor_seed = run_seed(self.seed, index, SENSOR_STREAM);
        let mut consistency = None;
        let result = self.scenario_for(index, &inputs).and_then(|sc| {
            let probes = probe_times_for(&sc);
            let history = if watch {
                let mut ctl = crate::sim::controller_config::<f32>(&sc)
                    .and_then(|c| Controller::new(c).map_err(crate::sim::SimError::Config))
                    .map_err(|e| e.to_string())?;
                let mut watched = Watched::new(&sc, &mut ctl).map_err(|e| e.to_string())?;
                let h = crate::sim::run_stepper(&sc, &mut watched, &probes, &mut |_| {});
                if let Ok(h) = &h {
                    consistency = Some(watched.finish(h, sc.controller.period_s));
                }
                h
            } else {
                crate::sim::run(&sc, &probes, &mut |_| {})
            };
            history
                .map(|h| Outcome::of(&sc, &h))
                .map_err(|e| e.to_string())
        });
        let (outcome, failed, error) = match result {
            Ok(o) => {
                let failed = o.failed(&self.scenario.montecarlo);
                (Some(o), failed, String::new())
            }
            Err(e) => (None, vec![Criterion::Completed], e),
        };
        let record = RunRecord {
            run: index,
            sensor_seed,
            inputs,
            outcome,
            failed,
            error,
        };
        (record, consistency)
    }

    /// Flies the runs `indices` on `threads` threads (0: one per core), calling `done` after
    /// each; the records come back sorted by run index whatever the thread count.
    pub fn run_all(
        &self,
        indices: &[u64],
        threads: usize,
        done: &(dyn Fn() + Sync),
    ) -> anyhow::Result<Vec<RunRecord>> {
        Ok(self.run_all_watched(indices, threads, false, done)?.0)
    }

    /// [`Campaign::run_all`], with `watch` the estimator's consistency summed over the runs
    /// (exactly, so the sums do not depend on the thread count).
    pub fn run_all_watched(
        &self,
        indices: &[u64],
        threads: usize,
        watch: bool,
        done: &(dyn Fn() + Sync),
    ) -> anyhow::Result<(Vec<RunRecord>, Option<ConsistencySums>)> {
        let mut records = Vec::with_capacity(indices.len());
        let mut sums = watch.then(ConsistencySums::default);
        self.fly_each(indices, threads, watch, &mut |record, consistency| {
            if let (Some(sums), Some(c)) = (&mut sums, &consistency) {
                sums.add(c);
            }
            records.push(record);
            done();
            Ok(())
        })?;
        records.sort_by_key(|r| r.run);
        Ok((records, sums))
    }

    /// Flies the runs `indices` on `threads` threads (0: one per core) and hands each run to
    /// `finished` on the calling thread as soon as it is flown, in the order they finish (with
    /// `watch`, its NEES and NIS too). An error from `finished` stops the campaign: the runs
    /// under way finish, no other starts, and the error is returned.
    pub fn fly_each(
        &self,
        indices: &[u64],
        threads: usize,
        watch: bool,
        finished: &mut dyn FnMut(RunRecord, Option<RunConsistency>) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| anyhow::anyhow!("cannot start {threads} threads: {e}"))?;
        let stop = AtomicBool::new(false);
        let (tx, rx) = mpsc::channel();
        std::thread::scope(|scope| {
            let flying = scope.spawn(|| {
                pool.install(|| {
                    indices.par_iter().for_each_with(tx, |tx, &i| {
                        if stop.load(Ordering::Relaxed) {
                            return;
                        }
                        if tx.send(self.fly(i, watch)).is_err() {
                            stop.store(true, Ordering::Relaxed);
                        }
                    })
                })
            });
            let mut outcome = Ok(());
            for (record, consistency) in rx.iter() {
                outcome = finished(record, consistency);
                if outcome.is_err() {
                    stop.store(true, Ordering::Relaxed);
                    break;
                }
            }
            drop(rx);
            if let Err(panic) = flying.join() {
                std::panic::resume_unwind(panic);
            }
            outcome
        })
    }
}

/// Sets the number at dotted `key` of a complete scenario table (every section present).
fn set_dotted(table: &mut toml::Table, key: &str, value: f64) {
    let mut parts: Vec<&str> = key.split('.').collect();
    let Some(last) = parts.pop() else {
        return;
    };
    let mut cursor = table;
    for part in parts {
        let entry = cursor
            .entry(part.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        match entry {
            toml::Value::Table(t) => cursor = t,
            _ => return,
        }
    }
    cursor.insert(last.to_string(), toml::Value::Float(value));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix64_matches_the_reference() {
        // splitmix64.c (Vigna), seeded with 0: the first outputs are the function applied to
        // 0, γ, 2γ, … minus the added γ, i.e. splitmix64(0), splitmix64(γ), …
        assert_eq!(splitmix64(0), 0xE220_A839_7B1D_CDAF);
        assert_eq!(splitmix64(0x9E37_79B9_7F4A_7C15), 0x6E78_9E6A_A1B9_65F4);
    }

    #[test]
    fn run_seeds_are_distinct_over_runs_and_streams() {
        let mut seen = std::collections::BTreeSet::new();
        for i in 0..10_000 {
            for stream in [DISPERSION_STREAM, SENSOR_STREAM] {
                assert!(seen.insert(run_seed(1, i, stream)));
            }
        }
        assert_ne!(run_seed(1, 0, 0), run_seed(2, 0, 0));
    }

    #[test]
    fn names_round_trip() {
        for c in Criterion::ALL {
            assert_eq!(Criterion::parse(c.name()), Some(c));
        }
        for h in WorstHealth::ALL {
            assert_eq!(WorstHealth::parse(h.as_str()), Some(h));
        }
        for (i, m) in Metric::ALL.iter().enumerate() {
            assert_eq!(*m as usize, i);
        }
    }
}
