//! The paper's Table 1 (tether length during station keeping) and its comparison with a
//! simulated run.
//!
//! He, Liang & Xu (2011), Table 1: l at t = 7.00…8.00 h (stage 1, keep at 30 km) and
//! 14.00…15.00 h (stage 2, keep at 2 km), every 0.05 h (180 s), in m to 3 decimals (the paper
//! states a truncation error of 0.01 m). Transcribed from
//! `shared/paper/he-liang-xu-2011-tss-stability.txt`.

use std::fmt::Write as _;
use std::io::{self, Write};

/// One value of the paper's Table 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperPoint {
    /// Mission stage: 1 (keep at 30 km) or 2 (keep at 2 km).
    pub stage: u8,
    /// Time as printed in the paper, h.
    pub t_h: f64,
    /// The same time in s, `round(t_h · 3600)`: the probe instant passed to `sim::run`.
    pub t_s: f64,
    /// Tether length printed in the paper, m.
    pub length_m: f64,
}

/// Number of values in the paper's Table 1 (21 per stage).
pub const PAPER_TABLE1_LEN: usize = 42;

/// The paper's Table 1, stage 1 then stage 2, in time order.
pub const PAPER_TABLE1: [PaperPoint; PAPER_TABLE1_LEN] = [
    PaperPoint {
        stage: 1,
        t_h: 7.00,
        t_s: 25200.0,
        length_m: 29999.965,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.05,
        t_s: 25380.0,
        length_m: 29999.959,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.10,
        t_s: 25560.0,
        length_m: 29999.958,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.15,
        t_s: 25740.0,
        length_m: 29999.961,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.20,
        t_s: 25920.0,
        length_m: 29999.967,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.25,
        t_s: 26100.0,
        length_m: 29999.975,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.30,
        t_s: 26280.0,
        length_m: 29999.982,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.35,
        t_s: 26460.0,
        length_m: 29999.990,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.40,
        t_s: 26640.0,
        length_m: 29999.996,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.45,
        t_s: 26820.0,
        length_m: 30000.002,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.50,
        t_s: 27000.0,
        length_m: 30000.005,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.55,
        t_s: 27180.0,
        length_m: 30000.008,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.60,
        t_s: 27360.0,
        length_m: 30000.009,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.65,
        t_s: 27540.0,
        length_m: 30000.009,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.70,
        t_s: 27720.0,
        length_m: 30000.008,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.75,
        t_s: 27900.0,
        length_m: 30000.007,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.80,
        t_s: 28080.0,
        length_m: 30000.005,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.85,
        t_s: 28260.0,
        length_m: 30000.003,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.90,
        t_s: 28440.0,
        length_m: 30000.002,
    },
    PaperPoint {
        stage: 1,
        t_h: 7.95,
        t_s: 28620.0,
        length_m: 30000.000,
    },
    PaperPoint {
        stage: 1,
        t_h: 8.00,
        t_s: 28800.0,
        length_m: 29999.999,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.00,
        t_s: 50400.0,
        length_m: 2000.512,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.05,
        t_s: 50580.0,
        length_m: 2000.477,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.10,
        t_s: 50760.0,
        length_m: 2000.444,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.15,
        t_s: 50940.0,
        length_m: 2000.415,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.20,
        t_s: 51120.0,
        length_m: 2000.388,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.25,
        t_s: 51300.0,
        length_m: 2000.363,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.30,
        t_s: 51480.0,
        length_m: 2000.341,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.35,
        t_s: 51660.0,
        length_m: 2000.321,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.40,
        t_s: 51840.0,
        length_m: 2000.302,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.45,
        t_s: 52020.0,
        length_m: 2000.285,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.50,
        t_s: 52200.0,
        length_m: 2000.270,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.55,
        t_s: 52380.0,
        length_m: 2000.256,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.60,
        t_s: 52560.0,
        length_m: 2000.243,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.65,
        t_s: 52740.0,
        length_m: 2000.232,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.70,
        t_s: 52920.0,
        length_m: 2000.221,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.75,
        t_s: 53100.0,
        length_m: 2000.212,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.80,
        t_s: 53280.0,
        length_m: 2000.203,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.85,
        t_s: 53460.0,
        length_m: 2000.195,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.90,
        t_s: 53640.0,
        length_m: 2000.188,
    },
    PaperPoint {
        stage: 2,
        t_h: 14.95,
        t_s: 53820.0,
        length_m: 2000.181,
    },
    PaperPoint {
        stage: 2,
        t_h: 15.00,
        t_s: 54000.0,
        length_m: 2000.175,
    },
];

/// The 42 Table-1 instants in s (`PAPER_TABLE1[i].t_s`), to pass to `sim::run` as probe times.
pub const PROBE_TIMES_S: [f64; PAPER_TABLE1_LEN] = {
    let mut times = [0.0; PAPER_TABLE1_LEN];
    let mut i = 0;
    while i < PAPER_TABLE1_LEN {
        times[i] = PAPER_TABLE1[i].t_s;
        i += 1;
    }
    times
};

