//! Plots of `tss-sim extent`: Fig. 3 (extent and θ* against e) and Fig. 2 (Depl and Retr
//! against θ for a family of e), as PNG and SVG.
//!
//! Fig. 2 of the paper is a pair of 3-D surfaces; a family of curves, one per e, shows the same
//! data more readably, with each curve's extremum θ* marked.

use std::path::PathBuf;

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;

use crate::output::OutputSet;
use crate::plots::{draw_error, png_and_svg, tick_label, write_png_and_svg, FONT};

/// One row of Fig. 3: the whole-orbit bounds of Eq. 13 at one e.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ExtentRow {
    /// e.
    pub eccentricity: f64,
    /// min_θ Depl(e, θ).
    pub min_depl: f64,
    /// θ* of min Depl, rad.
    pub theta_star_depl_rad: f64,
    /// θ* of min Depl, deg.
    pub theta_star_depl_deg: f64,
    /// max_θ Retr(e, θ) (= −min Depl).
    pub max_retr: f64,
    /// θ* of max Retr, rad (= −θ* of min Depl).
    pub theta_star_retr_rad: f64,
    /// θ* of max Retr, deg.
    pub theta_star_retr_deg: f64,
    /// Root-finder iterations.
    pub iterations: u32,
    /// Whether an equilibrium can exist at every θ for some rate (min Depl ≥ 0, i.e. e ≤ 0.75).
    pub exists_whole_orbit: bool,
}

/// Pixel size of Fig. 3 (two panels side by side).
pub const FIG3_SIZE_PX: (u32, u32) = (1400, 620);
/// Pixel size of Fig. 2 (two panels stacked).
pub const FIG2_SIZE_PX: (u32, u32) = (1200, 1000);
/// File stem of Fig. 3.
pub const FIG3_STEM: &str = "fig3_extent";
/// File stem of Fig. 2.
pub const FIG2_STEM: &str = "fig2_depl_retr";
/// Most curves in the Fig. 2 family (picked evenly from the e values).
pub const MAX_FAMILY: usize = 7;

const DEPL_COLOR: RGBColor = RGBColor(0x1f, 0x77, 0xb4);
const RETR_COLOR: RGBColor = RGBColor(0xd6, 0x27, 0x28);
const PALETTE: [RGBColor; MAX_FAMILY] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0x17, 0xbe, 0xcf),
];

type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// The file names of the figures.
pub fn figure_names() -> Vec<String> {
    [FIG3_STEM, FIG2_STEM]
        .iter()
        .flat_map(|s| png_and_svg(s))
        .collect()
}

/// Writes Fig. 3 and Fig. 2 into `out` as PNG and SVG; returns the paths written.
pub fn write_extent_plots(
    out: &mut OutputSet,
    rows: &[ExtentRow],
    thetas: &[f64],
) -> anyhow::Result<Vec<PathBuf>> {
    crate::plots::check_font()?;
    let family = pick_family(rows);
    let mut written = write_png_and_svg(out, FIG3_STEM, FIG3_SIZE_PX, &Figure::Extent(rows))?;
    written.extend(write_png_and_svg(
        out,
        FIG2_STEM,
        FIG2_SIZE_PX,
        &Figure::Surfaces(&family, thetas),
    )?);
    Ok(written)
}

/// What to draw.
enum Figure<'a> {
    /// Fig. 3 from its rows.
    Extent(&'a [ExtentRow]),
    /// Fig. 2 for a family of rows on a θ grid.
    Surfaces(&'a [ExtentRow], &'a [f64]),
}

impl crate::plots::Figure for Figure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()> {
        match self {
            Figure::Extent(rows) => draw_fig3(root, rows),
            Figure::Surfaces(family, thetas) => draw_fig2(root, family, thetas),
        }
        .map_err(draw_error)
    }
}

/// At most [`MAX_FAMILY`] rows, evenly spread, always with the first and the last.
pub fn pick_family(rows: &[ExtentRow]) -> Vec<ExtentRow> {
    if rows.len() <= MAX_FAMILY {
        return rows.to_vec();
    }
    let last = rows.len() - 1;
    let mut idx: Vec<usize> = (0..MAX_FAMILY)
        .map(|i| (i * last + (MAX_FAMILY - 1) / 2) / (MAX_FAMILY - 1))
        .collect();
    idx.dedup();
    idx.into_iter()
        .filter_map(|i| rows.get(i).copied())
        .collect()
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !(lo.is_finite() && hi.is_finite()) {
        return (-1.0, 1.0);
    }
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad, hi + pad)
}

