//! The output folder of `eval`, `merge` and `golden`: what a run owns there, checked before the
//! first render and cleared, so a reused folder holds no stale heat map, sheet or mismatch image
//! from an earlier run, and so a folder that is not lodeval's is never written into.
//!
//! Decisions:
//! - A run owns a fixed set of top-level entries ([`EVAL`], [`GOLDEN`]). A folder lodeval may
//!   use is one that does not exist yet, is empty, holds only owned entries, or carries
//!   `shard.json` (an earlier run's folder, where files a person added are left alone). Any other
//!   folder — the config's own (`out = ""`), a models folder, a home folder — is refused: the
//!   run would mix its files with someone else's.
//! - Before a run writes anything, the entries it owns are removed. The inputs are checked
//!   first: a gate baseline that is the folder's own `summary.csv`, or any input inside an owned
//!   entry, is refused, since clearing would destroy it (and the gate would compare the new run
//!   with itself).

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// What `eval` and `merge` write at the top of their output folder.
pub const EVAL: &[&str] = &[
    "metrics.csv",
    "summary.csv",
    "distances.csv",
    "lods.csv",
    "junit.xml",
    "report.html",
    "shard.json",
    "heatmaps",
    "sheets",
    "plots",
    "export",
];

/// What `golden` writes there (actual and diff images of mismatches).
pub const GOLDEN: &[&str] = &["golden"];

/// The marker of a folder lodeval wrote.
const MARKER: &str = "shard.json";

/// Check `out` for a run that owns `owned` and reads `inputs`, then remove the owned entries an
/// earlier run left there. Nothing is removed when a check fails.
pub fn prepare(out: &Path, owned: &[&str], inputs: &[PathBuf]) -> Result<()> {
    if out.as_os_str().is_empty() {
        return Err(Error::Usage(
            "the output folder is empty text; name a folder".into(),
        ));
    }
    let fix = "choose a new or empty folder (lodeval clears what it wrote there before each run)";
    let meta = match std::fs::metadata(out) {
        Err(_) => return Ok(()), // created when the first file is written
        Ok(m) => m,
    };
    if !meta.is_dir() {
        return Err(Error::input(out, "is not a folder", fix));
    }
    let mut entries: Vec<String> = std::fs::read_dir(out)
        .map_err(|e| Error::input(out, format!("cannot list the folder: {e}"), fix))?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    entries.sort();
    let lodeval_owns = |e: &str| EVAL.contains(&e) || GOLDEN.contains(&e);
    if !entries.iter().any(|e| e == MARKER)
        && let Some(foreign) = entries.iter().find(|e| !lodeval_owns(e))
    {
        return Err(Error::input(
            out,
            format!(
                "the output folder holds '{foreign}', which lodeval did not write, and no \
                 {MARKER}: it is not an earlier run's folder"
            ),
            fix,
        ));
    }
    for input in inputs {
        if let Some(entry) = owned.iter().find(|e| inside(input, &out.join(e))) {
            return Err(Error::input(
                input,
                format!(
                    "is inside the output folder's '{entry}', which this run clears and rewrites"
                ),
                "copy it out of the output folder, or write the run elsewhere (--out)",
            ));
        }
    }
    for e in owned.iter().filter(|e| entries.iter().any(|x| x == *e)) {
        let p = out.join(e);
        let removed = if p.is_dir() {
            std::fs::remove_dir_all(&p)
        } else {
            std::fs::remove_file(&p)
        };
        removed.map_err(|err| {
            Error::input(
                &p,
                format!("cannot remove the earlier run's output: {err}"),
                "check the folder's permissions, or choose another output folder",
            )
        })?;
    }
    Ok(())
}

/// Whether `path` is `root` or lies inside it (both existing; compared canonically, so links
/// and `..` do not hide it).
fn inside(path: &Path, root: &Path) -> bool {
    match (path.canonicalize(), root.canonicalize()) {
        (Ok(p), Ok(r)) => p.starts_with(r),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_foreign_folder_is_refused_and_an_earlier_run_is_cleared() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        // A new folder and an empty one are fine.
        prepare(&d.join("new"), EVAL, &[]).unwrap();
        prepare(d, EVAL, &[]).unwrap();
        // A folder with someone else's file and no marker is refused, and nothing is removed.
        std::fs::write(d.join("config.toml"), "x").unwrap();
        std::fs::write(d.join("metrics.csv"), "old").unwrap();
        let e = prepare(d, EVAL, &[]).unwrap_err().to_string();
        assert!(
            e.contains("config.toml") && e.contains("did not write"),
            "{e}"
        );
        assert!(d.join("metrics.csv").exists());
        // With the marker it is an earlier run's folder: owned entries go, others stay.
        std::fs::write(d.join("shard.json"), "{}").unwrap();
        std::fs::create_dir_all(d.join("heatmaps/a/b")).unwrap();
        std::fs::write(d.join("heatmaps/a/b/00-flip.png"), "stale").unwrap();
        std::fs::create_dir_all(d.join("golden")).unwrap();
        prepare(d, EVAL, &[]).unwrap();
        assert!(!d.join("heatmaps").exists() && !d.join("metrics.csv").exists());
        assert!(!d.join("shard.json").exists());
        assert!(d.join("config.toml").exists() && d.join("golden").exists());
        // Only owned entries (a golden run's folder): fine, and golden clears its own.
        std::fs::remove_file(d.join("config.toml")).unwrap();
        prepare(d, GOLDEN, &[]).unwrap();
        assert!(!d.join("golden").exists());
    }

    #[test]
    fn an_input_inside_what_the_run_clears_is_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        std::fs::write(d.join("shard.json"), "{}").unwrap();
        std::fs::write(d.join("summary.csv"), "baseline").unwrap();
        let e = prepare(d, EVAL, &[d.join("summary.csv")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("summary.csv") && e.contains("clears"), "{e}");
        assert!(d.join("summary.csv").exists(), "nothing removed on refusal");
        // The same file is no obstacle to a golden run, which does not touch it.
        prepare(d, GOLDEN, &[d.join("summary.csv")]).unwrap();
        assert!(prepare(Path::new(""), EVAL, &[]).is_err());
    }
}