/// The Table-1 instants a run of `scenario` reaches (t ≤ duration, whole control periods).
pub fn probe_times_for(scenario: &crate::scenario::Scenario) -> Vec<f64> {
    let period = scenario.controller.period_s;
    PROBE_TIMES_S
        .iter()
        .copied()
        .filter(|&t| {
            let n = (t / period).round();
            t <= scenario.simulation.duration_s && (n * period - t).abs() <= 1e-9 * t.max(period)
        })
        .collect()
}

/// A probe is matched to a Table-1 instant when their times differ by at most this, s.
pub const PROBE_TIME_TOLERANCE_S: f64 = 1e-6;

/// One row of the comparison: the paper's value and the simulated length at the same instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ComparedPoint {
    /// The paper's value.
    pub paper: PaperPoint,
    /// Simulated length at `paper.t_s`, m (`None` when the run did not reach that instant).
    pub sim_length_m: Option<f64>,
}

impl ComparedPoint {
    /// Simulated minus paper length, m.
    pub fn difference_m(&self) -> Option<f64> {
        self.sim_length_m.map(|l| l - self.paper.length_m)
    }
}

/// The paper's Table 1 next to a simulated run.
#[derive(Clone, Debug, PartialEq)]
pub struct Table1Comparison {
    /// One row per paper value, in the paper's order.
    pub rows: Vec<ComparedPoint>,
}

/// The largest |simulated − paper| of one stage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaxDifference {
    /// The signed difference with the largest magnitude, m.
    pub difference_m: f64,
    /// When it occurs, h.
    pub t_h: f64,
    /// How many of the stage's 21 instants the run covered.
    pub compared: usize,
}

impl Table1Comparison {
    /// Matches `probes` ((t_s, length_m), as in `History::probes`) to the paper's instants by
    /// time; an instant without a probe is left empty.
    pub fn new(probes: &[(f64, f64)]) -> Self {
        let rows = PAPER_TABLE1
            .iter()
            .map(|&paper| {
                let sim_length_m = probes
                    .iter()
                    .find(|(t, _)| (t - paper.t_s).abs() <= PROBE_TIME_TOLERANCE_S)
                    .map(|&(_, l)| l);
                ComparedPoint {
                    paper,
                    sim_length_m,
                }
            })
            .collect();
        Self { rows }
    }

    /// Max |simulated − paper| over the stage's rows that the run covered (`None` if none).
    pub fn max_abs_difference(&self, stage: u8) -> Option<MaxDifference> {
        let mut best: Option<MaxDifference> = None;
        let mut compared = 0;
        for row in self.rows.iter().filter(|r| r.paper.stage == stage) {
            let Some(d) = row.difference_m() else {
                continue;
            };
            compared += 1;
            // NaN counts as the worst possible difference.
            let size = |d: f64| if d.is_nan() { f64::INFINITY } else { d.abs() };
            if best.is_none_or(|b| size(d) > size(b.difference_m)) {
                best = Some(MaxDifference {
                    difference_m: d,
                    t_h: row.paper.t_h,
                    compared: 0,
                });
            }
        }
        best.map(|b| MaxDifference { compared, ..b })
    }

    /// Writes `table1.csv`: `stage,t_h,t_s,paper_length_m,sim_length_m,difference_m`
    /// (empty cells where the run did not reach the instant; simulated values at full precision).
    pub fn write_csv<W: Write>(&self, mut w: W) -> io::Result<()> {
        writeln!(w, "{TABLE1_CSV_HEADER}")?;
        for r in &self.rows {
            let sim = r.sim_length_m.map(|l| l.to_string()).unwrap_or_default();
            let diff = r.difference_m().map(|d| d.to_string()).unwrap_or_default();
            writeln!(
                w,
                "{},{:.2},{},{:.3},{},{}",
                r.paper.stage, r.paper.t_h, r.paper.t_s, r.paper.length_m, sim, diff
            )?;
        }
        w.flush()
    }

