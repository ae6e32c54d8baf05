//! The output folder of `eval`, `merge` and `golden`: what a run owns there, checked before the
//! first render and cleared, so a reused folder holds no stale heat map, sheet or mismatch image
//! from an earlier run, so a folder that is not lodeval's is never written into, and so two runs
//! never share one.
//!
//! Decisions:
//! - A run owns a fixed set of top-level entries ([`EVAL`], [`GOLDEN`]). A folder lodeval may
//!   use is one that does not exist yet, is empty, holds only owned entries, or is an earlier
//!   run's: it carries the record of what that run wrote ([`RECORD`]), or (folders of lodeval
//!   before the record) a `shard.json` that parses as a manifest. Any other folder — the config's
//!   own (`out = ""`), a models folder, a home folder, one with a planted `shard.json` of `{}` —
//!   is refused: the run would mix its files with someone else's.
//! - Before a run writes anything, what the earlier run wrote goes: exactly the files its record
//!   lists (then the folders they leave empty), so a file a person put beside them stays. The
//!   inputs are checked first: a gate baseline that is the folder's own `summary.csv`, or any
//!   input inside an owned entry, is refused, since clearing would destroy it.
//! - A run holds a lock on the folder ([`LOCK`], an advisory `flock`) from its first check to
//!   its last file; a second run into the same folder is refused with a message naming the
//!   first. The lock dies with its process, so a killed run never blocks the next.
//! - A run that ends with an error, a panic or a signal (SIGINT, SIGTERM) removes what it wrote
//!   ([`RunDir`]'s drop, `io::interrupted`): what is left is an earlier state, never a
//!   half-written run that looks complete. A run that finishes writes its record ([`RunDir::seal`]).

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

/// The record of what a finished run wrote: relative, `/`-separated paths, one per line.
pub const RECORD: &str = ".lodeval-owned";

/// The lock file a running run holds.
pub const LOCK: &str = ".lodeval.lock";

/// The marker of a folder written by lodeval before the record.
const LEGACY_MARKER: &str = "shard.json";

const FIX: &str =
    "choose a new or empty folder (lodeval clears what it wrote there before each run)";

/// An output folder a run holds: locked, cleared, and its new files remembered.
#[must_use = "the folder stays locked and owned only while this is held; seal it when the run finishes"]
#[derive(Debug)]
pub struct RunDir {
    root: PathBuf,
    lock: Option<std::fs::File>,
    sealed: bool,
}

impl RunDir {
    /// The folder.
    pub fn path(&self) -> &Path {
        &self.root
    }

    /// The run finished: record what it wrote, so the next run clears exactly that, and keep it.
    pub fn seal(mut self) -> Result<()> {
        let root = crate::io::target(&self.root);
        let mut lines: Vec<String> = crate::io::written_under(&self.root)
            .iter()
            .filter_map(|f| f.strip_prefix(&root).ok())
            .map(|r| {
                r.components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect::<Vec<_>>()
                    .join("/")
            })
            .filter(|r| r != RECORD && r != LOCK)
            .collect();
        lines.sort();
        lines.dedup();
        let text: String = lines.iter().map(|l| format!("{l}\n")).collect();
        crate::io::write_atomic(&self.root.join(RECORD), text.as_bytes())?;
        self.sealed = true;
        Ok(())
    }
}

impl Drop for RunDir {
    fn drop(&mut self) {
        if !self.sealed {
            // An error or a panic: take back what this run wrote (its record included).
            for f in crate::io::written_under(&self.root).iter().rev() {
                let _ = std::fs::remove_file(f);
            }
        }
        crate::io::disown(&self.root);
        if let Some(lock) = self.lock.take() {
            let path = self.root.join(LOCK);
            crate::io::forget(&path);
            let _ = std::fs::remove_file(&path);
            drop(lock);
        }
    }
}

/// Check `out` for a run that owns `owned` and reads `inputs`, lock it, then remove what an
/// earlier run wrote there. Nothing is removed when a check fails.
pub fn prepare(out: &Path, owned: &[&str], inputs: &[PathBuf]) -> Result<RunDir> {
    if out.as_os_str().is_empty() {
        return Err(Error::Usage(
            "the output folder is empty text; name a folder".into(),
        ));
    }
    // Everything below looks where the files will land (`missing/../x` is `x`).
    let real = crate::io::target(out);
    let existing = match std::fs::metadata(&real) {
        Err(_) => None,
        Ok(m) if !m.is_dir() => return Err(Error::input(out, "is not a folder", FIX)),
        Ok(_) => Some(earlier_run(out, &real)?),
    };
    for input in inputs {
        if let Some(entry) = owned
            .iter()
            .find(|e| crate::io::within(input, &out.join(e)))
        {
            return Err(Error::input(
                input,
                format!(
                    "is inside the output folder's '{entry}', which this run clears and rewrites"
                ),
                "copy it out of the output folder, or write the run elsewhere (--out)",
            ));
        }
    }
    std::fs::create_dir_all(out)
        .map_err(|e| Error::input(out, format!("cannot create the output folder: {e}"), FIX))?;
    let lock = take_lock(out)?;
    match existing {
        Some(Earlier::Record(files)) => clear_recorded(&real, &files)?,
        Some(Earlier::Legacy) => clear_entries(&real, owned)?,
        None => {}
    }
    crate::io::own(out);
    Ok(RunDir {
        root: out.to_path_buf(),
        lock: Some(lock),
        sealed: false,
    })
}

