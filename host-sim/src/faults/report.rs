//! The fault summary as text: what was injected ([`injected_faults`]) and what happened
//! ([`render_fault_summary`]), printed by `tss-sim run` and written to `faults.txt`.

use std::fmt::Write as _;

use tss_reel::controller::{Envelope, Fault, Health};

use super::plan::InjectionPlan;
use super::summary::{FaultEventKind, FaultSummary};
use crate::reel::ReelDrive;

/// How many events [`render_fault_summary`] lists.
pub const EVENTS_SHOWN: usize = 40;

fn health_name(h: Health) -> &'static str {
    match h {
        Health::Nominal => "nominal",
        Health::Degraded => "degraded",
        Health::SafeHold => "safe hold",
    }
}

/// A fault as text, e.g. `sensor: missing`, `law: …`.
pub fn fault_name(f: Fault) -> String {
    match f {
        Fault::Sensor(s) => format!("sensor {s:?}"),
        Fault::Law(l) => format!("law {l:?}"),
        Fault::Libration => "libration beyond the law's domain".to_string(),
    }
}

fn window(from_s: f64, until_s: f64) -> String {
    if until_s == f64::INFINITY {
        format!("from {from_s} s")
    } else {
        format!("{from_s}–{until_s} s")
    }
}

/// What a fault summary describes besides its counts: the run's name, what was injected, the
/// reel drive and the controller's envelope (a scenario converts into it).
#[derive(Clone, Debug, PartialEq)]
pub struct FaultSetup {
    /// The scenario's name.
    pub name: String,
    /// The sensor errors and faults injected.
    pub injection: InjectionPlan,
    /// The reel drive's lag and limits (`reel.model = "drive"`).
    pub reel: ReelDrive,
    /// The reel mechanism.
    pub mechanism: ReelMechanism,
    /// The reel is locked (the drum never turns).
    pub locked: bool,
    /// The controller's envelope.
    pub envelope: Envelope<f64>,
}

/// The reel mechanism a run flies, as the fault summary describes it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReelMechanism {
    /// The rate follows the command: at once (ideal) or through the lag drive of
    /// [`FaultSetup::reel`].
    Drive,
    /// The drum and motor with their own speed loop, friction, torque limit and brake.
    Motor,
    /// The drum driven by the flight speed loop.
    FlightDrive {
        /// The loop's inner rate, Hz.
        inner_rate_hz: u32,
    },
}

