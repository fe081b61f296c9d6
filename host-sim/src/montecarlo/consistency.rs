//! The libration estimator's consistency over a campaign: NEES and NIS averaged over
//! the runs, against their χ² bounds (`tss-sim montecarlo --consistency`).
//!
//! A filter is consistent when its errors are as large as its covariance says (Bar-Shalom, Li &
//! Kirubarajan, *Estimation with Applications to Tracking and Navigation*, 2001, §5.4):
//!
//! - NEES ε = eᵀ P⁻¹ e of the error e = (α̂ − α, α̇̂ − α̇) against the plant's truth, with P the
//!   filter's 2×2 covariance of (α̂, α̇̂): χ² with 2 degrees of freedom (d, the filter's third
//!   state, has no truth to compare with);
//! - NIS ν²/S of each α sample's innovation: χ² with 1 degree of freedom.
//!
//! Averaged over N independent runs at one instant, N·ε̄ is χ² with 2N degrees of freedom, so
//! ε̄ lies in [χ²₂ₙ(0.025), χ²₂ₙ(0.975)]/N with probability 0.95 (the two-sided 95 % band);
//! likewise the NIS with N degrees of freedom. [`ConsistencySums`] accumulates both at every
//! [`EVERY_S`] of mission time; the report gives the fraction of instants inside the band and
//! the averages over time from [`SETTLED_S`] on (after the release transient and the prior).
//!
//! The filter watched ([`Watched`]) is the controller's own when it flies on the estimator
//! (`Controller::estimate`, `Output::nis`: the filter in the loop, on what the controller
//! reads). A controller flying the α̇ sensor has none; then the flight filter,
//! `tss_reel::estimator::Estimator` in f32 tuned by `Scenario::estimator_config`, runs beside
//! it on the same readings: the swing sensor's α (its noise, bias, quantum, latency and
//! dropouts) and the drive over each period (the length the controller estimates, the
//! encoder's rate, else the rate command held, and the orbit's rate, circular).

use std::fmt::Write as _;
use std::io::{self, Write};

use plotters::coord::Shift;
use plotters::prelude::*;

use tss_reel::controller::{Controller, Input, Output, RateSource};
use tss_reel::estimator::{ConfigError, Drive, Estimate, Estimator, Measurement, OrbitTerms};
use tss_reel::mass::MassModel;
use tss_reel::Real;

use super::exact_sum::ExactSum;
use crate::history::History;
use crate::plots::{draw_error as err, tick_label, Figure, FONT};
use crate::scenario::Scenario;
use crate::sim::{SimError, Stepper};

/// The mission time between two consistency instants, s.
pub const EVERY_S: f64 = 60.0;

/// The averages over time start here, s: 30 min, once the release transient and the filter's
/// prior are forgotten.
pub const SETTLED_S: f64 = 1_800.0;

/// Degrees of freedom of the NEES (α, α̇).
pub const NEES_DOF: f64 = 2.0;
/// Degrees of freedom of the NIS (α).
pub const NIS_DOF: f64 = 1.0;

/// The standard-normal quantile of 0.975 (the two-sided 95 % band).
pub const Z_975: f64 = 1.959_963_984_540_054;

/// The χ² quantile of `dof` degrees of freedom at the standard-normal quantile `z`
/// (Wilson & Hilferty 1931: within 0.1 % of the exact quantile for dof ≥ 50, 1 % for dof ≥ 10).
pub fn chi2_quantile(dof: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * dof);
    dof * (1.0 - a + z * a.sqrt()).powi(3).max(0.0)
}

/// The two-sided 95 % band of the mean of `n` independent χ² values of `dof` degrees of
/// freedom.
pub fn band(dof: f64, n: u64) -> (f64, f64) {
    let n = n.max(1) as f64;
    (
        chi2_quantile(dof * n, -Z_975) / n,
        chi2_quantile(dof * n, Z_975) / n,
    )
}

/// The NEES of `e` over (α, α̇): eᵀ P⁻¹ e with P its 2×2 covariance (`None` if P is not
/// positive definite).
pub fn nees<T: Real>(e: &Estimate<T>, alpha_rad: f64, alpha_rate_radps: f64) -> Option<f64> {
    let (ea, er) = (
        e.alpha_rad.to_f64() - alpha_rad,
        e.alpha_rate_radps.to_f64() - alpha_rate_radps,
    );
    let (paa, prr, par) = (
        e.alpha_var_rad2.to_f64(),
        e.alpha_rate_var_rad2ps2.to_f64(),
        e.alpha_rate_cov_rad2ps.to_f64(),
    );
    let det = paa * prr - par * par;
    (paa > 0.0 && det > 0.0).then(|| (prr * ea * ea - 2.0 * par * ea * er + paa * er * er) / det)
}

