//! Writing several files as one: every file of an output (a glTF and its images, an OBJ with its
//! `.mtl` and textures) is first written to a temporary file beside its destination, and only
//! when all of them are written are they renamed into place. A failure on the way removes the
//! temporaries and leaves the destinations as they were, so a failed export leaves no orphan
//! images and no document naming missing files.
//!
//! Every temporary lodeval has open is also listed process-wide, and so is every file written
//! into a folder a run owns ([`own`]), so an interrupted run (SIGINT, SIGTERM) removes both before
//! it exits ([`interrupted`]) and a failed run can take back what it wrote ([`written_under`]).

use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::{Error, Result};

/// Temporaries written and not yet renamed or removed, across the process.
static LIVE: Mutex<BTreeSet<PathBuf>> = Mutex::new(BTreeSet::new());

fn live() -> std::sync::MutexGuard<'static, BTreeSet<PathBuf>> {
    LIVE.lock().unwrap_or_else(|p| p.into_inner())
}

/// Files committed into an owned folder (absolute, by [`super::target`]), and the owned folders.
static WRITTEN: Mutex<(BTreeSet<PathBuf>, Vec<PathBuf>)> =
    Mutex::new((BTreeSet::new(), Vec::new()));

fn written() -> std::sync::MutexGuard<'static, (BTreeSet<PathBuf>, Vec<PathBuf>)> {
    WRITTEN.lock().unwrap_or_else(|p| p.into_inner())
}

/// List `path` with the temporaries: removed on interruption unless [`forget`] first (a lock file).
pub fn remove_on_interrupt(path: &Path) {
    live().insert(path.to_path_buf());
}

/// Take `path` off the interruption list.
pub fn forget(path: &Path) {
    live().remove(path);
}

/// From now on, remember every file written inside `root` (a run's output folder).
pub fn own(root: &Path) {
    written().1.push(super::target(root));
}

/// Stop remembering files written inside `root`, and forget those remembered.
pub fn disown(root: &Path) {
    let root = super::target(root);
    let mut w = written();
    w.1.retain(|r| *r != root);
    w.0.retain(|f| !f.starts_with(&root));
}

/// The files this process wrote inside `root` since [`own`], in path order.
pub fn written_under(root: &Path) -> Vec<PathBuf> {
    let root = super::target(root);
    written()
        .0
        .iter()
        .filter(|f| f.starts_with(&root))
        .cloned()
        .collect()
}

/// What an interruption (SIGINT, SIGTERM) leaves undone: every temporary, lock file and file
/// written into an owned folder is removed, so nothing half-written looks complete.
///
/// The two lists' locks are taken and never given back: a worker thread about to create a
/// temporary ([`Staged::write`]) or to put a file in place ([`Staged::commit`], which renames and
/// lists it under the lock) waits on them until the process exits, so nothing lands after the
/// removal. (A file renamed into place just before the signal, and listed a moment after the
/// removal, once outlived an interrupted run.) Call it only on the way out.
pub fn interrupted() {
    let temporaries = live();
    let files = written();
    for t in temporaries.iter() {
        let _ = std::fs::remove_file(t);
    }
    for f in files.0.iter().rev() {
        let _ = std::fs::remove_file(f);
    }
    std::mem::forget(files);
    std::mem::forget(temporaries);
}

/// The temporary that stands for `path` until it is renamed into place.
fn temporary(path: &Path) -> Result<PathBuf> {
    let dir = super::parent_dir(path);
    std::fs::create_dir_all(&dir).map_err(|e| super::cannot_write(path, e))?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    static SERIAL: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = SERIAL.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    Ok(dir.join(format!(".{name}.tmp{}-{n}", std::process::id())))
}

/// Files written to temporaries, put in place together by [`Staged::commit`]; dropped without
/// a commit, the temporaries are removed.
#[derive(Debug, Default)]
pub struct Staged {
    files: Vec<(PathBuf, PathBuf)>, // (temporary, destination)
}

impl Staged {
    /// Write `bytes` for `path` (to a temporary until [`Staged::commit`]).
    pub fn write(&mut self, path: &Path, bytes: &[u8]) -> Result<()> {
        if self.files.iter().any(|(_, d)| super::same_target(d, path)) {
            return Err(Error::Internal(format!(
                "{}: written twice in one output",
                path.display()
            )));
        }
        let tmp = temporary(path)?;
        self.files.push((tmp.clone(), path.to_path_buf()));
        // Listed and created under the lock, so an interruption removes it or it never exists.
        let file = {
            let mut temporaries = live();
            temporaries.insert(tmp.clone());
            std::fs::File::create(&tmp)
        };
        file.and_then(|mut f| f.write_all(bytes).and_then(|_| f.sync_all()))
            .map_err(|e| super::cannot_write(path, e))
    }

    /// The destinations, in the order written.
    pub fn paths(&self) -> Vec<PathBuf> {
        self.files.iter().map(|(_, d)| d.clone()).collect()
    }

    /// Rename every temporary into place, in the order written (so the file that names the
    /// others goes last when it was written last). When one cannot be renamed (its destination is
    /// a folder, say), the ones already in place are removed again: all or nothing.
    pub fn commit(mut self) -> Result<()> {
        let files = std::mem::take(&mut self.files);
        for (i, (tmp, dest)) in files.iter().enumerate() {
            // Put in place and listed under one lock, so an interruption sees both or neither.
            let mut w = written();
            if let Err(e) = std::fs::rename(tmp, dest) {
                drop(w);
                // Not all of it can land: take back what did, so no part stands alone.
                for (_, d) in &files[..i] {
                    let _ = std::fs::remove_file(d);
                }
                for (t, _) in &files[i..] {
                    let _ = std::fs::remove_file(t);
                    live().remove(t);
                }
                return Err(super::cannot_write(dest, e));
            }
            let dest = super::target(dest);
            if w.1.iter().any(|r| dest.starts_with(r)) {
                w.0.insert(dest);
            }
            drop(w);
            live().remove(tmp);
        }
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        for (tmp, _) in self.files.drain(..) {
            let _ = std::fs::remove_file(&tmp);
            live().remove(&tmp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nothing_lands_until_commit_and_a_dropped_batch_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.png"), dir.path().join("sub/b.bin"));
        std::fs::write(&a, b"old").unwrap();
        let mut s = Staged::default();
        s.write(&a, b"new").unwrap();
        s.write(&b, b"bin").unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"old");
        assert!(s.write(&dir.path().join("sub/../a.png"), b"x").is_err());
        drop(s);
        assert_eq!(std::fs::read(&a).unwrap(), b"old");
        assert_eq!(
            std::fs::read_dir(dir.path().join("sub")).unwrap().count(),
            0
        );
        let mut s = Staged::default();
        s.write(&a, b"new").unwrap();
        s.write(&b, b"bin").unwrap();
        s.commit().unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"new");
        assert_eq!(std::fs::read(&b).unwrap(), b"bin");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
        assert!(!live().iter().any(|t| t.starts_with(dir.path())));
    }
}
