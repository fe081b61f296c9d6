//! The paper's Figs. 4–6 drawn from a run, as PNG and SVG.
//!
//! - Fig. 4: tether length l (km) and tension T_t (N) against t (h), two panels.
//! - Fig. 5: (a) the reference angle α_r and (b) the in-plane angle α (deg) against t (h).
//! - Fig. 6: the same angles against l (km).
//! - On the elastic plant, the tether's shape ([`TetherShapes`], `tether_shape`): one curve per
//!   shape the run recorded (every `plant.shape_interval_s` and at the end), in the plane of the
//!   orbit relative to the main satellite: along-track e_θ against radial e_r (km), equal scales.
//!
//! Text is rendered with plotters' `ttf` feature, which finds a sans-serif system font through
//! fontconfig (DejaVu Sans on the project's Debian machines, package `fonts-dejavu-core`).
//! Long histories are thinned with a min/max envelope per bucket, so peaks survive.
//!
//! The set-up every figure of tss-sim shares (the Monte Carlo and `extent` figures too) is here:
//! the [`FONT`], the font check, and [`write_png_and_svg`] for any [`Figure`].

use std::path::PathBuf;

use anyhow::{anyhow, Context};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::history::{History, Sample};
use crate::output::OutputSet;
use crate::scenario::Scenario;

/// Seconds per hour.
const S_PER_H: f64 = 3600.0;
/// Metres per kilometre.
const M_PER_KM: f64 = 1000.0;
/// Pixel size of the two-panel figures.
pub const FIGURE_SIZE_PX: (u32, u32) = (1200, 900);
/// Points drawn per series at most (the rest is thinned, keeping each bucket's min and max).
pub const MAX_POINTS_PER_SERIES: usize = 4000;
/// Font family of every figure's text.
pub const FONT: &str = "sans-serif";

/// File stems of the figures, in order (each written as `.png` and `.svg`).
pub const FIGURE_STEMS: [&str; 3] = [
    "fig4_length_tension",
    "fig5_angles_time",
    "fig6_angles_length",
];

/// File stem of the tether's shape figure (elastic plant only).
pub const SHAPE_STEM: &str = "tether_shape";
/// File stem of the flight drive's figure (`reel.model = "flight_drive"` only).
pub const DRIVE_STEM: &str = "flight_drive";
/// Pixel size of the shape figure (square: its two axes share one scale).
pub const SHAPE_FIGURE_SIZE_PX: (u32, u32) = (1000, 1000);
/// Legend entries of the shape figure at most (the other curves are drawn unlabelled; their
/// colour runs from blue, early, to red, late).
pub const MAX_SHAPE_LABELS: usize = 8;

const LENGTH_COLOR: RGBColor = RGBColor(0x1f, 0x77, 0xb4);
const TENSION_COLOR: RGBColor = RGBColor(0xd6, 0x27, 0x28);
const ALPHA_COLOR: RGBColor = RGBColor(0x1f, 0x77, 0xb4);
const ALPHA_REF_COLOR: RGBColor = RGBColor(0xff, 0x7f, 0x0e);
const STAGE_LINE_COLOR: RGBColor = RGBColor(0x99, 0x99, 0x99);

/// One curve of a panel.
struct Curve {
    label: &'static str,
    color: RGBColor,
    dashed: bool,
    points: Vec<(f64, f64)>,
}

/// One panel: a caption, axis descriptions and its curves.
struct Panel {
    caption: String,
    x_desc: &'static str,
    y_desc: &'static str,
    curves: Vec<Curve>,
    /// x of a vertical marker (the stage-2 start), if inside the data.
    marker_x: Option<f64>,
}

/// Checks that the figures' text can be rendered: plotters' `ttf` backend needs a sans-serif
/// system font that fontconfig can find.
pub fn check_font() -> anyhow::Result<()> {
    FontDesc::new(FontFamily::from(FONT), 16.0, FontStyle::Normal)
        .box_size("α (deg)")
        .map(|_| ())
        .map_err(|e| {
            anyhow!(
                "no {FONT} font for the figures' text ({e}); install one that fontconfig finds, \
                 e.g. Debian's fonts-dejavu-core"
            )
        })
}

