//! `tss-sim compare SCENARIO --laws paper,paper+loop,rupp,tracking [--runs N [--seed S]] [-o DIR]`:
//! flies each law (`[controller] law`, `crate::laws`; the paper's without its tension loop,
//! `paper`, and with it, `paper+loop`: docs/equations.md §17) on the same scenario — and with `--runs` on the
//! same dispersed campaign (the scenario's `[montecarlo]` dispersions, the same seeds for every
//! law) — and writes one table (`compare.txt`, `compare.csv`), the runs (`compare_runs.csv`,
//! with `--runs`) and overlaid figures of the nominal runs (`compare.png`/`.svg`: length, α,
//! tension and reel rate against time).
//!
//! The metrics of a run ([`LawMetrics`], docs/equations.md §15.3):
//! - time to reach the target: first l ≥ stage1.keep_length_m − 0.5 m (the run summary's
//!   landmark, `crate::report`);
//! - overshoot: the largest stage-1 length above the keep length, once reached;
//! - largest libration: max |α| over the run (α wrapped to (−180°, 180°]), and the libration
//!   after arrival: max |α| from the arrival to the end of stage 1;
//! - final speed: |l̇| at the end of the run (the plant's, from the last two samples);
//! - tension range over the run (the minimum over every control tick), slack time and episodes,
//!   each from the point the tether must be taut on (`simulation.taut_from_length_m`,
//!   docs/equations.md §17.7; from the start by default);
//! - reel energy: ∫ T |l̇| dt, the work the tether does on (paying out) or against (winding in)
//!   the reel, from the recorded samples (trapezoid in T over each sample's Δl): what a brake
//!   dissipates and a motor supplies, not the motor's electrical energy;
//! - keep error: max |l − keep₁| over the scenario's criteria window
//!   (`montecarlo.criteria.keep1_from_s … keep1_until_s`, Monte Carlo's own metric);
//! - pass: the scenario's `[montecarlo.criteria]` (all of them), the Monte Carlo verdict.
//!
//! With `--runs N` the table gives each metric's median over the runs that completed, and the
//! pass rate over all N. Exit codes as the other commands: 2 for a usage error (unknown law,
//! bad scenario, `--runs 0`, unusable output directory), 1 if a run failed.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;

use anyhow::Context;
use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;

use crate::history::{History, Sample};
use crate::montecarlo::campaign::Metric;
use crate::montecarlo::{Campaign, Outcome};
use crate::output::OutputSet;
use crate::plots::{check_font, draw_error, tick_label, write_png_and_svg, Figure, FONT};
use crate::report::summarize;
use crate::scenario::{LawName, PlantModel, Scenario};
use crate::table1::probe_times_for;
use crate::usage::{quiet, UsageError};

/// The largest `--runs`.
pub const MAX_RUNS: u64 = 100_000;

/// Arguments of `tss-sim compare`.
#[derive(clap::Args, Clone, Debug)]
pub struct CompareArgs {
    /// Scenario file (TOML), e.g. scenarios/seds2.toml.
    pub scenario: PathBuf,
    /// The laws to fly, comma-separated: paper (without the tension loop), paper+loop (with
    /// the scenario's `[tension_loop]`), rupp, tracking [default: all of them; on the rigid
    /// plant all but paper+loop, whose loop needs an elastic tether].
    #[arg(long, value_delimiter = ',')]
    pub laws: Vec<String>,
    /// Fly each law on this many runs of the scenario's `[montecarlo]` campaign (same seeds for
    /// every law) besides the nominal run.
    #[arg(long)]
    pub runs: Option<u64>,
    /// The campaign's seed (with --runs).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output directory [default: out/NAME/compare, with the overrides in NAME as `run` writes
    /// them: out/NAME+KEY=VALUE/compare].
    #[arg(long, short, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Override one scenario field, dotted key and TOML value (repeatable).
    #[arg(long = "set", short = 's', value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

/// What `--laws` names: a law, and for the paper's law whether its tension loop flies
/// (`[tension_loop] enabled`; the tension laws command the tension themselves, without it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Contender {
    /// The law.
    pub law: LawName,
    /// The paper's law flies with its tension loop (docs/equations.md §17).
    pub tension_loop: bool,
}

