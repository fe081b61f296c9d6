//! How far a campaign is: a progress bar on a terminal, and lines in a log otherwise (a batch
//! job's output file, a CI log), where a bar would be invisible until the end.
//!
//! A line says the runs done of the total, how many pass, how many an earlier invocation had
//! flown (resumed from the journal), the rate and the time left:
//!
//! ```text
//! progress: 120/500 runs (24.0 %), 118 pass, 40 resumed; 3.12 runs/s, 2 min 02 s left
//! ```
//!
//! It is written every `--progress-every` seconds, and once more when the runs are done.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

use crate::usage::quiet;

/// The default of `--progress-every`, s.
pub const PROGRESS_EVERY_S: f64 = 10.0;

/// The campaign's progress, shown as it goes.
pub struct Progress {
    show: Show,
    total: u64,
    done: u64,
    passed: u64,
    resumed: u64,
    started: Instant,
}

enum Show {
    /// `--quiet`.
    Nothing,
    /// On a terminal.
    Bar(ProgressBar),
    /// Elsewhere: a line every `every`; `written` is the runs done the last line said.
    Lines {
        every: Duration,
        last: Instant,
        written: Option<u64>,
    },
}

impl Progress {
    /// The progress of `total` runs of which `resumed` (`resumed_passed` of them passing) were
    /// flown before; lines every `every` where there is no terminal.
    pub fn new(total: u64, resumed: u64, resumed_passed: u64, every: Duration) -> Self {
        let show = if quiet() {
            Show::Nothing
        } else if std::io::stderr().is_terminal() {
            let bar = ProgressBar::new(total);
            if let Ok(style) = ProgressStyle::with_template(
                "{spinner} runs [{bar:30}] {pos}/{len}, {per_sec}, eta {eta}",
            ) {
                bar.set_style(style.progress_chars("=> "));
            }
            bar.set_position(resumed);
            bar.reset_eta();
            Show::Bar(bar)
        } else {
            Show::Lines {
                every,
                last: Instant::now(),
                written: None,
            }
        };
        Self {
            show,
            total,
            done: resumed,
            passed: resumed_passed,
            resumed,
            started: Instant::now(),
        }
    }

    /// One more run done.
    pub fn run_done(&mut self, passed: bool) {
        self.done += 1;
        self.passed += u64::from(passed);
        let done = self.done;
        let line_due = match &mut self.show {
            Show::Nothing => false,
            Show::Bar(bar) => {
                bar.inc(1);
                false
            }
            Show::Lines {
                every,
                last,
                written,
            } => {
                let due = last.elapsed() >= *every;
                if due {
                    *last = Instant::now();
                    *written = Some(done);
                }
                due
            }
        };
        if line_due {
            eprintln!("{}", self.line());
        }
    }

    /// Every run done: the bar goes, a last line is written (unless the last one said it).
    pub fn finish(&mut self) {
        match &self.show {
            Show::Nothing => {}
            Show::Bar(bar) => bar.finish_and_clear(),
            Show::Lines { written, .. } => {
                if *written != Some(self.done) {
                    eprintln!("{}", self.line());
                }
            }
        }
    }

    /// The progress line.
    pub fn line(&self) -> String {
        let percent = if self.total > 0 {
            100.0 * self.done as f64 / self.total as f64
        } else {
            100.0
        };
        let mut line = format!(
            "progress: {}/{} runs ({percent:.1} %), {} pass",
            self.done, self.total, self.passed
        );
        if self.resumed > 0 {
            line += &format!(", {} resumed", self.resumed);
        }
        let flown = self.done - self.resumed;
        let elapsed = self.started.elapsed().as_secs_f64();
        if flown > 0 && elapsed > 0.0 {
            let rate = flown as f64 / elapsed;
            let left = (self.total - self.done) as f64 / rate;
            line += &format!("; {rate:.3} runs/s, {} left", duration_text(left));
        }
        line
    }
}

/// A duration as `2 h 05 min`, `3 min 07 s` or `12 s`.
pub fn duration_text(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    match (s / 3600, s % 3600 / 60, s % 60) {
        (0, 0, s) => format!("{s} s"),
        (0, m, s) => format!("{m} min {s:02} s"),
        (h, m, _) => format!("{h} h {m:02} min"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_as_hours_minutes_seconds() {
        assert_eq!(duration_text(12.4), "12 s");
        assert_eq!(duration_text(187.0), "3 min 07 s");
        assert_eq!(duration_text(7_500.0), "2 h 05 min");
        assert_eq!(duration_text(-1.0), "0 s");
    }
}
