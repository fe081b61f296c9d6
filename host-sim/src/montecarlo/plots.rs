//! The campaign's figures, PNG and SVG: histograms of the outcomes and scatter plots of
//! outcomes against each dispersed input. Passing runs are blue, failing runs red; a declared
//! criterion's limit is a dashed line.

use std::path::PathBuf;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::campaign::{Metric, RunRecord};
use crate::output::OutputSet;
use crate::plots::{draw_error as err, png_and_svg, tick_label, write_png_and_svg, Figure, FONT};
use crate::scenario::Scenario;
/// Bins per histogram.
pub const HISTOGRAM_BINS: usize = 30;
/// Panels per row of the scatter figures.
const SCATTER_COLUMNS: usize = 3;

const PASS_COLOR: RGBColor = RGBColor(0x1f, 0x77, 0xb4);
const FAIL_COLOR: RGBColor = RGBColor(0xd6, 0x27, 0x28);
const LIMIT_COLOR: RGBColor = RGBColor(0x33, 0x33, 0x33);

/// The outcomes shown as histograms (`mc_histograms`).
pub const HISTOGRAM_METRICS: [Metric; 8] = [
    Metric::TimeToKeep1,
    Metric::Overshoot,
    Metric::Keep1Error,
    Metric::Table1Stage1,
    Metric::Table1Stage2,
    Metric::MinTension,
    Metric::FinalError,
    Metric::Slack,
];

/// The outcomes plotted against every dispersed input (`mc_scatter_<name>`).
pub const SCATTER_METRICS: [Metric; 3] =
    [Metric::Keep1Error, Metric::Overshoot, Metric::MinTension];

/// The limit a declared criterion puts on `m`, if any.
fn limit(sc: &Scenario, m: Metric) -> Option<f64> {
    let c = &sc.montecarlo.criteria;
    let v = match m {
        Metric::Keep1Error => c.max_keep1_error_m,
        Metric::TimeToKeep1 => c.max_time_to_keep1_s,
        Metric::Overshoot => c.max_overshoot_m,
        Metric::MinTension => c.min_tension_n,
        Metric::FinalError => c.max_final_error_m,
        _ => return None,
    };
    v.is_finite().then_some(v)
}

/// (value, passed) of `m` over the runs where it is finite.
fn values(records: &[RunRecord], m: Metric) -> Vec<(f64, bool)> {
    records
        .iter()
        .filter_map(|r| {
            let v = r.outcome.as_ref()?.get(m)?;
            v.is_finite().then_some((v, r.passed()))
        })
        .collect()
}

/// The finite range of `values` and `extra`, padded by 5 % (±1 when flat, 0..1 when empty).
fn padded_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return (0.0, 1.0);
    }
    let span = hi - lo;
    if span <= 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
        let pad = if lo == 0.0 { 1.0 } else { 0.01 * lo.abs() };
        return (lo - pad, hi + pad);
    }
    (lo - 0.05 * span, hi + 0.05 * span)
}

/// What the figures are drawn from.
struct Inputs<'a> {
    sc: &'a Scenario,
    fields: &'a [&'a str],
    records: &'a [RunRecord],
    title: String,
}

/// One figure of the campaign.
#[derive(Clone, Copy)]
enum Kind {
    /// The outcomes' histograms.
    Histograms,
    /// One outcome against every dispersed input.
    Scatter(Metric),
}

/// The file names of every figure a campaign may draw.
pub fn figure_names() -> Vec<String> {
    let mut names = png_and_svg("mc_histograms").to_vec();
    for m in SCATTER_METRICS {
        names.extend(png_and_svg(&format!("mc_scatter_{}", m.name())));
    }
    names
}

/// Writes every figure into `out`; returns the paths written.
pub fn write_figures(
    out: &mut OutputSet,
    sc: &Scenario,
    fields: &[&str],
    records: &[RunRecord],
) -> anyhow::Result<Vec<PathBuf>> {
    crate::plots::check_font()?;
    let cx = Inputs {
        sc,
        fields,
        records,
        title: format!("{} runs of `{}`", records.len(), sc.name),
    };
    let mut written = Vec::new();
    let rows = HISTOGRAM_METRICS.len().div_ceil(2) as u32;
    written.extend(write_png_and_svg(
        out,
        "mc_histograms",
        (1400, 60 + 320 * rows),
        &(&cx, Kind::Histograms),
    )?);
    if !fields.is_empty() {
        let rows = fields.len().div_ceil(SCATTER_COLUMNS) as u32;
        for m in SCATTER_METRICS {
            let stem = format!("mc_scatter_{}", m.name());
            written.extend(write_png_and_svg(
                out,
                &stem,
                (1500, 60 + 360 * rows),
                &(&cx, Kind::Scatter(m)),
            )?);
        }
    }
    Ok(written)
}

impl Figure for (&Inputs<'_>, Kind) {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()> {
        let (cx, kind) = *self;
        match kind {
            Kind::Histograms => histograms(root, cx.sc, cx.records, &cx.title),
            Kind::Scatter(m) => scatter(root, cx.sc, cx.fields, cx.records, m, &cx.title),
        }
    }
}

fn histograms<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    sc: &Scenario,
    records: &[RunRecord],
    title: &str,
) -> anyhow::Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            &format!("{title}: outcomes (blue: pass, red: fail; dashed: criterion)"),
            (FONT, 24),
        )
        .map_err(err)?;
    let rows = HISTOGRAM_METRICS.len().div_ceil(2);
    for (area, &m) in root.split_evenly((rows, 2)).iter().zip(&HISTOGRAM_METRICS) {
        histogram(area, m, &values(records, m), limit(sc, m)).map_err(err)?;
    }
    Ok(())
}

