//! The crate's layers, and the test that keeps dependencies pointing down.
//!
//! Each top-level module sits on a layer and may use modules of lower layers only; the bottom
//! layer's modules may use the ones listed before them. The binary (`main.rs`, `cli/`) sits on
//! top of everything and is not checked. The test reads every library source file, drops test
//! code (`tests.rs` files and `#[cfg(test)] mod tests { … }` blocks) and comments, takes each
//! `crate::NAME` path and fails on an edge that points up or sideways, naming the file and line.

/// (module, layer), bottom first; within layer 0 in the order they may use each other.
pub(crate) const LAYERS: &[(&str, u8)] = &[
    ("error", 0),
    ("cpu", 0),
    ("prefetch", 0),
    ("progress", 0),
    ("limits", 0),
    ("io", 0),
    ("color", 0),
    ("image", 0),
    ("mesh", 1),
    ("scene", 2),
    ("raster", 3),
    ("metric", 3),
    ("gpu", 4),
    ("backend", 5),
    ("simplify", 6),
    ("eval", 7),
    ("experiments", 8),
    ("app", 9),
    ("layers", 10),
];

/// Root re-exports (`crate::Error` and the like) and the module that owns them.
const ROOT_NAMES: &[(&str, &str)] = &[
    ("Error", "error"),
    ("Location", "error"),
    ("Result", "error"),
    ("LoadOptions", "mesh"),
    ("Mesh", "mesh"),
    ("MeshSummary", "mesh"),
    ("MissingAssets", "mesh"),
];

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    use super::*;

    fn layer(module: &str) -> Option<(u8, usize)> {
        LAYERS
            .iter()
            .position(|(m, _)| *m == module)
            .map(|i| (LAYERS[i].1, i))
    }

    /// Every `.rs` file under `dir`.
    fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                sources(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }

    /// The non-test code of a file, line by line (test modules and comments blanked).
    fn code_lines(text: &str) -> Vec<String> {
        let cut = text.find("#[cfg(test)]\nmod tests {").unwrap_or(text.len());
        text[..cut]
            .lines()
            .map(|l| match l.find("//") {
                Some(i) => l[..i].to_string(),
                None => l.to_string(),
            })
            .collect()
    }

    /// (line, target module) for each `crate::NAME` of a file, and each `super::…::NAME` whose
    /// chain of `super` climbs to the crate root (`depth`: how many modules deep the file is).
    fn edges(text: &str, depth: usize) -> Vec<(usize, String)> {
        let mut out = Vec::new();
        for (i, line) in code_lines(text).iter().enumerate() {
            let mut rest = line.as_str();
            while let Some(k) = rest.find("super::") {
                let before = rest[..k].chars().last();
                let mut tail = &rest[k..];
                let mut climbs = 0;
                while let Some(t) = tail.strip_prefix("super::") {
                    climbs += 1;
                    tail = t;
                }
                let name: String = tail
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                let escapes = !before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':');
                if escapes && climbs >= depth && !name.is_empty() {
                    out.push((i + 1, name.clone()));
                }
                rest = &tail[name.len()..];
            }
            let mut rest = line.as_str();
            while let Some(k) = rest.find("crate::") {
                let tail = &rest[k + "crate::".len()..];
                let name: String = tail
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                let before = rest[..k].chars().last();
                // `lodeval::crate` does not exist; skip `$crate` and identifiers ending in crate.
                if !name.is_empty() && !before.is_some_and(|c| c.is_alphanumeric() || c == '$') {
                    let module = ROOT_NAMES
                        .iter()
                        .find(|(n, _)| *n == name)
                        .map_or(name.clone(), |(_, m)| m.to_string());
                    out.push((i + 1, module));
                }
                rest = &tail[name.len()..];
            }
        }
        out
    }

    /// Upward or sideways edges of the library's files under `src`, as messages.
    fn violations(src: &Path) -> Vec<String> {
        let mut files = Vec::new();
        sources(src, &mut files);
        files.sort();
        let mut bad = Vec::new();
        for f in files {
            let rel = f.strip_prefix(src).unwrap();
            let top = rel
                .components()
                .next()
                .unwrap()
                .as_os_str()
                .to_string_lossy()
                .trim_end_matches(".rs")
                .to_string();
            if top == "main" || top == "cli" || top == "lib" || rel.ends_with("tests.rs") {
                continue;
            }
            let Some((from_layer, from_rank)) = layer(&top) else {
                bad.push(format!(
                    "{}: module `{top}` is not in the layer table",
                    rel.display()
                ));
                continue;
            };
            let text = std::fs::read_to_string(&f).unwrap();
            let parts = rel.components().count();
            let depth = if rel.ends_with("mod.rs") {
                parts - 1
            } else {
                parts
            };
            for (line, target) in edges(&text, depth) {
                if target == top {
                    continue;
                }
                match layer(&target) {
                    None => bad.push(format!(
                        "{}:{line}: `crate::{target}` is not in the layer table",
                        rel.display()
                    )),
                    Some((to_layer, to_rank)) => {
                        let ok = to_layer < from_layer
                            || (to_layer == 0 && from_layer == 0 && to_rank < from_rank);
                        if !ok {
                            bad.push(format!(
                                "{}:{line}: `{top}` (layer {from_layer}) uses `crate::{target}` (layer {to_layer}): dependencies must point down",
                                rel.display()
                            ));
                        }
                    }
                }
            }
        }
        bad
    }

    #[test]
    fn dependencies_point_down_the_layers() {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let bad = violations(&src);
        assert!(bad.is_empty(), "{}", bad.join("\n"));
    }

    #[test]
    fn an_upward_import_is_caught_with_its_file_and_line() {
        // A copy of the tree with one upward edge added: mesh (layer 1) using eval (layer 7).
        let dir = std::env::temp_dir().join(format!("lodeval-layers-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("mesh")).unwrap();
        std::fs::write(
            dir.join("mesh/bad.rs"),
            "//! A file with an upward edge.\n\nuse crate::eval::Plan;\n",
        )
        .unwrap();
        // Test code and comments may say anything.
        std::fs::write(
            dir.join("mesh/fine.rs"),
            "// crate::eval in a comment\n#[cfg(test)]\nmod tests {\n    use crate::eval::Plan;\n}\n",
        )
        .unwrap();
        // A `super::super::` chain that climbs to the root and back down into a higher layer.
        std::fs::write(
            dir.join("mesh/sneaky.rs"),
            "//! Relative paths count too.\n\nfn f() {\n    let _ = super::super::eval::config::stem;\n    let _ = super::load;\n}\n",
        )
        .unwrap();
        let bad = violations(&dir);
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(bad.len(), 2, "{bad:?}");
        assert!(
            bad[1].starts_with("mesh/sneaky.rs:4: `mesh` (layer 1) uses `crate::eval` (layer 7)"),
            "{}",
            bad[1]
        );
        assert!(
            bad[0].starts_with("mesh/bad.rs:3: `mesh` (layer 1) uses `crate::eval` (layer 7)"),
            "{}",
            bad[0]
        );
    }
}
