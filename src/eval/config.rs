//! The batch configuration: a TOML file parsed with serde (`deny_unknown_fields` everywhere), its
//! defaults (documented key by key in `configs/README.md`), and the checks that turn a
//! bad key or value into one exit-2 message naming the key, the file and the line.
//!
//! Decisions:
//! - Paths inside a config (meshes, baseline, goldens, `out`) are relative to the config file's
//!   folder, so a config means the same thing whatever the working directory. `--out` on the
//!   command line is relative to the working directory, as command-line paths are.
//! - Values are checked while deserializing (newtypes with `TryFrom`), so the TOML parser reports
//!   the span of the offending value and the message can give its line.
//! - Thresholds are layered global → asset → LOD field by field; each resolved threshold remembers
//!   which layer it came from, so a gate failure can say where its limit was set.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{Error, Location, Result};
use crate::metric::Metric;
use crate::metric::vdp::Display;
use crate::raster::{RenderSettings, SamplePattern, Shading, ToneMapping};
use crate::scene::{Light, Lighting, Rig, Viewing};

/// A whole config file.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// Output folder, relative to the config file. Default value: `../results/<config file stem>`.
    pub out: Option<PathBuf>,
    /// Render settings.
    #[serde(default)]
    pub render: RenderConfig,
    /// Viewing conditions.
    #[serde(default)]
    pub viewing: ViewingConfig,
    /// Metric families to compute. Default value: `["flip", "ssim", "psnr", "vdp"]`.
    #[serde(default = "default_metrics")]
    pub metrics: Vec<MetricFamily>,
    /// Face samples per mesh for the geometric error columns of `lods.csv` (Hausdorff, mean and
    /// RMS surface distance); 0 turns them off. Default value: 200000.
    #[serde(default = "default_geometry_samples")]
    pub geometry_samples: usize,
    /// FLIP per-pixel level above which a pixel counts as "different" for `flip_share`. Default 0.1.
    #[serde(default = "default_flip_pixel")]
    pub flip_pixel_threshold: UnitInterval,
    /// Output images.
    #[serde(default)]
    pub images: ImagesConfig,
    /// Imperceptibility distances.
    #[serde(default)]
    pub distance: DistanceConfig,
    /// Global thresholds (the first layer).
    #[serde(default)]
    pub thresholds: Thresholds,
    /// Baseline comparison.
    #[serde(default)]
    pub gate: GateConfig,
    /// Golden-image comparison (`lodeval golden`).
    #[serde(default)]
    pub golden: GoldenConfig,
    /// LOD chains for engines.
    #[serde(default)]
    pub export: ExportConfig,
    /// The assets.
    #[serde(rename = "asset")]
    pub assets: Vec<AssetConfig>,
}

fn default_metrics() -> Vec<MetricFamily> {
    vec![
        MetricFamily::Flip,
        MetricFamily::Ssim,
        MetricFamily::Psnr,
        MetricFamily::Vdp,
    ]
}

fn default_geometry_samples() -> usize {
    200_000
}

fn default_flip_pixel() -> UnitInterval {
    UnitInterval(0.1)
}

/// `[render]`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderConfig {
    /// Square image edge in pixels (1..=16384). Default value: 512.
    pub size: ImageSize,
    /// Samples per pixel: 1, 4, 9, …, 64. Default value: 4.
    pub samples: SampleCount,
    /// `rotated` or `ordered`. Default value: `rotated`.
    pub pattern: PatternName,
    /// `dodecahedron`, `icosahedron` or `fibonacci:N`. Default value: `dodecahedron` (20 views).
    pub rig: RigName,
    /// Shading model name. Default value: `auto` (`pbr` for metallic–roughness materials,
    /// `gouraud` otherwise).
    pub shading: ShadingName,
    /// Skip back faces. Default value: false (flipped LOD triangles must show).
    pub cull_backfaces: bool,
    /// Background colour, sRGB in [0, 1]. Default value: [0.5, 0.5, 0.5].
    pub background: [UnitInterval; 3],
    /// Ambient term. Default value: 0.15.
    pub ambient: UnitInterval,
    /// Lights. Default value: one headlight for the Blinn–Phong models; the file's own
    /// (`KHR_lights_punctual`) for `pbr`.
    pub lights: Option<Vec<LightConfig>>,
    /// Image-based lighting of `pbr`: `neutral` (built in) or an equirectangular `.hdr`/`.exr`
    /// file, relative to the config. Default value: `neutral`.
    pub environment: String,
    /// Rotation of the environment about +Y, degrees. Default value: 0.
    pub environment_rotation: Finite,
    /// Factor on the environment's radiance (0 to 10⁶). Default value: 1.
    pub environment_intensity: Intensity,
    /// Exposure in stops (−24 to 24). Default value: 0.
    pub exposure: Stops,
    /// `linear`, `aces` or `pbr-neutral`. Default value: `pbr-neutral` for `pbr`, `linear`
    /// for the others.
    pub tone_mapping: Option<ToneMappingName>,
    /// `pbr`'s multiple-scattering energy compensation. Default value: true.
    pub multiple_scattering: bool,
    /// The environment, read once when the config is loaded (not a key).
    #[serde(skip)]
    pub lighting: Lighting,
}

impl Default for RenderConfig {
    fn default() -> Self {
        RenderConfig {
            size: ImageSize(512),
            samples: SampleCount(4),
            pattern: PatternName::Rotated,
            rig: RigName(Rig::Dodecahedron),
            shading: ShadingName(Shading::Auto),
            cull_backfaces: false,
            background: [UnitInterval(0.5); 3],
            ambient: UnitInterval(0.15),
            lights: None,
            environment: "neutral".into(),
            environment_rotation: Finite(0.0),
            environment_intensity: Intensity(1.0),
            exposure: Stops(0.0),
            tone_mapping: None,
            multiple_scattering: true,
            lighting: Lighting::default(),
        }
    }
}

impl RenderConfig {
    /// The rasterizer settings this section describes.
    pub fn settings(&self) -> RenderSettings {
        let mut s = RenderSettings::DEFAULT;
        s.width = self.size.0;
        s.height = self.size.0;
        let n = self.samples.side();
        s.samples = match self.pattern {
            PatternName::Rotated => SamplePattern::Rotated(n),
            PatternName::Ordered => SamplePattern::Ordered(n),
        };
        s.shading = self.shading.0;
        s.cull_backfaces = self.cull_backfaces;
        s.exposure = self.exposure.0 as f32;
        s.tone_mapping = self.tone_mapping.map(|t| t.0);
        s.multiple_scattering = self.multiple_scattering;
        s
    }

