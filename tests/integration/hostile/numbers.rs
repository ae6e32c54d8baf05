//! Numbers that turned into NaN or infinity in outputs: finite coordinates near f32's range
//! (1e30, 3e38), a model a billionth of a unit across, one far from the origin, or one stray
//! vertex among unit-sized ones gave `inf`/`null` bounds, blank renders and NaN in
//! `distances.csv`, `lods.csv` and `summary.csv`; an identical LOD gave PSNR `inf`; an EXR with a
//! NaN pixel was scored. Now such meshes are refused by the bounds of `src/limits.rs`, what is
//! within them renders and scores with finite numbers only, and no output holds NaN or inf.

use std::path::Path;

use super::{assert_refused, scratch, write};
use crate::common::{lodeval_within, model, simplify};

const TETRA_FACES: &str = "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";

/// A tetrahedron with edge `s` whose first corner sits at `at`.
fn tetra(dir: &Path, name: &str, s: f64, at: [f64; 3]) -> std::path::PathBuf {
    let mut text = String::new();
    for c in [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]] {
        let v: Vec<String> = (0..3).map(|k| format!("{:e}", c[k] * s + at[k])).collect();
        text.push_str(&format!("v {}\n", v.join(" ")));
    }
    write(dir, name, &(text + TETRA_FACES))
}

/// A config scoring `mesh` against itself and a QEM LOD of it, every metric and distances.
fn config(dir: &Path, name: &str, mesh: &Path) -> std::path::PathBuf {
    write(
        dir,
        &format!("{name}.toml"),
        &format!(
            "out = \"out-{name}\"\n[render]\nsize = 48\n[distance]\nmax_diameter_px = 32\n\
             [[asset]]\nname = \"a\"\nmesh = \"{m}\"\nlods = [{{ mesh = \"{m}\", name = \"same\" }}]\n",
            m = mesh.display()
        ),
    )
}

/// No CSV or JSON file under `dir` holds a NaN or an infinity as a field.
#[track_caller]
fn assert_all_finite(dir: &Path) {
    let mut checked = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        let Some(ext) = p.extension().and_then(|e| e.to_str()) else {
            continue;
        };
        if ext != "csv" && ext != "json" {
            continue;
        }
        let text = std::fs::read_to_string(&p).unwrap();
        for field in text.split([',', '\n', ' ', ':', '[', ']']) {
            let f = field.trim().trim_matches('"').to_ascii_lowercase();
            assert!(
                !matches!(f.as_str(), "nan" | "inf" | "-inf" | "infinity" | "null"),
                "{}: holds '{field}':\n{text}",
                p.display()
            );
        }
        checked += 1;
    }
    assert!(checked >= 4, "only {checked} tables in {}", dir.display());
}

#[test]
fn meshes_beyond_single_precision_are_refused() {
    let tmp = scratch("numbers-refused");
    let d = tmp.path();
    let mixed = write(
        d,
        "mixed.obj",
        &format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1e30 0 0\n{TETRA_FACES}f 1 2 5\n"),
    );
    for (mesh, words) in [
        (tetra(d, "e30.obj", 1e30, [0.; 3]), &["diagonal", "1e9"][..]),
        (tetra(d, "e38.obj", 3e38, [0.; 3]), &["diagonal"][..]),
        (
            tetra(d, "tiny.obj", 1e-30, [0.; 3]),
            &["diagonal", "1e-6"][..],
        ),
        (
            tetra(d, "far.obj", 1.0, [1e30, 0., 0.]),
            &["vertex", "from the origin"][..],
        ),
        (
            tetra(d, "utm.obj", 50.0, [4.1e6, 5e5, 0.]),
            &["vertex", "from the origin"][..],
        ),
        (mixed, &["diagonal"][..]),
    ] {
        let r = lodeval_within(20, ["info".as_ref(), mesh.as_os_str()]);
        let name = mesh.file_name().unwrap().to_string_lossy().to_string();
        let mut all = vec![name.as_str(), "outside lodeval's limits"];
        all.extend_from_slice(words);
        assert_refused(&r, &name, &all);
        // eval refuses it before it writes anything.
        let stem = name.trim_end_matches(".obj");
        let cfg = config(d, stem, &mesh);
        let r = lodeval_within(60, ["eval".as_ref(), cfg.as_os_str()]);
        assert_refused(&r, &format!("eval {name}"), &[&name]);
        assert!(!d.join(format!("out-{stem}/metrics.csv")).exists());
    }
}

