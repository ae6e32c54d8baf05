//! The `lodeval` command line (binary only): clap's argument structs, one file per command, each
//! with its `*Args` and a `run` that turns them into a library job, calls it and prints what comes
//! back; `args.rs` holds the value types several commands share, `print.rs` the output, and
//! `progress.rs` the terminal and log progress reporter the library's jobs report through.

/// `eprintln!` that never panics: a message to a closed or full standard error is dropped
/// (the exit code still tells the outcome).
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr().lock(), $($arg)*);
    }};
}

mod args;
mod bench;
mod calibrate;
mod compare;
mod diff;
mod docs;
mod eval;
mod geometry;
mod golden;
mod info;
mod merge;
mod optimize;
mod print;
mod progress;
mod remesh;
mod render;
mod simplify;

use clap::{Parser, Subcommand};
use lodeval::Error;

/// The command line.
#[derive(Parser, Debug)]
#[command(
    name = "lodeval",
    version,
    about = "Does a simplified mesh still look like the original, and from how far away can nobody tell them apart?",
    after_help = "Exit codes: 0 success · 1 the gate found a regression, a golden image mismatched \
        or diff --fail failed · 2 bad input or usage (one message naming the file and what to do) · \
        3 internal error (a lodeval bug)\n\nStart with: lodeval eval configs/demo.toml\n(From a clone: `cargo install --path .` puts lodeval on your PATH; or run target/release/lodeval.)"
)]
pub(crate) struct Cli {
    /// Worker threads, 1 to 1024 (default: all cores). Results are identical for any value.
    #[arg(long, global = true, value_name = "N",
          value_parser = args::count::<usize>(&lodeval::limits::THREADS))]
    threads: Option<usize>,
    /// No progress output.
    #[arg(long, short, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Print what a mesh file contains: counts, attributes, materials, textures, bounds.
    Info(info::InfoArgs),
    /// Render a mesh from the views of a rig with the CPU rasterizer.
    Render(render::RenderArgs),
    /// Compare two images with the perceptual metrics.
    Diff(diff::DiffArgs),
    /// Compare two meshes: both rendered from the original's framing, every view scored, the
    /// imperceptibility distances (no config).
    Compare(compare::CompareArgs),
    /// Run a batch evaluation config: render, score, write CSVs, heat maps, report; gate.
    Eval(eval::EvalArgs),
    /// Compare renders with golden images, or bless new ones.
    Golden(golden::GoldenArgs),
    /// Simplify a mesh (QEM edge collapse, vertex clustering, meshoptimizer or Williams et al.)
    /// and write OBJ.
    Simplify(simplify::SimplifyArgs),
    /// Image-driven optimization of a simplified mesh (Lindstrom & Turk): same vertex count,
    /// renderings closer to the original's.
    Optimize(optimize::OptimizeArgs),
    /// Remesh a textured mesh with vertices placed by curvature and the visual masking of its
    /// surface signal (Qu & Meyer), or by curvature or uniformly.
    Remesh(remesh::RemeshArgs),
    /// Geometric error between two meshes: Hausdorff, mean and RMS surface distance (Metro-style).
    Geometry(geometry::GeometryArgs),
    /// Run a benchmark and print its table.
    Bench(bench::BenchArgs),
    /// Merge the outputs of sharded runs into what one machine would have written.
    Merge(merge::MergeArgs),
    /// Check the visible-difference predictor against observers' detection thresholds.
    Calibrate(calibrate::CalibrateArgs),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(docs::CompletionsArgs),
    /// Print the manual page, or write one per command into a folder.
    Man(docs::ManArgs),
}

/// Set up the worker threads and run the command.
pub(crate) fn run(cli: Cli) -> Result<(), Error> {
    if let Some(n) = cli.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| Error::Internal(format!("cannot start {n} worker threads: {e}")))?;
    }
    let quiet = cli.quiet;
    match cli.command {
        Command::Info(a) => info::run(a),
        Command::Render(a) => render::run(a, quiet),
        Command::Diff(a) => diff::run(a),
        Command::Compare(a) => compare::run(a, quiet),
        Command::Eval(a) => eval::run(a, quiet),
        Command::Golden(a) => golden::run(a),
        Command::Simplify(a) => simplify::run(a, quiet),
        Command::Optimize(a) => optimize::run(a, quiet),
        Command::Remesh(a) => remesh::run(a, quiet),
        Command::Geometry(a) => geometry::run(a),
        Command::Bench(a) => bench::run(a),
        Command::Merge(a) => merge::run(a),
        Command::Calibrate(a) => calibrate::run(a),
        Command::Completions(a) => docs::completions(a),
        Command::Man(a) => docs::man(a),
    }
}
