//! Imperceptibility distances: from how far away nobody can tell a LOD from its original, and
//! that distance in each engine's own LOD parameter.
//!
//! Geometry. The display is a window of `display_px` × `display_height_px` pixels, `display_width_m`
//! wide, seen from `distance_m` (the default viewing conditions). A pixel at the centre subtends
//! 1/k radians with k = distance_m · display_px / display_width_m, which also fixes the engine
//! camera's vertical field of view (cot(fov/2) = 2k / height_px). An object's size is its minimal
//! enclosing sphere's (Welzl; [`crate::mesh::minimal_sphere`]): one whose sphere has radius R
//! (metres) at distance D from the eye projects to a disc of diameter 2k·R/√(D² − R²) pixels;
//! the inverse is D = R·√(1 + (2k/diameter)²).
//!
//! Method. For a candidate on-screen diameter the original and the LOD are rendered exactly as
//! that viewer would see them (perspective camera at distance D, the display's pixel scale, a
//! square crop around the object with a 10 % + 4 px border, supersampled), and scored with the VDP
//! at the display's pixels per degree (and with FLIP). The LOD is imperceptible at that size when
//! the worst view's detection probability is at or below the configured level (default 0.5: a
//! coin toss, 0.84 JND on the VDP's scale, where 1 JND is the ModelFest observers' 84 %-correct
//! threshold). Each row also gives the VDP's probability and JND at the reported size. The
//! search doubles the diameter from 4 px until the LOD becomes visible, then bisects on the
//! logarithm of the diameter to 2 %; the smallest distance beyond which the LOD is imperceptible
//! is the distance of the largest invisible diameter. A LOD with an engine switch distance
//! (`switch_m`) has the range widened to take in its diameter there (down to 1 px, up to the
//! display's height), so the gate's question — visible where the engine uses it? — has an answer.
//! Where the search hits a limit the row says which bound it is (`DistanceBound`): visible even
//! at the smallest size (imperceptible only farther than the distance given) or invisible up to
//! the largest (imperceptible from the distance given at the latest). Views: the `views` worst
//! views of the full-size evaluation (by FLIP, else the first metric; `eval::run::worst_first`
//! orders them), since the worst view decides.
//!
//! To look at a verdict: [`probe_views`] gives the probe renders at one size (both images and
//! each view's probability, JND and FLIP), [`search_trace`] the worst view's values at every size
//! the search probed, [`visibility_at`] the worst view's values at a distance in metres.
//!
//! Engine parameters at that distance, each from the bound that engine itself computes (not from
//! lodeval's sphere; [`crate::mesh::EngineBounds`] cites where each is defined): Unity's LODGroup
//! relative screen height (`LODGroup.size`, the box's largest side, over the frustum height:
//! size / (2·D·tan(fov/2)), `screen_height_fraction`), Unreal's `ScreenSize` (max(P₀₀, P₁₁)·R/D
//! with R the farthest vertex from the box centre, as `ComputeBoundsScreenSize` computes it), the
//! screen coverage of glTF's `MSFT_lod` as Babylon.js evaluates it (π(R/D)² over the screen area
//! at unit distance, R half the box diagonal), and meshoptimizer's error projected to pixels
//! (error · k / D). Engines measure D to the box centre; the parameters are taken at D plus the
//! box-to-sphere centre offset, so a switch there is never nearer than the measured distance.
//!
//! Caveat, stated rather than hidden: probabilities are taken as-is from one render per view;
//! the VDP is not guaranteed monotone in size, so the bisection finds *a* crossing, the nearest to
//! the largest size where the LOD was first seen.

use std::collections::{BTreeMap, HashMap};
use std::sync::{Arc, Mutex};

use glam::Vec3;
use rayon::prelude::*;

use super::config::{DistanceConfig, SampleCount, ViewingConfig};
use super::tables::{DistanceBound, DistanceRow, round7};
use crate::error::Result;
use crate::image::LinearImage;
use crate::metric::flip::{Flip, FlipPrepared};
use crate::metric::vdp::{Vdp, VdpPrepared};
use crate::raster::{self, RenderScene, RenderSettings, SamplePattern};
use crate::scene::{Camera, Projection};

