//! Outputs that destroyed inputs or mixed runs: `-o` naming the input mesh overwrote it; `merge
//! --out` pointing at a shard folder overwrote it; `out = ""` wrote into the config's folder; a
//! reused output folder kept the previous run's stale heat maps; `merge` trusted whatever the
//! shard folders held (edited, duplicated or deleted rows, missing heat maps); a failed merge
//! left a half-made folder. Each is refused before anything is written, inputs byte-identical.

use std::path::{Path, PathBuf};

use super::{assert_refused, scratch, write};
use crate::common::{files, lodeval_within, model, simplify};

/// A copy of the shipped Spot (OBJ, MTL, texture) in `dir`.
fn spot_copy(dir: &Path) -> PathBuf {
    let src = model("spot");
    for f in ["spot_mtl.obj", "spot.mtl", "spot_texture.png"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    dir.join("spot_mtl.obj")
}

fn run(args: &[&std::ffi::OsStr]) -> crate::common::Run {
    lodeval_within(120, args)
}

#[test]
fn an_output_that_is_an_input_is_refused() {
    let tmp = scratch("outputs-inputs");
    let d = tmp.path();
    let spot = spot_copy(d);
    std::os::unix::fs::symlink("spot_mtl.obj", d.join("link.obj")).unwrap();
    let before = files(d);
    // -o the input itself, a link to it, and an OBJ whose .mtl would replace the input's.
    for (out, culprit) in [
        ("spot_mtl.obj", "spot_mtl.obj"),
        ("link.obj", "link.obj"),
        ("spot.obj", "spot.mtl"),
    ] {
        let r = simplify(&spot, &d.join(out), &["--ratio", "0.5"]);
        assert_refused(&r, out, &[culprit, "is an input of this run"]);
    }
    // A chain whose second file is the input: refused before the first file is written.
    std::fs::copy(&spot, d.join("lod-r25.obj")).unwrap();
    let before_chain = files(d);
    let r = simplify(
        &d.join("lod-r25.obj"),
        &d.join("lod.obj"),
        &["--chain", "0.5,0.25"],
    );
    assert_refused(&r, "chain", &["lod-r25.obj", "is an input"]);
    assert_eq!(files(d), before_chain, "the refused chain wrote a file");
    std::fs::remove_file(d.join("lod-r25.obj")).unwrap();
    // render onto the mesh's texture; optimize onto the original.
    let r = run(&[
        "render".as_ref(),
        spot.as_os_str(),
        "-o".as_ref(),
        d.join("spot_texture.png").as_os_str(),
    ]);
    assert_refused(&r, "render", &["spot_texture.png", "is an input"]);
    let r = run(&[
        "optimize".as_ref(),
        spot.as_os_str(),
        spot.as_os_str(),
        "-o".as_ref(),
        spot.as_os_str(),
        "--evals".as_ref(),
        "10".as_ref(),
    ]);
    assert_refused(&r, "optimize", &["spot_mtl.obj", "is an input"]);
    assert_eq!(files(d), before, "an input changed");
}

/// A small eval config in `dir` with `extra` keys, writing to `out` (as written in the file).
fn config(dir: &Path, name: &str, out: &str, extra: &str) -> PathBuf {
    write(
        dir,
        name,
        &format!(
            "out = \"{out}\"\nmetrics = [\"flip\"]\n[render]\nsize = 32\nrig = \"icosahedron\"\n\
             [distance]\nenabled = false\n{extra}\n[[asset]]\nname = \"spot\"\nmesh = \"{}\"\n\
             generate = {{ method = \"meshopt\", ratios = [0.5] }}\n",
            model("spot/spot_mtl.obj").display()
        ),
    )
}

#[test]
fn an_output_folder_that_is_not_lodevals_is_refused() {
    let tmp = scratch("outputs-folder");
    let d = tmp.path();
    // out = "" would write into the config's own folder.
    let cfg = config(d, "empty.toml", "", "");
    let r = run(&["eval".as_ref(), cfg.as_os_str()]);
    assert_refused(&r, "out = \"\"", &["empty.toml", "line 1", "out is empty"]);
    // A folder holding someone else's files (here: the config itself) is refused untouched.
    let cfg = config(d, "here.toml", ".", "");
    let before = files(d);
    let r = run(&["eval".as_ref(), cfg.as_os_str()]);
    assert_refused(&r, "out = \".\"", &["did not write", "new or empty folder"]);
    assert_eq!(files(d), before);
    // A gate baseline inside what the run would clear is refused, and survives.
    let cfg = config(d, "ok.toml", "out", "");
    assert_eq!(
        run(&["eval".as_ref(), cfg.as_os_str(), "-q".as_ref()]).code,
        0
    );
    let cfg = config(
        d,
        "self.toml",
        "out",
        "[gate]\nbaseline = \"out/summary.csv\"\n",
    );
    let summary = std::fs::read(d.join("out/summary.csv")).unwrap();
    let r = run(&["eval".as_ref(), cfg.as_os_str()]);
    assert_refused(&r, "baseline in out", &["summary.csv", "clears"]);
    assert_eq!(std::fs::read(d.join("out/summary.csv")).unwrap(), summary);
}

#[test]
fn a_reused_output_folder_holds_no_stale_images() {
    let tmp = scratch("outputs-stale");
    let d = tmp.path();
    let all = config(d, "all.toml", "out", "");
    assert_eq!(
        run(&["eval".as_ref(), all.as_os_str(), "-q".as_ref()]).code,
        0
    );
    assert!(d.join("out/heatmaps/spot").is_dir() && d.join("out/sheets/spot").is_dir());
    std::fs::write(d.join("out/notes.txt"), "mine").unwrap();
    let none = config(
        d,
        "none.toml",
        "out",
        "[images]\nheatmaps = \"none\"\ncontact_sheets = false\n",
    );
    assert_eq!(
        run(&["eval".as_ref(), none.as_os_str(), "-q".as_ref()]).code,
        0
    );
    assert!(!d.join("out/heatmaps").exists(), "stale heat maps survived");
    assert!(!d.join("out/sheets").exists(), "stale sheets survived");
    assert_eq!(std::fs::read(d.join("out/notes.txt")).unwrap(), b"mine");
}

#[test]
fn merge_verifies_what_the_shards_wrote_and_never_overwrites_them() {
    let tmp = scratch("outputs-merge");
    let d = tmp.path();
    let cfg = write(
        d,
        "two.toml",
        &format!(
            "out = \"out\"\nmetrics = [\"flip\"]\n[render]\nsize = 32\nrig = \"icosahedron\"\n\
             [distance]\nenabled = false\n\
             [[asset]]\nname = \"spot\"\nmesh = \"{}\"\ngenerate = {{ method = \"meshopt\", ratios = [0.5, 0.25, 0.1] }}\n",
            model("spot/spot_mtl.obj").display()
        ),
    );
    let shard = |i: usize| d.join(format!("s{i}"));
    for i in 0..2 {
        let r = run(&[
            "eval".as_ref(),
            cfg.as_os_str(),
            "-q".as_ref(),
            "--shard".as_ref(),
            format!("{i}/2").as_ref(),
            "--out".as_ref(),
            shard(i).as_os_str(),
        ]);
        assert_eq!(r.code, 0, "{}", r.stderr);
    }
    let merge = |out: &Path| {
        run(&[
            "merge".as_ref(),
            shard(0).as_os_str(),
            shard(1).as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
        ])
    };
    // Into a shard folder, inside one, or around both: refused, shards untouched.
    let before = files(d);
    for out in [shard(0), shard(1).join("sub"), d.to_path_buf()] {
        let r = merge(&out);
        assert_refused(
            &r,
            &out.display().to_string(),
            &["shard folder", "new folder"],
        );
    }
    assert_eq!(files(d), before);
    assert_eq!(merge(&d.join("m")).code, 0);
    // Tampered shards: an edited row, a duplicated row, a deleted heat map, a stray file. Each
    // is refused and leaves no merged folder behind.
    // Tamper with a shard that has cases (the stable hash may give all three to one shard).
    let busy = (0..2)
        .find(|&i| {
            let t = std::fs::read_to_string(shard(i).join("metrics.csv")).unwrap();
            t.lines().count() > 1
        })
        .unwrap();
    let metrics = shard(busy).join("metrics.csv");
    let text = std::fs::read_to_string(&metrics).unwrap();
    let second = text.lines().nth(1).unwrap().to_string();
    let heat = std::fs::read_dir(shard(busy).join("heatmaps/spot"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let heat = std::fs::read_dir(&heat)
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let heat_bytes = std::fs::read(&heat).unwrap();
    type Tamper = Box<dyn Fn()>;
    let cases: Vec<(&str, Tamper, Tamper)> = vec![
        (
            "metrics.csv",
            Box::new({
                let (m, t) = (metrics.clone(), text.clone());
                move || std::fs::write(&m, t.replacen(",0.", ",0.9", 1)).unwrap()
            }),
            Box::new({
                let (m, t) = (metrics.clone(), text.clone());
                move || std::fs::write(&m, &t).unwrap()
            }),
        ),
        (
            "metrics.csv",
            Box::new({
                let (m, t, s) = (metrics.clone(), text.clone(), second.clone());
                move || std::fs::write(&m, format!("{t}{s}\n")).unwrap()
            }),
            Box::new({
                let (m, t) = (metrics.clone(), text.clone());
                move || std::fs::write(&m, &t).unwrap()
            }),
        ),
        (
            "missing",
            Box::new({
                let h = heat.clone();
                move || std::fs::remove_file(&h).unwrap()
            }),
            Box::new({
                let (h, b) = (heat.clone(), heat_bytes.clone());
                move || std::fs::write(&h, &b).unwrap()
            }),
        ),
        (
            "stray.png",
            Box::new({
                let p = shard(busy).join("sheets/stray.png");
                move || std::fs::write(&p, "x").unwrap()
            }),
            Box::new({
                let p = shard(busy).join("sheets/stray.png");
                move || std::fs::remove_file(&p).unwrap()
            }),
        ),
    ];
    for (i, (word, tamper, undo)) in cases.iter().enumerate() {
        tamper();
        let out = d.join(format!("bad{i}"));
        let r = merge(&out);
        assert_refused(&r, word, &[word, "shard"]);
        assert!(!out.exists(), "{word}: a failed merge left a folder");
        undo();
    }
    assert_eq!(
        merge(&d.join("m2")).code,
        0,
        "the shards, restored, merge again"
    );
}
