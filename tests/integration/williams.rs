//! `lodeval simplify --method williams` (Williams et al. 2003) end to end, its bad inputs, and the
//! paper experiment on a tiny config.

use crate::common::{lodeval, model};

fn simplify(dir: &std::path::Path, threads: &str, extra: &[&str]) -> (crate::common::Run, Vec<u8>) {
    let original = model("bunny/bunny_odedstein_3k.obj");
    // One folder per thread count: the OBJ names its MTL file, so the file name must not differ.
    let out = dir.join(format!("t{threads}")).join("w.obj");
    std::fs::create_dir_all(out.parent().unwrap()).unwrap();
    let mut args = vec![
        "--threads",
        threads,
        "simplify",
        original.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--method",
        "williams",
    ];
    args.extend_from_slice(extra);
    let r = lodeval(args);
    let bytes = std::fs::read(&out).unwrap_or_default();
    (r, bytes)
}

#[test]
fn a_view_dependent_lod_within_budget_identical_for_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let (r1, a) = simplify(dir.path(), "1", &["--budget", "800"]);
    assert_eq!(r1.code, 0, "{}", r1.stderr);
    let tris = a
        .split(|&b| b == b'\n')
        .filter(|l| l.starts_with(b"f "))
        .count();
    assert!(
        (700..=800).contains(&tris),
        "{tris} triangles for a budget of 800"
    );
    for t in ["2", "8"] {
        let (r, b) = simplify(dir.path(), t, &["--budget", "800"]);
        assert_eq!(r.code, 0, "{}", r.stderr);
        assert!(a == b, "--threads {t} changed the LOD");
    }
    // Another view gives another LOD; an explicit camera and the static all-views LOD work too.
    let (r, c) = simplify(dir.path(), "1", &["--budget", "800", "--view", "7"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(a != c, "view 7 gave view 0's LOD");
    let (r, _) = simplify(dir.path(), "1", &["--budget", "800", "--camera", "0,0.1,1"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let (r, _) = simplify(
        dir.path(),
        "1",
        &[
            "--budget",
            "800",
            "--all-views",
            "--criterion",
            "screen-space",
        ],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
}

#[test]
fn bad_williams_requests_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    for extra in [
        &[][..],
        &["--budget", "800", "--camera", "1,2,3,4"][..],
        &["--budget", "800", "--criterion", "psnr"][..],
        &["--budget", "800", "--view", "99"][..],
        &["--budget", "800", "--shading", "toon"][..],
        &["--budget", "800", "--camera", "0,0,0,0,0,0"][..],
    ] {
        let (r, bytes) = simplify(dir.path(), "1", extra);
        assert_eq!(r.code, 2, "{extra:?}: {}", r.stderr);
        assert!(r.stderr.contains("--"), "{extra:?}: {}", r.stderr);
        assert!(bytes.is_empty(), "{extra:?} wrote a file");
    }
}

#[test]
fn the_paper_experiment_runs_from_a_config() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("w.toml");
    std::fs::write(
        &config,
        format!(
            "out = \"out\"\nbudgets = [0.1]\nsingle_size = 96\nmean_size = 64\nrig = \"fibonacci:3\"\n\
             [[scene]]\nname = \"b\"\nmesh = \"{}\"\nshading = \"gouraud\"\n",
            model("bunny/bunny_odedstein_3k.obj").display()
        ),
    )
    .unwrap();
    let r = lodeval(["simplify", "--experiment", config.to_str().unwrap()]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let summary = std::fs::read_to_string(dir.path().join("out/summary.csv")).unwrap();
    // Header plus one row per criterion.
    assert_eq!(summary.lines().count(), 5, "{summary}");
    for f in ["results.csv", "preprocess.csv", "b.svg", "b-sheet.png"] {
        assert!(dir.path().join("out").join(f).exists(), "{f}");
    }
    // An unknown key is an input error naming the file.
    std::fs::write(
        &config,
        "out = \"o\"\nbudgets = [0.1]\nscene = []\nbogus = 1\n",
    )
    .unwrap();
    let r = lodeval(["simplify", "--experiment", config.to_str().unwrap()]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("w.toml"), "{}", r.stderr);
}

#[test]
fn eval_generates_williams_lods_within_budget() {
    // `generate = { method = "williams" }`: one static LOD per ratio for the rig's views.
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "out = \"out\"\nmetrics = [\"flip\"]\ngeometry_samples = 0\n[render]\nsize = 64\nrig = \"icosahedron\"\n[distance]\nenabled = false\n[[asset]]\nname = \"w\"\nmesh = \"{}\"\ngenerate = {{ method = \"williams\", ratios = [0.5, 0.1] }}\n",
        model("bunny/bunny_odedstein_3k.obj").display()
    );
    let cfg = dir.path().join("g.toml");
    std::fs::write(&cfg, text).unwrap();
    let r = lodeval(["eval", cfg.to_str().unwrap()]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let lods = std::fs::read_to_string(dir.path().join("out/lods.csv")).unwrap();
    let header: Vec<&str> = lods.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "triangles").unwrap();
    let rows: Vec<Vec<&str>> = lods
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    for (name, budget) in [("williams-r50", 3299), ("williams-r10", 660)] {
        let row = rows
            .iter()
            .find(|r| r.contains(&name))
            .unwrap_or_else(|| panic!("{name}: {lods}"));
        let t: usize = row[col].parse().unwrap();
        assert!(
            t <= budget && t + 8 >= budget,
            "{name}: {t} triangles for {budget}"
        );
    }
    // The coarser LOD has the larger mean FLIP (summary.csv: asset,lod,…,metric,mean,…).
    let summary = std::fs::read_to_string(dir.path().join("out/summary.csv")).unwrap();
    let flip = |lod: &str| -> f64 {
        summary
            .lines()
            .map(|l| l.split(',').collect::<Vec<_>>())
            .find(|r| r[1] == lod && r[4] == "flip")
            .unwrap_or_else(|| panic!("{lod}: {summary}"))[5]
            .parse()
            .unwrap()
    };
    assert!(flip("williams-r50") < flip("williams-r10"));
}

#[test]
fn a_non_manifold_scan_gets_a_lod_within_budget() {
    // The shipped dragon has non-manifold edges; the MT is built by replaying QEM's collapse
    // record, which now passes through them, so the replay must use the same rules.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("w.obj");
    let r = crate::common::simplify(
        &model("dragon/dragon_vrip_res4.ply"),
        &out,
        &["--method", "williams", "--budget", "500"],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    let tris = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("f "))
        .count();
    assert!(
        (400..=500).contains(&tris),
        "{tris} triangles for a budget of 500"
    );
}