/// The display geometry used to convert between distances and pixels.
#[derive(Debug, Clone, Copy)]
pub struct Screen {
    /// Pixels per radian at the centre (k).
    pub k: f64,
    /// Display width in pixels.
    pub width_px: f64,
    /// Display height in pixels.
    pub height_px: f64,
}

impl Screen {
    /// From the config's viewing section.
    pub fn new(v: &ViewingConfig) -> Screen {
        let k = match v.ppd {
            // ppd given directly: pixels per radian = ppd · 180/π.
            Some(p) => p.0 * 180.0 / std::f64::consts::PI,
            None => v.distance_m.0 * v.display_px.0 / v.display_width_m.0,
        };
        Screen {
            k,
            width_px: v.display_px.0,
            height_px: v.display_height_px.0,
        }
    }

    /// On-screen diameter in pixels of a sphere of radius `r` at distance `d` (same units).
    pub fn diameter_px(&self, r: f64, d: f64) -> f64 {
        2.0 * self.k * r / (d * d - r * r).max(1e-30).sqrt()
    }

    /// Distance at which a sphere of radius `r` appears `diameter` pixels wide.
    pub fn distance_for(&self, r: f64, diameter: f64) -> f64 {
        r * (1.0 + (2.0 * self.k / diameter).powi(2)).sqrt()
    }

    /// Each engine's LOD parameter when the viewer is `d` metres from the centre of lodeval's
    /// sphere: (Unity's relative screen height, Unreal's `ScreenSize`, glTF `MSFT_screencoverage`),
    /// each from the bound that engine uses ([`EngineScale`]). An engine measures its distance to
    /// the box centre, up to `offset_m` nearer or farther than lodeval's depending on the
    /// direction; the parameters are taken at `d + offset_m`, the far end, so that an engine
    /// switching at them never shows the LOD nearer than `d`.
    fn engine_params(&self, e: &EngineScale, d: f64) -> (f64, f64, f64) {
        let d = d + e.offset_m;
        // tan(fov_y / 2) of the display's camera: half the height over k.
        let tan_half = self.height_px / (2.0 * self.k);
        let unity = e.unity_size_m / (2.0 * d * tan_half);
        // Unreal: ScreenMultiple = max(P₀₀, P₁₁)/2, radius · multiple / max(1 cm, D), times 2.
        let (p00, p11) = (2.0 * self.k / self.width_px, 2.0 * self.k / self.height_px);
        let unreal = p00.max(p11) * e.unreal_radius_m / d.max(0.01);
        // Babylon: π (R / D)² over the screen's area at unit distance, 4 tan²(fov/2) · aspect.
        let coverage = std::f64::consts::PI * (e.babylon_radius_m / d).powi(2)
            / (4.0 * tan_half * tan_half * self.width_px / self.height_px);
        (unity, unreal, coverage)
    }
}

/// The original's bounds as each engine computes them ([`crate::mesh::EngineBounds`]), in metres,
/// and the distance from their reference point (the box centre) to lodeval's sphere centre.
#[derive(Debug, Clone, Copy)]
pub struct EngineScale {
    /// Unity `LODGroup.size`: the box's largest side.
    pub unity_size_m: f64,
    /// Unreal `SphereRadius`: the farthest vertex from the box centre.
    pub unreal_radius_m: f64,
    /// Babylon.js `BoundingSphere` radius: half the box diagonal.
    pub babylon_radius_m: f64,
    /// Box centre to the minimal sphere's centre.
    pub offset_m: f64,
}

impl EngineScale {
    /// From the original mesh and its metres per model unit.
    pub fn new(mesh: &crate::mesh::Mesh, meters_per_unit: f64) -> EngineScale {
        let b = mesh.engine_bounds();
        let offset = b.center.distance(mesh.bounding_sphere().center);
        EngineScale {
            unity_size_m: b.unity_size as f64 * meters_per_unit,
            unreal_radius_m: b.unreal_radius as f64 * meters_per_unit,
            babylon_radius_m: b.babylon_radius as f64 * meters_per_unit,
            offset_m: offset as f64 * meters_per_unit,
        }
    }
}

