//! `lodeval remesh MESH -o OUT.obj --vertices N`: Qu & Meyer's perceptually driven remeshing (or
//! its curvature-only and uniform baselines), written as OBJ with the input's materials, and the
//! maps as PNG pictures on request.

use std::path::PathBuf;
use std::sync::Arc;

use crate::error::{Error, Result};
use crate::mesh::{self, LoadOptions};
use crate::simplify::qu_meyer::{self, Options, Seconds};

/// A `lodeval remesh` request.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct RemeshJob {
    /// Input mesh (with texture coordinates).
    pub mesh: PathBuf,
    /// Output `.obj`.
    pub out: PathBuf,
    /// What to build.
    pub options: Options,
    /// Folder for the maps as PNG (signal, masking, curvature, density, samples).
    pub maps: Option<PathBuf>,
}

impl RemeshJob {
    /// `mesh` remeshed with `options` into `out`, no maps written.
    pub fn new(mesh: PathBuf, out: PathBuf, options: Options) -> RemeshJob {
        RemeshJob {
            mesh,
            out,
            options,
            maps: None,
        }
    }
}

/// What `remesh` wrote.
#[derive(Debug, Clone, serde::Serialize)]
pub struct RemeshReport {
    /// The mesh written.
    pub file: PathBuf,
    /// What the output could not keep of the input.
    pub warnings: Vec<String>,
    /// The method's name.
    pub method: &'static str,
    /// 3D points of the result (seam vertices once).
    pub vertices: usize,
    /// Of those, on the UV charts' boundaries.
    pub boundary_vertices: usize,
    /// Vertices as stored (one per chart and UV).
    pub stored_vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// The input's 3D points and triangles.
    pub input_vertices: usize,
    /// The input's triangles.
    pub input_triangles: usize,
    /// UV charts.
    pub charts: usize,
    /// Lloyd iterations.
    pub iterations: usize,
    /// Share of the vertices in the most strongly masked quarter of the surface.
    pub masked_share: f64,
    /// Seconds per stage.
    pub seconds: Seconds,
    /// Map pictures written.
    pub maps: Vec<PathBuf>,
}

use crate::simplify::qu_meyer::MAP_FILES;

/// Remesh and write.
pub fn remesh(job: &RemeshJob) -> Result<RemeshReport> {
    if job.out.extension().and_then(|e| e.to_str()) != Some("obj") {
        return Err(Error::Usage(format!(
            "-o {}: lodeval writes remeshed meshes as .obj (with .mtl and textures beside it)",
            job.out.display()
        )));
    }
    job.options.check()?;
    let input = Arc::new(mesh::load(&job.mesh, &LoadOptions::default())?);
    let mut planned = mesh::write_obj::planned_files(&input, &job.out);
    let map_files: Vec<PathBuf> = job
        .maps
        .iter()
        .flat_map(|d| MAP_FILES.iter().map(move |f| d.join(f)))
        .collect();
    planned.extend(map_files.iter().cloned());
    crate::io::check_not_inputs(&planned, &input.source().files)?;
    let options = Options {
        keep_maps: job.maps.is_some(),
        ..job.options
    };
    let r = qu_meyer::remesh(&input, &options)?;
    let mut warnings = mesh::write_obj::write(&r.mesh, &job.out)?;
    // Fewer vertices than asked (a small map has too few texels to place them): said.
    if (r.vertices as f64) < 0.95 * options.vertices as f64 {
        warnings.push(format!(
            "the remesh has {} vertices, short of the {} asked for: the {}² maps have too few \
             texels inside the charts to place more; raise --map-size",
            r.vertices, options.vertices, options.map_size
        ));
    }
    if let (Some(dir), Some(images)) = (&job.maps, &r.maps) {
        images.write(dir)?;
    }
    Ok(RemeshReport {
        file: job.out.clone(),
        method: options.method.name(),
        vertices: r.vertices,
        boundary_vertices: r.boundary_vertices,
        stored_vertices: r.mesh.vertex_count(),
        triangles: r.mesh.triangle_count(),
        input_vertices: input.welded_vertex_count(),
        input_triangles: input.triangle_count(),
        charts: r.charts,
        iterations: r.iterations,
        masked_share: r.masked_share,
        seconds: r.seconds,
        maps: map_files,
        warnings,
    })
}