    /// Read the environment the section names (relative to the config's folder); a bad file is
    /// an input error naming it, with the config line that named it in the fix.
    fn load_lighting(&self, text: &str, path: &Path) -> Result<Lighting> {
        let base = path.parent().unwrap_or(Path::new("."));
        Lighting::new(
            &self.environment,
            base,
            self.environment_rotation.0 as f32,
            self.environment_intensity.0 as f32,
        )
        .map_err(|e| match e {
            Error::Input {
                path: file,
                location,
                problem,
                fix,
            } => {
                let line = find_key(&key_lines(text), "render.environment").unwrap_or(0);
                Error::Input {
                    path: file,
                    location,
                    problem,
                    fix: format!("{fix} (named by {} line {line})", path.display()),
                }
            }
            other => other,
        })
    }

    /// The scene lights: the configured ones, or `None` for the default of the model that
    /// draws the scene ([`crate::scene::Scene::default_lights`]).
    pub fn scene_lights(&self) -> Option<Vec<Light>> {
        self.lights
            .as_ref()
            .map(|lights| lights.iter().map(LightConfig::light).collect())
    }
}

/// How a one-off run (`compare`, `simplify -o CHAIN.glb`) looks: the `[render]` keys the
/// command line sets, written into the in-memory config the run builds.
#[derive(Debug, Clone, PartialEq)]
pub struct Look {
    /// Shading model. Default value: `auto`.
    pub shading: Shading,
    /// `neutral` or an environment file (absolute, or relative to the working directory).
    pub environment: String,
    /// Environment rotation, degrees.
    pub environment_rotation: f64,
    /// Environment intensity.
    pub environment_intensity: f64,
    /// Exposure, stops.
    pub exposure: f64,
    /// Tone mapper (`None`: the model's).
    pub tone_mapping: Option<ToneMapping>,
    /// `pbr`'s multiple-scattering term.
    pub multiple_scattering: bool,
}

impl Default for Look {
    fn default() -> Self {
        Look {
            shading: Shading::Auto,
            environment: "neutral".into(),
            environment_rotation: 0.0,
            environment_intensity: 1.0,
            exposure: 0.0,
            tone_mapping: None,
            multiple_scattering: true,
        }
    }
}

impl Look {
    /// Set these keys of `render` (an environment path made absolute, so that the config
    /// reads the same from any folder); `Err` names a value out of its key's range.
    pub fn apply_to(&self, render: &mut RenderConfig) -> std::result::Result<(), String> {
        render.shading = ShadingName(self.shading);
        render.environment = match self.environment.as_str() {
            "neutral" => "neutral".to_string(),
            path => std::path::absolute(path)
                .unwrap_or_else(|_| PathBuf::from(path))
                .to_string_lossy()
                .into_owned(),
        };
        render.environment_rotation = Finite::try_from(self.environment_rotation)?;
        render.environment_intensity = Intensity::try_from(self.environment_intensity)?;
        render.exposure = Stops::try_from(self.exposure)?;
        render.tone_mapping = self.tone_mapping.map(ToneMappingName);
        render.multiple_scattering = self.multiple_scattering;
        Ok(())
    }
}

/// One `[[render.lights]]` entry.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "lowercase")]
pub enum LightConfig {
    /// The camera-following light (the default).
    Headlight {
        /// Grey intensity. Default value: 0.85.
        intensity: Option<UnitInterval>,
    },
    /// A fixed world-space light.
    Directional {
        /// Towards the light, world space (normalised).
        direction: [f32; 3],
        /// Grey intensity. Default value: 0.85.
        intensity: Option<UnitInterval>,
    },
}

impl LightConfig {
    fn light(&self) -> Light {
        let grey = |i: &Option<UnitInterval>| glam::Vec3::splat(i.map_or(0.85, |v| v.0 as f32));
        match self {
            LightConfig::Headlight { intensity } => Light::Headlight {
                offset: crate::scene::HEADLIGHT_OFFSET,
                color: grey(intensity),
            },
            LightConfig::Directional {
                direction,
                intensity,
            } => Light::Directional {
                direction: glam::Vec3::from_array(*direction),
                color: grey(intensity),
            },
        }
    }
}

/// `[viewing]`: the display and the viewer.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct ViewingConfig {
    /// Display width in metres. Default value: 0.7.
    pub display_width_m: Positive,
    /// Display width in pixels. Default value: 3840.
    pub display_px: Positive,
    /// Display height in pixels (for engine screen-size parameters). Default value: 2160.
    pub display_height_px: Positive,
    /// Viewer distance to the display in metres. Default value: 0.7.
    pub distance_m: Positive,
    /// Pixels per degree, overriding the display geometry for the metrics. Default: derived.
    pub ppd: Option<Positive>,
    /// Luminance of the display's white, cd/m² (the VDP's display model). Default value: 100.
    pub peak_cd_m2: Positive,
    /// Luminance of its black in a dark room, cd/m². Default value: 0.5.
    pub black_cd_m2: NonNegative,
    /// Room light falling on the screen, lux. Default value: 250.
    pub ambient_lux: NonNegative,
    /// Fraction of that light the screen reflects. Default value: 0.005.
    pub reflectivity: UnitInterval,
}

impl Default for ViewingConfig {
    fn default() -> Self {
        ViewingConfig {
            display_width_m: Positive(0.7),
            display_px: Positive(3840.0),
            display_height_px: Positive(2160.0),
            distance_m: Positive(0.7),
            ppd: None,
            peak_cd_m2: Positive(Display::DEFAULT.peak_cd_m2 as f64),
            black_cd_m2: NonNegative(Display::DEFAULT.black_cd_m2 as f64),
            ambient_lux: NonNegative(Display::DEFAULT.ambient_lux as f64),
            reflectivity: UnitInterval(Display::DEFAULT.reflectivity as f64),
        }
    }
}

