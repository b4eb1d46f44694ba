//! How a set of values (distances, deviations, heights) is distributed:
//! nearest-rank percentiles and a histogram over a percentile range with an
//! overflow bin, so that a few stray values neither stretch the bins nor
//! a colour scale until the bulk of the data falls into one of them.

use crate::{Error, Result};

/// The nearest-rank `q`-quantile (`q` in `[0, 1]`) of `values`: the value at
/// index `round((n - 1) q)` of the sorted values; `None` for an empty set or
/// a `q` outside `[0, 1]`. Non-finite values sort by [`f64::total_cmp`]
/// (NaN last), so callers pass finite values.
///
/// ```
/// use scanfit::distribution::percentile;
/// let v: Vec<f64> = (1..=1000).map(f64::from).collect();
/// assert_eq!(percentile(&v, 0.99), Some(990.0));
/// assert_eq!(percentile(&v, 0.5), Some(501.0));
/// assert_eq!(percentile(&[], 0.5), None);
/// ```
pub fn percentile(values: &[f64], q: f64) -> Option<f64> {
    if values.is_empty() || !(0.0..=1.0).contains(&q) {
        return None;
    }
    let mut v = values.to_vec();
    let k = ((v.len() - 1) as f64 * q).round() as usize;
    let (_, x, _) = v.select_nth_unstable_by(k, f64::total_cmp);
    Some(*x)
}

/// [`percentile`] of values already sorted ascending (no copy).
pub fn percentile_sorted(sorted: &[f64], q: f64) -> Option<f64> {
    if sorted.is_empty() || !(0.0..=1.0).contains(&q) {
        return None;
    }
    sorted
        .get(((sorted.len() - 1) as f64 * q).round() as usize)
        .copied()
}

/// Counts of non-negative values (distances) in equal bins over
/// `[0, top]`, `top` the `percentile`-th percentile, and the values above
/// `top` in one overflow bin. When no value exceeds the percentile (or it is
/// 0), `top` is the maximum and the overflow bin is empty.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Histogram {
    /// Counts per bin; bin `k` holds `[k w, (k + 1) w)` with `w = top / bins`
    /// (the last regular bin includes `top`).
    pub counts: Vec<usize>,
    /// Upper end of the last regular bin.
    pub top: f64,
    /// The percentile `top` is, in `(0, 100]` (100 when `top` is the maximum).
    pub percentile: f64,
    /// Values above `top`.
    pub overflow: usize,
    /// The largest value.
    pub max: f64,
}

