//! Files in and out. Inputs are read only from regular files and only up to a size the format
//! can need ([`read_input`], [`check_input`]), so a FIFO, `/dev/zero` or a symlink to one is an
//! error, not a hang. Outputs are written to a temporary file in the destination folder and
//! renamed into place, so a crash or a bad input never leaves a half-written output (ARCHITECTURE.md,
//! "Errors"). The 8-bit image writers here are the only place where linear colour
//! becomes sRGB bytes on disk.

pub mod csv;
pub mod finite;
pub mod label;
pub mod plot;
pub mod plot_png;
pub mod sheet;
pub mod staged;

pub use staged::{Staged, disown, forget, interrupted, own, remove_on_interrupt, written_under};

use std::io::Read;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Check that `path` is a regular file (symlinks followed) of at most `limit` bytes. `what` names
/// the file in the message ("mesh", "texture"), `fix` says what to do.
pub fn check_input(path: &Path, what: &str, limit: u64, fix: &str) -> Result<u64> {
    let meta = std::fs::metadata(path)
        .map_err(|e| Error::input(path, format!("cannot read the {what}: {e}"), fix))?;
    if !meta.is_file() {
        let kind = if meta.is_dir() {
            "a folder, not a regular file"
        } else {
            "not a regular file (a device, a pipe or a socket)"
        };
        return Err(Error::input(
            path,
            format!("the {what} is {kind}; lodeval reads only regular files"),
            fix,
        ));
    }
    if meta.len() > limit {
        return Err(too_large(path, what, meta.len(), limit, fix));
    }
    Ok(meta.len())
}

fn too_large(path: &Path, what: &str, len: u64, limit: u64, fix: &str) -> Error {
    Error::input(
        path,
        format!("the {what} is {len} bytes, over lodeval's limit of {limit} bytes for a {what}"),
        fix,
    )
}

/// Read a whole input file after [`check_input`]; reads at most `limit` bytes even if the file
/// grows while it is read.
pub fn read_input(path: &Path, what: &str, limit: u64, fix: &str) -> Result<Vec<u8>> {
    let len = check_input(path, what, limit, fix)?;
    let cannot =
        |e: std::io::Error| Error::input(path, format!("cannot read the {what}: {e}"), fix);
    let file = std::fs::File::open(path).map_err(cannot)?;
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(path, what, bytes.len() as u64, limit, fix));
    }
    Ok(bytes)
}

/// [`read_input`] for text: the bytes must be UTF-8.
pub fn read_input_text(path: &Path, what: &str, limit: u64, fix: &str) -> Result<String> {
    let bytes = read_input(path, what, limit, fix)?;
    String::from_utf8(bytes).map_err(|e| {
        Error::input(
            path,
            format!(
                "the {what} is not UTF-8 text (byte {})",
                e.utf8_error().valid_up_to()
            ),
            fix,
        )
    })
}

/// Where writing `path` really lands, as an absolute path: the part that exists is resolved
/// through the file system (symlinks, `..` after a symlink), the part that does not is resolved
/// lexically (`missing/../in.obj` is `in.obj`, since the writer creates `missing` as a plain
/// folder). Every "is this output one of my inputs?" question compares these.
pub fn target(path: &Path) -> PathBuf {
    use std::path::Component;
    let absolute = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir()
            .unwrap_or_else(|_| PathBuf::from("/"))
            .join(path)
    };
    let mut out = PathBuf::new();
    let mut real = true; // `out` exists and is canonical
    for c in absolute.components() {
        match c {
            Component::Prefix(_) | Component::RootDir => out.push(c.as_os_str()),
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
                real = real || out.exists();
            }
            Component::Normal(name) => {
                out.push(name);
                if real && let Ok(c) = out.canonicalize() {
                    out = c;
                } else {
                    real = false;
                }
            }
        }
    }
    out
}

/// Whether writing `output` would replace `input` (the same file through any path, symlink,
/// hard link or not-yet-existing folder followed by `..`).
pub fn same_target(output: &Path, input: &Path) -> bool {
    let (o, i) = (target(output), target(input));
    o == i
        || matches!((std::fs::metadata(&o), std::fs::metadata(&i)),
            (Ok(a), Ok(b)) if same_file(&a, &b, &o, &i))
}

/// Whether `path` is `root` or lies inside it, compared by [`target`].
pub fn within(path: &Path, root: &Path) -> bool {
    target(path).starts_with(target(root))
}

/// `Err` when writing any of `outputs` would replace one of `inputs` ([`same_target`]):
/// lodeval never overwrites what it reads (`-o` naming the input mesh used to replace it).
pub fn check_not_inputs(outputs: &[PathBuf], inputs: &[PathBuf]) -> Result<()> {
    for out in outputs {
        if let Some(input) = inputs.iter().find(|i| same_target(out, i)) {
            let which = if input == out {
                String::new()
            } else {
                format!(" ({})", input.display())
            };
            return Err(Error::input(
                out,
                format!(
                    "is an input of this run{which}; writing the output there would destroy it"
                ),
                "choose another output path",
            ));
        }
    }
    Ok(())
}

#[cfg(unix)]
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata, _: &Path, _: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

#[cfg(not(unix))]
fn same_file(_: &std::fs::Metadata, _: &std::fs::Metadata, a: &Path, b: &Path) -> bool {
    matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
}

/// Write `bytes` to `path` atomically (temp file in the same folder, then rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut staged = Staged::default();
    staged.write(path, bytes)?;
    staged.commit()
}

fn cannot_write(path: &Path, e: std::io::Error) -> Error {
    Error::input(
        path,
        format!("cannot write the output: {e}"),
        "check that the folder exists and is writable",
    )
}

/// The folder `path` is in (`.` for a bare file name): where a config's or a mesh's relative
/// paths start from.
pub fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// `base` joined with `rel`, with `dir/..` pairs removed lexically (`configs/../results` →
/// `results`), so messages show the paths a user would type. Leading `..` stay.
pub fn resolve(base: &Path, rel: &Path) -> PathBuf {
    use std::path::Component;
    let joined = base.join(rel);
    let mut out: Vec<Component> = Vec::new();
    for c in joined.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    if out.is_empty() {
        return PathBuf::from(".");
    }
    out.iter().collect()
}

/// Encode an image in the format its extension names (`.png`, `.exr`) and write it atomically.
pub fn write_image(path: &Path, image: &image::DynamicImage) -> Result<()> {
    write_atomic(path, &encode_image(path, image)?)
}

/// The bytes of `image` in the format `path`'s extension names (`.png`, `.exr`).
pub fn encode_image(path: &Path, image: &image::DynamicImage) -> Result<Vec<u8>> {
    let format = image::ImageFormat::from_path(path).map_err(|_| {
        Error::Usage(format!(
            "{}: unknown image extension; use .png (or .exr for linear float)",
            path.display()
        ))
    })?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    image
        .write_to(&mut bytes, format)
        .map_err(|e| Error::Internal(format!("encoding {}: {e}", path.display())))?;
    Ok(bytes.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces_and_leaves_no_temp_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.txt");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
