//! Simplifiers, one algorithm per file: the industrial baseline (meshoptimizer, `meshopt.rs`), our
//! edge-collapse engine with Garland–Heckbert quadrics (`qem.rs`, on `mesh::edit`), and
//! Rossignac–Borrel vertex clustering (`cluster.rs`). The paper algorithms (Williams et al.,
//! Menzel–Guthe, Lindstrom–Turk, Qu–Meyer) join here. This file is the one entry point `eval` and
//! the CLI use: a method, a chain of targets, LOD meshes out.

pub mod attributes;
pub mod cluster;
pub mod goals;
pub mod lindstrom_turk;
pub mod menzel_guthe;
pub mod meshopt;
pub mod qem;
pub mod qu_meyer;
mod queue;
pub mod williams;

use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// A paper experiment's TOML config: `T` parsed from `config`, or an input error naming the file
/// and pointing at `schema` (the shipped config that documents the keys).
pub(crate) fn read_experiment<T: serde::de::DeserializeOwned>(
    config: &std::path::Path,
    schema: &str,
) -> Result<T> {
    let text = String::from_utf8(crate::mesh::read_file(config)?)
        .map_err(|_| Error::input(config, "the config is not UTF-8 text", "save it as UTF-8"))?;
    toml::from_str(&text).map_err(|e| {
        Error::input(
            config,
            e.message().trim().to_string(),
            format!("fix the key or value (see {schema} for the schema)"),
        )
    })
}

/// A simplification method.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, serde::Serialize, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Our edge collapse with Garland–Heckbert 1997 quadrics.
    #[value(help = "Our edge collapse with Garland–Heckbert quadrics")]
    Qem,
    /// Rossignac–Borrel vertex clustering.
    Cluster,
    /// meshoptimizer's `simplify`.
    #[value(help = "meshoptimizer's index-only simplification")]
    Meshopt,
    /// meshoptimizer's `simplifyWithUpdate`: attribute-aware, moves the kept vertices.
    #[serde(rename = "meshopt-update")]
    #[value(help = "meshoptimizer moving vertices and attributes, as qem does")]
    MeshoptUpdate,
    /// Williams et al. 2003 perceptual budget refinement: one static LOD for the 20 views of the
    /// default rig (each node keyed by its worst view), Gouraud shading, default viewing.
    #[value(help = "Williams et al. 2003: perceptual, view-dependent, to a --budget or --distance")]
    Williams,
    /// Menzel & Guthe 2010: collapses tested in vertex space for imperceptibility, with the
    /// distance beyond which each is invisible (`menzel_guthe/`).
    #[serde(rename = "menzel-guthe")]
    #[value(
        help = "Menzel & Guthe 2010: each collapse tested for imperceptibility in vertex space, to a --distance, --error, --ratio or --triangles"
    )]
    MenzelGuthe,
    /// Qu & Meyer: a remesh of a textured mesh to a vertex count, placed by curvature and the
    /// visual masking of its surface signal (`qu_meyer/`; vertex goals only).
    #[serde(rename = "qu-meyer")]
    #[value(skip)] // `lodeval remesh`, not `simplify`
    QuMeyer,
}

impl Method {
    /// The name used in LOD names and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Qem => "qem",
            Method::Cluster => "cluster",
            Method::Meshopt => "meshopt",
            Method::MeshoptUpdate => "meshopt-update",
            Method::Williams => "williams",
            Method::MenzelGuthe => "menzel-guthe",
            Method::QuMeyer => "qu-meyer",
        }
    }
}

/// What one LOD of a chain aims for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Goal {
    /// Fraction of the original's triangles.
    Ratio(f64),
    /// Triangle count: at most this many, where the mesh can be simplified that far.
    Triangles(usize),
    /// Error relative to the bounding-box diagonal (each method's own error measure).
    Error(f64),
    /// Imperceptible from this viewing distance on, metres (menzel-guthe only).
    Distance(f64),
    /// A remesh with this many vertices (qu-meyer only).
    Vertices(usize),
}

impl std::fmt::Display for Goal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Goal::Ratio(r) => write!(f, "ratio {r}"),
            Goal::Triangles(t) => write!(f, "{t} triangles"),
            Goal::Error(e) => write!(f, "error {e}"),
            Goal::Distance(d) => write!(f, "distance {d} m"),
            Goal::Vertices(v) => write!(f, "{v} vertices"),
        }
    }
}

/// A LOD and the simplifier's own error estimate for it (model units), where it has one.
#[derive(Debug, Clone)]
pub struct Lod {
    /// The mesh.
    pub mesh: Mesh,
    /// The simplifier's error estimate in model units.
    pub error: Option<f64>,
}

