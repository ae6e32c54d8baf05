//! `lodeval simplify`: a LOD (or a chain) by QEM, clustering, meshoptimizer or Williams et al.,
//! written as OBJ with its materials and textures.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::mesh::{self, LoadOptions, Mesh};
use crate::scene::{Camera, Rig};

/// A `lodeval simplify` request.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct SimplifyJob {
    /// Input mesh.
    pub mesh: PathBuf,
    /// Output `.obj` (with `--chain`: the stem; files become `STEM-rXX.obj`).
    pub out: PathBuf,
    /// Method.
    pub method: crate::simplify::Method,
    /// Goals (one, or the chain).
    pub goals: Vec<crate::simplify::Goal>,
    /// Write one file per goal with a suffix (a chain) rather than `out` itself.
    pub chain: bool,
    /// Metres per model unit (menzel-guthe's distance goals).
    pub meters_per_unit: f64,
    /// How a glTF chain's switch points are measured (shading, lighting, display).
    pub look: crate::eval::config::Look,
}

impl SimplifyJob {
    /// `mesh` to `goals` with `method` into `out`: one file per goal, one metre per unit, the
    /// default look.
    pub fn new(
        mesh: PathBuf,
        out: PathBuf,
        method: crate::simplify::Method,
        goals: Vec<crate::simplify::Goal>,
    ) -> SimplifyJob {
        SimplifyJob {
            mesh,
            out,
            method,
            goals,
            chain: false,
            meters_per_unit: 1.0,
            look: crate::eval::config::Look::default(),
        }
    }
}

/// One written LOD.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SimplifyRow {
    /// The file written.
    pub file: PathBuf,
    /// Triangles.
    pub triangles: usize,
    /// Over the input's triangles.
    pub ratio: f64,
    /// The simplifier's own error estimate, model units.
    pub simplifier_error: Option<f64>,
    /// Seconds for the whole chain (wall clock; reporting only).
    pub seconds: f64,
    /// Menzel–Guthe's figures for this LOD and its run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub menzel_guthe: Option<MenzelGutheRow>,
    /// In a glTF chain: where this level takes over, as measured and as written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub switch: Option<SwitchPoint>,
}

/// Where a level of a glTF chain written by `simplify` takes over from the finer one.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SwitchPoint {
    /// Its level in the chain (`FILE#level`; 0 is the original).
    pub level: usize,
    /// The `MSFT_screencoverage` below which it is used (the finer level's value as written,
    /// never more than a finer level's).
    pub screen_coverage: f64,
    /// The measured imperceptibility distance it comes from (criterion, distance, on-screen
    /// diameter, Unity and Unreal values, bound), where one was measured.
    pub measured: Option<crate::eval::tables::DistanceRow>,
}

/// What a Menzel–Guthe run did, reported with each of its LODs.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MenzelGutheRow {
    /// The LOD is imperceptible from this distance on, metres.
    pub distance_m: f64,
    /// Collapses made to reach this LOD.
    pub collapses: usize,
    /// The whole run's counts (applied collapses, perception tests, postponements, Hausdorff
    /// tests).
    #[serde(flatten)]
    pub run: crate::simplify::menzel_guthe::Counts,
}

/// What `simplify` wrote and what the user should know.
#[derive(Debug, Clone)]
pub struct SimplifyReport {
    /// One row per LOD written.
    pub rows: Vec<SimplifyRow>,
    /// Notes for the user (stderr).
    pub warnings: Vec<String>,
}

/// Whether `out` asks for one glTF LOD chain (`.glb`, `.gltf`) rather than OBJ files.
fn gltf_out(out: &Path) -> bool {
    matches!(
        out.extension().and_then(|e| e.to_str()),
        Some("glb" | "gltf")
    )
}