impl ViewingConfig {
    /// The VDP's display model (checked by [`Config::parse`]: black below peak).
    pub fn display(&self) -> Display {
        Display {
            peak_cd_m2: self.peak_cd_m2.0 as f32,
            black_cd_m2: self.black_cd_m2.0 as f32,
            ambient_lux: self.ambient_lux.0 as f32,
            reflectivity: self.reflectivity.0 as f32,
        }
    }

    /// The metric stack's viewing conditions.
    pub fn viewing(&self) -> Viewing {
        match self.ppd {
            Some(p) => Viewing::from_ppd(p.0),
            None => {
                Viewing::from_display(self.display_width_m.0, self.display_px.0, self.distance_m.0)
            }
        }
    }
}

/// `[images]`: which pictures `eval` writes.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct ImagesConfig {
    /// Heat maps per asset/LOD/view/metric: `all`, `worst` (worst view per LOD) or `none`.
    /// Default value: `all`.
    pub heatmaps: HeatmapChoice,
    /// One contact sheet per LOD (original | LOD | heat map, worst views first). Default: true.
    pub contact_sheets: bool,
    /// Views per contact sheet, worst first. Default value: 6.
    pub sheet_views: usize,
}

impl Default for ImagesConfig {
    fn default() -> Self {
        ImagesConfig {
            heatmaps: HeatmapChoice::All,
            contact_sheets: true,
            sheet_views: 6,
        }
    }
}

/// `[export]`: LOD chains for engines.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct ExportConfig {
    /// Each asset's original and LODs as one glTF asset in `export/` (`ASSET.glb` or
    /// `ASSET.gltf`), linked by `MSFT_lod` with switch points from the measured distances
    /// (needs `[distance] enabled`). Default value: `none`.
    pub gltf: GltfExport,
}

/// See [`ExportConfig::gltf`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum GltfExport {
    /// No export.
    #[default]
    None,
    /// One binary `.glb` per asset.
    Glb,
    /// `.gltf` JSON with its `.bin` and PNG images beside it.
    Gltf,
}

/// See [`ImagesConfig::heatmaps`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum HeatmapChoice {
    /// Every view.
    All,
    /// Only each LOD's worst view.
    Worst,
    /// None.
    None,
}

/// `[distance]`: the imperceptibility distance search (`eval/distance.rs`).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct DistanceConfig {
    /// Compute distances. Default value: true.
    pub enabled: bool,
    /// VDP detection probability at or below which a LOD counts as imperceptible. Default: 0.5.
    pub probability: UnitInterval,
    /// Also report FLIP's distance: the nearest distance beyond which the worst view's FLIP mean
    /// stays at or below this value. Default value: 0.01.
    pub flip_mean: Option<UnitInterval>,
    /// Samples per pixel for the small renders. Default value: 16.
    pub samples: SampleCount,
    /// Largest on-screen object diameter searched, pixels; a LOD still visible there is reported
    /// as visible at every distance down to it. Default value: 512.
    pub max_diameter_px: ImageSize,
    /// How many views the search probes: the N worst of the full-size evaluation (by FLIP, else
    /// the first metric), worst first — the worst view decides. Default value: 3.
    pub views: Option<usize>,
}

impl Default for DistanceConfig {
    fn default() -> Self {
        DistanceConfig {
            enabled: true,
            probability: UnitInterval(0.5),
            flip_mean: Some(UnitInterval(0.01)),
            samples: SampleCount(16),
            max_diameter_px: ImageSize(512),
            views: None,
        }
    }
}

/// Limits on a LOD's scores. Every field is optional; unset fields inherit from the layer above.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Thresholds {
    /// Largest allowed FLIP mean, averaged over views.
    pub flip_mean: Option<f64>,
    /// Largest allowed FLIP mean of the worst view.
    pub flip_worst_view: Option<f64>,
    /// Largest allowed per-pixel 95th-percentile FLIP, worst view.
    pub flip_p95: Option<f64>,
    /// Largest allowed share of pixels with FLIP above `flip_pixel_threshold`, worst view.
    pub flip_share: Option<f64>,
    /// Largest allowed VDP detection probability, worst view.
    pub vdp_probability: Option<f64>,
    /// Smallest allowed PSNR in dB, worst view.
    pub psnr_min: Option<f64>,
    /// Smallest allowed SSIM, worst view.
    pub ssim_min: Option<f64>,
    /// Smallest allowed MS-SSIM, worst view.
    pub msssim_min: Option<f64>,
}

impl Thresholds {
    /// Every threshold as (key, value), in [`THRESHOLD_KEYS`] order.
    pub fn entries(&self) -> [(&'static str, Option<f64>); 8] {
        let v = [
            self.flip_mean,
            self.flip_worst_view,
            self.flip_p95,
            self.flip_share,
            self.vdp_probability,
            self.psnr_min,
            self.ssim_min,
            self.msssim_min,
        ];
        std::array::from_fn(|i| (THRESHOLD_KEYS[i].key, v[i]))
    }
}

/// The statistic over views a threshold bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Statistic {
    /// The mean over views.
    Mean,
    /// The worst view, in the metric's direction.
    WorstView,
}

impl Statistic {
    /// How a chart or a message names it.
    pub fn label(self) -> &'static str {
        match self {
            Statistic::Mean => "mean",
            Statistic::WorstView => "worst view",
        }
    }
}

/// What a threshold key bounds: a metric of `metric::catalog`, over a statistic; from above for
/// metrics where higher is worse, from below for the others.
#[derive(Debug, Clone, Copy)]
pub struct ThresholdKey {
    /// The key in `[thresholds]`.
    pub key: &'static str,
    /// The metric it bounds.
    pub metric: Metric,
    /// The statistic over views.
    pub statistic: Statistic,
}

/// Every threshold key, in the order of [`Thresholds`]' fields.
pub const THRESHOLD_KEYS: [ThresholdKey; 8] = {
    const fn k(key: &'static str, metric: Metric, statistic: Statistic) -> ThresholdKey {
        ThresholdKey {
            key,
            metric,
            statistic,
        }
    }
    use Statistic::{Mean, WorstView};
    [
        k("flip_mean", Metric::Flip, Mean),
        k("flip_worst_view", Metric::Flip, WorstView),
        k("flip_p95", Metric::FlipP95, WorstView),
        k("flip_share", Metric::FlipShare, WorstView),
        k("vdp_probability", Metric::Vdp, WorstView),
        k("psnr_min", Metric::Psnr, WorstView),
        k("ssim_min", Metric::Ssim, WorstView),
        k("msssim_min", Metric::Msssim, WorstView),
    ]
};

