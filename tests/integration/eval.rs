//! The batch evaluator end to end: determinism over thread counts, shards merged equal one run,
//! the gate (thresholds, broken LODs, baselines, switch distances), golden images, bad configs, and
//! monotone scores and distances along the LOD chain of every shipped model.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::{Run, files, lodeval, lodeval_env, model};

/// Run the CLI with `CI` set or removed.
fn lodeval_ci(args: &[&str], ci: bool) -> Run {
    lodeval_env(args, &[("CI", ci.then_some("true"))])
}

/// A config in `dir` with small renders; `assets` is TOML for the `[[asset]]` entries.
fn config(dir: &Path, extra: &str, assets: &str) -> PathBuf {
    let text = format!(
        "out = \"out\"\nmetrics = [\"flip\", \"ssim\", \"psnr\", \"vdp\"]\n[render]\nsize = 64\nrig = \"icosahedron\"\n[distance]\nviews = 1\nmax_diameter_px = 64\n{extra}\n{assets}"
    );
    let path = dir.join("c.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn asset(name: &str, mesh: &Path, rest: &str) -> String {
    format!(
        "[[asset]]\nname = \"{name}\"\nmesh = \"{}\"\n{rest}\n",
        mesh.display()
    )
}

fn assert_same_tree(a: &Path, b: &Path) {
    let (fa, fb) = (files(a), files(b));
    assert_eq!(
        fa.keys().collect::<Vec<_>>(),
        fb.keys().collect::<Vec<_>>(),
        "{} vs {}",
        a.display(),
        b.display()
    );
    for (k, v) in &fa {
        assert!(
            *v == fb[k],
            "{} differs between {} and {}",
            k.display(),
            a.display(),
            b.display()
        );
    }
}

const CHAIN: &str = "generate = { method = \"meshopt\", ratios = [0.5, 0.25] }";

#[test]
fn worst_view_heat_maps_equal_the_same_views_maps_of_a_full_run_for_any_thread_count() {
    // Worst-view heat maps are re-rendered, one original per distinct worst view with its LODs in
    // parallel: each must be byte for byte the map a run writing every view's maps writes there,
    // and the distances (probes that stop early from three views) the same for 1, 2 and 8 threads.
    let dir = tempfile::tempdir().unwrap();
    let assets = asset(
        "spot",
        &model("spot/spot_mtl.obj"),
        "generate = { method = \"meshopt\", ratios = [0.5, 0.1, 0.02] }",
    );
    let cfg = |heatmaps: &str| {
        let sub = dir.path().join(heatmaps);
        std::fs::create_dir_all(&sub).unwrap();
        let extra = format!("[images]\nheatmaps = \"{heatmaps}\"");
        let path = config(&sub, &extra, &assets);
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&path, text.replace("views = 1", "views = 3")).unwrap();
        path
    };
    let (all_cfg, worst_cfg) = (cfg("all"), cfg("worst"));
    let run = |cfg: &Path, out: &str, threads: &str| {
        let out = dir.path().join(out);
        let r = lodeval([
            "eval",
            cfg.to_str().unwrap(),
            "--threads",
            threads,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(r.code, 0, "{}", r.stderr);
        out
    };
    let all = files(&run(&all_cfg, "all-out", "2"));
    let worst: Vec<PathBuf> = ["1", "2", "8"]
        .iter()
        .map(|t| run(&worst_cfg, &format!("worst{t}"), t))
        .collect();
    assert_same_tree(&worst[0], &worst[1]);
    assert_same_tree(&worst[0], &worst[2]);
    let worst = files(&worst[0]);
    let maps: Vec<&PathBuf> = worst.keys().filter(|p| p.starts_with("heatmaps")).collect();
    // Three LODs, one view each, FLIP, SSIM and the VDP.
    assert_eq!(maps.len(), 3 * 3, "{maps:?}");
    for m in maps {
        assert!(all[m] == worst[m], "{} differs", m.display());
    }
    let distances = Path::new("distances.csv");
    assert!(all[distances] == worst[distances], "distances differ");
}

#[test]
fn outputs_are_identical_for_any_thread_count_and_merged_shards_equal_one_run() {
    let dir = tempfile::tempdir().unwrap();
    let assets = asset("bunny3k", &model("bunny/bunny_odedstein_3k.obj"), CHAIN)
        + &asset("spot", &model("spot/spot_mtl.obj"), CHAIN);
    let cfg = config(dir.path(), "", &assets);
    let c = cfg.to_str().unwrap();
    let out = |name: &str| dir.path().join(name);
    for t in ["1", "2", "8"] {
        let o = out(&format!("t{t}"));
        let r = lodeval(["eval", c, "--threads", t, "--out", o.to_str().unwrap()]);
        assert_eq!(r.code, 0, "{}", r.stderr);
    }
    assert_same_tree(&out("t1"), &out("t2"));
    assert_same_tree(&out("t1"), &out("t8"));
    let t1 = files(&out("t1"));
    for f in [
        "metrics.csv",
        "summary.csv",
        "distances.csv",
        "junit.xml",
        "report.html",
    ] {
        assert!(t1.contains_key(Path::new(f)), "{f} missing");
    }
    assert!(t1.contains_key(Path::new("heatmaps/spot/meshopt-r25/11-flip.png")));
    assert!(t1.contains_key(Path::new("sheets/bunny3k/meshopt-r50.png")));
    let metrics = String::from_utf8(t1[Path::new("metrics.csv")].clone()).unwrap();
    // 2 assets × 2 LODs × 12 views × (flip, flip_p95, flip_share, ssim, psnr, psnr_luminance, mse,
    // vdp, vdp_jnd).
    assert_eq!(metrics.lines().count(), 1 + 2 * 2 * 12 * 9);
    // Two shards, merged, equal the single run byte for byte; each shard has work.
    for s in ["0/2", "1/2"] {
        let o = out(&format!("shard{}", &s[..1]));
        let r = lodeval(["eval", c, "--shard", s, "--out", o.to_str().unwrap()]);
        assert_eq!(r.code, 0, "{}", r.stderr);
        let m = std::fs::read_to_string(o.join("shard.json")).unwrap();
        assert!(m.contains("meshopt-r"), "shard {s} got no case: {m}");
    }
    let merged = out("merged");
    let r = lodeval([
        "merge",
        out("shard0").to_str().unwrap(),
        out("shard1").to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert_same_tree(&out("t1"), &merged);
    // A missing shard or a shard given twice is an error.
    let r = lodeval([
        "merge",
        out("shard0").to_str().unwrap(),
        "--out",
        out("m2").to_str().unwrap(),
    ]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("in no shard"), "{}", r.stderr);
    let r = lodeval([
        "merge",
        out("shard0").to_str().unwrap(),
        out("shard0").to_str().unwrap(),
        out("shard1").to_str().unwrap(),
        "--out",
        out("m3").to_str().unwrap(),
    ]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("also in"), "{}", r.stderr);
}

/// Rewrite an OBJ line by line.
fn edit_obj(src: &Path, dst: &Path, f: impl Fn(&str, &[glam::Vec3]) -> Option<String>) {
    let text = std::fs::read_to_string(src).unwrap();
    let mut verts = Vec::new();
    let mut out = String::new();
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("v ") {
            let v: Vec<f32> = rest
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            verts.push(glam::Vec3::new(v[0], v[1], v[2]));
        }
        if let Some(l) = f(line, &verts) {
            out.push_str(&l);
            out.push('\n');
        }
    }
    std::fs::write(dst, out).unwrap();
}

#[test]
fn gate_passes_good_lods_and_names_broken_ones() {
    let dir = tempfile::tempdir().unwrap();
    let src = model("bunny/bunny_odedstein_3k.obj");
    // A hole: faces whose first vertex lies in the +x third of the bunny are dropped.
    let holey = dir.path().join("holey.obj");
    edit_obj(&src, &holey, |line, verts| {
        if let Some(rest) = line.strip_prefix("f ") {
            let first: usize = rest.split('/').next().unwrap().trim().parse().unwrap();
            if verts[first - 1].x > 0.3 {
                return None;
            }
        }
        Some(line.to_string())
    });
    // Flipped normals: every file normal negated.
    let flipped = dir.path().join("flipped.obj");
    edit_obj(&src, &flipped, |line, _| {
        Some(match line.strip_prefix("vn ") {
            Some(rest) => {
                let n: Vec<String> = rest
                    .split_whitespace()
                    .map(|x| format!("{}", -x.parse::<f32>().unwrap()))
                    .collect();
                format!("vn {}", n.join(" "))
            }
            None => line.to_string(),
        })
    });
    let thresholds = "[thresholds]\nflip_mean = 0.05\n";
    let good = asset(
        "bunny3k",
        &src,
        "generate = { method = \"meshopt\", ratios = [0.5] }",
    );
    let cfg = config(dir.path(), thresholds, &good);
    let r = lodeval(["eval", cfg.to_str().unwrap()]);
    assert_eq!(r.code, 0, "{}{}", r.stdout, r.stderr);
    assert!(r.stdout.contains("meshopt-r50") && r.stdout.contains("pass"));

    let lods = format!(
        "lods = [{{ name = \"holey\", mesh = \"{}\" }}, {{ name = \"flipped\", mesh = \"{}\" }}]\ngenerate = {{ method = \"meshopt\", ratios = [0.5] }}",
        holey.display(),
        flipped.display()
    );
    let cfg = config(dir.path(), thresholds, &asset("bunny3k", &src, &lods));
    let r = lodeval(["eval", cfg.to_str().unwrap()]);
    assert_eq!(r.code, 1, "{}{}", r.stdout, r.stderr);
    assert!(
        r.stderr.contains("FAIL bunny3k/holey flip_mean"),
        "{}",
        r.stderr
    );
    assert!(
        r.stderr.contains("FAIL bunny3k/flipped flip_mean"),
        "{}",
        r.stderr
    );
    assert!(r.stderr.contains("limit from"), "{}", r.stderr);
    assert!(!r.stderr.contains("bunny3k/meshopt-r50"), "{}", r.stderr);
    let junit = std::fs::read_to_string(dir.path().join("out/junit.xml")).unwrap();
    assert!(
        junit.contains("<failure") && junit.contains("holey"),
        "{junit}"
    );
    let report = std::fs::read_to_string(dir.path().join("out/report.html")).unwrap();
    let first_fail = report.find("FAIL bunny3k/").unwrap();
    assert!(
        first_fail < report.find("<table").unwrap(),
        "failures come first"
    );
}

#[test]
fn baseline_regressions_and_switch_distances_fail_the_gate() {
    let dir = tempfile::tempdir().unwrap();
    let src = model("bunny/bunny_odedstein_3k.obj");
    let good = asset(
        "bunny3k",
        &src,
        "generate = { method = \"meshopt\", ratios = [0.5] }",
    );
    let cfg = config(dir.path(), "", &good);
    assert_eq!(lodeval(["eval", cfg.to_str().unwrap()]).code, 0);
    // A baseline whose FLIP means were half of today's: today is a regression.
    let summary = std::fs::read_to_string(dir.path().join("out/summary.csv")).unwrap();
    let mut base = String::new();
    for (i, line) in summary.lines().enumerate() {
        let mut f: Vec<String> = line.split(',').map(str::to_string).collect();
        if i > 0 && f[4] == "flip" {
            f[5] = format!("{}", f[5].parse::<f64>().unwrap() / 2.0);
        }
        base.push_str(&f.join(","));
        base.push('\n');
    }
    std::fs::write(dir.path().join("baseline.csv"), base).unwrap();
    let cfg = config(
        dir.path(),
        "[gate]\nbaseline = \"baseline.csv\"\ntolerance = 0.1\n",
        &good,
    );
    let r = lodeval(["eval", cfg.to_str().unwrap()]);
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert!(r.stderr.contains("baseline:flip"), "{}", r.stderr);
    assert!(!r.stderr.contains("baseline:ssim"), "{}", r.stderr);
    // Its own summary as the baseline passes.
    std::fs::write(dir.path().join("baseline.csv"), summary).unwrap();
    assert_eq!(lodeval(["eval", cfg.to_str().unwrap()]).code, 0);
    // An engine switch distance nearer than the measured one fails, naming both distances.
    let near = asset(
        "bunny3k",
        &src,
        "generate = { method = \"meshopt\", ratios = [0.5], switch_m = [0.5] }",
    );
    let cfg = config(dir.path(), "", &near);
    let r = lodeval(["eval", cfg.to_str().unwrap()]);
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert!(
        r.stderr.contains("is used from 0.5 m but is visible until"),
        "{}",
        r.stderr
    );
}

#[test]
fn a_bad_key_is_named_at_its_own_line_not_where_its_name_first_appears() {
    // The line came from a substring search for the key's name, so `views` was found in a
    // comment, or inside `sheet_views`, and the message named the wrong line. The TOML parser's
    // spans give the key's own line; an asset's problem is at the line of its name.
    let dir = tempfile::tempdir().unwrap();
    let mesh = model("bunny/bunny_odedstein_3k.obj");
    let head = "# views (distance) and sheet_views (images) for asset \"b\"\nout = \"out\"\nmetrics = [\"flip\"]\n[render]\nsize = 64\nrig = \"icosahedron\"\n[images]\nsheet_views = 4\n[distance]\n";
    for (distance, assets, want) in [
        ("views = 0\n", asset("b", &mesh, CHAIN), "line 10"),
        ("views = 1\n", asset("b", &mesh, ""), "line 12"),
    ] {
        let path = dir.path().join("c.toml");
        std::fs::write(&path, format!("{head}{distance}{assets}")).unwrap();
        let r = lodeval(["eval", path.to_str().unwrap()]);
        assert_eq!(r.code, 2, "{}", r.stderr);
        assert!(r.stderr.contains(want), "want {want}: {}", r.stderr);
    }
}

#[test]
fn bad_configs_exit_2_naming_the_file_key_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let src = model("bunny/bunny_odedstein_3k.obj");
    let good = asset("b", &src, CHAIN);
    for (extra, words) in [
        ("[images]\nsise = 3\n", vec!["line 10", "sise"]),
        (
            "[images]\nheatmaps = \"some\"\n",
            vec!["line 10", "some", "worst"],
        ),
        ("[viewing]\ndistance_m = 0.0\n", vec!["line 10", "above 0"]),
        (
            "[thresholds]\nflip_mean = \"low\"\n",
            vec!["line 10", "flip_mean"],
        ),
    ] {
        let cfg = config(dir.path(), extra, &good);
        let r = lodeval(["eval", cfg.to_str().unwrap()]);
        assert_eq!(r.code, 2, "{extra}: {}", r.stderr);
        assert!(r.stderr.contains("c.toml"), "{}", r.stderr);
        for w in words {
            assert!(r.stderr.contains(w), "{extra}: {w} not in {}", r.stderr);
        }
        assert!(!dir.path().join("out/metrics.csv").exists());
    }
    // A missing mesh names the mesh file.
    let cfg = config(
        dir.path(),
        "",
        &asset("b", &dir.path().join("nope.obj"), CHAIN),
    );
    let r = lodeval(["eval", cfg.to_str().unwrap()]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("nope.obj"), "{}", r.stderr);
    // A missing config, and a bad shard.
    assert_eq!(lodeval(["eval", "no-such.toml"]).code, 2);
    let cfg = config(dir.path(), "", &good);
    let r = lodeval(["eval", cfg.to_str().unwrap(), "--shard", "2/2"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
}

#[test]
fn golden_images_compare_mismatch_bless_and_refuse_under_ci() {
    let dir = tempfile::tempdir().unwrap();
    let extra = "[golden]\ndir = \"golden\"\nlods = false\n";
    let assets = asset(
        "bunny3k",
        &model("bunny/bunny_odedstein_3k.obj"),
        "generate = { method = \"meshopt\", ratios = [0.5] }",
    );
    let cfg = config(dir.path(), extra, &assets);
    let c = cfg.to_str().unwrap();
    // No goldens yet: exit 1, one line that says so with the bless command (not one line per
    // image), no pending renders written, and the report says "missing", not "sizes differ".
    let r = lodeval_ci(&["golden", c], false);
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert!(
        r.stderr.contains("MISSING 12 of 12 golden image(s)")
            && r.stderr.contains(&format!("lodeval golden {c} --bless")),
        "{}",
        r.stderr
    );
    assert!(r.stderr.lines().count() <= 3, "{}", r.stderr);
    let pending = dir.path().join("out/golden/bunny3k");
    assert!(!pending.exists(), "renders written for missing goldens");
    let report = std::fs::read_to_string(dir.path().join("out/golden/report.html")).unwrap();
    assert!(
        report.contains("12 missing") && !report.contains("sizes differ"),
        "{report}"
    );
    // Blessing is refused under CI, and writes nothing.
    let r = lodeval_ci(&["golden", c, "--bless"], true);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("refusing"), "{}", r.stderr);
    assert!(!dir.path().join("golden").exists());
    // Bless, then compare clean.
    let r = lodeval_ci(&["golden", c, "--bless"], false);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let golden = dir.path().join("golden/bunny3k/original/view-03.png");
    assert!(golden.exists());
    let r = lodeval_ci(&["golden", c], true);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(r.stdout.contains("12 image(s) match"), "{}", r.stdout);
    // Paint a block into one golden: that view (only) mismatches, with actual and diff images.
    let mut img = image::open(&golden).unwrap().to_rgb8();
    for y in 20..40 {
        for x in 20..40 {
            img.put_pixel(x, y, image::Rgb([255, 0, 0]));
        }
    }
    img.save(&golden).unwrap();
    let r = lodeval_ci(&["golden", c], true);
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert_eq!(r.stderr.matches("MISMATCH").count(), 1, "{}", r.stderr);
    assert!(r.stderr.contains("view-03.png"), "{}", r.stderr);
    let out = dir.path().join("out/golden/bunny3k/original");
    assert!(out.join("view-03-actual.png").exists() && out.join("view-03-diff.png").exists());
    // The report shows the mismatch first, with expected, actual, diff and the wipe slider.
    let report = dir.path().join("out/golden/report.html");
    let html = std::fs::read_to_string(&report).unwrap();
    assert!(html.contains("<b>1</b> of 12 image(s) differ"), "{html}");
    assert!(html.contains("bunny3k/original/view 3"), "{html}");
    assert_eq!(
        html.matches("data:image/png;base64,").count(),
        5,
        "expected, actual, diff, and both in the wipe"
    );
    assert!(html.contains("type=\"range\""));
    golden_report_renders_in_chromium(&report, dir.path());
    // A filter that names nothing is refused; one that names the view blesses only it.
    let r = lodeval_ci(&["golden", c, "--bless", "bunny3k/original/99"], false);
    assert_eq!(r.code, 2, "{}", r.stderr);
    let r = lodeval_ci(&["golden", c, "--bless", "nope"], false);
    assert_eq!(r.code, 2, "{}", r.stderr);
    let other = dir.path().join("golden/bunny3k/original/view-05.png");
    let before = std::fs::read(&other).unwrap();
    let r = lodeval_ci(&["golden", c, "--bless", "bunny3k/original/3"], false);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stdout.contains("blessed 1 golden image(s)"),
        "{}",
        r.stdout
    );
    assert!(r.stdout.contains("11 image(s) match"), "{}", r.stdout);
    assert_eq!(
        std::fs::read(&other).unwrap(),
        before,
        "other goldens are untouched"
    );
    let r = lodeval_ci(&["golden", c], true);
    assert_eq!(r.code, 0, "{}", r.stderr);
}

/// The golden report in headless Chromium: the failing row's tint and the images are drawn.
fn golden_report_renders_in_chromium(report: &Path, dir: &Path) {
    let Some(img) = screenshot(report, &dir.join("golden-shot.png"), (1400, 700)) else {
        return;
    };
    let count = |f: &dyn Fn(&image::Rgb<u8>) -> bool| img.pixels().filter(|p| f(p)).count();
    // The failing row's tint (#fde2e2), its red edge (#c0392b), the painted block in the golden
    // (pure red) and the renders' mid-grey background.
    let tint = count(&|p| p.0 == [0xfd, 0xe2, 0xe2]);
    let edge = count(&|p| p.0 == [0xc0, 0x39, 0x2b]);
    let red = count(&|p| p.0[0] > 240 && p.0[1] < 20 && p.0[2] < 20);
    let grey = count(&|p| (p.0[0] as i32 - 128).abs() < 6 && p.0[0] == p.0[1] && p.0[1] == p.0[2]);
    assert!(
        tint > 5_000 && edge > 500 && red > 200 && grey > 20_000,
        "tint {tint} edge {edge} red {red} grey {grey}"
    );
}

/// Per LOD, in chain order: (FLIP mean over views, VDP imperceptibility distance).
fn chain_scores(dir: &Path) -> Vec<(String, f64, f64)> {
    let summary = std::fs::read_to_string(dir.join("summary.csv")).unwrap();
    let distances = std::fs::read_to_string(dir.join("distances.csv")).unwrap();
    summary
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|f| f[4] == "flip")
        .map(|f| {
            let d = distances
                .lines()
                .map(|l| l.split(',').collect::<Vec<_>>())
                .find(|d| d[1] == f[1] && d[3].starts_with("vdp"))
                .map(|d| d[4].parse::<f64>().unwrap())
                .unwrap();
            (f[1].to_string(), f[5].parse().unwrap(), d)
        })
        .collect()
}

#[test]
fn scores_and_distances_grow_along_the_lod_chain_of_every_shipped_model() {
    let dir = tempfile::tempdir().unwrap();
    let chain = "generate = { method = \"meshopt\", ratios = [0.5, 0.2, 0.05] }";
    let assets: String = [
        ("bunny", "bunny/stanford-bunny.obj"),
        ("bunny3k", "bunny/bunny_odedstein_3k.obj"),
        ("spot", "spot/spot_mtl.obj"),
        ("barrel", "barrel/barrel.glb"),
        ("dragon", "dragon/dragon_vrip_res4.ply"),
    ]
    .iter()
    .map(|(n, p)| asset(n, &model(p), chain))
    .collect();
    let text = format!(
        "out = \"out\"\nmetrics = [\"flip\", \"vdp\"]\n[render]\nsize = 96\nrig = \"icosahedron\"\n[distance]\nviews = 2\nmax_diameter_px = 512\n{assets}"
    );
    let cfg = dir.path().join("chain.toml");
    std::fs::write(&cfg, text).unwrap();
    let r = lodeval(["eval", cfg.to_str().unwrap()]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    eprintln!("{}", r.stdout);
    let summary = std::fs::read_to_string(dir.path().join("out/summary.csv")).unwrap();
    let all = chain_scores(&dir.path().join("out"));
    let distances = std::fs::read_to_string(dir.path().join("out/distances.csv")).unwrap();
    for name in ["bunny", "bunny3k", "spot", "barrel", "dragon"] {
        let mine: Vec<&str> = summary
            .lines()
            .filter(|l| l.starts_with(&format!("{name},")) && l.contains(",flip,"))
            .collect();
        assert_eq!(mine.len(), 3, "{name}");
        let flips: Vec<f64> = mine
            .iter()
            .map(|l| l.split(',').nth(5).unwrap().parse().unwrap())
            .collect();
        assert!(
            flips.windows(2).all(|w| w[0] < w[1]),
            "{name}: FLIP {flips:?}"
        );
        let dists: Vec<f64> = distances
            .lines()
            .filter(|l| l.starts_with(&format!("{name},")) && l.contains(",vdp_p"))
            .map(|l| l.split(',').nth(4).unwrap().parse().unwrap())
            .collect();
        assert_eq!(dists.len(), 3, "{name}");
        assert!(
            dists.windows(2).all(|w| w[0] <= w[1]),
            "{name}: distances {dists:?}"
        );
    }
    assert_eq!(all.len(), 15);
    assert!(all.iter().all(|(_, flip, d)| *flip > 0.0 && *d > 0.0));
}

/// The Chromium binary, if installed.
fn chromium() -> Option<PathBuf> {
    ["chromium", "chromium-browser", "google-chrome"]
        .iter()
        .find_map(|name| {
            let ok = Command::new(name)
                .arg("--version")
                .output()
                .ok()?
                .status
                .success();
            ok.then(|| PathBuf::from(name))
        })
}

/// A headless Chromium screenshot of `page` at `size`, or `None` (with a note) where Chromium
/// is missing outside CI; under CI a missing browser fails the test.
fn screenshot(page: &Path, shot: &Path, size: (u32, u32)) -> Option<image::RgbImage> {
    let Some(browser) = chromium() else {
        // CI installs Chromium (.ci/run); there a missing browser is a failure, not a skip.
        assert!(
            std::env::var_os("CI").is_none(),
            "Chromium is required under CI for the report screenshot tests"
        );
        eprintln!("SKIPPED: no chromium on this machine (apt-get install chromium)");
        return None;
    };
    let out = Command::new(&browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--hide-scrollbars",
            &format!("--window-size={},{}", size.0, size.1),
            &format!("--screenshot={}", shot.display()),
        ])
        .arg(format!("file://{}", page.display()))
        .output()
        .unwrap();
    assert!(shot.exists(), "{}", String::from_utf8_lossy(&out.stderr));
    Some(image::open(shot).unwrap().to_rgb8())
}

#[test]
fn report_renders_in_headless_chromium_with_its_plot_and_contact_sheets() {
    let dir = tempfile::tempdir().unwrap();
    let assets = asset(
        "spot",
        &model("spot/spot_mtl.obj"),
        "generate = { method = \"meshopt\", ratios = [0.5, 0.1] }",
    );
    let cfg = config(dir.path(), "[thresholds]\nflip_mean = 0.03\n", &assets);
    let r = lodeval(["eval", cfg.to_str().unwrap()]);
    assert_eq!(r.code, 1, "the 10 % LOD fails the gate: {}", r.stderr);
    let report = dir.path().join("out/report.html");
    let Some(img) = screenshot(&report, &dir.path().join("shot.png"), (1200, 1600)) else {
        return;
    };
    assert_eq!(img.dimensions(), (1200, 1600));
    let count = |f: &dyn Fn(&image::Rgb<u8>) -> bool| img.pixels().filter(|p| f(p)).count();
    // The plot line (#b5367a), the failing row's tint (#fde2e2) and the renders' mid-grey
    // background inside the contact sheets must all be on screen.
    let near = |p: &image::Rgb<u8>, c: [u8; 3]| {
        p.0.iter()
            .zip(c)
            .all(|(a, b)| (*a as i32 - b as i32).abs() <= 6)
    };
    let plot = count(&|p| near(p, [0xb5, 0x36, 0x7a]));
    let fail_row = count(&|p| near(p, [0xfd, 0xe2, 0xe2]));
    let grey = count(&|p| near(p, [128, 128, 128]));
    eprintln!("plot {plot} px, failing row {fail_row} px, render background {grey} px");
    assert!(plot > 200, "plot not drawn ({plot} px)");
    assert!(fail_row > 2000, "failing row not shown ({fail_row} px)");
    assert!(grey > 20_000, "contact sheets not loaded ({grey} px)");
}

#[test]
fn the_shipped_ci_config_passes_its_gate_and_matches_its_goldens() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = crate::common::root().join("configs/ci.toml");
    let r = lodeval([
        "eval",
        cfg.to_str().unwrap(),
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(r.code, 0, "{}{}", r.stdout, r.stderr);
    let r = lodeval([
        "golden",
        cfg.to_str().unwrap(),
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(r.code, 0, "{}{}", r.stdout, r.stderr);
    assert!(r.stdout.contains("24 image(s) match"), "{}", r.stdout);
}

#[test]
fn the_example_ci_files_set_the_variables_lodeval_reads() {
    use lodeval::eval::Shard;
    let read = |f: &str| {
        std::fs::read_to_string(crate::common::root().join("examples/ci").join(f)).unwrap()
    };
    // The value after `key:` on its line (first occurrence).
    let value = |text: &str, key: &str| -> String {
        text.lines()
            .find_map(|l| l.trim().strip_prefix(key))
            .unwrap_or_else(|| panic!("{key} missing"))
            .trim()
            .trim_matches('"')
            .to_string()
    };
    // Every index of a run of `count` jobs gets its own shard, and together they cover all.
    let check = |env: &dyn Fn(usize) -> Vec<(&'static str, String)>, jobs: usize, count: u32| {
        let mut seen = Vec::new();
        for j in 0..jobs {
            let vars = env(j);
            let s = Shard::from_env(|k| vars.iter().find(|(n, _)| *n == k).map(|(_, v)| v.clone()))
                .unwrap()
                .expect("the variables select a shard");
            assert_eq!(s.count, count);
            seen.push(s.index);
        }
        seen.sort_unstable();
        assert_eq!(seen, (0..count).collect::<Vec<_>>());
    };
    // GitHub Actions: a matrix of shard indices, TEST_SHARD_INDEX from it, TEST_TOTAL_SHARDS.
    let gh = read("github-actions.yml");
    let matrix: Vec<u32> = value(&gh, "shard: [")
        .trim_matches(|c| c == ']')
        .split(',')
        .map(|v| v.trim().parse().unwrap())
        .collect();
    assert_eq!(value(&gh, "TEST_SHARD_INDEX:"), "${{ matrix.shard }}");
    let total: u32 = value(&gh, "TEST_TOTAL_SHARDS:").parse().unwrap();
    assert_eq!(matrix.len() as u32, total);
    check(
        &|j| {
            vec![
                ("TEST_SHARD_INDEX", matrix[j].to_string()),
                ("TEST_TOTAL_SHARDS", total.to_string()),
            ]
        },
        matrix.len(),
        total,
    );
    assert!(
        gh.contains("lodeval merge"),
        "the workflow merges and gates"
    );
    // GitLab: `parallel: N` sets CI_NODE_INDEX (1-based) and CI_NODE_TOTAL.
    let gl = read("gitlab-ci.yml");
    let n: u32 = value(&gl, "parallel:").parse().unwrap();
    check(
        &|j| {
            vec![
                ("CI_NODE_INDEX", (j + 1).to_string()),
                ("CI_NODE_TOTAL", n.to_string()),
            ]
        },
        n as usize,
        n,
    );
    assert!(gl.contains("lodeval merge"));
    // Kubernetes: an Indexed Job sets JOB_COMPLETION_INDEX; the file sets LODEVAL_SHARD_COUNT
    // to its `completions`.
    let k8s = read("kubernetes-indexed-job.yaml");
    assert_eq!(value(&k8s, "completionMode:"), "Indexed");
    let completions: u32 = value(&k8s, "completions:").parse().unwrap();
    let pos = k8s
        .find("name: LODEVAL_SHARD_COUNT")
        .expect("the shard count is set");
    let count: u32 = value(&k8s[pos..], "value:").parse().unwrap();
    assert_eq!(count, completions);
    check(
        &|j| {
            vec![
                ("JOB_COMPLETION_INDEX", j.to_string()),
                ("LODEVAL_SHARD_COUNT", count.to_string()),
            ]
        },
        completions as usize,
        completions,
    );
}

#[test]
fn the_render_cache_gives_the_same_bytes_and_renders_originals_once() {
    let dir = tempfile::tempdir().unwrap();
    let assets = asset("bunny3k", &model("bunny/bunny_odedstein_3k.obj"), CHAIN);
    let cfg = config(dir.path(), "", &assets);
    let c = cfg.to_str().unwrap();
    let out = |name: &str| dir.path().join(name);
    let cache = dir.path().join("cache");
    let run = |o: &str, with_cache: bool| {
        let o = out(o);
        let mut args = vec!["eval", c, "--out", o.to_str().unwrap()];
        if with_cache {
            args.extend(["--cache", cache.to_str().unwrap()]);
        }
        let r = lodeval(args);
        assert_eq!(r.code, 0, "{}", r.stderr);
    };
    run("plain", false);
    run("cold", true);
    let entries = || files(&cache).len();
    // One frame per view of the original (12 icosahedron views).
    assert_eq!(entries(), 12);
    run("warm", true);
    assert_eq!(entries(), 12, "a warm run adds nothing");
    assert_same_tree(&out("plain"), &out("cold"));
    assert_same_tree(&out("plain"), &out("warm"));
    // A damaged entry is a miss: rendered again, rewritten, and the outputs stay the same.
    let first = files(&cache).keys().next().unwrap().clone();
    std::fs::write(cache.join(&first), b"garbage").unwrap();
    run("repaired", true);
    assert_same_tree(&out("plain"), &out("repaired"));
    assert!(std::fs::metadata(cache.join(&first)).unwrap().len() > 1000);
    // An entry that is a FIFO is a miss too, not a hang (the bounded reader of regular files).
    let entry = cache.join(&first);
    std::fs::remove_file(&entry).unwrap();
    crate::hostile::files::fifo(
        entry.parent().unwrap(),
        entry.file_name().unwrap().to_str().unwrap(),
    );
    let o = out("fifo");
    let r = crate::common::lodeval_within(
        60,
        [
            "eval",
            c,
            "--out",
            o.to_str().unwrap(),
            "--cache",
            cache.to_str().unwrap(),
        ],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert_same_tree(&out("plain"), &o);
    // Another image size is another set of frames.
    let cfg2 = dir.path().join("c2.toml");
    std::fs::write(
        &cfg2,
        std::fs::read_to_string(&cfg)
            .unwrap()
            .replace("size = 64", "size = 48"),
    )
    .unwrap();
    let o = out("other");
    let r = lodeval([
        "eval",
        cfg2.to_str().unwrap(),
        "--out",
        o.to_str().unwrap(),
        "--cache",
        cache.to_str().unwrap(),
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert_eq!(entries(), 24);
}
