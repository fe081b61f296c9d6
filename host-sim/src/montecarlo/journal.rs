//! The journal of a campaign's output directory: each run's row of `runs.csv` appended as the
//! run finishes, so that a shard killed or requeued by a batch system resumes where it stopped.
//!
//! `runs.journal.csv` starts with a line that names the campaign ([`identity`]: build,
//! scenario fingerprint, seed, runs, shard, `--consistency`), then `runs.csv`'s header, then
//! one row per flown run in the order the runs finished. Rows are appended a batch at a time
//! (every [`JOURNAL_EVERY_S`] at most, and at the end) and each batch is flushed to the disk
//! (`fsync`) before the campaign goes on, so a killed process loses at most its last batch. With
//! `--consistency`, `consistency.checkpoint.csv` holds the exact NEES/NIS sums over the first
//! `covers` rows of the journal (replaced atomically after each batch).
//!
//! On start, [`Journal::open`] reads the journal of the same campaign back: a line cut short
//! by the kill is dropped, and so are the rows the checkpoint does not cover; the rest are the
//! runs already flown. Rows are written with the same shortest round-trip numbers as
//! `runs.csv`, so a run read back is the run flown, and the finished campaign's files are the
//! same bytes as those of a campaign never interrupted. A journal of another campaign (other
//! build, scenario, seed, size or shard) is replaced: that campaign starts from its first run.
//! The journal stays beside the results once the campaign is done: rerunning the command then
//! flies nothing and writes the same files again.
//!
//! While it flies, a campaign holds an exclusive lock on `campaign.lock` in its directory: a
//! second process on the same directory (a requeued job whose first copy still runs) is refused
//! rather than interleaving its rows with the first's.

use std::collections::BTreeSet;
use std::fs::{File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::Context as _;

use super::campaign::RunRecord;
use super::consistency::ConsistencySums;
use super::table;
use crate::usage::UsageError;

/// The journal of runs.
pub const RUNS_JOURNAL: &str = "runs.journal.csv";
/// The checkpoint of the consistency sums (`--consistency`).
pub const CONSISTENCY_CHECKPOINT: &str = "consistency.checkpoint.csv";
/// The file a flying campaign holds locked.
pub const LOCK: &str = "campaign.lock";

/// The longest a finished run waits before its row is appended and flushed, s.
pub const JOURNAL_EVERY_S: f64 = 1.0;

/// [`JOURNAL_EVERY_S`] as a duration.
pub fn journal_every() -> Duration {
    Duration::from_secs_f64(JOURNAL_EVERY_S)
}

/// What the journal's first line says a campaign is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Identity {
    /// The build (`Manifest::build`).
    pub build: String,
    /// The scenario's fingerprint.
    pub fingerprint: String,
    /// The seed.
    pub seed: String,
    /// Runs of the whole campaign.
    pub runs: u64,
    /// The shard, `K/N`.
    pub shard: String,
    /// `--consistency`.
    pub consistency: bool,
}

/// The first line of a journal and of a checkpoint.
pub fn identity(id: &Identity) -> String {
    format!(
        "# tss-sim campaign journal: build {}, scenario {}, seed {}, runs {}, shard {}, \
         consistency {}",
        id.build, id.fingerprint, id.seed, id.runs, id.shard, id.consistency
    )
}

/// What an earlier, interrupted invocation had flown.
#[derive(Debug, Default)]
pub struct Resumed {
    /// The runs flown, in the order they finished.
    pub records: Vec<RunRecord>,
    /// With `--consistency`, their sums.
    pub sums: Option<ConsistencySums>,
    /// Why the journal found was not used, if it was not (another campaign's).
    pub replaced: Option<String>,
}

/// An open journal, appending.
#[derive(Debug)]
pub struct Journal {
    dir: PathBuf,
    /// Held locked until the journal is dropped (and by the system until the process ends).
    _lock: File,
    file: File,
    first_line: String,
    rows: u64,
}