impl ThresholdKey {
    /// The entry of a key from [`Thresholds::entries`].
    pub fn of(key: &str) -> &'static ThresholdKey {
        THRESHOLD_KEYS
            .iter()
            .find(|k| k.key == key)
            .expect("a key from Thresholds::entries")
    }

    /// Whether it bounds from above (the metric gets worse upwards).
    pub fn upper(&self) -> bool {
        self.metric.higher_is_worse()
    }
}

/// `[gate]`: comparison with a baseline run.
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct GateConfig {
    /// A `summary.csv` from an accepted run. Default: none.
    pub baseline: Option<PathBuf>,
    /// Relative tolerance: a LOD regresses when a summary mean is worse than the baseline's by
    /// more than this fraction (and by more than `absolute`). Default value: 0.1.
    pub tolerance: Option<f64>,
    /// Absolute slack added to the tolerance (ignores noise near zero). Default value: 1e-4.
    pub absolute: Option<f64>,
}

/// `[golden]`: golden-image checks.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct GoldenConfig {
    /// Folder of golden PNGs, `ASSET/LOD/view-NN.png`. Default value: `../reference/golden/<stem>`.
    pub dir: Option<PathBuf>,
    /// Largest FLIP mean between a render and its golden. Default value: 0.005.
    pub flip_mean: UnitInterval,
    /// Largest per-pixel 99th-percentile FLIP. Default value: 0.05.
    pub flip_p99: UnitInterval,
    /// Also check the LODs, not only the originals. Default value: true.
    pub lods: bool,
}

impl Default for GoldenConfig {
    fn default() -> Self {
        GoldenConfig {
            dir: None,
            flip_mean: UnitInterval(0.005),
            flip_p99: UnitInterval(0.05),
            lods: true,
        }
    }
}

/// One `[[asset]]`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct AssetConfig {
    /// Name used in outputs (letters, digits, `-`, `_`, `.`).
    pub name: Name,
    /// The original mesh.
    pub mesh: PathBuf,
    /// Metres per model unit. Default value: 1.
    #[serde(default = "one")]
    pub meters_per_unit: Positive,
    /// LOD files.
    #[serde(default)]
    pub lods: Vec<LodConfig>,
    /// A LOD generator.
    pub generate: Option<GenerateConfig>,
    /// Asset-level thresholds (second layer).
    #[serde(default)]
    pub thresholds: Thresholds,
}

fn one() -> Positive {
    Positive(1.0)
}

impl GenerateConfig {
    /// Its goals in chain order: ratios, then errors, distances and vertex counts.
    pub fn goals(&self) -> Vec<crate::simplify::Goal> {
        use crate::simplify::Goal;
        (self.ratios.iter().map(|r| Goal::Ratio(r.0)))
            .chain(self.errors.iter().map(|e| Goal::Error(e.0)))
            .chain(self.distances.iter().map(|d| Goal::Distance(d.0)))
            .chain(self.vertices.iter().map(|&v| Goal::Vertices(v)))
            .collect()
    }
}

impl AssetConfig {
    /// An asset `name` with its original `mesh`, one metre per unit, no LODs yet.
    pub fn new(name: &str, mesh: PathBuf) -> std::result::Result<AssetConfig, String> {
        Ok(AssetConfig {
            name: Name::try_from(name.to_string())?,
            mesh,
            meters_per_unit: one(),
            lods: Vec::new(),
            generate: None,
            thresholds: Thresholds::default(),
        })
    }
}

impl LodConfig {
    /// A LOD read from `mesh`, named `name`.
    pub fn new(name: &str, mesh: PathBuf) -> std::result::Result<LodConfig, String> {
        Ok(LodConfig {
            name: Some(Name::try_from(name.to_string())?),
            mesh,
            switch_m: None,
            thresholds: Thresholds::default(),
        })
    }
}

/// One LOD file of an asset.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LodConfig {
    /// Name used in outputs. Default value: `lodN` (1-based position in the list).
    pub name: Option<Name>,
    /// The LOD mesh.
    pub mesh: PathBuf,
    /// The engine's current switch distance for this LOD, metres: the gate fails when the LOD is
    /// still visible beyond it.
    pub switch_m: Option<Positive>,
    /// LOD-level thresholds (third layer).
    #[serde(default)]
    pub thresholds: Thresholds,
}

/// A LOD generator.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GenerateConfig {
    /// `meshopt` (meshoptimizer's `simplify`, the industrial baseline), `meshopt-update`
    /// (meshoptimizer's `simplifyWithUpdate`, moving vertices and attributes), `qem` (our edge
    /// collapse with Garland–Heckbert quadrics) or `cluster` (Rossignac–Borrel vertex clustering).
    pub method: crate::simplify::Method,
    /// Target triangle ratios of the original, each LOD simplified from the previous one.
    #[serde(default)]
    pub ratios: Vec<UnitInterval>,
    /// Target errors relative to the bounding-box diagonal (each method's own error measure), as
    /// further LODs of the chain.
    #[serde(default)]
    pub errors: Vec<UnitInterval>,
    /// Viewing distances in metres from which each LOD is imperceptible (menzel-guthe only), as
    /// further LODs of the chain.
    #[serde(default)]
    pub distances: Vec<Positive>,
    /// Vertex counts of remeshes (qu-meyer only), as further LODs of the chain.
    #[serde(default)]
    pub vertices: Vec<usize>,
    /// Engine switch distances for the generated LODs, metres, in chain order.
    #[serde(default)]
    pub switch_m: Vec<Positive>,
}

pub use crate::metric::MetricFamily;

