//! `lodeval optimize`: the image-driven optimizer end to end on the shipped bunny.

use crate::common::{lodeval, model};

/// Simplify the 3k-triangle bunny with vertex clustering, then optimize it with a small budget.
fn run(
    dir: &std::path::Path,
    threads: &str,
    out: &str,
) -> (crate::common::Run, std::path::PathBuf) {
    let original = model("bunny/bunny_odedstein_3k.obj");
    let coarse = dir.join("coarse.obj");
    if !coarse.exists() {
        let r = crate::common::simplify(
            &original,
            &coarse,
            &["--method", "cluster", "--ratio", "0.1"],
        );
        assert_eq!(r.code, 0, "{}", r.stderr);
    }
    let out = dir.join(out);
    std::fs::create_dir_all(out.parent().unwrap()).unwrap();
    let csv = out.with_extension("csv");
    let r = lodeval([
        "--threads",
        threads,
        "optimize",
        original.to_str().unwrap(),
        coarse.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--evals",
        "1500",
        "--views",
        "8",
        "--size",
        "96",
        "--energy-csv",
        csv.to_str().unwrap(),
    ]);
    (r, out)
}

#[test]
fn lowers_the_energy_keeps_the_vertex_count_and_is_thread_independent() {
    let dir = tempfile::tempdir().unwrap();
    let (r1, out1) = run(dir.path(), "1", "t1/o.obj");
    assert_eq!(r1.code, 0, "{}", r1.stderr);
    // "… d_MS a -> b (p % of the input's energy) …": the energy went down.
    let pct: f64 = r1
        .stdout
        .split('(')
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no percentage in {}", r1.stdout));
    assert!(pct < 100.0, "{}", r1.stdout);
    // The energy log starts at 1 and never goes up (only improving moves are kept, except a
    // teleport's rare uphill collapse, which cannot occur at this budget without being followed
    // by the split it pays for — so check the end against the start only).
    let log = std::fs::read_to_string(out1.with_extension("csv")).unwrap();
    let rows: Vec<&str> = log.lines().collect();
    assert_eq!(rows[0], "evals,seconds,d_ms,relative");
    assert!(
        rows[1].ends_with(",1.0") || rows[1].ends_with(",1"),
        "{}",
        rows[1]
    );
    let last: f64 = rows
        .last()
        .unwrap()
        .rsplit(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(last < 1.0);
    // Vertex count: same as the input's.
    let count = |p: &std::path::Path| {
        let r = lodeval(["info", "--json", p.to_str().unwrap()]);
        let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
        v["welded_vertices"].as_u64().unwrap()
    };
    assert_eq!(count(&out1), count(&dir.path().join("coarse.obj")));
    // Same bytes for 2 and 8 threads.
    for t in ["2", "8"] {
        let (r, out) = run(dir.path(), t, &format!("t{t}/o.obj"));
        assert_eq!(r.code, 0, "{}", r.stderr);
        // (The OBJ names its .mtl, so the outputs share a file name in separate folders.)
        let same = std::fs::read(&out).unwrap() == std::fs::read(&out1).unwrap();
        assert!(
            same,
            "{t} threads: {} differs from {}",
            out.display(),
            out1.display()
        );
    }
}

#[test]
fn bad_input_exits_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.obj");
    let original = model("bunny/bunny_odedstein_3k.obj");
    let r = lodeval([
        "optimize",
        original.to_str().unwrap(),
        dir.path().join("missing.obj").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("missing.obj"), "{}", r.stderr);
    assert!(!out.exists());
    let r = lodeval([
        "optimize",
        original.to_str().unwrap(),
        original.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--normals",
        "sideways",
    ]);
    assert_eq!(r.code, 2);
    assert!(r.stderr.contains("--normals"), "{}", r.stderr);
}

#[test]
fn bench_optimize_reports_steady_rates_on_the_issue_case() {
    // `lodeval bench optimize`: our QEM LOD of each mesh, 20 views at 256², timed runs; a
    // small LOD and budget here.
    let original = model("bunny/bunny_odedstein_3k.obj");
    let bench = |extra: &[&str]| {
        let mut args = vec!["--threads", "2", "bench", "optimize"];
        args.extend_from_slice(extra);
        lodeval(args)
    };
    let mesh = original.to_str().unwrap();
    let r = bench(&[
        mesh,
        "--triangles",
        "300",
        "--evals",
        "1500",
        "--runs",
        "2",
        "--json",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let rows: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let row = &rows[0];
    assert_eq!(row["mesh"], "bunny_odedstein_3k", "{row}");
    let tris = row["triangles"].as_u64().unwrap();
    assert!((250..=300).contains(&tris), "{row}");
    assert!(row["vertices"].as_u64().unwrap() > 100, "{row}");
    assert_eq!(
        (row["views"].as_u64(), row["size"].as_u64()),
        (Some(20), Some(256))
    );
    assert_eq!(
        (row["evaluations"].as_u64(), row["runs"].as_u64()),
        (Some(1500), Some(2))
    );
    let rate = |k: &str| row[k].as_f64().unwrap();
    assert!(rate("best_per_s") >= rate("median_per_s"), "{row}");
    assert!(rate("median_per_s") >= rate("worst_per_s"), "{row}");
    assert!(
        rate("worst_per_s") > 0.0 && rate("setup_seconds") > 0.0,
        "{row}"
    );

    // No mesh, or a budget too small to time: usage errors.
    let r = bench(&[]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("give at least one mesh"), "{}", r.stderr);
    let r = bench(&[mesh, "--triangles", "300", "--evals", "0"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("--evals"), "{}", r.stderr);
}
