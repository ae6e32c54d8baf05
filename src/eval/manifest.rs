//! `shard.json`: what one run (or one shard of it) covered and wrote, so that `merge` needs
//! nothing but the folders and can prove it is joining exactly what the shards produced.
//!
//! Decisions:
//! - The manifest records the config text, the shard, its cases, and every file `merge` reads or
//!   copies — the four tables and each heat map and contact sheet — with its size, SHA-256 and,
//!   for tables, its row count. `merge` checks each against the folder: an edited, truncated or
//!   duplicated row changes the hash, a deleted heat map is missing, a stray file was not
//!   written by the shard. Plots, `junit.xml` and `report.html` are rebuilt by `merge` and not
//!   recorded.
//! - Paths are relative to the folder with `/` separators, sorted, so the manifest is the same
//!   bytes for any thread count and on any machine.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::error::{Error, Result};

/// The tables a run writes and `merge` reads.
const TABLES: &[&str] = &["metrics.csv", "summary.csv", "distances.csv", "lods.csv"];

/// The image folders a run writes and `merge` copies.
pub(super) const IMAGE_DIRS: &[&str] = &["heatmaps", "sheets"];

/// `shard.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(super) struct Manifest {
    pub config_path: PathBuf,
    pub config_text: String,
    pub shard: String,
    pub cases: Vec<String>,
    /// What the run wrote that `merge` uses (absent in manifests of lodeval before 0.1's
    /// hostile-input round: such folders are refused by `merge`).
    #[serde(default)]
    pub files: Vec<FileRecord>,
    /// The content of every file the run's meshes were read from, so that `merge` refuses
    /// shards that ran on different (or edited) inputs.
    #[serde(default)]
    pub inputs: Vec<InputRecord>,
}

/// One input file of a run.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub(super) struct InputRecord {
    /// As the config names it, relative to the config's folder (`/`-separated).
    pub path: String,
    /// SHA-256 of the content, lower-case hex.
    pub sha256: String,
}

/// Whether `bytes` is a manifest lodeval wrote (it parses, and names a config and its cases).
pub(super) fn parses(bytes: &[u8]) -> bool {
    serde_json::from_slice::<Manifest>(bytes)
        .is_ok_and(|m| !m.cases.is_empty() && !m.config_text.is_empty())
}

/// The records of `files` (read bounded), paths relative to `base` where they lie in it; sorted,
/// one per path.
pub(super) fn record_inputs(files: &[PathBuf], base: &Path) -> Result<Vec<InputRecord>> {
    let base = crate::io::target(base);
    let mut out: Vec<InputRecord> = Vec::new();
    for f in files {
        let bytes = crate::io::read_input(f, "input", crate::limits::MESH_BYTES, "check the file")?;
        let t = crate::io::target(f);
        let rel = t.strip_prefix(&base).map(Path::to_path_buf).unwrap_or(t);
        let path: Vec<String> = rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        out.push(InputRecord {
            path: path.join("/"),
            sha256: sha256(&bytes),
        });
    }
    out.sort();
    out.dedup();
    Ok(out)
}

/// `Err` when two shards read one input (by its path from the config) with different content.
pub(super) fn check_same_inputs(
    a: &Manifest,
    a_dir: &Path,
    b: &Manifest,
    b_dir: &Path,
) -> Result<()> {
    for x in &b.inputs {
        if let Some(y) = a
            .inputs
            .iter()
            .find(|y| y.path == x.path && y.sha256 != x.sha256)
        {
            return Err(Error::input(
                &b_dir.join("shard.json"),
                format!(
                    "read {} with other content than {} did (SHA-256 {}… vs {}…): the shards \
                     ran on different or edited inputs",
                    y.path,
                    a_dir.display(),
                    &x.sha256[..12.min(x.sha256.len())],
                    &y.sha256[..12.min(y.sha256.len())]
                ),
                "rerun every shard on the same inputs, then merge",
            ));
        }
    }
    Ok(())
}

/// One file a run wrote.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(super) struct FileRecord {
    /// Relative to the output folder, `/`-separated.
    pub path: String,
    /// Size in bytes.
    pub bytes: u64,
    /// SHA-256 of the content, lower-case hex.
    pub sha256: String,
    /// Data rows (without the header), for tables.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rows: Option<usize>,
}

pub(super) const FIX: &str =
    "rerun that shard with `lodeval eval --shard` into a fresh folder, then merge";

/// Hex SHA-256 of `bytes`.
fn sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Every file under `dir/sub` as a relative `/`-separated path, sorted.
fn files_under(dir: &Path, sub: &str) -> Result<Vec<String>> {
    let mut out = Vec::new();
    let mut stack = vec![PathBuf::from(sub)];
    while let Some(rel) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(dir.join(&rel)) else {
            continue;
        };
        for e in entries.filter_map(|e| e.ok()) {
            let r = rel.join(e.file_name());
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                stack.push(r);
            } else {
                let parts: Vec<String> = r
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                out.push(parts.join("/"));
            }
        }
    }
    out.sort();
    Ok(out)
}

