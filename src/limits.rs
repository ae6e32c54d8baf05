//! Every bound on a size, count or value a user can give lodeval, on the command line or in a
//! config, in one place with the reason for each. A value outside its bound is refused with a
//! message naming the flag or key, the bound and why it exists; nothing is clamped silently.
//! README.md's "Limits" table lists the same bounds, and a test keeps the two in step.
//!
//! Decisions:
//! - Bounds are set where memory or time would otherwise grow without end, or where the
//!   computation stops meaning anything (a pixel wider than a degree of visual angle), and
//!   generously above what any real job needs, so they never get in a real job's way.
//! - Sizes of files read are bounds too (an input is read only up to what its format can need,
//!   so `/dev/zero` under a mesh's name cannot exhaust memory).

/// A number a bound is about, printed briefly (1e30, not thirty zeros).
pub trait Quantity: PartialOrd + Copy {
    /// The value as a person reads it.
    fn show(self) -> String;
}

impl Quantity for u64 {
    fn show(self) -> String {
        self.to_string()
    }
}

impl Quantity for f64 {
    fn show(self) -> String {
        brief(self)
    }
}

impl Quantity for f32 {
    fn show(self) -> String {
        brief(self as f64)
    }
}

/// Six significant digits at most, trailing zeros dropped; scientific notation outside
/// 1e-3 … 1e7 (`1e30`, `0.7`, `1.41421`, `1024`).
fn brief(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() || a == 0.0 {
        return v.to_string();
    }
    let trim = |t: String| {
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    };
    if (1e-3..1e7).contains(&a) {
        let decimals = (5 - a.log10().floor() as i32).max(0) as usize;
        trim(format!("{v:.decimals$}"))
    } else if format!("{v:e}").trim_start_matches('-').len() <= 12 {
        // Rust's shortest round-trip form when it is short (`1e-320`: a subnormal printed with
        // five decimals would show its lost precision, 9.99989e-321).
        format!("{v:e}")
    } else {
        let t = format!("{v:.5e}");
        let (mantissa, exponent) = t.split_once('e').unwrap_or((&t, "0"));
        format!("{}e{exponent}", trim(mantissa.to_string()))
    }
}

/// An inclusive range of allowed values with the words a message needs.
///
/// # Guarantees
/// `min ≤ max`, both finite (the constants below are the only instances).
#[derive(Debug, Clone, Copy)]
pub struct Bound<T> {
    /// Smallest allowed value.
    pub min: T,
    /// Largest allowed value.
    pub max: T,
    /// What is counted or measured ("worker threads", "pixels per degree").
    pub unit: &'static str,
    /// Why the bound is there, for the message.
    pub why: &'static str,
}

impl<T: Quantity> Bound<T> {
    /// Whether `v` lies within the bound (a NaN does not).
    pub fn contains(&self, v: T) -> bool {
        self.min <= v && v <= self.max
    }

    /// `Ok(v)` within the bound, else a message naming `what` (a flag or a config key), the
    /// value, the bound and the reason.
    pub fn check(&self, what: &str, v: T) -> Result<T, String> {
        self.refuse(v).map_or(Ok(v), |m| Err(format!("{what} {m}")))
    }

    /// `None` within the bound, else "V is outside lodeval's limits of MIN to MAX UNIT (WHY)".
    pub fn refuse(&self, v: T) -> Option<String> {
        (!self.contains(v)).then(|| format!("{} is {}", v.show(), self.outside()))
    }

    /// "outside lodeval's limits of MIN to MAX UNIT (WHY)".
    pub fn outside(&self) -> String {
        format!(
            "outside lodeval's limits of {} to {} {} ({})",
            self.min.show(),
            self.max.show(),
            self.unit,
            self.why
        )
    }
}