/// The NEES of `e` over α̇ alone: (α̇̂ − α̇)²/P_α̇α̇ (`None` if the variance is not positive).
/// An α-sensor bias, which no filter on α alone can tell from α (see `tss_reel::estimator`,
/// *Observability*), leaves it χ²(1): it judges the rate the law flies on.
pub fn rate_nees<T: Real>(e: &Estimate<T>, alpha_rate_radps: f64) -> Option<f64> {
    let er = e.alpha_rate_radps.to_f64() - alpha_rate_radps;
    let prr = e.alpha_rate_var_rad2ps2.to_f64();
    (prr > 0.0).then(|| er * er / prr)
}

/// What the watched filter gave at one consistency instant.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Seen {
    tick: u32,
    estimate: Option<Estimate<f32>>,
    nis: Option<f64>,
}

/// The flight filter run beside a controller that flies the α̇ sensor, on the same readings.
struct Shadow {
    filter: Estimator<f32>,
    masses: MassModel<f32>,
    /// (length estimate at the start of the period, rate command held over it) of the last
    /// step.
    last: Option<(f32, f32)>,
}

impl Shadow {
    /// The drive of the period that ended at this sample: the controller's length estimate at
    /// its start, the encoder's rate over it (else the rate command held), the orbit's rate
    /// (circular: θ̈ = 0, μ/R³ = θ̇²). The first sample starts the filter with the drive of its
    /// own instant.
    fn drive(&self, x: &Input<f32>) -> Drive<f32> {
        let n = x.orbit_rate_radps;
        let (length_m, rate_mps, mu3) = match self.last {
            Some((l, cmd)) => (
                l,
                x.reel_rate_mps.unwrap_or(cmd),
                self.masses.mu3_and_slope(l).0,
            ),
            None => (x.length_m, 0.0, 0.0),
        };
        Drive {
            length_m,
            rate_mps,
            accel_mps2: 0.0,
            orbit: OrbitTerms::circular(n).expect("the monitor accepted θ̇ in range"),
            mu3,
        }
    }
}

/// The controller in the loop ([`Stepper`]), its estimate and NIS kept at every [`EVERY_S`]:
/// its own filter's when it flies on the estimator (`Controller::estimate`, `Output::nis`),
/// else those of the flight filter run beside it on the same readings (tuned by
/// `Scenario::estimator_config`).
pub struct Watched<'a> {
    ctl: &'a mut Controller<f32>,
    shadow: Option<Shadow>,
    every_ticks: u32,
    seen: Vec<Seen>,
}

impl<'a> Watched<'a> {
    /// Watches `ctl` flying `sc`.
    pub fn new(sc: &Scenario, ctl: &'a mut Controller<f32>) -> Result<Self, ConfigError> {
        let shadow = match ctl.config().rate_source {
            RateSource::Estimator(_) => None,
            RateSource::Sensor => Some(Shadow {
                filter: Estimator::new(sc.estimator_config::<f32>())?,
                masses: ctl.config().masses,
                last: None,
            }),
        };
        let every_ticks = (EVERY_S / sc.controller.period_s).round().max(1.0) as u32;
        Ok(Self {
            ctl,
            shadow,
            every_ticks,
            seen: Vec::new(),
        })
    }

    /// The consistency of the run, judged on its `history` (the plant's truth).
    pub fn finish(self, history: &History, period_s: f64) -> RunConsistency {
        let slots = self
            .seen
            .iter()
            .map(|s| s.tick / self.every_ticks + 1)
            .max();
        let slots = slots.unwrap_or(0) as usize;
        let mut run = RunConsistency {
            nees: vec![None; slots],
            rate_nees: vec![None; slots],
            nis: vec![None; slots],
        };
        // The history's samples every output interval; the instants are whole minutes.
        let truth_at = |tick: u32| {
            let t_s = f64::from(tick) * period_s;
            history
                .samples
                .binary_search_by(|x| x.t_s.total_cmp(&t_s))
                .ok()
                .map(|i| &history.samples[i])
        };
        for s in &self.seen {
            let slot = (s.tick / self.every_ticks) as usize;
            if let (Some(e), Some(x)) = (s.estimate, truth_at(s.tick)) {
                run.nees[slot] = nees(&e, x.alpha_rad, x.alpha_rate_radps);
                run.rate_nees[slot] = rate_nees(&e, x.alpha_rate_radps);
            }
            run.nis[slot] = s.nis;
        }
        run
    }
}

