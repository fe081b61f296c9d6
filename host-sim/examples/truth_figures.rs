//! The figures and figures-of-merit of `docs/truth-model.md`: the paper's mission flown by the
//! rigid plant (`scenarios/paper.toml`) and by the truth model (`scenarios/paper-elastic.toml`),
//! overlaid, written as PNG to `docs/figures/` (or the directory given as the first argument).
//!
//! `cargo run --release -p tss-sim --example truth_figures [DIR]`

use std::path::{Path, PathBuf};

use plotters::prelude::*;
use tss_sim::history::{History, PhaseLabel};
use tss_sim::plots::{Figure, TetherShapes, SHAPE_FIGURE_SIZE_PX};
use tss_sim::scenario::Scenario;
use tss_sim::table1::PAPER_TABLE1;

const FONT: &str = "sans-serif";
const BLUE: RGBColor = RGBColor(0x1f, 0x77, 0xb4);
const RED: RGBColor = RGBColor(0xd6, 0x27, 0x28);
const ORANGE: RGBColor = RGBColor(0xff, 0x7f, 0x0e);
const GREEN: RGBColor = RGBColor(0x2c, 0xa0, 0x2c);
const GREY: RGBColor = RGBColor(0x55, 0x55, 0x55);

struct Curve {
    label: String,
    color: RGBColor,
    points: Vec<(f64, f64)>,
}

struct Panel {
    caption: String,
    x_desc: String,
    y_desc: String,
    curves: Vec<Curve>,
}