/// Check that `out` is an OBJ or glTF path, then load `input` (the simplifiers' common start).
fn load_for_lod(input: &Path, out: &Path) -> Result<Mesh> {
    if out.extension().and_then(|e| e.to_str()) != Some("obj") && !gltf_out(out) {
        return Err(Error::Usage(format!(
            "-o {}: lodeval writes LODs as .obj (with .mtl and textures beside it), or a whole \
             chain as one .glb or .gltf",
            out.display()
        )));
    }
    mesh::load(input, &LoadOptions::default())
}

/// Simplify a mesh and write the LOD(s) as OBJ.
pub fn simplify(
    job: &SimplifyJob,
    progress: &dyn crate::progress::Progress,
) -> Result<SimplifyReport> {
    let mesh = load_for_lod(&job.mesh, &job.out)?;
    // Every file of the chain is checked before the simplifier runs: none may be an input.
    let gltf = gltf_out(&job.out);
    let files: Vec<PathBuf> = job
        .goals
        .iter()
        .map(|g| {
            if gltf {
                job.out.clone()
            } else {
                lod_file(job, g)
            }
        })
        .collect();
    let planned: Vec<PathBuf> = if gltf {
        crate::mesh::write_gltf::planned_files(&[("original", &mesh)], &job.out)?
    } else {
        files
            .iter()
            .flat_map(|f| crate::mesh::write_obj::planned_files(&mesh, f))
            .collect()
    };
    crate::io::check_not_inputs(&planned, &mesh.source().files)?;
    let start = std::time::Instant::now();
    progress.start(
        None,
        "",
        &format!(
            "simplifying {} triangles with {}",
            mesh.triangle_count(),
            job.method.name()
        ),
    );
    let mut warnings = Vec::new();
    let lods = if job.method == crate::simplify::Method::MenzelGuthe {
        if mesh.materials().iter().all(|m| m.name == "default") {
            warnings.push(format!(
                "{}: no material information: menzel-guthe shades it with the default material \
                 (light grey, faint highlight)",
                job.mesh.display()
            ));
        }
        let options = crate::simplify::menzel_guthe::Options {
            meters_per_unit: job.meters_per_unit,
            ..crate::simplify::menzel_guthe::Options::DEFAULT
        };
        let goals = crate::simplify::menzel_guthe_goals(mesh.triangle_count(), &job.goals);
        crate::simplify::check_goals(job.method, mesh.triangle_count(), &job.goals).and_then(|()| {
            let s = crate::simplify::menzel_guthe::simplify(&mesh, &goals, &options)?;
            let counts = s.counts;
            Ok(s.lods
                .into_iter()
                .map(|l| {
                    let row = MenzelGutheRow {
                        distance_m: l.distance_m,
                        collapses: l.collapses,
                        run: counts,
                    };
                    (l.mesh, None, Some(row))
                })
                .collect::<Vec<_>>())
        })
    } else {
        crate::simplify::chain(&mesh, job.method, &job.goals)
            .map(|ls| ls.into_iter().map(|l| (l.mesh, l.error, None)).collect())
    };
    progress.finish();
    let lods = lods?;
    let seconds = start.elapsed().as_secs_f64();
    let lod_meshes: Vec<&Mesh> = lods.iter().map(|(l, _, _)| l).collect();
    let switches = if gltf {
        write_gltf_chain(job, &mesh, &lod_meshes, &mut warnings)?
    } else {
        vec![None; lods.len()]
    };
    let mut rows = Vec::new();
    for (((lod, error, mg), file), switch) in lods.iter().zip(files).zip(switches) {
        if !gltf {
            for w in crate::mesh::write_obj::write(lod, &file)? {
                if !warnings.contains(&w) {
                    warnings.push(w);
                }
            }
        }
        let file = match &switch {
            Some(s) => PathBuf::from(format!("{}#{}", file.display(), s.level)),
            None => file,
        };
        rows.push(SimplifyRow {
            file,
            triangles: lod.triangle_count(),
            ratio: lod.triangle_count() as f64 / mesh.triangle_count() as f64,
            simplifier_error: *error,
            seconds,
            menzel_guthe: mg.clone(),
            switch,
        });
    }
    Ok(SimplifyReport { rows, warnings })
}