impl Stepper<f32> for Watched<'_> {
    fn step(&mut self, tick: u32, input: Option<&Input<f32>>) -> Result<Output<f32>, SimError> {
        // The shadow filter sees what the controller sees: a missing sample, or this one.
        let shadow = match (&mut self.shadow, input) {
            (Some(s), Some(x)) => {
                let d = s.drive(x);
                Some(s.filter.step(&d, x.alpha_rad))
            }
            _ => None,
        };
        let out = Stepper::step(&mut *self.ctl, tick, input)?;
        if let Some(s) = &mut self.shadow {
            s.last = Some((out.length_estimate_m, out.rate_cmd_mps));
        }
        if tick.is_multiple_of(self.every_ticks) {
            let seen = match &self.shadow {
                Some(_) => Seen {
                    tick,
                    estimate: shadow.and_then(|s| s.estimate),
                    nis: shadow.and_then(|s| match s.measurement {
                        Measurement::Accepted(i) | Measurement::Gated(i) => Some(f64::from(i.nis)),
                        _ => None,
                    }),
                },
                None => Seen {
                    tick,
                    estimate: self.ctl.estimate(),
                    nis: out.nis.map(f64::from),
                },
            };
            self.seen.push(seen);
        }
        Ok(out)
    }
}

/// One run's NEES and NIS at each instant k·[`EVERY_S`] (`None`: no estimate, no sample, or
/// the run ended before).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunConsistency {
    /// NEES (2 dof) per instant.
    pub nees: Vec<Option<f64>>,
    /// NEES of α̇ alone (1 dof) per instant.
    pub rate_nees: Vec<Option<f64>>,
    /// NIS (1 dof) per instant.
    pub nis: Vec<Option<f64>>,
}

/// One statistic at one instant, summed over the runs that gave a value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InstantSum {
    /// Σ of the values, exact: the same whatever the order the runs are added in.
    pub sum: ExactSum,
    /// Runs that gave a value.
    pub runs: u64,
}

impl InstantSum {
    /// The average over the runs that gave a value (`None` if none did).
    pub fn mean(&self) -> Option<f64> {
        (self.runs > 0).then(|| self.sum.value() / self.runs as f64)
    }
}

/// Sums over runs at each instant. The sums are exact ([`ExactSum`]), so the runs may be added
/// in any order, or summed shard by shard and merged ([`ConsistencySums::merge`]): the
/// campaign's files come out the same, byte for byte.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConsistencySums {
    /// NEES, per instant.
    pub nees: Vec<InstantSum>,
    /// NEES of α̇, per instant.
    pub rate_nees: Vec<InstantSum>,
    /// NIS, per instant.
    pub nis: Vec<InstantSum>,
}

/// The statistics of [`ConsistencySums`] by their names in `consistency_sums.csv`.
const STATISTICS: [&str; 3] = ["nees", "rate_nees", "nis"];

impl ConsistencySums {
    fn statistics(&self) -> [&Vec<InstantSum>; 3] {
        [&self.nees, &self.rate_nees, &self.nis]
    }

    fn statistics_mut(&mut self) -> [&mut Vec<InstantSum>; 3] {
        [&mut self.nees, &mut self.rate_nees, &mut self.nis]
    }

    /// Adds one run.
    pub fn add(&mut self, run: &RunConsistency) {
        for (sums, values) in
            self.statistics_mut()
                .into_iter()
                .zip([&run.nees, &run.rate_nees, &run.nis])
        {
            if sums.len() < values.len() {
                sums.resize(values.len(), InstantSum::default());
            }
            for (s, v) in sums.iter_mut().zip(values) {
                if let Some(v) = v {
                    s.sum.add(*v);
                    s.runs += 1;
                }
            }
        }
    }

    /// Adds the runs summed in `other` (another shard's).
    pub fn merge(&mut self, other: &ConsistencySums) {
        for (sums, theirs) in self.statistics_mut().into_iter().zip(other.statistics()) {
            if sums.len() < theirs.len() {
                sums.resize(theirs.len(), InstantSum::default());
            }
            for (s, t) in sums.iter_mut().zip(theirs) {
                s.sum.merge(&t.sum);
                s.runs += t.runs;
            }
        }
    }

