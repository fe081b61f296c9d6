//! `tss-sim eccentric SCENARIO [--eccentricity E,...] [--set KEY=VALUE]... [--out DIR]`: the
//! scenario's mission flown at each eccentricity (docs/equations.md §16.6), and how well each
//! keep holds: `eccentric.csv`, `eccentric.txt` (the table) and the figure
//! `eccentric_keep_error.{png,svg}` (keep error against e).
//!
//! **Keep error** (docs/equations.md §16.6): the largest |l − l_keep| over the last hour of a
//! keep, sampled at the history's interval: for the stage-1 keep the hour before stage 2 starts
//! (for the paper's mission 7.00–8.00 h, Table 1's stage-1 window), for the stage-2 keep the
//! last hour of the run. The Table-1 figure of `tss-sim run`'s summary (max |simulated − paper|
//! at the paper's instants) is written beside it when the run covers those instants.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::history::{History, PhaseLabel};
use crate::output::OutputSet;
use crate::plots::{draw_error, png_and_svg, tick_label, write_png_and_svg, FONT};
use crate::scenario::Scenario;
use crate::sim;
use crate::table1::{probe_times_for, Table1Comparison};
use crate::usage::{quiet, UsageError};

/// The default eccentricities: 0 to 0.3 in steps of 0.05.
pub const DEFAULT_ECCENTRICITIES: [f64; 7] = [0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3];
/// The window of a keep error: the last hour of the keep, s.
pub const KEEP_WINDOW_S: f64 = 3600.0;
/// The table's file.
pub const TABLE_TXT: &str = "eccentric.txt";
/// The rows' file.
pub const ROWS_CSV: &str = "eccentric.csv";
/// The figure's file stem.
pub const FIGURE_STEM: &str = "eccentric_keep_error";
/// Pixel size of the figure.
pub const FIGURE_SIZE_PX: (u32, u32) = (1000, 640);
/// When the paper's stage 2 starts, s (8 h: Table 1's last stage-1 instant, `table1.rs`).
pub const PAPER_STAGE2_START_S: f64 = 28_800.0;
/// Most eccentricities one sweep flies.
pub const MAX_ECCENTRICITIES: usize = 1000;

/// Arguments of `tss-sim eccentric`.
#[derive(clap::Args, Clone, Debug)]
pub struct EccentricArgs {
    /// Scenario file (TOML), e.g. scenarios/paper.toml.
    pub scenario: PathBuf,
    /// Eccentricities, comma-separated [default: 0,0.05,…,0.3].
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub eccentricity: Vec<f64>,
    /// Override one scenario field, as for `tss-sim run` (applied before the eccentricity).
    #[arg(long = "set", short = 's', value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Output directory [default: out/NAME/eccentric].
    #[arg(long, short, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

/// One eccentricity's mission.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeepRow {
    /// e.
    pub eccentricity: f64,
    /// a, m.
    pub semi_major_axis_m: f64,
    /// Keep error of the stage-1 keep, m (module docs).
    pub keep1_error_m: f64,
    /// Keep error of the stage-2 keep, m.
    pub keep2_error_m: f64,
    /// The summary's Table-1 figure of stage 1, max |simulated − paper|, m (NaN: not covered).
    pub table1_stage1_m: f64,
    /// The same for stage 2, m (NaN also when stage 2 does not start at the paper's 8 h,
    /// [`PAPER_STAGE2_START_S`]: Table 1's stage-2 instants then fall elsewhere in the mission).
    pub table1_stage2_m: f64,
    /// The length at the end of the run, m.
    pub final_length_m: f64,
    /// The run ended in the stage-2 keep.
    pub completed: bool,
    /// The smallest tension after the first sample, N.
    pub min_tension_n: f64,
    /// Samples with T ≤ 0.
    pub slack_samples: usize,
    /// The last sample with T ≤ 0, s (NaN: none).
    pub last_slack_s: f64,
}