impl Histogram {
    /// Bins `values` (distances, `>= 0`) into `bins` bins over `[0, p-th
    /// percentile]` and an overflow bin (see the type documentation).
    ///
    /// ```
    /// use scanfit::distribution::Histogram;
    /// // 99 values spread over [0, 1) and one stray value at 1000
    /// let mut v: Vec<f64> = (0..99).map(|i| i as f64 / 99.0).collect();
    /// v.push(1000.0);
    /// let h = Histogram::over_percentile(&v, 10, 99.0)?;
    /// assert_eq!(h.overflow, 1);
    /// assert_eq!(h.counts.iter().sum::<usize>(), 99);
    /// assert_eq!(h.max, 1000.0);
    /// # Ok::<(), scanfit::Error>(())
    /// ```
    pub fn over_percentile(values: &[f64], bins: usize, percentile: f64) -> Result<Self> {
        if bins == 0 || bins > 100_000 {
            return Err(Error::InvalidSetting {
                setting: "bins",
                value: bins.to_string(),
                hint: "give 1 to 100000 histogram bins".into(),
            });
        }
        if !(percentile > 0.0 && percentile <= 100.0) {
            return Err(Error::InvalidSetting {
                setting: "percentile",
                value: percentile.to_string(),
                hint: "give a percentile in (0, 100], e.g. 99".into(),
            });
        }
        if let Some(bad) = values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(Error::InvalidSetting {
                setting: "values",
                value: bad.to_string(),
                hint: "histogram values are distances: finite and >= 0".into(),
            });
        }
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let max = sorted.last().copied().unwrap_or(0.0);
        let p = percentile_sorted(&sorted, percentile / 100.0).unwrap_or(0.0);
        let (top, percentile) = if p > 0.0 && p < max {
            (p, percentile)
        } else {
            (max, 100.0)
        };
        let mut counts = vec![0usize; bins];
        let mut overflow = 0;
        for &d in &sorted {
            if d > top {
                overflow += 1;
                continue;
            }
            let b = if top > 0.0 {
                (d / top * bins as f64) as usize
            } else {
                0
            };
            counts[b.min(bins - 1)] += 1;
        }
        Ok(Self {
            counts,
            top,
            percentile,
            overflow,
            max,
        })
    }

    /// Width of one regular bin.
    pub fn bin_width(&self) -> f64 {
        self.top / self.counts.len().max(1) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentile_is_the_nearest_rank_of_the_sorted_values() {
        // an independent definition: the smallest value with at least
        // round((n - 1) q) + 1 values at or below it
        let v: Vec<f64> = (0..517).map(|i| ((i * 7919) % 517) as f64 * 0.37).collect();
        for q in [0.0, 0.01, 0.5, 0.9, 0.95, 0.99, 1.0] {
            let rank = ((v.len() - 1) as f64 * q).round() as usize + 1;
            let expected = v
                .iter()
                .copied()
                .filter(|&x| v.iter().filter(|&&y| y <= x).count() >= rank)
                .fold(f64::INFINITY, f64::min);
            assert_eq!(percentile(&v, q), Some(expected), "q = {q}");
        }
        assert_eq!(percentile(&v, 1.5), None);
    }

    #[test]
    fn histogram_of_a_known_distribution() {
        // 1000 values k / 1000 (k = 0..999) uniform over [0, 1) and 10 strays at 50:
        // p99 of 1010 values is index round(1009 * 0.99) = 999 -> 0.999
        let mut v: Vec<f64> = (0..1000).map(|k| k as f64 / 1000.0).collect();
        v.extend(std::iter::repeat_n(50.0, 10));
        let h = Histogram::over_percentile(&v, 10, 99.0).unwrap();
        assert_eq!(h.top, 0.999);
        assert_eq!(h.overflow, 10);
        assert_eq!(h.max, 50.0);
        // bins of width 0.0999: values k/1000 in [0.0999 b, 0.0999 (b+1))
        let expected: Vec<usize> = (0..10)
            .map(|b| {
                (0..1000)
                    .filter(|k| {
                        let x = *k as f64 / 1000.0;
                        let bin = ((x / 0.999 * 10.0) as usize).min(9);
                        bin == b
                    })
                    .count()
            })
            .collect();
        assert_eq!(h.counts, expected);
        assert_eq!(
            h.counts,
            vec![100, 100, 100, 100, 100, 100, 100, 100, 100, 100]
        );
        // equal bins over [0, max] would put 1000 of 1010 values in the first bin
        assert!(h.counts.iter().all(|&c| c == 100));
    }

    #[test]
    fn without_strays_the_range_is_the_maximum() {
        let v = vec![1.0; 50];
        let h = Histogram::over_percentile(&v, 4, 99.0).unwrap();
        assert_eq!((h.top, h.percentile, h.overflow), (1.0, 100.0, 0));
        assert_eq!(h.counts, vec![0, 0, 0, 50]);
        let z = Histogram::over_percentile(&[0.0, 0.0], 3, 99.0).unwrap();
        assert_eq!((z.top, z.counts.clone()), (0.0, vec![2, 0, 0]));
        assert!(Histogram::over_percentile(&[f64::NAN], 3, 99.0).is_err());
        assert!(Histogram::over_percentile(&[1.0], 0, 99.0).is_err());
    }
}