macro_rules! checked_newtype {
    ($(#[$m:meta])* $name:ident($inner:ty), $from:literal, |$v:ident| $check:expr, $why:expr) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Deserialize, Serialize)]
        #[serde(try_from = $from)]
        pub struct $name(pub $inner);
        impl TryFrom<$inner> for $name {
            type Error = String;
            fn try_from($v: $inner) -> std::result::Result<Self, String> {
                if $check { Ok($name($v)) } else { Err(format!("{} is out of range: {}", $v, $why)) }
            }
        }
    };
}

checked_newtype!(
    /// A number in [0, 1].
    UnitInterval(f64), "f64", |v| (0.0..=1.0).contains(&v), "use a value between 0 and 1"
);
checked_newtype!(
    /// A finite number > 0.
    Positive(f64), "f64", |v| v.is_finite() && v > 0.0, "use a finite number above 0"
);
checked_newtype!(
    /// Any finite number.
    Finite(f64), "f64", |v| v.is_finite(), "use a finite number"
);
checked_newtype!(
    /// Exposure in stops ([`crate::limits::EXPOSURE_STOPS`]).
    Stops(f64), "f64", |v| crate::limits::EXPOSURE_STOPS.contains(v), "use −24 to 24 stops"
);
checked_newtype!(
    /// An environment intensity ([`crate::limits::ENVIRONMENT_INTENSITY`]).
    Intensity(f64), "f64", |v| crate::limits::ENVIRONMENT_INTENSITY.contains(v),
    "use 0 to 1000000"
);
checked_newtype!(
    /// A finite number ≥ 0.
    NonNegative(f64), "f64", |v| v.is_finite() && v >= 0.0, "use a finite number of at least 0"
);
checked_newtype!(
    /// An image edge in pixels.
    ImageSize(u32), "u32", |v| (1..=RenderSettings::MAX_SIZE).contains(&v),
    "use 1 to 16384 pixels"
);
checked_newtype!(
    /// Samples per pixel, a square n² with 1 ≤ n ≤ 8.
    SampleCount(u32), "u32", |v| SamplePattern::side_for(v).is_some(),
    "use 1, 4, 9, 16, 25, 36, 49 or 64 samples per pixel"
);

impl SampleCount {
    /// The grid side n (the count is n², checked when parsed).
    pub fn side(self) -> u32 {
        SamplePattern::side_for(self.0).unwrap_or(1)
    }
}

/// Supersampling pattern names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PatternName {
    /// Rotated grid.
    Rotated,
    /// Ordered grid.
    Ordered,
}

/// A view rig by name.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(try_from = "String")]
pub struct RigName(pub Rig);
impl Serialize for RigName {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match &self.0 {
            Rig::Dodecahedron => s.serialize_str("dodecahedron"),
            Rig::Icosahedron => s.serialize_str("icosahedron"),
            Rig::Fibonacci(n) => s.serialize_str(&format!("fibonacci:{n}")),
            Rig::Explicit(_) => Err(serde::ser::Error::custom(
                "a rig of explicit directions has no name in a config",
            )),
        }
    }
}
impl TryFrom<String> for RigName {
    type Error = String;
    fn try_from(s: String) -> std::result::Result<Self, String> {
        Rig::parse(&s).map(RigName)
    }
}

/// A shading model by name.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "String", into = "String")]
pub struct ShadingName(pub Shading);
impl From<ShadingName> for String {
    fn from(s: ShadingName) -> String {
        s.0.name().to_string()
    }
}
impl TryFrom<String> for ShadingName {
    type Error = String;
    fn try_from(s: String) -> std::result::Result<Self, String> {
        Shading::parse(&s).map(ShadingName).ok_or_else(|| {
            let names: Vec<_> = Shading::ALL.iter().map(|s| s.name()).collect();
            format!("unknown shading '{s}': use one of {}", names.join(", "))
        })
    }
}

/// A tone mapper by name.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "String", into = "String")]
pub struct ToneMappingName(pub ToneMapping);
impl From<ToneMappingName> for String {
    fn from(t: ToneMappingName) -> String {
        t.0.name().to_string()
    }
}
impl TryFrom<String> for ToneMappingName {
    type Error = String;
    fn try_from(s: String) -> std::result::Result<Self, String> {
        ToneMapping::parse(&s).map(ToneMappingName).ok_or_else(|| {
            let names: Vec<_> = ToneMapping::ALL.iter().map(|t| t.name()).collect();
            format!("unknown tone mapper '{s}': use one of {}", names.join(", "))
        })
    }
}

/// An asset or LOD name: safe as a folder name and a CSV field.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Deserialize, Serialize)]
#[serde(try_from = "String", into = "String")]
pub struct Name(pub String);
impl From<Name> for String {
    fn from(n: Name) -> String {
        n.0
    }
}
impl TryFrom<String> for Name {
    type Error = String;
    fn try_from(s: String) -> std::result::Result<Self, String> {
        let ok = !s.is_empty()
            && s != "."
            && s != ".."
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'));
        if ok {
            Ok(Name(s))
        } else {
            Err(format!(
                "name '{s}' may only use letters, digits, '-', '_' and '.'"
            ))
        }
    }
}

