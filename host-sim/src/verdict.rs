//! What a run achieved, judged: the failures of its mission, for the headline of `tss-sim
//! run`'s report (a `verdict:` line) and its `verdict.json`. A run passes only when none
//! happened; the landmarks and tables that follow the headline say how far it got.
//!
//! - **Tumble**: the tether's in-plane angle |α| reached π/2 (the line horizontal: past it the
//!   tether librates over the top, outside every law's domain, Eq. 5 and docs/equations.md §3);
//! - **Spool overrun**: the tether paid out to the end of its spool
//!   (`envelope.max_length_m`, the tether the main satellite carries): the run stops there;
//! - **Slack tether**: the tension at the reel was ≤ 0 at a control tick from the point the
//!   tether must be taut on (`simulation.taut_from_length_m`, docs/equations.md §17.7; from the
//!   start by default), the criterion of the Monte Carlo campaigns too;
//! - **Drive trip**: the flight drive (`reel.model = "flight_drive"`) raised a fault;
//! - **Stalled mission**: the controller flagged no progress, ended the run in safe hold, or
//!   stage 1 never reached its keep length before stage 2 began.

use std::fmt::Write as _;

use tss_reel::controller::{Flags, Health};

use crate::history::History;
use crate::report::summarize;
use crate::scenario::Scenario;

/// One way a mission failed.
#[derive(Clone, Debug, PartialEq)]
pub enum Failure {
    /// |α| reached π/2 (`faults::TUMBLE_ANGLE_RAD`).
    Tumble {
        /// First time, s.
        first_s: f64,
        /// The largest |α| of the run, rad.
        max_abs_alpha_rad: f64,
    },
    /// The tether ran off the end of its spool (the run stopped there).
    SpoolOverrun {
        /// When, s.
        t_s: f64,
        /// The paid-out length, m.
        length_m: f64,
        /// The spool's length (`envelope.max_length_m`), m.
        spool_m: f64,
    },
    /// The tension at the reel fell to ≤ 0 from the point the tether must be taut on.
    Slack {
        /// The length from which the tether must be taut, m (0: from the start).
        from_length_m: f64,
        /// Start of the first slack episode from that point, s.
        first_s: f64,
        /// Slack episodes.
        episodes: u32,
        /// Time slack in all, s.
        total_s: f64,
        /// The least tension from that point, N.
        min_tension_n: f64,
    },
    /// The flight drive raised faults.
    DriveTrip {
        /// Every fault it raised (bits of `tss_reel::reel_drive::DriveFaults`).
        fault_bits: u16,
    },
    /// The mission stopped making progress.
    Stalled {
        /// When it was first seen, s.
        t_s: f64,
        /// The length then, m.
        length_m: f64,
        /// How it was seen.
        why: &'static str,
    },
}

impl Failure {
    /// Its name in `verdict.json` and on the headline.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Tumble { .. } => "tumble",
            Self::SpoolOverrun { .. } => "spool_overrun",
            Self::Slack { .. } => "slack",
            Self::DriveTrip { .. } => "drive_trip",
            Self::Stalled { .. } => "stalled",
        }
    }

    /// One phrase for the headline.
    pub fn describe(&self) -> String {
        match self {
            Self::Tumble {
                first_s,
                max_abs_alpha_rad,
            } => format!(
                "tumble: |α| reached π/2 at {first_s:.0} s (largest {max_abs_alpha_rad:.2} rad)"
            ),
            Self::SpoolOverrun {
                t_s,
                length_m,
                spool_m,
            } => format!(
                "spool overrun: {length_m:.1} m paid out of a {spool_m} m spool at {t_s:.0} s \
                 (the run stopped there)"
            ),
            Self::Slack {
                from_length_m,
                first_s,
                episodes,
                total_s,
                min_tension_n,
            } => {
                let taut_from = if *from_length_m > 0.0 {
                    format!(" once {from_length_m} m long")
                } else {
                    String::new()
                };
                format!(
                    "slack tether{taut_from}: {episodes} episode(s), {total_s:.0} s in all, from \
                     {first_s:.0} s (least tension {min_tension_n:.4} N)"
                )
            }
            Self::DriveTrip { fault_bits } => {
                format!("drive trip: flight drive faults {fault_bits:#06x} (DriveFault::ALL order)")
            }
            Self::Stalled { t_s, length_m, why } => {
                format!("stalled at {length_m:.1} m ({t_s:.0} s): {why}")
            }
        }
    }
}

/// A run's verdict: its failures, in the order above (none: it passed).
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    /// The scenario's name.
    pub name: String,
    /// Mission time of the last sample, s.
    pub end_s: f64,
    /// What went wrong.
    pub failures: Vec<Failure>,
}

