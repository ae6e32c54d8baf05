//! Simplifiers: each algorithm in its own file. Today: the industrial baseline (meshoptimizer,
//! `meshopt.rs`) that `eval`'s LOD generator calls. The edge-collapse engine (QEM, clustering) and
//! the paper algorithms (Williams et al., Menzel–Guthe, Lindstrom–Turk, Qu–Meyer) join here.

pub mod meshopt;
