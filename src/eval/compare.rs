//! `lodeval compare ORIGINAL LOD`: the one-shot comparison of two meshes, with no config — both
//! rendered from the *original's* framing (the LOD is not re-framed by its own bounding sphere,
//! so the two renders line up), every view scored, the summary and the imperceptibility
//! distances. It is `eval` on a one-asset, one-LOD plan built in memory, with the same renderer,
//! cameras, metrics and distance search, so its numbers are `eval`'s for the same settings; it
//! writes no files.

use std::path::{Path, PathBuf};

use super::config::{AssetConfig, Config, HeatmapChoice, ImageSize, LodConfig, RigName};
use super::plan::Plan;
use super::run::{RunOptions, evaluate};
use super::tables::{DistanceRow, MetricRow, SummaryRow};
use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::scene::Rig;

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

/// A file's stem as an asset or LOD name: characters a name cannot hold (see
/// `config::Name`) become `_`, so that any file can be compared.
fn stem(p: &Path) -> String {
    let stem: String = p
        .file_stem()
        .map_or_else(|| "mesh".into(), |s| s.to_string_lossy().into_owned())
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if stem.is_empty() || stem == "." || stem == ".." {
        "mesh".into()
    } else {
        stem
    }
}

/// The in-memory plan: one asset, one LOD, images off, built as a value (no TOML text, so
/// any file name works); a message about a bad value names the argument it came from.
fn plan(job: &CompareJob) -> Result<Plan> {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    for (what, path) in [("ORIGINAL", &job.original), ("LOD", &job.lod)] {
        if !crate::mesh::split_level(path).0.is_file() {
            return Err(Error::input(
                path,
                format!("{what} is not there (or not a file)"),
                "give the path of a mesh file (OBJ, PLY, glTF, GLB or OFF)",
            ));
        }
    }
    let original = stem(&job.original);
    let mut lod = stem(&job.lod);
    if lod == original {
        lod.push_str("-lod");
    }
    let argument = |what: &str, path: &Path, why: String| {
        Error::input(
            path,
            format!("{what}: {why}"),
            "rename the file: its stem names the rows (letters, digits, '-', '_', '.')",
        )
    };
    let mut asset = AssetConfig::new(&original, abs(&job.original))
        .map_err(|why| argument("ORIGINAL", &job.original, why))?;
    asset
        .lods
        .push(LodConfig::new(&lod, abs(&job.lod)).map_err(|why| argument("LOD", &job.lod, why))?);
    let mut config = Config::new(vec![asset]);
    config.render.size =
        ImageSize::try_from(job.size).map_err(|why| Error::Usage(format!("--size: {why}")))?;
    config.render.rig = RigName(Rig::parse(&rig_for(job.views)).map_err(Error::Usage)?);
    job.look
        .apply_to(&mut config.render)
        .map_err(|why| Error::Usage(format!("the look: {why}")))?;
    config.images.heatmaps = HeatmapChoice::None;
    config.images.contact_sheets = false;
    config.distance.enabled = job.distances;
    Plan::from_config(config, Path::new("<compare>"))
}

/// Compare `job.lod` with `job.original`.
pub fn compare(job: &CompareJob, progress: &dyn Progress) -> Result<CompareReport> {
    let plan = plan(job)?;
    let mut options = RunOptions::DEFAULT;
    options.backend = job.backend;
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