impl<'a> DistanceJob<'a> {
    /// `lod` against `original` from `directions`: one metre per model unit, no simplifier
    /// error, unnamed rows, no switch distance, the original's probes rendered afresh.
    pub fn new(original: &'a RenderScene, lod: &'a RenderScene, directions: Vec<Vec3>) -> Self {
        DistanceJob {
            original,
            lod,
            directions,
            meters_per_unit: 1.0,
            simplifier_error: None,
            names: ("", "", 0),
            switch_m: None,
            originals: None,
        }
    }
}

/// Smallest on-screen diameter probed, pixels.
pub(super) const MIN_PROBE: u32 = 4;

/// What a search needs about one LOD: [`DistanceJob::new`], then set what is known.
#[derive(Debug)]
#[non_exhaustive]
pub struct DistanceJob<'a> {
    /// The original.
    pub original: &'a RenderScene,
    /// The LOD.
    pub lod: &'a RenderScene,
    /// View directions to test (the worst views first).
    pub directions: Vec<Vec3>,
    /// Metres per model unit.
    pub meters_per_unit: f64,
    /// The simplifier's error estimate in model units, if known.
    pub simplifier_error: Option<f64>,
    /// Asset and LOD names and the LOD's triangle count, for the rows.
    pub names: (&'a str, &'a str, usize),
    /// The engine's switch distance for this LOD, metres, if the gate checks one: the search
    /// then also covers the on-screen size at that distance, so the gate gets an answer there.
    pub switch_m: Option<f64>,
    /// The original's probe renders, shared by the searches of every LOD of one asset (they
    /// probe the same diameters from mostly the same views); `None`: this search's own.
    pub originals: Option<&'a OriginalProbes>,
}

/// The original's side of each probe — its render at one diameter from one direction, prepared
/// for the VDP (and FLIP) — kept for the searches of all LODs of one asset, which run in
/// parallel. Valid for one original scene, one viewing condition and one set of render settings.
/// Entries are pure functions of their key, so which search computes one first does not change
/// any result.
#[derive(Debug, Default)]
pub struct OriginalProbes {
    entries: Mutex<HashMap<ProbeKey, Arc<PreparedOriginal>>>,
}

/// (diameter in pixels' bits, view direction's bits, samples per side, with FLIP).
type ProbeKey = (u64, [u32; 3], u32, bool);

#[derive(Debug)]
struct PreparedOriginal {
    vdp: VdpPrepared,
    flip: Option<FlipPrepared>,
}

impl OriginalProbes {
    /// An empty cache.
    pub fn new() -> OriginalProbes {
        OriginalProbes::default()
    }