fn damaged(path: &Path, what: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!(
        "{}: {what}: the journal is damaged; remove it to fly the campaign from its first run",
        path.display()
    )
}

/// Flushes the directory entry of a file just created or renamed in `dir`.
fn sync_dir(dir: &Path) -> io::Result<()> {
    File::open(dir)?.sync_all()
}

impl Journal {
    /// Opens the journal of the campaign `id` in `dir` (created if needed), flying the runs
    /// `runs` and dispersing `fields`: returns it, ready to append, with what it already holds.
    pub fn open(
        dir: &Path,
        id: &Identity,
        fields: &[&str],
        runs: &[u64],
    ) -> anyhow::Result<(Self, Resumed)> {
        let lock = lock(dir)?;
        let first_line = identity(id);
        let path = dir.join(RUNS_JOURNAL);
        let mut resumed = match std::fs::read(&path) {
            Ok(bytes) => read(&path, &bytes, &first_line, fields, runs)?,
            Err(e) if e.kind() == io::ErrorKind::NotFound => Resumed::default(),
            Err(e) => return Err(e).with_context(|| format!("reading {}", path.display())),
        };
        if resumed.replaced.is_none() && id.consistency {
            let (covered, sums) = read_checkpoint(dir, &first_line)?;
            if covered > resumed.records.len() {
                return Err(damaged(
                    &dir.join(CONSISTENCY_CHECKPOINT),
                    format_args!(
                        "covers {covered} runs, the journal holds {}",
                        resumed.records.len()
                    ),
                ));
            }
            // The rows after the checkpoint are flown again: their NEES and NIS are not in it.
            resumed.records.truncate(covered);
            resumed.sums = Some(sums);
        } else if id.consistency {
            resumed.sums = Some(ConsistencySums::default());
        }
        // Rewritten whole, atomically: what it holds now is exactly what resumes.
        let tmp = dir.join("runs.journal.partial.csv");
        write_synced(&tmp, |w| {
            writeln!(w, "{first_line}")?;
            table::write_runs(&mut *w, fields, &resumed.records).map_err(io::Error::other)
        })?;
        std::fs::rename(&tmp, &path)
            .with_context(|| format!("renaming {} to {}", tmp.display(), path.display()))?;
        sync_dir(dir).with_context(|| format!("flushing {}", dir.display()))?;
        let file = OpenOptions::new()
            .append(true)
            .open(&path)
            .with_context(|| format!("opening {}", path.display()))?;
        let journal = Self {
            dir: dir.to_path_buf(),
            _lock: lock,
            file,
            first_line,
            rows: resumed.records.len() as u64,
        };
        if let Some(sums) = &resumed.sums {
            journal.checkpoint(sums)?;
        }
        Ok((journal, resumed))
    }

    /// Appends `records` (and with `--consistency` replaces the checkpoint by `sums`, the sums
    /// over every run journaled), flushed to the disk before it returns.
    pub fn append(
        &mut self,
        records: &[RunRecord],
        sums: Option<&ConsistencySums>,
    ) -> anyhow::Result<()> {
        let path = self.dir.join(RUNS_JOURNAL);
        let mut rows = Vec::new();
        table::write_rows(&mut rows, records).map_err(io::Error::other)?;
        self.file
            .write_all(&rows)
            .and_then(|()| self.file.sync_data())
            .with_context(|| format!("appending to {}", path.display()))?;
        self.rows += records.len() as u64;
        if let Some(sums) = sums {
            self.checkpoint(sums)?;
        }
        Ok(())
    }

    /// Replaces the checkpoint by `sums`, covering the rows journaled so far.
    fn checkpoint(&self, sums: &ConsistencySums) -> anyhow::Result<()> {
        let path = self.dir.join(CONSISTENCY_CHECKPOINT);
        let tmp = self.dir.join("consistency.checkpoint.partial.csv");
        write_synced(&tmp, |w| {
            writeln!(w, "{}", self.first_line)?;
            writeln!(w, "# covers {} runs of {RUNS_JOURNAL}", self.rows)?;
            sums.write_sums(w)
        })?;
        std::fs::rename(&tmp, &path)
            .with_context(|| format!("renaming {} to {}", tmp.display(), path.display()))?;
        sync_dir(&self.dir).with_context(|| format!("flushing {}", self.dir.display()))
    }
}