/// For a mesh without UVs or colours whose vertices are split only by normals (flat shading makes
/// every vertex a seam, and no seam-respecting simplifier could collapse anything): the welded
/// mesh with smooth normals, and whether the original was flat-shaded (≥ 99 % of triangles have
/// all three corner normals equal to the face normal).
pub(crate) fn normal_only_seams(mesh: &Mesh) -> Option<(Mesh, bool)> {
    if mesh.uvs().is_some()
        || mesh.colors().is_some()
        || mesh.welded_vertex_count() == mesh.vertex_count()
    {
        return None;
    }
    let p = mesh.positions();
    let face_normal = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| p[v as usize]);
        (b - a).cross(c - a).normalize_or_zero()
    };
    let flat = mesh
        .triangles()
        .iter()
        .filter(|t| {
            let n = face_normal(t);
            t.iter().all(|&v| mesh.normals()[v as usize].dot(n) > 0.999)
        })
        .count()
        * 100
        >= mesh.triangle_count() * 99;
    let weld = mesh.weld();
    let mut data = mesh.to_data();
    let mut positions = vec![glam::Vec3::ZERO; mesh.welded_vertex_count()];
    for (v, &w) in weld.iter().enumerate() {
        positions[w as usize] = p[v];
    }
    data.positions = positions;
    data.normals = None;
    data.triangles = mesh
        .triangles()
        .iter()
        .map(|t| t.map(|v| weld[v as usize]))
        .collect();
    Some((
        Mesh::new(data, &crate::mesh::LoadOptions::default()).ok()?,
        flat,
    ))
}

/// Give a LOD of a flat-shaded original its flat shading back: one vertex per corner with the
/// face's normal.
pub(crate) fn flatten(lod: &Mesh) -> Result<Mesh> {
    let p = lod.positions();
    let mut data = lod.to_data();
    data.positions = lod
        .triangles()
        .iter()
        .flat_map(|t| t.map(|v| p[v as usize]))
        .collect();
    data.normals = Some(
        lod.triangles()
            .iter()
            .flat_map(|t| {
                let [a, b, c] = t.map(|v| p[v as usize]);
                [(b - a).cross(c - a).normalize_or(glam::Vec3::Z); 3]
            })
            .collect(),
    );
    data.triangles = (0..lod.triangle_count() as u32)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    Mesh::new(data, &crate::mesh::LoadOptions::default())
}

/// Simplify `mesh` to every goal of `chain`, in order. meshoptimizer chains each LOD from the
/// previous one (as engines build LOD chains); QEM extracts triangle goals as prefixes of one
/// progressive run from the original (error goals run separately); clustering starts from the
/// original each time.
///
/// Meshes split only by normals are simplified welded, and flat-shaded originals get flat LODs
/// (see `normal_only_seams`).
///
/// Goals are checked first (a usage error, exit 2): a triangle goal may not exceed the mesh, and
/// consecutive goals of one kind must get strictly coarser (ratios and triangle counts
/// decreasing, errors increasing), since each LOD of a chain is simpler than the one before.
pub fn chain(mesh: &Mesh, method: Method, goals: &[Goal]) -> Result<Vec<Lod>> {
    chain_scaled(mesh, method, goals, 1.0)
}

/// [`chain`] for a mesh of `meters_per_unit` metres per model unit (what distance goals are
/// measured in).
pub fn chain_scaled(
    mesh: &Mesh,
    method: Method,
    goals: &[Goal],
    meters_per_unit: f64,
) -> Result<Vec<Lod>> {
    check_goals(method, mesh.triangle_count(), goals)?;
    if method == Method::QuMeyer {
        return qu_meyer_chain(mesh, goals);
    }
    if method == Method::MenzelGuthe {
        // Its own weld and attributes: the simplifier keeps seams and flat shading as they are.
        return menzel_guthe_chain(mesh, goals, meters_per_unit);
    }
    if let Some((welded, flat)) = normal_only_seams(mesh) {
        let lods = chain_of(&welded, method, goals)?;
        return lods
            .into_iter()
            .map(|l| {
                Ok(Lod {
                    mesh: if flat { flatten(&l.mesh)? } else { l.mesh },
                    error: l.error,
                })
            })
            .collect();
    }
    chain_of(mesh, method, goals)
}

/// The checks of [`chain`]'s goals for `method` against a mesh of `triangles` triangles (see
/// `goals.rs`), as a usage error.
pub fn check_goals(method: Method, triangles: usize, goals: &[Goal]) -> Result<()> {
    goals::check(method, goals, Some(triangles)).map_err(Error::Usage)
}

