//! The paper reproductions: each paper's own evaluation rebuilt with lodeval's renderer, metrics
//! and batch evaluator, one file per paper. They sit above `eval` (they score with its `Scorer`)
//! and below the commands that run them (`simplify --experiment`, `optimize --experiment`).
//!
//! - `williams2003.rs` — Williams et al. 2003 §6, Figure 4: four error criteria on the same
//!   Multi-Triangulation at the same budgets, scored with FLIP and the VDP.
//! - `lindstrom_turk.rs` — Lindstrom & Turk §6, Figures 5–6: clustering, QEM and meshoptimizer
//!   inputs, each optimized, energies on held-out views.

pub mod lindstrom_turk;
pub mod williams2003;
