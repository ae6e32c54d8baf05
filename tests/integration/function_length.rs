//! House rule: a function reads as its outline — at most [`LIMIT`] lines, from its signature to
//! its closing brace, in the library and the binary (`src/`), test code aside. Measured by parsing
//! every file with `syn`, so a brace in a string or a comment cannot move a count. (The 26
//! functions that were longer when the rule came in were split into named steps on 2026-12-07;
//! there is no list of exceptions.)

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use syn::spanned::Spanned;
use syn::visit::Visit;

use crate::common::root;

/// The most lines a function may have.
const LIMIT: usize = 120;

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
    let bad: Vec<String> = found
        .iter()
        .map(|((file, name), lines)| {
            format!(
                "{file}: fn {name} has {lines} lines (at most {LIMIT}): split it into named steps"
            )
        })
        .collect();
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