/// The files of `dir` that a manifest records: the tables and every image, sorted.
fn recorded_paths(dir: &Path) -> Result<Vec<String>> {
    let mut paths: Vec<String> = TABLES
        .iter()
        .filter(|t| dir.join(t).is_file())
        .map(|t| t.to_string())
        .collect();
    for sub in IMAGE_DIRS {
        paths.extend(files_under(dir, sub)?);
    }
    paths.sort();
    Ok(paths)
}

/// Read one recorded file (bounded, regular files only).
fn read(dir: &Path, rel: &str) -> Result<Vec<u8>> {
    crate::io::read_input(
        &dir.join(rel),
        "shard output",
        crate::limits::TABLE_BYTES,
        FIX,
    )
}

/// The records of what `dir` holds now (called after a run wrote its tables and images).
pub(super) fn record(dir: &Path) -> Result<Vec<FileRecord>> {
    recorded_paths(dir)?
        .into_iter()
        .map(|path| {
            let bytes = read(dir, &path)?;
            let rows = path.ends_with(".csv").then(|| {
                bytes
                    .iter()
                    .filter(|&&b| b == b'\n')
                    .count()
                    .saturating_sub(1)
            });
            Ok(FileRecord {
                bytes: bytes.len() as u64,
                sha256: sha256(&bytes),
                rows,
                path,
            })
        })
        .collect()
}

/// Check that `dir` holds exactly what its manifest says the shard wrote.
pub(super) fn verify(dir: &Path, manifest: &Manifest) -> Result<()> {
    let shard_json = dir.join("shard.json");
    if manifest.files.is_empty() {
        return Err(Error::input(
            &shard_json,
            "records no files: the shard was written by an older lodeval, or the manifest was \
             edited",
            FIX,
        ));
    }
    let present = recorded_paths(dir)?;
    for rec in &manifest.files {
        if !present.contains(&rec.path) {
            return Err(Error::input(
                &dir.join(&rec.path),
                "is missing: the shard wrote it, and the merge needs it",
                FIX,
            ));
        }
        let bytes = read(dir, &rec.path)?;
        if bytes.len() as u64 != rec.bytes || sha256(&bytes) != rec.sha256 {
            let rows = rec
                .rows
                .map(|r| format!(" (the shard wrote {r} rows)"))
                .unwrap_or_default();
            return Err(Error::input(
                &dir.join(&rec.path),
                format!(
                    "was changed after the shard wrote it{rows}: its content no longer matches shard.json"
                ),
                FIX,
            ));
        }
    }
    if let Some(extra) = present
        .iter()
        .find(|p| !manifest.files.iter().any(|r| &r.path == *p))
    {
        return Err(Error::input(
            &dir.join(extra),
            "was not written by the shard (shard.json does not record it)",
            "remove it from the shard folder, or rerun the shard into a fresh folder",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_matches_the_standard_vector() {
        // FIPS 180-2, appendix B.1.
        assert_eq!(
            sha256(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn records_find_edits_deletions_and_strays() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        std::fs::write(d.join("metrics.csv"), "h\na\nb\n").unwrap();
        std::fs::create_dir_all(d.join("heatmaps/x/y")).unwrap();
        std::fs::write(d.join("heatmaps/x/y/00-flip.png"), "png").unwrap();
        let files = record(d).unwrap();
        assert_eq!(files.len(), 2);
        assert_eq!(files[0].path, "heatmaps/x/y/00-flip.png".to_string());
        assert_eq!(files[1].rows, Some(2));
        let m = Manifest {
            config_path: "c.toml".into(),
            config_text: String::new(),
            shard: "0/1".into(),
            cases: vec![],
            files,
            inputs: vec![],
        };
        verify(d, &m).unwrap();
        std::fs::write(d.join("metrics.csv"), "h\na\nb\nb\n").unwrap();
        let e = verify(d, &m).unwrap_err().to_string();
        assert!(e.contains("metrics.csv") && e.contains("2 rows"), "{e}");
        std::fs::write(d.join("metrics.csv"), "h\na\nb\n").unwrap();
        std::fs::write(d.join("heatmaps/x/stray.png"), "png").unwrap();
        assert!(verify(d, &m).unwrap_err().to_string().contains("stray.png"));
        std::fs::remove_file(d.join("heatmaps/x/stray.png")).unwrap();
        std::fs::remove_file(d.join("heatmaps/x/y/00-flip.png")).unwrap();
        assert!(verify(d, &m).unwrap_err().to_string().contains("missing"));
    }
}
