//! Helpers shared by the integration tests: running the CLI and locating data.

use std::path::{Path, PathBuf};
use std::process::Command;

/// What one CLI run produced.
#[derive(Debug)]
pub struct Run {
    pub code: i32,
    pub stdout: String,
    pub stderr: String,
}

/// Run the `lodeval` binary built for this test run with `args`.
pub fn lodeval<I, S>(args: I) -> Run
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    let out = Command::new(env!("CARGO_BIN_EXE_lodeval"))
        .args(args)
        .env_remove("RUST_BACKTRACE")
        .output()
        .expect("the lodeval binary runs");
    Run {
        code: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// `lodeval simplify SRC -o OUT` with `args` after them.
pub fn simplify(src: &Path, out: &Path, args: &[&str]) -> Run {
    let mut all = vec![
        "simplify",
        src.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    lodeval(all)
}

/// The repository root.
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A shipped reference model.
pub fn model(rel: &str) -> PathBuf {
    root().join("reference/models").join(rel)
}

/// The shared model collection beside the checkout, if present.
pub fn shared_models() -> Option<PathBuf> {
    let p = root().join("../shared/models");
    p.join("MANIFEST.md").exists().then_some(p)
}
