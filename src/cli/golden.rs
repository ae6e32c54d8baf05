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
    /// Write the current renders as the new goldens (refused when CI is set); with filters
    /// (ASSET, ASSET/LOD or ASSET/LOD/VIEW, LOD `original` for the original) only those, and
    /// the rest are compared.
    #[arg(long, num_args = 0.., value_name = "FILTER")]
    pub(crate) bless: Option<Vec<String>>,
    /// Where actual and diff images of mismatches go (default: the config's output folder).
    #[arg(long, value_name = "DIR")]
    pub(crate) out: Option<PathBuf>,
}

/// Run `golden`.
pub(crate) fn run(a: GoldenArgs) -> Result<(), Error> {
    let plan = lodeval::eval::Plan::load(&a.config)?;
    let out = plan.config.out_dir(&plan.config_path, a.out.as_deref());
    let ci = std::env::var_os("CI").is_some_and(|v| !v.is_empty());
    use lodeval::eval::golden::Bless;
    let bless = match a.bless {
        None => Bless::No,
        Some(f) if f.is_empty() => Bless::All,
        Some(f) => Bless::Only(f),
    };
    let g = lodeval::eval::golden::run(&plan, &bless, ci, &out)?;
    let dir = lodeval::eval::golden::golden_dir(&plan);
    let report = g
        .report
        .as_ref()
        .map_or(String::new(), |r| format!("; report: {}", r.display()));
    if g.blessed > 0 {
        emit(&format!(
            "blessed {} golden image(s) in {}\n",
            g.blessed,
            dir.display()
        ))?;
    }
    for m in &g.mismatches {
        note!("{m}");
    }
    let bless_all = format!("lodeval golden {} --bless", a.config.display());
    // Missing goldens are one line, not one per image: a config without goldens yet is the
    // usual first run. Said here beside the mismatches, or as the error when alone.
    let missing = format!(
        "MISSING {} of {} golden image(s) in {}: make them with {bless_all}",
        g.missing,
        g.checked,
        dir.display()
    );
    if g.missing > 0 && !g.mismatches.is_empty() {
        note!("{missing}");
    }
    if g.mismatches.is_empty() && g.missing == 0 {
        emit(&format!(
            "{} image(s) match their goldens in {}{report}\n",
            g.checked - g.blessed,
            dir.display()
        ))
    } else if g.mismatches.is_empty() {
        Err(Error::Regression(format!("{missing}{report}")))
    } else {
        Err(Error::Regression(format!(
            "{} of {} image(s) differ from their goldens{} (pending -actual.png files and the \
             report in {}{report}); to accept them: {bless_all}, or one at a time with --bless \
             ASSET/LOD/VIEW",
            g.mismatches.len(),
            g.checked,
            if g.missing > 0 {
                format!(" and {} are missing", g.missing)
            } else {
                String::new()
            },
            out.join("golden").display(),
        )))
    }
}
