//! `lodeval eval CONFIG`: the batch evaluation and its gate.

use std::path::PathBuf;

use clap::Args;
use lodeval::Error;
use lodeval::backend::Backend;

use super::print::gate_result;
use super::progress::Reporter;

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval eval configs/demo.toml\n  lodeval eval configs/ci.toml --shard 0/2 --out results/ci-0\n\nExit codes: 0 every gate passed · 1 a gate failed (details in report.html) · 2 bad config or input · 3 internal error"
)]
pub(crate) struct EvalArgs {
    /// The batch config (TOML; see configs/README.md).
    pub(crate) config: PathBuf,
    /// Output folder (default: the config's `out`, else ../results/<config name> beside it).
    #[arg(long, value_name = "DIR")]
    pub(crate) out: Option<PathBuf>,
    /// Run one shard: INDEX/COUNT, 0-based (also from TEST_SHARD_INDEX/TEST_TOTAL_SHARDS,
    /// CI_NODE_INDEX/CI_NODE_TOTAL, JOB_COMPLETION_INDEX with LODEVAL_SHARD_COUNT).
    #[arg(long, value_name = "INDEX/COUNT")]
    pub(crate) shard: Option<String>,
    /// Renderer and FLIP/MSE kernels: cpu, gpu or auto (recorded in the CSVs and the report).
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    pub(crate) backend: Backend,
    /// Keep the originals' frames in this folder, keyed by a hash of the mesh files, the scene,
    /// the settings, the camera and this build, and reuse them (same outputs, fewer renders).
    #[arg(long, value_name = "DIR")]
    pub(crate) cache: Option<PathBuf>,
}

/// Run `eval`.
pub(crate) fn run(a: EvalArgs, quiet: bool) -> Result<(), Error> {
    let shard = match &a.shard {
        Some(s) => lodeval::eval::Shard::parse(s)?,
        None => lodeval::eval::Shard::from_env(|k| std::env::var(k).ok())?
            .unwrap_or(lodeval::eval::Shard::ALL),
    };
    let mut options = lodeval::eval::RunOptions::DEFAULT;
    options.out = a.out;
    options.shard = shard;
    options.backend = a.backend;
    options.cache = a.cache;
    let outcome = lodeval::eval::eval(&a.config, &options, &Reporter::new(quiet))?;
    gate_result(&outcome)
}
