//! `history.csv`: one row per [`Sample`], every number at full (round-trip) precision.
//!
//! The first ten columns are fixed (scripts and the paper's figures rely on them); the extra
//! columns follow in [`HISTORY_EXTRA_COLUMNS`] order. Numbers are written with Rust's `{}`
//! formatting of `f64`, the shortest text that parses back to the same bits
//! (`NaN`, `inf` and `-inf` for non-finite values).

use std::io::{self, BufRead, Write};

use crate::history::{PhaseLabel, Sample};

/// The fixed leading columns of `history.csv`.
pub const HISTORY_COLUMNS: [&str; 10] = [
    "t_s",
    "length_m",
    "length_rate_mps",
    "alpha_rad",
    "alpha_ref_rad",
    "delta_rad",
    "delta_rate_radps",
    "beta_rad",
    "tension_n",
    "phase",
];

/// The extra columns after [`HISTORY_COLUMNS`], in order.
pub const HISTORY_EXTRA_COLUMNS: [&str; 5] = [
    "alpha_rate_radps",
    "length_accel_mps2",
    "law_rate_mps",
    "blend_weight",
    "flags",
];

/// The complete header line of `history.csv` (no newline).
pub fn history_header() -> String {
    let mut cols: Vec<&str> = HISTORY_COLUMNS.to_vec();
    cols.extend(HISTORY_EXTRA_COLUMNS);
    cols.join(",")
}

/// Writes the header and one row per sample.
pub fn write_history_csv<W: Write>(mut w: W, samples: &[Sample]) -> io::Result<()> {
    writeln!(w, "{}", history_header())?;
    for s in samples {
        writeln!(
            w,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            s.t_s,
            s.length_m,
            s.length_rate_mps,
            s.alpha_rad,
            s.alpha_ref_rad,
            s.delta_rad,
            s.delta_rate_radps,
            s.beta_rad,
            s.tension_n,
            s.phase.as_str(),
            s.alpha_rate_radps,
            s.length_accel_mps2,
            s.law_rate_mps,
            s.blend_weight,
            s.flags,
        )?;
    }
    w.flush()
}

/// The columns the elastic plant's `history.csv` adds after [`HISTORY_EXTRA_COLUMNS`]
/// (`length_m` is then the paid-out length at the reel, `tension_n` the tension there).
pub const HISTORY_ELASTIC_COLUMNS: [&str; 6] = [
    "range_m",
    "tension_tip_n",
    "bowing_m",
    "alpha_sensed_rad",
    "reel_rate_mps",
    "beads",
];

/// Writes the elastic plant's history: the columns of [`write_history_csv`], then
/// [`HISTORY_ELASTIC_COLUMNS`] from `elastic` (one per sample).
pub fn write_elastic_history_csv<W: Write>(
    mut w: W,
    samples: &[Sample],
    elastic: &[crate::plant::ElasticObservation],
) -> io::Result<()> {
    writeln!(
        w,
        "{},{}",
        history_header(),
        HISTORY_ELASTIC_COLUMNS.join(",")
    )?;
    for (s, e) in samples.iter().zip(elastic) {
        writeln!(
            w,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            s.t_s,
            s.length_m,
            s.length_rate_mps,
            s.alpha_rad,
            s.alpha_ref_rad,
            s.delta_rad,
            s.delta_rate_radps,
            s.beta_rad,
            s.tension_n,
            s.phase.as_str(),
            s.alpha_rate_radps,
            s.length_accel_mps2,
            s.law_rate_mps,
            s.blend_weight,
            s.flags,
            e.range_m,
            e.tension_tip_n,
            e.bowing_m,
            e.alpha_sensed_rad,
            e.reel_rate_mps,
            e.beads,
        )?;
    }
    w.flush()
}

