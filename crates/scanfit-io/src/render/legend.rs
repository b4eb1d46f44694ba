//! What a picture says in words and colours: the caption (wrapped to the
//! canvas, never cut off), the colour scale (clipped at percentiles so a few
//! stray values do not wash the map into one colour, the true extremes
//! written on the bar) and the layout that keeps caption and bar off the
//! drawing.

use scanfit::distribution::percentile;

use super::{draw_text, viridis, Canvas};

/// Pixels per character of the bitmap font at scale 1 (8 x 8 glyphs).
pub const GLYPH: usize = 8;
/// Line height of caption and bar text at scale 1.
pub const LINE: usize = 14;
/// Blank pixels around captions and bar.
const PAD: usize = 8;

/// Width in pixels of `text` drawn with [`draw_text`] at `scale`.
pub fn text_width(text: &str, scale: usize) -> usize {
    text.chars().count() * GLYPH * scale
}

/// `text` broken into lines no wider than `max_width` pixels at `scale`:
/// at spaces where possible, inside a word only when the word alone is
/// wider than a line. No character is lost (only the spaces at the breaks).
///
/// ```
/// use scanfit_io::render::{text_width, wrap_text};
/// let lines = wrap_text("the quick brown fox jumps", 80, 1);
/// assert_eq!(lines, ["the quick", "brown fox", "jumps"]);
/// assert!(lines.iter().all(|l| text_width(l, 1) <= 80));
/// ```
pub fn wrap_text(text: &str, max_width: usize, scale: usize) -> Vec<String> {
    let per_line = (max_width / (GLYPH * scale.max(1))).max(1);
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        let mut word: Vec<char> = word.chars().collect();
        let used = line.chars().count();
        if used > 0 && used + 1 + word.len() <= per_line {
            line.push(' ');
            line.extend(&word);
            continue;
        }
        if used > 0 {
            lines.push(std::mem::take(&mut line));
        }
        while word.len() > per_line {
            lines.push(word.drain(..per_line).collect());
        }
        line = word.into_iter().collect();
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

/// A number as bar and caption text: 4 significant digits, exponent form
/// outside `[1e-3, 1e5)`.
pub fn format_value(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.3e}");
    }
    let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
    format!("{v:.decimals$}")
}

/// Where a colour scale was cut: the percentile and the true extreme beyond it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clip {
    /// The percentile (0-100) the scale's end is.
    pub percentile: f64,
    /// The extreme value of the data on that side (the maximum above, the
    /// minimum below); values beyond the scale's end get its end colour.
    pub extreme: f64,
}

/// What the colours of a picture mean: a name (with units), the value
/// range mapped onto viridis, and where it was clipped.
#[derive(Debug, Clone, PartialEq)]
pub struct ColourScale {
    /// What is shown, with units, e.g. "deviation [mm]".
    pub name: String,
    /// Values mapped onto the colour map, low to high.
    pub range: (f64, f64),
    /// Clipping below the range.
    pub low: Option<Clip>,
    /// Clipping above the range.
    pub high: Option<Clip>,
}

/// The percentile deviation and error colours are clipped at by default.
pub const DEVIATION_PERCENTILE: f64 = 99.0;

impl ColourScale {
    /// A scale over `range`, unclipped.
    pub fn new(name: impl Into<String>, range: (f64, f64)) -> Self {
        Self {
            name: name.into(),
            range,
            low: None,
            high: None,
        }
    }

    /// A scale for non-negative values (deviations, distances) from 0 to
    /// their `percentile`-th percentile (nearest rank, as
    /// [`scanfit::distribution::percentile`]); clipped there when the
    /// maximum is larger, the maximum written on the bar. Non-finite values
    /// are ignored.
    ///
    /// ```
    /// use scanfit_io::render::ColourScale;
    /// let mut v: Vec<f64> = (1..=1000).map(f64::from).collect();
    /// v.push(1e6); // one stray value
    /// let s = ColourScale::deviation("deviation [mm]", &v, 99.0);
    /// // 1001 values: the 99th percentile is the one at index round(1000 x 0.99)
    /// assert_eq!(s.range, (0.0, 991.0));
    /// assert_eq!(s.high.unwrap().extreme, 1e6);
    /// ```
    pub fn deviation(name: impl Into<String>, values: &[f64], percentile_: f64) -> Self {
        let v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
        let max = v.iter().copied().fold(0.0f64, f64::max);
        let p = percentile(&v, percentile_ / 100.0).unwrap_or(0.0);
        let mut s = Self::new(name, (0.0, max));
        if p > 0.0 && p < max {
            s.range.1 = p;
            s.high = Some(Clip {
                percentile: percentile_,
                extreme: max,
            });
        }
        s
    }

