//! Menzel & Guthe 2010: perceptual simplification of models with arbitrary materials — an edge
//! collapse is made only while it is imperceptible, tested in *vertex space* (the reflectance of
//! the original and the simplified surface at a point, over all light and view directions)
//! instead of on rendered image pairs. The result is a progressive mesh in which every collapse
//! carries the distance beyond which it is invisible.
//!
//! Based on: Nicolas Menzel, Michael Guthe. Towards Perceptual Simplification of Models with
//! Arbitrary Materials. Pacific Graphics 2010 (Computer Graphics Forum 29(7)). Hugues Hoppe. New
//! Quadric Metric for Simplifying Meshes with Appearance Attributes. IEEE Visualization 1999 (the
//! queue's order and the attribute values, through our QEM engine's attribute quadrics).
//!
//! One step per file, in the order of the paper:
//! - `pipeline.rs` — Figure 3 and §5.1: the queue, the two tests, postponement, blocks;
//! - `proposal.rs` — a collapse before it is made: placement, attributes, fan, test points;
//! - `surface.rs` — the points compared: the original's closest point and the new fan's;
//! - `response.rs` — §4.1: colour to JND-scaled opponent responses;
//! - `field.rs` — §4.2, §5: the hemispherical reflectance field of a point;
//! - `spectrum.rs` — §4.2, §5: its spherical-harmonics and Fourier spectrum;
//! - `rotation.rs` — §4.2: the rotation between two frames, phase shifts, δ_max;
//! - `curvature.rs` — §4.3: principal curvatures and torsion;
//! - `distance.rs` — §4.3 and Figure 4: frequencies, CSFs, the Newton iteration, silhouettes;
//! - `masking.rs` — §4.4: the masker and Daly's threshold elevation;
//! - `global.rs` — §4.4: global masking from renders of the whole model;
//! - `hausdorff.rs` — §3.1: the geometric test against the original;
//! - `perception.rs` — §4: one pair of points compared, the split distance.
//!
//! Each file's comment says how it reads the places where the project's copy of the paper is
//! garbled (δ_max, the phase shift, the regulariser of the pseudo-inverse) and what it adds where
//! the paper is silent (the frequency floor of a collapse's fan).
//!
//! Units: distances inside are model units from the viewer; [`Options::meters_per_unit`] turns
//! them into metres at this API. `--error E` follows the paper's §6 scaling: an error of E times
//! the bounding-box diagonal is at the limit when it subtends 1/30 of a degree.

#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod curvature;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod distance;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod field;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod global;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod hausdorff;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod masking;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod perception;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod pipeline;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod proposal;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod response;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod rotation;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod spectrum;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `simplify`
pub mod surface;

use glam::Vec3;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::metric::vdp::Display;

pub use pipeline::{Counts, Outcome, Stop};

/// Settings of a Menzel–Guthe simplification.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Options {
    /// The hemispherical sampling. Default value: the paper's 16 × 16 × 32 × 16.
    pub grid: field::Grid,
    /// The lighting the reflectance fields are shaded with. Default value: the renderer's
    /// ambient 0.15 and a white light of 0.85.
    pub lighting: field::Lighting,
    /// The display the differences are seen on. Default value: the README's office monitor.
    pub display: Display,
    /// Daly's masking of differences by the signals themselves. Default value: true.
    pub masking: bool,
    /// Global masking from renders of the whole model (§4.4). Default value: true.
    pub global_masking: bool,
    /// Queue heads tested together (§5.1). Default value: 64.
    pub block: usize,
    /// The threshold of visibility in JND (the paper's user study: ¼ to 4). Default value: 1.
    pub jnd: f64,
    /// Metres per model unit. Default value: 1.
    pub meters_per_unit: f64,
    /// Test collapses for visibility (§4). Without it only the Hausdorff test to the original
    /// bounds them: an attribute-aware QEM with a guaranteed geometric error, the baseline of
    /// the paper's Table 2 and of `results/papers/menzel-guthe2010/`. Default value: true.
    pub perception: bool,
}

impl Options {
    /// The defaults listed on the fields.
    pub const DEFAULT: Options = Options {
        grid: field::Grid::PAPER,
        lighting: field::Lighting {
            ambient: 0.15,
            color: Vec3::splat(0.85),
        },
        display: Display::DEFAULT,
        masking: true,
        global_masking: true,
        block: 64,
        jnd: 1.0,
        meters_per_unit: 1.0,
        perception: true,
    };
}

