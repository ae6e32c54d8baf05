//! The layer test. Every library file is parsed as Rust (`syn`), so what the compiler sees is what
//! the test sees: grouped imports (`use crate::{a, eval::X}`), the crate root or a module under
//! another name (`use crate as x`, `use super::super as up`), paths inside macros (`$crate::…`,
//! `crate::…` in a macro's arguments), `//` inside a string, and code after a test module. Each
//! path is resolved to a module path from the crate root (through `crate`, `$crate`, `super`,
//! `self`, a file's aliases, and one level of `pub use` re-exports), and gives two kinds of edge:
//! between top-level modules (checked against [`LAYERS`]) and between sibling modules under one
//! parent (which must not form a cycle). Items under `#[cfg(test)]` and `tests.rs` files are not
//! checked: tests may reach anywhere.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use proc_macro2::{TokenStream, TokenTree};
use syn::visit::Visit;

use super::LAYERS;

/// A module path from the crate root, e.g. `["eval", "run"]`.
type ModPath = Vec<String>;

/// One use of a path: the file, its line, the module it was written in and where it points.
#[derive(Debug, Clone)]
struct Edge {
    file: PathBuf,
    line: usize,
    from: ModPath,
    to: ModPath,
}

/// A parsed library file and the module it defines.
struct Source {
    rel: PathBuf,
    module: ModPath,
    syntax: syn::File,
}

fn layer(module: &str) -> Option<(u8, usize)> {
    LAYERS
        .iter()
        .position(|(m, _)| *m == module)
        .map(|i| (LAYERS[i].1, i))
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The library's files under `src` (not the binary's `main.rs` and `cli/`, not `tests.rs`),
/// parsed, with their module paths (`lib.rs` → the root, `a/mod.rs` → `a`, `a/b.rs` → `a::b`).
fn sources(src: &Path) -> Vec<Source> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    files.sort();
    files
        .into_iter()
        .filter_map(|f| {
            let rel = f.strip_prefix(src).unwrap().to_path_buf();
            let mut module: ModPath = rel
                .with_extension("")
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            if matches!(module.last().map(String::as_str), Some("mod" | "lib")) {
                module.pop();
            }
            let skip = matches!(module.first().map(String::as_str), Some("main" | "cli"))
                || rel.ends_with("tests.rs");
            let text = std::fs::read_to_string(&f).unwrap();
            let syntax = syn::parse_file(&text)
                .unwrap_or_else(|e| panic!("{}: not Rust the test can parse: {e}", rel.display()));
            (!skip).then_some(Source {
                rel,
                module,
                syntax,
            })
        })
        .collect()
}

fn is_cfg_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.parse_args::<TokenStream>().is_ok_and(|t| {
                t.into_iter()
                    .any(|t| matches!(t, TokenTree::Ident(i) if i == "test"))
            })
    })
}

fn item_attrs(item: &syn::Item) -> &[syn::Attribute] {
    use syn::Item::*;
    match item {
        Const(i) => &i.attrs,
        Enum(i) => &i.attrs,
        ExternCrate(i) => &i.attrs,
        Fn(i) => &i.attrs,
        ForeignMod(i) => &i.attrs,
        Impl(i) => &i.attrs,
        Macro(i) => &i.attrs,
        Mod(i) => &i.attrs,
        Static(i) => &i.attrs,
        Struct(i) => &i.attrs,
        Trait(i) => &i.attrs,
        TraitAlias(i) => &i.attrs,
        Type(i) => &i.attrs,
        Union(i) => &i.attrs,
        Use(i) => &i.attrs,
        _ => &[],
    }
}

/// Paths written in one file, as segments, before resolution.
#[derive(Default)]
struct Collector {
    /// The module the visitor is in (the file's, plus inline `mod x { … }` blocks).
    module: ModPath,
    /// (line, module written in, segments).
    paths: Vec<(usize, ModPath, Vec<String>)>,
    /// `use … as NAME` and `use …::NAME` of this file: name → segments (in the module written).
    aliases: BTreeMap<String, (ModPath, Vec<String>)>,
    /// `pub use` items: (module, exported name, segments).
    exports: Vec<(ModPath, String, Vec<String>)>,
}