/// What an existing output folder holds.
enum Earlier {
    /// A finished run's record: the files it wrote (relative paths).
    Record(Vec<String>),
    /// Empty, only owned entries, or a folder of lodeval before the record.
    Legacy,
}

/// Whether the existing folder `out` is lodeval's, and what an earlier run left there.
fn earlier_run(out: &Path, real: &Path) -> Result<Earlier> {
    let mut entries: Vec<String> = std::fs::read_dir(real)
        .map_err(|e| Error::input(out, format!("cannot list the folder: {e}"), FIX))?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|e| e != LOCK)
        .collect();
    entries.sort();
    if entries.iter().any(|e| e == RECORD) {
        let text = crate::io::read_input_text(
            &real.join(RECORD),
            "run record",
            crate::limits::TABLE_BYTES,
            "delete the output folder, or choose another",
        )?;
        let files: Vec<String> = text.lines().map(str::to_string).collect();
        if let Some(bad) = files.iter().find(|f| !plain_relative(f)) {
            return Err(Error::input(
                &out.join(RECORD),
                format!(
                    "lists '{}', which is not a plain path inside the folder",
                    crate::error::quote(bad)
                ),
                "delete the output folder, or choose another",
            ));
        }
        return Ok(Earlier::Record(files));
    }
    let lodeval_owns = |e: &str| EVAL.contains(&e) || GOLDEN.contains(&e);
    let legacy = entries.iter().any(|e| e == LEGACY_MARKER)
        && crate::io::read_input(
            &real.join(LEGACY_MARKER),
            "manifest",
            crate::limits::TABLE_BYTES,
            FIX,
        )
        .ok()
        .is_some_and(|b| super::manifest::parses(&b));
    if !legacy && let Some(foreign) = entries.iter().find(|e| !lodeval_owns(e)) {
        return Err(Error::input(
            out,
            format!(
                "the output folder holds '{}', which lodeval did not write, and no record of an \
                 earlier run ({RECORD}, or a valid {LEGACY_MARKER}): it is not lodeval's folder",
                crate::error::quote(foreign)
            ),
            FIX,
        ));
    }
    Ok(Earlier::Legacy)
}

/// Whether `rel` is a relative path of plain names (no `..`, no root, not empty).
fn plain_relative(rel: &str) -> bool {
    !rel.is_empty()
        && rel
            .split('/')
            .all(|p| !p.is_empty() && p != "." && p != ".." && !p.contains('\\'))
}

/// Remove the files an earlier run recorded (never through a link), then the folders they
/// leave empty.
fn clear_recorded(out: &Path, files: &[String]) -> Result<()> {
    let mut folders = std::collections::BTreeSet::new();
    for f in files {
        let p = out.join(f);
        if std::fs::symlink_metadata(&p).is_ok_and(|m| !m.is_dir()) {
            std::fs::remove_file(&p).map_err(|e| cannot_remove(&p, e))?;
        }
        let mut parent = Path::new(f).parent();
        while let Some(d) = parent.filter(|d| !d.as_os_str().is_empty()) {
            folders.insert(d.to_path_buf());
            parent = d.parent();
        }
    }
    // Deepest first; a folder that still holds something stays.
    for d in folders.iter().rev() {
        let _ = std::fs::remove_dir(out.join(d));
    }
    let _ = std::fs::remove_file(out.join(RECORD));
    Ok(())
}

/// Remove whole owned entries (a folder of lodeval before the record).
fn clear_entries(out: &Path, owned: &[&str]) -> Result<()> {
    for e in owned {
        let p = out.join(e);
        let Ok(meta) = std::fs::symlink_metadata(&p) else {
            continue;
        };
        let removed = if meta.is_dir() {
            std::fs::remove_dir_all(&p)
        } else {
            std::fs::remove_file(&p)
        };
        removed.map_err(|err| cannot_remove(&p, err))?;
    }
    Ok(())
}

fn cannot_remove(p: &Path, err: std::io::Error) -> Error {
    Error::input(
        p,
        format!("cannot remove the earlier run's output: {err}"),
        "check the folder's permissions, or choose another output folder",
    )
}

