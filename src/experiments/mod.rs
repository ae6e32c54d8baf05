//! The paper reproductions: each paper's own evaluation rebuilt with lodeval's renderer, metrics
//! and batch evaluator, one file per paper. They sit above `eval` (they score with its `Scorer`)
//! and below the commands that run them (`simplify --experiment`, `optimize --experiment`).
//!
//! - `williams2003.rs` — Williams et al. 2003 §6, Figure 4: four error criteria on the same
//!   Multi-Triangulation at the same budgets, scored with FLIP and the VDP.
//! - `lindstrom_turk.rs` — Lindstrom & Turk §6, Figures 5–6: clustering, QEM and meshoptimizer
//!   inputs, each optimized, energies on held-out views.
//! - `menzel_guthe2010.rs` — Menzel & Guthe §6: Table 2 (triangles at 0.1 % and 1 % against our
//!   QEM), Figure 1 (four materials), the user study's analogue (¼ to 4 JND against the VDP).
//! - `qu_meyer.rs` — Qu & Meyer §5.3, Figure 7: uniform, curvature and perceptual remeshes at
//!   equal vertex budgets, scored with FLIP and the VDP and by where their vertices went.

pub mod lindstrom_turk;
pub mod menzel_guthe2010;
pub mod qu_meyer;
pub mod williams2003;

/// The paper a `simplify --experiment` config is for: its top-level `paper` key
/// (`"menzel-guthe2010"`), else Williams et al. 2003 (whose config predates the key).
pub fn paper_of(config: &std::path::Path) -> crate::error::Result<String> {
    #[derive(serde::Deserialize)]
    struct Head {
        paper: Option<String>,
    }
    let text = crate::io::read_input_text(
        config,
        "experiment config",
        crate::limits::CONFIG_BYTES,
        "give a config from configs/papers/",
    )?;
    let head: Head = toml::from_str::<toml::Table>(&text)
        .ok()
        .and_then(|t| t.try_into().ok())
        .unwrap_or(Head { paper: None });
    Ok(head.paper.unwrap_or_else(|| "williams2003".into()))
}
