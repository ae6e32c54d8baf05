//! Value types shared by several commands' flags: where to render, how to sample, how to load,
//! and the parsers for rigs, shading models and sample counts. Each enumerated flag is defined
//! once, here or beside its one command, as a `ValueEnum` or a `value_parser`.

use clap::{Args, ValueEnum};
use lodeval::limits::Bound;
use lodeval::raster::{RenderSettings, SamplePattern, Shading, ToneMapping};
use lodeval::scene::{Lighting, Rig};
use lodeval::{Error, LoadOptions, MissingAssets};

#[derive(Copy, Clone, Debug, ValueEnum)]
pub(crate) enum PatternArg {
    /// Rotated ("n-rooks") grid.
    Rotated,
    /// Regular grid.
    Ordered,
}

impl PatternArg {
    /// The pattern with grid side `n`.
    pub(crate) fn with_side(self, n: u32) -> SamplePattern {
        match self {
            PatternArg::Rotated => SamplePattern::Rotated(n),
            PatternArg::Ordered => SamplePattern::Ordered(n),
        }
    }
}

#[derive(Args, Debug)]
pub(crate) struct LoadArgs {
    /// What to do when a texture or material library is missing or undecodable.
    #[arg(long, value_enum, default_value_t = MissingAssets::Error)]
    pub(crate) missing_assets: MissingAssets,
    /// Crease angle in degrees for computed normals (180 = smooth everywhere).
    #[arg(long, default_value_t = 180.0, value_name = "DEGREES")]
    pub(crate) crease_angle: f32,
}

impl LoadArgs {
    pub(crate) fn options(&self) -> Result<LoadOptions, Error> {
        if !(0.0..=180.0).contains(&self.crease_angle) {
            return Err(Error::Usage(format!(
                "--crease-angle {} is outside 0..180 degrees",
                self.crease_angle
            )));
        }
        let mut o = LoadOptions::DEFAULT;
        o.missing_assets = self.missing_assets;
        o.crease_angle_deg = self.crease_angle;
        Ok(o)
    }
}

/// `--rig`: dodecahedron, icosahedron or fibonacci:N.
pub(crate) fn parse_rig(text: &str) -> Result<Rig, String> {
    Rig::parse(text)
}

/// `--shading`: one of the rasterizer's shading models.
pub(crate) fn parse_shading(text: &str) -> Result<Shading, String> {
    Shading::parse(text).ok_or_else(|| {
        let names: Vec<&str> = Shading::ALL.iter().map(|s| s.name()).collect();
        format!(
            "unknown shading model '{text}': use one of {}",
            names.join(", ")
        )
    })
}

/// `--samples`: a square count n² with 1 ≤ n ≤ 8; returns the count (checked by
/// [`SamplePattern::side_for`]).
pub(crate) fn parse_samples(text: &str) -> Result<u32, String> {
    let bad = || format!("{text} samples per pixel: use 1, 4, 9, 16, 25, 36, 49 or 64");
    let n: u32 = text.trim().parse().map_err(|_| bad())?;
    SamplePattern::side_for(n).map(|_| n).ok_or_else(bad)
}

/// The grid side of a count that [`parse_samples`] accepted.
pub(crate) fn side(samples: u32) -> u32 {
    SamplePattern::side_for(samples).unwrap_or(1)
}

/// A clap value parser for a whole number within `bound` (a `lodeval::limits` bound), given as
/// `T` (`u32`, `u64`, `usize`).
pub(crate) fn count<T: TryFrom<u64>>(
    bound: &'static Bound<u64>,
) -> impl Fn(&str) -> Result<T, String> + Clone + Send + Sync + 'static {
    move |text| {
        let v: u64 = text
            .trim()
            .parse()
            .map_err(|_| format!("'{text}' is not a whole number of {}", bound.unit))?;
        if let Some(m) = bound.refuse(v) {
            return Err(m);
        }
        T::try_from(v).map_err(|_| format!("{v} {} do not fit this platform", bound.unit))
    }
}

