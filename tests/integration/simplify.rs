//! `lodeval simplify` and `lodeval geometry` end to end, and the eval generators `qem` and
//! `cluster`.

use crate::common::{lodeval, model, simplify};

#[test]
fn simplify_writes_loadable_lods_with_every_method() {
    let dir = tempfile::tempdir().unwrap();
    let src = model("spot/spot_mtl.obj");
    for method in ["qem", "cluster", "meshopt", "meshopt-update"] {
        let out = dir.path().join(format!("{method}.obj"));
        let r = simplify(
            &src,
            &out,
            &["--method", method, "--triangles", "1000", "--json"],
        );
        assert_eq!(r.code, 0, "{method}: {}", r.stderr);
        let rows: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
        let t = rows[0]["triangles"].as_u64().unwrap();
        assert!(t <= 1000 && t > 500, "{method}: {t}");
        // The written OBJ (with its MTL and texture) loads back with the same triangle count.
        let info = lodeval(["info", "--json", out.to_str().unwrap()]);
        assert_eq!(info.code, 0, "{}", info.stderr);
        let v: serde_json::Value = serde_json::from_str(&info.stdout).unwrap();
        assert_eq!(v["triangles"].as_u64().unwrap(), t, "{method}");
        assert!(
            info.stdout.contains("basecolor"),
            "{method}: texture lost: {}",
            info.stdout
        );
    }
    // A chain writes one file per ratio.
    let out = dir.path().join("chain.obj");
    let r = simplify(&src, &out, &["--chain", "0.5,0.1"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(dir.path().join("chain-r50.obj").exists() && dir.path().join("chain-r10.obj").exists());
}

#[test]
fn simplify_rejects_bad_requests_with_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let src = model("spot/spot_mtl.obj");
    let out = dir.path().join("x.obj");
    let (s, o) = (src.to_str().unwrap(), out.to_str().unwrap());
    for args in [
        vec![
            "simplify", s, "-o", o, "--method", "magic", "--ratio", "0.5",
        ],
        vec!["simplify", s, "-o", o, "--ratio", "1.5"],
        vec!["simplify", s, "-o", o],
        vec!["simplify", s, "-o", "x.ply", "--ratio", "0.5"],
        vec![
            "simplify", s, "-o", o, "--method", "cluster", "--error", "0.01",
        ],
    ] {
        let r = lodeval(&args);
        assert_eq!(r.code, 2, "{args:?}: {}", r.stderr);
        assert!(!out.exists());
    }
}

#[test]
fn geometry_reports_zero_for_a_copy_and_the_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let a = model("bunny/bunny_odedstein_3k.obj");
    let lod = dir.path().join("lod.obj");
    let r = simplify(&a, &lod, &["--ratio", "0.25"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let r = lodeval([
        "geometry",
        a.to_str().unwrap(),
        a.to_str().unwrap(),
        "--json",
        "--samples",
        "20000",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    assert!(v["hausdorff"].as_f64().unwrap() < 1e-6);
    let r = lodeval([
        "geometry",
        a.to_str().unwrap(),
        lod.to_str().unwrap(),
        "--json",
        "--samples",
        "20000",
    ]);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    for k in [
        "hausdorff",
        "mean",
        "rms",
        "hausdorff_relative",
        "mean_relative",
        "rms_relative",
        "samples",
    ] {
        assert!(!v[k].is_null(), "{k} missing: {v}");
    }
    let (h, m, rms) = (
        v["hausdorff"].as_f64().unwrap(),
        v["mean"].as_f64().unwrap(),
        v["rms"].as_f64().unwrap(),
    );
    assert!(h > 0.0 && m > 0.0 && m <= rms && rms <= h, "{v}");
}

#[test]
fn eval_generates_qem_and_cluster_chains_with_geometric_columns() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "out = \"out\"\nmetrics = [\"flip\"]\ngeometry_samples = 20000\n[render]\nsize = 64\nrig = \"icosahedron\"\n[distance]\nenabled = false\n[[asset]]\nname = \"q\"\nmesh = \"{0}\"\ngenerate = {{ method = \"qem\", ratios = [0.5, 0.1] }}\n[[asset]]\nname = \"c\"\nmesh = \"{0}\"\ngenerate = {{ method = \"cluster\", ratios = [0.5, 0.1] }}\n",
        model("bunny/bunny_odedstein_3k.obj").display()
    );
    let cfg = dir.path().join("g.toml");
    std::fs::write(&cfg, text).unwrap();
    let r = lodeval(["eval", cfg.to_str().unwrap()]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    for name in ["qem-r50", "qem-r10", "cluster-r50", "cluster-r10"] {
        assert!(r.stdout.contains(name), "{name}: {}", r.stdout);
    }
    let lods = std::fs::read_to_string(dir.path().join("out/lods.csv")).unwrap();
    assert!(
        lods.lines()
            .next()
            .unwrap()
            .ends_with("hausdorff,mean_distance,rms_distance,hausdorff_relative,mean_relative")
    );
    // Geometric error grows along each chain.
    for method in ["qem", "cluster"] {
        let h: Vec<f64> = lods
            .lines()
            .filter(|l| l.contains(&format!(",{method}-r")))
            .map(|l| l.split(',').nth(9).unwrap().parse().unwrap())
            .collect();
        assert_eq!(h.len(), 2);
        assert!(h[0] < h[1], "{method}: {h:?}");
    }
}

#[test]
fn a_goal_the_simplifier_cannot_reach_is_reported() {
    // Twenty separate tetrahedra: QEM takes each down to a closed two-triangle "pillow" and no
    // further (collapsing a pillow would delete a closed part), so 10 % (8 triangles) cannot be
    // reached. The LOD is written and stderr says the goal was missed and what to do.
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("tets.obj");
    let mut obj = String::new();
    for k in 0..20 {
        for [x, y, z] in [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]] {
            obj.push_str(&format!("v {} {y} {z}\n", x + 3 * k));
        }
        let b = 4 * k;
        for [p, q, r] in [[1, 3, 2], [1, 2, 4], [2, 3, 4], [1, 4, 3]] {
            obj.push_str(&format!("f {} {} {}\n", b + p, b + q, b + r));
        }
    }
    std::fs::write(&src, obj).unwrap();
    let out = dir.path().join("lod.obj");
    let r = simplify(&src, &out, &["--method", "qem", "--ratio", "0.1"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stderr
            .contains("stopped at 40 triangles, short of the goal of 8")
            && r.stderr.contains("--method"),
        "{}",
        r.stderr
    );
    assert!(out.exists());
    // A reachable goal gives no warning.
    let r = simplify(
        &model("spot/spot_mtl.obj"),
        &out,
        &["--method", "qem", "--ratio", "0.25"],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(!r.stderr.contains("warning"), "{}", r.stderr);
}

#[test]
fn qem_simplifies_through_non_manifold_parts() {
    // A 3×3 grid whose every triangle is doubled back to back: every edge has four triangles and
    // every vertex is non-manifold. QEM still reaches the goal (it used to keep all 36 triangles).
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("doubled.obj");
    let mut obj = String::new();
    for y in 0..4 {
        for x in 0..4 {
            obj.push_str(&format!("v {x} {y} 0\n"));
        }
    }
    for y in 0..3 {
        for x in 0..3 {
            let v = |dx: u32, dy: u32| (y + dy) * 4 + x + dx + 1;
            let (a, b, c, d) = (v(0, 0), v(1, 0), v(1, 1), v(0, 1));
            for [p, q, r] in [[a, b, c], [a, c, d]] {
                obj.push_str(&format!("f {p} {q} {r}\nf {p} {r} {q}\n"));
            }
        }
    }
    std::fs::write(&src, obj).unwrap();
    let out = dir.path().join("lod.obj");
    let r = simplify(
        &src,
        &out,
        &["--method", "qem", "--triangles", "12", "--json"],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    let rows: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    assert!(rows[0]["triangles"].as_u64().unwrap() <= 12, "{}", r.stdout);
    assert!(!r.stderr.contains("warning"), "{}", r.stderr);
}

#[test]
fn qem_reaches_its_goal_on_the_non_manifold_dragon_scan() {
    // The shipped Stanford dragon (res4, 11 102 triangles) has non-manifold edges from its
    // reconstruction. QEM used to stop at 25 % when asked for 2 %; it must reach the goal, with a
    // measured mean surface distance no larger than meshoptimizer's at the same goal.
    let dir = tempfile::tempdir().unwrap();
    let src = model("dragon/dragon_vrip_res4.ply");
    let mean = |method: &str| {
        let out = dir.path().join(format!("{method}.obj"));
        let r = simplify(
            &src,
            &out,
            &["--method", method, "--ratio", "0.02", "--json"],
        );
        assert_eq!(r.code, 0, "{method}: {}", r.stderr);
        assert!(!r.stderr.contains("warning"), "{method}: {}", r.stderr);
        let rows: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
        let t = rows[0]["triangles"].as_u64().unwrap();
        assert!(
            (200..=235).contains(&t),
            "{method}: {t} triangles for a goal of 222"
        );
        let g = lodeval([
            "geometry",
            src.to_str().unwrap(),
            out.to_str().unwrap(),
            "--samples",
            "50000",
            "--json",
        ]);
        assert_eq!(g.code, 0, "{}", g.stderr);
        let d: serde_json::Value = serde_json::from_str(&g.stdout).unwrap();
        d["mean_relative"].as_f64().unwrap()
    };
    let (qem, meshopt) = (mean("qem"), mean("meshopt"));
    assert!(
        qem <= meshopt,
        "QEM mean {qem} above meshoptimizer's {meshopt}"
    );
}