/// A figure drawn the same on every plotters backend (PNG and SVG).
pub trait Figure {
    /// Draws the figure on `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>;
}

/// A plotters drawing error as an [`anyhow::Error`].
pub fn draw_error<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> anyhow::Error {
    anyhow!("{e}")
}

/// The file names of a figure: `<stem>.png` and `<stem>.svg`.
pub fn png_and_svg(stem: &str) -> [String; 2] {
    [format!("{stem}.png"), format!("{stem}.svg")]
}

/// Draws `figure` (`size` pixels) into `<stem>.png` and `<stem>.svg` of `out`; returns their
/// final paths.
pub fn write_png_and_svg(
    out: &mut OutputSet,
    stem: &str,
    size: (u32, u32),
    figure: &impl Figure,
) -> anyhow::Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for name in png_and_svg(stem) {
        let tmp = out.stage(&name);
        let drawn = if name.ends_with(".svg") {
            let root = SVGBackend::new(&tmp, size).into_drawing_area();
            figure
                .draw(&root)
                .and_then(|()| root.present().map_err(draw_error))
        } else {
            let root = BitMapBackend::new(&tmp, size).into_drawing_area();
            figure
                .draw(&root)
                .and_then(|()| root.present().map_err(draw_error))
        };
        drawn.with_context(|| format!("drawing {name}"))?;
        written.push(out.dir().join(&name));
    }
    Ok(written)
}

/// The file names of the run's figures (the shape figure's too: a rigid run removes an
/// earlier elastic run's).
pub fn figure_names() -> Vec<String> {
    FIGURE_STEMS
        .iter()
        .chain([&SHAPE_STEM, &DRIVE_STEM])
        .flat_map(|s| png_and_svg(s))
        .collect()
}

/// What [`write_figures`] draws for this run, in words: Figs. 4–6, and the flight drive's
/// figure and the tether's shape when the run has them.
pub fn figures_heading(scenario: &Scenario, history: &History) -> String {
    let mut parts = vec!["Figs. 4–6 of the paper".to_string()];
    if drive_panels(scenario, history).is_some() {
        parts.push("the flight drive's rate and duty".to_string());
    }
    if !history.shapes.is_empty() {
        parts.push("the tether's shape on the elastic plant".to_string());
    }
    parts.join("; ")
}

/// A figure of panels stacked vertically.
struct Panels(Vec<Panel>);

impl Figure for Panels {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()> {
        draw(root, &self.0)
    }
}

/// Writes the three figures into `out` as PNG and SVG; returns the paths written.
pub fn write_figures(
    out: &mut OutputSet,
    scenario: &Scenario,
    history: &History,
) -> anyhow::Result<Vec<PathBuf>> {
    check_font()?;
    let figures = figures(scenario, &history.samples);
    let mut written = Vec::new();
    for (stem, panels) in FIGURE_STEMS.iter().zip(figures) {
        written.extend(write_png_and_svg(
            out,
            stem,
            FIGURE_SIZE_PX,
            &Panels(panels),
        )?);
    }
    if let Some(panels) = drive_panels(scenario, history) {
        written.extend(write_png_and_svg(
            out,
            DRIVE_STEM,
            FIGURE_SIZE_PX,
            &Panels(panels),
        )?);
    }
    if !history.shapes.is_empty() {
        let shapes = TetherShapes {
            caption: format!(
                "Tether shape in the orbit plane — scenario {}",
                scenario.name
            ),
            shapes: history.shapes.clone(),
        };
        written.extend(write_png_and_svg(
            out,
            SHAPE_STEM,
            SHAPE_FIGURE_SIZE_PX,
            &shapes,
        )?);
    }
    Ok(written)
}