/// A clap value parser for any finite number (a limit the user sets, such as a gate).
pub(crate) fn finite(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("'{text}': give a finite number")),
        Err(_) => Err(format!("'{text}' is not a number")),
    }
}

/// A clap value parser for a number within `bound` (a `lodeval::limits` bound).
pub(crate) fn value(
    bound: &'static Bound<f64>,
) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync + 'static {
    move |text| {
        let v: f64 = text
            .trim()
            .parse()
            .map_err(|_| format!("'{text}' is not a number of {}", bound.unit))?;
        bound.refuse(v).map_or(Ok(v), Err)
    }
}

/// `--tone-mapping`: one of the display transform's tone mappers.
pub(crate) fn parse_tone_mapping(text: &str) -> Result<ToneMapping, String> {
    ToneMapping::parse(text).ok_or_else(|| {
        let names: Vec<&str> = ToneMapping::ALL.iter().map(|t| t.name()).collect();
        format!(
            "unknown tone mapper '{text}': use one of {}",
            names.join(", ")
        )
    })
}

/// How the `pbr` model is lit and every model is shown: the flags `render`, `compare` and
/// `simplify -o CHAIN.glb` share with a config's `[render]` section.
#[derive(Args, Debug, Clone)]
pub(crate) struct LookArgs {
    /// Image-based lighting of the pbr model: `neutral` (a built-in lit room) or an
    /// equirectangular (2:1) Radiance .hdr or OpenEXR .exr file.
    #[arg(long, default_value = "neutral", value_name = "neutral|PATH")]
    pub(crate) environment: String,
    /// Rotation of the environment about the up axis, degrees.
    #[arg(long, default_value_t = 0.0, value_parser = finite, value_name = "DEGREES", allow_negative_numbers = true)]
    pub(crate) environment_rotation: f64,
    /// Factor on the environment's radiance.
    #[arg(long, default_value_t = 1.0, value_parser = value(&lodeval::limits::ENVIRONMENT_INTENSITY))]
    pub(crate) environment_intensity: f64,
    /// Exposure in stops (radiance × 2^STOPS before tone mapping).
    #[arg(long, default_value_t = 0.0, value_parser = value(&lodeval::limits::EXPOSURE_STOPS), value_name = "STOPS", allow_negative_numbers = true)]
    pub(crate) exposure: f64,
    /// Tone mapper: linear (a clamp), aces (Hill's fit) or pbr-neutral (Khronos). Default:
    /// pbr-neutral for the pbr model, linear for the others.
    #[arg(long, value_parser = parse_tone_mapping)]
    pub(crate) tone_mapping: Option<ToneMapping>,
    /// Turn off the pbr model's multiple-scattering energy compensation.
    #[arg(long)]
    pub(crate) no_multiple_scattering: bool,
}

impl LookArgs {
    /// The lighting these flags choose (the environment file is read here).
    pub(crate) fn lighting(&self) -> Result<Lighting, Error> {
        Lighting::new(
            &self.environment,
            std::path::Path::new("."),
            self.environment_rotation as f32,
            self.environment_intensity as f32,
        )
    }

    /// The look of a one-off run (`compare`, `simplify -o CHAIN.glb`) with `shading`.
    pub(crate) fn look(&self, shading: Shading) -> lodeval::eval::config::Look {
        lodeval::eval::config::Look {
            shading,
            environment: self.environment.clone(),
            environment_rotation: self.environment_rotation,
            environment_intensity: self.environment_intensity,
            exposure: self.exposure,
            tone_mapping: self.tone_mapping,
            multiple_scattering: !self.no_multiple_scattering,
        }
    }

    /// Set the display transform and the pbr options on `settings`.
    pub(crate) fn apply(&self, settings: &mut RenderSettings) {
        settings.exposure = self.exposure as f32;
        settings.tone_mapping = self.tone_mapping;
        settings.multiple_scattering = !self.no_multiple_scattering;
    }
}