    fn get_or_make(
        &self,
        key: ProbeKey,
        make: impl FnOnce() -> Result<PreparedOriginal>,
    ) -> Result<Arc<PreparedOriginal>> {
        if let Some(p) = self.lock().get(&key) {
            return Ok(p.clone());
        }
        // Made outside the lock: two searches may make the same entry at once (the same
        // values), and the first one stored is kept.
        let made = Arc::new(make()?);
        Ok(self.lock().entry(key).or_insert(made).clone())
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<ProbeKey, Arc<PreparedOriginal>>> {
        // A poisoned lock only means another search panicked; the map itself is consistent.
        self.entries.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Renders the original and the LOD as the display's viewer sees them at a given on-screen size
/// and scores the pair, worst over the job's views.
struct Prober<'a> {
    job: &'a DistanceJob<'a>,
    display: Screen,
    vdp: Vdp,
    /// FLIP, where a criterion or the caller needs it.
    flip: Option<Flip>,
    sphere: crate::mesh::Sphere,
    settings: RenderSettings,
    side: u32,
}

impl<'a> Prober<'a> {
    fn new(
        job: &'a DistanceJob<'a>,
        viewing: &ViewingConfig,
        settings: &RenderSettings,
        side: u32,
        with_flip: bool,
    ) -> Prober<'a> {
        let view = viewing.viewing();
        Prober {
            job,
            display: Screen::new(viewing),
            vdp: Vdp::new(&view, viewing.display()),
            flip: with_flip.then(|| Flip::new(view.ppd() as f32)),
            sphere: job.original.mesh().bounding_sphere(),
            settings: *settings,
            side,
        }
    }

    /// The camera and render settings of the probe at on-screen diameter `diameter` (pixels)
    /// seen from direction `dir`: the viewer at the distance that gives that diameter, a square
    /// crop around the disc with a 10 % + 4 px border on each side, at the display's pixel scale.
    fn camera(&self, diameter: f64, dir: Vec3) -> (Camera, RenderSettings) {
        let (display, sphere) = (&self.display, self.sphere);
        let r_units = sphere.radius as f64;
        let d_units = display.distance_for(r_units, diameter);
        let size = (diameter * 1.1).ceil() as u32 + 8;
        let mut s = self.settings;
        s.width = size;
        s.height = size;
        s.samples = SamplePattern::Rotated(self.side);
        // The crop's field of view at the display's pixel scale.
        let fov = 2.0 * ((size as f64 / 2.0) / display.k).atan();
        let mut cam = Camera::frame_sphere(sphere, dir, 30.0, 1.0, 0.0);
        let eye_dir = cam.to_eye();
        cam.eye = sphere.center + eye_dir * d_units as f32;
        cam.projection = Projection::Perspective {
            fov_y_deg: fov.to_degrees() as f32,
        };
        cam.near = ((d_units - r_units * 1.01) as f32).max(d_units as f32 * 1e-4);
        cam.far = (d_units + r_units * 1.01) as f32;
        (cam, s)
    }

    /// The original's prepared render for a probe.
    fn prepare_original(&self, image: &LinearImage) -> PreparedOriginal {
        PreparedOriginal {
            vdp: self.vdp.prepare(image),
            flip: self.flip.as_ref().map(|f| f.prepare(image)),
        }
    }

    /// One view's scores: the LOD's render against the original's prepared one.
    fn score(&self, original: &PreparedOriginal, lod: &LinearImage) -> Result<Probe> {
        let v = self
            .vdp
            .compare_prepared(&original.vdp, &self.vdp.prepare(lod))?;
        let f = match (&self.flip, &original.flip) {
            (Some(flip), Some(fa)) => flip.compare_prepared(fa, &flip.prepare(lod))?.mean,
            _ => 0.0,
        };
        Ok(Probe {
            vdp: v.probability,
            vdp_jnd: v.jnd,
            flip: f,
            complete: true,
        })
    }

    /// Worst over the views at on-screen diameter `diameter` (pixels); `originals` holds (and
    /// receives) the original's prepared renders. Views run two at a time in parallel, in the
    /// job's order; where `enough` holds for the worst so far the rest are skipped (the worst can
    /// only grow) and the probe comes back marked incomplete. The worst is a maximum, the same in
    /// any order.
    fn at(
        &self,
        diameter: f64,
        originals: &OriginalProbes,
        enough: Option<&dyn Fn(&Probe) -> bool>,
    ) -> Result<Probe> {
        let view = |dir: Vec3| -> Result<Probe> {
            let (cam, s) = self.camera(diameter, dir);
            let key = (
                diameter.to_bits(),
                cam.to_eye().to_array().map(f32::to_bits),
                self.side,
                self.flip.is_some(),
            );
            let a = originals.get_or_make(key, || {
                let a = LinearImage::from(&raster::render(self.job.original, &cam, &s)?);
                Ok(self.prepare_original(&a))
            })?;
            let b = LinearImage::from(&raster::render(self.job.lod, &cam, &s)?);
            self.score(&a, &b)
        };
        let mut worst = Probe {
            vdp: 0.0,
            vdp_jnd: 0.0,
            flip: 0.0,
            complete: true,
        };
        let chunks = self.job.directions.chunks(2);
        let n = chunks.len();
        for (i, pair) in chunks.enumerate() {
            let per_view = pair
                .par_iter()
                .map(|&dir| view(dir))
                .collect::<Result<Vec<_>>>()?;
            worst = per_view.iter().fold(worst, |w, p| Probe {
                vdp: w.vdp.max(p.vdp),
                vdp_jnd: w.vdp_jnd.max(p.vdp_jnd),
                flip: w.flip.max(p.flip),
                complete: true,
            });
            if i + 1 < n && enough.is_some_and(|e| e(&worst)) {
                worst.complete = false;
                break;
            }
        }
        Ok(worst)
    }
}

/// One view of a probe, rendered and scored as [`search`] renders and scores it.
#[derive(Debug, Clone)]
pub struct ViewProbe {
    /// The view's direction (from the object's centre towards the eye).
    pub direction: Vec3,
    /// The original's render.
    pub original: LinearImage,
    /// The LOD's render.
    pub lod: LinearImage,
    /// VDP detection probability of the pair.
    pub vdp: f64,
    /// VDP difference in JND.
    pub vdp_jnd: f64,
    /// FLIP mean of the pair.
    pub flip: f64,
}

/// The probe renders at on-screen diameter `diameter_px`, one per view of `job` in its order,
/// with each view's scores: what [`search`] looks at for that size (its decision is the worst
/// view's). For looking at a verdict, or testing one.
pub fn probe_views(
    job: &DistanceJob,
    viewing: &ViewingConfig,
    settings: &RenderSettings,
    samples: SampleCount,
    diameter_px: f64,
) -> Result<Vec<ViewProbe>> {
    let prober = Prober::new(job, viewing, settings, samples.side(), true);
    job.directions
        .par_iter()
        .map(|&dir| {
            let (cam, s) = prober.camera(diameter_px, dir);
            let original = LinearImage::from(&raster::render(job.original, &cam, &s)?);
            let lod = LinearImage::from(&raster::render(job.lod, &cam, &s)?);
            let p = prober.score(&prober.prepare_original(&original), &lod)?;
            Ok(ViewProbe {
                direction: cam.to_eye(),
                original,
                lod,
                vdp: p.vdp,
                vdp_jnd: p.vdp_jnd,
                flip: p.flip,
            })
        })
        .collect()
}

/// How visible `job`'s LOD is at `distance_m` metres (viewer to the bounding sphere's centre):
/// the worst of its views' VDP detection probability, VDP JND and FLIP mean, rendered as
/// [`search`] renders its probes (`samples` per pixel, at most [`crate::limits::IMAGE_SIDE`]
/// pixels across).
pub fn visibility_at(
    job: &DistanceJob,
    viewing: &ViewingConfig,
    settings: &RenderSettings,
    samples: SampleCount,
    distance_m: f64,
) -> Result<(f64, f64, f64)> {
    let prober = Prober::new(job, viewing, settings, samples.side(), true);
    let r_m = prober.sphere.radius as f64 * job.meters_per_unit;
    let diameter = prober
        .display
        .diameter_px(r_m, distance_m.max(r_m * 1.0001))
        .min(crate::limits::IMAGE_SIDE.max as f64 / 1.1 - 16.0);
    let own = OriginalProbes::new();
    let p = prober.at(diameter, job.originals.unwrap_or(&own), None)?;
    Ok((p.vdp, p.vdp_jnd, p.flip))
}

/// "Visible at this probe?"
type Criterion = Box<dyn Fn(&Probe) -> bool>;

/// Worst-view scores at one on-screen diameter.
#[derive(Debug, Clone, Copy)]
struct Probe {
    vdp: f64,
    vdp_jnd: f64,
    flip: f64,
    /// Every view scored: false where the probe stopped early, already visible by every
    /// criterion (its decisions hold, its values are lower bounds).
    complete: bool,
}

/// The worst view's values at one on-screen size the search probed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbedSize {
    /// On-screen diameter of the bounding sphere, pixels.
    pub diameter_px: u32,
    /// Worst view's VDP detection probability.
    pub vdp: f64,
    /// Worst view's VDP JND.
    pub vdp_jnd: f64,
    /// Worst view's FLIP mean.
    pub flip: f64,
    /// Every view scored; false where the probe stopped early, already visible by every
    /// criterion (its decisions hold, its values are lower bounds).
    pub complete: bool,
}