    /// The summary from [`SETTLED_S`] on.
    pub fn summary(&self) -> Summary {
        let first = (SETTLED_S / EVERY_S).ceil() as usize;
        Summary {
            nees: Statistic::of(&self.nees, first, NEES_DOF),
            rate_nees: Statistic::of(&self.rate_nees, first, 1.0),
            nis: Statistic::of(&self.nis, first, NIS_DOF),
        }
    }

    /// `consistency.csv`: one row per instant, the run-averaged NEES and NIS with their 95 %
    /// bands.
    pub fn write_csv<W: Write>(&self, mut w: W) -> io::Result<()> {
        writeln!(
            w,
            "t_s,nees_runs,nees_mean,nees_low,nees_high,rate_nees_runs,rate_nees_mean,\
             rate_nees_low,rate_nees_high,nis_runs,nis_mean,nis_low,nis_high"
        )?;
        let rows = self.nees.len().max(self.nis.len());
        let cell = |sums: &[InstantSum], k: usize, dof: f64| match sums.get(k) {
            Some(s) if s.runs > 0 => {
                let (lo, hi) = band(dof, s.runs);
                format!("{},{},{lo},{hi}", s.runs, s.sum.value() / s.runs as f64)
            }
            _ => "0,,,".to_string(),
        };
        for k in 0..rows {
            writeln!(
                w,
                "{},{},{},{}",
                k as f64 * EVERY_S,
                cell(&self.nees, k, NEES_DOF),
                cell(&self.rate_nees, k, 1.0),
                cell(&self.nis, k, NIS_DOF)
            )?;
        }
        Ok(())
    }

    /// `consistency_sums.csv`: the exact sums themselves (`statistic,instant,runs,sum`, the sum
    /// as [`ExactSum::to_text`]), what `tss-sim merge` adds up across shards.
    pub fn write_sums<W: Write>(&self, mut w: W) -> io::Result<()> {
        writeln!(w, "statistic,instant,runs,sum")?;
        for (name, sums) in STATISTICS.iter().zip(self.statistics()) {
            for (k, s) in sums.iter().enumerate() {
                writeln!(w, "{name},{k},{},{}", s.runs, s.sum.to_text())?;
            }
        }
        Ok(())
    }

    /// Reads [`ConsistencySums::write_sums`]; an error says which line is wrong.
    pub fn read_sums(text: &str) -> Result<Self, String> {
        let mut lines = text.lines().enumerate();
        match lines.next() {
            Some((_, "statistic,instant,runs,sum")) => {}
            other => {
                return Err(format!(
                    "line 1: expected the header `statistic,instant,runs,sum`, found {:?}",
                    other.map_or("", |(_, l)| l)
                ))
            }
        }
        let mut sums = ConsistencySums::default();
        for (i, line) in lines {
            let bad = |what: &str| format!("line {}: {what}: {line:?}", i + 1);
            let cells: Vec<&str> = line.split(',').collect();
            let [name, instant, runs, sum] = cells[..] else {
                return Err(bad("expected 4 cells"));
            };
            let which = STATISTICS
                .iter()
                .position(|s| *s == name)
                .ok_or_else(|| bad("unknown statistic"))?;
            let target = &mut sums.statistics_mut()[which];
            if instant.parse::<usize>() != Ok(target.len()) {
                return Err(bad("instants out of order"));
            }
            target.push(InstantSum {
                sum: ExactSum::from_text(sum).map_err(|e| bad(&e))?,
                runs: runs
                    .parse()
                    .map_err(|_| bad("runs is not a whole number"))?,
            });
        }
        Ok(sums)
    }
}

/// One statistic (NEES or NIS) over the settled instants.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Statistic {
    /// Degrees of freedom.
    pub dof: f64,
    /// Instants with at least one value.
    pub instants: usize,
    /// Instants whose run average is inside its 95 % band.
    pub inside: usize,
    /// Instants whose run average is below it (the filter claims more error than it makes).
    pub below: usize,
    /// Instants whose run average is above it (the filter is over-confident).
    pub above: usize,
    /// The average over runs and instants.
    pub mean: f64,
    /// The 95 % band of that average if the values were independent (they are correlated in
    /// time, so it is narrower than the truth: a guide, not a test).
    pub mean_band: (f64, f64),
    /// The band of one instant's run average (for the smallest run count).
    pub instant_band: (f64, f64),
    /// Values averaged.
    pub values: u64,
}