    /// A scale from the `(100 - percentile)`-th to the `percentile`-th
    /// percentile of `values` (heights of points, which may hold strays),
    /// each end clipped when the data reach beyond it.
    pub fn two_sided(name: impl Into<String>, values: &[f64], percentile_: f64) -> Self {
        let v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
        let (min, max) = v
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        let q = percentile_ / 100.0;
        let lo = percentile(&v, 1.0 - q).unwrap_or(0.0);
        let hi = percentile(&v, q).unwrap_or(0.0);
        if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
            return Self::new(name, (min.min(0.0), max.max(0.0)));
        }
        let mut s = Self::new(name, (lo, hi));
        if min < lo {
            s.low = Some(Clip {
                percentile: 100.0 - percentile_,
                extreme: min,
            });
        }
        if max > hi {
            s.high = Some(Clip {
                percentile: percentile_,
                extreme: max,
            });
        }
        s
    }

    /// `value` as a position `[0, 1]` on the colour map.
    pub fn position(&self, value: f64) -> f64 {
        let (lo, hi) = self.range;
        if hi > lo {
            ((value - lo) / (hi - lo)).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// The texts of the bar: the lines at its top end, at its middle, at its
    /// bottom end, and under it (the true extremes beyond the clipped ends).
    pub fn bar_labels(&self) -> BarLabels {
        let (lo, hi) = self.range;
        let end = |v: f64, clip: &Option<Clip>, sign: &str| match clip {
            Some(c) => vec![
                format!("{sign} {}", format_value(v)),
                format!("({} percentile)", ordinal(c.percentile)),
            ],
            None => vec![format_value(v)],
        };
        let mut below = Vec::new();
        if let Some(c) = &self.high {
            below.push(format!("max {}", format_value(c.extreme)));
        }
        if let Some(c) = &self.low {
            below.push(format!("min {}", format_value(c.extreme)));
        }
        BarLabels {
            top: end(hi, &self.high, ">="),
            middle: format_value(0.5 * (lo + hi)),
            bottom: end(lo, &self.low, "<="),
            below,
        }
    }
}

/// `99` as "99th", `1` as "1st", `99.5` as "99.5th".
fn ordinal(p: f64) -> String {
    if p.fract() != 0.0 {
        return format!("{p}th");
    }
    let n = p as i64;
    let suffix = match (n % 10, n % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{n}{suffix}")
}

/// The texts around a colour bar ([`ColourScale::bar_labels`]).
#[derive(Debug, Clone, PartialEq)]
pub struct BarLabels {
    /// Beside the top end (the high end of the range).
    pub top: Vec<String>,
    /// Beside the middle.
    pub middle: String,
    /// Beside the bottom end.
    pub bottom: Vec<String>,
    /// Under the bar: the true extremes beyond clipped ends.
    pub below: Vec<String>,
}

/// Where a picture's parts go: the caption across the top, the colour bar
/// in a column at the right, the drawing in the rest (`area`).
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Image size.
    pub width: usize,
    /// Image height.
    pub height: usize,
    /// The caption, wrapped to the width.
    pub caption: Vec<String>,
    /// The drawing's rectangle `(x0, y0, x1, y1)`, pixels, exclusive ends.
    pub area: (usize, usize, usize, usize),
    /// The bar's column `(x0, x1)` (exclusive), title lines and labels.
    pub bar: Option<BarLayout>,
}

/// The colour bar's place ([`Layout::bar`]).
#[derive(Debug, Clone, PartialEq)]
pub struct BarLayout {
    /// Columns of the reserved strip, `x0..x1`.
    pub columns: (usize, usize),
    /// Columns of the coloured bar itself.
    pub bar_columns: (usize, usize),
    /// Rows of the coloured bar, `y0..y1`.
    pub rows: (usize, usize),
    /// The scale's name, wrapped to the strip.
    pub title: Vec<String>,
    /// The labels.
    pub labels: BarLabels,
}

impl Layout {
    /// The layout of a `width x height` picture with `caption` lines and,
    /// when `scale` is given, a colour bar.
    pub fn new(
        width: usize,
        height: usize,
        caption: &[String],
        scale: Option<&ColourScale>,
    ) -> Self {
        let text_room = width.saturating_sub(2 * PAD).max(GLYPH);
        let lines: Vec<String> = caption
            .iter()
            .flat_map(|l| wrap_text(l, text_room, 1))
            .collect();
        let top = if lines.is_empty() {
            0
        } else {
            (PAD / 2 + LINE * lines.len() + PAD / 2).min(height / 2)
        };
        let bar = scale.map(|s| {
            let labels = s.bar_labels();
            let widest = labels
                .top
                .iter()
                .chain(&labels.bottom)
                .chain(&labels.below)
                .chain(std::iter::once(&labels.middle))
                .map(|t| text_width(t, 1))
                .max()
                .unwrap_or(0);
            // strip: pad, bar 18, gap 6, labels, pad; at most a third of the width
            let strip = (PAD + 18 + 6 + widest + PAD).min(width / 3);
            let x0 = width - strip;
            let title = wrap_text(&s.name, strip.saturating_sub(PAD), 1);
            let y_title = top + PAD;
            let y0 = y_title + LINE * title.len() + LINE;
            let below = LINE * labels.below.len() + LINE;
            let y1 = height.saturating_sub(PAD + below + LINE).max(y0 + 1);
            BarLayout {
                columns: (x0, width),
                bar_columns: (x0 + PAD, x0 + PAD + 18),
                rows: (y0, y1),
                title,
                labels,
            }
        });
        let right = bar.as_ref().map_or(width, |b| b.columns.0);
        Self {
            width,
            height,
            caption: lines,
            area: (0, top, right, height),
            bar,
        }
    }

    /// Draws the caption and the colour bar (viridis, `scale`'s labels).
    pub fn draw(&self, rgb: &mut [u8]) {
        let mut canvas = Canvas {
            rgb,
            width: self.width,
            height: self.height,
        };
        for (k, line) in self.caption.iter().enumerate() {
            draw_text(&mut canvas, PAD, PAD / 2 + LINE * k, line, 1, [20, 20, 20]);
        }
        let Some(b) = &self.bar else {
            return;
        };
        let ink = [20, 20, 20];
        let (bx0, bx1) = b.bar_columns;
        let (y0, y1) = b.rows;
        for y in y0..y1.min(self.height) {
            let t = 1.0 - (y - y0) as f64 / (y1 - y0).max(2).saturating_sub(1) as f64;
            let c = viridis(t).map(|v| (v * 255.0).round() as u8);
            for x in bx0..bx1.min(self.width) {
                let o = (y * self.width + x) * 3;
                canvas.rgb[o..o + 3].copy_from_slice(&c);
            }
        }
        let x0 = b.columns.0;
        for (k, line) in b.title.iter().enumerate() {
            draw_text(
                &mut canvas,
                x0 + PAD / 2,
                self.area.1 + PAD + LINE * k,
                line,
                1,
                ink,
            );
        }
        let lx = bx1 + 6;
        for (k, line) in b.labels.top.iter().enumerate() {
            draw_text(
                &mut canvas,
                lx,
                (y0 + LINE * k).saturating_sub(4),
                line,
                1,
                ink,
            );
        }
        draw_text(&mut canvas, lx, (y0 + y1) / 2 - 4, &b.labels.middle, 1, ink);
        let nb = b.labels.bottom.len();
        for (k, line) in b.labels.bottom.iter().enumerate() {
            let y = (y1 + LINE * k).saturating_sub(4 + LINE * (nb - 1));
            draw_text(&mut canvas, lx, y, line, 1, ink);
        }
        for (k, line) in b.labels.below.iter().enumerate() {
            draw_text(&mut canvas, bx0, y1 + LINE + LINE * k, line, 1, ink);
        }
    }

    /// The scale and offset that fit the projected box `(x0, x1, y0, y1)`
    /// (world units, y up) into [`Layout::area`] with a 5% margin, centred.
    pub fn fit(&self, x0: f64, x1: f64, y0: f64, y1: f64) -> Fit {
        let (ax0, ay0, ax1, ay1) = self.area;
        let (aw, ah) = ((ax1 - ax0) as f64, (ay1 - ay0) as f64);
        let scale = (aw * 0.9 / (x1 - x0).max(1e-300)).min(ah * 0.9 / (y1 - y0).max(1e-300));
        Fit {
            scale,
            centre: (0.5 * (x0 + x1), 0.5 * (y0 + y1)),
            pixel_centre: (ax0 as f64 + 0.5 * aw, ay0 as f64 + 0.5 * ah),
        }
    }
}

/// A projected box fitted into a picture ([`Layout::fit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fit {
    /// Pixels per world unit.
    pub scale: f64,
    /// World point at the centre of the area.
    pub centre: (f64, f64),
    /// The area's centre in pixels.
    pub pixel_centre: (f64, f64),
}