fn draw_fig3<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[ExtentRow],
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(FIG3_SIZE_PX.0 / 2);
    let (e0, e1) = range(rows.iter().map(|r| r.eccentricity));
    let (y0, y1) = range(rows.iter().flat_map(|r| [r.min_depl, r.max_retr]));

    let mut chart = ChartBuilder::on(&left)
        .caption(
            "Fig. 3: extent of the equilibrium conditions (Eq. 13)",
            (FONT, 22),
        )
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(e0..e1, y0..y1)?;
    chart
        .configure_mesh()
        .x_desc("orbit eccentricity e (-)")
        .y_desc("(2+mu3) ldot/(omega l) bound (-)")
        .x_label_formatter(&|x| tick_label(*x, e1 - e0))
        .y_label_formatter(&|y| tick_label(*y, y1 - y0))
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 18))
        .light_line_style(RGBColor(0xee, 0xee, 0xee))
        .draw()?;
    chart.draw_series(LineSeries::new([(e0, 0.0), (e1, 0.0)], BLACK.mix(0.4)))?;
    for (label, color, pick) in [
        ("min Depl: deploying needs 0 < x <= this", DEPL_COLOR, 0),
        ("max Retr: retrieving needs this <= x < 0", RETR_COLOR, 1),
    ] {
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .map(|r| {
                (
                    r.eccentricity,
                    if pick == 0 { r.min_depl } else { r.max_retr },
                )
            })
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], color.stroke_width(2)));
        chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 15))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;

    let (t0, t1) = range(
        rows.iter()
            .flat_map(|r| [r.theta_star_depl_deg, r.theta_star_retr_deg]),
    );
    let mut chart = ChartBuilder::on(&right)
        .caption("True anomaly theta* of the extremum", (FONT, 22))
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(e0..e1, t0..t1)?;
    chart
        .configure_mesh()
        .x_desc("orbit eccentricity e (-)")
        .y_desc("theta* (deg)")
        .x_label_formatter(&|x| tick_label(*x, e1 - e0))
        .y_label_formatter(&|t| tick_label(*t, t1 - t0))
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 18))
        .light_line_style(RGBColor(0xee, 0xee, 0xee))
        .draw()?;
    for (label, color, pick) in [
        ("theta* of min Depl", DEPL_COLOR, 0),
        ("theta* of max Retr", RETR_COLOR, 1),
    ] {
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .map(|r| {
                let t = if pick == 0 {
                    r.theta_star_depl_deg
                } else {
                    r.theta_star_retr_deg
                };
                (r.eccentricity, t)
            })
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], color.stroke_width(2)));
        chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::MiddleRight)
        .label_font((FONT, 15))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

fn draw_fig2<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    family: &[ExtentRow],
    thetas: &[f64],
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let (top, bottom) = root.split_vertically(FIG2_SIZE_PX.1 / 2);
    let panels: [(&DrawingArea<DB, Shift>, &str, &str, bool); 2] = [
        (
            &top,
            "Fig. 2a: Depl(e, theta) = F1/(1-e^2)^1.5 (dots: min over theta)",
            "Depl (-)",
            true,
        ),
        (
            &bottom,
            "Fig. 2b: Retr(e, theta) = F2/(1-e^2)^1.5 (dots: max over theta)",
            "Retr (-)",
            false,
        ),
    ];
    for (area, caption, y_desc, deploy) in panels {
        let f = |e: f64, th: f64| {
            if deploy {
                tss_reel::equilibrium::depl(e, th)
            } else {
                tss_reel::equilibrium::retr(e, th)
            }
        };
        let (y0, y1) = range(
            family
                .iter()
                .flat_map(|r| thetas.iter().map(move |&th| f(r.eccentricity, th))),
        );
        let mut chart = ChartBuilder::on(area)
            .caption(caption, (FONT, 22))
            .margin(16)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(-180.0..180.0, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc("true anomaly theta (deg)")
            .y_desc(y_desc)
            .x_labels(9)
            .y_label_formatter(&|y| tick_label(*y, y1 - y0))
            .label_style((FONT, 16))
            .axis_desc_style((FONT, 18))
            .light_line_style(RGBColor(0xee, 0xee, 0xee))
            .draw()?;
        for (r, color) in family.iter().zip(PALETTE.iter().cycle()) {
            let color = *color;
            let e = r.eccentricity;
            chart
                .draw_series(LineSeries::new(
                    thetas.iter().map(|&th| (th.to_degrees(), f(e, th))),
                    color.stroke_width(2),
                ))?
                .label(format!("e = {e:.3}"))
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 24, y)], color.stroke_width(2))
                });
            let (t, v) = if deploy {
                (r.theta_star_depl_deg, r.min_depl)
            } else {
                (r.theta_star_retr_deg, r.max_retr)
            };
            chart.draw_series([Circle::new((t, v), 5, color.filled())])?;
        }
        chart
            .configure_series_labels()
            .position(if deploy {
                SeriesLabelPosition::UpperLeft
            } else {
                SeriesLabelPosition::LowerRight
            })
            .label_font((FONT, 15))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
    }
    Ok(())
}
