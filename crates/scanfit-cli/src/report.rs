//! `scanfit report SURFACE.json INPUT`: how well a fitted surface represents a
//! point file — deviation statistics on the terminal, and a self-contained
//! HTML page with renders, the error histogram and the fit's parameters.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use scanfit::bspline::tessellate;
use scanfit::metrics::{nearest_points, orthogonal_errors};
use scanfit::project::{InversionConfig, SurfaceInverter};
use scanfit_io::json::read_surface;
use scanfit_io::read_points;
use scanfit_io::render::{render_png, render_points_png, Colouring, RenderOptions};
use scanfit_io::write_atomic;

use crate::progress::Progress;
use crate::table::{num, Table};

const EXAMPLES: &str = "Examples:
  scanfit fit examples/data/terrain_50k.xyz --ctrl 40x40 -o terrain.json
  scanfit report terrain.json examples/data/terrain_50k.xyz -o terrain.html

The deviations are orthogonal distances from the points to the surface (point
inversion); the HTML page embeds its pictures, so it can be mailed as one file.";

/// Arguments of `scanfit report`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct ReportArgs {
    /// The surface (JSON written by `scanfit fit -o`).
    pub surface: PathBuf,
    /// The points to compare with (XYZ, CSV or TXT).
    pub input: PathBuf,
    /// The HTML report [default: SURFACE with .html].
    #[arg(short, long, value_name = "OUT.html")]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub view: crate::view::ViewArgs,
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

