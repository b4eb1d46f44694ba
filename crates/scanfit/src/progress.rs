//! Progress reporting from long pipelines to the front that runs them.
//!
//! A pipeline never prints: it tells a [`Progress`] which stage it is in and
//! how far it has come, and the front (the CLI's progress bar, a Python
//! callback) decides what to show. [`NoProgress`] ignores everything.

/// What a pipeline reports while it runs.
///
/// Both methods have empty defaults, so an implementation overrides only what
/// it shows. Implementations must be cheap: `advance` may be called once per
/// work item from several threads.
///
/// ```
/// use scanfit::progress::{Progress, NoProgress};
/// use std::sync::Mutex;
///
/// struct Log(Mutex<Vec<String>>);
/// impl Progress for Log {
///     fn stage(&self, name: &str, _steps: Option<u64>) {
///         if let Ok(mut v) = self.0.lock() {
///             v.push(name.to_string());
///         }
///     }
/// }
/// let log = Log(Mutex::new(Vec::new()));
/// log.stage("parameters", Some(10));
/// log.advance(3);
/// NoProgress.stage("ignored", None);
/// assert_eq!(log.0.lock().map(|v| v.len()).unwrap_or(0), 1);
/// ```
pub trait Progress: Sync {
    /// A new stage begins; `steps` is its length when known.
    fn stage(&self, name: &str, steps: Option<u64>) {
        let _ = (name, steps);
    }
    /// `n` more steps of the current stage are done.
    fn advance(&self, n: u64) {
        let _ = n;
    }
}

/// A [`Progress`] that reports nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {}

impl<P: Progress + ?Sized> Progress for &P {
    fn stage(&self, name: &str, steps: Option<u64>) {
        (**self).stage(name, steps);
    }
    fn advance(&self, n: u64) {
        (**self).advance(n);
    }
}
