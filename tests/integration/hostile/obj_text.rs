//! OBJ text that used to load with exit 0 and a silently wrong mesh: a byte-order mark glued to
//! the first record (a vertex or the `mtllib` line dropped, so the mesh was scored untextured),
//! and `usemtl` naming a material no library defines (the default material, quietly). And the
//! reverse: a Latin-1 byte in a comment, which real exporters write, rejected the whole file.

use super::{assert_refused, scratch};
use crate::common::lodeval;

const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";

fn info_json(path: &std::path::Path) -> (i32, String, String) {
    let r = lodeval(["info".as_ref(), path.as_os_str(), "--json".as_ref()]);
    (r.code, r.stdout, r.stderr)
}

#[test]
fn a_byte_order_mark_does_not_drop_the_first_line() {
    let tmp = scratch("bom");
    let d = tmp.path();
    // The first record is a vertex: without it the face refers to a vertex that does not exist.
    let text = format!("\u{feff}{QUAD}f 1/1 2/2 3/3 4/4\n");
    std::fs::write(d.join("bom.obj"), text).unwrap();
    let (code, out, err) = info_json(&d.join("bom.obj"));
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\"vertices\": 4"), "{out}");
    // The first record is the mtllib line: the texture must still be found and used.
    std::fs::write(d.join("m.mtl"), "newmtl red\nKd 1 0 0\n").unwrap();
    let text = format!("\u{feff}mtllib m.mtl\n{QUAD}usemtl red\nf 1/1 2/2 3/3 4/4\n");
    std::fs::write(d.join("bom-mtl.obj"), text).unwrap();
    let (code, out, err) = info_json(&d.join("bom-mtl.obj"));
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("red"), "the material was dropped: {out}");
}

#[test]
fn usemtl_of_an_undefined_material_is_a_missing_asset() {
    let tmp = scratch("usemtl");
    let d = tmp.path();
    std::fs::write(d.join("m.mtl"), "newmtl red\nKd 1 0 0\n").unwrap();
    std::fs::write(d.join("empty.mtl"), "").unwrap();
    let cases = [
        ("typo.obj", "mtllib m.mtl\n", "usemtl blue\n", "'blue'"),
        ("nolib.obj", "", "usemtl red\n", "no mtllib line"),
        (
            "empty.obj",
            "mtllib empty.mtl\n",
            "usemtl red\n",
            "empty.mtl",
        ),
        ("self.obj", "mtllib self.obj\n", "usemtl red\n", "self.obj"),
    ];
    for (name, lib, usemtl, word) in cases {
        let p = d.join(name);
        std::fs::write(&p, format!("{lib}{QUAD}{usemtl}f 1/1 2/2 3/3 4/4\n")).unwrap();
        let r = lodeval(["info".as_ref(), p.as_os_str()]);
        assert_refused(&r, name, &[name, "usemtl", word]);
        // The documented escape hatch loads it with the default material and says so.
        let r = lodeval([
            "info".as_ref(),
            p.as_os_str(),
            "--missing-assets".as_ref(),
            "warn".as_ref(),
        ]);
        assert_eq!(r.code, 0, "{name}: {}", r.stderr);
        assert!(
            r.stdout.contains("warning:") && r.stdout.contains("usemtl"),
            "{name}: {}",
            r.stdout
        );
    }
}

#[test]
fn latin1_in_comments_and_names_is_accepted_and_elsewhere_refused() {
    let tmp = scratch("latin1");
    let d = tmp.path();
    let mut bytes = b"# Export\xe9 par Mod\xe8leur\ng Teil_\xfc\n".to_vec();
    bytes.extend_from_slice(format!("{QUAD}f 1/1 2/2 3/3 4/4\n").as_bytes());
    std::fs::write(d.join("latin1.obj"), &bytes).unwrap();
    let (code, out, err) = info_json(&d.join("latin1.obj"));
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\"triangles\": 2"), "{out}");
    let mut bad = QUAD.to_string().into_bytes();
    bad.extend_from_slice(b"f 1/1 2/2 3/3 4\xe9\n");
    std::fs::write(d.join("bad.obj"), &bad).unwrap();
    let r = lodeval(["info".as_ref(), d.join("bad.obj").as_os_str()]);
    assert_refused(&r, "bad.obj", &["bad.obj", "line 9", "not text"]);
}