    /// The comparison as a text table, both stages side by side, plus each stage's max
    /// |difference|.
    pub fn render(&self) -> String {
        let mut out = String::new();
        let stage = |n: u8| -> Vec<&ComparedPoint> {
            self.rows.iter().filter(|r| r.paper.stage == n).collect()
        };
        let (s1, s2) = (stage(1), stage(2));
        let _ = writeln!(
            out,
            "Table 1 (He, Liang & Xu 2011): tether length during station keeping, m"
        );
        let head = format!(
            "{:>6} {:>11} {:>11} {:>8}",
            "t (h)", "paper", "simulated", "sim−pap"
        );
        let _ = writeln!(
            out,
            "  {:<39}  |  stage 2 (paper: keep at 2 km)",
            "stage 1 (paper: keep at 30 km)"
        );
        let _ = writeln!(out, "  {head}  |  {head}");
        for i in 0..s1.len().max(s2.len()) {
            let cell = |r: Option<&&ComparedPoint>| match r {
                Some(r) => format!(
                    "{:>6.2} {:>11.3} {:>11} {:>8}",
                    r.paper.t_h,
                    r.paper.length_m,
                    r.sim_length_m
                        .map_or_else(|| "—".to_string(), |l| format!("{l:.3}")),
                    r.difference_m()
                        .map_or_else(|| "—".to_string(), |d| format!("{d:+.3}")),
                ),
                None => format!("{:39}", ""),
            };
            let _ = writeln!(out, "  {}  |  {}", cell(s1.get(i)), cell(s2.get(i)));
        }
        for (n, rows) in [(1u8, &s1), (2u8, &s2)] {
            match self.max_abs_difference(n) {
                Some(m) => {
                    let _ = writeln!(
                        out,
                        "  stage {n}: max |simulated − paper| = {:.3} m (at {:.2} h; {} of {} instants)",
                        m.difference_m.abs(),
                        m.t_h,
                        m.compared,
                        rows.len()
                    );
                }
                None => {
                    let _ = writeln!(
                        out,
                        "  stage {n}: no comparison, the run ended before these instants"
                    );
                }
            }
        }
        out
    }
}

/// Header line of `table1.csv`.
pub const TABLE1_CSV_HEADER: &str = "stage,t_h,t_s,paper_length_m,sim_length_m,difference_m";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn has_42_values_21_per_stage_every_180_s() {
        assert_eq!(PAPER_TABLE1.len(), 42);
        for (stage, start_s) in [(1u8, 25_200.0), (2u8, 50_400.0)] {
            let rows: Vec<_> = PAPER_TABLE1.iter().filter(|p| p.stage == stage).collect();
            assert_eq!(rows.len(), 21);
            for (k, p) in rows.iter().enumerate() {
                assert_eq!(p.t_s, start_s + 180.0 * k as f64);
                assert_eq!(p.t_s, (p.t_h * 3600.0).round());
            }
        }
        assert_eq!(PROBE_TIMES_S[0], 25_200.0);
        assert_eq!(PROBE_TIMES_S[20], 28_800.0);
        assert_eq!(PROBE_TIMES_S[21], 50_400.0);
        assert_eq!(PROBE_TIMES_S[41], 54_000.0);
    }

    #[test]
    fn values_match_the_paper() {
        let at = |t_h: f64| {
            PAPER_TABLE1
                .iter()
                .find(|p| (p.t_h - t_h).abs() < 1e-9)
                .map(|p| p.length_m)
        };
        assert_eq!(at(7.0), Some(29_999.965));
        assert_eq!(at(7.6), Some(30_000.009));
        assert_eq!(at(8.0), Some(29_999.999));
        assert_eq!(at(14.0), Some(2_000.512));
        assert_eq!(at(14.5), Some(2_000.270));
        assert_eq!(at(15.0), Some(2_000.175));
        // Stage 1 stays within 0.1 m of 30 km; stage 2 decreases monotonically (the paper's text).
        for p in PAPER_TABLE1.iter().filter(|p| p.stage == 1) {
            assert!((p.length_m - 30_000.0).abs() < 0.1);
        }
        let s2: Vec<f64> = PAPER_TABLE1
            .iter()
            .filter(|p| p.stage == 2)
            .map(|p| p.length_m)
            .collect();
        assert!(s2.windows(2).all(|w| w[1] < w[0]));
    }

    #[test]
    fn comparison_matches_probes_by_time_and_finds_the_worst_difference() {
        // Stage 1 only, every probe 0.01 m above the paper except one 0.05 m below.
        let probes: Vec<(f64, f64)> = PAPER_TABLE1
            .iter()
            .filter(|p| p.stage == 1)
            .map(|p| {
                let d = if p.t_h == 7.5 { -0.05 } else { 0.01 };
                (p.t_s, p.length_m + d)
            })
            .collect();
        let c = Table1Comparison::new(&probes);
        let m1 = c.max_abs_difference(1).unwrap();
        assert!((m1.difference_m + 0.05).abs() < 1e-9);
        assert_eq!(m1.t_h, 7.5);
        assert_eq!(m1.compared, 21);
        assert_eq!(c.max_abs_difference(2), None);
        let text = c.render();
        assert!(
            text.contains("stage 2: no comparison, the run ended before these instants"),
            "{text}"
        );
        let mut csv = Vec::new();
        c.write_csv(&mut csv).unwrap();
        let csv = String::from_utf8(csv).unwrap();
        assert_eq!(csv.lines().next(), Some(TABLE1_CSV_HEADER));
        assert_eq!(csv.lines().count(), 43);
        assert!(csv
            .lines()
            .nth(22)
            .unwrap()
            .starts_with("2,14.00,50400,2000.512,,"));
    }
}