impl Collector {
    fn use_tree(&mut self, tree: &syn::UseTree, prefix: &mut Vec<String>, public: bool) {
        let line = |i: &syn::Ident| i.span().start().line;
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(&p.tree, prefix, public);
                prefix.pop();
            }
            syn::UseTree::Name(n) => {
                self.use_leaf(line(&n.ident), prefix, &n.ident, &n.ident, public)
            }
            syn::UseTree::Rename(r) => {
                self.use_leaf(line(&r.ident), prefix, &r.ident, &r.rename, public)
            }
            syn::UseTree::Glob(g) => self.paths.push((
                g.star_token.span.start().line,
                self.module.clone(),
                prefix.clone(),
            )),
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.use_tree(t, prefix, public);
                }
            }
        }
    }

    fn use_leaf(
        &mut self,
        line: usize,
        prefix: &[String],
        ident: &syn::Ident,
        name: &syn::Ident,
        public: bool,
    ) {
        let mut full = prefix.to_vec();
        if ident != "self" {
            full.push(ident.to_string());
        }
        self.paths.push((line, self.module.clone(), full.clone()));
        if name != "_" {
            self.aliases
                .insert(name.to_string(), (self.module.clone(), full.clone()));
            if public {
                self.exports
                    .push((self.module.clone(), name.to_string(), full));
            }
        }
    }

    /// `crate ::`, `$ crate ::`, `super ::` and `self ::` sequences in a macro's tokens.
    fn tokens(&mut self, tokens: TokenStream) {
        let trees: Vec<TokenTree> = tokens.into_iter().collect();
        let mut i = 0;
        while i < trees.len() {
            if let TokenTree::Group(g) = &trees[i] {
                self.tokens(g.stream());
                i += 1;
                continue;
            }
            let dollar = matches!(&trees[i], TokenTree::Punct(p) if p.as_char() == '$');
            let start = i + usize::from(dollar);
            let head = match trees.get(start) {
                Some(TokenTree::Ident(id))
                    if id == "crate" || (!dollar && (id == "super" || id == "self")) =>
                {
                    id
                }
                _ => {
                    i += 1;
                    continue;
                }
            };
            let line = head.span().start().line;
            let mut segments = vec![head.to_string()];
            let mut j = start + 1;
            // `::` is two `:` puncts, then an identifier.
            while let (
                Some(TokenTree::Punct(a)),
                Some(TokenTree::Punct(b)),
                Some(TokenTree::Ident(id)),
            ) = (trees.get(j), trees.get(j + 1), trees.get(j + 2))
            {
                if a.as_char() != ':' || b.as_char() != ':' {
                    break;
                }
                segments.push(id.to_string());
                j += 3;
            }
            if segments.len() > 1 {
                self.paths.push((line, self.module.clone(), segments));
            }
            i = j.max(i + 1);
        }
    }
}

impl<'ast> Visit<'ast> for Collector {
    fn visit_item(&mut self, item: &'ast syn::Item) {
        if !is_cfg_test(item_attrs(item)) {
            syn::visit::visit_item(self, item);
        }
    }

    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if m.content.is_some() {
            self.module.push(m.ident.to_string());
            syn::visit::visit_item_mod(self, m);
            self.module.pop();
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        let public = matches!(
            u.vis,
            syn::Visibility::Public(_) | syn::Visibility::Restricted(_)
        );
        self.use_tree(&u.tree, &mut Vec::new(), public);
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        let segments: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
        let line = p
            .segments
            .first()
            .map_or(0, |s| s.ident.span().start().line);
        self.paths.push((line, self.module.clone(), segments));
        syn::visit::visit_path(self, p);
    }

    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        self.visit_path(&m.path);
        self.tokens(m.tokens.clone());
    }
}

/// What a file's paths resolve against: the library's modules and the file's aliases.
struct Scope<'a> {
    modules: &'a BTreeSet<ModPath>,
    aliases: &'a BTreeMap<String, (ModPath, Vec<String>)>,
}

/// `segments` written in `module` as a module path from the root, or `None` when it does not
/// start at `crate`, `$crate`, `super`, `self`, a child module or one of the file's aliases (an
/// external crate, a local name).
fn resolve(scope: &Scope, module: &[String], segments: &[String], depth: usize) -> Option<ModPath> {
    let (head, rest) = segments.split_first()?;
    let mut base: ModPath = match head.as_str() {
        "crate" | "$crate" => Vec::new(),
        "self" => module.to_vec(),
        "super" => {
            let mut b = module.to_vec();
            b.pop()?;
            let mut rest = rest;
            while rest.first().is_some_and(|s| s == "super") {
                b.pop()?;
                rest = &rest[1..];
            }
            b.extend(rest.iter().cloned());
            return Some(b);
        }
        name => {
            let mut child = module.to_vec();
            child.push(name.to_string());
            if scope.modules.contains(&child) {
                child
            } else {
                let (m, target) = scope.aliases.get(name)?;
                if depth > 4 || target.first().is_some_and(|t| t == name) {
                    return None;
                }
                resolve(scope, m, target, depth + 1)?
            }
        }
    };
    base.extend(rest.iter().cloned());
    Some(base)
}