/// The keep errors and the rest of one run of `scenario` (module docs).
pub fn keep_row(scenario: &Scenario, history: &History) -> KeepRow {
    let end_s = history.samples.last().map_or(0.0, |s| s.t_s);
    let stage2_s = scenario.stage2.start_time_s;
    let worst = |from: f64, to: f64, keep: f64| {
        history
            .samples
            .iter()
            .filter(|s| s.t_s >= from && s.t_s <= to)
            .map(|s| (s.length_m - keep).abs())
            .fold(f64::NAN, |a, b| {
                if b.is_nan() || b > a || a.is_nan() {
                    b
                } else {
                    a
                }
            })
    };
    let table = Table1Comparison::new(&history.probes);
    let table1 = |stage| {
        table
            .max_abs_difference(stage)
            .map_or(f64::NAN, |d| d.difference_m.abs())
    };
    // Table 1's stage-2 instants (14–15 h) follow the paper's stage-2 start: against a run
    // whose stage 2 starts elsewhere they compare two different moments of the mission.
    let stage2_as_paper = (stage2_s - PAPER_STAGE2_START_S).abs() < 0.5;
    let after_start = history.samples.iter().skip(1);
    let slack: Vec<f64> = after_start
        .clone()
        .filter(|s| s.tension_n <= 0.0)
        .map(|s| s.t_s)
        .collect();
    KeepRow {
        eccentricity: scenario.orbit.eccentricity,
        semi_major_axis_m: scenario.orbit.semi_major_axis_m,
        keep1_error_m: worst(
            stage2_s - KEEP_WINDOW_S,
            stage2_s,
            scenario.stage1.keep_length_m,
        ),
        keep2_error_m: worst(end_s - KEEP_WINDOW_S, end_s, scenario.stage2.keep_length_m),
        table1_stage1_m: table1(1),
        table1_stage2_m: if stage2_as_paper { table1(2) } else { f64::NAN },
        final_length_m: history.samples.last().map_or(f64::NAN, |s| s.length_m),
        completed: history
            .samples
            .last()
            .is_some_and(|s| s.phase == PhaseLabel::Keep2),
        min_tension_n: after_start
            .map(|s| s.tension_n)
            .fold(f64::INFINITY, f64::min),
        slack_samples: slack.len(),
        last_slack_s: slack.last().copied().unwrap_or(f64::NAN),
    }
}

/// Flies `path` (with `sets`) at each of `eccentricities`.
pub fn sweep(path: &Path, sets: &[String], eccentricities: &[f64]) -> anyhow::Result<Vec<KeepRow>> {
    eccentricities
        .iter()
        .map(|&e| {
            let mut all = sets.to_vec();
            all.push(format!("orbit.eccentricity={e}"));
            let sc = Scenario::load(path, &all)?;
            let history = sim::run(&sc, &probe_times_for(&sc), &mut |_| {})
                .with_context(|| format!("e = {e}"))?;
            Ok(keep_row(&sc, &history))
        })
        .collect()
}

/// The table of `rows` as text. A Table-1 column no row has a figure for (the run does not
/// cover its instants, or stage 2 starts elsewhere than the paper's) is left out.
pub fn render(rows: &[KeepRow]) -> String {
    let stage1 = rows.iter().any(|r| !r.table1_stage1_m.is_nan());
    let stage2 = rows.iter().any(|r| !r.table1_stage2_m.is_nan());
    let mut o = String::new();
    let _ = write!(o, "     e      a (km)  keep 1 (m)  keep 2 (m)");
    match (stage1, stage2) {
        (true, true) => o.push_str("  Table 1: stage 1  stage 2 (m)"),
        (true, false) => o.push_str("  Table 1 stage 1 (m)"),
        (false, true) => o.push_str("  Table 1 stage 2 (m)"),
        (false, false) => {}
    }
    let _ = writeln!(o, "  final l (m)  done  min T (N)  slack (last, h)");
    for r in rows {
        let slack = if r.slack_samples == 0 {
            "0".to_string()
        } else {
            format!("{} ({:.2})", r.slack_samples, r.last_slack_s / 3600.0)
        };
        let _ = write!(
            o,
            "{:>6.3} {:>11.1} {:>11.3} {:>11.3}",
            r.eccentricity,
            r.semi_major_axis_m / 1000.0,
            r.keep1_error_m,
            r.keep2_error_m,
        );
        match (stage1, stage2) {
            (true, true) => {
                let _ = write!(
                    o,
                    " {:>17.3} {:>12.3}",
                    r.table1_stage1_m, r.table1_stage2_m
                );
            }
            (true, false) => {
                let _ = write!(o, " {:>20.3}", r.table1_stage1_m);
            }
            (false, true) => {
                let _ = write!(o, " {:>20.3}", r.table1_stage2_m);
            }
            (false, false) => {}
        }
        let _ = writeln!(
            o,
            " {:>12.3} {:>5} {:>10.2e}  {slack}",
            r.final_length_m,
            if r.completed { "yes" } else { "no" },
            r.min_tension_n,
        );
    }
    o
}