/// `goals` for a mesh of `triangles` triangles in Menzel & Guthe's terms (ratios become
/// triangle counts).
pub fn menzel_guthe_goals(triangles: usize, goals: &[Goal]) -> Vec<menzel_guthe::Goal> {
    goals
        .iter()
        .map(|&g| match g {
            Goal::Ratio(r) => menzel_guthe::Goal::Triangles(
                ((triangles as f64 * r).round() as usize).clamp(1, triangles),
            ),
            Goal::Triangles(t) => menzel_guthe::Goal::Triangles(t),
            Goal::Error(e) => menzel_guthe::Goal::Error(e),
            Goal::Distance(d) => menzel_guthe::Goal::Distance(d),
            // Refused before: chain_scaled sends vertex goals to qu-meyer only.
            Goal::Vertices(v) => menzel_guthe::Goal::Triangles(v.clamp(1, triangles)),
        })
        .collect()
}

/// Qu & Meyer's chain: each LOD remeshed from the original to its vertex count, with the
/// method's defaults.
fn qu_meyer_chain(mesh: &Mesh, goals: &[Goal]) -> Result<Vec<Lod>> {
    let shared = std::sync::Arc::new(mesh.clone());
    goals
        .iter()
        .map(|g| match *g {
            Goal::Vertices(v) => Ok(Lod {
                mesh: qu_meyer::remesh(&shared, &qu_meyer::Options::new(v))?.mesh,
                error: None,
            }),
            other => Err(Error::Usage(format!(
                "qu-meyer remeshes to a vertex count (`vertices = [...]`), not to {other}"
            ))),
        })
        .collect()
}

/// Menzel & Guthe's chain: one progressive run to the coarsest goal, each LOD a prefix of it.
fn menzel_guthe_chain(mesh: &Mesh, goals: &[Goal], meters_per_unit: f64) -> Result<Vec<Lod>> {
    let mg = menzel_guthe_goals(mesh.triangle_count(), goals);
    let options = menzel_guthe::Options {
        meters_per_unit,
        ..menzel_guthe::Options::DEFAULT
    };
    Ok(menzel_guthe::simplify(mesh, &mg, &options)?
        .lods
        .into_iter()
        .map(|l| Lod {
            mesh: l.mesh,
            error: None,
        })
        .collect())
}