/// The flight drive's figure: the drum's surface rate against the law's command, and the
/// speed loop's duty, at the output samples (the last inner tick's); `None` without the drive.
fn drive_panels(scenario: &Scenario, history: &History) -> Option<Vec<Panel>> {
    if !history.elastic.iter().any(|e| e.drive.is_some()) {
        return None;
    }
    let t_h = |s: &Sample| s.t_s / S_PER_H;
    let pairs = || history.samples.iter().zip(&history.elastic);
    let command = thin(pairs().map(|(s, _)| (t_h(s), s.length_rate_mps)).collect());
    let drum = thin(pairs().map(|(s, e)| (t_h(s), e.reel_rate_mps)).collect());
    let duty = thin(
        pairs()
            .filter_map(|(s, e)| e.drive.map(|d| (t_h(s), d.duty)))
            .collect(),
    );
    Some(vec![
        Panel {
            caption: format!(
                "Flight drive: drum rate vs command — scenario {}",
                scenario.name
            ),
            x_desc: "t (h)",
            y_desc: "l̇ (m/s)",
            curves: vec![
                Curve {
                    label: "command",
                    color: ALPHA_REF_COLOR,
                    dashed: true,
                    points: command,
                },
                Curve {
                    label: "drum",
                    color: LENGTH_COLOR,
                    dashed: false,
                    points: drum,
                },
            ],
            marker_x: None,
        },
        Panel {
            caption: "Flight drive: speed-loop duty".to_string(),
            x_desc: "t (h)",
            y_desc: "duty",
            curves: vec![Curve {
                label: "duty",
                color: TENSION_COLOR,
                dashed: false,
                points: duty,
            }],
            marker_x: None,
        },
    ])
}

/// The tether's shape at some instants, in the plane of the orbit: along-track (e_θ) against
/// radial (e_r), km, relative to the main satellite, both axes on one scale; one curve per
/// instant, its nodes (main satellite, beads, sub-satellite) as vertices.
pub struct TetherShapes {
    /// The figure's caption.
    pub caption: String,
    /// (t in s, node positions (e_r, e_θ, e_h) in m), as `History::shapes` holds them.
    pub shapes: Vec<(f64, Vec<[f64; 3]>)>,
}

impl TetherShapes {
    /// Each shape's (along-track, radial) vertices in km, the finite ones.
    fn curves(&self) -> Vec<(f64, Vec<(f64, f64)>)> {
        self.shapes
            .iter()
            .map(|(t_s, nodes)| {
                let points = nodes
                    .iter()
                    .map(|n| (n[1] / M_PER_KM, n[0] / M_PER_KM))
                    .filter(|p| p.0.is_finite() && p.1.is_finite())
                    .collect();
                (*t_s, points)
            })
            .collect()
    }
}

/// The colour of curve `i` of `n`: hue from blue (first) to red (last).
fn time_color(i: usize, n: usize) -> HSLColor {
    let late = if n > 1 {
        i as f64 / (n - 1) as f64
    } else {
        0.0
    };
    HSLColor(0.62 * (1.0 - late), 0.8, 0.42)
}