/// `-o CHAIN.glb|.gltf`: the original and every LOD as one asset, switching where each was
/// measured invisible; returns each LOD's switch point (in `lods`' order).
fn write_gltf_chain(
    job: &SimplifyJob,
    mesh: &Mesh,
    lods: &[&Mesh],
    warnings: &mut Vec<String>,
) -> Result<Vec<Option<SwitchPoint>>> {
    let original = std::sync::Arc::new(mesh.clone());
    let named: Vec<(String, std::sync::Arc<Mesh>)> = lods
        .iter()
        .zip(&job.goals)
        .map(|(l, g)| (goal_name(job.method, g), std::sync::Arc::new((*l).clone())))
        .collect();
    let refs: Vec<(&str, std::sync::Arc<Mesh>)> =
        named.iter().map(|(n, m)| (n.as_str(), m.clone())).collect();
    let rows = crate::eval::export::measure(&original, &refs, job.meters_per_unit, &job.look)?;
    let chain: Vec<(&str, &Mesh)> = named.iter().map(|(n, m)| (n.as_str(), &**m)).collect();
    let written = crate::eval::export::write_chain(
        &job.out,
        crate::eval::export::ORIGINAL,
        mesh,
        &chain,
        &rows,
    )?;
    warnings.extend(written.warnings.iter().cloned());
    Ok(named
        .iter()
        .map(|(name, _)| switch_point(&written, &rows, name))
        .collect())
}

/// The switch point of the LOD named `name` in a chain `written` from distance `rows`.
fn switch_point(
    written: &crate::eval::export::ChainWritten,
    rows: &[crate::eval::tables::DistanceRow],
    name: &str,
) -> Option<SwitchPoint> {
    let level = written.levels.iter().position(|l| l == name)? + 1;
    Some(SwitchPoint {
        level,
        screen_coverage: written.coverage[level - 1],
        measured: rows
            .iter()
            .find(|r| r.lod == name && Some(&r.criterion) == written.criterion.as_ref())
            .cloned(),
    })
}

/// A LOD's name in a glTF chain: the method and the goal (`qem-r50`, `meshopt-t1000`).
fn goal_name(method: crate::simplify::Method, goal: &crate::simplify::Goal) -> String {
    format!("{}-{}", method.name(), goal_suffix(goal))
}

/// The file a LOD of `goal` goes to: `-o` itself, or in a chain `STEM-SUFFIX.obj` beside it (the
/// suffix from [`goal_suffix`]).
fn lod_file(job: &SimplifyJob, goal: &crate::simplify::Goal) -> PathBuf {
    if !job.chain {
        return job.out.clone();
    }
    let stem = job
        .out
        .file_stem()
        .map_or_else(|| "lod".into(), |s| s.to_string_lossy().into_owned());
    job.out
        .with_file_name(format!("{stem}-{}.obj", goal_suffix(goal)))
}

/// A goal in a name: `r50` (ratio in percent), `t1000`, `e0.01`, `d5`, `v2000`.
fn goal_suffix(goal: &crate::simplify::Goal) -> String {
    match goal {
        crate::simplify::Goal::Ratio(r) => {
            format!("r{}", crate::eval::config::percent_label(*r))
        }
        crate::simplify::Goal::Triangles(t) => format!("t{t}"),
        crate::simplify::Goal::Error(e) => format!("e{e}"),
        crate::simplify::Goal::Distance(d) => format!("d{d}"),
        crate::simplify::Goal::Vertices(v) => format!("v{v}"),
    }
}

/// Which views a Williams et al. LOD is made for.
#[derive(Debug, Clone)]
pub enum WilliamsViews {
    /// View K of a rig (default framing).
    One(Rig, usize),
    /// One static LOD for every view of a rig.
    All(Rig),
    /// A camera at an eye position looking at a target (default: the model's centre), framed
    /// with the default field of view.
    Camera(glam::Vec3, Option<glam::Vec3>),
}

