//! `scanfit report SURFACE.json INPUT`: how well a fitted surface represents a
//! point file — deviation statistics on the terminal, and a self-contained
//! HTML page with renders, the error histogram and the fit's parameters.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use scanfit::bspline::{tessellate, Surface};
use scanfit::distribution::Histogram;
use scanfit::metrics::nearest_points;
use scanfit::pipeline::measure::{run as measure, MeasureConfig, MeasureReport};
use scanfit::trim::TrimmedSurface;
use scanfit::{Point3, PointCloud};
use scanfit_io::json::{read_surface, SurfaceDoc};
use scanfit_io::render::{
    format_value, render_png, render_points_png, ColourScale, Colouring, RenderOptions,
    DEVIATION_PERCENTILE,
};
use scanfit_io::write_atomic;

use crate::args::InputArgs;
use crate::outputs::check_outputs;
use crate::progress::Progress;
use crate::table::{num, Table};

const EXAMPLES: &str = "Examples:
  scanfit fit examples/data/terrain_50k.xyz --ctrl 40x40 -o terrain.json
  scanfit report terrain.json examples/data/terrain_50k.xyz -o terrain.html
  scanfit reconstruct examples/data/vessel_30k.ply -o vessel.json
  scanfit report vessel.json examples/data/vessel_30k.ply

The deviations are orthogonal distances from the points to the surface (point
inversion); the HTML page embeds its pictures, so it can be mailed as one file.
A multi-patch model (scanfit-model/1, from `reconstruct -o`) is reported per
patch, per edge and in total as tables (or --json), its points assigned by
their label attribute (as reconstruct), else to the nearest patch.";

/// Arguments of `scanfit report`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct ReportArgs {
    /// The surface (JSON written by `scanfit fit -o`), or a multi-patch
    /// model (written by `scanfit reconstruct -o`).
    pub surface: PathBuf,
    /// The points to compare with and how to read them.
    #[command(flatten)]
    pub input: InputArgs,
    /// The HTML report [default: SURFACE with .html].
    #[arg(short, long, value_name = "OUT.html")]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub view: crate::view::ViewArgs,
    /// Model only: the attribute holding the patch ids [default: the first
    /// of label, segment, segment_id, class, scalar_label; none: each point
    /// goes to its nearest patch].
    #[arg(long, value_name = "NAME")]
    pub labels: Option<String>,
    /// Model only: patch ids whose points are left out, e.g. "0,99".
    #[arg(long, value_name = "LIST", allow_hyphen_values = true, value_parser = crate::args::IDS)]
    pub ignore: Option<crate::args::Ids>,
    /// Print the statistics as JSON on stdout instead of a table.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

fn base64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The three pictures of the page, the vertical exaggeration used and the
/// deviation picture's colour scale.
struct Pictures {
    height: Vec<u8>,
    deviation: Vec<u8>,
    points: Vec<u8>,
    z_scale: f64,
    scale: ColourScale,
}

fn pictures(
    a: &ReportArgs,
    surface: &Surface,
    trimmed: Option<&TrimmedSurface>,
    pts: &[Point3],
    r: &MeasureReport,
) -> Result<Pictures> {
    let (cu, cv) = surface.counts();
    let (nu, nv) = ((cu * 4).clamp(32, 300), (cv * 4).clamp(32, 300));
    // a face saved trimmed is shown trimmed
    let mesh = match trimmed {
        Some(t) => t.tessellate(nu, nv),
        None => tessellate(surface, nu, nv),
    };
    let near = nearest_points(pts, &mesh.vertices)?;
    let inv = &r.assessment.inversions;
    let local: Vec<f64> = near.iter().map(|&(i, _)| inv[i].distance).collect();
    let base = RenderOptions {
        width: 900,
        height: 650,
        ..a.view.options(pts)?
    };
    let shown: Vec<_> = pts
        .iter()
        .step_by((pts.len() / 5000).max(1))
        .copied()
        .collect();
    // colours from 0 to the 99th percentile of the points' distances
    let scale = ColourScale::deviation(
        "orthogonal distance [data units]",
        r.assessment.distances(),
        DEVIATION_PERCENTILE,
    );
    let deviation = Colouring::Scalar {
        values: &local,
        scale: &scale,
    };
    Ok(Pictures {
        height: render_png(&mesh, Some(&shown), Colouring::Height, &base)?,
        deviation: render_png(&mesh, None, deviation, &base)?,
        points: render_points_png(pts, &base)?,
        z_scale: base.z_scale,
        scale,
    })
}

