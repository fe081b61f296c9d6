//! `runs.csv`: one row per run, sorted by run index.
//!
//! Columns: `run`, `sensor_seed`, one column per dispersed field (named by its dotted key),
//! the outcomes ([`Metric::ALL`]), `worst_health`, `pass`, `failed` (the criteria failed,
//! `;`-separated) and `error` (why a run did not complete). Numbers are written in Rust's
//! shortest round-trip form, so reading a file back gives the very same values, and an
//! undefined outcome is an empty cell. A file read back and written again is byte-identical.

use std::io::{Read, Write};

use super::campaign::{Criterion, Metric, Outcome, RunRecord, WorstHealth};

/// The header of `runs.csv` for a campaign dispersing `fields`.
pub fn header(fields: &[&str]) -> Vec<String> {
    let mut h = vec!["run".to_string(), "sensor_seed".to_string()];
    h.extend(fields.iter().map(|f| f.to_string()));
    h.extend(Metric::ALL.iter().map(|m| m.name().to_string()));
    h.extend(["worst_health", "pass", "failed", "error"].map(String::from));
    h
}

fn cell(v: Option<f64>) -> String {
    v.map(|x| x.to_string()).unwrap_or_default()
}

fn writer<W: Write>(w: W) -> csv::Writer<W> {
    csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(w)
}

/// Writes `runs.csv` (records in the order given: sort them by run index first).
pub fn write_runs<W: Write>(w: W, fields: &[&str], records: &[RunRecord]) -> csv::Result<()> {
    let mut out = writer(w);
    out.write_record(header(fields))?;
    write_records(&mut out, records)?;
    out.flush()?;
    Ok(())
}

/// Writes the rows of `records` alone, as [`write_runs`] writes them after the header (the
/// lines a campaign's journal appends).
pub fn write_rows<W: Write>(w: W, records: &[RunRecord]) -> csv::Result<()> {
    let mut out = writer(w);
    write_records(&mut out, records)?;
    out.flush()?;
    Ok(())
}

fn write_records<W: Write>(out: &mut csv::Writer<W>, records: &[RunRecord]) -> csv::Result<()> {
    for r in records {
        let mut row = vec![r.run.to_string(), r.sensor_seed.to_string()];
        row.extend(r.inputs.iter().map(|x| x.to_string()));
        match &r.outcome {
            Some(o) => {
                row.extend(o.values.iter().map(|v| cell(*v)));
                row.push(o.worst_health.as_str().to_string());
            }
            None => row.extend(std::iter::repeat_n(String::new(), Metric::ALL.len() + 1)),
        }
        row.push(r.passed().to_string());
        let failed: Vec<&str> = r.failed.iter().map(|c| c.name()).collect();
        row.push(failed.join(";"));
        row.push(r.error.clone());
        out.write_record(&row)?;
    }
    Ok(())
}