impl Contender {
    /// Every contender, in the order `tss-sim compare` lists them.
    pub const ALL: [Contender; 4] = [
        Contender::without_loop(LawName::Paper),
        Contender {
            law: LawName::Paper,
            tension_loop: true,
        },
        Contender::without_loop(LawName::Rupp),
        Contender::without_loop(LawName::Tracking),
    ];

    const fn without_loop(law: LawName) -> Self {
        Self {
            law,
            tension_loop: false,
        }
    }

    /// The name on the command line and in the outputs.
    pub fn as_str(self) -> &'static str {
        match (self.law, self.tension_loop) {
            (LawName::Paper, true) => "paper+loop",
            (law, _) => law.as_str(),
        }
    }

    /// The contender named `s`, if any.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.as_str() == s)
    }
}

/// What one run of one law did (see the module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LawMetrics {
    /// Time to reach the stage-1 keep length, s.
    pub time_to_target_s: Option<f64>,
    /// Stage-1 overshoot, m.
    pub overshoot_m: Option<f64>,
    /// Largest |α| over the run, deg.
    pub max_libration_deg: f64,
    /// Largest |α| from the arrival to the end of stage 1, deg.
    pub libration_after_deg: Option<f64>,
    /// |l̇| at the end, m/s.
    pub final_speed_mps: f64,
    /// Smallest tension over every control tick, N.
    pub min_tension_n: f64,
    /// Largest recorded tension, N.
    pub max_tension_n: f64,
    /// Time slack, s.
    pub slack_s: f64,
    /// Slack episodes.
    pub slack_episodes: f64,
    /// ∫ T |l̇| dt, J.
    pub reel_energy_j: f64,
    /// Keep error over the criteria window, m.
    pub keep_error_m: Option<f64>,
    /// Passed every criterion.
    pub passed: bool,
}

/// α wrapped to (−180°, 180°], deg.
fn wrapped_deg(alpha_rad: f64) -> f64 {
    let d = alpha_rad.to_degrees().rem_euclid(360.0);
    if d > 180.0 {
        d - 360.0
    } else {
        d
    }
}

impl LawMetrics {
    /// The metrics of `h`, a run of `sc`.
    pub fn of(sc: &Scenario, h: &History) -> Self {
        let s = summarize(sc, h);
        let outcome = Outcome::of(sc, h);
        let reached = s.landmarks.get(1).and_then(|l| l.t_s);
        let stage1_end = sc.stage2.start_time_s;
        let samples = &h.samples;
        let abs_alpha = |x: &Sample| wrapped_deg(x.alpha_rad).abs();
        let libration_after = reached.map(|t0| {
            samples
                .iter()
                .filter(|x| x.t_s >= t0 && x.t_s <= stage1_end)
                .map(abs_alpha)
                .fold(0.0, f64::max)
        });
        let final_speed = match samples.as_slice() {
            [.., a, b] if b.t_s > a.t_s => ((b.length_m - a.length_m) / (b.t_s - a.t_s)).abs(),
            _ => 0.0,
        };
        let energy = samples
            .windows(2)
            .map(|w| {
                0.5 * (w[0].tension_n + w[1].tension_n) * (w[1].length_m - w[0].length_m).abs()
            })
            .sum();
        let f = &h.faults;
        Self {
            time_to_target_s: outcome.get(Metric::TimeToKeep1),
            overshoot_m: outcome.get(Metric::Overshoot),
            max_libration_deg: samples.iter().map(abs_alpha).fold(0.0, f64::max),
            libration_after_deg: libration_after,
            final_speed_mps: final_speed,
            min_tension_n: f.taut.min_tension_n.0,
            max_tension_n: samples
                .iter()
                .map(|x| x.tension_n)
                .fold(f64::NEG_INFINITY, f64::max),
            slack_s: f.taut.slack_s,
            slack_episodes: f64::from(f.taut.slack_events),
            reel_energy_j: energy,
            keep_error_m: outcome.get(Metric::Keep1Error),
            passed: outcome.failed(&sc.montecarlo).is_empty(),
        }
    }