fn chain_of(mesh: &Mesh, method: Method, goals: &[Goal]) -> Result<Vec<Lod>> {
    let n = mesh.triangle_count();
    let tris = |g: Goal| match g {
        Goal::Ratio(r) => Some((n as f64 * r).round().max(1.0) as usize),
        Goal::Triangles(t) => Some(t),
        Goal::Error(_) | Goal::Distance(_) | Goal::Vertices(_) => None,
    };
    match method {
        Method::MenzelGuthe => menzel_guthe_chain(mesh, goals, 1.0),
        Method::QuMeyer => qu_meyer_chain(mesh, goals),
        Method::Meshopt | Method::MeshoptUpdate => {
            let mut out: Vec<Lod> = Vec::new();
            for &g in goals {
                let input = out.last().map_or(mesh, |l| &l.mesh);
                let target = match tris(g) {
                    Some(t) => meshopt::Target::Triangles(t),
                    None => match g {
                        Goal::Error(e) => meshopt::Target::Error(e as f32),
                        _ => unreachable!(),
                    },
                };
                let s = if method == Method::Meshopt {
                    meshopt::simplify(input, target)?
                } else {
                    meshopt::simplify_updating(input, target)?
                };
                let acc = out.last().and_then(|l| l.error).unwrap_or(0.0);
                out.push(Lod {
                    mesh: s.mesh,
                    error: Some(acc + s.absolute_error as f64),
                });
            }
            Ok(out)
        }
        Method::Qem => {
            let smallest = goals.iter().filter_map(|&g| tris(g)).min();
            let progressive = smallest.map(|t| qem::progressive(mesh, qem::Stop::Triangles(t)));
            goals
                .iter()
                .map(|&g| match (tris(g), &progressive, g) {
                    (Some(t), Some(pm), _) => Ok(Lod {
                        mesh: pm.extract(t).to_mesh(mesh)?,
                        error: Some(pm.error_at(t)),
                    }),
                    (_, _, Goal::Error(e)) => {
                        let (m, err) = qem::simplify(mesh, qem::Stop::RelativeError(e))?;
                        Ok(Lod {
                            mesh: m,
                            error: Some(err),
                        })
                    }
                    _ => Err(Error::Internal("qem goal".into())),
                })
                .collect()
        }
        Method::Williams => {
            let w = williams::Williams::build(mesh)?;
            let cameras = crate::scene::Rig::Dodecahedron.cameras(mesh, 1.0);
            let opts = williams::Options::default();
            goals
                .iter()
                .map(|&g| {
                    let t = tris(g).ok_or_else(|| {
                        Error::Usage(
                            "williams takes triangle or ratio targets (a budget), not an error"
                                .into(),
                        )
                    })?;
                    Ok(Lod {
                        mesh: w.static_lod(&cameras, williams::StaticGoal::Budget(t), &opts)?,
                        error: None,
                    })
                })
                .collect()
        }
        Method::Cluster => goals
            .iter()
            .map(|&g| {
                let t = tris(g).ok_or_else(|| {
                    Error::Usage("clustering takes triangle or ratio targets, not an error".into())
                })?;
                Ok(Lod {
                    mesh: cluster::cluster_to(mesh, t)?,
                    error: None,
                })
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn goals_are_checked_before_any_simplifier_runs() {
        let mesh = crate::mesh::shapes::icosphere(2); // 320 triangles
        let n = mesh.triangle_count();
        for (goals, word) in [
            (
                vec![Goal::Ratio(0.25), Goal::Ratio(0.5)],
                "do not get coarser",
            ),
            (
                vec![Goal::Ratio(0.501), Goal::Ratio(0.502)],
                "do not get coarser",
            ),
            (vec![Goal::Triangles(n + 1)], "outside 1..=320"),
            (vec![Goal::Triangles(0)], "outside 1..=320"),
            (vec![Goal::Ratio(f64::NAN)], "outside (0, 1]"),
            (
                vec![Goal::Error(0.02), Goal::Error(0.01)],
                "do not get coarser",
            ),
        ] {
            for method in [Method::Meshopt, Method::MeshoptUpdate, Method::Qem] {
                match chain(&mesh, method, &goals) {
                    Err(Error::Usage(msg)) => assert!(msg.contains(word), "{goals:?}: {msg}"),
                    other => panic!("{goals:?} with {method:?}: {:?}", other.map(|l| l.len())),
                }
            }
        }
        // The whole mesh is a valid goal; a chain may mix kinds.
        let lods = chain(
            &mesh,
            Method::Meshopt,
            &[Goal::Triangles(n), Goal::Ratio(0.5), Goal::Error(0.05)],
        )
        .unwrap();
        assert_eq!(lods.len(), 3);
    }

    #[test]
    fn meshoptimizer_is_never_asked_for_more_than_its_input() {
        // Its assertion would abort the process; the target is clamped to each group's size.
        let mesh = crate::mesh::shapes::icosphere(2);
        let n = mesh.triangle_count();
        let s = meshopt::simplify(&mesh, meshopt::Target::Triangles(4 * n)).unwrap();
        assert_eq!(s.mesh.triangle_count(), n);
        let s = meshopt::simplify_updating(&mesh, meshopt::Target::Triangles(4 * n)).unwrap();
        assert_eq!(s.mesh.triangle_count(), n);
    }

    #[test]
    fn flat_shaded_meshes_simplify_and_stay_flat() {
        for method in [Method::Qem, Method::Meshopt, Method::Cluster] {
            // Every vertex split per face (flat normals), as in bunny_odedstein_3k.obj.
            let smooth = crate::mesh::shapes::icosphere(3);
            let mut data = smooth.to_data();
            let p = smooth.positions();
            data.positions = smooth
                .triangles()
                .iter()
                .flat_map(|t| t.map(|v| p[v as usize]))
                .collect();
            data.normals = Some(
                smooth
                    .triangles()
                    .iter()
                    .flat_map(|t| {
                        let [a, b, c] = t.map(|v| p[v as usize]);
                        [(b - a).cross(c - a).normalize(); 3]
                    })
                    .collect(),
            );
            data.triangles = (0..smooth.triangle_count() as u32)
                .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
                .collect();
            data.material_ids = Vec::new();
            let flat = Mesh::new(data, &crate::mesh::LoadOptions::default()).unwrap();
            let n = flat.triangle_count();
            let s = chain(&flat, method, &[Goal::Triangles(n / 4)])
                .unwrap()
                .remove(0);
            assert!(
                s.mesh.triangle_count() <= n / 4,
                "{n} -> {}",
                s.mesh.triangle_count()
            );
            assert_eq!(s.mesh.vertex_count(), 3 * s.mesh.triangle_count());
        }
    }
}
