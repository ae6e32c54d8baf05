//! The render cache was trusted blindly: two entries swapped, one linked to another, one forged
//! at the same size, or a cache inside the run's own output folder, and the run exited 0 with
//! outputs unlike a clean run's. An entry now proves its key and content; a cache that cannot be
//! written is a warning; a cache inside the output folder is refused.

use std::path::{Path, PathBuf};

use super::{assert_refused, config, run, s, scratch, spot_copy};

/// Every `.frame` entry under `dir`, sorted.
fn entries(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for sub in std::fs::read_dir(dir).unwrap().filter_map(|e| e.ok()) {
        if sub.path().is_dir() {
            for e in std::fs::read_dir(sub.path())
                .unwrap()
                .filter_map(|e| e.ok())
            {
                out.push(e.path());
            }
        }
    }
    out.sort();
    out
}

#[test]
fn tampered_entries_are_misses_and_the_outputs_are_a_clean_runs() {
    let tmp = scratch("r3-cache");
    let d = tmp.path();
    let spot = spot_copy(d);
    let cfg = config(d, "c.toml", &spot, "out", "");
    let cache = d.join("cache");
    let clean = run(&["eval", s(&cfg), "--out", s(&d.join("clean")), "-q"]);
    assert_eq!(clean.code, 0, "{}", clean.stderr);
    let want = std::fs::read(d.join("clean/metrics.csv")).unwrap();
    let r = run(&[
        "eval",
        s(&cfg),
        "--out",
        s(&d.join("o1")),
        "--cache",
        s(&cache),
        "-q",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let e = entries(&cache);
    assert!(e.len() >= 3, "{e:?}");
    // Swap two, link a third to the first, forge a fourth at the same size.
    let (a, b) = (std::fs::read(&e[0]).unwrap(), std::fs::read(&e[1]).unwrap());
    std::fs::write(&e[0], &b).unwrap();
    std::fs::write(&e[1], &a).unwrap();
    std::fs::remove_file(&e[2]).unwrap();
    std::os::unix::fs::symlink(&e[0], &e[2]).unwrap();
    if let Some(f) = e.get(3) {
        let mut bytes = std::fs::read(f).unwrap();
        let n = bytes.len();
        for x in &mut bytes[n - 400..] {
            *x ^= 0x55;
        }
        std::fs::write(f, bytes).unwrap();
    }
    let r = run(&[
        "eval",
        s(&cfg),
        "--out",
        s(&d.join("o2")),
        "--cache",
        s(&cache),
        "-q",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert_eq!(
        std::fs::read(d.join("o2/metrics.csv")).unwrap(),
        want,
        "a tampered entry was used"
    );
    assert!(
        r.stderr.contains("render cache") && r.stderr.contains("did not prove"),
        "said once: {}",
        r.stderr
    );
    assert_eq!(r.stderr.matches("did not prove").count(), 1, "{}", r.stderr);
    // Rewritten: the next run trusts every entry and says nothing.
    let r = run(&[
        "eval",
        s(&cfg),
        "--out",
        s(&d.join("o3")),
        "--cache",
        s(&cache),
        "-q",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(!r.stderr.contains("render cache"), "{}", r.stderr);
    assert_eq!(std::fs::read(d.join("o3/metrics.csv")).unwrap(), want);
}

#[test]
fn a_cache_inside_the_output_is_refused_and_an_unusable_one_warned() {
    let tmp = scratch("r3-cache-where");
    let d = tmp.path();
    let spot = spot_copy(d);
    let cfg = config(d, "c.toml", &spot, "out", "");
    let r = run(&["eval", s(&cfg), "--cache", s(&d.join("out/cache")), "-q"]);
    assert_refused(&r, "cache in out", &["--cache", "inside the output folder"]);
    assert!(!d.join("out").exists());
    // A cache path that is a file cannot be a folder: the run renders without it.
    std::fs::write(d.join("cachefile"), "not a folder").unwrap();
    let r = run(&["eval", s(&cfg), "--cache", s(&d.join("cachefile")), "-q"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(r.stderr.contains("rendering without it"), "{}", r.stderr);
    assert_eq!(std::fs::read(d.join("cachefile")).unwrap(), b"not a folder");
}