impl Fit {
    /// Pixel coordinates of the projected point `(x, y)`.
    pub fn pixel(&self, x: f64, y: f64) -> (f64, f64) {
        (
            self.pixel_centre.0 + (x - self.centre.0) * self.scale,
            self.pixel_centre.1 - (y - self.centre.1) * self.scale,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_captions_wrap_inside_the_canvas_and_keep_every_character() {
        let long = "/very/long/path/to/some/scan/directory/with/a/name/that/goes/on/and/on/face_scan_86k_points_cleaned.ply: colour = orthogonal distance of the nearest input point [data units], mean 0.0123 max 52.9 RMSE 2.27";
        for width in [200usize, 400, 1200] {
            let l = Layout::new(width, 300, &[long.to_string()], None);
            for line in &l.caption {
                assert!(
                    PAD + text_width(line, 1) <= width - PAD,
                    "{width}: '{line}' is {} px",
                    text_width(line, 1)
                );
            }
            let kept: String = l.caption.concat().chars().filter(|c| *c != ' ').collect();
            let given: String = long.chars().filter(|c| *c != ' ').collect();
            assert_eq!(kept, given);
            // the drawing starts below the last caption line
            assert!(l.area.1 >= PAD / 2 + LINE * l.caption.len(), "{:?}", l.area);
        }
        // 1200 px hold the caption in 1 line of 149 characters (at most 148 fit)
        assert_eq!(
            Layout::new(1200, 900, &[long.to_string()], None)
                .caption
                .len(),
            2
        );
    }

    #[test]
    fn the_bar_strip_holds_its_labels() {
        let v: Vec<f64> = (0..1000)
            .map(|i| i as f64 * 1e-4)
            .chain([52.9077])
            .collect();
        let s = ColourScale::deviation("orthogonal distance [data units]", &v, 99.0);
        let l = Layout::new(1200, 900, &[], Some(&s));
        let b = l.bar.as_ref().unwrap();
        assert_eq!(b.labels.top, [">= 0.09900", "(99th percentile)"]);
        assert_eq!(b.labels.below, ["max 52.91"]);
        let lx = b.bar_columns.1 + 6;
        for t in b.labels.top.iter().chain(&b.labels.below) {
            assert!(lx + text_width(t, 1) <= 1200, "{t}");
        }
        for t in &b.title {
            assert!(b.columns.0 + PAD / 2 + text_width(t, 1) <= 1200, "{t}");
        }
        assert_eq!(l.area.2, b.columns.0);
    }

    #[test]
    fn clipped_scales_sit_at_independently_computed_percentiles() {
        // heights: 2000 values on a sine, 7 strays far above and 3 below
        let mut v: Vec<f64> = (0..2000).map(|i| (i as f64 * 0.01).sin()).collect();
        v.extend([
            90.0, 91.0, 92.0, 93.0, 94.0, 95.0, 96.0, -80.0, -81.0, -82.0,
        ]);
        let s = ColourScale::two_sided("height [m]", &v, 99.0);
        // an independent nearest rank: sort, take index round((n - 1) q)
        let mut sorted = v.clone();
        sorted.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let at = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
        assert_eq!(s.range, (at(0.01), at(0.99)));
        assert!(s.range.1 < 1.0 && s.range.0 > -1.0, "{:?}", s.range);
        assert_eq!(s.high.unwrap().extreme, 96.0);
        assert_eq!(s.low.unwrap().extreme, -82.0);
        assert_eq!(s.bar_labels().below, ["max 96.00", "min -82.00"]);
        // without strays nothing is clipped below; a constant field is not clipped
        let d = ColourScale::deviation("d", &[0.0; 10], 99.0);
        assert_eq!((d.range, d.high), ((0.0, 0.0), None));
    }

    #[test]
    fn numbers_keep_four_significant_digits() {
        assert_eq!(format_value(186.0603), "186.1");
        assert_eq!(format_value(0.012345), "0.01235");
        assert_eq!(format_value(52.9077), "52.91");
        assert_eq!(format_value(123456.0), "1.235e5");
        assert_eq!(ordinal(99.0), "99th");
        assert_eq!(ordinal(1.0), "1st");
        assert_eq!(ordinal(12.0), "12th");
    }
}