fn histogram<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    m: Metric,
    vals: &[(f64, bool)],
    limit: Option<f64>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (x0, x1) = padded_range(vals.iter().map(|v| v.0).chain(limit));
    let width = (x1 - x0) / HISTOGRAM_BINS as f64;
    let bin = |x: f64| (((x - x0) / width) as usize).min(HISTOGRAM_BINS - 1);
    let mut all = [0u32; HISTOGRAM_BINS];
    let mut fail = [0u32; HISTOGRAM_BINS];
    for &(v, passed) in vals {
        all[bin(v)] += 1;
        if !passed {
            fail[bin(v)] += 1;
        }
    }
    let top = f64::from(all.iter().copied().max().unwrap_or(0).max(1)) * 1.1;
    let caption = format!("{} [{}]", m.label(), m.name());
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FONT, 18))
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(56)
        .build_cartesian_2d(x0..x1, 0.0..top)?;
    chart
        .configure_mesh()
        .y_desc("runs")
        .x_labels(6)
        .x_label_formatter(&|x| tick_label(*x, x1 - x0))
        // Whole runs: no more labels than whole numbers up to the top, so none repeats.
        .y_labels((top.floor() as usize + 1).min(10))
        .y_label_formatter(&|y| format!("{y:.0}"))
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .light_line_style(RGBColor(0xee, 0xee, 0xee))
        .draw()?;
    let bars = |counts: [u32; HISTOGRAM_BINS], color: RGBColor| {
        counts
            .into_iter()
            .enumerate()
            .filter(|(_, c)| *c > 0)
            .map(move |(i, c)| {
                let a = x0 + i as f64 * width;
                Rectangle::new(
                    [(a, 0.0), (a + width, f64::from(c))],
                    color.mix(0.8).filled(),
                )
            })
    };
    chart.draw_series(bars(all, PASS_COLOR))?;
    chart.draw_series(bars(fail, FAIL_COLOR))?;
    if let Some(x) = limit {
        chart.draw_series(DashedLineSeries::new(
            [(x, 0.0), (x, top)],
            6,
            4,
            LIMIT_COLOR.stroke_width(2),
        ))?;
    }
    if vals.is_empty() {
        area.draw_text(
            "not defined in any run",
            &(FONT, 16).into_text_style(area),
            (80, 80),
        )?;
    }
    Ok(())
}

fn scatter<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    sc: &Scenario,
    fields: &[&str],
    records: &[RunRecord],
    m: Metric,
    title: &str,
) -> anyhow::Result<()> {
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            &format!(
                "{title}: {} against each dispersed input (blue: pass, red: fail)",
                m.name()
            ),
            (FONT, 24),
        )
        .map_err(err)?;
    let rows = fields.len().div_ceil(SCATTER_COLUMNS);
    let lim = limit(sc, m);
    for (i, (area, field)) in root
        .split_evenly((rows, SCATTER_COLUMNS))
        .iter()
        .zip(fields)
        .enumerate()
    {
        let pts: Vec<(f64, f64, bool)> = records
            .iter()
            .filter_map(|r| {
                let y = r.outcome.as_ref()?.get(m)?;
                let x = r.inputs[i];
                (x.is_finite() && y.is_finite()).then_some((x, y, r.passed()))
            })
            .collect();
        scatter_panel(area, field, m, &pts, lim).map_err(err)?;
    }
    Ok(())
}

fn scatter_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    field: &str,
    m: Metric,
    pts: &[(f64, f64, bool)],
    limit: Option<f64>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (x0, x1) = padded_range(pts.iter().map(|p| p.0));
    let (y0, y1) = padded_range(pts.iter().map(|p| p.1).chain(limit));
    let mut chart = ChartBuilder::on(area)
        .caption(field, (FONT, 17))
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .y_desc(m.name())
        .x_labels(5)
        .y_labels(6)
        .x_label_formatter(&|x| tick_label(*x, x1 - x0))
        .y_label_formatter(&|y| tick_label(*y, y1 - y0))
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .light_line_style(RGBColor(0xee, 0xee, 0xee))
        .draw()?;
    for (passed, color) in [(true, PASS_COLOR), (false, FAIL_COLOR)] {
        chart.draw_series(
            pts.iter()
                .filter(|p| p.2 == passed)
                .map(|p| Circle::new((p.0, p.1), 2, color.mix(0.7).filled())),
        )?;
    }
    if let Some(y) = limit {
        chart.draw_series(DashedLineSeries::new(
            [(x0, y), (x1, y)],
            6,
            4,
            LIMIT_COLOR.stroke_width(2),
        ))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A histogram of a few runs labels each whole count once: with ticks at halves written as
    /// whole numbers, its count axis would read 0, 0, 1, 1.
    #[test]
    fn a_histogram_s_count_labels_do_not_repeat() {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (500, 300)).into_drawing_area();
            let vals = [(100.0, true), (200.0, true), (300.0, false)];
            histogram(&root, HISTOGRAM_METRICS[0], &vals, None).unwrap();
            root.present().unwrap();
        }
        for label in ["0", "1"] {
            let n = svg.matches(&format!(">{label}</text>")).count();
            assert!(n <= 1, "label {label} appears {n} times");
        }
    }
}