/// Worker threads (`--threads`). Starting threads costs time that grows faster than their
/// number (1 024 take 1.5 s to start on the 2-core reference machine, 4 000 took 22 s), and no
/// machine lodeval runs on has more cores than this.
pub const THREADS: Bound<u64> = Bound {
    min: 1,
    max: 1024,
    unit: "worker threads",
    why: "more threads than cores only cost start-up time",
};

/// Views of a rig (`fibonacci:N`, `--views`): each view is rendered and scored, and the views'
/// cameras and scores are held at once.
pub const VIEWS: Bound<u64> = Bound {
    min: 1,
    max: 10_000,
    unit: "views",
    why: "10 000 views already sample the sphere every 2 degrees",
};

/// Image edge in pixels (`--size`, `[render] size`, `max_diameter_px`): a 16 384² frame with its
/// depth and sample buffers takes several GiB.
pub const IMAGE_SIDE: Bound<u64> = Bound {
    min: 1,
    max: 16_384,
    unit: "pixels",
    why: "a 16 384² frame and its buffers already take several GiB",
};

/// Pixels per degree of visual angle (`--ppd`, `[viewing] ppd`, and the value the display
/// geometry gives). Below 1 a pixel is wider than a degree and the metrics' filters have no
/// pixels to act on; above 1 000 a pixel is 17 times finer than the eye resolves, and the
/// filter kernels (which grow with it) take the memory.
pub const PPD: Bound<f64> = Bound {
    min: 1.0,
    max: 1000.0,
    unit: "pixels per degree",
    why: "below 1 a pixel spans more than a degree; above 1 000 it is far finer than the eye resolves",
};

/// Face samples per mesh for the surface distances (`geometry --samples`,
/// `geometry_samples`): 32 bytes of memory each, over both meshes.
pub const SURFACE_SAMPLES: Bound<u64> = Bound {
    min: 0,
    max: 50_000_000,
    unit: "face samples",
    why: "50 million samples take 1.6 GiB and measure to about 0.01 % of the diagonal",
};

/// Views on one contact sheet (`sheet_views`).
pub const SHEET_VIEWS: Bound<u64> = Bound {
    min: 1,
    max: 100,
    unit: "views",
    why: "a sheet is a picture for a person; use heat maps for more views",
};

/// Pixels of one contact sheet (three tiles across, one row per view): the sheet is held in
/// memory as 8-bit RGBA before it is written.
pub const SHEET_PIXELS: Bound<u64> = Bound {
    min: 1,
    max: 1 << 28,
    unit: "pixels",
    why: "a sheet of 268 million pixels takes 1 GiB; lower sheet_views or the image size",
};

/// Triangles of a generated benchmark mesh (`bench raster --rings × --sides × 2`,
/// `bench simplify --bumpy`): vertices, indices and the prepared mesh are held at once.
pub const GENERATED_TRIANGLES: Bound<u64> = Bound {
    min: 1,
    max: 100_000_000,
    unit: "triangles",
    why: "100 million triangles take about 10 GiB once prepared for rendering",
};

/// Rings and sides of the benchmark torus (`bench raster --rings`, `--sides`): fewer than three
/// make no closed surface; the triangle count is bounded by [`GENERATED_TRIANGLES`].
pub const TORUS_SEGMENTS: Bound<u64> = Bound {
    min: 3,
    max: 10_000_000,
    unit: "segments",
    why: "fewer than three make no torus, and more than ten million rings or sides exceed the \
          bound of 100 000 000 triangles with any partner",
};

/// Energy evaluations of the image-driven optimizer (`--evals`): only time grows with it.
pub const EVALS: Bound<u64> = Bound {
    min: 1,
    max: 10_000_000_000,
    unit: "evaluations",
    why: "ten billion evaluations take weeks",
};

/// Timed runs of a benchmark (`--runs`).
pub const RUNS: Bound<u64> = Bound {
    min: 1,
    max: 1000,
    unit: "runs",
    why: "the median of 1 000 runs is as good as it gets",
};