/// What `setup` injects, one line per item, the reel when it is not the ideal one included
/// (empty: perfect sensors and an ideal reel).
pub fn injected_faults(setup: &FaultSetup) -> Vec<String> {
    let mut v = Vec::new();
    let plan = &setup.injection;
    for (name, c) in [
        ("length (m)", &plan.length.errors),
        ("alpha (rad)", &plan.alpha.errors),
        ("alpha_rate (rad/s)", &plan.alpha_rate),
        ("tension (N)", &plan.load_cell.errors),
    ] {
        let mut parts = Vec::new();
        if c.noise_std > 0.0 {
            parts.push(format!("noise σ = {}", c.noise_std));
        }
        if c.bias != 0.0 {
            parts.push(format!("bias {}", c.bias));
        }
        if c.quantum > 0.0 {
            parts.push(format!("quantum {}", c.quantum));
        }
        if let Some(w) = c.stuck {
            parts.push(format!("stuck {}", window(w.from_s, w.until_s)));
        }
        if !parts.is_empty() {
            v.push(format!("sensor {name}: {}", parts.join(", ")));
        }
    }
    if v.iter().any(|l| l.contains("noise")) || plan.alpha.dropout_prob > 0.0 {
        v.push(format!("noise seed {}", plan.seed));
    }
    if let Some(q) = plan.length.count_m() {
        v.push(format!(
            "reel encoder: {} counts per revolution of a {} m drum ({:.4e} m per count)",
            plan.length.counts_per_rev, plan.length.drum_radius_m, q
        ));
    }
    let a = &plan.alpha;
    if a.latency_periods > 0 {
        v.push(format!(
            "swing sensor latency: {} periods",
            a.latency_periods
        ));
    }
    if a.dropout_prob > 0.0 {
        v.push(format!(
            "swing sensor: no α with probability {}",
            a.dropout_prob
        ));
    }
    for w in &a.dropout {
        v.push(format!("no α {}", window(w.from_s, w.until_s)));
    }
    if !plan.load_cell.enabled {
        v.push("no load cell".to_string());
    } else if plan.load_cell.full_scale_n < f64::INFINITY {
        v.push(format!(
            "load cell full scale {} N",
            plan.load_cell.full_scale_n
        ));
    }
    for w in &plan.dropout {
        v.push(format!(
            "dropout (no sample) {}",
            window(w.from_s, w.until_s)
        ));
    }
    for c in &plan.corrupt {
        v.push(format!(
            "{} reads {} {}",
            c.sensor.as_str(),
            c.value,
            window(c.window.from_s, c.window.until_s)
        ));
    }
    for g in &plan.length_glitch {
        v.push(format!("length glitch {} m at {} s", g.size_m, g.at_s));
    }
    if setup.locked {
        v.push("reel locked: the drum never turns".to_string());
    }
    match setup.mechanism {
        ReelMechanism::Drive => {}
        ReelMechanism::Motor => v.push(
            "reel: the motor drum with its speed loop, friction, torque limit and brake"
                .to_string(),
        ),
        ReelMechanism::FlightDrive { inner_rate_hz } => v.push(format!(
            "reel: the drum driven by the flight speed loop at {inner_rate_hz} Hz through a \
             quantised encoder"
        )),
    }
    let r = &setup.reel;
    let lagging =
        r.lag_s > 0.0 || r.max_rate_mps < f64::INFINITY || r.max_accel_mps2 < f64::INFINITY;
    if setup.mechanism == ReelMechanism::Drive && lagging {
        v.push(format!(
            "reel drive: lag {} s, rate limit {} m/s, acceleration limit {} m/s²",
            r.lag_s, r.max_rate_mps, r.max_accel_mps2
        ));
    }
    v
}