/// Runs `scanfit report`.
pub fn run(a: ReportArgs) -> Result<()> {
    let progress = Progress::spinner(a.quiet);
    progress.stage("reading");
    let (doc, surface) = read_surface(&a.surface)?;
    let table = read_points(&a.input)?;
    crate::print_warnings(&table.warnings);
    let pts = &table.points;
    progress.stage(format!("projecting {} points", pts.len()));
    let inverter = SurfaceInverter::new(&surface, InversionConfig::default())?;
    let (stats, inv) = orthogonal_errors(&inverter, pts);
    let mut sorted: Vec<f64> = inv.iter().map(|r| r.distance).collect();
    sorted.sort_by(f64::total_cmp);
    let pct = |f: f64| sorted[((sorted.len() - 1) as f64 * f).round() as usize];
    let (median, p95) = (pct(0.5), pct(0.95));
    let unconverged = inv.iter().filter(|r| !r.converged).count();
    // histogram: 24 bins over [0, max]
    let bins = 24;
    let mut hist = vec![0usize; bins];
    for &d in &sorted {
        let b = if stats.max > 0.0 {
            ((d / stats.max) * bins as f64) as usize
        } else {
            0
        };
        hist[b.min(bins - 1)] += 1;
    }
    progress.stage("rendering");
    let (cu, cv) = surface.counts();
    let mesh = tessellate(&surface, (cu * 4).clamp(32, 300), (cv * 4).clamp(32, 300));
    let near = nearest_points(pts, &mesh.vertices)?;
    let local: Vec<f64> = near.iter().map(|&(i, _)| inv[i].distance).collect();
    let base = RenderOptions {
        width: 900,
        height: 650,
        ..a.view.options(pts)?
    };
    let z_scale = base.z_scale;
    let shown: Vec<_> = pts
        .iter()
        .step_by((pts.len() / 5000).max(1))
        .copied()
        .collect();
    let img_height = render_png(&mesh, Some(&shown), Colouring::Height, &base)?;
    let img_dev = render_png(
        &mesh,
        None,
        Colouring::Scalar {
            values: &local,
            range: (0.0, stats.max),
        },
        &base,
    )?;
    let img_points = render_points_png(pts, &base)?;
    progress.finish();

    let out = a
        .output
        .clone()
        .unwrap_or_else(|| a.surface.with_extension("html"));
    let mut html = String::new();
    let title = format!(
        "scanfit report: {} against {}",
        a.surface.display(),
        a.input.display()
    );
    let _ = write!(
        html,
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{t}</title><style>body{{font-family:sans-serif;max-width:1000px;margin:2em auto;color:#222}}table{{border-collapse:collapse}}td,th{{padding:3px 10px;border-bottom:1px solid #ddd;text-align:left}}td.n{{text-align:right;font-family:monospace}}img{{max-width:100%;border:1px solid #ccc}}</style></head><body><h1>{t}</h1>",
        t = escape(&title)
    );
    let (p, q) = surface.degrees();
    let _ = write!(html, "<h2>Deviation of the points from the surface</h2><p>{} points, orthogonal distances (point inversion){}.</p><table>", pts.len(), if unconverged > 0 { format!(", {unconverged} inversions not converged") } else { String::new() });
    for (k, v) in [
        ("mean", stats.mean),
        ("median", median),
        ("95th percentile", p95),
        ("max", stats.max),
        ("RMSE", stats.rmse),
    ] {
        let _ = write!(
            html,
            "<tr><td>{k}</td><td class=n>{}</td><td>data units</td></tr>",
            num(v)
        );
    }
    let _ = write!(
        html,
        "</table><h3>Histogram</h3>{}",
        histogram_svg(&hist, stats.max)
    );
    let _ = write!(html, "<h2>Surface</h2><table><tr><td>degrees</td><td class=n>{p} x {q}</td></tr><tr><td>control points</td><td class=n>{cu} x {cv}</td></tr><tr><td>periodic</td><td class=n>{:?}</td></tr>", surface.periodic());
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
    let ex = if z_scale != 1.0 {
        format!(" (vertical exaggeration {z_scale}x)")
    } else {
        String::new()
    };
    let _ = write!(html, "</table><h2>Pictures{}</h2>", escape(&ex));
    for (cap, img) in [
        ("The surface, coloured by height, with iso-parameter lines and the input points", &img_height),
        ("The surface coloured by the local fit error (orthogonal distance of the nearest point)", &img_dev),
        ("The input points, coloured by height", &img_points),
    ] {
        let _ = write!(html, "<figure><img src=\"data:image/png;base64,{}\"><figcaption>{}</figcaption></figure>", base64(img), escape(cap));
    }
    html.push_str("</body></html>\n");
    write_atomic(&out, html.as_bytes())?;

    if a.json {
        let v = serde_json::json!({
            "surface": a.surface.display().to_string(),
            "input": a.input.display().to_string(),
            "points": pts.len(),
            "mean": stats.mean, "median": median, "p95": p95, "max": stats.max, "rmse": stats.rmse,
            "unconverged": unconverged,
            "histogram": {"max": stats.max, "counts": hist},
            "report": out.display().to_string(),
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    println!(
        "{}: {} points against {} ({p} x {q} degrees, {cu} x {cv} control points)\n",
        a.input.display(),
        pts.len(),
        a.surface.display()
    );
    let mut t = Table::new(
        &["orthogonal distance", "value", "unit"],
        &[true, false, true],
    );
    for (k, v) in [
        ("mean", stats.mean),
        ("median", median),
        ("95th percentile", p95),
        ("max", stats.max),
        ("RMSE", stats.rmse),
    ] {
        t.row(vec![k.into(), num(v), "data units".into()]);
    }
    print!("{}", t.render());
    if unconverged > 0 {
        println!("note: {unconverged} point inversions did not converge");
    }
    println!("wrote {}", out.display());
    Ok(())
}

/// An inline SVG bar chart of the distance histogram.
fn histogram_svg(hist: &[usize], max: f64) -> String {
    let (w, h) = (720.0, 220.0);
    let top = *hist.iter().max().unwrap_or(&1).max(&1) as f64;
    let bw = (w - 60.0) / hist.len() as f64;
    let mut s = format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"11\">");
    for (k, &c) in hist.iter().enumerate() {
        let bh = (h - 40.0) * c as f64 / top;
        let _ = write!(s, "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{bh:.1}\" fill=\"#3b6fb6\"><title>{c}</title></rect>", 50.0 + k as f64 * bw, h - 25.0 - bh, bw - 1.0);
    }
    let _ = write!(s, "<text x=\"50\" y=\"{}\">0</text><text x=\"{}\" y=\"{}\" text-anchor=\"end\">{} data units</text><text x=\"5\" y=\"20\">{} points</text></svg>", h - 8.0, w - 10.0, h - 8.0, num(max), top as usize);
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