impl Config {
    /// Parse a config from its text; `path` is only used in messages.
    pub fn parse(text: &str, path: &Path) -> Result<Config> {
        let config: Config = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
            let mut problem = e.message().trim().to_string();
            // Name the key: toml's type errors give the span of the value but not the key.
            if let Some(start) = e.span().map(|s| s.start.min(text.len())) {
                let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
                let line_text = text[line_start..].lines().next().unwrap_or("");
                if let Some((key, _)) = line_text.split_once('=') {
                    let key = key.trim();
                    if !key.is_empty() && !problem.contains(key) {
                        problem = format!("`{key}`: {problem}");
                    }
                }
            }
            let fix = "see configs/README.md for every key, its type and its default";
            match line {
                Some(l) => Error::input_at(path, Location::Line(l), problem, fix),
                None => Error::input(path, problem, fix),
            }
        })?;
        config.validated(text, path)
    }

    /// A config of `assets` with every other key at its default (what a file with only those
    /// `[[asset]]` tables gives), for building plans as Rust values.
    pub fn new(assets: Vec<AssetConfig>) -> Config {
        Config {
            out: None,
            render: RenderConfig::default(),
            viewing: ViewingConfig::default(),
            metrics: default_metrics(),
            geometry_samples: default_geometry_samples(),
            flip_pixel_threshold: default_flip_pixel(),
            images: ImagesConfig::default(),
            distance: DistanceConfig::default(),
            thresholds: Thresholds::default(),
            gate: GateConfig::default(),
            golden: GoldenConfig::default(),
            export: ExportConfig::default(),
            assets,
        }
    }

    /// The checks a parsed config gets, and its environment read, for a config built as a
    /// value; `origin` names it in messages and anchors its relative paths.
    pub fn checked(self, origin: &Path) -> Result<Config> {
        self.validated("", origin)
    }

    /// Cross-field checks (messages name the line of `text` where it has the key) and the
    /// environment read.
    fn validated(mut self, text: &str, path: &Path) -> Result<Config> {
        self.check(text, path)?;
        self.render.lighting = self.render.load_lighting(text, path)?;
        Ok(self)
    }

    /// The config as TOML text, as a file with these keys would read (the record a run keeps
    /// in its manifest, and what `Plan::from_config` writes beside a run).
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| Error::Internal(format!("a config as TOML: {e}")))
    }

    /// Cross-field checks that serde cannot express.
    fn check(&self, text: &str, path: &Path) -> Result<()> {
        let at = At::new(text, path);
        let fail = |needle: &str, problem: String, fix: &str| at.fail(needle, problem, fix);
        if self.assets.is_empty() {
            return Err(Error::input(
                path,
                "has no [[asset]] entries",
                "add at least one [[asset]] with a name and a mesh",
            ));
        }
        if self.out.as_ref().is_some_and(|o| o.as_os_str().is_empty()) {
            return Err(fail(
                "out",
                "out is empty, which would write into the config's own folder".into(),
                "name an output folder, e.g. out = \"../results/NAME\", or leave out away",
            ));
        }
        self.check_viewing(&at)?;
        self.check_sizes(&at)?;
        if self.metrics.is_empty() {
            return Err(fail(
                "metrics",
                "metrics is empty".into(),
                "list at least one of flip, ssim, msssim, psnr, vdp",
            ));
        }
        let mut names = std::collections::BTreeSet::new();
        for a in &self.assets {
            let quoted = format!("\"{}\"", a.name.0);
            if !names.insert(a.name.0.clone()) {
                return Err(fail(
                    &quoted,
                    format!("asset name '{}' is used twice", a.name.0),
                    "give every [[asset]] its own name",
                ));
            }
            self.check_asset(a, &at)?;
        }
        check_thresholds(&self.thresholds)
            .map_err(|why| fail("[thresholds]", why, THRESHOLD_FIX))?;
        if let Some(t) = self.gate.tolerance
            && !(t.is_finite() && t >= 0.0)
        {
            return Err(fail(
                "gate.tolerance",
                format!("gate.tolerance {t} must be a finite number ≥ 0"),
                "use e.g. 0.1 for 10 %",
            ));
        }
        Ok(())
    }

    /// The display model and the viewing geometry describe something real.
    fn check_viewing(&self, at: &At<'_>) -> Result<()> {
        let fail = |needle: &str, problem: String, fix: &str| at.fail(needle, problem, fix);
        let v = &self.viewing;
        if let Err(e) = Display::new(
            v.peak_cd_m2.0 as f32,
            v.black_cd_m2.0 as f32,
            v.ambient_lux.0 as f32,
            v.reflectivity.0 as f32,
        ) {
            return Err(fail(
                "viewing.black_cd_m2",
                format!("[viewing] {e}"),
                "set black_cd_m2 below peak_cd_m2 (an office monitor: 0.5 and 100)",
            ));
        }
        if let Err(problem) = v.viewing().check() {
            return Err(fail(
                if v.ppd.is_some() {
                    "viewing.ppd"
                } else {
                    "[viewing]"
                },
                format!("[viewing] {problem}"),
                "describe a real display and viewer, or set ppd (the default display gives 67)",
            ));
        }
        Ok(())
    }

    /// Counts within their bounds, and the run's memory and contact sheets within theirs.
    fn check_sizes(&self, at: &At<'_>) -> Result<()> {
        let fail = |needle: &str, problem: String, fix: &str| at.fail(needle, problem, fix);
        let counts = [
            (
                "geometry_samples",
                self.geometry_samples,
                &crate::limits::SURFACE_SAMPLES,
            ),
            (
                "images.sheet_views",
                self.images.sheet_views,
                &crate::limits::SHEET_VIEWS,
            ),
            (
                "distance.views",
                self.distance.views.unwrap_or(1),
                &crate::limits::VIEWS,
            ),
        ];
        for (key, value, bound) in counts {
            let name = key.rsplit('.').next().unwrap_or(key);
            if let Err(problem) = bound.check(name, value as u64) {
                return Err(fail(
                    key,
                    problem,
                    "see configs/README.md for the key's range",
                ));
            }
        }
        // Memory: one scored pair at the render size and at the distance search's largest
        // probe, plus every view's prepared reference.
        {
            use crate::limits::{BYTES_PER_REFERENCE_PIXEL, BYTES_PER_SCORED_PIXEL};
            let px = (self.render.size.0 as u64).pow(2);
            let views = self.render.rig.0.count() as u64;
            let probe = if self.distance.enabled {
                ((self.distance.max_diameter_px.0 as f64 * 1.1).ceil() as u64 + 8).pow(2)
            } else {
                0
            };
            let bytes =
                px.max(probe) * BYTES_PER_SCORED_PIXEL + views * px * BYTES_PER_REFERENCE_PIXEL;
            let job = format!(
                "a run of {views} views at {0}x{0} pixels",
                self.render.size.0
            );
            if let Err(problem) = crate::limits::check_memory(&job, bytes) {
                return Err(fail(
                    "render.size",
                    problem,
                    "lower [render] size or the rig's views",
                ));
            }
        }
        if self.images.contact_sheets {
            let views = self.render.rig.0.count().min(self.images.sheet_views) as u64;
            let side = self.render.size.0 as u64;
            crate::io::sheet::check_sheet(3 * views, 3, (side, side), 4).map_err(|e| {
                fail(
                    "images.sheet_views",
                    format!("[images] {e}"),
                    "lower sheet_views or [render] size, or set contact_sheets = false",
                )
            })?;
        }
        Ok(())
    }

    /// One asset: LODs or a generator, a generator that makes sense, unique LOD names, and
    /// thresholds.
    fn check_asset(&self, a: &AssetConfig, at: &At<'_>) -> Result<()> {
        let fail = |needle: &str, problem: String, fix: &str| at.fail(needle, problem, fix);
        let quoted = format!("\"{}\"", a.name.0);
        if a.lods.is_empty() && a.generate.is_none() {
            return Err(fail(
                &quoted,
                format!("asset '{}' has neither lods nor generate", a.name.0),
                "list LOD files in `lods` or add `generate = { method = \"meshopt\", ratios = [...] }`",
            ));
        }
        if let Some(g) = &a.generate {
            check_generate(a, g, at)?;
        }
        let mut lod_names = std::collections::BTreeSet::new();
        for (name, _) in self.lod_names(a) {
            if !lod_names.insert(name.clone()) {
                return Err(fail(
                    &quoted,
                    format!("asset '{}': LOD name '{name}' is used twice", a.name.0),
                    "give every LOD its own name",
                ));
            }
        }
        for t in [&a.thresholds]
            .into_iter()
            .chain(a.lods.iter().map(|l| &l.thresholds))
        {
            check_thresholds(t).map_err(|why| fail(&quoted, why, THRESHOLD_FIX))?;
        }
        Ok(())
    }

    /// Every LOD of an asset as (name, index in the chain), files first then generated.
    pub fn lod_names(&self, asset: &AssetConfig) -> Vec<(String, usize)> {
        let mut out: Vec<(String, usize)> = asset
            .lods
            .iter()
            .enumerate()
            .map(|(i, l)| {
                (
                    l.name
                        .as_ref()
                        .map_or_else(|| format!("lod{}", i + 1), |n| n.0.clone()),
                    i,
                )
            })
            .collect();
        if let Some(g) = &asset.generate {
            let base = out.len();
            for (k, r) in g.ratios.iter().enumerate() {
                out.push((
                    format!("{}-r{}", g.method.name(), percent_label(r.0)),
                    base + k,
                ));
            }
            for (k, e) in g.errors.iter().enumerate() {
                out.push((
                    format!("{}-e{}", g.method.name(), e.0),
                    base + g.ratios.len() + k,
                ));
            }
            for (k, d) in g.distances.iter().enumerate() {
                out.push((
                    format!("{}-d{}", g.method.name(), d.0),
                    base + g.ratios.len() + g.errors.len() + k,
                ));
            }
            for (k, v) in g.vertices.iter().enumerate() {
                out.push((
                    format!("{}-v{v}", g.method.name()),
                    base + g.ratios.len() + g.errors.len() + g.distances.len() + k,
                ));
            }
        }
        out
    }

    /// The output folder: `override_out` if given, else `out` relative to the config, else
    /// `../results/<stem>` relative to the config.
    pub fn out_dir(&self, config_path: &Path, override_out: Option<&Path>) -> PathBuf {
        if let Some(o) = override_out {
            return o.to_path_buf();
        }
        let base = config_dir(config_path);
        match &self.out {
            Some(o) => resolve(&base, o),
            None => resolve(
                &base,
                &Path::new("..").join("results").join(stem(config_path)),
            ),
        }
    }
}