/// Vertices of a remesh (`remesh --vertices`): each is a Lloyd site and a triangulation vertex,
/// and there can be no more than the UV layout's texels anyway.
pub const REMESH_VERTICES: Bound<u64> = Bound {
    min: 4,
    max: 10_000_000,
    unit: "vertices",
    why: "a remesh needs a triangle's worth, and ten million take gigabytes of maps to place",
};

/// Texels per side of a remesh's maps (`remesh --map-size`): about a dozen maps of that size are
/// held at once, 4–12 bytes per texel each.
pub const REMESH_MAP: Bound<u64> = Bound {
    min: 16,
    max: 8192,
    unit: "texels per side",
    why: "an 8192² layout's maps take several GiB",
};

/// Lloyd iterations of a remesh (`remesh --lloyd-iterations`): only time grows with it.
pub const LLOYD_ITERATIONS: Bound<u64> = Bound {
    min: 0,
    max: 1000,
    unit: "iterations",
    why: "Lloyd's relaxation settles in tens of iterations",
};

/// The gammas of a remesh's density (`--curvature-gamma`, `--perceptual-gamma`): the density
/// goes with a map raised to it, so large values only reach the range of single precision.
pub const REMESH_GAMMA: Bound<f64> = Bound {
    min: 0.0,
    max: 10.0,
    unit: "",
    why: "a map raised beyond the 10th power leaves single precision's range",
};

/// Exposures of HDR-FLIP (`diff --num-exposures`): each is a full LDR-FLIP of the pair.
pub const EXPOSURES: Bound<u64> = Bound {
    min: 1,
    max: 64,
    unit: "exposures",
    why: "64 exposures span far more than any display's range; each costs a whole FLIP",
};

/// Width of an environment map (`environment = PATH`), texels; the height is half. The renderer
/// prefilters at most 512 texels across, so a larger map only costs memory: 8 192 × 4 096 takes
/// 400 MiB as floats.
pub const ENVIRONMENT_SIDE: Bound<u64> = Bound {
    min: 16,
    max: 8192,
    unit: "texels across",
    why: "an 8 192-wide map already takes 400 MiB, and the lighting is prefiltered at 512",
};

/// Exposure in stops (`exposure`, `--exposure`): 2^±24 spans far more than any scene's range.
pub const EXPOSURE_STOPS: Bound<f64> = Bound {
    min: -24.0,
    max: 24.0,
    unit: "stops",
    why: "2^24 is beyond any scene's range, and single precision loses it",
};

/// Environment intensity (`environment_intensity`): a factor on the map's radiance.
pub const ENVIRONMENT_INTENSITY: Bound<f64> = Bound {
    min: 0.0,
    max: 1e6,
    unit: "",
    why: "a million times a map's radiance is beyond any exposure",
};

/// A mesh's size: its bounding-box diagonal in model units. Squared triangle areas (fourth
/// powers of lengths) are formed in single precision, whose range is about 1e±38.
pub const MESH_EXTENT: Bound<f64> = Bound {
    min: 1e-6,
    max: 1e9,
    unit: "model units across",
    why: "squared triangle areas, the fourth power of the size, must fit single precision",
};

/// How far a mesh may sit from the origin (its farthest coordinate), in multiples of its size.
/// Positions are single precision: 1 024 sizes out they resolve the shape to 1/8 000 of its
/// size, and much farther out vertices merge and renders break up.
pub const MESH_OFFSET: Bound<f64> = Bound {
    min: 0.0,
    max: 1024.0,
    unit: "times its size from the origin",
    why: "single-precision positions farther out cannot hold the shape",
};

/// Memory a job is estimated to need, checked before it starts from its image sizes and view
/// counts with the per-pixel costs below (peak-memory slopes measured on the reference machine,
/// rounded up), so a job that cannot fit is refused at once instead of being killed hours in.
pub const MEMORY_GIB: Bound<f64> = Bound {
    min: 0.0,
    max: 16.0,
    unit: "GiB of memory",
    why: "estimated before the job starts; lower the image size or the number of views",
};

