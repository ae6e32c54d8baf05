//! Per-view evaluation of an MT node (Williams et al. 2003 §3, §5.2–5.4): is it visible, is it on
//! the silhouette, the worst-case contrast it can induce, the worst-case (lowest) spatial frequency
//! of the features it can change, and from these its *imperceptibility distance* by inverting the
//! contrast sensitivity function. Also the three comparison criteria of §6 (object-space error,
//! screen-space texture deviation, and screen-space deviation ×10 on the silhouette).
//!
//! - Visibility (§5.3, Luebke & Erikson 1997): the node's bounding sphere against the view frustum,
//!   and its silhouette normal cone against the cone of directions from the eye to the sphere.
//!   Off-screen or wholly back-facing nodes are invisible: distance 0.
//! - Contrast (§3.3, §5.2, §5.4): Michelson contrast (L_max − L_min)/(L_max + L_min) of the display
//!   luminances of the darkest and brightest shading the node can show: the intrinsic (texture ×
//!   material × vertex colour) luminance range, lit by the renderer's Blinn–Phong model (OpenGL
//!   fixed function for an infinite light and viewer) over the shading normal cone — diffuse from the
//!   normals nearest to and farthest from L, the highlight likewise with H. Silhouette nodes get the
//!   maximal contrast, 1.
//! - Frequency (§3.2, §5.4): a feature spanning n degrees has its lowest frequency at 1/(2n) cycles
//!   per degree. The feature is the node's bounding sphere (diameter) under per-vertex lighting
//!   (`gouraud`), and twice the texture deviation otherwise; both are projected at the sphere's
//!   nearest point to the eye. The frequency is clamped to no lower than the CSF's peak (Fig. 3).
//! - Imperceptibility distance (§3.4): the contrast's threshold frequency f_t (the inverted,
//!   clamped CSF) against the feature's frequency f at the current viewing distance D: frequencies
//!   scale with distance, so the feature becomes invisible from D·f_t/f on (metres).
//!
//! Decisions: the CSF is Daly's (Rushmeier et al. form, `metric::csf`) scaled to an absolute peak
//! sensitivity of [`PEAK_SENSITIVITY`] (Daly's P = 250, the VDP default); display luminance is the
//! VDP's office monitor (0.5–100 cd/m²); lights and ambient are the scene's.

use glam::{Mat4, Vec3, Vec4};

use super::bounds::Range;
use super::preprocess::{MaterialFacts, NodeData};
use crate::metric::csf::{ClampedCsf, daly_rushmeier};
use crate::metric::vdp::Display;
use crate::raster::Shading;
use crate::scene::{Camera, Light, Projection, Viewing};

/// Peak contrast sensitivity (1 / threshold contrast) of the scaled CSF.
pub const PEAK_SENSITIVITY: f64 = 250.0;

/// The error criterion the budget refinement minimises.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Deserialize, serde::Serialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Criterion {
    /// Williams et al.: imperceptibility distance.
    #[value(help = "The paper's imperceptibility distance")]
    Perceptual,
    /// View-independent object-space texture deviation.
    ObjectSpace,
    /// Texture deviation projected to pixels (view-dependent APS).
    #[value(help = "Texture deviation projected to pixels")]
    ScreenSpace,
    /// Screen-space deviation, ×10 on the silhouette.
    #[serde(rename = "silhouette-10")]
    #[value(name = "silhouette-10")]
    Silhouette10,
}

impl Criterion {
    /// All four, in the paper's order.
    pub const ALL: [Criterion; 4] = [
        Criterion::Perceptual,
        Criterion::ObjectSpace,
        Criterion::ScreenSpace,
        Criterion::Silhouette10,
    ];

    /// Name in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Criterion::Perceptual => "perceptual",
            Criterion::ObjectSpace => "object-space",
            Criterion::ScreenSpace => "screen-space",
            Criterion::Silhouette10 => "silhouette-10",
        }
    }
}

/// How a node sits in a view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Visibility {
    /// Outside the frustum.
    OffScreen,
    /// Wholly back-facing.
    BackFacing,
    /// Wholly front-facing.
    FrontFacing,
    /// May lie on the silhouette.
    Silhouette,
}

/// A light resolved for the view: direction, half vector, luminance of its colour.
#[derive(Debug, Clone, Copy)]
struct ViewLight {
    l: Vec3,
    h: Vec3,
    y: f32,
}