/// An asset's `generate`: a method and goals that fit together, each LOD coarser than the last,
/// at most one switch distance per LOD.
fn check_generate(a: &AssetConfig, g: &GenerateConfig, at: &At<'_>) -> Result<()> {
    let quoted = format!("\"{}\"", a.name.0);
    crate::simplify::goals::check(g.method, &g.goals(), None).map_err(|why| {
        at.fail(
            &quoted,
            format!("asset '{}': generate: {why}", a.name.0),
            "e.g. generate = { method = \"meshopt\", ratios = [0.5, 0.25] }, errors = [0.01] \
             (fractions of the bounding-box diagonal), distances = [5.0, 10.0] (metres, \
             menzel-guthe) or vertices = [2000, 1000] (qu-meyer)",
        )
    })?;
    let lods = g.goals().len();
    if g.switch_m.len() > lods {
        return Err(at.fail(
            &quoted,
            format!(
                "asset '{}': generate has {} switch_m values for {lods} LODs",
                a.name.0,
                g.switch_m.len()
            ),
            "give one switch distance per generated LOD (ratios first, then errors), or fewer",
        ));
    }
    Ok(())
}

/// One key of a TOML document: its dotted path (entries of an array of tables numbered:
/// `asset.0.name`), the line it is written on, and its value if that is a string.
struct KeyLine {
    path: String,
    line: usize,
    string: Option<String>,
}

/// Every key of a TOML document, in the order they appear. Found with the TOML parser's spans,
/// so a key is never matched inside a comment, a string or a longer key's name.
fn key_lines(text: &str) -> Vec<KeyLine> {
    use toml::de::{DeTable, DeValue};
    fn walk(text: &str, prefix: &str, table: &DeTable, out: &mut Vec<KeyLine>) {
        for (key, value) in table {
            let path = if prefix.is_empty() {
                key.get_ref().to_string()
            } else {
                format!("{prefix}.{}", key.get_ref())
            };
            let start = key.span().start.min(text.len());
            let string = match value.get_ref() {
                DeValue::String(v) => Some(v.to_string()),
                _ => None,
            };
            out.push(KeyLine {
                path: path.clone(),
                line: text[..start].matches('\n').count() + 1,
                string,
            });
            match value.get_ref() {
                DeValue::Table(t) => walk(text, &path, t, out),
                DeValue::Array(items) => {
                    for (i, item) in items.iter().enumerate() {
                        if let DeValue::Table(t) = item.get_ref() {
                            walk(text, &format!("{path}.{i}"), t, out);
                        }
                    }
                }
                _ => {}
            }
        }
    }
    let mut out = Vec::new();
    if let Ok(root) = DeTable::parse(text) {
        walk(text, "", root.get_ref(), &mut out);
    }
    out.sort_by_key(|k| k.line);
    out
}

/// The line of `what` in a document's keys: `"NAME"` (in quotes) is the first key whose string
/// value is NAME; `[table]` or a key is the key whose dotted path is exactly that, else the first
/// whose path ends with `.key` (`size` finds `render.size`; `images.size` only that one).
fn find_key(keys: &[KeyLine], what: &str) -> Option<usize> {
    if let Some(value) = what.strip_prefix('"').and_then(|w| w.strip_suffix('"')) {
        return keys
            .iter()
            .find(|k| k.string.as_deref() == Some(value))
            .map(|k| k.line);
    }
    let key = what.trim_start_matches('[').trim_end_matches(']');
    let suffix = format!(".{key}");
    keys.iter()
        .find(|k| k.path == key)
        .or_else(|| keys.iter().find(|k| k.path.ends_with(&suffix)))
        .map(|k| k.line)
}

/// Where a problem of the config text sits: errors at the line of the key they are about.
struct At<'a> {
    path: &'a Path,
    keys: Vec<KeyLine>,
}