/// Bytes per pixel of one image pair scored with every metric (FLIP, SSIM, PSNR, the VDP's band
/// planes): measured 165 in `eval`, 90 in `diff`.
pub const BYTES_PER_SCORED_PIXEL: u64 = 200;
/// Bytes per pixel of each view's prepared reference, which `eval` keeps for all views of an
/// asset while its LODs are scored: measured 16.
pub const BYTES_PER_REFERENCE_PIXEL: u64 = 24;
/// Bytes per pixel of each view the image-driven optimizer holds: measured 72.
pub const BYTES_PER_OPTIMIZER_PIXEL: u64 = 96;
/// Bytes per pixel of one render (any sample count: samples are resolved tile by tile):
/// measured 28.
pub const BYTES_PER_RENDERED_PIXEL: u64 = 40;

/// `Ok` when a job estimated at `bytes` fits [`MEMORY_GIB`]; else "JOB would need about N GiB,
/// outside …".
pub fn check_memory(job: &str, bytes: u64) -> Result<(), String> {
    let gib = bytes as f64 / (1u64 << 30) as f64;
    match MEMORY_GIB.refuse(gib) {
        None => Ok(()),
        Some(_) => Err(format!(
            "{job} would need about {:.1} GiB, {}",
            gib,
            MEMORY_GIB.outside()
        )),
    }
}

/// Largest mesh file read (OBJ, MTL, PLY, OFF, glTF, GLB and glTF buffers), bytes.
pub const MESH_BYTES: u64 = 4 << 30;
/// Largest image file read (textures, `diff` and golden images), bytes.
pub const IMAGE_BYTES: u64 = 1 << 30;
/// Largest config or manifest read (TOML, JSON), bytes.
pub const CONFIG_BYTES: u64 = 16 << 20;
/// Largest CSV table read (a gate baseline, a shard's tables), bytes.
pub const TABLE_BYTES: u64 = 4 << 30;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_are_inclusive_and_refuse_nan() {
        assert!(THREADS.contains(1) && THREADS.contains(1024));
        assert!(!THREADS.contains(0) && !THREADS.contains(1025));
        assert!(PPD.contains(1.0) && PPD.contains(1000.0));
        assert!(!PPD.contains(f64::NAN) && !PPD.contains(1e-30) && !PPD.contains(1e30));
        assert_eq!(1e30f64.show(), "1e30");
        assert_eq!(1.7320508336e30f64.show(), "1.73205e30");
        assert_eq!(0.7f64.show(), "0.7");
        assert_eq!(0.1f32.show(), "0.1");
        assert_eq!(1024f64.show(), "1024");
        assert_eq!(5773503.27f64.show(), "5773503");
        assert_eq!(1e-6f64.show(), "1e-6");
        assert!(check_memory("x", 1 << 30).is_ok());
        let m = check_memory("eval at 16384²", 48 << 30).unwrap_err();
        assert!(
            m.contains("about 48.0 GiB") && m.contains("0 to 16 GiB"),
            "{m}"
        );
        let e = THREADS.check("--threads", 100_000).unwrap_err();
        assert!(
            e.contains("--threads 100000") && e.contains("1 to 1024 worker threads"),
            "{e}"
        );
    }

    #[test]
    fn every_bound_is_in_the_readme() {
        // The README's "Limits" table must name every bound of this file with its maximum.
        let readme = include_str!("../README.md");
        let section = readme
            .split("\n## Limits")
            .nth(1)
            .expect("README.md has a Limits section");
        let section = section.split("\n## ").next().unwrap();
        let code = include_str!("limits.rs");
        let names: Vec<&str> = code
            .lines()
            .filter_map(|l| l.strip_prefix("pub const "))
            .filter_map(|l| l.split(':').next())
            .collect();
        assert!(names.len() >= 20, "{names:?}");
        for name in names {
            assert!(
                section.contains(&format!("`{name}`")),
                "README's Limits section lacks `{name}`"
            );
        }
    }
}
