//! Parsing of the option values the commands share.

use anyhow::{Context, Result};

/// `"NxM"` (or `"N"` for `N x N`) as two whole numbers; `what` names the
/// option in the error (e.g. `--ctrl`).
pub fn pair(s: &str, what: &str) -> Result<(usize, usize)> {
    let parse = |x: &str| {
        x.trim().parse::<usize>().with_context(|| {
            format!("{what} '{s}' must be N or NxM with whole numbers, e.g. 20x16")
        })
    };
    match s.split_once(['x', 'X']) {
        Some((a, b)) => Ok((parse(a)?, parse(b)?)),
        None => {
            let n = parse(s)?;
            Ok((n, n))
        }
    }
}
