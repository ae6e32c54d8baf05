//! The crate's layers, and the test that keeps dependencies pointing down.
//!
//! Each top-level module sits on a layer and may use modules of lower layers only; the bottom
//! layer's modules may use the ones listed before them. The binary (`main.rs`, `cli/`) sits on
//! top of everything and is not checked. Within a module, sibling files may use each other in one
//! direction only: no cycle between siblings (`eval/a.rs` → `eval/b.rs` → `eval/a.rs`). The test
//! (`layers/tests.rs`) parses every library file as Rust and resolves every path it names.

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

#[cfg(test)]
mod tests;