    /// The table's columns: (header, value) with `None` for "not defined".
    fn columns(&self) -> [(&'static str, Option<f64>); 12] {
        [
            ("t_target_h", self.time_to_target_s.map(|t| t / 3600.0)),
            ("overshoot_m", self.overshoot_m),
            ("max_libration_deg", Some(self.max_libration_deg)),
            ("libration_after_deg", self.libration_after_deg),
            ("final_speed_mps", Some(self.final_speed_mps)),
            ("min_tension_n", Some(self.min_tension_n)),
            ("max_tension_n", Some(self.max_tension_n)),
            ("slack_s", Some(self.slack_s)),
            ("slack_episodes", Some(self.slack_episodes)),
            ("reel_energy_kj", Some(self.reel_energy_j / 1000.0)),
            ("keep_error_m", self.keep_error_m),
            ("pass", Some(if self.passed { 1.0 } else { 0.0 })),
        ]
    }
}

/// One law's row of the table: the nominal run, and with `--runs` the campaign.
#[derive(Clone, Debug)]
pub struct LawRow {
    /// The law (and its tension loop).
    pub law: Contender,
    /// Its nominal run.
    pub nominal: LawMetrics,
    /// Its campaign runs (run index, metrics; `None` if the run did not complete).
    pub runs: Vec<(u64, Option<LawMetrics>)>,
}

impl LawRow {
    /// The median of column `i` over the completed runs that define it.
    fn median(&self, i: usize) -> Option<f64> {
        let mut v: Vec<f64> = self
            .runs
            .iter()
            .filter_map(|(_, m)| m.and_then(|m| m.columns()[i].1))
            .filter(|x| x.is_finite())
            .collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let n = v.len();
        Some(if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        })
    }

    /// Passed runs / all runs.
    fn pass_rate(&self) -> f64 {
        let passed = self
            .runs
            .iter()
            .filter(|(_, m)| m.is_some_and(|m| m.passed))
            .count();
        passed as f64 / self.runs.len().max(1) as f64
    }
}

/// A column's width: its header's, at least 9.
fn width(header: &str) -> usize {
    header.len().max(9)
}

fn cell(v: Option<f64>) -> String {
    match v {
        Some(x) if x.abs() >= 1e4 || (x != 0.0 && x.abs() < 1e-3) => format!("{x:.3e}"),
        Some(x) => format!("{x:.3}"),
        None => "-".to_string(),
    }
}

/// The table as text: one row per law (nominal run; with runs, the medians and the pass rate).
pub fn render_table(sc: &Scenario, rows: &[LawRow]) -> String {
    let headers = LawMetrics::default().columns().map(|c| c.0);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Laws compared on scenario `{}` (target {} m; nominal run)",
        sc.name, sc.stage1.keep_length_m
    );
    let _ = write!(out, "{:<11}", "law");
    for h in headers {
        let _ = write!(out, " {h:>w$}", w = width(h));
    }
    out.push('\n');
    for r in rows {
        let _ = write!(out, "{:<11}", r.law.as_str());
        for (h, v) in r.nominal.columns() {
            let _ = write!(out, " {:>w$}", cell(v), w = width(h));
        }
        out.push('\n');
    }
    if rows.iter().any(|r| !r.runs.is_empty()) {
        let n = rows[0].runs.len();
        let _ = writeln!(
            out,
            "\nMedians over {n} dispersed runs (same seeds for every law); pass = pass rate"
        );
        for r in rows {
            let _ = write!(out, "{:<11}", r.law.as_str());
            for (i, h) in headers.iter().enumerate().take(headers.len() - 1) {
                let _ = write!(out, " {:>w$}", cell(r.median(i)), w = width(h));
            }
            let _ = write!(out, " {:>w$}", cell(Some(r.pass_rate())), w = width("pass"));
            out.push('\n');
        }
    }
    out
}

/// The table as CSV: `law,set,<metrics>` with set = `nominal` or `median` (pass = pass rate).
pub fn write_table_csv<W: std::io::Write>(mut w: W, rows: &[LawRow]) -> std::io::Result<()> {
    let headers = LawMetrics::default().columns().map(|c| c.0);
    writeln!(w, "law,set,{}", headers.join(","))?;
    let num = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x}"));
    for r in rows {
        let values: Vec<String> = r.nominal.columns().iter().map(|c| num(c.1)).collect();
        writeln!(w, "{},nominal,{}", r.law.as_str(), values.join(","))?;
        if !r.runs.is_empty() {
            let mut values: Vec<String> =
                (0..headers.len() - 1).map(|i| num(r.median(i))).collect();
            values.push(num(Some(r.pass_rate())));
            writeln!(w, "{},median,{}", r.law.as_str(), values.join(","))?;
        }
    }
    Ok(())
}

