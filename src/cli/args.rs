//! Value types shared by several commands' flags: where to render, how to sample, how to load,
//! and the parsers for rigs, shading models and sample counts. Each enumerated flag is defined
//! once, here or beside its one command, as a `ValueEnum` or a `value_parser`.

use clap::{Args, ValueEnum};
use lodeval::limits::Bound;
use lodeval::raster::{SamplePattern, Shading};
use lodeval::scene::Rig;
use lodeval::{Error, LoadOptions, MissingAssets};

#[derive(Copy, Clone, Debug, ValueEnum)]
pub(crate) enum BackendArg {
    /// The CPU reference rasterizer and metrics.
    Cpu,
    /// The wgpu mirror (cargo feature `gpu`).
    Gpu,
    /// The GPU when built and an adapter exists, else the CPU.
    Auto,
}

impl From<BackendArg> for lodeval::backend::Backend {
    fn from(b: BackendArg) -> Self {
        match b {
            BackendArg::Cpu => Self::Cpu,
            BackendArg::Gpu => Self::Gpu,
            BackendArg::Auto => Self::Auto,
        }
    }
}

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
    #[arg(long, value_enum, default_value_t = MissingArg::Error)]
    pub(crate) missing_assets: MissingArg,
    /// Crease angle in degrees for computed normals (180 = smooth everywhere).
    #[arg(long, default_value_t = 180.0, value_name = "DEGREES")]
    pub(crate) crease_angle: f32,
}

#[derive(Copy, Clone, Debug, ValueEnum)]
pub(crate) enum MissingArg {
    /// Fail with a message naming the file.
    Error,
    /// Warn and render with the material's base colour.
    Warn,
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
        o.missing_assets = match self.missing_assets {
            MissingArg::Error => MissingAssets::Error,
            MissingArg::Warn => MissingAssets::Warn,
        };
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
