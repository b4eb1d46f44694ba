//! `scanfit`: turn measured points into B-spline curves and surfaces.
//!
//! A thin layer over the `scanfit` library and `scanfit-io`: parse arguments,
//! read files, call the library, print tables, write outputs.

mod args;
mod cad;
mod cloud;
mod coons;
mod curve;
mod export;
mod mba;
mod outputs;
mod progress;
mod reconstruct;
mod report;
mod surface;
mod table;
mod turntable;
mod view;

use clap::{Parser, Subcommand};

/// Fit CAD-grade B-spline curves and surfaces to measured points.
#[derive(Parser, Debug)]
#[command(name = "scanfit", version, about, long_about = None)]
#[command(
    after_help = "Examples:\n  scanfit curve compare examples/data/dataset5.csv\n  scanfit curve fit examples/data/dataset6.csv --ctrl 20 -o curve.json\n  scanfit cloud boundary examples/data/patch_20k.ply --png boundary.png\n  scanfit mba examples/data/terrain_50k.xyz --levels 6 --adjust -o terrain.json\n  scanfit coons examples/data/patch_20k.ply --pde 5x5 --png patch.png"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Point clouds: statistics, normals, hidden point removal, boundary and corners.
    #[command(subcommand)]
    Cloud(cloud::CloudCommand),
    /// Coons base surface of a patch (boundary, corners, curves), then a B-spline or PDE surface.
    Coons(coons::CoonsArgs),
    /// B-spline curves through or near a sequence of points.
    #[command(subcommand)]
    Curve(curve::CurveCommand),
    /// Several curves and surfaces (JSON) into one STEP and/or IGES file.
    Export(export::ExportArgs),
    /// Least-squares B-spline surface through scattered points, with an error table.
    Fit(surface::FitArgs),
    /// Bicubic surface z = f(x, y) by multilevel B-spline approximation (MBA).
    Mba(mba::MbaArgs),
    /// Whole objects from segmented clouds: patches sharing their edge curves, one sewn model.
    Reconstruct(reconstruct::ReconstructArgs),
    /// Deviation of points from a fitted surface: statistics and an HTML report.
    Report(report::ReportArgs),
    /// Cylinder-like clouds (heads, bottles, arms): virtual turntable parameterization and a surface closed around the axis.
    Turntable(turntable::TurntableArgs),
}

fn main() {
    // `scanfit ... | head`: a closed stdout ends the program quietly, as for
    // any Unix tool, instead of a panic message from println!
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.contains("failed printing to stdout") && msg.contains("Broken pipe") {
            std::process::exit(141);
        }
        default_hook(info);
    }));
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Cloud(c) => cloud::run(c),
        Command::Coons(a) => coons::run(a),
        Command::Curve(c) => curve::run(c),
        Command::Export(a) => export::run(a),
        Command::Fit(a) => surface::run(a),
        Command::Mba(a) => mba::run(a),
        Command::Reconstruct(a) => reconstruct::run(a),
        Command::Report(a) => report::run(a),
        Command::Turntable(a) => turntable::run(a),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
