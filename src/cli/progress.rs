//! The CLI's [`Progress`]: on a terminal an indicatif bar (or a spinner for uncounted work); in a
//! log (CI, a pipe) one line every [`LOG_EVERY`] of the form `[00:01:05] 120/240 renders  bunny`,
//! so a long job shows it is alive without flooding the log; nothing with `--quiet`.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use lodeval::progress::Progress;

/// Interval between progress lines when stderr is not a terminal.
const LOG_EVERY: Duration = Duration::from_secs(5);

/// [`LOG_EVERY`], or `LODEVAL_PROGRESS_EVERY_MS` milliseconds where that is set (a CI that
/// wants denser or sparser lines; the tests use it to see the lines of a short run).
fn log_every() -> Duration {
    std::env::var("LODEVAL_PROGRESS_EVERY_MS")
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
        .map_or(LOG_EVERY, Duration::from_millis)
}

/// A stage as the log-line form tracks it.
#[derive(Debug)]
pub(crate) struct Stage {
    started: Instant,
    last_line: Instant,
    total: Option<u64>,
    unit: String,
    message: String,
    done: u64,
}

/// Where progress goes.
#[derive(Debug)]
pub(crate) enum Reporter {
    /// `--quiet`.
    Quiet,
    /// A bar on the terminal.
    Bar(Mutex<Option<indicatif::ProgressBar>>),
    /// Lines in a log.
    Log(Mutex<Option<Stage>>),
}

impl Reporter {
    /// The reporter for this process's stderr.
    pub(crate) fn new(quiet: bool) -> Reporter {
        if quiet {
            Reporter::Quiet
        } else if std::io::stderr().is_terminal() {
            Reporter::Bar(Mutex::new(None))
        } else {
            Reporter::Log(Mutex::new(None))
        }
    }
}

fn elapsed(d: Duration) -> String {
    let s = d.as_secs();
    format!("{:02}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
}

impl Stage {
    fn line(&self) -> String {
        let count = match self.total {
            Some(t) => format!("{}/{t} {}", self.done, self.unit),
            None => "working".to_string(),
        };
        format!(
            "[{}] {count}  {}",
            elapsed(self.started.elapsed()),
            self.message
        )
    }

    /// Print a line if the last one is old enough.
    fn tick(&mut self) {
        if self.last_line.elapsed() >= log_every() {
            self.last_line = Instant::now();
            note!("{}", self.line());
        }
    }
}

impl Progress for Reporter {
    fn start(&self, total: Option<u64>, unit: &str, message: &str) {
        match self {
            Reporter::Quiet => {}
            Reporter::Bar(slot) => {
                let bar = match total {
                    Some(n) => {
                        let bar = indicatif::ProgressBar::new(n);
                        if let Ok(style) = indicatif::ProgressStyle::with_template(&format!(
                            "{{spinner}} [{{elapsed_precise}}] {{bar:40}} {{pos}}/{{len}} {unit}  {{msg}}"
                        )) {
                            bar.set_style(style);
                        }
                        bar
                    }
                    None => {
                        let bar = indicatif::ProgressBar::new_spinner();
                        if let Ok(style) = indicatif::ProgressStyle::with_template(
                            "{spinner} [{elapsed_precise}] {msg}",
                        ) {
                            bar.set_style(style);
                        }
                        bar.enable_steady_tick(Duration::from_millis(120));
                        bar
                    }
                };
                bar.set_message(message.to_string());
                if let Ok(mut s) = slot.lock() {
                    *s = Some(bar);
                }
            }
            Reporter::Log(slot) => {
                if let Ok(mut s) = slot.lock() {
                    let now = Instant::now();
                    *s = Some(Stage {
                        started: now,
                        last_line: now,
                        total,
                        unit: unit.to_string(),
                        message: message.to_string(),
                        done: 0,
                    });
                }
            }
        }
    }

    fn set_message(&self, message: &str) {
        match self {
            Reporter::Quiet => {}
            Reporter::Bar(slot) => {
                if let Ok(s) = slot.lock()
                    && let Some(b) = s.as_ref()
                {
                    b.set_message(message.to_string());
                }
            }
            Reporter::Log(slot) => {
                if let Ok(mut s) = slot.lock()
                    && let Some(st) = s.as_mut()
                {
                    st.message = message.to_string();
                    st.tick();
                }
            }
        }
    }

    fn advance(&self, steps: u64) {
        match self {
            Reporter::Quiet => {}
            Reporter::Bar(slot) => {
                if let Ok(s) = slot.lock()
                    && let Some(b) = s.as_ref()
                {
                    b.inc(steps);
                }
            }
            Reporter::Log(slot) => {
                if let Ok(mut s) = slot.lock()
                    && let Some(st) = s.as_mut()
                {
                    st.done += steps;
                    st.tick();
                }
            }
        }
    }

    fn set_position(&self, done: u64) {
        match self {
            Reporter::Quiet => {}
            Reporter::Bar(slot) => {
                if let Ok(s) = slot.lock()
                    && let Some(b) = s.as_ref()
                {
                    b.set_position(done);
                }
            }
            Reporter::Log(slot) => {
                if let Ok(mut s) = slot.lock()
                    && let Some(st) = s.as_mut()
                {
                    st.done = done;
                    st.tick();
                }
            }
        }
    }

    fn finish(&self) {
        match self {
            Reporter::Quiet => {}
            Reporter::Bar(slot) => {
                if let Ok(mut s) = slot.lock()
                    && let Some(b) = s.take()
                {
                    b.finish_and_clear();
                }
            }
            Reporter::Log(slot) => {
                // The last line says where the stage ended, however recent the one before.
                if let Ok(mut s) = slot.lock()
                    && let Some(st) = s.take()
                    && st.total.is_some()
                    && st.done > 0
                {
                    note!("{}", st.line());
                }
            }
        }
    }
}