/// The five distance figures of the table and the page.
fn figures(r: &MeasureReport) -> [(&'static str, f64); 5] {
    let s = &r.assessment.quality.orthogonal;
    [
        ("mean", s.mean),
        ("median", r.median),
        ("95th percentile", r.p95),
        ("max", s.max),
        ("RMSE", s.rmse),
    ]
}

/// One line on the surface samples' distance to the points.
fn samples_line(r: &MeasureReport, trimmed: bool) -> String {
    let s = &r.assessment.quality.samples_to_points;
    format!(
        "surface samples to nearest point ({} samples{}): mean {}, max {}, RMSE {}; {:.1}% farther than {} point spacings ({})",
        s.stats.count,
        if trimmed { " on the trimmed face" } else { "" },
        num(s.stats.mean),
        num(s.stats.max),
        num(s.stats.rmse),
        100.0 * s.far_share,
        s.far_spacings,
        num(s.spacing)
    )
}

/// The self-contained HTML page.
fn page(
    a: &ReportArgs,
    doc: &SurfaceDoc,
    surface: &Surface,
    r: &MeasureReport,
    pic: &Pictures,
    trimmed: bool,
) -> String {
    let q = &r.assessment.quality;
    let mut html = String::new();
    let title = format!(
        "scanfit report: {} against {}",
        a.surface.display(),
        a.input.input.display()
    );
    let _ = write!(
        html,
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{t}</title><style>body{{font-family:sans-serif;max-width:1000px;margin:2em auto;color:#222}}table{{border-collapse:collapse}}td,th{{padding:3px 10px;border-bottom:1px solid #ddd;text-align:left}}td.n{{text-align:right;font-family:monospace}}img{{max-width:100%;border:1px solid #ccc}}</style></head><body><h1>{t}</h1>",
        t = escape(&title)
    );
    let (p, qd) = surface.degrees();
    let (cu, cv) = surface.counts();
    let _ = write!(html, "<h2>Deviation of the points from the surface</h2><p>{} points, orthogonal distances (point inversion){}.</p><table>", q.points, if q.unconverged > 0 { format!(", {} inversions not converged", q.unconverged) } else { String::new() });
    for (k, v) in figures(r) {
        let _ = write!(
            html,
            "<tr><td>{k}</td><td class=n>{}</td><td>data units</td></tr>",
            num(v)
        );
    }
    let _ = write!(
        html,
        "</table><p>{}.</p><h3>Histogram</h3>{}",
        escape(&samples_line(r, trimmed)),
        histogram_svg(&r.histogram)
    );
    let _ = write!(html, "<h2>Surface</h2><table><tr><td>degrees</td><td class=n>{p} x {qd}</td></tr><tr><td>control points</td><td class=n>{cu} x {cv}</td></tr><tr><td>periodic</td><td class=n>{:?}</td></tr>", surface.periodic());
    if let Some(pv) = &doc.provenance {
        let _ = write!(
            html,
            "<tr><td>made by</td><td>{} ({})</td></tr>",
            escape(&pv.tool),
            escape(&pv.operation)
        );
        if let Some(i) = &pv.input {
            let _ = write!(html, "<tr><td>input</td><td>{}</td></tr>", escape(i));
        }
        if let Some(m) = &pv.parameterization {
            let _ = write!(html, "<tr><td>parameters</td><td>{}</td></tr>", escape(m));
        }
        for (k, v) in &pv.settings {
            let _ = write!(
                html,
                "<tr><td>{}</td><td>{}</td></tr>",
                escape(k),
                escape(&v.to_string())
            );
        }
    }
    let ex = if pic.z_scale != 1.0 {
        format!(" (vertical exaggeration {}x)", pic.z_scale)
    } else {
        String::new()
    };
    let _ = write!(html, "</table><h2>Pictures{}</h2>", escape(&ex));
    let clip = match pic.scale.high {
        Some(c) => format!(
            "; colours from 0 to the {}th percentile of the distances, {} (max {} on the bar)",
            c.percentile,
            format_value(pic.scale.range.1),
            format_value(c.extreme)
        ),
        None => String::new(),
    };
    let deviation_caption = format!(
        "The surface coloured by the local fit error (orthogonal distance of the nearest point){clip}"
    );
    for (cap, img) in [
        ("The surface, coloured by height, with iso-parameter lines and the input points", &pic.height),
        (deviation_caption.as_str(), &pic.deviation),
        ("The input points, coloured by height (colours clipped at the 1st and 99th percentiles, the extremes on the bar)", &pic.points),
    ] {
        let _ = write!(html, "<figure><img src=\"data:image/png;base64,{}\"><figcaption>{}</figcaption></figure>", base64(img), escape(cap));
    }
    html.push_str("</body></html>\n");
    html
}

/// Runs `scanfit report`.
pub fn run(a: ReportArgs) -> Result<()> {
    if crate::report_model::is_model(&a.surface) {
        return crate::report_model::run(a);
    }
    let out = a
        .output
        .clone()
        .unwrap_or_else(|| a.surface.with_extension("html"));
    check_outputs(
        &[&a.surface, &a.input.input],
        &[(&Some(out.clone()), "--output", &["html", "htm"][..])],
    )?;
    let progress = Progress::spinner(a.quiet);
    progress.stage("reading");
    let (doc, surface) = read_surface(&a.surface)?;
    let trimmed = doc
        .trimmed(&surface)
        .map_err(|e| anyhow::anyhow!("{}: {e}", a.surface.display()))?;
    let cloud = PointCloud::new(a.input.table(false)?.points)?;
    let pts = cloud.points();
    let config = MeasureConfig::default();
    let mut r = measure(&surface, pts, &config, &progress)?;
    // a trimmed face is measured as trimmed: the surface samples cover the
    // face, not its parameter rectangle
    let q = &mut r.assessment.quality;
    if let Some(t) = &trimmed {
        scanfit::pipeline::assess_trimmed::assess_trimmed(q, t, &cloud, &config.assess)?;
    }
    progress.stage("rendering");
    let pic = pictures(&a, &surface, trimmed.as_ref(), pts, &r)?;
    progress.finish();
    write_atomic(
        &out,
        page(&a, &doc, &surface, &r, &pic, trimmed.is_some()).as_bytes(),
    )?;
    let q = &r.assessment.quality;
    let s = &q.orthogonal;
    if a.json {
        let v = serde_json::json!({
            "surface": a.surface.display().to_string(),
            "input": a.input.input.display().to_string(),
            "points": pts.len(),
            "mean": s.mean, "median": r.median, "p95": r.p95, "max": s.max, "rmse": s.rmse,
            "unconverged": q.unconverged,
            "histogram": histogram_json(&r.histogram),
            "samples_to_points": crate::outputs::samples_json(q),
            "trim": crate::cad::trim_json(trimmed.as_ref()),
            "report": out.display().to_string(),
        });
        out!("{}", scanfit_io::json::finite_json(&v, "the JSON report")?);
        return Ok(());
    }
    let (p, qd) = surface.degrees();
    let (cu, cv) = surface.counts();
    outln!(
        "{}: {} points against {} ({p} x {qd} degrees, {cu} x {cv} control points)\n",
        a.input.input.display(),
        pts.len(),
        a.surface.display()
    );
    let mut t = Table::new(
        &["orthogonal distance", "value", "unit"],
        &[true, false, true],
    );
    for (k, v) in figures(&r) {
        t.row(vec![k.into(), num(v), "data units".into()]);
    }
    out!("{}", t.render());
    outln!("{}", samples_line(&r, trimmed.is_some()));
    crate::cad::print_trim(trimmed.as_ref())?;
    if q.unconverged > 0 {
        outln!("note: {} point inversions did not converge", q.unconverged);
    }
    outln!("wrote {}", out.display());
    Ok(())
}

/// The histogram in `--json`: bins over `[0, top]` (`top` the
/// `percentile`-th percentile) and the overflow bin.
fn histogram_json(h: &Histogram) -> serde_json::Value {
    serde_json::json!({
        "top": h.top,
        "percentile": h.percentile,
        "bin_width": h.bin_width(),
        "counts": h.counts,
        "overflow": h.overflow,
        "max": h.max,
    })
}

/// An inline SVG bar chart of the distance histogram: equal bins from 0 to
/// the 99th percentile, then the overflow bin (hatched colour) with the
/// distances beyond it up to the maximum.
fn histogram_svg(h: &Histogram) -> String {
    let (w, ht) = (720.0, 240.0);
    let n = h.counts.len() + usize::from(h.overflow > 0);
    let top = (*h.counts.iter().max().unwrap_or(&1))
        .max(h.overflow)
        .max(1) as f64;
    let (x0, plot_w) = (50.0, w - 70.0);
    let bw = plot_w / n as f64;
    let mut s = format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{ht}\" font-family=\"sans-serif\" font-size=\"11\">");
    let bar = |s: &mut String, k: usize, c: usize, fill: &str, tip: String| {
        let bh = (ht - 60.0) * c as f64 / top;
        let _ = write!(s, "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{bh:.1}\" fill=\"{fill}\"><title>{}</title></rect>", x0 + k as f64 * bw, ht - 40.0 - bh, (bw - 1.0).max(0.5), escape(&tip));
    };
    let width = h.bin_width();
    for (k, &c) in h.counts.iter().enumerate() {
        let tip = format!(
            "{c} points in [{}, {})",
            num(k as f64 * width),
            num((k + 1) as f64 * width)
        );
        bar(&mut s, k, c, "#3b6fb6", tip);
    }
    let top_label = if h.percentile < 100.0 {
        format!("{} ({}th percentile)", num(h.top), h.percentile)
    } else {
        format!("{} (max)", num(h.top))
    };
    let _ = write!(s, "<text x=\"{x0}\" y=\"{}\">0</text><text x=\"{:.1}\" y=\"{}\" text-anchor=\"middle\">{}</text>", ht - 25.0, x0 + h.counts.len() as f64 * bw, ht - 25.0, escape(&top_label));
    if h.overflow > 0 {
        let k = h.counts.len();
        bar(
            &mut s,
            k,
            h.overflow,
            "#c0504d",
            format!("{} points above {}", h.overflow, num(h.top)),
        );
        let _ = write!(
            s,
            "<text x=\"{:.1}\" y=\"{}\" text-anchor=\"end\">&gt; {}: {} points, max {}</text>",
            w - 10.0,
            ht - 8.0,
            escape(&num(h.top)),
            h.overflow,
            escape(&num(h.max))
        );
    }
    let _ = write!(s, "<text x=\"5\" y=\"14\">{} points (tallest bin); {} equal bins of {} data units{}</text></svg>", top as usize, h.counts.len(), escape(&num(width)), if h.overflow > 0 { ", then the overflow bin (red)" } else { "" });
    s
}

#[cfg(test)]
mod tests {
    #[test]
    fn base64_matches_rfc4648_vectors() {
        for (i, o) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(super::base64(i.as_bytes()), o);
        }
    }
}