impl Statistic {
    fn of(sums: &[InstantSum], first: usize, dof: f64) -> Self {
        let settled = sums.get(first..).unwrap_or(&[]);
        let (mut inside, mut below, mut above) = (0, 0, 0);
        let mut instants = 0;
        let (mut total, mut values) = (0.0, 0);
        let mut fewest = u64::MAX;
        for (s, n) in settled
            .iter()
            .filter(|s| s.runs > 0)
            .map(|s| (s.sum.value(), s.runs))
        {
            instants += 1;
            let (lo, hi) = band(dof, n);
            let mean = s / n as f64;
            if mean < lo {
                below += 1;
            } else if mean > hi {
                above += 1;
            } else {
                inside += 1;
            }
            total += s;
            values += n;
            fewest = fewest.min(n);
        }
        Self {
            dof,
            instants,
            inside,
            below,
            above,
            mean: if values > 0 {
                total / values as f64
            } else {
                f64::NAN
            },
            mean_band: band(dof, values),
            instant_band: band(dof, if fewest == u64::MAX { 1 } else { fewest }),
            values,
        }
    }

    /// The fraction of instants inside the band.
    pub fn fraction_inside(&self) -> f64 {
        if self.instants == 0 {
            0.0
        } else {
            self.inside as f64 / self.instants as f64
        }
    }
}

/// NEES and NIS over the settled instants of a campaign.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Summary {
    /// NEES (α, α̇).
    pub nees: Statistic,
    /// NEES (α̇).
    pub rate_nees: Statistic,
    /// NIS (α).
    pub nis: Statistic,
}

impl Summary {
    /// The summary as text (`consistency.txt`, printed by `montecarlo --consistency`).
    pub fn render(&self, runs: usize) -> String {
        let mut o = String::new();
        let _ = writeln!(
            o,
            "Estimator consistency over {runs} runs, every {EVERY_S} s from {SETTLED_S} s \
             (the flight filter in f32 beside the controller, against the plant's truth)"
        );
        for (name, s) in [
            ("NEES (α, α̇)", &self.nees),
            ("NEES (α̇)", &self.rate_nees),
            ("NIS (α)", &self.nis),
        ] {
            let _ = writeln!(
                o,
                "  {name:<13} {} dof: mean {:.3} over {} values (band if independent \
                 [{:.3}, {:.3}]); of {} instants, {:.1} % inside their 95 % band \
                 [{:.3}, {:.3}], {:.1} % below, {:.1} % above",
                s.dof,
                s.mean,
                s.values,
                s.mean_band.0,
                s.mean_band.1,
                s.instants,
                100.0 * s.fraction_inside(),
                s.instant_band.0,
                s.instant_band.1,
                100.0 * s.below as f64 / s.instants.max(1) as f64,
                100.0 * s.above as f64 / s.instants.max(1) as f64
            );
        }
        o
    }
}

/// File stem of the consistency figure.
pub const FIGURE_STEM: &str = "consistency";

/// The consistency figure: the run-averaged NEES and NIS against mission time (hours), each
/// with its 95 % band.
pub struct ConsistencyFigure<'a> {
    /// The sums over the campaign.
    pub sums: &'a ConsistencySums,
    /// The title.
    pub title: String,
}