/// Every run as CSV: `law,run,completed,<metrics>`.
fn write_runs_csv<W: std::io::Write>(mut w: W, rows: &[LawRow]) -> std::io::Result<()> {
    let headers = LawMetrics::default().columns().map(|c| c.0);
    writeln!(w, "law,run,completed,{}", headers.join(","))?;
    for r in rows {
        for (i, m) in &r.runs {
            let values: Vec<String> = match m {
                Some(m) => m
                    .columns()
                    .iter()
                    .map(|c| c.1.map_or(String::new(), |x| format!("{x}")))
                    .collect(),
                None => vec![String::new(); headers.len()],
            };
            writeln!(
                w,
                "{},{i},{},{}",
                r.law.as_str(),
                m.is_some(),
                values.join(",")
            )?;
        }
    }
    Ok(())
}

/// The figure's stem.
pub const FIGURE_STEM: &str = "compare";

/// Every file `tss-sim compare` may write.
pub fn output_names() -> Vec<String> {
    let mut names: Vec<String> = ["compare.txt", "compare.csv", "compare_runs.csv"]
        .map(String::from)
        .to_vec();
    names.extend(crate::plots::png_and_svg(FIGURE_STEM));
    names
}

/// The laws named on the command line, in order; a law named twice is refused.
pub fn parse_laws(names: &[String]) -> Result<Vec<Contender>, UsageError> {
    let mut laws = Vec::new();
    for n in names {
        let law = Contender::parse(n.trim()).ok_or_else(|| {
            UsageError(format!(
                "--laws: unknown law {n:?} (the laws: {})",
                Contender::ALL.map(Contender::as_str).join(", ")
            ))
        })?;
        if laws.contains(&law) {
            return Err(UsageError(format!(
                "--laws: {:?} is named twice (each law is flown once)",
                law.as_str()
            )));
        }
        laws.push(law);
    }
    if laws.is_empty() {
        return Err(UsageError("--laws: name at least one law".into()));
    }
    Ok(laws)
}

/// The laws `compare` flies when none are named: every contender the scenario's plant can fly
/// (the tension loop damps an elastic tether, and is unstable on the rigid rod:
/// docs/equations.md §17.3).
pub fn default_laws(sc: &Scenario) -> Vec<Contender> {
    let elastic = sc.plant.model == PlantModel::Elastic;
    Contender::ALL
        .into_iter()
        .filter(|c| elastic || !c.tension_loop)
        .collect()
}

/// `sc` flown by `law`, validated (a tension law on the elastic plant needs the motor reel).
fn with_law(sc: &Scenario, law: Contender) -> Result<Scenario, UsageError> {
    let mut s = sc.clone();
    s.controller.law = law.law;
    s.tension_loop.enabled = law.tension_loop;
    let problems = s.problems();
    if problems.is_empty() {
        Ok(s)
    } else {
        let lines: Vec<String> = problems.iter().map(ToString::to_string).collect();
        Err(UsageError(format!(
            "law {} on this scenario: {}",
            law.as_str(),
            lines.join("; ")
        )))
    }
}