/// Why a `history.csv` could not be read back.
#[derive(Debug, thiserror::Error)]
pub enum HistoryCsvError {
    /// Reading failed.
    #[error("cannot read history.csv")]
    Io(#[from] io::Error),
    /// The first line is not [`history_header`].
    #[error("unexpected header {found:?}")]
    Header {
        /// The header found.
        found: String,
    },
    /// A row that does not parse.
    #[error("line {line}: column {column}: cannot parse {text:?}")]
    Cell {
        /// 1-based line number.
        line: usize,
        /// Column name.
        column: &'static str,
        /// The cell's text.
        text: String,
    },
}

/// Parses a phase label written by [`PhaseLabel::as_str`].
pub fn parse_phase(text: &str) -> Option<PhaseLabel> {
    [
        PhaseLabel::Deploy,
        PhaseLabel::Keep1,
        PhaseLabel::Slew,
        PhaseLabel::Retrieve,
        PhaseLabel::Keep2,
    ]
    .into_iter()
    .find(|p| p.as_str() == text)
}

/// Reads a `history.csv` written by [`write_history_csv`] back into samples (bit-exact).
pub fn read_history_csv<R: BufRead>(r: R) -> Result<Vec<Sample>, HistoryCsvError> {
    let mut lines = r.lines();
    let header = lines.next().transpose()?.unwrap_or_default();
    if header != history_header() {
        return Err(HistoryCsvError::Header { found: header });
    }
    let names: Vec<&'static str> = HISTORY_COLUMNS
        .iter()
        .chain(HISTORY_EXTRA_COLUMNS.iter())
        .copied()
        .collect();
    let mut samples = Vec::new();
    for (i, line) in lines.enumerate() {
        let line = line?;
        let line_no = i + 2;
        let cells: Vec<&str> = line.split(',').collect();
        let cell = |k: usize| -> Result<&str, HistoryCsvError> {
            cells.get(k).copied().ok_or_else(|| HistoryCsvError::Cell {
                line: line_no,
                column: names[k],
                text: String::new(),
            })
        };
        let bad = |k: usize, text: &str| HistoryCsvError::Cell {
            line: line_no,
            column: names[k],
            text: text.to_string(),
        };
        let f = |k: usize| -> Result<f64, HistoryCsvError> {
            let text = cell(k)?;
            text.parse::<f64>().map_err(|_| bad(k, text))
        };
        if cells.len() != names.len() {
            return Err(bad(names.len().min(cells.len()), &line));
        }
        let phase_text = cell(9)?;
        let flags_text = cell(14)?;
        samples.push(Sample {
            t_s: f(0)?,
            length_m: f(1)?,
            length_rate_mps: f(2)?,
            alpha_rad: f(3)?,
            alpha_ref_rad: f(4)?,
            delta_rad: f(5)?,
            delta_rate_radps: f(6)?,
            beta_rad: f(7)?,
            tension_n: f(8)?,
            phase: parse_phase(phase_text).ok_or_else(|| bad(9, phase_text))?,
            alpha_rate_radps: f(10)?,
            length_accel_mps2: f(11)?,
            law_rate_mps: f(12)?,
            blend_weight: f(13)?,
            flags: flags_text.parse().map_err(|_| bad(14, flags_text))?,
        });
    }
    Ok(samples)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn header_is_exact() {
        assert_eq!(
            history_header(),
            "t_s,length_m,length_rate_mps,alpha_rad,alpha_ref_rad,delta_rad,delta_rate_radps,\
             beta_rad,tension_n,phase,alpha_rate_radps,length_accel_mps2,law_rate_mps,\
             blend_weight,flags"
        );
    }

    fn phase() -> impl Strategy<Value = PhaseLabel> {
        prop_oneof![
            Just(PhaseLabel::Deploy),
            Just(PhaseLabel::Keep1),
            Just(PhaseLabel::Slew),
            Just(PhaseLabel::Retrieve),
            Just(PhaseLabel::Keep2),
        ]
    }

    fn sample() -> impl Strategy<Value = Sample> {
        let x = || any::<f64>().prop_filter("not NaN (NaN != NaN)", |v| !v.is_nan());
        (
            (x(), x(), x(), x(), x(), x(), x(), x()),
            (x(), x(), x(), x(), x(), phase(), any::<u32>()),
        )
            .prop_map(
                |((a, b, c, d, e, f, g, h), (i, j, k, l, m, phase, flags))| Sample {
                    t_s: a,
                    length_m: b,
                    length_rate_mps: c,
                    alpha_rad: d,
                    alpha_rate_radps: e,
                    alpha_ref_rad: f,
                    delta_rad: g,
                    delta_rate_radps: h,
                    beta_rad: i,
                    tension_n: j,
                    length_accel_mps2: k,
                    law_rate_mps: l,
                    blend_weight: m,
                    phase,
                    flags,
                },
            )
    }

    proptest! {
        #[test]
        fn csv_round_trips_bit_exactly(samples in proptest::collection::vec(sample(), 0..20)) {
            let mut buf = Vec::new();
            write_history_csv(&mut buf, &samples).unwrap();
            let back = read_history_csv(buf.as_slice()).unwrap();
            prop_assert_eq!(back, samples);
        }
    }

    #[test]
    fn nan_is_written_and_read() {
        let s = Sample {
            t_s: 0.0,
            length_m: f64::NAN,
            length_rate_mps: f64::INFINITY,
            alpha_rad: f64::NEG_INFINITY,
            alpha_rate_radps: 0.0,
            alpha_ref_rad: 0.0,
            delta_rad: 0.0,
            delta_rate_radps: 0.0,
            beta_rad: 0.0,
            tension_n: 0.0,
            length_accel_mps2: 0.0,
            law_rate_mps: 0.0,
            blend_weight: 1.0,
            phase: PhaseLabel::Deploy,
            flags: 5,
        };
        let mut buf = Vec::new();
        write_history_csv(&mut buf, &[s]).unwrap();
        let text = String::from_utf8(buf.clone()).unwrap();
        assert!(text.lines().nth(1).unwrap().starts_with("0,NaN,inf,-inf,"));
        let back = read_history_csv(buf.as_slice()).unwrap();
        assert!(back[0].length_m.is_nan());
        assert_eq!(back[0].length_rate_mps, f64::INFINITY);
        assert_eq!(back[0].flags, 5);
    }
}
