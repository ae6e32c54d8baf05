//! The output folder: two evals into one folder both exited 0 and one run's results silently
//! replaced the other's; SIGTERM/SIGINT left temporary files; clearing an earlier run's owned
//! sub-folders deleted what a person had put there; a planted `shard.json` of `{}` made any
//! folder lodeval's. Runs now lock the folder, clean up on signals, and clear only the files
//! their record lists.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use super::{assert_refused, run, s, scratch, spot_copy, write};
use crate::common::files;

/// A config slow enough to be caught mid-run (a few seconds): the bunny, 20 views at 256².
fn slow_config(dir: &Path) -> std::path::PathBuf {
    write(
        dir,
        "slow.toml",
        &format!(
            "out = \"out\"\nmetrics = [\"flip\", \"ssim\", \"vdp\"]\n[render]\nsize = 256\n\
             samples = 4\nrig = \"dodecahedron\"\n[distance]\nenabled = false\n[[asset]]\n\
             name = \"bunny\"\nmesh = \"{}\"\ngenerate = {{ method = \"meshopt\", ratios = [0.5, 0.25, 0.1, 0.05, 0.02] }}\n",
            crate::common::model("bunny/stanford-bunny.obj").display()
        ),
    )
}

fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_lodeval"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Wait until `cond` holds (at most the hang limit for a minute's work).
fn wait_for(what: &str, cond: impl Fn() -> bool) {
    let start = Instant::now();
    while !cond() {
        assert!(
            start.elapsed() < crate::common::hang_limit(60),
            "timed out waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Every file under `dir` (paths), tolerating files that vanish while it looks (a run is writing
/// there).
fn names_under(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.filter_map(|e| e.ok()) {
            let p = e.path();
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                stack.push(p);
            } else {
                out.push(p);
            }
        }
    }
    out
}

fn any_file_under(dir: &Path, sub: &str) -> bool {
    !names_under(&dir.join(sub)).is_empty()
}

#[test]
fn a_second_run_into_a_busy_folder_is_refused_and_the_first_finishes() {
    let tmp = scratch("r3-folder-lock");
    let d = tmp.path();
    let cfg = slow_config(d);
    let out = d.join("out");
    let mut first = spawn(&["eval", s(&cfg), "-q"]);
    wait_for("the first run's lock", || {
        out.join(".lodeval.lock").exists()
    });
    let r = run(&["eval", s(&cfg), "-q"]);
    assert_refused(
        &r,
        "second run",
        &["another lodeval run", "pid", "choose another output folder"],
    );
    let status = first.wait().unwrap();
    assert!(status.success(), "the first run failed");
    for f in ["metrics.csv", "summary.csv", "shard.json", ".lodeval-owned"] {
        assert!(out.join(f).is_file(), "{f} missing after the first run");
    }
    assert!(
        !out.join(".lodeval.lock").exists(),
        "the lock outlived its run"
    );
}

#[test]
fn sigterm_mid_run_leaves_no_temporary_and_nothing_that_looks_complete() {
    let tmp = scratch("r3-folder-signal");
    let d = tmp.path();
    let cfg = slow_config(d);
    let out = d.join("out");
    let mut child = spawn(&["eval", s(&cfg), "-q"]);
    wait_for("the first heat map", || any_file_under(&out, "heatmaps"));
    // Through the shell's builtin `kill` (a `kill` executable may not be installed).
    let killed = Command::new("sh")
        .args(["-c", &format!("kill -TERM {}", child.id())])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{status:?}");
    let left = names_under(&out);
    assert!(
        left.is_empty(),
        "files left by the interrupted run: {left:?}"
    );
    // The folder is usable at once.
    let cfg_fast = super::config(
        d,
        "fast.toml",
        &crate::common::model("spot/spot_mtl.obj"),
        "out",
        "",
    );
    let r = run(&["eval", s(&cfg_fast), "-q"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
}

#[test]
fn only_what_the_run_wrote_is_cleared_and_a_planted_marker_is_no_marker() {
    let tmp = scratch("r3-folder-owned");
    let d = tmp.path();
    let spot = spot_copy(d);
    let cfg = super::config(d, "c.toml", &spot, "out", "");
    assert_eq!(run(&["eval", s(&cfg), "-q"]).code, 0);
    let out = d.join("out");
    std::fs::write(out.join("heatmaps/m/notes.txt"), "mine").unwrap();
    std::fs::create_dir_all(out.join("plots/mine")).unwrap();
    std::fs::write(out.join("plots/mine/chart.svg"), "mine").unwrap();
    assert_eq!(run(&["eval", s(&cfg), "-q"]).code, 0);
    assert_eq!(
        std::fs::read(out.join("heatmaps/m/notes.txt")).unwrap(),
        b"mine"
    );
    assert_eq!(
        std::fs::read(out.join("plots/mine/chart.svg")).unwrap(),
        b"mine"
    );
    // A folder of a person's images with a planted `{}` marker is not lodeval's.
    let theirs = d.join("theirs");
    std::fs::create_dir_all(theirs.join("heatmaps")).unwrap();
    std::fs::write(theirs.join("heatmaps/mine.png"), "x").unwrap();
    std::fs::write(theirs.join("photo.jpg"), "x").unwrap();
    std::fs::write(theirs.join("shard.json"), "{}").unwrap();
    let before = files(&theirs);
    let r = run(&["eval", s(&cfg), "--out", s(&theirs), "-q"]);
    assert_refused(&r, "planted marker", &["photo.jpg", "did not write"]);
    assert_eq!(files(&theirs), before);
}