/// The fault summary of a run as text (printed by `tss-sim run`, written to `faults.txt`);
/// `setup` is typically the run's `&Scenario`.
pub fn render_fault_summary(setup: impl Into<FaultSetup>, s: &FaultSummary) -> String {
    let setup = setup.into();
    let mut o = String::new();
    let dt = s.period_s;
    let _ = writeln!(
        o,
        "Faults, health and envelope of scenario `{}`",
        setup.name
    );
    let injected = injected_faults(&setup);
    if injected.is_empty() {
        let _ = writeln!(o, "  injected: nothing (perfect sensors, ideal reel)");
    } else {
        let _ = writeln!(o, "  injected:");
        for l in &injected {
            let _ = writeln!(o, "    {l}");
        }
    }
    let _ = writeln!(
        o,
        "  health: nominal {:.0} s, degraded {:.0} s, safe hold {:.0} s; final {} ({} ticks, {} without a sample)",
        s.nominal_s,
        s.degraded_s,
        s.safe_hold_s,
        s.final_health.map_or("-", health_name),
        s.ticks,
        s.missing_ticks
    );
    if s.faults.is_empty() {
        let _ = writeln!(o, "  faults raised: none");
    } else {
        let _ = writeln!(o, "  faults raised (first, last, ticks):");
        for t in &s.faults {
            let _ = writeln!(
                o,
                "    {:<26} {:>9.0} s {:>9.0} s {:>7}",
                fault_name(t.fault),
                t.first_s,
                t.last_s,
                t.ticks
            );
        }
    }
    let total = s.events.len() + s.events_dropped as usize;
    if total > 0 {
        let shown = s.events.len().min(EVENTS_SHOWN);
        let _ = writeln!(o, "  events ({shown} of {total} shown):");
        for e in s.events.iter().take(shown) {
            let what = match e.kind {
                FaultEventKind::Health { from, to, fault } => format!(
                    "{} → {}{}",
                    health_name(from),
                    health_name(to),
                    fault.map_or(String::new(), |f| format!(" ({})", fault_name(f)))
                ),
                FaultEventKind::Raised(f) => format!("raised {}", fault_name(f)),
            };
            let _ = writeln!(o, "    {:>9.0} s  {what}", e.t_s);
        }
    }
    let _ = writeln!(
        o,
        "  length estimate: max |estimate − true| = {:.4} m at {:.0} s",
        s.max_length_error_m.0, s.max_length_error_m.1
    );
    let _ = writeln!(
        o,
        "  tension: min {:.6} N at {:.0} s; slack (T ≤ 0): {} events, {:.0} s",
        s.min_tension_n.0, s.min_tension_n.1, s.slack_events, s.slack_s
    );
    let t = &s.taut;
    match t.from_s {
        Some(from_s) => {
            let _ = writeln!(
                o,
                "  taut from l = {} m (reached at {from_s:.0} s): slack {} events, {:.0} s; min {:.6} N at {:.0} s",
                t.from_length_m, t.slack_events, t.slack_s, t.min_tension_n.0, t.min_tension_n.1
            );
        }
        None => {
            let _ = writeln!(o, "  taut from l = {} m: never reached", t.from_length_m);
        }
    }
    if !s.slack_episodes.is_empty() {
        let shown: Vec<String> = s
            .slack_episodes
            .iter()
            .take(8)
            .map(|(a, b)| format!("{a:.0}–{b:.0} s"))
            .collect();
        let more = s.slack_episodes.len().saturating_sub(shown.len());
        let _ = writeln!(
            o,
            "    slack episodes: {}{}",
            shown.join(", "),
            if more > 0 {
                format!(" (+{more} more)")
            } else {
                String::new()
            }
        );
    }
    let _ = writeln!(
        o,
        "  libration: max |α| = {:.4} rad at {:.0} s; {}",
        s.max_abs_alpha_rad.0,
        s.max_abs_alpha_rad.1,
        s.tumble_s.map_or("never past π/2".to_string(), |t| format!(
            "past π/2 (tumbled) from {t:.0} s"
        ))
    );
    let _ = writeln!(
        o,
        "  tether: {:.3} … {:.3} m; outside [{}, {}] m for {:.0} s (by at most {:.4} m)",
        s.length_range_m.0,
        s.length_range_m.1,
        setup.envelope.min_length_m,
        setup.envelope.max_length_m,
        s.outside_envelope_s,
        s.max_excursion_m
    );
    let _ = writeln!(
        o,
        "  commands: max |l̇| = {:.4} m/s (limit {}), max |Δl̇|/Δt = {:.4} m/s² (limit {}); \
         beyond the limits: rate {} ticks, acceleration {} ticks",
        s.max_rate_cmd_mps,
        setup.envelope.max_rate_mps,
        s.max_accel_cmd_mps2,
        setup.envelope.max_accel_mps2,
        s.rate_exceeded_ticks,
        s.accel_exceeded_ticks
    );
    let flags: Vec<String> = s
        .flags
        .named()
        .iter()
        .filter(|(_, n)| *n > 0)
        .map(|(name, n)| format!("{name} {n}"))
        .collect();
    let _ = writeln!(
        o,
        "  controller flags (ticks): {}",
        if flags.is_empty() {
            "none".to_string()
        } else {
            flags.join(", ")
        }
    );
    if s.reel_rate_saturated_ticks > 0 || s.reel_accel_saturated_ticks > 0 {
        let _ = writeln!(
            o,
            "  reel drive saturated: rate {} ticks ({:.0} s), acceleration {} ticks ({:.0} s)",
            s.reel_rate_saturated_ticks,
            f64::from(s.reel_rate_saturated_ticks) * dt,
            s.reel_accel_saturated_ticks,
            f64::from(s.reel_accel_saturated_ticks) * dt
        );
    }
    o
}