/// A `lodeval simplify --method williams` request.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct WilliamsJob {
    /// Input mesh.
    pub mesh: PathBuf,
    /// Output `.obj`.
    pub out: PathBuf,
    /// A triangle budget, or a viewing distance (metres) from which the LOD is to be
    /// imperceptible.
    pub goal: crate::simplify::williams::StaticGoal,
    /// Views.
    pub views: WilliamsViews,
    /// Shading the LOD is for.
    pub shading: crate::raster::Shading,
    /// Error criterion.
    pub criterion: crate::simplify::williams::Criterion,
    /// Image size (pixels) the views are seen at.
    pub size: u32,
}

impl WilliamsJob {
    /// `mesh` to `goal` into `out`: one static LOD for the 20 views of the dodecahedron rig,
    /// Gouraud shading, the paper's perceptual criterion, 512² views.
    pub fn new(
        mesh: PathBuf,
        out: PathBuf,
        goal: crate::simplify::williams::StaticGoal,
    ) -> WilliamsJob {
        WilliamsJob {
            mesh,
            out,
            goal,
            views: WilliamsViews::All(Rig::Dodecahedron),
            shading: crate::raster::Shading::Gouraud,
            criterion: crate::simplify::williams::Criterion::Perceptual,
            size: 512,
        }
    }
}

/// Simplify with Williams et al. 2003 and write the LOD as OBJ, or as a one-level glTF.
pub fn simplify_williams(job: &WilliamsJob) -> Result<SimplifyReport> {
    use crate::simplify::williams::{Options, Williams};
    let mesh = load_for_lod(&job.mesh, &job.out)?;
    let planned = if gltf_out(&job.out) {
        crate::mesh::write_gltf::planned_files(&[("williams", &mesh)], &job.out)?
    } else {
        crate::mesh::write_obj::planned_files(&mesh, &job.out)
    };
    crate::io::check_not_inputs(&planned, &mesh.source().files)?;
    let start = std::time::Instant::now();
    let w = Williams::build(&mesh)?;
    let opts = Options {
        shading: job.shading,
        criterion: job.criterion,
        size: (job.size, job.size),
        ..Options::default()
    };
    let cameras = match &job.views {
        WilliamsViews::All(rig) => rig.cameras(&mesh, 1.0),
        WilliamsViews::One(rig, k) => {
            let cams = rig.cameras(&mesh, 1.0);
            vec![*cams.get(*k).ok_or_else(|| {
                Error::Usage(format!("--view {k}: the rig has views 0..{}", cams.len()))
            })?]
        }
        WilliamsViews::Camera(eye, target) => {
            let sphere = mesh.bounding_sphere();
            let target = target.unwrap_or(sphere.center);
            if !(eye.is_finite() && target.is_finite()) || eye.distance(target) <= 0.0 {
                return Err(Error::Usage(
                    "--camera: the eye must be finite and apart from the target".into(),
                ));
            }
            vec![Camera::looking_at(
                sphere,
                *eye,
                target,
                Camera::DEFAULT_FOV_Y_DEG,
            )]
        }
    };
    let lod = w.static_lod(&cameras, job.goal, &opts)?;
    let seconds = start.elapsed().as_secs_f64();
    let warnings = if gltf_out(&job.out) {
        // One level: the LOD alone, named by its method.
        crate::mesh::write_gltf::write_lod_chain(&[("williams", &lod)], &[0.0], &job.out)?.warnings
    } else {
        crate::mesh::write_obj::write(&lod, &job.out)?
    };
    Ok(SimplifyReport {
        rows: vec![SimplifyRow {
            file: job.out.clone(),
            triangles: lod.triangle_count(),
            ratio: lod.triangle_count() as f64 / mesh.triangle_count() as f64,
            simplifier_error: None,
            seconds,
            menzel_guthe: None,
            switch: None,
        }],
        warnings,
    })
}