impl Figure for TetherShapes {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()> {
        root.fill(&WHITE).map_err(draw_error)?;
        let curves = self.curves();
        let all = || curves.iter().flat_map(|c| c.1.iter()).chain([&(0.0, 0.0)]);
        let (x0, x1) = padded_range(all().map(|p| p.0));
        let (y0, y1) = padded_range(all().map(|p| p.1));
        // One scale on both axes: widen the narrower range about its centre.
        let half = 0.5 * (x1 - x0).max(y1 - y0);
        let (xc, yc) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
        let mut chart = ChartBuilder::on(root)
            .caption(&self.caption, (FONT, 22))
            .margin(14)
            .x_label_area_size(48)
            .y_label_area_size(80)
            .build_cartesian_2d(xc - half..xc + half, yc - half..yc + half)
            .map_err(draw_error)?;
        let span = 2.0 * half;
        chart
            .configure_mesh()
            .x_desc("along-track e_θ (km)")
            .y_desc("radial e_r (km)")
            .x_label_formatter(&|x| tick_label(*x, span))
            .y_label_formatter(&|y| tick_label(*y, span))
            .label_style((FONT, 16))
            .axis_desc_style((FONT, 18))
            .light_line_style(RGBColor(0xee, 0xee, 0xee))
            .draw()
            .map_err(draw_error)?;
        let n = curves.len();
        let every = n.div_ceil(MAX_SHAPE_LABELS).max(1);
        for (i, (t_s, points)) in curves.iter().enumerate() {
            let color = time_color(i, n);
            let drawn = chart
                .draw_series(LineSeries::new(
                    points.iter().copied(),
                    color.stroke_width(2),
                ))
                .map_err(draw_error)?;
            if i % every == 0 || i + 1 == n {
                drawn
                    .label(format!("t = {:.2} h", t_s / S_PER_H))
                    .legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 24, y)], color.stroke_width(2))
                    });
            }
        }
        chart
            .draw_series([Circle::new((0.0, 0.0), 5, BLACK.filled())])
            .map_err(draw_error)?
            .label("main satellite")
            .legend(|(x, y)| Circle::new((x + 12, y), 4, BLACK.filled()));
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font((FONT, 16))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(draw_error)?;
        Ok(())
    }
}

/// The panels of Figs. 4, 5 and 6.
fn figures(scenario: &Scenario, samples: &[Sample]) -> [Vec<Panel>; 3] {
    let name = &scenario.name;
    let t_h = |s: &Sample| s.t_s / S_PER_H;
    let l_km = |s: &Sample| s.length_m / M_PER_KM;
    let series = |x: &dyn Fn(&Sample) -> f64, y: &dyn Fn(&Sample) -> f64| -> Vec<(f64, f64)> {
        thin(samples.iter().map(|s| (x(s), y(s))).collect())
    };
    let end_h = samples.last().map_or(0.0, t_h);
    let stage2_h = scenario.stage2.start_time_s / S_PER_H;
    let marker = (stage2_h > 0.0 && stage2_h < end_h).then_some(stage2_h);
    let alpha_ref = |x: &dyn Fn(&Sample) -> f64, dashed: bool| Curve {
        label: "α_r (reference)",
        color: ALPHA_REF_COLOR,
        dashed,
        points: series(x, &|s| s.alpha_ref_rad.to_degrees()),
    };
    let alpha = |x: &dyn Fn(&Sample) -> f64| Curve {
        label: "α (actual)",
        color: ALPHA_COLOR,
        dashed: false,
        points: series(x, &|s| s.alpha_rad.to_degrees()),
    };
    let fig4 = vec![
        Panel {
            caption: format!("Fig. 4 (a): tether length — scenario {name}"),
            x_desc: "t (h)",
            y_desc: "l (km)",
            curves: vec![Curve {
                label: "l",
                color: LENGTH_COLOR,
                dashed: false,
                points: series(&t_h, &l_km),
            }],
            marker_x: marker,
        },
        Panel {
            caption: "Fig. 4 (b): tether tension".to_string(),
            x_desc: "t (h)",
            y_desc: "T_t (N)",
            curves: vec![Curve {
                label: "T_t",
                color: TENSION_COLOR,
                dashed: false,
                points: series(&t_h, &|s| s.tension_n),
            }],
            marker_x: marker,
        },
    ];
    let fig5 = vec![
        Panel {
            caption: format!("Fig. 5 (a): reference in-plane angle — scenario {name}"),
            x_desc: "t (h)",
            y_desc: "α_r (deg)",
            curves: vec![alpha_ref(&t_h, false)],
            marker_x: marker,
        },
        Panel {
            caption: "Fig. 5 (b): actual in-plane angle".to_string(),
            x_desc: "t (h)",
            y_desc: "α (deg)",
            curves: vec![alpha(&t_h), alpha_ref(&t_h, true)],
            marker_x: marker,
        },
    ];
    let fig6 = vec![
        Panel {
            caption: format!(
                "Fig. 6 (a): reference in-plane angle against length — scenario {name}"
            ),
            x_desc: "l (km)",
            y_desc: "α_r (deg)",
            curves: vec![alpha_ref(&l_km, false)],
            marker_x: None,
        },
        Panel {
            caption: "Fig. 6 (b): actual in-plane angle against length".to_string(),
            x_desc: "l (km)",
            y_desc: "α (deg)",
            curves: vec![alpha(&l_km), alpha_ref(&l_km, true)],
            marker_x: None,
        },
    ];
    [fig4, fig5, fig6]
}