fn curve(label: &str, color: RGBColor, points: Vec<(f64, f64)>) -> Curve {
    Curve {
        label: label.to_string(),
        color,
        points,
    }
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo >= hi {
        return (lo - 1.0, hi + 1.0);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

fn draw(path: &Path, panels: &[Panel], size: (u32, u32)) -> anyhow::Result<()> {
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE)?;
    for (area, p) in root.split_evenly((panels.len(), 1)).iter().zip(panels) {
        let all = || p.curves.iter().flat_map(|c| c.points.iter());
        let (x0, x1) = range(all().map(|q| q.0));
        let (y0, y1) = range(all().map(|q| q.1));
        let mut chart = ChartBuilder::on(area)
            .caption(&p.caption, (FONT, 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc(p.x_desc.as_str())
            .y_desc(p.y_desc.as_str())
            .label_style((FONT, 14))
            .light_line_style(RGBColor(0xee, 0xee, 0xee))
            .draw()?;
        for c in &p.curves {
            let color = c.color;
            chart
                .draw_series(LineSeries::new(
                    c.points.iter().copied(),
                    color.stroke_width(2),
                ))?
                .label(c.label.as_str())
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
    }
    root.present()?;
    Ok(())
}

fn load(name: &str) -> anyhow::Result<Scenario> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../scenarios/{name}.toml"));
    Ok(Scenario::load(&path, &[])?)
}

fn fly(sc: &Scenario) -> anyhow::Result<History> {
    let probes: Vec<f64> = PAPER_TABLE1.iter().map(|p| p.t_s).collect();
    Ok(tss_sim::sim::run(sc, &probes, &mut |_| {})?)
}

fn main() -> anyhow::Result<()> {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/figures"));
    std::fs::create_dir_all(&dir)?;
    let rigid = fly(&load("paper")?)?;
    let elastic_sc = load("paper-elastic")?;
    let started = std::time::Instant::now();
    let elastic = fly(&elastic_sc)?;
    println!(
        "paper-elastic flown in {:.2} s",
        started.elapsed().as_secs_f64()
    );
    let h = |t: f64| t / 3600.0;
    let rs = &rigid.samples;
    let es = &elastic.samples;
    let ee = &elastic.elastic;

    // Table 1 and where the law breaks, for the note.
    println!("Table 1 (m): t_h, paper, rigid, elastic");
    for ((p, r), e) in PAPER_TABLE1.iter().zip(&rigid.probes).zip(&elastic.probes) {
        println!("  {:.2} {:.3} {:.3} {:.3}", p.t_h, p.length_m, r.1, e.1);
    }
    for phase in [
        PhaseLabel::Deploy,
        PhaseLabel::Keep1,
        PhaseLabel::Slew,
        PhaseLabel::Retrieve,
        PhaseLabel::Keep2,
    ] {
        let rows: Vec<_> = es
            .iter()
            .zip(ee)
            .filter(|(s, _)| s.phase == phase)
            .collect();
        if rows.is_empty() {
            continue;
        }
        let slack = rows.iter().filter(|(s, _)| s.tension_n <= 0.0).count();
        let max_t = rows.iter().map(|(s, _)| s.tension_n).fold(0.0, f64::max);
        let max_bow = rows.iter().map(|(_, e)| e.bowing_m).fold(0.0, f64::max);
        let stretch = rows
            .iter()
            .map(|(s, e)| (e.range_m - s.length_m).abs())
            .fold(0.0, f64::max);
        let sensed = rows
            .iter()
            .map(|(s, e)| (e.alpha_sensed_rad - s.alpha_rad).abs())
            .fold(0.0, f64::max);
        println!(
            "{:>8}: {} samples, slack {} ({:.0} %), max T {:.2} N, max |range − l| {:.2} m, \
             max bowing {:.1} m, max |α_sensed − α_line| {:.2e} rad",
            phase.as_str(),
            rows.len(),
            slack,
            100.0 * slack as f64 / rows.len() as f64,
            max_t,
            stretch,
            max_bow,
            sensed
        );
    }

    let series_r = |f: &dyn Fn(&tss_sim::history::Sample) -> f64| -> Vec<(f64, f64)> {
        rs.iter().map(|s| (h(s.t_s), f(s))).collect()
    };
    let series_e = |f: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        (0..es.len()).map(|i| (h(es[i].t_s), f(i))).collect()
    };
    let x = "t (h)".to_string();
    draw(
        &dir.join("truth_length_tension.png"),
        &[
            Panel {
                caption: "Length: rigid plant (paper.toml) and truth model (paper-elastic.toml)"
                    .into(),
                x_desc: x.clone(),
                y_desc: "km".into(),
                curves: vec![
                    curve("rigid l", GREY, series_r(&|s| s.length_m / 1e3)),
                    curve(
                        "elastic paid out",
                        BLUE,
                        series_e(&|i| es[i].length_m / 1e3),
                    ),
                    curve("elastic range", ORANGE, series_e(&|i| ee[i].range_m / 1e3)),
                ],
            },
            Panel {
                caption: "Tension".into(),
                x_desc: x.clone(),
                y_desc: "N".into(),
                curves: vec![
                    curve("elastic at the reel", BLUE, series_e(&|i| es[i].tension_n)),
                    curve(
                        "elastic at the tip",
                        ORANGE,
                        series_e(&|i| ee[i].tension_tip_n),
                    ),
                    curve("rigid (Eq. 5a)", GREY, series_r(&|s| s.tension_n)),
                ],
            },
            Panel {
                caption: "Stretch (range − paid out) and bowing".into(),
                x_desc: x.clone(),
                y_desc: "m".into(),
                curves: vec![
                    curve(
                        "range − paid out",
                        BLUE,
                        series_e(&|i| ee[i].range_m - es[i].length_m),
                    ),
                    curve("bowing", RED, series_e(&|i| ee[i].bowing_m)),
                ],
            },
        ],
        (1200, 1200),
    )?;
    draw(
        &dir.join("truth_angles.png"),
        &[
            Panel {
                caption: "In-plane angle: rigid, elastic (line), sensed, reference".into(),
                x_desc: x.clone(),
                y_desc: "α (deg)".into(),
                curves: vec![
                    curve(
                        "α_r (elastic run)",
                        GREEN,
                        series_e(&|i| es[i].alpha_ref_rad.to_degrees()),
                    ),
                    curve("rigid α", GREY, series_r(&|s| s.alpha_rad.to_degrees())),
                    curve(
                        "elastic α (line)",
                        BLUE,
                        series_e(&|i| es[i].alpha_rad.to_degrees()),
                    ),
                ],
            },
            Panel {
                caption: "Reel rate: commanded and actual (motor reel)".into(),
                x_desc: x.clone(),
                y_desc: "m/s".into(),
                curves: vec![
                    curve("rigid command", GREY, series_r(&|s| s.length_rate_mps)),
                    curve(
                        "elastic command",
                        BLUE,
                        series_e(&|i| es[i].length_rate_mps),
                    ),
                    curve("elastic reel", ORANGE, series_e(&|i| ee[i].reel_rate_mps)),
                ],
            },
        ],
        (1200, 900),
    )?;
    // The stage-2 keep, ten minutes: the slack–snap cycle.
    let window: Vec<usize> = (0..es.len())
        .filter(|&i| (60_000.0..=60_600.0).contains(&es[i].t_s))
        .collect();
    let zoom = |f: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        window.iter().map(|&i| (es[i].t_s, f(i))).collect()
    };
    draw(
        &dir.join("truth_keep2_zoom.png"),
        &[
            Panel {
                caption: "Stage-2 keep (2 km): paid out and range".into(),
                x_desc: "t (s)".into(),
                y_desc: "m".into(),
                curves: vec![
                    curve("paid out", BLUE, zoom(&|i| es[i].length_m)),
                    curve("range", ORANGE, zoom(&|i| ee[i].range_m)),
                ],
            },
            Panel {
                caption: "Tension at the reel".into(),
                x_desc: "t (s)".into(),
                y_desc: "N".into(),
                curves: vec![curve("T", RED, zoom(&|i| es[i].tension_n))],
            },
        ],
        (1200, 800),
    )?;
    // Shapes: along-track (e_θ) against radial (e_r), relative to the main satellite, drawn
    // as `tss-sim run` draws them (`plots::TetherShapes`), at six chosen instants.
    let picks = [7_200.0, 14_400.0, 28_800.0, 29_700.0, 30_600.0, 36_000.0];
    let shapes_png = dir.join("truth_shapes.png");
    let shapes = TetherShapes {
        caption: "Tether shape in the orbit frame (main satellite at 0; beads as vertices)".into(),
        shapes: picks
            .iter()
            .filter_map(|t| elastic.shapes.iter().find(|s| s.0 >= *t).cloned())
            .collect(),
    };
    let root = BitMapBackend::new(&shapes_png, SHAPE_FIGURE_SIZE_PX).into_drawing_area();
    shapes.draw(&root)?;
    root.present()?;
    println!("figures written to {}", dir.display());
    Ok(())
}