/// `tss-sim compare`.
pub fn compare(args: &CompareArgs) -> anyhow::Result<()> {
    let sc = Scenario::load(&args.scenario, &args.set)?;
    let laws = if args.laws.is_empty() {
        default_laws(&sc)
    } else {
        parse_laws(&args.laws)?
    };
    if let Some(n) = args.runs {
        if n == 0 || n > MAX_RUNS {
            return Err(UsageError(format!("--runs {n}: must be in 1..={MAX_RUNS}")).into());
        }
    }
    if args.runs.is_some() && sc.montecarlo.dispersion.is_empty() {
        return Err(UsageError(format!(
            "--runs: {} has no [[montecarlo.dispersion]] to disperse",
            args.scenario.display()
        ))
        .into());
    }
    let scenarios: Vec<Scenario> = laws
        .iter()
        .map(|&l| with_law(&sc, l))
        .collect::<Result<_, _>>()?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| crate::output::default_dir(&sc.name, &args.set).join("compare"));
    let mut out = OutputSet::prepare("--out", &dir, output_names())?;

    let mut rows = Vec::new();
    let mut histories = Vec::new();
    for (law, s) in laws.iter().zip(&scenarios) {
        let h = crate::sim::run(s, &probe_times_for(s), &mut |_| {}).with_context(|| {
            format!("flying law {} on {}", law.as_str(), args.scenario.display())
        })?;
        let runs = match args.runs {
            Some(n) => campaign_runs(s, args.seed, n)?,
            None => Vec::new(),
        };
        rows.push(LawRow {
            law: *law,
            nominal: LawMetrics::of(s, &h),
            runs,
        });
        histories.push((*law, h));
    }

    let table = render_table(&sc, &rows);
    let mut files = vec![out.write("compare.txt", |w| w.write_all(table.as_bytes()))?];
    files.push(out.write("compare.csv", |w| write_table_csv(w, &rows))?);
    if args.runs.is_some() {
        files.push(out.write("compare_runs.csv", |w| write_runs_csv(w, &rows))?);
    }
    let mark = out.mark();
    let figure = check_font().and_then(|()| {
        write_png_and_svg(
            &mut out,
            FIGURE_STEM,
            (1200, 1400),
            &Overlay {
                scenario: sc.name.clone(),
                stage2_s: sc.stage2.start_time_s,
                runs: &histories,
            },
        )
    });
    let figure_error = match figure {
        Ok(paths) => {
            files.extend(paths);
            None
        }
        Err(e) => {
            out.abandon_since(mark);
            Some(e)
        }
    };
    out.commit()?;
    if !quiet() {
        print!("{table}");
        println!("\nWritten to {}:", dir.display());
        for f in &files {
            println!("  {}", f.display());
        }
    }
    match figure_error {
        Some(e) => Err(e.context("the figure was not drawn (every other output was written)")),
        None => Ok(()),
    }
}

/// Runs 0..n of the campaign of `sc` (its law set), in parallel; a run that fails is `None`.
fn campaign_runs(
    sc: &Scenario,
    seed: u64,
    n: u64,
) -> anyhow::Result<Vec<(u64, Option<LawMetrics>)>> {
    let campaign = Campaign::new(sc.clone(), seed, n)?;
    Ok((0..n)
        .into_par_iter()
        .map(|i| {
            let inputs = campaign.draw(i);
            let m = campaign.scenario_for(i, &inputs).ok().and_then(|mut s| {
                s.montecarlo = sc.montecarlo.clone();
                crate::sim::run(&s, &probe_times_for(&s), &mut |_| {})
                    .ok()
                    .map(|h: History| LawMetrics::of(&s, &h))
            });
            (i, m)
        })
        .collect())
}

/// The overlaid figure: length, α, tension and reel rate against time, one curve per law.
struct Overlay<'a> {
    scenario: String,
    stage2_s: f64,
    runs: &'a [(Contender, History)],
}

const LAW_COLORS: [RGBColor; 4] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
];

impl Figure for Overlay<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()> {
        root.fill(&WHITE).map_err(draw_error)?;
        type Series = fn(&[Sample]) -> Vec<(f64, f64)>;
        let panels: [(&str, &str, Series); 4] = [
            ("Tether length", "l (km)", |s| {
                s.iter()
                    .map(|x| (x.t_s / 3600.0, x.length_m / 1000.0))
                    .collect()
            }),
            ("In-plane libration", "α (deg)", |s| {
                s.iter()
                    .map(|x| (x.t_s / 3600.0, wrapped_deg(x.alpha_rad)))
                    .collect()
            }),
            ("Tension at the reel", "T (N)", |s| {
                s.iter().map(|x| (x.t_s / 3600.0, x.tension_n)).collect()
            }),
            (
                "Reel rate (the plant's, from the recorded lengths)",
                "l̇ (m/s)",
                rates,
            ),
        ];
        let areas = root.split_evenly((panels.len(), 1));
        for (area, (title, y_desc, series)) in areas.iter().zip(panels) {
            let curves: Vec<(Contender, Vec<(f64, f64)>)> = self
                .runs
                .iter()
                .map(|(law, h)| (*law, series(&h.samples)))
                .collect();
            draw_panel(
                area,
                &format!("{title} — scenario {}", self.scenario),
                y_desc,
                self.stage2_s / 3600.0,
                &curves,
            )
            .map_err(draw_error)?;
        }
        Ok(())
    }
}