/// Thins a long series to at most [`MAX_POINTS_PER_SERIES`] points, keeping the min and max `y`
/// of each bucket (in their original order) and the last point.
fn thin(points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    let n = points.len();
    if n <= MAX_POINTS_PER_SERIES {
        return points;
    }
    let buckets = MAX_POINTS_PER_SERIES / 2 - 1;
    let per = n.div_ceil(buckets);
    let mut out = Vec::with_capacity(MAX_POINTS_PER_SERIES);
    for chunk in points.chunks(per) {
        let (mut lo, mut hi) = (0, 0);
        for (i, p) in chunk.iter().enumerate() {
            if p.1 < chunk[lo].1 {
                lo = i;
            }
            if p.1 > chunk[hi].1 {
                hi = i;
            }
        }
        let (a, b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        out.push(chunk[a]);
        if b != a {
            out.push(chunk[b]);
        }
    }
    if let (Some(&last), Some(&kept)) = (points.last(), out.last()) {
        if kept != last {
            out.push(last);
        }
    }
    out
}

/// The finite range of `values`, padded by 5 % (±1 when flat, 0..1 when empty).
fn padded_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return (0.0, 1.0);
    }
    if hi - lo <= f64::EPSILON * hi.abs().max(1.0) {
        return (lo - 1.0, hi + 1.0);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// A tick's label on an axis spanning `span`: 0 for a tick within 10⁻⁹ of the span of zero
/// (the axis' round numbers carry the float error of their sum: −1.7e-21 is 0), else the
/// value to 6 significant digits, written as short as it reads back.
pub fn tick_label(value: f64, span: f64) -> String {
    if value.abs() <= 1e-9 * span.abs() {
        return "0".to_string();
    }
    let rounded: f64 = format!("{value:.5e}").parse().unwrap_or(value);
    format!("{rounded}")
}

/// Draws the panels stacked vertically on `root`.
fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, panels: &[Panel]) -> anyhow::Result<()> {
    root.fill(&WHITE).map_err(draw_error)?;
    let areas = root.split_evenly((panels.len(), 1));
    for (area, panel) in areas.iter().zip(panels) {
        draw_panel(area, panel).map_err(draw_error)?;
    }
    Ok(())
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let all = || panel.curves.iter().flat_map(|c| c.points.iter());
    let (x0, x1) = padded_range(all().map(|p| p.0));
    let (y0, y1) = padded_range(all().map(|p| p.1));
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.caption, (FONT, 22))
        .margin(14)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    let (x_span, y_span) = (x1 - x0, y1 - y0);
    chart
        .configure_mesh()
        .x_desc(panel.x_desc)
        .y_desc(panel.y_desc)
        .x_label_formatter(&|x| tick_label(*x, x_span))
        .y_label_formatter(&|y| tick_label(*y, y_span))
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 18))
        .light_line_style(RGBColor(0xee, 0xee, 0xee))
        .draw()?;
    if let Some(x) = panel.marker_x {
        chart
            .draw_series(DashedLineSeries::new(
                [(x, y0), (x, y1)],
                4,
                6,
                STAGE_LINE_COLOR.stroke_width(1),
            ))?
            .label("stage 2 starts")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 24, y)], STAGE_LINE_COLOR));
    }
    let width_px = area.dim_in_pixel().0 as usize;
    for curve in &panel.curves {
        let color = curve.color;
        let finite = curve
            .points
            .iter()
            .copied()
            .filter(|p| p.0.is_finite() && p.1.is_finite());
        // More points than pixels across: the segments are shorter than a pixel, and plotters'
        // bitmap rasterizer fills such 2 px segments as polygons that spike out of the panel
        // (the elastic Fig. 4(b)); one pixel is as wide as the curve can be drawn there anyway.
        let stroke = if curve.points.len() > width_px { 1 } else { 2 };
        let drawn = if curve.dashed {
            chart.draw_series(DashedLineSeries::new(
                finite,
                8,
                6,
                color.stroke_width(stroke),
            ))?
        } else {
            chart.draw_series(LineSeries::new(finite, color.stroke_width(stroke)))?
        };
        drawn
            .label(curve.label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], color.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 16))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thinning_keeps_extremes_and_bounds_the_count() {
        let mut pts: Vec<(f64, f64)> = (0..100_000).map(|i| (i as f64, 0.0)).collect();
        pts[54_321].1 = 7.0;
        pts[12_345].1 = -3.0;
        let thin = thin(pts.clone());
        assert!(thin.len() <= MAX_POINTS_PER_SERIES);
        assert!(thin.contains(&(54_321.0, 7.0)));
        assert!(thin.contains(&(12_345.0, -3.0)));
        assert_eq!(thin.last(), pts.last());
        assert!(thin.windows(2).all(|w| w[0].0 < w[1].0));
    }

    /// A tick at the float error of zero read "-1.69407e-21" on an axis from −0.1 to 0.1.
    #[test]
    fn tick_labels_are_round_and_zero_is_zero() {
        assert_eq!(tick_label(-1.694_07e-21, 0.2), "0");
        assert_eq!(tick_label(0.1 + 0.2, 1.0), "0.3");
        assert_eq!(tick_label(40_000.0, 50_000.0), "40000");
        assert_eq!(tick_label(2.5e-5, 1e-4), "0.000025");
    }

    /// A curve stays inside its panel: the elastic Fig. 4(b), a tension jumping between 0 and
    /// 20 N from sample to sample, must not be drawn with spikes down to the bottom of the
    /// image, below the plot area.
    #[test]
    fn a_jumping_curve_stays_inside_its_panel() {
        let (w, h) = (600u32, 300u32);
        let mut buf = vec![0u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            root.fill(&WHITE).unwrap();
            let points = (0..4000)
                .map(|i| (f64::from(i) / 200.0, if i % 7 < 3 { 0.0 } else { 20.0 }))
                .collect();
            let panel = Panel {
                caption: "tension".to_string(),
                x_desc: "t (h)",
                y_desc: "T (N)",
                curves: vec![Curve {
                    label: "T",
                    color: TENSION_COLOR,
                    dashed: false,
                    points,
                }],
                marker_x: None,
            };
            draw_panel(&root, &panel).unwrap();
            root.present().unwrap();
        }
        // The bottom rows hold the x axis' description (black) and nothing red.
        let red = |x: u32, y: u32| {
            let i = ((y * w + x) * 3) as usize;
            buf[i] > 0xa0 && buf[i + 1] < 0x60 && buf[i + 2] < 0x60
        };
        let below: usize = (h - 20..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter(|&(x, y)| red(x, y))
            .count();
        assert_eq!(below, 0, "red pixels below the plot area");
    }

    #[test]
    fn ranges_are_padded_and_never_empty() {
        assert_eq!(padded_range([].into_iter()), (0.0, 1.0));
        assert_eq!(padded_range([2.0, 2.0].into_iter()), (1.0, 3.0));
        let (lo, hi) = padded_range([0.0, 10.0, f64::NAN].into_iter());
        assert!((lo + 0.5).abs() < 1e-12 && (hi - 10.5).abs() < 1e-12);
    }
}