impl<'a> At<'a> {
    fn new(text: &str, path: &'a Path) -> At<'a> {
        At {
            path,
            keys: key_lines(text),
        }
    }

    /// An input error at the line of `what` (see [`find_key`]), or naming no line if the text
    /// does not have it.
    fn fail(&self, what: &str, problem: String, fix: &str) -> Error {
        match find_key(&self.keys, what) {
            Some(line) => Error::input_at(self.path, Location::Line(line), problem, fix),
            None => Error::input(self.path, problem, fix),
        }
    }
}

const THRESHOLD_FIX: &str = "thresholds are finite numbers in their metric's range (FLIP, shares \
     and probabilities between 0 and 1, SSIM between -1 and 1, PSNR at least 0 dB)";

fn check_thresholds(t: &Thresholds) -> std::result::Result<(), String> {
    for (name, v) in t.entries() {
        let Some(v) = v else { continue };
        let (lo, hi) = ThresholdKey::of(name).metric.range();
        if !v.is_finite() || !(lo..=hi).contains(&v) {
            return Err(format!("threshold {name} = {v} is out of range"));
        }
    }
    Ok(())
}

/// `0.5` → `50`, `0.025` → `2.5`: a ratio as a percentage label without trailing zeros.
pub fn percent_label(ratio: f64) -> String {
    let p = (ratio * 1e4).round() / 100.0;
    format!("{p}")
}

/// The folder a config's relative paths start from (the config's own folder).
pub use crate::io::parent_dir as config_dir;
/// Relative config paths joined onto that folder, tidied.
pub use crate::io::resolve;

/// The config's file stem (`demo` for `configs/demo.toml`).
pub fn stem(config_path: &Path) -> String {
    config_path
        .file_stem()
        .map_or_else(|| "run".to_string(), |s| s.to_string_lossy().into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Config> {
        Config::parse(text, Path::new("t.toml"))
    }

    const MINIMAL: &str = "[[asset]]\nname = \"a\"\nmesh = \"a.obj\"\ngenerate = { method = \"meshopt\", ratios = [0.5] }\n";

    #[test]
    fn defaults_follow_design() {
        let c = parse(MINIMAL).unwrap();
        let s = c.render.settings();
        assert_eq!((s.width, s.height, s.samples.count()), (512, 512, 4));
        assert_eq!(c.render.rig.0, Rig::Dodecahedron);
        assert!((c.viewing.viewing().ppd() - 67.02).abs() < 0.01);
        assert_eq!(c.metrics, default_metrics());
        assert_eq!(c.lod_names(&c.assets[0])[0].0, "meshopt-r50");
    }

    #[test]
    fn unknown_key_names_key_and_line() {
        let e = parse(&format!("{MINIMAL}[render]\nsise = 3\n")).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("line 6") && msg.contains("sise"), "{msg}");
    }

    #[test]
    fn bad_values_name_the_line() {
        for (extra, line, word) in [
            ("[render]\nsamples = 3\n", 6, "samples"),
            ("[render]\nrig = \"cube\"\n", 6, "rig"),
            ("[render]\nshading = \"toon\"\n", 6, "toon"),
            ("[viewing]\ndistance_m = -1.0\n", 6, "-1"),
            ("[render]\nsize = 0\n", 6, "out of range"),
        ] {
            let msg = parse(&format!("{MINIMAL}{extra}")).unwrap_err().to_string();
            assert!(
                msg.contains(&format!("line {line}")) && msg.contains(word),
                "{extra}: {msg}"
            );
        }
    }

    #[test]
    fn a_chain_must_get_coarser() {
        for (generate, word) in [
            ("ratios = [0.25, 0.5]", "ratio 0.25 then ratio 0.5"),
            ("ratios = [0.5, 0.5]", "ratio 0.5 then ratio 0.5"),
            ("ratios = [0.501, 0.502]", "ratio 0.501 then ratio 0.502"),
            ("errors = [0.02, 0.01]", "error 0.02 then error 0.01"),
        ] {
            let text = format!(
                "[[asset]]\nname = \"a\"\nmesh = \"a.obj\"\ngenerate = {{ method = \"meshopt\", {generate} }}\n"
            );
            let msg = parse(&text).unwrap_err().to_string();
            assert!(
                msg.contains(word) && msg.contains("t.toml") && msg.contains("line 2"),
                "{generate}: {msg}"
            );
        }
        let fine = "[[asset]]\nname = \"a\"\nmesh = \"a.obj\"\ngenerate = { method = \"meshopt\", ratios = [0.5, 0.25], errors = [0.01, 0.02] }\n";
        assert!(parse(fine).is_ok());
        let extra = "[[asset]]\nname = \"a\"\nmesh = \"a.obj\"\ngenerate = { method = \"meshopt\", ratios = [0.5], switch_m = [3.0, 6.0] }\n";
        let msg = parse(extra).unwrap_err().to_string();
        assert!(msg.contains("2 switch_m values for 1 LODs"), "{msg}");
    }

    #[test]
    fn cross_field_errors() {
        assert!(parse("metrics = []\n").is_err());
        let twice = format!("{MINIMAL}{MINIMAL}");
        assert!(parse(&twice).unwrap_err().to_string().contains("twice"));
        let none = "[[asset]]\nname = \"a\"\nmesh = \"a.obj\"\n";
        assert!(parse(none).unwrap_err().to_string().contains("neither"));
        let bad_t = format!("{MINIMAL}[thresholds]\nflip_mean = 2.0\n");
        assert!(parse(&bad_t).unwrap_err().to_string().contains("flip_mean"));
    }

    #[test]
    fn paths_resolve_lexically() {
        let r = |b: &str, p: &str| resolve(Path::new(b), Path::new(p));
        assert_eq!(r("configs", "../results/demo"), Path::new("results/demo"));
        assert_eq!(r(".", "../x"), Path::new("../x"));
        assert_eq!(r("/a/b", "/abs/m.obj"), Path::new("/abs/m.obj"));
        assert_eq!(r("a", ".."), Path::new("."));
    }

    #[test]
    fn percent_labels() {
        assert_eq!(percent_label(0.5), "50");
        assert_eq!(percent_label(0.025), "2.5");
        assert_eq!(percent_label(0.05), "5");
    }
}