impl Figure for ConsistencyFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()> {
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(&self.title, (FONT, 22)).map_err(err)?;
        let panels = root.split_evenly((3, 1));
        for (area, (name, sums, dof)) in panels.iter().zip([
            // The figure's font draws no combining dot: α̇ is written dα/dt.
            ("NEES (α, dα/dt), 2 dof", &self.sums.nees, NEES_DOF),
            ("NEES (dα/dt), 1 dof", &self.sums.rate_nees, 1.0),
            ("NIS (α), 1 dof", &self.sums.nis, NIS_DOF),
        ]) {
            panel(area, name, sums, dof).map_err(err)?;
        }
        Ok(())
    }
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    name: &str,
    sums: &[InstantSum],
    dof: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let hours = |k: usize| k as f64 * EVERY_S / 3_600.0;
    let points: Vec<(f64, f64, (f64, f64))> = sums
        .iter()
        .enumerate()
        .filter_map(|(k, s)| s.mean().map(|mean| (hours(k), mean, band(dof, s.runs))))
        .collect();
    let t1 = points.last().map_or(1.0, |p| p.0.max(1e-3));
    // The scale shows the band well; values beyond it are clipped at its top.
    let top = points
        .iter()
        .map(|p| p.2 .1)
        .fold(dof, f64::max)
        .max(2.0 * dof);
    let mut chart = ChartBuilder::on(area)
        .caption(name, (FONT, 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t1, 0.0..1.5 * top)?;
    chart
        .configure_mesh()
        .x_desc("mission time (h)")
        .y_desc("average over runs")
        .x_label_formatter(&|x| tick_label(*x, t1))
        .y_label_formatter(&|y| tick_label(*y, 1.5 * top))
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .light_line_style(RGBColor(0xee, 0xee, 0xee))
        .draw()?;
    let clip = |v: f64| v.min(1.5 * top);
    chart.draw_series(LineSeries::new(
        points.iter().map(|p| (p.0, clip(p.1))),
        RGBColor(0x1f, 0x77, 0xb4).stroke_width(1),
    ))?;
    for bound in [
        |p: &(f64, f64, (f64, f64))| p.2 .0,
        |p: &(f64, f64, (f64, f64))| p.2 .1,
    ] {
        chart.draw_series(DashedLineSeries::new(
            points.iter().map(|p| (p.0, bound(p))),
            6,
            4,
            RGBColor(0xd6, 0x27, 0x28).stroke_width(2),
        ))?;
    }
    chart.draw_series(LineSeries::new(
        [(0.0, dof), (t1, dof)],
        RGBColor(0x33, 0x33, 0x33).stroke_width(1),
    ))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi2_quantiles_match_the_tables() {
        // χ²(100) at 0.025 and 0.975: 74.222 and 129.561 (Abramowitz & Stegun, Table 26.8).
        assert!((chi2_quantile(100.0, -Z_975) - 74.222).abs() < 0.05);
        assert!((chi2_quantile(100.0, Z_975) - 129.561).abs() < 0.05);
        // The band of the mean of 50 NEES of 2 dof: χ²(100)/50.
        let (lo, hi) = band(2.0, 50);
        assert!(
            (lo - 1.484).abs() < 1e-3 && (hi - 2.591).abs() < 1e-3,
            "{lo} {hi}"
        );
    }

    #[test]
    fn nees_of_a_known_error() {
        let e = Estimate::<f32> {
            alpha_rad: 1e-4,
            alpha_rate_radps: 0.0,
            disturbance_radps2: 0.0,
            alpha_var_rad2: 1e-8,
            alpha_rate_var_rad2ps2: 1e-12,
            disturbance_var_rad2ps4: 1e-18,
            alpha_rate_cov_rad2ps: 0.0,
            alpha_disturbance_cov_rad2ps2: 0.0,
            rate_disturbance_cov_rad2ps3: 0.0,
        };
        // One σ in α, two in α̇: 1 + 4.
        let v = nees(&e, 0.0, -2e-6).unwrap();
        assert!((v - 5.0).abs() < 1e-5, "{v}");
    }

    #[test]
    fn sums_average_over_the_runs_that_gave_a_value() {
        let mut s = ConsistencySums::default();
        s.add(&RunConsistency {
            nees: vec![Some(1.0), Some(3.0)],
            rate_nees: vec![],
            nis: vec![None, Some(2.0)],
        });
        s.add(&RunConsistency {
            nees: vec![Some(3.0)],
            rate_nees: vec![],
            nis: vec![Some(1.0)],
        });
        let pairs = |v: &[InstantSum]| -> Vec<(f64, u64)> {
            v.iter().map(|s| (s.sum.value(), s.runs)).collect()
        };
        assert_eq!(pairs(&s.nees), [(4.0, 2), (3.0, 1)]);
        assert_eq!(pairs(&s.nis), [(1.0, 1), (2.0, 1)]);
        // The exact sums' file reads back to the same sums.
        let mut file = Vec::new();
        s.write_sums(&mut file).unwrap();
        let back = ConsistencySums::read_sums(std::str::from_utf8(&file).unwrap()).unwrap();
        assert_eq!(back, s);
        // Merged with another shard's: the sums of both.
        let mut merged = back.clone();
        merged.merge(&s);
        assert_eq!(pairs(&merged.nees), [(8.0, 4), (6.0, 2)]);
        let mut csv = Vec::new();
        s.write_csv(&mut csv).unwrap();
        let text = String::from_utf8(csv).unwrap();
        assert!(text.lines().nth(1).unwrap().starts_with("0,2,2,"), "{text}");
    }
}