impl Default for Options {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What a LOD aims for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Goal {
    /// Imperceptible from this viewing distance on, metres.
    Distance(f64),
    /// An error relative to the bounding-box diagonal, mapped to a distance (§6).
    Error(f64),
    /// At most this many triangles.
    Triangles(usize),
}

/// One LOD.
#[derive(Debug, Clone)]
pub struct Lod {
    /// The mesh.
    pub mesh: Mesh,
    /// The distance beyond which it is imperceptible, metres (its last collapse's split
    /// distance; 0 for the original).
    pub distance_m: f64,
    /// Collapses made to reach it.
    pub collapses: usize,
}

/// A simplification's LODs and what the run did.
#[derive(Debug, Clone)]
pub struct Simplified {
    /// One LOD per goal, in order.
    pub lods: Vec<Lod>,
    /// The run's counts.
    pub counts: Counts,
    /// Seconds the run took (wall clock; reporting only).
    pub seconds: f64,
    /// Of which before the collapse loop: the original's BVH, curvatures, global masking and
    /// first queue.
    pub setup_seconds: f64,
}

/// Check `goals` (exit 2 on nonsense), as every simplifier's goals are (`simplify/goals.rs`):
/// distances finite and above 0, errors in (0, 1), triangle counts within the mesh's, a chain
/// that gets coarser.
pub fn check_goals(triangles: usize, goals: &[Goal]) -> Result<()> {
    let goals: Vec<super::Goal> = goals
        .iter()
        .map(|&g| match g {
            Goal::Triangles(t) => super::Goal::Triangles(t),
            Goal::Error(e) => super::Goal::Error(e),
            Goal::Distance(d) => super::Goal::Distance(d),
        })
        .collect();
    super::goals::check(super::Method::MenzelGuthe, &goals, Some(triangles)).map_err(Error::Usage)
}

/// Simplify `mesh` to every goal in one progressive run (to the coarsest).
pub fn simplify(mesh: &Mesh, goals: &[Goal], options: &Options) -> Result<Simplified> {
    check_goals(mesh.triangle_count(), goals)?;
    // A mesh split only by normals (flat shading) is simplified welded, and a flat original gets
    // flat LODs, as with the other simplifiers (`simplify::normal_only_seams`).
    if let Some((welded, flat)) = super::normal_only_seams(mesh) {
        let mut s = simplify_welded(&welded, goals, options)?;
        if flat {
            for l in &mut s.lods {
                l.mesh = super::flatten(&l.mesh)?;
            }
        }
        return Ok(s);
    }
    simplify_welded(mesh, goals, options)
}

fn simplify_welded(mesh: &Mesh, goals: &[Goal], options: &Options) -> Result<Simplified> {
    if !(options.meters_per_unit.is_finite() && options.meters_per_unit > 0.0) {
        return Err(Error::Usage(format!(
            "--meters-per-unit {}: give a finite number above 0",
            options.meters_per_unit
        )));
    }
    let start = std::time::Instant::now();
    let diagonal = mesh.aabb().diagonal() as f64;
    // Every goal as a distance in model units, or a triangle count.
    let distance_of = |g: &Goal| match *g {
        Goal::Distance(d) => Some(d / options.meters_per_unit),
        Goal::Error(e) => Some(distance::error_distance(e * diagonal)),
        Goal::Triangles(_) => None,
    };
    let stop = Stop {
        distance: goals.iter().filter_map(distance_of).reduce(f64::max),
        triangles: goals
            .iter()
            .filter_map(|g| match g {
                Goal::Triangles(t) => Some(*t),
                _ => None,
            })
            .min(),
    };
    let perception = perception::Perception::new(
        options.grid,
        options.lighting,
        &options.display,
        if options.masking {
            masking::Masking::daly()
        } else {
            masking::Masking::none()
        },
    )
    .with_jnd(options.jnd as f32);
    let engine = pipeline::Engine {
        block: options.block,
        perception: options.perception,
    };
    let global_start = std::time::Instant::now();
    let global = if options.perception && options.global_masking && options.masking {
        global::GlobalMasking::measure(
            &std::sync::Arc::new(mesh.clone()),
            &options.lighting,
            perception.response(),
        )
    } else {
        global::GlobalMasking::none()
    };
    let global_seconds = global_start.elapsed().as_secs_f64();
    let outcome = pipeline::run(mesh, &perception, &engine, stop, &|t, c, f| {
        global.at(t, c, f)
    });
    let lods = goals
        .iter()
        .map(|g| {
            let n = match (g, distance_of(g)) {
                (_, Some(d)) => outcome.prefix_for_distance(d),
                (Goal::Triangles(t), None) => outcome
                    .progressive
                    .collapses
                    .iter()
                    .position(|c| c.triangles <= *t)
                    .map_or(outcome.progressive.collapses.len(), |k| k + 1),
                _ => 0,
            };
            let adj = outcome.progressive.replay(n);
            let distance = n
                .checked_sub(1)
                .map_or(0.0, |k| outcome.progressive.collapses[k].error);
            Ok(Lod {
                mesh: adj.to_mesh(mesh)?,
                distance_m: distance * options.meters_per_unit,
                collapses: n,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Simplified {
        lods,
        counts: outcome.counts,
        seconds: start.elapsed().as_secs_f64(),
        setup_seconds: global_seconds + outcome.seconds.0,
    })
}
