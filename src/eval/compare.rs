//! `lodeval compare ORIGINAL LOD`: the one-shot comparison of two meshes, with no config — both
//! rendered from the *original's* framing (the LOD is not re-framed by its own bounding sphere,
//! so the two renders line up), every view scored, the summary and the imperceptibility
//! distances. It is `eval` on a one-asset, one-LOD plan built in memory, with the same renderer,
//! cameras, metrics and distance search, so its numbers are `eval`'s for the same settings; it
//! writes no files.

use std::path::{Path, PathBuf};

use super::plan::{Plan, Shard};
use super::run::{RunOptions, evaluate};
use super::tables::{DistanceRow, MetricRow, SummaryRow};
use crate::error::{Error, Result};
use crate::progress::Progress;

/// A `compare` request: [`CompareJob::new`] with the two meshes, then set what differs.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CompareJob {
    /// The original mesh.
    pub original: PathBuf,
    /// The mesh compared with it.
    pub lod: PathBuf,
    /// Views: 20 (dodecahedron), 12 (icosahedron) or any count on a Fibonacci sphere.
    pub views: u32,
    /// Image size, pixels.
    pub size: u32,
    /// Search the imperceptibility distances too.
    pub distances: bool,
    /// Where frames are rendered.
    pub backend: crate::backend::Backend,
    /// Shading, lighting and display.
    pub look: super::config::Look,
}

impl CompareJob {
    /// `lod` against `original` as `lodeval compare` does by default: 20 views, 512² frames,
    /// distances searched, the CPU reference, the default look.
    pub fn new(original: PathBuf, lod: PathBuf) -> CompareJob {
        CompareJob {
            original,
            lod,
            views: 20,
            size: 512,
            distances: true,
            backend: crate::backend::Backend::Cpu,
            look: super::config::Look::default(),
        }
    }
}

/// What `compare` found.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CompareReport {
    /// Per view and metric (`metrics.csv`'s rows).
    pub views: Vec<MetricRow>,
    /// Per metric over views (`summary.csv`'s rows).
    pub summary: Vec<SummaryRow>,
    /// The imperceptibility distances (`distances.csv`'s rows; empty without `distances`).
    pub distances: Vec<DistanceRow>,
    /// The original's and the LOD's triangles.
    pub triangles: (usize, usize),
    /// Notes for the user.
    pub warnings: Vec<String>,
}

/// The rig name `eval` configs use for `views` views.
pub fn rig_for(views: u32) -> String {
    match views {
        20 => "dodecahedron".into(),
        12 => "icosahedron".into(),
        n => format!("fibonacci:{n}"),
    }
}

/// A file's stem as an asset or LOD name.
fn stem(p: &Path) -> String {
    p.file_stem()
        .map_or_else(|| "mesh".into(), |s| s.to_string_lossy().into_owned())
}

/// The in-memory plan: one asset, one LOD, images off.
fn plan(job: &CompareJob) -> Result<Plan> {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let text = |p: &Path| {
        abs(p).to_str().map(str::to_string).ok_or_else(|| {
            Error::input(
                p,
                "the path is not valid UTF-8",
                "rename the file or its folder with UTF-8 characters",
            )
        })
    };
    let original = stem(&job.original);
    let mut lod = stem(&job.lod);
    if lod == original {
        lod.push_str("-lod");
    }
    let mut asset = toml::Table::new();
    asset.insert("name".into(), original.into());
    asset.insert("mesh".into(), text(&job.original)?.into());
    let mut l = toml::Table::new();
    l.insert("mesh".into(), text(&job.lod)?.into());
    l.insert("name".into(), lod.into());
    asset.insert("lods".into(), toml::Value::Array(vec![l.into()]));
    let mut render = toml::Table::new();
    render.insert("size".into(), i64::from(job.size).into());
    render.insert("rig".into(), rig_for(job.views).into());
    job.look.insert_into(&mut render);
    let mut images = toml::Table::new();
    images.insert("heatmaps".into(), "none".into());
    images.insert("contact_sheets".into(), false.into());
    let mut distance = toml::Table::new();
    distance.insert("enabled".into(), job.distances.into());
    let mut config = toml::Table::new();
    config.insert("render".into(), render.into());
    config.insert("images".into(), images.into());
    config.insert("distance".into(), distance.into());
    config.insert("asset".into(), toml::Value::Array(vec![asset.into()]));
    let text = toml::to_string(&config)
        .map_err(|e| Error::Internal(format!("compare: the plan as TOML: {e}")))?;
    let plan = Plan::from_text(text, Path::new("<compare>"))?;
    plan.check_meshes()?;
    Ok(plan)
}

/// Compare `job.lod` with `job.original`.
pub fn compare(job: &CompareJob, progress: &dyn Progress) -> Result<CompareReport> {
    let plan = plan(job)?;
    let options = RunOptions {
        out: None,
        shard: Shard::ALL,
        backend: job.backend,
        cache: None,
    };
    let (results, warnings, _) = evaluate(&plan, &options, progress, None)?;
    let triangles = results
        .lods
        .first()
        .map_or((0, 0), |l| (l.original_triangles, l.triangles));
    Ok(CompareReport {
        summary: results.summary(),
        views: results.rows,
        distances: results.distances,
        triangles,
        warnings,
    })
}
