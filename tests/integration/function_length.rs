//! House rule: a function reads as its outline — at most [`LIMIT`] lines, from its signature to
//! its closing brace, in the library and the binary (`src/`), test code aside. Measured by parsing
//! every file with `syn`, so a brace in a string or a comment cannot move a count. The functions
//! that were longer when the rule was written are listed in [`OVER`] with their length then; each
//! may only shrink, must leave the list once it is within the limit, and nothing new may join.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use syn::spanned::Spanned;
use syn::visit::Visit;

use crate::common::root;

/// The most lines a function may have.
const LIMIT: usize = 120;

/// Functions over the limit when the rule came in (2026-12-07): (file, function, lines then).
/// Splitting one into named steps takes it off this list.
const OVER: &[(&str, &str, usize)] = &[
    ("src/cli/bench.rs", "run", 172),
    ("src/cli/diff.rs", "run", 166),
    ("src/cli/simplify.rs", "run", 137),
    ("src/eval/mod.rs", "merge", 131),
    ("src/eval/plots.rs", "write", 127),
    ("src/experiments/lindstrom_turk.rs", "run", 126),
    ("src/experiments/qu_meyer.rs", "run", 140),
    ("src/experiments/williams2003.rs", "run", 157),
    ("src/gpu/render.rs", "upload", 166),
    ("src/io/plot_png.rs", "render", 176),
    ("src/mesh/gltf/mod.rs", "add_mesh", 144),
    ("src/mesh/mtl.rs", "material", 121),
    ("src/mesh/obj.rs", "scan", 143),
    ("src/mesh/off.rs", "load", 138),
    ("src/mesh/write_gltf.rs", "write_lod_chain", 141),
    ("src/raster/incremental/trial.rs", "prepare", 121),
    ("src/raster/incremental/trial.rs", "render", 241),
    ("src/raster/incremental/views.rs", "new", 131),
    ("src/raster/texture_space.rs", "texture_space", 142),
    ("src/simplify/attributes.rs", "reduced", 122),
    ("src/simplify/lindstrom_turk/simplex.rs", "minimize", 125),
    ("src/simplify/menzel_guthe/perception.rs", "compare", 173),
    ("src/simplify/qem.rs", "run", 133),
    ("src/simplify/qu_meyer/charts.rs", "of", 162),
    ("src/simplify/qu_meyer/mod.rs", "remesh", 148),
    ("src/simplify/qu_meyer/triangulate.rs", "triangulate", 155),
];

/// (file, function) → lines, for every function of `src/` over `limit` lines outside test code.
fn long_functions(src: &Path, limit: usize) -> BTreeMap<(String, String), usize> {
    struct Lengths<'a> {
        file: &'a str,
        limit: usize,
        out: &'a mut BTreeMap<(String, String), usize>,
    }
    impl Lengths<'_> {
        fn record(&mut self, sig: &syn::Signature, body: &syn::Block) {
            let (name, span) = (&sig.ident, sig.span());
            let lines = body.span().end().line - span.start().line + 1;
            if lines > self.limit {
                self.out
                    .insert((self.file.to_string(), name.to_string()), lines);
            }
        }
    }
    fn is_test(attrs: &[syn::Attribute]) -> bool {
        attrs.iter().any(|a| {
            (a.path().is_ident("cfg") && a.parse_args::<syn::Ident>().is_ok_and(|i| i == "test"))
                || a.path().is_ident("test")
        })
    }
    impl<'ast> Visit<'ast> for Lengths<'_> {
        fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
            if !is_test(&m.attrs) {
                syn::visit::visit_item_mod(self, m);
            }
        }
        fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
            if !is_test(&f.attrs) {
                self.record(&f.sig, &f.block);
                syn::visit::visit_item_fn(self, f);
            }
        }
        fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
            if !is_test(&f.attrs) {
                self.record(&f.sig, &f.block);
                syn::visit::visit_impl_item_fn(self, f);
            }
        }
        fn visit_trait_item_fn(&mut self, f: &'ast syn::TraitItemFn) {
            if let Some(body) = &f.default {
                self.record(&f.sig, body);
            }
            syn::visit::visit_trait_item_fn(self, f);
        }
    }
    fn files(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                files(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") && !p.ends_with("tests.rs") {
                out.push(p);
            }
        }
    }
    let mut paths = Vec::new();
    files(src, &mut paths);
    let mut out = BTreeMap::new();
    for p in paths {
        let rel = p.strip_prefix(src.parent().unwrap()).unwrap();
        let file = rel.to_string_lossy().replace('\\', "/");
        let text = std::fs::read_to_string(&p).unwrap();
        let syntax = syn::parse_file(&text).unwrap_or_else(|e| panic!("{file}: {e}"));
        Lengths {
            file: &file,
            limit,
            out: &mut out,
        }
        .visit_file(&syntax);
    }
    out
}

#[test]
fn functions_read_as_their_outline() {
    let found = long_functions(&root().join("src"), LIMIT);
    let mut bad = Vec::new();
    for ((file, name), &lines) in &found {
        match OVER.iter().find(|(f, n, _)| f == file && n == name) {
            None => bad.push(format!(
                "{file}: fn {name} has {lines} lines (at most {LIMIT}): split it into named steps"
            )),
            Some(&(_, _, then)) if lines > then => bad.push(format!(
                "{file}: fn {name} grew from {then} to {lines} lines: it may only shrink"
            )),
            Some(_) => {}
        }
    }
    for (file, name, _) in OVER {
        if !found.contains_key(&(file.to_string(), name.to_string())) {
            bad.push(format!(
                "{file}: fn {name} is within {LIMIT} lines now (or gone): take it off OVER"
            ));
        }
    }
    eprintln!("{} functions over {LIMIT} lines in src/", found.len());
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

#[test]
fn the_measure_counts_lines_of_code_not_braces_in_strings() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    std::fs::create_dir_all(&src).unwrap();
    let body = "    let _ = \"}}}\";\n".repeat(5);
    std::fs::write(
        src.join("a.rs"),
        format!("fn short() {{\n{body}}}\n\nimpl A {{\n    fn long(&self) {{\n{body}{body}    }}\n}}\n\n#[cfg(test)]\nmod tests {{\n    fn hidden() {{\n{body}{body}    }}\n}}\n"),
    )
    .unwrap();
    let found = long_functions(&src, 8);
    assert_eq!(
        found.into_iter().collect::<Vec<_>>(),
        vec![(("src/a.rs".to_string(), "long".to_string()), 12)]
    );
}
