//! Progress display on stderr: a spinner with the current stage when stderr is
//! a terminal, nothing when it is piped or `--quiet` is given.
//!
//! [`Progress`] implements the library's [`scanfit::progress::Progress`], so a
//! command hands it to a pipeline (`&progress`) and the pipeline's stages
//! show on the spinner, its steps on a bar.
//!
//! With the environment variable `SCANFIT_TIMINGS` set (to anything), every
//! stage's wall time is printed to stderr when the next one begins, as
//! `timing: <stage>: <seconds> s`: the stage split of the benchmarks in
//! BENCHMARKS.md (`benches/scale/run.sh`).

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// A stage display that is silent off a terminal.
pub struct Progress {
    bar: Option<ProgressBar>,
    /// With `SCANFIT_TIMINGS`: the current stage and when it began.
    timing: Option<Mutex<(String, Instant)>>,
}

/// The stage clock when `SCANFIT_TIMINGS` is set.
fn clock() -> Option<Mutex<(String, Instant)>> {
    std::env::var_os("SCANFIT_TIMINGS").map(|_| Mutex::new(("start".into(), Instant::now())))
}

impl Progress {
    /// A spinner (or nothing when quiet / not a terminal).
    pub fn spinner(quiet: bool) -> Self {
        if quiet || !std::io::stderr().is_terminal() {
            return Self {
                bar: None,
                timing: clock(),
            };
        }
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.enable_steady_tick(Duration::from_millis(100));
        Self {
            bar: Some(bar),
            timing: clock(),
        }
    }

    /// A bar over `len` steps (or nothing when quiet / not a terminal).
    pub fn bar(quiet: bool, len: u64) -> Self {
        if quiet || !std::io::stderr().is_terminal() {
            return Self {
                bar: None,
                timing: clock(),
            };
        }
        let bar = ProgressBar::new(len);
        bar.set_style(
            ProgressStyle::with_template("{bar:30} {pos}/{len} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        Self {
            bar: Some(bar),
            timing: clock(),
        }
    }

    /// Shows what is being done now.
    pub fn stage(&self, msg: impl Into<String>) {
        let msg = msg.into();
        self.time(&msg);
        if let Some(b) = &self.bar {
            b.set_message(msg);
        }
    }

    /// With `SCANFIT_TIMINGS`: prints the time of the stage that ends and
    /// starts the clock of `next`.
    fn time(&self, next: &str) {
        let Some(t) = &self.timing else { return };
        if let Ok(mut t) = t.lock() {
            crate::print_stderr(format_args!(
                "timing: {}: {:.3} s",
                t.0,
                t.1.elapsed().as_secs_f64()
            ));
            *t = (next.to_string(), Instant::now());
        }
    }

    /// Advances a bar by one step.
    pub fn inc(&self) {
        if let Some(b) = &self.bar {
            b.inc(1);
        }
    }

    /// Removes the display.
    pub fn finish(&self) {
        self.time("done");
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

impl scanfit::progress::Progress for Progress {
    /// Shows the stage's name; a stage of known length turns a bar's length
    /// to it and starts it from zero.
    fn stage(&self, name: &str, steps: Option<u64>) {
        self.time(name);
        if let Some(b) = &self.bar {
            if let (Some(n), Some(_)) = (steps, b.length()) {
                b.set_length(n);
                b.set_position(0);
            }
            b.set_message(name.to_string());
        }
    }

    fn advance(&self, n: u64) {
        if let Some(b) = &self.bar {
            b.inc(n);
        }
    }
}
