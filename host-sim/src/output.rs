//! Every file a command writes goes through this module.
//!
//! **Output directories** ([`OutputSet`]). A command checks its output directory before any
//! work (it is created and probed for writing: an unusable one is a [`UsageError`], exit code
//! 2), writes each file under a temporary name next to its final one (`history.partial.csv`
//! for `history.csv`), and renames them all into place only when the whole set is written. A
//! failed run leaves the directory as it was (what it created is removed again), except for a
//! log that explains the failure (PIL's `firmware.partial.log`). Each command owns a fixed set
//! of file names: on success, those of its names that this run did not write (say `pil.txt`
//! after a run without `--pil`, or the figures when they could not be drawn) are removed, so
//! that no earlier run's file sits next to this run's results. Other files are left alone.
//!
//! **`history.csv`**: one row per [`Sample`], every number at full (round-trip) precision.
//! The first ten columns are fixed (scripts and the paper's figures rely on them); the extra
//! columns follow in [`HISTORY_EXTRA_COLUMNS`] order. Numbers are written with Rust's `{}`
//! formatting of `f64`, the shortest text that parses back to the same bits
//! (`NaN`, `inf` and `-inf` for non-finite values).

use std::fs::File;
use std::io::{self, BufRead, BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::Context as _;

use crate::history::{PhaseLabel, Sample};
use crate::usage::UsageError;

/// The longest directory name [`default_dir`] makes from the overrides, bytes (file systems
/// allow 255).
const MAX_DEFAULT_DIR_NAME: usize = 120;

/// Where a command writes without `--out`: `out/<scenario name>` for the file as it is, and
/// `out/<name>+<key>=<value>+…` with `--set` overrides (their characters outside
/// `[A-Za-z0-9._=+-]` written `_`; a name longer than 120 bytes ends in a hash of the
/// overrides instead), so that a run with overrides never replaces the results of one without.
pub fn default_dir(scenario_name: &str, sets: &[String]) -> PathBuf {
    let mut name = scenario_name.to_string();
    for set in sets {
        name.push('+');
        name.extend(set.chars().map(|c| {
            if c.is_ascii_alphanumeric() || "._=+-".contains(c) {
                c
            } else {
                '_'
            }
        }));
    }
    if name.len() > MAX_DEFAULT_DIR_NAME {
        let hash = fnv1a(sets.join("\n").as_bytes());
        name = format!("{scenario_name}+{hash:016x}");
    }
    Path::new("out").join(name)
}

/// FNV-1a, 64 bits (Fowler, Noll and Vo): a short, stable name for a list of overrides.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Checks, without creating anything, that `dir` is a directory or can be created as one
/// (`flag` names the option in the message).
pub fn check_output_dir(flag: &str, dir: &Path) -> Result<(), UsageError> {
    if dir.as_os_str().is_empty() {
        return Err(UsageError(format!("{flag}: the output directory is empty")));
    }
    let mut probe = Some(dir);
    while let Some(p) = probe {
        if p.as_os_str().is_empty() {
            break; // a relative path: its base is the working directory
        }
        match std::fs::metadata(p) {
            Ok(m) if m.is_dir() => return Ok(()),
            Ok(_) if p == dir => {
                return Err(UsageError(format!(
                    "{flag} {}: exists and is not a directory",
                    dir.display()
                )))
            }
            Ok(_) => {
                return Err(UsageError(format!(
                    "{flag} {}: cannot be created: {} is not a directory",
                    dir.display(),
                    p.display()
                )))
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => probe = p.parent(),
            Err(e) => {
                return Err(UsageError(format!(
                    "{flag} {}: cannot inspect {}: {e}",
                    dir.display(),
                    p.display()
                )))
            }
        }
    }
    Ok(())
}

/// Creates `path` and writes it through a buffer with `body`; an error names the file.
pub fn write_file(
    path: &Path,
    body: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> anyhow::Result<()> {
    let file = File::create(path).with_context(|| format!("creating {}", path.display()))?;
    let mut w = BufWriter::new(file);
    body(&mut w)
        .and_then(|()| w.flush())
        .with_context(|| format!("writing {}", path.display()))
}

/// The temporary name a file is written under until its set is complete: `.partial` before
/// the extension (plotters picks the image format from the extension).
fn partial_name(name: &str) -> String {
    match name.rsplit_once('.') {
        Some((stem, ext)) => format!("{stem}.partial.{ext}"),
        None => format!("{name}.partial"),
    }
}

/// The files one command writes into one directory, renamed into place together (see the
/// module docs).
#[derive(Debug)]
pub struct OutputSet {
    dir: PathBuf,
    /// Every file name the command may write.
    owned: Vec<String>,
    /// Files staged so far: final name, temporary path.
    staged: Vec<(String, PathBuf)>,
    /// Temporary files kept if the run fails (they explain it).
    keep_on_failure: Vec<PathBuf>,
    /// Directories this set created, innermost first (removed again on failure if empty).
    created: Vec<PathBuf>,
    committed: bool,
}

impl OutputSet {
    /// Checks `dir` (named by `flag` in errors), creates it if needed and makes sure a file can
    /// be written in it: all before any work. `owned` are the file names the command writes.
    pub fn prepare(flag: &str, dir: &Path, mut owned: Vec<String>) -> Result<Self, UsageError> {
        check_output_dir(flag, dir)?;
        owned.sort();
        owned.dedup();
        let mut created = Vec::new();
        let mut p = Some(dir);
        while let Some(d) = p.filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
            created.push(d.to_path_buf());
            p = d.parent();
        }
        // Built first, so that a failure below removes what was created.
        let set = Self {
            dir: dir.to_path_buf(),
            owned,
            staged: Vec::new(),
            keep_on_failure: Vec::new(),
            created,
            committed: false,
        };
        let unusable =
            |e: io::Error| UsageError(format!("{flag} {}: cannot write there: {e}", dir.display()));
        std::fs::create_dir_all(dir).map_err(unusable)?;
        let probe = dir.join(format!(".tss-sim-probe-{}", std::process::id()));
        File::create(&probe)
            .and_then(|mut f| f.write_all(b"probe"))
            .map_err(unusable)?;
        std::fs::remove_file(&probe).map_err(unusable)?;
        // A directory where a result goes would make its rename fail after all the work.
        for name in &set.owned {
            let path = dir.join(name);
            if path.is_dir() {
                return Err(UsageError(format!(
                    "{flag} {}: {} is a directory, where the file {name} goes",
                    dir.display(),
                    path.display()
                )));
            }
        }
        Ok(set)
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The temporary path to write the file `name` to; it is renamed to `name` by
    /// [`OutputSet::commit`].
    pub fn stage(&mut self, name: &str) -> PathBuf {
        debug_assert!(
            self.owned
                .binary_search_by(|o| o.as_str().cmp(name))
                .is_ok(),
            "{name} is not among the command's files"
        );
        let tmp = self.dir.join(partial_name(name));
        self.staged.push((name.to_string(), tmp.clone()));
        tmp
    }

    /// Writes the file `name` with `body` (under its temporary name); returns its final path.
    pub fn write(
        &mut self,
        name: &str,
        body: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
    ) -> anyhow::Result<PathBuf> {
        let tmp = self.stage(name);
        write_file(&tmp, body)?;
        Ok(self.dir.join(name))
    }

    /// Has the file `name` been staged?
    pub fn is_staged(&self, name: &str) -> bool {
        self.staged.iter().any(|(n, _)| n == name)
    }

    /// Keeps the staged file `name` under its temporary name if the run fails.
    pub fn keep_on_failure(&mut self, name: &str) {
        self.keep_on_failure.push(self.dir.join(partial_name(name)));
    }

    /// How many files are staged (a mark for [`OutputSet::abandon_since`]).
    pub fn mark(&self) -> usize {
        self.staged.len()
    }

    /// Drops the files staged since `mark` (a part that failed, e.g. the figures): they are not
    /// committed, and their earlier versions are removed by the commit.
    pub fn abandon_since(&mut self, mark: usize) {
        for (_, tmp) in self.staged.drain(mark.min(self.staged.len())..) {
            let _ = std::fs::remove_file(tmp);
        }
    }

    /// Renames every staged file into place and removes the command's other files (those of
    /// an earlier run that this one did not write).
    pub fn commit(mut self) -> anyhow::Result<()> {
        for name in &self.owned {
            if self.staged.iter().any(|(n, _)| n == name) {
                continue;
            }
            let stale = self.dir.join(name);
            match std::fs::remove_file(&stale) {
                Ok(()) => {}
                Err(e) if e.kind() == io::ErrorKind::NotFound => {}
                Err(e) => {
                    return Err(e).with_context(|| {
                        format!("removing {} (an earlier run's file)", stale.display())
                    })
                }
            }
            let _ = std::fs::remove_file(self.dir.join(partial_name(name)));
        }
        for (name, tmp) in &self.staged {
            let to = self.dir.join(name);
            std::fs::rename(tmp, &to)
                .with_context(|| format!("renaming {} to {}", tmp.display(), to.display()))?;
        }
        self.committed = true;
        Ok(())
    }
}

impl Drop for OutputSet {
    /// A set dropped without [`OutputSet::commit`] is a failed run: its temporary files go
    /// (but those that explain the failure), and so do the directories it created, if empty.
    fn drop(&mut self) {
        if self.committed {
            return;
        }
        for (_, tmp) in &self.staged {
            if !self.keep_on_failure.contains(tmp) {
                let _ = std::fs::remove_file(tmp);
            }
        }
        for d in &self.created {
            if std::fs::remove_dir(d).is_err() {
                break;
            }
        }
    }
}

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
        write_sample(&mut w, s)?;
        writeln!(w)?;
    }
    w.flush()
}

/// One sample's [`HISTORY_COLUMNS`] and [`HISTORY_EXTRA_COLUMNS`], comma-separated, without
/// the line end (the elastic history appends its own columns).
fn write_sample<W: Write>(w: &mut W, s: &Sample) -> io::Result<()> {
    write!(
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
    )
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
        write_sample(&mut w, s)?;
        writeln!(
            w,
            ",{},{},{},{},{},{}",
            e.range_m, e.tension_tip_n, e.bowing_m, e.alpha_sensed_rad, e.reel_rate_mps, e.beads,
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