#[test]
fn extreme_but_representable_meshes_score_with_finite_numbers() {
    let tmp = scratch("numbers-finite");
    let d = tmp.path();
    // 5e8 units across, 20 sizes from the origin; and 2e-6 across: both within the bounds.
    for (name, s, at) in [
        ("big", 5e8, [1e10, 0., 0.]),
        ("small", 2e-6, [1e-5, 0., 0.]),
    ] {
        let mesh = tetra(d, &format!("{name}.obj"), s, at);
        let cfg = config(d, name, &mesh);
        let r = lodeval_within(120, ["eval".as_ref(), cfg.as_os_str(), "-q".as_ref()]);
        assert_eq!(r.code, 0, "{name}: {}", r.stderr);
        let out = d.join(format!("out-{name}"));
        assert_all_finite(&out);
        // The LOD is the original: identical scores, finite (PSNR at its 100 dB ceiling).
        let metrics = std::fs::read_to_string(out.join("metrics.csv")).unwrap();
        assert!(metrics.contains(",psnr,100.0,"), "{metrics}");
        assert!(metrics.contains(",mse,0.0,"), "{metrics}");
        // And the render is not blank: the tetrahedron covers part of the frame.
        let png = d.join(format!("{name}.png"));
        let r = lodeval_within(
            20,
            [
                "render".as_ref(),
                mesh.as_os_str(),
                "-o".as_ref(),
                png.as_os_str(),
            ],
        );
        assert_eq!(r.code, 0, "{}", r.stderr);
        let img = image::open(&png).unwrap().into_luma8();
        let background = img.get_pixel(0, 0)[0];
        let covered = img.pixels().filter(|p| p[0] != background).count();
        assert!(
            covered > img.len() / 20,
            "{name}: {covered} pixels differ from the background"
        );
    }
}

#[test]
fn an_image_with_a_nan_pixel_is_not_scored() {
    let tmp = scratch("numbers-exr");
    let d = tmp.path();
    let mut img = image::Rgb32FImage::from_pixel(8, 8, image::Rgb([0.5, 0.5, 0.5]));
    img.save(d.join("ok.exr")).unwrap();
    img.put_pixel(3, 5, image::Rgb([0.5, f32::NAN, 0.5]));
    img.save(d.join("nan.exr")).unwrap();
    img.put_pixel(3, 5, image::Rgb([f32::INFINITY, 0.5, 0.5]));
    img.save(d.join("inf.exr")).unwrap();
    for bad in ["nan.exr", "inf.exr"] {
        let r = lodeval_within(
            20,
            [
                "diff".as_ref(),
                d.join("ok.exr").as_os_str(),
                d.join(bad).as_os_str(),
                "--metric".as_ref(),
                "all".as_ref(),
            ],
        );
        assert_refused(&r, bad, &[bad, "pixel (3, 5)", "NaN or infinite"]);
    }
    // Identical images: PSNR saturates at 100 dB instead of infinity.
    let r = lodeval_within(
        20,
        [
            "diff".as_ref(),
            d.join("ok.exr").as_os_str(),
            d.join("ok.exr").as_os_str(),
            "--metric".as_ref(),
            "psnr".as_ref(),
            "--json".as_ref(),
        ],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(r.stdout.contains("100.0"), "{}", r.stdout);
}

#[test]
fn a_lod_simplified_to_nothing_says_so() {
    let tmp = scratch("numbers-empty-lod");
    let r = simplify(
        &model("spot/spot_mtl.obj"),
        &tmp.path().join("lod.obj"),
        &["--method", "cluster", "--ratio", "0.00001"],
    );
    assert_refused(
        &r,
        "cluster to nothing",
        &["left no triangles", "larger ratio"],
    );
    assert!(
        !r.stderr.contains("the file contains no triangles"),
        "{}",
        r.stderr
    );
}