/// Everything the evaluation needs of one view.
#[derive(Debug, Clone)]
pub struct ViewModel {
    eye: Vec3,
    to_eye: Vec3,
    perspective: bool,
    planes: [Vec4; 6],
    near: f32,
    /// Pixels per model unit at distance 1 (perspective) or at any distance (orthographic).
    px_scale: f32,
    lights: Vec<ViewLight>,
    ambient: f32,
    shading: Shading,
    ppd: f64,
    distance_m: f64,
    csf: ClampedCsf,
    display: Display,
}

impl ViewModel {
    /// The view of `camera` on an image `height` pixels tall, shown at `viewing`.
    pub fn new(
        camera: &Camera,
        width: u32,
        height: u32,
        shading: Shading,
        lights: &[Light],
        ambient: f32,
        viewing: &Viewing,
    ) -> ViewModel {
        let aspect = width as f32 / height as f32;
        let m = camera.projection(aspect) * camera.view();
        let planes = frustum_planes(&m);
        let (perspective, px_scale) = match camera.projection {
            Projection::Perspective { fov_y_deg } => (
                true,
                height as f32 / (2.0 * (fov_y_deg.to_radians() * 0.5).tan()),
            ),
            Projection::Orthographic { half_height } => {
                (false, height as f32 / (2.0 * half_height))
            }
        };
        let to_eye = camera.to_eye();
        let lights = lights
            .iter()
            .filter_map(|l| l.resolve(camera))
            .map(|(dir, color)| ViewLight {
                l: dir,
                h: (dir + to_eye).normalize_or_zero(),
                y: crate::color::luminance(color),
            })
            .collect();
        let peak = daly_rushmeier(ClampedCsf::daly().peak_frequency());
        ViewModel {
            eye: camera.eye,
            to_eye,
            perspective,
            planes,
            near: camera.near,
            px_scale,
            lights,
            ambient,
            shading,
            ppd: viewing.ppd(),
            distance_m: viewing.distance_m,
            csf: ClampedCsf::new(move |f| PEAK_SENSITIVITY / peak * daly_rushmeier(f)),
            display: Display::DEFAULT,
        }
    }

    /// Where the node is in this view.
    pub fn visibility(&self, d: &NodeData) -> Visibility {
        let (c, r) = (d.ball.center, d.ball.radius.max(0.0));
        if self.planes.iter().any(|p| p.truncate().dot(c) + p.w < -r) {
            return Visibility::OffScreen;
        }
        if d.silhouette.is_empty() {
            return Visibility::Silhouette;
        }
        // Directions from the sphere towards the eye lie within β of `towards`.
        let (towards, beta) = if self.perspective {
            let v = self.eye - c;
            let dist = v.length();
            if dist <= r {
                return Visibility::Silhouette;
            }
            (v / dist, (r / dist).asin())
        } else {
            (self.to_eye, 0.0)
        };
        let phi = d.silhouette.axis.dot(towards).clamp(-1.0, 1.0).acos();
        let spread = d.silhouette.half_angle + beta;
        let half_pi = std::f32::consts::FRAC_PI_2;
        if phi + spread < half_pi {
            Visibility::FrontFacing
        } else if phi - spread > half_pi {
            Visibility::BackFacing
        } else {
            Visibility::Silhouette
        }
    }

    /// Pixels per model unit at the node's nearest point to the eye.
    pub fn pixels_per_unit(&self, d: &NodeData) -> f32 {
        if !self.perspective {
            return self.px_scale;
        }
        let dist = (d.ball.center.distance(self.eye) - d.ball.radius.max(0.0)).max(self.near);
        self.px_scale / dist
    }

    /// The range of linear luminance the node can show under this view's lighting.
    pub fn lit_range(&self, d: &NodeData, m: &MaterialFacts) -> Range {
        let t = d.luminance;
        match self.shading {
            Shading::Gouraud | Shading::Phong | Shading::NormalMapped => {
                let (mut dlo, mut dhi) = (self.ambient, self.ambient);
                let (mut slo, mut shi) = (0.0f32, 0.0f32);
                for l in &self.lights {
                    let (nl_lo, nl_hi) = d.shading.cos_range(l.l);
                    let (nh_lo, nh_hi) = d.shading.cos_range(l.h);
                    dlo += l.y * nl_lo.max(0.0);
                    dhi += l.y * nl_hi.max(0.0);
                    if nl_hi > 0.0 {
                        shi += l.y * nh_hi.max(0.0).powf(m.shininess);
                    }
                    if nl_lo > 0.0 {
                        slo += l.y * nh_lo.max(0.0).powf(m.shininess);
                    }
                }
                Range {
                    lo: t.lo * dlo + m.specular * slo,
                    hi: t.hi * dhi + m.specular * shi,
                }
            }
            _ => t,
        }
    }

