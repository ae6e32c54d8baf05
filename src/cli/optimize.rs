//! `lodeval optimize ORIGINAL SIMPLIFIED -o OUT.obj`: Lindstrom & Turk's image-driven
//! optimization, and the paper's experiment (`--experiment`).

use std::path::PathBuf;

use clap::Args;
use lodeval::Error;
use lodeval::simplify::lindstrom_turk::Normals;

use super::args::count;
use super::print::emit;
use super::progress::Reporter;

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval optimize bunny.obj bunny-lod.obj -o bunny-opt.obj --evals 20000\n\nExit codes: 0 written · 2 bad input or usage · 3 internal error"
)]
pub(crate) struct OptimizeArgs {
    /// The original mesh (the target of the renderings).
    #[arg(required_unless_present = "experiment")]
    pub(crate) original: Option<PathBuf>,
    /// The simplified mesh to improve (any simplifier's output).
    #[arg(required_unless_present = "experiment")]
    pub(crate) simplified: Option<PathBuf>,
    /// Output OBJ.
    #[arg(short, long, required_unless_present = "experiment")]
    pub(crate) out: Option<PathBuf>,
    /// Run the paper's experiment from a config (configs/papers/lindstrom-turk.toml) instead.
    #[arg(long, conflicts_with_all = ["original", "simplified", "out"])]
    pub(crate) experiment: Option<PathBuf>,
    /// Budget in energy evaluations.
    #[arg(long, default_value_t = 20_000, value_parser = count::<u64>(&lodeval::limits::EVALS))]
    pub(crate) evals: u64,
    /// Views while optimizing (20: dodecahedron, 12: icosahedron, else a Fibonacci sphere).
    #[arg(long, default_value_t = 20, value_parser = count::<u32>(&lodeval::limits::VIEWS))]
    pub(crate) views: u32,
    /// Image edge in pixels.
    #[arg(long, default_value_t = 256, value_parser = count::<u32>(&lodeval::limits::IMAGE_SIDE))]
    pub(crate) size: u32,
    /// Seed of the random edge choice.
    #[arg(long, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Normals: derived (from the geometry) or free (optimized as attributes).
    #[arg(long, value_enum, default_value_t = Normals::Derived)]
    pub(crate) normals: Normals,
    /// Do not optimize UVs and colours.
    #[arg(long)]
    pub(crate) no_attributes: bool,
    /// Write energy against evaluations (and seconds) here.
    #[arg(long)]
    pub(crate) energy_csv: Option<PathBuf>,
}

/// Run `optimize`.
pub(crate) fn run(a: OptimizeArgs, quiet: bool) -> Result<(), Error> {
    use lodeval::simplify::lindstrom_turk::Options;
    if let Some(config) = &a.experiment {
        let rows = lodeval::experiments::lindstrom_turk::run(config, &mut |line| {
            if !quiet {
                note!("{line}");
            }
        })?;
        emit(&format!(
            "{} runs; results.csv and plots written\n",
            rows.len()
        ))?;
        return Ok(());
    }
    let (Some(original), Some(simplified), Some(out)) =
        (a.original.clone(), a.simplified.clone(), a.out.clone())
    else {
        return Err(Error::Usage(
            "give ORIGINAL SIMPLIFIED -o OUT, or --experiment CONFIG".into(),
        ));
    };
    let normals = a.normals;
    if a.views == 0 || a.size < 8 || a.size > 4096 {
        return Err(Error::Usage(
            "--views must be at least 1 and --size within 8..4096".into(),
        ));
    }
    let mut options = Options::default();
    options.views = a.views;
    options.size = a.size;
    options.evals = a.evals;
    options.seed = a.seed;
    options.normals = normals;
    options.attributes = !a.no_attributes;
    let mut job = lodeval::app::OptimizeJob::new(original, simplified, out.clone());
    job.energy_csv = a.energy_csv;
    job.options = options;
    let o = lodeval::app::optimize(&job, &Reporter::new(quiet))?;
    emit(&format!(
        "{}  {} vertices  d_MS {:.6e} -> {:.6e} ({:.1} % of the input's energy)  {} evaluations in {:.1} s ({:.0}/s)  accepted: {} no-op, {} swap, {} teleport\n",
        out.display(),
        o.vertices.1,
        o.initial_d_ms,
        o.final_d_ms,
        100.0 * o.final_d_ms / o.initial_d_ms.max(f64::MIN_POSITIVE),
        o.evals,
        o.seconds,
        o.evals as f64 / o.seconds.max(1e-9),
        o.accepted.no_op,
        o.accepted.swap,
        o.accepted.teleport
    ))?;
    super::print::warnings(&o.warnings);
    Ok(())
}