/// Find the distances for one LOD: one row for the VDP criterion and one for FLIP if configured.
pub fn search(
    job: &DistanceJob,
    config: &DistanceConfig,
    viewing: &ViewingConfig,
    settings: &RenderSettings,
) -> Result<Vec<DistanceRow>> {
    search_probing(job, config, viewing, settings, true).map(|(rows, _)| rows)
}

/// [`search`], with the values at every size it probed, smallest first.
pub fn search_trace(
    job: &DistanceJob,
    config: &DistanceConfig,
    viewing: &ViewingConfig,
    settings: &RenderSettings,
) -> Result<(Vec<DistanceRow>, Vec<ProbedSize>)> {
    search_probing(job, config, viewing, settings, true)
}

/// [`search`], with probes that stop early (`early`) or score every view (the test's reference),
/// and the values at every size probed.
fn search_probing(
    job: &DistanceJob,
    config: &DistanceConfig,
    viewing: &ViewingConfig,
    settings: &RenderSettings,
    early: bool,
) -> Result<(Vec<DistanceRow>, Vec<ProbedSize>)> {
    let display = Screen::new(viewing);
    let prober = Prober::new(
        job,
        viewing,
        settings,
        config.samples.side(),
        config.flip_mean.is_some(),
    );
    let own = OriginalProbes::new();
    let originals = job.originals.unwrap_or(&own);
    let r_units = prober.sphere.radius as f64;
    // The sizes searched: MIN_PROBE to max_diameter_px, widened to take in the size at the
    // switch distance (up to the display's height) so that the gate's question has an answer.
    let r_m = r_units * job.meters_per_unit;
    let (min_d, max_d) = probe_range(&display, r_m, config, job.switch_m);
    let engines = EngineScale::new(job.original.mesh(), job.meters_per_unit);
    let mut criteria: Vec<(String, Criterion)> = vec![(
        format!("vdp_p{}", config.probability.0),
        Box::new({
            let level = config.probability.0;
            move |p: &Probe| p.vdp > level
        }),
    )];
    if let Some(f) = config.flip_mean {
        criteria.push((
            format!("flip_mean{}", f.0),
            Box::new(move |p: &Probe| p.flip > f.0),
        ));
    }
    // A probe may stop once every criterion sees the LOD (its decisions are then final); one
    // whose values are reported is completed.
    let all_visible = |p: &Probe| criteria.iter().all(|(_, visible)| visible(p));
    let mut probes: BTreeMap<u32, Probe> = BTreeMap::new();
    let mut probe = |diameter: u32, full: bool| -> Result<Probe> {
        if let Some(p) = probes.get(&diameter)
            && (p.complete || !full)
        {
            return Ok(*p);
        }
        let enough: Option<&dyn Fn(&Probe) -> bool> = if full || !early {
            None
        } else {
            Some(&all_visible)
        };
        let worst = prober.at(diameter as f64, originals, enough)?;
        probes.insert(diameter, worst);
        Ok(worst)
    };
    let mut rows = Vec::new();
    for (criterion, visible) in &criteria {
        let (lo, hi) = threshold_diameter(min_d, max_d, |d| Ok(visible(&probe(d, false)?)))?;
        // Imperceptible beyond the distance of the largest invisible diameter. When the search hit a
        // limit (visible at the smallest probe, or invisible up to the largest) it is a bound.
        let bound = match (hi, lo) {
            (Some(_), 0) => DistanceBound::AtLeast,
            (Some(_), _) => DistanceBound::Measured,
            (None, _) => DistanceBound::AtMost,
        };
        let diameter = if lo == 0 { min_d } else { lo };
        let at = probe(diameter, true)?;
        let d_m = display.distance_for(r_m, diameter as f64);
        let (fraction, unreal, coverage) = display.engine_params(&engines, d_m);
        rows.push(DistanceRow {
            asset: job.names.0.to_string(),
            lod: job.names.1.to_string(),
            triangles: job.names.2,
            criterion: criterion.clone(),
            imperceptible_beyond_m: round7(d_m),
            screen_height_fraction: round7(fraction),
            unreal_screen_size: round7(unreal),
            screen_coverage: round7(coverage),
            pixel_error: job
                .simplifier_error
                .map(|e| round7(e * job.meters_per_unit * display.k / d_m)),
            diameter_px: round7(display.diameter_px(r_m, d_m)),
            resolved: bound == DistanceBound::Measured,
            renderer: crate::backend::CPU_RENDERER.to_string(),
            vdp_probability: Some(round7(at.vdp)),
            vdp_jnd: Some(round7(at.vdp_jnd)),
            bound,
        });
    }
    let probed = probes
        .iter()
        .map(|(&diameter_px, p)| ProbedSize {
            diameter_px,
            vdp: p.vdp,
            vdp_jnd: p.vdp_jnd,
            flip: p.flip,
            complete: p.complete,
        })
        .collect();
    Ok((rows, probed))
}