    /// Worst-case Michelson contrast of the node (1 on the silhouette, 0 if invisible).
    pub fn contrast(&self, d: &NodeData, vis: Visibility, m: &MaterialFacts) -> f64 {
        match vis {
            Visibility::OffScreen | Visibility::BackFacing => 0.0,
            Visibility::Silhouette => 1.0,
            Visibility::FrontFacing => {
                let r = self.lit_range(d, m);
                let (lo, hi) = (
                    self.display.luminance(r.lo) as f64,
                    self.display.luminance(r.hi) as f64,
                );
                if hi + lo > 0.0 {
                    ((hi - lo) / (hi + lo)).clamp(0.0, 1.0)
                } else {
                    0.0
                }
            }
        }
    }

    /// The feature size in pixels: the sphere's diameter under per-vertex lighting, twice the
    /// texture deviation otherwise.
    pub fn feature_pixels(&self, d: &NodeData) -> f64 {
        let size = if self.shading == Shading::Gouraud {
            2.0 * d.ball.radius.max(0.0)
        } else {
            2.0 * d.deviation
        };
        (size * self.pixels_per_unit(d)) as f64
    }

    /// Worst-case (lowest) spatial frequency of the node's features, cycles per degree; infinite
    /// for a feature of zero size. [`ViewModel::distance`] clamps it at the CSF peak.
    pub fn frequency(&self, d: &NodeData) -> f64 {
        let px = self.feature_pixels(d);
        if px <= 0.0 {
            return f64::INFINITY;
        }
        self.ppd / (2.0 * px)
    }

    /// The imperceptibility distance of the node, metres, and the same without the clamp of
    /// the frequency at the CSF peak (which only breaks ties between clamped nodes).
    pub fn distance(&self, d: &NodeData, m: &MaterialFacts) -> [f64; 2] {
        let vis = self.visibility(d);
        let c = self.contrast(d, vis, m);
        let f = self.frequency(d);
        match self.csf.max_visible_frequency(c) {
            Some(ft) if f.is_finite() => [
                self.distance_m * ft / f.max(self.csf.peak_frequency()),
                self.distance_m * ft / f,
            ],
            _ => [0.0, 0.0],
        }
    }

    /// The node's error under `criterion` (larger refines first), with a tie-break.
    pub fn key(&self, criterion: Criterion, d: &NodeData, m: &MaterialFacts) -> [f64; 2] {
        let one = |k: f64| [k, 0.0];
        match criterion {
            Criterion::Perceptual => self.distance(d, m),
            Criterion::ObjectSpace => one(d.deviation as f64),
            Criterion::ScreenSpace | Criterion::Silhouette10 => one(match self.visibility(d) {
                Visibility::OffScreen => 0.0,
                v => {
                    let px = (d.deviation * self.pixels_per_unit(d)) as f64;
                    if criterion == Criterion::Silhouette10 && v == Visibility::Silhouette {
                        10.0 * px
                    } else {
                        px
                    }
                }
            }),
        }
    }

    /// The CSF in use (scaled, clamped).
    pub fn csf(&self) -> &ClampedCsf {
        &self.csf
    }
}

/// Frustum planes (a, b, c, d) of a clip transform with depth 0..1, inside where a·x + d ≥ 0
/// (Gribb & Hartmann), normalised so the distance is in model units.
fn frustum_planes(m: &Mat4) -> [Vec4; 6] {
    let r = [m.row(0), m.row(1), m.row(2), m.row(3)];
    [
        r[3] + r[0],
        r[3] - r[0],
        r[3] + r[1],
        r[3] - r[1],
        r[2],
        r[3] - r[2],
    ]
    .map(|p| p / p.truncate().length().max(f32::MIN_POSITIVE))
}