/// What is wrong with a `runs.csv`.
#[derive(Debug, thiserror::Error)]
pub enum RunsCsvError {
    /// The CSV could not be read.
    #[error("{0}")]
    Csv(#[from] csv::Error),
    /// The header is not the one this campaign writes.
    #[error("the header is not that of this campaign: expected `{expected}`, found `{found}`")]
    Header {
        /// The expected header.
        expected: String,
        /// The header found.
        found: String,
    },
    /// A cell could not be parsed.
    #[error("line {line}: column `{column}` = {value:?} {message}")]
    Cell {
        /// 1-based line number.
        line: u64,
        /// Column name.
        column: String,
        /// The cell as written.
        value: String,
        /// What was expected.
        message: &'static str,
    },
}

/// Reads a `runs.csv` written by [`write_runs`] for a campaign dispersing `fields`.
pub fn read_runs<R: Read>(r: R, fields: &[&str]) -> Result<Vec<RunRecord>, RunsCsvError> {
    let expected = header(fields);
    let mut rd = csv::ReaderBuilder::new().has_headers(true).from_reader(r);
    let found: Vec<String> = rd.headers()?.iter().map(String::from).collect();
    if found != expected {
        return Err(RunsCsvError::Header {
            expected: expected.join(","),
            found: found.join(","),
        });
    }
    let n_in = fields.len();
    let mut records = Vec::new();
    for row in rd.records() {
        let row = row?;
        let line = row.position().map_or(0, |p| p.line());
        let bad = |col: usize, message: &'static str| RunsCsvError::Cell {
            line,
            column: expected[col].clone(),
            value: row.get(col).unwrap_or("").to_string(),
            message,
        };
        let text = |col: usize| row.get(col).unwrap_or("");
        let int = |col: usize| {
            text(col)
                .parse::<u64>()
                .map_err(|_| bad(col, "is not a whole number"))
        };
        let num = |col: usize| {
            text(col)
                .parse::<f64>()
                .map_err(|_| bad(col, "is not a number"))
        };
        let run = int(0)?;
        let sensor_seed = int(1)?;
        let inputs = (2..2 + n_in).map(num).collect::<Result<Vec<f64>, _>>()?;
        let first = 2 + n_in;
        let health_col = first + Metric::ALL.len();
        let outcome = if text(health_col).is_empty() {
            None
        } else {
            let mut values = [None; Metric::ALL.len()];
            for (k, v) in values.iter_mut().enumerate() {
                let col = first + k;
                if !text(col).is_empty() {
                    *v = Some(num(col)?);
                }
            }
            let worst_health = WorstHealth::parse(text(health_col))
                .ok_or_else(|| bad(health_col, "is not a health level"))?;
            Some(Outcome {
                values,
                worst_health,
            })
        };
        let failed_col = health_col + 2;
        let failed = if text(failed_col).is_empty() {
            Vec::new()
        } else {
            text(failed_col)
                .split(';')
                .map(|s| {
                    Criterion::parse(s).ok_or_else(|| bad(failed_col, "names an unknown criterion"))
                })
                .collect::<Result<Vec<_>, _>>()?
        };
        let record = RunRecord {
            run,
            sensor_seed,
            inputs,
            outcome,
            failed,
            error: text(failed_col + 1).to_string(),
        };
        if text(health_col + 1) != record.passed().to_string() {
            return Err(bad(health_col + 1, "disagrees with the `failed` column"));
        }
        records.push(record);
    }
    Ok(records)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_read_back_is_the_same_records_and_the_same_bytes() {
        let mut values = [None; Metric::ALL.len()];
        values[0] = Some(11_802.345_678_9);
        values[5] = Some(3.3e-5);
        values[6] = Some(0.0);
        values[7] = Some(f64::NAN);
        let records = vec![
            RunRecord {
                run: 0,
                sensor_seed: u64::MAX,
                inputs: vec![0.1 + 0.2, -1e-300],
                outcome: Some(Outcome {
                    values,
                    worst_health: WorstHealth::Degraded,
                }),
                failed: vec![Criterion::Keep1Error, Criterion::NoSlack],
                error: String::new(),
            },
            RunRecord {
                run: 1,
                sensor_seed: 7,
                inputs: vec![f64::INFINITY, 2.0],
                outcome: None,
                failed: vec![Criterion::Completed],
                error: "invalid dispersed scenario: masses.sub_kg = -1 must be above 0, \"quoted\""
                    .into(),
            },
        ];
        let fields = ["initial.delta_rad", "masses.sub_kg"];
        let mut a = Vec::new();
        write_runs(&mut a, &fields, &records).unwrap();
        let back = read_runs(a.as_slice(), &fields).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[1], records[1]);
        assert_eq!(back[0].inputs[0].to_bits(), records[0].inputs[0].to_bits());
        let mut b = Vec::new();
        write_runs(&mut b, &fields, &back).unwrap();
        assert_eq!(a, b);
        let text = String::from_utf8(a).unwrap();
        assert!(
            text.starts_with("run,sensor_seed,initial.delta_rad,masses.sub_kg,time_to_keep1_s,"),
            "{text}"
        );
        assert!(
            text.contains(",degraded,false,keep1_error;slack,\n"),
            "{text}"
        );
        let e = read_runs(text.as_bytes(), &["initial.delta_rad"]).unwrap_err();
        assert!(e.to_string().contains("header"), "{e}");
    }
}
