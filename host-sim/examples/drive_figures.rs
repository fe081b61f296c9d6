//! # drive_figures: the flight speed loop on the truth model's drum over the whole paper mission
//!
//! Flies `scenarios/paper.toml` (rigid plant, 20 h, every law period recorded), then the reel
//! MCU's speed loop (`tss_reel::reel_drive::SpeedLoop`, f32, 1 kHz, quantised encoder) on the
//! truth model's drum (`tss_sim::elastic::reel_drum::FlightDrum`) under its commands, Eq. 30
//! accelerations and tension at the reel, period by period. Prints the drive's figures per
//! phase (tracking RMS and max against its reference, duty saturation, tension, faults) and
//! draws `drive_paper.png`: the command and the drum's speed at each period's end, and each
//! period's largest tracking error.
//!
//! ```text
//! cargo run --release -p tss-sim --example drive_figures [-- OUT_DIR]   # default docs/figures
//! ```

use std::path::{Path, PathBuf};

use plotters::prelude::*;
use tss_reel::reel_drive::RateCommand;
use tss_sim::elastic::reel_drum::{DrumParams, FlightDrum};
use tss_sim::history::PhaseLabel;
use tss_sim::scenario::Scenario;

fn main() -> anyhow::Result<()> {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/figures"));
    std::fs::create_dir_all(&dir)?;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper.toml");
    let sc = Scenario::load(path, &["simulation.output_interval_s=1.0".to_string()])?;
    let history = tss_sim::sim::run(&sc, &[], &mut |_| {})?;
    let r = &sc.reel;
    let params = DrumParams {
        radius_m: r.drum_radius_m,
        inertia_kgm2: r.drum_inertia_kgm2,
        viscous_nms: r.viscous_nms,
        coulomb_nm: r.coulomb_nm,
        static_nm: r.static_nm,
        max_torque_nm: r.motor_max_torque_nm,
        brake_nm: r.brake_nm,
        speed_bandwidth_radps: r.speed_bandwidth_radps,
    };
    let cfg = FlightDrum::drive_config(&params, 1000, sc.controller.period_s);
    let mut reel = FlightDrum::new(params, cfg).map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut rows = Vec::with_capacity(history.samples.len());
    let mut phase = None;
    let mut at_phase_start = *reel.figures();
    for s in &history.samples {
        if phase != Some(s.phase) {
            if let Some(p) = phase {
                report(p, &at_phase_start, reel.figures());
            }
            phase = Some(s.phase);
            at_phase_start = *reel.figures();
        }
        let cmd = RateCommand {
            rate_mps: s.length_rate_mps as f32,
            accel_mps2: s.length_accel_mps2 as f32,
            safe_hold: false,
        };
        let (end_mps, max_error_mps) = reel.period(cmd, s.tension_n, cfg.outer_period_ticks);
        rows.push((s.t_s / 3600.0, s.length_rate_mps, end_mps, max_error_mps));
    }
    if let Some(p) = phase {
        report(p, &at_phase_start, reel.figures());
    }
    let f = reel.figures();
    println!(
        "whole mission: {} periods at {} Hz: tracking RMS {:.2e} m/s, max {:.2e} m/s; period-end max {:.2e} m/s; duty saturated {} ticks ({:.4} %); tension at the reel {:.3e}..{:.3e} N; faults {:#x}",
        history.samples.len(),
        cfg.inner_rate_hz,
        f.rms_error_mps(),
        f.max_error_mps,
        f.max_period_end_error_mps,
        f.saturated_ticks,
        100.0 * f.saturated_fraction(),
        f.tension_range_n.0,
        f.tension_range_n.1,
        f.fault_bits
    );

    let file = dir.join("drive_paper.png");
    let root = BitMapBackend::new(&file, (1200, 800)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, bottom) = root.split_vertically(400);
    let t_end = rows.last().map_or(1.0, |r| r.0);
    let (lo, hi) = rows.iter().fold((0.0_f64, 0.0_f64), |(lo, hi), r| {
        (lo.min(r.1).min(r.2), hi.max(r.1).max(r.2))
    });
    let mut chart = ChartBuilder::on(&top)
        .caption(
            "Paper mission: law's command and drum speed (period end)",
            ("sans-serif", 20),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t_end, (lo - 0.5)..(hi + 0.5))?;
    chart.configure_mesh().x_desc("t, h").y_desc("m/s").draw()?;
    chart
        .draw_series(LineSeries::new(rows.iter().map(|r| (r.0, r.1)), &BLUE))?
        .label("command")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
    chart
        .draw_series(LineSeries::new(rows.iter().map(|r| (r.0, r.2)), &RED))?
        .label("drum (encoder)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    chart.configure_series_labels().border_style(BLACK).draw()?;
    let max_err = rows.iter().map(|r| r.3).fold(1e-6_f64, f64::max);
    let mut chart = ChartBuilder::on(&bottom)
        .caption(
            "Largest |drum − reference| in each period (brake released)",
            ("sans-serif", 20),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t_end, (1e-6..max_err * 2.0).log_scale())?;
    chart.configure_mesh().x_desc("t, h").y_desc("m/s").draw()?;
    chart.draw_series(
        rows.iter()
            .filter(|r| r.3 > 0.0)
            .map(|r| Circle::new((r.0, r.3), 1, BLUE.filled())),
    )?;
    root.present()?;
    println!("wrote {}", file.display());
    Ok(())
}

/// The figures of one phase: the difference of the running figures at its end and start.
fn report(
    phase: PhaseLabel,
    start: &tss_sim::plant::DriveFigures,
    end: &tss_sim::plant::DriveFigures,
) {
    let released = end.released_ticks - start.released_ticks;
    let rms = if released == 0 {
        0.0
    } else {
        ((end.sum_sq_error - start.sum_sq_error) / released as f64).sqrt()
    };
    println!(
        "{phase:?}: {} ticks, {released} released: tracking RMS {rms:.2e} m/s; duty saturated {} ticks",
        end.ticks - start.ticks,
        end.saturated_ticks - start.saturated_ticks
    );
}
