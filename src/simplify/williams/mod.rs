//! Nathaniel Williams, David Luebke, Jonathan D. Cohen, Michael Kelley, Brenden Schubert.
//! Perceptually Guided Simplification of Lit, Textured Meshes. I3D 2003.
//!
//! View-dependent, best-effort simplification to a triangle budget, driven by the contrast
//! sensitivity function. One step per file:
//! - `hierarchy.rs` — the Multi-Triangulation (§2.3) from our edge-collapse engine's record;
//! - `texels.rs`, `bounds.rs`, `preprocess.rs` — per-node preprocessing (§4): bounding sphere,
//!   silhouette and shading normal cones, texel luminance range, texture deviation;
//! - `perception.rs` — per-view contrast, frequency and imperceptibility distance (§3, §5.2–5.4),
//!   and the comparison criteria of §6;
//! - `cut.rs` — best-effort dual-queue refinement to a budget with temporal coherence (§5.1);
//! - `experiment.rs` — the paper's evaluation (§6, Figure 4).
//!
//! This file ties them together: build once ([`Williams::build`]), then adapt a cut per camera
//! ([`Williams::adapt`]), or make a static LOD for a set of views ([`Williams::static_lod`]).

pub mod bounds;
pub mod cut;
pub mod experiment;
pub mod hierarchy;
pub mod perception;
pub mod preprocess;
pub mod texels;

use std::sync::Arc;

pub use cut::Cut;
pub use hierarchy::Hierarchy;
pub use perception::{Criterion, ViewModel, Visibility};
pub use preprocess::Preprocessed;

use crate::error::Result;
use crate::mesh::Mesh;
use crate::raster::Shading;
use crate::scene::{Camera, Light, Scene, Viewing};

/// How the views are seen and what is minimised.
#[derive(Debug, Clone)]
pub struct Options {
    /// The shading the LOD will be rendered with (decides the lighting contrast and the feature
    /// size). Default value: `Gouraud`.
    pub shading: Shading,
    /// The error criterion. Default value: `Perceptual`.
    pub criterion: Criterion,
    /// Viewing conditions (pixels per degree, viewing distance). Default value: DESIGN.md's.
    pub viewing: Viewing,
    /// Image width and height in pixels. Default value: 512 × 512.
    pub size: (u32, u32),
    /// Lights. Default value: the scene default (one headlight).
    pub lights: Vec<Light>,
    /// Ambient term. Default value: the scene default, 0.15.
    pub ambient: f32,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            shading: Shading::Gouraud,
            criterion: Criterion::Perceptual,
            viewing: Viewing::DEFAULT,
            size: (512, 512),
            lights: vec![Light::HEADLIGHT],
            ambient: Scene::DEFAULT_AMBIENT,
        }
    }
}

/// A preprocessed hierarchy, ready for any camera.
#[derive(Debug, Clone)]
pub struct Williams {
    /// The MT.
    pub hierarchy: Hierarchy,
    /// Per-node data.
    pub pre: Preprocessed,
}

impl Williams {
    /// Build the MT of `mesh` and preprocess it. Meshes split only by normals (flat shading) are
    /// welded first, as the other simplifiers do.
    pub fn build(mesh: &Mesh) -> Result<Williams> {
        let input = match super::normal_only_seams(mesh) {
            Some((welded, _)) => welded,
            None => mesh.clone(),
        };
        let hierarchy = Hierarchy::build(&Arc::new(input))?;
        let pre = preprocess::preprocess(&hierarchy);
        Ok(Williams { hierarchy, pre })
    }

    /// The evaluation model of one camera.
    pub fn view(&self, camera: &Camera, opts: &Options) -> ViewModel {
        ViewModel::new(
            camera,
            opts.size.0,
            opts.size.1,
            opts.shading,
            &opts.lights,
            opts.ambient,
            &opts.viewing,
        )
    }

    /// Node `n`'s error in view `vm` under `criterion`.
    pub fn key(&self, vm: &ViewModel, criterion: Criterion, n: u32) -> f64 {
        let d = &self.pre.nodes[n as usize];
        vm.key(criterion, d, &self.pre.materials[d.material as usize])
    }

    /// Adapt `cut` to `camera` within `budget` triangles (the cut and its queues carry over from
    /// the previous call: temporal coherence).
    pub fn adapt(&self, cut: &mut Cut, camera: &Camera, budget: usize, opts: &Options) {
        let vm = self.view(camera, opts);
        cut.adapt(&self.hierarchy, budget, &|n| {
            self.key(&vm, opts.criterion, n)
        });
    }

    /// The mesh of a cut.
    pub fn mesh(&self, cut: &Cut) -> Result<Mesh> {
        self.hierarchy.mesh_of(|t| cut.is_alive(&self.hierarchy, t))
    }

    /// One LOD for all of `cameras`: every node keyed by its largest error over them.
    pub fn static_lod(&self, cameras: &[Camera], goal: StaticGoal, opts: &Options) -> Result<Mesh> {
        let views: Vec<ViewModel> = cameras.iter().map(|c| self.view(c, opts)).collect();
        let key = |n: u32| {
            views
                .iter()
                .map(|vm| self.key(vm, opts.criterion, n))
                .fold(0.0, f64::max)
        };
        let mut cut = Cut::coarsest(&self.hierarchy);
        match goal {
            StaticGoal::Budget(b) => cut.adapt(&self.hierarchy, b, &key),
            StaticGoal::Distance(d) => cut.refine_above(&self.hierarchy, d, &key),
        }
        self.mesh(&cut)
    }
}

/// What a static LOD aims for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StaticGoal {
    /// At most this many triangles.
    Budget(usize),
    /// Imperceptible from this viewing distance (metres) on: every node whose imperceptibility
    /// distance exceeds it is refined.
    Distance(f64),
}

/// The LOD of `mesh` for one camera within `budget` triangles.
pub fn simplify_for_camera(
    mesh: &Mesh,
    camera: &Camera,
    budget: usize,
    opts: &Options,
) -> Result<Mesh> {
    let w = Williams::build(mesh)?;
    let mut cut = Cut::coarsest(&w.hierarchy);
    w.adapt(&mut cut, camera, budget, opts);
    w.mesh(&cut)
}
