//! `lodeval merge DIR... --out DIR`: shard outputs joined into what one machine writes.

use std::path::PathBuf;

use clap::Args;
use lodeval::Error;

use super::print::gate_result;

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval merge results/ci-0 results/ci-1 --out results/ci\n\nExit codes: 0 merged and every gate passed · 1 a gate failed · 2 the shards disagree or are damaged · 3 internal error"
)]
pub(crate) struct MergeArgs {
    /// Output folders of the shard runs.
    #[arg(required = true)]
    pub(crate) shards: Vec<PathBuf>,
    /// The merged output folder.
    #[arg(long, value_name = "DIR")]
    pub(crate) out: PathBuf,
}

/// Run `merge`.
pub(crate) fn run(a: MergeArgs) -> Result<(), Error> {
    let outcome = lodeval::eval::merge(&a.shards, &a.out)?;
    gate_result(&outcome)
}