impl Verdict {
    /// Judges the run of `sc` that made `h`.
    pub fn of(sc: &Scenario, h: &History) -> Self {
        let f = &h.faults;
        let mut failures = Vec::new();
        if let Some(first_s) = f.tumble_s {
            failures.push(Failure::Tumble {
                first_s,
                max_abs_alpha_rad: f.max_abs_alpha_rad.0,
            });
        }
        if let Some(o) = h.spool_overrun {
            failures.push(Failure::SpoolOverrun {
                t_s: o.t_s,
                length_m: o.length_m,
                spool_m: o.spool_m,
            });
        }
        let taut = &f.taut;
        if let Some(from_s) = taut.from_s.filter(|_| taut.slack_s > 0.0) {
            // The first episode that lasts to the point or begins after it (one already slack
            // at the point counts from there).
            let first_s = f
                .slack_episodes
                .iter()
                .find(|(_, end_s)| *end_s > from_s)
                .map_or(f64::NAN, |(start_s, _)| start_s.max(from_s));
            failures.push(Failure::Slack {
                from_length_m: taut.from_length_m,
                first_s,
                episodes: taut.slack_events,
                total_s: taut.slack_s,
                min_tension_n: taut.min_tension_n.0,
            });
        }
        let drive_bits = h
            .elastic
            .last()
            .and_then(|e| e.drive)
            .map_or(0, |d| d.fault_bits);
        if drive_bits != 0 {
            failures.push(Failure::DriveTrip {
                fault_bits: drive_bits,
            });
        }
        if let Some(s) = h.samples.iter().find(|s| s.flags & Flags::NO_PROGRESS != 0) {
            failures.push(Failure::Stalled {
                t_s: s.t_s,
                length_m: s.length_m,
                why: "the controller flagged no progress",
            });
        } else if let (Some(Health::SafeHold), Some(s)) = (f.final_health, h.samples.last()) {
            failures.push(Failure::Stalled {
                t_s: s.t_s,
                length_m: s.length_m,
                why: "the controller ended the run in safe hold",
            });
        } else {
            let stage2_s = sc.stage2.start_time_s;
            let keep1_reached = summarize(sc, h)
                .landmarks
                .get(1)
                .is_some_and(|l| l.t_s.is_some());
            let at_stage2 = h.samples.iter().find(|s| s.t_s >= stage2_s);
            if let (false, Some(s)) = (keep1_reached, at_stage2) {
                failures.push(Failure::Stalled {
                    t_s: s.t_s,
                    length_m: s.length_m,
                    why: "stage 1 never reached stage1.keep_length_m before stage 2",
                });
            }
        }
        Self {
            name: sc.name.clone(),
            end_s: h.samples.last().map_or(0.0, |s| s.t_s),
            failures,
        }
    }

    /// No failure.
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }

    /// The headline: `verdict: passed …` or `verdict: FAILED: …; …`.
    pub fn headline(&self) -> String {
        if self.passed() {
            return format!(
                "verdict: passed (no tumble, spool overrun, slack, drive trip or stall in {:.0} s)",
                self.end_s
            );
        }
        let what: Vec<String> = self.failures.iter().map(Failure::describe).collect();
        format!("verdict: FAILED: {}", what.join("; "))
    }

    /// `verdict.json`: `{"scenario": …, "passed": …, "end_s": …, "failures": [{"kind": …,
    /// …}, …]}` (a non-finite number is `null`).
    pub fn to_json(&self) -> String {
        let mut o = String::new();
        let _ = write!(
            o,
            "{{\"scenario\": {}, \"passed\": {}, \"end_s\": {}, \"failures\": [",
            json_string(&self.name),
            self.passed(),
            json_number(self.end_s)
        );
        for (i, f) in self.failures.iter().enumerate() {
            if i > 0 {
                o.push_str(", ");
            }
            let fields: Vec<(&str, String)> = match f {
                Failure::Tumble {
                    first_s,
                    max_abs_alpha_rad,
                } => vec![
                    ("first_s", json_number(*first_s)),
                    ("max_abs_alpha_rad", json_number(*max_abs_alpha_rad)),
                ],
                Failure::SpoolOverrun {
                    t_s,
                    length_m,
                    spool_m,
                } => vec![
                    ("t_s", json_number(*t_s)),
                    ("length_m", json_number(*length_m)),
                    ("spool_m", json_number(*spool_m)),
                ],
                Failure::Slack {
                    from_length_m,
                    first_s,
                    episodes,
                    total_s,
                    min_tension_n,
                } => vec![
                    ("from_length_m", json_number(*from_length_m)),
                    ("first_s", json_number(*first_s)),
                    ("episodes", episodes.to_string()),
                    ("total_s", json_number(*total_s)),
                    ("min_tension_n", json_number(*min_tension_n)),
                ],
                Failure::DriveTrip { fault_bits } => {
                    vec![("fault_bits", fault_bits.to_string())]
                }
                Failure::Stalled { t_s, length_m, why } => vec![
                    ("t_s", json_number(*t_s)),
                    ("length_m", json_number(*length_m)),
                    ("why", json_string(why)),
                ],
            };
            let _ = write!(o, "{{\"kind\": {}", json_string(f.kind()));
            for (k, v) in fields {
                let _ = write!(o, ", \"{k}\": {v}");
            }
            o.push('}');
        }
        o.push_str("]}\n");
        o
    }
}

/// A JSON number (`null` when not finite).
fn json_number(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        "null".to_string()
    }
}

/// A JSON string literal.
fn json_string(s: &str) -> String {
    let mut o = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => o.push_str("\\\""),
            '\\' => o.push_str("\\\\"),
            c if u32::from(c) < 0x20 => {
                let _ = write!(o, "\\u{:04x}", u32::from(c));
            }
            c => o.push(c),
        }
    }
    o.push('"');
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_strings_and_numbers_are_escaped() {
        assert_eq!(json_string("a\"b\\c\n"), "\"a\\\"b\\\\c\\u000a\"");
        assert_eq!(json_number(f64::NAN), "null");
        assert_eq!(json_number(1.5), "1.5");
    }
}