/// The search over on-screen diameters from `min_d` to `max_d` pixels for where `visible` turns
/// true: double from the smallest until visible or at the limit, then bisect on log(diameter) to
/// 2 %. Returns the largest diameter known invisible (0: none) and the smallest known visible
/// (`None`: invisible up to `max_d`).
fn threshold_diameter(
    min_d: u32,
    max_d: u32,
    mut visible: impl FnMut(u32) -> Result<bool>,
) -> Result<(u32, Option<u32>)> {
    let mut lo = 0u32;
    let mut hi = None;
    let mut d = min_d;
    loop {
        if visible(d)? {
            hi = Some(d);
            break;
        }
        lo = d;
        if d >= max_d {
            break;
        }
        d = (d * 2).min(max_d);
    }
    if let Some(mut h) = hi {
        while lo > 0 && (h as f64) > lo as f64 * 1.02 && h - lo > 1 {
            let mid = ((lo as f64 * h as f64).sqrt().round() as u32).clamp(lo + 1, h - 1);
            if visible(mid)? {
                h = mid;
            } else {
                lo = mid;
            }
        }
    }
    Ok((lo, hi))
}

/// The smallest and largest on-screen diameters searched, pixels: [`MIN_PROBE`] to
/// `max_diameter_px`, widened to take in the diameter at `switch_m` (at least 1 px, at most the
/// display's height: beyond it the object is larger than the screen, and the gate says it cannot
/// check there).
fn probe_range(
    display: &Screen,
    r_m: f64,
    config: &DistanceConfig,
    switch_m: Option<f64>,
) -> (u32, u32) {
    let max_d = config.max_diameter_px.0.max(MIN_PROBE);
    let (mut lo, mut hi) = (MIN_PROBE.min(max_d), max_d);
    if let Some(s) = switch_m {
        let cap = (display.height_px as u32).max(max_d);
        let at = if s > r_m {
            display.diameter_px(r_m, s)
        } else {
            f64::INFINITY // the viewer inside the bounding sphere
        };
        lo = lo.min(at.floor().clamp(1.0, cap as f64) as u32);
        hi = hi.max(at.ceil().clamp(1.0, cap as f64) as u32);
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probes_that_stop_early_give_the_rows_of_full_probes() {
        // Spot against its 5 % LOD from four views, both criteria: the early stops change no
        // decision and no reported value, and a shared cache of the original's probes changes
        // nothing either.
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("reference/models/spot/spot_mtl.obj");
        let mesh = crate::mesh::load(&path, &Default::default()).unwrap();
        let lod = crate::simplify::chain(
            &mesh,
            crate::simplify::Method::Meshopt,
            &[crate::simplify::Goal::Ratio(0.05)],
        )
        .unwrap()
        .remove(0)
        .mesh;
        let (original, lod) = (
            RenderScene::of(std::sync::Arc::new(mesh)),
            RenderScene::of(std::sync::Arc::new(lod)),
        );
        let shared = OriginalProbes::new();
        let job = |originals| DistanceJob {
            original: &original,
            lod: &lod,
            directions: crate::scene::Rig::Dodecahedron.directions()[..4].to_vec(),
            meters_per_unit: 0.5,
            simplifier_error: None,
            names: ("spot", "r5", 0),
            switch_m: None,
            originals,
        };
        let config = DistanceConfig {
            samples: SampleCount(4),
            max_diameter_px: crate::eval::config::ImageSize(96),
            ..DistanceConfig::default()
        };
        let (viewing, settings) = (ViewingConfig::default(), RenderSettings::DEFAULT);
        let (full, trace) =
            search_probing(&job(None), &config, &viewing, &settings, false).unwrap();
        let (early, _) = search_probing(&job(None), &config, &viewing, &settings, true).unwrap();
        let cached = search(&job(Some(&shared)), &config, &viewing, &settings).unwrap();
        assert_eq!(full.len(), 2);
        assert_eq!(full, early);
        assert_eq!(full, cached);
        assert!(!shared.lock().is_empty());
        // The trace holds every size probed, smallest first, the reported one among them with
        // the row's values; the VDP row's size is invisible there, and the next size probed up
        // visible (unless the search hit its limit).
        assert!(
            trace
                .windows(2)
                .all(|w| w[0].diameter_px < w[1].diameter_px)
        );
        let row = &full[0];
        let at = trace
            .iter()
            .position(|p| p.diameter_px as f64 == row.diameter_px.round())
            .expect("the reported size was probed");
        assert_eq!(Some(round7(trace[at].vdp)), row.vdp_probability);
        assert!(trace[at].vdp <= config.probability.0);
        if row.bound == DistanceBound::Measured {
            assert!(trace[at + 1].vdp > config.probability.0, "{trace:?}");
        }
        // The probe renders at that size: one per view, the crop the search renders, and the
        // worst view's values are the row's.
        let views = probe_views(
            &job(None),
            &viewing,
            &settings,
            config.samples,
            trace[at].diameter_px as f64,
        )
        .unwrap();
        assert_eq!(views.len(), 4);
        let side = (trace[at].diameter_px as f64 * 1.1).ceil() as usize + 8;
        assert!(
            views
                .iter()
                .all(|v| v.original.width() == side && v.lod.width() == side)
        );
        let worst = views.iter().map(|v| v.vdp).fold(0.0, f64::max);
        assert_eq!(worst, trace[at].vdp);
        let worst_jnd = views.iter().map(|v| v.vdp_jnd).fold(0.0, f64::max);
        assert_eq!(Some(round7(worst_jnd)), row.vdp_jnd);
    }

    #[test]
    fn distance_and_diameter_are_inverse() {
        let d = Screen::new(&ViewingConfig::default());
        // 0.7 m · 3840 / 0.7 m = 3840 px per radian.
        assert!((d.k - 3840.0).abs() < 1e-9);
        for diameter in [3.0, 50.0, 700.0] {
            let dist = d.distance_for(0.5, diameter);
            assert!((d.diameter_px(0.5, dist) - diameter).abs() < 1e-9);
        }
    }

    #[test]
    fn engine_parameters_follow_each_engines_own_bound() {
        // The default display: 3840 × 2160 px, k = 3840 px/rad, so tan(fov_y/2) = 2160/7680.
        let d = Screen::new(&ViewingConfig::default());
        // A unit cube (metres) 10 m away, its box centre 0.1 m from the sphere's: engines are
        // evaluated at 10.1 m. Unity: side / (2 D tan) ; Unreal: (2k/h) · (√3/2) / D ;
        // Babylon: π (√3/2 / D)² / (4 tan² · 16/9).
        let e = EngineScale {
            unity_size_m: 1.0,
            unreal_radius_m: 3f64.sqrt() / 2.0,
            babylon_radius_m: 3f64.sqrt() / 2.0,
            offset_m: 0.1,
        };
        let (unity, unreal, coverage) = d.engine_params(&e, 10.0);
        let tan = 2160.0 / 7680.0;
        assert!((unity - 1.0 / (2.0 * 10.1 * tan)).abs() < 1e-12);
        assert!((unreal - 7680.0 / 2160.0 * 0.8660254037844386 / 10.1).abs() < 1e-12);
        let expected =
            std::f64::consts::PI * (0.75 / (10.1f64 * 10.1)) / (4.0 * tan * tan * 3840.0 / 2160.0);
        assert!((coverage - expected).abs() < 1e-12, "{coverage} {expected}");
        // Unity's relative height is the side over the frustum's height there: 1 m of 5.68 m.
        assert!((unity - 0.1760).abs() < 1e-4, "{unity}");
    }
}