/// Lock `out` for this run, or say which run holds it.
fn take_lock(out: &Path) -> Result<std::fs::File> {
    let path = out.join(LOCK);
    loop {
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(|e| Error::input(&path, format!("cannot create the lock file: {e}"), FIX))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let holder =
                    crate::io::read_input_text(&path, "lock file", 4096, FIX).unwrap_or_default();
                return Err(Error::Usage(format!(
                    "{}: another lodeval run is writing into this folder ({}); wait for it to \
                     finish, or choose another output folder",
                    out.display(),
                    crate::error::quote(holder.trim())
                )));
            }
            Err(std::fs::TryLockError::Error(e)) => {
                return Err(Error::input(
                    &path,
                    format!("cannot lock the folder: {e}"),
                    FIX,
                ));
            }
        }
        // The file may have been removed by a run that just ended: lock the one at the path.
        if !same_inode(&file, &path) {
            continue;
        }
        let mut file = file;
        let who = format!(
            "pid {}: {}",
            std::process::id(),
            std::env::args().collect::<Vec<_>>().join(" ")
        );
        use std::io::Write as _;
        let _ = file.set_len(0);
        let _ = file.write_all(who.as_bytes());
        crate::io::remove_on_interrupt(&path);
        return Ok(file);
    }
}

#[cfg(unix)]
fn same_inode(file: &std::fs::File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.ino() == b.ino() && a.dev() == b.dev(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_inode(_: &std::fs::File, path: &Path) -> bool {
    path.exists()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_foreign_folder_is_refused_and_an_earlier_run_is_cleared_by_its_record() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        // A new folder and an empty one are fine.
        prepare(&d.join("new"), EVAL, &[]).unwrap().seal().unwrap();
        drop(prepare(&d.join("empty"), EVAL, &[]).unwrap());
        // A folder with someone else's file and no record is refused, and nothing is removed;
        // a planted `shard.json` of `{}` does not make it lodeval's.
        std::fs::write(d.join("config.toml"), "x").unwrap();
        std::fs::write(d.join("metrics.csv"), "old").unwrap();
        std::fs::write(d.join("shard.json"), "{}").unwrap();
        let e = prepare(d, EVAL, &[]).unwrap_err().to_string();
        assert!(
            e.contains("config.toml") && e.contains("did not write"),
            "{e}"
        );
        assert!(d.join("metrics.csv").exists());
        // A finished run records what it wrote; the next clears exactly that.
        let run = d.join("run");
        let dir = prepare(&run, EVAL, &[]).unwrap();
        lodeval_writes(&run.join("heatmaps/a/00-flip.png"));
        lodeval_writes(&run.join("metrics.csv"));
        dir.seal().unwrap();
        std::fs::write(run.join("heatmaps/a/notes.txt"), "a person's").unwrap();
        std::fs::write(run.join("README.txt"), "a person's").unwrap();
        drop(prepare(&run, EVAL, &[]).unwrap());
        assert!(!run.join("heatmaps/a/00-flip.png").exists());
        assert!(!run.join("metrics.csv").exists());
        assert!(run.join("heatmaps/a/notes.txt").exists() && run.join("README.txt").exists());
    }

    fn lodeval_writes(p: &Path) {
        crate::io::write_atomic(p, b"x").unwrap();
    }

    #[test]
    fn a_failed_run_takes_back_what_it_wrote_and_a_held_folder_is_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let run = tmp.path().join("run");
        let dir = prepare(&run, EVAL, &[]).unwrap();
        lodeval_writes(&run.join("metrics.csv"));
        let e = prepare(&run, EVAL, &[]).unwrap_err().to_string();
        assert!(
            e.contains("another lodeval run") && e.contains("pid"),
            "{e}"
        );
        drop(dir); // not sealed: an error ended the run
        assert!(!run.join("metrics.csv").exists() && !run.join(LOCK).exists());
    }

    #[test]
    fn an_input_inside_what_the_run_clears_is_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        std::fs::write(d.join("summary.csv"), "baseline").unwrap();
        let e = prepare(d, EVAL, &[d.join("summary.csv")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("summary.csv") && e.contains("clears"), "{e}");
        assert!(d.join("summary.csv").exists(), "nothing removed on refusal");
        // Through a folder that does not exist yet, too.
        let sneaky = d.join("missing/../summary.csv");
        assert!(prepare(d, EVAL, &[sneaky]).is_err());
        // The same file is no obstacle to a golden run, which does not touch it.
        drop(prepare(d, GOLDEN, &[d.join("summary.csv")]).unwrap());
        assert!(prepare(Path::new(""), EVAL, &[]).is_err());
    }
}