/// Every resolved edge of the library under `src`, and the set of its modules.
fn edges(src: &Path) -> (Vec<Edge>, BTreeSet<ModPath>) {
    let sources = sources(src);
    let modules: BTreeSet<ModPath> = sources.iter().map(|s| s.module.clone()).collect();
    let mut collected = Vec::new();
    let mut exports: BTreeMap<(ModPath, String), ModPath> = BTreeMap::new();
    for s in &sources {
        let mut c = Collector {
            module: s.module.clone(),
            ..Collector::default()
        };
        c.visit_file(&s.syntax);
        let scope = Scope {
            modules: &modules,
            aliases: &c.aliases,
        };
        for (m, name, target) in &c.exports {
            if let Some(to) = resolve(&scope, m, target, 0) {
                exports.insert((m.clone(), name.clone()), to);
            }
        }
        collected.push((s.rel.clone(), c));
    }
    let mut out = Vec::new();
    for (rel, c) in collected {
        let scope = Scope {
            modules: &modules,
            aliases: &c.aliases,
        };
        for (line, module, segments) in &c.paths {
            let Some(mut to) = resolve(&scope, module, segments, 0) else {
                continue;
            };
            // One level of `pub use` re-export: `crate::Error` is `crate::error::Error`.
            if let Some(k) =
                (0..to.len()).find(|&k| exports.contains_key(&(to[..k].to_vec(), to[k].clone())))
            {
                let mut via = exports[&(to[..k].to_vec(), to[k].clone())].clone();
                via.extend(to[k + 1..].iter().cloned());
                to = via;
            }
            out.push(Edge {
                file: rel.clone(),
                line: *line,
                from: module.clone(),
                to,
            });
        }
    }
    (out, modules)
}

/// Layer violations, as messages naming file and line.
fn layer_violations(edges: &[Edge]) -> Vec<String> {
    let mut bad = BTreeSet::new();
    for e in edges {
        let (Some(from), Some(to)) = (e.from.first(), e.to.first()) else {
            continue;
        };
        if from == to {
            continue;
        }
        let at = format!("{}:{}", e.file.display(), e.line);
        let Some((from_layer, from_rank)) = layer(from) else {
            bad.insert(format!("{at}: module `{from}` is not in the layer table"));
            continue;
        };
        match layer(to) {
            // A name at the root that is not a module: a function or type of lib.rs.
            None if e.to.len() == 1 => {}
            None => {
                bad.insert(format!("{at}: `crate::{to}` is not in the layer table"));
            }
            Some((to_layer, to_rank)) => {
                let ok = to_layer < from_layer
                    || (to_layer == 0 && from_layer == 0 && to_rank < from_rank);
                if !ok {
                    bad.insert(format!(
                        "{at}: `{from}` (layer {from_layer}) uses `crate::{to}` (layer {to_layer}): dependencies must point down"
                    ));
                }
            }
        }
    }
    bad.into_iter().collect()
}

/// Cycles between sibling modules (`a::b` → `a::c` → `a::b`), one message per cycle.
fn sibling_cycles(edges: &[Edge], modules: &BTreeSet<ModPath>) -> Vec<String> {
    // Sibling edge: from P and to A share a parent P[..c] and differ at c; both are modules.
    let mut graph: BTreeMap<ModPath, BTreeMap<ModPath, String>> = BTreeMap::new();
    for e in edges {
        let c = e.from.iter().zip(&e.to).take_while(|(a, b)| a == b).count();
        if c == 0 || c >= e.from.len() || c >= e.to.len() {
            continue;
        }
        let (a, b) = (e.from[..=c].to_vec(), e.to[..=c].to_vec());
        if modules.contains(&b) {
            graph
                .entry(a)
                .or_default()
                .entry(b)
                .or_insert_with(|| format!("{}:{}", e.file.display(), e.line));
        }
    }
    let mut cycles = BTreeSet::new();
    for start in graph.keys() {
        // Depth-first from `start`; a path back to `start` is a cycle.
        let mut stack = vec![(start.clone(), vec![start.clone()])];
        let mut seen = BTreeSet::new();
        while let Some((node, path)) = stack.pop() {
            for (next, _) in graph.get(&node).into_iter().flatten() {
                if next == start {
                    let mut names: Vec<String> = path.iter().map(|m| m.join("::")).collect();
                    let at: Vec<&str> = path
                        .iter()
                        .zip(path.iter().skip(1).chain([start]))
                        .map(|(x, y)| graph[x][y].as_str())
                        .collect();
                    // One message per cycle, whichever member the search started from.
                    let key: BTreeSet<String> = names.iter().cloned().collect();
                    names.push(start.join("::"));
                    if cycles
                        .iter()
                        .all(|(k, _): &(BTreeSet<String>, String)| *k != key)
                    {
                        cycles.insert((
                            key,
                            format!("sibling cycle {} (at {})", names.join(" → "), at.join(", ")),
                        ));
                    }
                } else if seen.insert(next.clone()) {
                    let mut p = path.clone();
                    p.push(next.clone());
                    stack.push((next.clone(), p));
                }
            }
        }
    }
    cycles.into_iter().map(|(_, m)| m).collect()
}