/// The finite range of `values`, padded by 5 % (±1 when flat, 0..1 when empty).
fn padded(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        (0.0, 1.0)
    } else if hi - lo <= f64::EPSILON * hi.abs().max(1.0) {
        (lo - 1.0, hi + 1.0)
    } else {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    }
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    y_desc: &str,
    stage2_h: f64,
    curves: &[(Contender, Vec<(f64, f64)>)],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let all = || curves.iter().flat_map(|c| c.1.iter());
    let (x0, x1) = padded(all().map(|p| p.0));
    let (y0, y1) = padded(all().map(|p| p.1));
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FONT, 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .x_desc("t (h)")
        .y_desc(y_desc)
        .x_label_formatter(&|x| tick_label(*x, x1 - x0))
        .y_label_formatter(&|y| tick_label(*y, y1 - y0))
        .label_style((FONT, 15))
        .axis_desc_style((FONT, 16))
        .light_line_style(RGBColor(0xee, 0xee, 0xee))
        .draw()?;
    if stage2_h > x0 && stage2_h < x1 {
        chart.draw_series(DashedLineSeries::new(
            [(stage2_h, y0), (stage2_h, y1)],
            4,
            6,
            RGBColor(0x99, 0x99, 0x99).stroke_width(1),
        ))?;
    }
    for (law, points) in curves {
        let color = LAW_COLORS[Contender::ALL.iter().position(|l| l == law).unwrap_or(0)];
        for (i, piece) in pieces(points).into_iter().enumerate() {
            let drawn = chart.draw_series(LineSeries::new(piece, color.stroke_width(2)))?;
            if i == 0 {
                drawn.label(law.as_str()).legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 24, y)], color.stroke_width(2))
                });
            }
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 15))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

/// The finite points of a curve in pieces, cut where a value is not finite or jumps by more
/// than 180 (α wrapping from −180° to 180° is a tumble through the vertical, not a line across
/// the panel).
fn pieces(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for &p in points {
        let finite = p.0.is_finite() && p.1.is_finite();
        let jump = out
            .last()
            .and_then(|c| c.last())
            .is_some_and(|q| (p.1 - q.1).abs() > 180.0);
        if (!finite || jump) && out.last().is_some_and(|c| !c.is_empty()) {
            out.push(Vec::new());
        }
        if finite {
            if let Some(c) = out.last_mut() {
                c.push(p);
            }
        }
    }
    out.retain(|c| !c.is_empty());
    out
}

/// The plant's reel rate (m/s) from the recorded lengths, against time (h).
fn rates(samples: &[Sample]) -> Vec<(f64, f64)> {
    samples
        .windows(2)
        .filter(|w| w[1].t_s > w[0].t_s)
        .map(|w| {
            (
                w[1].t_s / 3600.0,
                (w[1].length_m - w[0].length_m) / (w[1].t_s - w[0].t_s),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curves_are_cut_at_wraps_and_gaps() {
        let p = [
            (0.0, 170.0),
            (1.0, 179.0),
            (2.0, -179.0),
            (3.0, f64::NAN),
            (4.0, 1.0),
        ];
        assert_eq!(
            pieces(&p),
            vec![
                vec![(0.0, 170.0), (1.0, 179.0)],
                vec![(2.0, -179.0)],
                vec![(4.0, 1.0)]
            ]
        );
        assert!(pieces(&[]).is_empty());
    }

    #[test]
    fn angles_wrap_to_a_half_open_turn() {
        assert_eq!(wrapped_deg(0.0), 0.0);
        assert!((wrapped_deg(std::f64::consts::PI) - 180.0).abs() < 1e-12);
        assert!((wrapped_deg(-std::f64::consts::PI) - 180.0).abs() < 1e-12);
        assert!((wrapped_deg(-1.5 * std::f64::consts::PI) - 90.0).abs() < 1e-12);
        assert!((wrapped_deg(3.0 * std::f64::consts::PI / 2.0) + 90.0).abs() < 1e-12);
    }
}