/// `tss-sim eccentric`.
pub fn run_eccentric(args: &EccentricArgs) -> anyhow::Result<()> {
    let eccs = if args.eccentricity.is_empty() {
        DEFAULT_ECCENTRICITIES.to_vec()
    } else {
        args.eccentricity.clone()
    };
    if eccs.len() > MAX_ECCENTRICITIES {
        return Err(UsageError(format!(
            "--eccentricity: at most {MAX_ECCENTRICITIES} values"
        ))
        .into());
    }
    if let Some(e) = eccs.iter().find(|e| !e.is_finite()) {
        return Err(UsageError(format!("--eccentricity: {e} is not a number")).into());
    }
    // Every eccentricity's scenario is checked before anything is flown.
    for &e in &eccs {
        let mut all = args.set.clone();
        all.push(format!("orbit.eccentricity={e}"));
        Scenario::load(&args.scenario, &all)?;
    }
    let name = Scenario::load(&args.scenario, &args.set)?.name;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| crate::output::default_dir(&name, &args.set).join("eccentric"));
    let mut owned = vec![TABLE_TXT.to_string(), ROWS_CSV.to_string()];
    owned.extend(png_and_svg(FIGURE_STEM));
    let mut out = OutputSet::prepare("--out", &dir, owned)?;
    let rows = sweep(&args.scenario, &args.set, &eccs)?;
    let table = render(&rows);
    std::fs::write(out.stage(TABLE_TXT), &table).context("writing the table")?;
    let mut csv = String::from(
        "eccentricity,semi_major_axis_m,keep1_error_m,keep2_error_m,table1_stage1_m,table1_stage2_m,final_length_m,completed,min_tension_n,slack_samples,last_slack_s\n",
    );
    for r in &rows {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{},{}",
            r.eccentricity,
            r.semi_major_axis_m,
            r.keep1_error_m,
            r.keep2_error_m,
            r.table1_stage1_m,
            r.table1_stage2_m,
            r.final_length_m,
            r.completed,
            r.min_tension_n,
            r.slack_samples,
            r.last_slack_s
        );
    }
    std::fs::write(out.stage(ROWS_CSV), csv).context("writing the rows")?;
    crate::plots::check_font()?;
    write_png_and_svg(
        &mut out,
        FIGURE_STEM,
        FIGURE_SIZE_PX,
        &KeepErrorFigure(&rows),
    )?;
    out.commit()?;
    if !quiet() {
        print!("{table}");
        println!("written to {}", dir.display());
    }
    Ok(())
}

/// Keep error against e, one curve per keep, log scale, with the 1 m line.
struct KeepErrorFigure<'a>(&'a [KeepRow]);

impl crate::plots::Figure for KeepErrorFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()> {
        draw(root, self.0).map_err(draw_error)
    }
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[KeepRow],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    // Floor the log axis at 10 µm (an error of 0 would have no place on it).
    let floor = 1e-5;
    let pts = |f: fn(&KeepRow) -> f64| -> Vec<(f64, f64)> {
        rows.iter()
            .filter(|r| f(r).is_finite())
            .map(|r| (r.eccentricity, f(r).max(floor)))
            .collect()
    };
    let (k1, k2) = (pts(|r| r.keep1_error_m), pts(|r| r.keep2_error_m));
    let top = k1.iter().chain(&k2).map(|p| p.1).fold(10.0, f64::max) * 2.0;
    let e_max = rows.iter().map(|r| r.eccentricity).fold(0.05, f64::max);
    let mut chart = ChartBuilder::on(root)
        .caption(
            "Keep error against eccentricity (last hour of each keep)",
            (FONT, 24),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..e_max, (floor..top).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("eccentricity e")
        .y_desc("keep error max |l − l_keep| (m)")
        .x_label_formatter(&|e| tick_label(*e, e_max))
        .label_style((FONT, 16))
        .draw()?;
    let blue = RGBColor(0x1f, 0x77, 0xb4);
    let red = RGBColor(0xd6, 0x27, 0x28);
    for (label, color, points) in [("30 km keep", blue, k1), ("2 km keep", red, k2)] {
        chart
            .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
        chart.draw_series(points.iter().map(|&p| Circle::new(p, 4, color.filled())))?;
    }
    chart
        .draw_series(LineSeries::new(
            vec![(0.0, 1.0), (e_max, 1.0)],
            BLACK.mix(0.5).stroke_width(1),
        ))?
        .label("1 m")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.5)));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font((FONT, 16))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()?;
    Ok(())
}