fn violations(src: &Path) -> Vec<String> {
    let (edges, modules) = edges(src);
    let mut bad = layer_violations(&edges);
    bad.extend(sibling_cycles(&edges, &modules));
    bad
}

#[test]
fn dependencies_point_down_the_layers_and_siblings_do_not_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let bad = violations(&src);
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// A crafted tree: `files` (path, text) under a fresh folder; its violations.
fn crafted(files: &[(&str, &str)]) -> Vec<String> {
    let dir = tempfile::tempdir().unwrap();
    for (p, text) in files {
        let p = dir.path().join(p);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }
    violations(dir.path())
}

#[test]
fn every_way_of_naming_a_higher_layer_is_caught_with_its_file_and_line() {
    // mesh is layer 1, eval layer 7. Each file hides an upward edge a line-by-line text search
    // missed or mis-read; the message must name the file and the line of the path.
    let up = |f: &str, line: usize| {
        format!("mesh/{f}:{line}: `mesh` (layer 1) uses `crate::eval` (layer 7)")
    };
    let cases: &[(&str, &str, usize)] = &[
        (
            "grouped.rs",
            "//! Grouped.\n\nuse crate::{error::Error, eval::Plan};\n",
            3,
        ),
        (
            "root_alias.rs",
            "use crate as x;\n\nfn f() {\n    let _ = x::eval::stem;\n}\n",
            4,
        ),
        (
            "super_alias.rs",
            "use super::super as up;\n\nfn f() {\n    let _ = up::eval::stem;\n}\n",
            4,
        ),
        (
            "in_macro.rs",
            "macro_rules! m {\n    () => {\n        $crate::eval::stem()\n    };\n}\n",
            3,
        ),
        (
            "in_string.rs",
            "const U: &str = \"http://x\"; fn f(_: crate::eval::Plan) {}\n",
            1,
        ),
        (
            "after_tests.rs",
            "#[cfg(test)]\nmod tests {}\n\nuse crate::eval::Plan;\n",
            4,
        ),
        (
            "in_format.rs",
            "fn f() {\n    println!(\"{}\", crate::eval::stem());\n}\n",
            2,
        ),
    ];
    for (file, text, line) in cases {
        let bad = crafted(&[(&format!("mesh/{file}"), text)]);
        let want = up(file, *line);
        assert!(
            bad.iter().any(|b| b.starts_with(&want)),
            "{file}: want {want}, got {bad:?}"
        );
    }
    // What may say anything: comments, strings, doc text and test code.
    let fine = crafted(&[(
        "mesh/fine.rs",
        "//! crate::eval in a doc comment\n// crate::eval in a comment\nconst S: &str = \"crate::eval::x\";\n#[cfg(test)]\nmod tests {\n    use crate::eval::Plan;\n}\n",
    )]);
    assert!(fine.is_empty(), "{fine:?}");
}

#[test]
fn a_cycle_between_sibling_files_is_caught() {
    let bad = crafted(&[
        ("mesh/a.rs", "use super::b::Y;\npub struct X;\n"),
        (
            "mesh/b.rs",
            "pub struct Y;\nfn f(_: crate::mesh::a::X) {}\n",
        ),
        ("mesh/c.rs", "use super::a::X;\n"),
    ]);
    assert_eq!(bad.len(), 1, "{bad:?}");
    assert!(
        bad[0]
            .starts_with("sibling cycle mesh::a → mesh::b → mesh::a (at mesh/a.rs:1, mesh/b.rs:2)"),
        "{}",
        bad[0]
    );
}
