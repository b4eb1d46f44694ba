//! `scanfit`: turn measured points into B-spline curves and surfaces.
//!
//! A thin layer over the `scanfit` library and `scanfit-io`: parse arguments,
//! read files, call the library, print tables, write outputs.

/// `println!` that returns the write error instead of panicking: a closed
/// stdout (`scanfit ... | head`) reaches `main` through the error chain as
/// `io::ErrorKind::BrokenPipe` and ends the program quietly with 141.
macro_rules! outln {
    () => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock())?
    }};
    ($($t:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($t)*)?
    }};
}

/// `print!` that returns the write error instead of panicking (see `outln!`).
macro_rules! out {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout().lock(), $($t)*)?
    }};
}

mod args;
mod cad;
mod clean;
mod cloud;
mod coons;
mod curve;
mod export;
mod extent;
mod mba;
mod measure;
mod outputs;
mod progress;
mod reconstruct;
mod report;
mod report_model;
mod segment;
mod stream;
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
    /// Threads for the parallel loops (0: one per core). Results are
    /// bit-identical for every count; only the time changes.
    #[arg(long, global = true, default_value_t = 0, value_name = "N")]
    threads: usize,
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

/// Exit status: the command ran and succeeded.
const EXIT_OK: i32 = 0;
/// Exit status: the command failed (bad input, a fit that cannot be done,
/// an output that cannot be written); the message says why.
const EXIT_ERROR: i32 = 1;
/// Exit status: the command line is wrong (unknown option, missing or
/// malformed value); clap's message says what to change.
const EXIT_USAGE: i32 = 2;
/// Exit status: stdout or stderr was closed by its reader (`scanfit ... |
/// head`): 128 + SIGPIPE, as a shell reports a Unix tool killed by SIGPIPE.
const EXIT_BROKEN_PIPE: i32 = 141;

/// Whether `e` is, or is caused by, a write to a closed pipe.
fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
            || c.downcast_ref::<scanfit_io::Error>().is_some_and(|s| {
                matches!(s, scanfit_io::Error::Io { error, .. } if error.kind() == std::io::ErrorKind::BrokenPipe)
            })
    })
}

/// Prints a line on stderr; a closed stderr is not an error of the command
/// (nothing can be reported on it), so the failure is ignored.
pub(crate) fn print_stderr(line: std::fmt::Arguments<'_>) {
    use std::io::Write;
    let mut err = std::io::stderr().lock();
    let _ = err.write_fmt(line).and_then(|()| err.write_all(b"\n"));
}

/// Prints the warnings of a reader (`PointTable::warnings`: a header count
/// that disagrees with the data, ...) on stderr.
pub(crate) fn print_warnings(warnings: &[String]) {
    for w in warnings {
        print_stderr(format_args!("warning: {w}"));
    }
}

fn main() {
    // every print of the commands goes through `out!`/`outln!` (write
    // errors returned) or `print_stderr` (write errors ignored), so a closed
    // stdout reaches here as an io::ErrorKind::BrokenPipe in the error chain
    // and no panic hook is needed
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // --help and --version print on stdout and succeed; a value
            // refused by a typed option parser is bad input (status 1, like
            // any other refused value); every other parse error is a usage
            // error on stderr (status 2)
            let code = if !e.use_stderr() {
                EXIT_OK
            } else if e.kind() == clap::error::ErrorKind::ValueValidation {
                EXIT_ERROR
            } else {
                EXIT_USAGE
            };
            match e.print() {
                Err(io) if io.kind() == std::io::ErrorKind::BrokenPipe && !e.use_stderr() => {
                    std::process::exit(EXIT_BROKEN_PIPE)
                }
                _ => std::process::exit(code),
            }
        }
    };
    let threads = scanfit::par::Threads::from_count(cli.threads);
    let result = scanfit::par::with_threads(threads, || dispatch(cli.command))
        .map_err(anyhow::Error::from)
        .and_then(|r| r);
    if let Err(e) = result {
        if is_broken_pipe(&e) {
            std::process::exit(EXIT_BROKEN_PIPE);
        }
        print_stderr(format_args!("error: {e:#}"));
        std::process::exit(EXIT_ERROR);
    }
    // a closed stdout that nothing wrote to after it closed: flush what is
    // buffered and report a broken pipe the same way
    use std::io::Write;
    if let Err(e) = std::io::stdout().flush() {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(EXIT_BROKEN_PIPE);
        }
    }
}

/// Runs one command.
fn dispatch(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Cloud(c) => cloud::run(c),
        Command::Coons(a) => coons::run(a),
        Command::Curve(c) => curve::run(c),
        Command::Export(a) => export::run(a),
        Command::Fit(a) => surface::run(a),
        Command::Mba(a) => mba::run(a),
        Command::Reconstruct(a) => reconstruct::run(a),
        Command::Report(a) => report::run(a),
        Command::Turntable(a) => turntable::run(a),
    }
}