/// Locks `dir`'s [`LOCK`] for this process; refused if another process holds it. A file
/// system without locks is not an error (the campaign then relies on one process a directory).
fn lock(dir: &Path) -> anyhow::Result<File> {
    let path = dir.join(LOCK);
    let file = OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .with_context(|| format!("opening {}", path.display()))?;
    match file.try_lock() {
        Ok(()) | Err(std::fs::TryLockError::Error(_)) => Ok(file),
        Err(std::fs::TryLockError::WouldBlock) => Err(UsageError(format!(
            "{}: another tss-sim is flying a campaign in {} (it holds {LOCK}); wait for it to \
             end, or stop it",
            path.display(),
            dir.display()
        ))
        .into()),
    }
}

/// Writes `path` with `body` and flushes it to the disk.
fn write_synced(
    path: &Path,
    body: impl FnOnce(&mut io::BufWriter<&File>) -> io::Result<()>,
) -> anyhow::Result<()> {
    let file = File::create(path).with_context(|| format!("creating {}", path.display()))?;
    let mut w = io::BufWriter::new(&file);
    body(&mut w)
        .and_then(|()| w.flush())
        .and_then(|()| file.sync_all())
        .with_context(|| format!("writing {}", path.display()))
}

/// The runs a journal holds, or why it is not this campaign's.
fn read(
    path: &Path,
    bytes: &[u8],
    first_line: &str,
    fields: &[&str],
    runs: &[u64],
) -> anyhow::Result<Resumed> {
    let text = String::from_utf8_lossy(bytes);
    let (head, body) = text.split_once('\n').unwrap_or((&text, ""));
    if head != first_line {
        return Ok(Resumed {
            replaced: Some(format!(
                "{} is the journal of another campaign ({:?}); this one starts from its first run",
                path.display(),
                head.chars().take(300).collect::<String>()
            )),
            ..Resumed::default()
        });
    }
    // A line cut short by the kill ends without its newline: dropped.
    let whole = body.rfind('\n').map_or("", |end| &body[..=end]);
    let records = table::read_runs(whole.as_bytes(), fields).map_err(|e| damaged(path, e))?;
    let ours: BTreeSet<u64> = runs.iter().copied().collect();
    let mut seen = BTreeSet::new();
    for r in &records {
        if !ours.contains(&r.run) {
            return Err(damaged(
                path,
                format_args!("run {} is not one of this shard's", r.run),
            ));
        }
        if !seen.insert(r.run) {
            return Err(damaged(path, format_args!("run {} is there twice", r.run)));
        }
    }
    Ok(Resumed {
        records,
        ..Resumed::default()
    })
}

/// The rows the checkpoint covers and its sums (0 and none if there is none of this campaign).
fn read_checkpoint(dir: &Path, first_line: &str) -> anyhow::Result<(usize, ConsistencySums)> {
    let path = dir.join(CONSISTENCY_CHECKPOINT);
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Ok((0, ConsistencySums::default()))
        }
        Err(e) => return Err(e).with_context(|| format!("reading {}", path.display())),
    };
    let mut lines = text.splitn(3, '\n');
    if lines.next() != Some(first_line) {
        return Ok((0, ConsistencySums::default()));
    }
    let covered = lines
        .next()
        .and_then(|l| l.strip_prefix("# covers "))
        .and_then(|l| l.strip_suffix(&format!(" runs of {RUNS_JOURNAL}")))
        .and_then(|n| n.parse::<usize>().ok())
        .ok_or_else(|| damaged(&path, "its second line is not `# covers N runs of …`"))?;
    let sums = ConsistencySums::read_sums(lines.next().unwrap_or(""))
        .map_err(|e| damaged(&path, format_args!("the sums after line 2: {e}")))?;
    Ok((covered, sums))
}
