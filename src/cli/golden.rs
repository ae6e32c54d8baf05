//! `lodeval golden CONFIG`: renders against golden images, or `--bless` new ones.

use std::path::PathBuf;

use clap::Args;
use lodeval::Error;

use super::print::emit;

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval golden configs/ci.toml\n  lodeval golden configs/ci.toml --bless\n\nExit codes: 0 every image matches (or blessed) · 1 a golden image mismatched · 2 bad config or input · 3 internal error"
)]
pub(crate) struct GoldenArgs {
    /// The batch config whose renders are checked.
    pub(crate) config: PathBuf,
    /// Write the current renders as the new goldens (refused when CI is set).
    #[arg(long)]
    pub(crate) bless: bool,
    /// Where actual and diff images of mismatches go (default: the config's output folder).
    #[arg(long, value_name = "DIR")]
    pub(crate) out: Option<PathBuf>,
}

/// Run `golden`.
pub(crate) fn run(a: GoldenArgs) -> Result<(), Error> {
    let plan = lodeval::eval::Plan::load(&a.config)?;
    let out = plan.config.out_dir(&plan.config_path, a.out.as_deref());
    let ci = std::env::var_os("CI").is_some_and(|v| !v.is_empty());
    let g = lodeval::eval::golden::run(&plan, a.bless, ci, &out)?;
    let dir = lodeval::eval::golden::golden_dir(&plan);
    if a.bless {
        return emit(&format!(
            "blessed {} golden image(s) in {}\n",
            g.checked,
            dir.display()
        ));
    }
    for m in &g.mismatches {
        note!("{m}");
    }
    if g.mismatches.is_empty() {
        emit(&format!(
            "{} image(s) match their goldens in {}\n",
            g.checked,
            dir.display()
        ))
    } else {
        Err(Error::Regression(format!(
            "{} of {} image(s) differ from their goldens; if the change is intended, run: lodeval golden {} --bless",
            g.mismatches.len(),
            g.checked,
            a.config.display()
        )))
    }
}
