//! `lodeval optimize`: Lindstrom & Turk's image-driven optimization of a simplified mesh.

use std::path::PathBuf;

use crate::error::{Error, Result};
use crate::mesh::{self, LoadOptions};

/// What `lodeval optimize` does.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct OptimizeJob {
    /// The original (target) mesh.
    pub original: PathBuf,
    /// The simplified mesh to improve.
    pub simplified: PathBuf,
    /// Output OBJ.
    pub out: PathBuf,
    /// Energy log CSV, if wanted.
    pub energy_csv: Option<PathBuf>,
    /// Optimizer settings.
    pub options: crate::simplify::lindstrom_turk::Options,
}

impl OptimizeJob {
    /// Optimize `simplified` towards `original` into `out` with the default options, no energy
    /// log.
    pub fn new(original: PathBuf, simplified: PathBuf, out: PathBuf) -> OptimizeJob {
        OptimizeJob {
            original,
            simplified,
            out,
            energy_csv: None,
            options: crate::simplify::lindstrom_turk::Options::DEFAULT,
        }
    }
}

/// Run the image-driven optimizer and write the mesh (and the energy log).
pub fn optimize(
    job: &OptimizeJob,
    progress: &dyn crate::progress::Progress,
) -> Result<crate::simplify::lindstrom_turk::Outcome> {
    use crate::simplify::lindstrom_turk;
    if job.out.extension().and_then(|e| e.to_str()) != Some("obj") {
        return Err(Error::Usage(format!(
            "-o {}: lodeval writes optimized meshes as .obj",
            job.out.display()
        )));
    }
    let o = &job.options;
    crate::limits::check_memory(
        &format!(
            "optimizing with {} views at {}x{} pixels",
            o.views, o.size, o.size
        ),
        o.views as u64 * (o.size as u64).pow(2) * crate::limits::BYTES_PER_OPTIMIZER_PIXEL,
    )
    .map_err(Error::Usage)?;
    let original = std::sync::Arc::new(mesh::load(&job.original, &LoadOptions::default())?);
    let simplified = std::sync::Arc::new(mesh::load(&job.simplified, &LoadOptions::default())?);
    // Neither the mesh nor the energy log may replace a file either input was read from.
    let mut outputs = crate::mesh::write_obj::planned_files(&simplified, &job.out);
    outputs.extend(job.energy_csv.clone());
    let inputs: Vec<std::path::PathBuf> = [&original, &simplified]
        .iter()
        .flat_map(|m| m.source().files.iter().cloned())
        .collect();
    crate::io::check_not_inputs(&outputs, &inputs)?;
    progress.start(Some(job.options.evals), "evaluations", "");
    let outcome = lindstrom_turk::optimize(&original, &simplified, &job.options, &|n| {
        progress.set_position(n)
    });
    progress.finish();
    let mut outcome = outcome?;
    outcome.warnings = crate::mesh::write_obj::write(&outcome.mesh, &job.out)?;
    if let Some(path) = &job.energy_csv {
        crate::io::csv::write_rows(path, None, &outcome.log)?;
    }
    Ok(outcome)
}
