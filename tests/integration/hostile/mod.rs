//! Hostile input, one module per class of failure (the second round of attacks on the tool): each
//! crafted input must end in exit 2 with one message naming the culprit and what to do, never in
//! an abort, a hang or a silently wrong exit 0.
//!
//! - `goals`: simplification goals the simplifier cannot take (a chain that does not get coarser,
//!   more triangles than the mesh has), which used to abort in meshoptimizer's assertion.
//! - `outputs`: outputs that destroyed inputs or mixed runs (`-o` the input, `merge --out` a
//!   shard, `out = ""`, stale heat maps, tampered shards, half-made merges), refused first.
//! - `plan`: configs the gate cannot judge (a threshold on a metric not computed, `switch_m`
//!   without distances, more `switch_m` values than LODs), refused before the first render.
//! - `baseline`: gate baselines that hold nothing usable (empty, a header only, prose, a folder,
//!   `/dev/zero`, another config's assets, NaN), refused; a LOD the baseline lacks fails the gate.
//! - `bounds`: sizes, counts and values far out of range (threads, views, pixels per degree,
//!   samples, benchmark meshes, contact sheets), refused with the bound of `src/limits.rs`.
//! - `gltf`: glTF structure the parser accepts but nothing can read through (a node cycle, which
//!   used to hang with growing memory; two parents; accessors and views past their ends).
//! - `distances`: a bound is not a measured distance (an identical LOD failed `switch_m` with
//!   the search limit as "visible until"); the `bound` column, `≤`/`≥` on the console.
//! - `files`: paths that are not regular files (a FIFO, `/dev/zero`, `/dev/urandom`, a symlink
//!   to one, a folder) as a mesh, material library, texture, glTF buffer or image, image or
//!   config, which used to block or read until memory ran out.
//! - `messages`: messages that misled (a config's mesh path "relative to the current
//!   directory"; a full stdout as "a lodeval bug"; a full stderr as a panic).
//! - `numbers`: meshes beyond single precision (1e30, 1e-30, far from the origin) refused; what
//!   is within the bounds scores with finite numbers only; NaN pixels refused; PSNR saturates.
//! - `obj_text`: OBJ text that loaded wrong (a byte-order mark, `usemtl` of an undefined
//!   material) or not at all (Latin-1 in a comment).

mod baseline;
mod bounds;
mod distances;
pub mod files;
pub mod gltf;
mod goals;
mod messages;
mod numbers;
mod obj_text;
mod outputs;
mod plan;

use std::path::{Path, PathBuf};

use crate::common::Run;

/// A fresh folder for one test, removed when it is dropped.
pub fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("lodeval-hostile-{name}-"))
        .tempdir()
        .unwrap()
}

/// Asserts that `r` is an input or usage error (exit 2) whose message holds every one of
/// `words`, and that nothing panicked.
pub fn assert_refused(r: &Run, what: &str, words: &[&str]) {
    assert_eq!(
        r.code, 2,
        "{what}: expected exit 2, got {}: {}",
        r.code, r.stderr
    );
    assert!(!r.stderr.contains("panicked"), "{what}: {}", r.stderr);
    for w in words {
        assert!(
            r.stderr.contains(w),
            "{what}: '{w}' missing from: {}",
            r.stderr
        );
    }
}

/// Writes `text` to `dir/name` and returns the path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}
