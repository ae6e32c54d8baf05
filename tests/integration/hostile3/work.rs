//! Unbounded output and work: a sparse 1 GiB PLY made `info` write a 1 GiB error message; a
//! sparse OBJ of gigabytes of zeros was read whole; a PLY header declaring billions of vertices
//! was believed; 100 000 materials took minutes in `eval` (each material simplified over the
//! whole vertex buffer), 65 536 textures likewise (a linear texture-pyramid cache), and a row of
//! 100 000 equal triangles made the surface-distance BVH build quadratic. Messages quote at most
//! a few hundred bytes of input, text meshes stop at their first NUL byte, allocations follow
//! what the file holds, and these paths grow with the input, not its square. The runs below are
//! guarded against hangs only (`lodeval_within`); their speed is in results/BENCHMARKS.md.

use std::io::Write as _;

use super::{assert_refused, s, scratch, write};
use crate::common::lodeval_within;

/// `dir/name`: `head`, then zeros up to `len` bytes (a sparse file).
fn sparse(dir: &std::path::Path, name: &str, head: &str, len: u64) -> std::path::PathBuf {
    let p = write(dir, name, head);
    std::fs::OpenOptions::new()
        .write(true)
        .open(&p)
        .unwrap()
        .set_len(len)
        .unwrap();
    p
}

#[test]
fn sparse_and_lying_files_get_short_messages_and_no_big_allocations() {
    let tmp = scratch("r3-work-sparse");
    let d = tmp.path();
    let ply = sparse(
        d,
        "zeros.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nend_header\n",
        64 << 20,
    );
    let off = sparse(d, "zeros.off", "OFF\n3 1 0\n", 64 << 20);
    let obj = sparse(
        d,
        "zeros.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        256 << 20,
    );
    for (p, words) in [
        (&ply, vec!["zeros.ply"]),
        (&off, vec!["zeros.off", "NUL byte"]),
        (&obj, vec!["zeros.obj", "NUL byte"]),
    ] {
        let r = lodeval_within(120, ["info", s(p)]);
        assert_refused(&r, s(p), &words);
        assert!(r.stderr.len() < 4096, "{} bytes of message", r.stderr.len());
    }
    // A header declaring four billion vertices in a few bytes.
    let lie = write(
        d,
        "lie.ply",
        "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n\
         property float y\nproperty float z\nend_header\n\0\0\0\0",
    );
    let r = lodeval_within(60, ["info", s(&lie)]);
    assert_refused(&r, "lying header", &["lie.ply", "4000000000", "truncated"]);
}

/// An OBJ of `n` separate triangles in a row, each with its own material (and, with `textures`,
/// its own 2×2 texture file).
fn many_materials(dir: &std::path::Path, n: usize, textures: bool) -> std::path::PathBuf {
    let png = {
        let mut b = std::io::Cursor::new(Vec::new());
        image::DynamicImage::ImageRgb8(image::RgbImage::from_pixel(
            2,
            2,
            image::Rgb([200, 90, 40]),
        ))
        .write_to(&mut b, image::ImageFormat::Png)
        .unwrap();
        b.into_inner()
    };
    let mut mtl = std::io::BufWriter::new(std::fs::File::create(dir.join("m.mtl")).unwrap());
    let mut obj = std::io::BufWriter::new(std::fs::File::create(dir.join("m.obj")).unwrap());
    writeln!(obj, "mtllib m.mtl").unwrap();
    for i in 0..n {
        writeln!(mtl, "newmtl mat{i}\nKd {} 0.5 0.5", (i % 7) as f32 / 7.0).unwrap();
        if textures {
            std::fs::write(dir.join(format!("t{i}.png")), &png).unwrap();
            writeln!(mtl, "map_Kd t{i}.png").unwrap();
        }
        let (x, y) = ((i % 256) as f32, (i / 256) as f32);
        writeln!(
            obj,
            "v {x} {y} 0\nv {x} {} 0\nv {} {y} 1\nvt 0 0\nvt 1 0\nvt 0 1",
            y + 1.0,
            x + 0.5
        )
        .unwrap();
    }
    for i in 0..n {
        let k = 3 * i + 1;
        writeln!(
            obj,
            "usemtl mat{i}\nf {k}/{k} {}/{} {}/{}",
            k + 1,
            k + 1,
            k + 2,
            k + 2
        )
        .unwrap();
    }
    dir.join("m.obj")
}

#[test]
fn a_hundred_thousand_materials_and_65536_textures_evaluate() {
    for (n, textures) in [(100_000, false), (65_536, true)] {
        let tmp = scratch("r3-work-materials");
        let d = tmp.path();
        let mesh = many_materials(d, n, textures);
        let r = lodeval_within(120, ["info", s(&mesh)]);
        assert_eq!(r.code, 0, "{}", r.stderr);
        let cfg = super::config(d, "c.toml", &mesh, "out", "");
        let r = lodeval_within(120, ["eval", s(&cfg), "-q"]);
        assert_eq!(r.code, 0, "{n} materials: {}", r.stderr);
        let lods = std::fs::read_to_string(d.join("out/lods.csv")).unwrap();
        assert_eq!(lods.lines().count(), 3, "{lods}");
    }
}

#[test]
fn a_row_of_equal_triangles_measures_its_distance() {
    // 100 000 copies of one triangle in a row: every BVH merge cost ties.
    let tmp = scratch("r3-work-row");
    let d = tmp.path();
    let mut text = String::new();
    for i in 0..100_000 {
        let x = i as f32;
        text.push_str(&format!("v {x} 0 0\nv {x} 1 0\nv {} 0 1\n", x + 0.5));
    }
    for i in 0..100_000 {
        let k = 3 * i + 1;
        text.push_str(&format!("f {k} {} {}\n", k + 1, k + 2));
    }
    let mesh = write(d, "row.obj", &text);
    let r = lodeval_within(120, ["geometry", s(&mesh), s(&mesh), "--samples", "10000"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(r.stdout.contains("hausdorff"), "{}", r.stdout);
}
