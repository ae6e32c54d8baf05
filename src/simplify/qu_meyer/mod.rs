//! Qu & Meyer: perceptually driven remeshing — where the surface signal (texture, normal-map
//! relief, lighting) masks geometric detail, fewer vertices are needed, so the vertices of a new
//! mesh are placed by a density that follows the surface's curvature and falls where the
//! signal's visual masking map is strong.
//!
//! Based on: Lijun Qu, Gary Meyer. Perceptually Driven Interactive Geometry Remeshing. I3D 2006;
//! Pierre Alliez, Mark Meyer, Mathieu Desbrun. Interactive Geometry Remeshing. SIGGRAPH 2002 (the
//! map-based framework it builds on).
//!
//! One stage per file, in the order they run:
//! - `raster::texture_space` — §4.3: the mesh rendered into its UV domain (the surface signal and
//!   the 3D point of every texel);
//! - `charts.rs` — the UV charts, their boundaries and the seams between them;
//! - `maps.rs` — §5.1: area distortion and curvature per texel;
//! - `masking.rs` — §4.2: the visual masking map (the calibrated VDP's masking stage and the TVI);
//! - `density.rs` — §5.2: the density with its two gammas, each chart's share;
//! - `sampling.rs` — §5.2: the first samples, by error diffusion;
//! - `lloyd.rs` — §5.2: Lloyd relaxation of the density-weighted CVT;
//! - `triangulate.rs` — §3, §5.3: constrained Delaunay in UV, projected back to 3D.
//!
//! The vertex budget counts 3D points: a seam vertex is one vertex however many charts share it
//! (the output, like the input, stores one copy per chart for their different UVs).
//!
//! Decision where the paper and the issue meet: a CVT's samples follow its weight w as
//! w^(d/(d+2)) (Gersho 1979), w^½ on a surface, so Lloyd's centroids (Equation 1) are weighted
//! with ρ² to keep the vertex counts following the density's integral, as error diffusion gives
//! them; with ρ itself (the paper's literal Equation 1) a region twice as dense would get only
//! √2 times the vertices.

#[doc(hidden)] // a step of the paper, public for tests and benches; start from `remesh`
pub mod charts;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `remesh`
pub mod density;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `remesh`
pub mod lloyd;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `remesh`
pub mod maps;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `remesh`
pub mod masking;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `remesh`
pub mod sampling;
#[doc(hidden)] // a step of the paper, public for tests and benches; start from `remesh`
pub mod triangulate;

use std::sync::Arc;
use std::time::Instant;

use glam::{Vec2, Vec3};

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::metric::vdp::Display;
use crate::raster::{RenderScene, TextureSpace, texture_space};
use crate::scene::Viewing;

use self::charts::Charts;
use self::density::{Density, apportion};
use self::maps::Maps;

/// Which density drives the samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Method {
    /// Curvature and the masking map (the paper's method).
    #[value(
        help = "Curvature and the visual masking map of the surface signal (the paper's method)"
    )]
    QuMeyer,
    /// Curvature only (the perceptual gamma 0).
    #[value(help = "Curvature only (--perceptual-gamma 0)")]
    Curvature,
    /// Neither: uniform on the surface (both gammas 0; the paper's baseline).
    #[value(help = "Uniform on the surface (both gammas 0; the paper's baseline)")]
    Uniform,
}

impl Method {
    /// All methods, in the order the CLI lists them.
    pub const ALL: [Method; 3] = [Method::QuMeyer, Method::Curvature, Method::Uniform];

    /// The CLI and config name.
    pub fn name(self) -> &'static str {
        match self {
            Method::QuMeyer => "qu-meyer",
            Method::Curvature => "curvature",
            Method::Uniform => "uniform",
        }
    }
}

/// Settings of a remesh.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Options {
    /// Vertices of the result (3D points). Required.
    pub vertices: usize,
    /// Which density. Default value: `QuMeyer`.
    pub method: Method,
    /// γ_c, the curvature map's weight. Default value: 1.2 (the paper's Figure 7c, d).
    pub curvature_gamma: f64,
    /// γ_p, the masking map's weight. Default value: 1.0 (the paper's Figure 7b).
    pub perceptual_gamma: f64,
    /// Lloyd iterations. Default value: 20 (the paper: 10–20).
    pub lloyd_iterations: usize,
    /// Texels per side of the maps. Default value: 512 (the paper's Figure 5).
    pub map_size: usize,
    /// Weight of the threshold-vs-intensity term in the masking map, 0 to 1 (the rest is the
    /// pattern term). Default value: 0.5.
    pub tvi_weight: f64,
    /// Pixels per degree the map is seen at (one texel per pixel). Default value: the default
    /// display's (0.7 m wide, 3840 px, seen from 0.7 m: about 67).
    pub ppd: f64,
    /// The display. Default value: [`Display::DEFAULT`].
    pub display: Display,
    /// Keep the maps as pictures. Default value: false.
    pub keep_maps: bool,
}

impl Options {
    /// The defaults, for `vertices` vertices.
    pub fn new(vertices: usize) -> Options {
        Options {
            vertices,
            method: Method::QuMeyer,
            curvature_gamma: 1.2,
            perceptual_gamma: 1.0,
            lloyd_iterations: 20,
            map_size: 512,
            tvi_weight: 0.5,
            ppd: Viewing::DEFAULT.ppd(),
            display: Display::DEFAULT,
            keep_maps: false,
        }
    }

    /// The gammas the method uses.
    pub fn gammas(&self) -> (f64, f64) {
        match self.method {
            Method::QuMeyer => (self.curvature_gamma, self.perceptual_gamma),
            Method::Curvature => (self.curvature_gamma, 0.0),
            Method::Uniform => (0.0, 0.0),
        }
    }

    /// Check every value before any work.
    pub fn check(&self) -> Result<()> {
        use crate::limits::{LLOYD_ITERATIONS, PPD, REMESH_GAMMA, REMESH_MAP, REMESH_VERTICES};
        for (name, g) in [
            ("--curvature-gamma", self.curvature_gamma),
            ("--perceptual-gamma", self.perceptual_gamma),
        ] {
            if !REMESH_GAMMA.contains(g) {
                return Err(Error::Usage(format!(
                    "{name} {g}: a gamma is a number from 0 to {} (0 turns its map off)",
                    REMESH_GAMMA.max
                )));
            }
        }
        if !(0.0..=1.0).contains(&self.tvi_weight) {
            return Err(Error::Usage(format!(
                "TVI weight {}: a weight from 0 to 1",
                self.tvi_weight
            )));
        }
        REMESH_VERTICES
            .check("--vertices", self.vertices as u64)
            .and(REMESH_MAP.check("--map-size", self.map_size as u64))
            .and(LLOYD_ITERATIONS.check("--lloyd-iterations", self.lloyd_iterations as u64))
            .and(PPD.check("--ppd", self.ppd))
            .map_err(Error::Usage)?;
        Ok(())
    }
}

/// Seconds per stage (wall clock; reporting only).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Seconds {
    /// The texture-space pass, charts, curvature and distortion maps.
    pub maps: f64,
    /// The masking map.
    pub masking: f64,
    /// Density, boundary sampling and error diffusion.
    pub sampling: f64,
    /// Lloyd relaxation.
    pub lloyd: f64,
    /// Triangulation and projection to 3D.
    pub triangulation: f64,
}

/// The maps as pictures (8-bit sRGB, map size), for people to look at.
#[derive(Debug, Clone)]
pub struct MapImages {
    /// The surface signal.
    pub signal: image::RgbImage,
    /// The masking map, brighter = stronger masking.
    pub masking: image::RgbImage,
    /// The curvature map.
    pub curvature: image::RgbImage,
    /// The density in the domain.
    pub density: image::RgbImage,
    /// The final samples over the density (boundary vertices in cyan, free ones in white).
    pub samples: image::RgbImage,
}

/// The map pictures' file names, in the order [`MapImages::write`] writes them.
pub const MAP_FILES: [&str; 5] = [
    "signal.png",
    "masking.png",
    "curvature.png",
    "density.png",
    "samples.png",
];

impl MapImages {
    /// Write the pictures into `dir` (created if missing) as [`MAP_FILES`].
    pub fn write(&self, dir: &std::path::Path) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|e| {
            Error::input(
                dir,
                format!("cannot create the maps folder: {e}"),
                "give a --maps folder you can write to",
            )
        })?;
        for (name, img) in MAP_FILES.iter().zip([
            &self.signal,
            &self.masking,
            &self.curvature,
            &self.density,
            &self.samples,
        ]) {
            crate::io::write_image(
                &dir.join(name),
                &image::DynamicImage::ImageRgb8(img.clone()),
            )?;
        }
        Ok(())
    }
}

/// A remesh and what it took.
#[derive(Debug, Clone)]
pub struct Remesh {
    /// The new mesh.
    pub mesh: Mesh,
    /// 3D points (welded vertices) of the new mesh.
    pub vertices: usize,
    /// Boundary (seam) vertices among them.
    pub boundary_vertices: usize,
    /// UV charts.
    pub charts: usize,
    /// Lloyd iterations run.
    pub iterations: usize,
    /// Seconds per stage.
    pub seconds: Seconds,
    /// Share of the vertices in the most strongly masked quarter of the surface (by area).
    pub masked_share: f64,
    /// The maps as pictures, when asked for.
    pub maps: Option<MapImages>,
}

/// Remesh `mesh` (which must have texture coordinates).
pub fn remesh(mesh: &Arc<Mesh>, options: &Options) -> Result<Remesh> {
    options.check()?;
    if mesh.uvs().is_none() {
        return Err(Error::input(
            &mesh.source().path,
            "the mesh has no texture coordinates; qu-meyer remeshes in the UV domain",
            "give a mesh with texture coordinates (unwrap it in a modelling tool first)",
        ));
    }
    let mut seconds = Seconds::default();
    let t = Instant::now();
    let ts = texture_space(&RenderScene::of(mesh.clone()), options.map_size)?;
    check_layout(mesh, &ts, options)?;
    let charts = Charts::of(mesh);
    let maps = Maps::new(mesh, &ts, &charts);
    seconds.maps = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let covered: Vec<bool> = maps.chart.iter().map(|&c| c != u32::MAX).collect();
    let (gc, gp) = options.gammas();
    // Computed for every method: the uniform and curvature remeshes are judged by where their
    // vertices fall on it too.
    let masking = masking::masking_map(
        ts.size,
        &ts.signal,
        &covered,
        options.ppd,
        options.display,
        options.tvi_weight as f32,
    )?;
    seconds.masking = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let m = &masking.masking;
    let density = Density::new(&maps.curvature, m, &maps, charts.count, (gc, gp));
    let welded = welded_positions(mesh);
    let representative = representative_texels(mesh, &ts);
    let mass = density.mass();
    let base = ((2.0 / 3f64.sqrt()) * mass / options.vertices as f64).sqrt();
    let mut refine = vec![false; welded.len()];
    let mut scale = 1.0f64;
    let mut keep = Vec::new();
    let mut boundary = 0;
    for _ in 0..40 {
        let spacing = |w: u32| {
            let r = representative[w as usize].map_or(0.0, |i| density.surface[i]);
            let r = if r > 0.0 { r as f64 } else { 1.0 };
            (scale * base / r.sqrt()) as f32
        };
        keep = charts.keep(&welded, &spacing, &refine);
        boundary = keep.iter().filter(|&&k| k).count();
        if boundary * 2 <= options.vertices {
            break;
        }
        scale *= 1.25;
    }
    if boundary >= options.vertices {
        return Err(Error::Usage(format!(
            "--vertices {}: the UV layout's {} charts need {} vertices on their seams alone; ask \
             for more vertices",
            options.vertices, charts.count, boundary
        )));
    }
    let targets = apportion(options.vertices - boundary, &density.chart_mass);
    let mut free = sampling::error_diffusion(ts.size, &maps.chart, &density.domain, &targets);
    seconds.sampling = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let fixed: Vec<Vec<Vec2>> = (0..charts.count)
        .map(|c| fixed_sites(mesh, &ts, &charts, &keep, c))
        .collect();
    relax(
        &ts,
        &maps,
        &density,
        &fixed,
        &mut free,
        options.lloyd_iterations,
    );
    seconds.lloyd = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let built = loop {
        match triangulate::triangulate(mesh, &ts, &charts, &keep, &free) {
            Ok(b) => break b,
            Err(Ok(more)) => {
                for w in more {
                    refine[w as usize] = true;
                    keep[w as usize] = true;
                }
            }
            Err(Err(e)) => return Err(e),
        }
    };
    let out = built.into_mesh(mesh)?;
    seconds.triangulation = t.elapsed().as_secs_f64();

    let masked_share = masked_share(&out, &ts, &maps, m);
    let images = options
        .keep_maps
        .then(|| map_images(&ts, &maps, &masking, &density, &out));
    Ok(Remesh {
        vertices: out.welded_vertex_count(),
        boundary_vertices: keep.iter().filter(|&&k| k).count(),
        charts: charts.count,
        iterations: options.lloyd_iterations,
        seconds,
        masked_share,
        maps: images,
        mesh: out,
    })
}

/// The UV layout can carry the remesh: one-to-one (at most 0.5 % of it covered twice), and
/// with a texel for every vertex asked for.
fn check_layout(mesh: &Mesh, ts: &TextureSpace, options: &Options) -> Result<()> {
    if ts.overlapping * 200 > ts.covered {
        return Err(Error::input(
            &mesh.source().path,
            format!(
                "{:.1} % of the UV layout is covered by more than one triangle (overlapping or \
                 mirrored charts), so texels do not map to one point of the surface",
                100.0 * ts.overlapping as f64 / ts.covered.max(1) as f64
            ),
            "qu-meyer needs a one-to-one UV layout: unwrap the mesh without overlaps, or give \
             mirrored parts their own space in the atlas",
        ));
    }
    if options.vertices > ts.covered {
        return Err(Error::Usage(format!(
            "--vertices {}: more than the {} texels the UV layout covers at --map-size {}; ask \
             for fewer vertices or a larger map",
            options.vertices, ts.covered, options.map_size
        )));
    }
    Ok(())
}

/// Lloyd relaxation of each chart's free samples, weighted by the squared density, around the
/// chart's `fixed` boundary sites.
fn relax(
    ts: &TextureSpace,
    maps: &Maps,
    density: &Density,
    fixed: &[Vec<Vec2>],
    free: &mut [Vec<Vec2>],
    iterations: usize,
) {
    let weights: Vec<f32> = density.domain.iter().map(|&d| d * d).collect();
    let mut texels: Vec<Vec<u32>> = vec![Vec::new(); fixed.len()];
    for (i, &c) in maps.chart.iter().enumerate() {
        if c != u32::MAX {
            texels[c as usize].push(i as u32);
        }
    }
    for (c, samples) in free.iter_mut().enumerate() {
        let chart = &maps.chart;
        let size = ts.size;
        let in_chart = |p: Vec2| {
            let (x, y) = (p.x.floor(), p.y.floor());
            x >= 0.0
                && y >= 0.0
                && (x as usize) < size
                && (y as usize) < size
                && chart[y as usize * size + x as usize] == c as u32
        };
        lloyd::relax(
            ts.size, &texels[c], &weights, &in_chart, &fixed[c], samples, iterations,
        );
    }
}

/// Position per welded vertex.
fn welded_positions(mesh: &Mesh) -> Vec<Vec3> {
    let mut p = vec![Vec3::ZERO; mesh.welded_vertex_count()];
    for (v, &w) in mesh.weld().iter().enumerate() {
        p[w as usize] = mesh.positions()[v];
    }
    p
}

/// Per welded vertex, a covered texel at (or within two texels of) its lowest copy's UV.
fn representative_texels(mesh: &Mesh, ts: &TextureSpace) -> Vec<Option<usize>> {
    let uvs = mesh.uvs().unwrap_or_default();
    let mut out = vec![None; mesh.welded_vertex_count()];
    for (v, &w) in mesh.weld().iter().enumerate().rev() {
        let p = ts.texel_of(uvs[v]);
        let (x0, y0) = (p.x.floor() as isize, p.y.floor() as isize);
        let s = ts.size as isize;
        let mut found = None;
        'search: for r in 0..=2isize {
            for y in y0 - r..=y0 + r {
                for x in x0 - r..=x0 + r {
                    if (0..s).contains(&x) && (0..s).contains(&y) {
                        let i = (y * s + x) as usize;
                        if ts.triangle[i] != crate::raster::NO_TRIANGLE {
                            found = Some(i);
                            break 'search;
                        }
                    }
                }
            }
        }
        if found.is_some() {
            out[w as usize] = found;
        }
    }
    out
}

/// Chart `c`'s kept boundary vertices as texel coordinates.
fn fixed_sites(
    mesh: &Mesh,
    ts: &TextureSpace,
    charts: &Charts,
    keep: &[bool],
    c: usize,
) -> Vec<Vec2> {
    let uvs = mesh.uvs().unwrap_or_default();
    let weld = mesh.weld();
    charts.loops[c]
        .iter()
        .flatten()
        .filter(|&&v| keep[weld[v as usize] as usize])
        .map(|&v| ts.texel_of(uvs[v as usize]))
        .collect()
}

/// Share of `out`'s vertices that lie where the masking map is in its strongest quarter of the
/// covered surface (by 3D area).
fn masked_share(out: &Mesh, ts: &TextureSpace, maps: &Maps, masking: &[f32]) -> f64 {
    let mut by_mask: Vec<(f32, f32)> = masking
        .iter()
        .zip(&maps.area)
        .filter(|(_, a)| **a > 0.0)
        .map(|(&m, &a)| (m, a))
        .collect();
    by_mask.sort_by(|a, b| b.0.total_cmp(&a.0));
    let total: f64 = by_mask.iter().map(|x| x.1 as f64).sum();
    let mut acc = 0.0;
    let mut threshold = f32::INFINITY;
    for (m, a) in &by_mask {
        acc += *a as f64;
        threshold = *m;
        if acc >= 0.25 * total {
            break;
        }
    }
    let uvs = out.uvs().unwrap_or_default();
    let mut seen = vec![false; out.welded_vertex_count()];
    let (mut inside, mut all) = (0usize, 0usize);
    for (v, &w) in out.weld().iter().enumerate() {
        if std::mem::replace(&mut seen[w as usize], true) {
            continue;
        }
        all += 1;
        let p = ts.texel_of(uvs[v]);
        let (x, y) = (p.x.floor() as isize, p.y.floor() as isize);
        let s = ts.size as isize;
        if (0..s).contains(&x) && (0..s).contains(&y) {
            let i = (y * s + x) as usize;
            if maps.area[i] > 0.0 && masking[i] >= threshold {
                inside += 1;
            }
        }
    }
    if all == 0 {
        0.0
    } else {
        inside as f64 / all as f64
    }
}

/// The maps as pictures.
fn map_images(
    ts: &TextureSpace,
    maps: &Maps,
    masking: &masking::MaskingMap,
    density: &Density,
    out: &Mesh,
) -> MapImages {
    let s = ts.size as u32;
    let covered = |i: usize| maps.chart[i] != u32::MAX;
    let grey = [40u8, 40, 40];
    let to_rgb = |f: &dyn Fn(usize) -> [u8; 3]| {
        image::RgbImage::from_fn(s, s, |x, y| {
            let i = (y * s + x) as usize;
            image::Rgb(if covered(i) { f(i) } else { grey })
        })
    };
    // A map scaled to its 99th percentile over covered texels, through magma.
    let scaled = |v: &[f32]| {
        let mut c: Vec<f32> = (0..v.len()).filter(|&i| covered(i)).map(|i| v[i]).collect();
        c.sort_by(f32::total_cmp);
        let lo = c.first().copied().unwrap_or(0.0);
        let hi = c
            .get(c.len() * 99 / 100)
            .copied()
            .unwrap_or(1.0)
            .max(lo + 1e-12);
        to_rgb(&|i| crate::metric::colormap::magma(((v[i] - lo) / (hi - lo)).clamp(0.0, 1.0)))
    };
    let signal = to_rgb(&|i| {
        let c = ts.signal[i];
        [c.x, c.y, c.z]
            .map(|v| (crate::color::linear_to_srgb(v.clamp(0.0, 1.0)) * 255.0).round() as u8)
    });
    // log M: the least masked texel black, the strongest white.
    let l: Vec<f32> = masking.masking.iter().map(|v| v.max(1e-6).ln()).collect();
    let (lo, hi) = (0..l.len())
        .filter(|&i| covered(i))
        .fold((f32::MAX, f32::MIN), |(a, b), i| (a.min(l[i]), b.max(l[i])));
    let masking_img = to_rgb(&|i| {
        [((l[i] - lo) / (hi - lo).max(1e-6))
            .clamp(0.0, 1.0)
            .mul_add(255.0, 0.0) as u8; 3]
    });
    let curvature = scaled(&maps.curvature);
    let density_img = scaled(&density.domain);
    let mut samples = density_img.clone();
    let uvs = out.uvs().unwrap_or_default();
    let mut boundary = vec![false; out.vertex_count()];
    // Boundary vertices of the output: on an edge of one triangle.
    let mut edges: Vec<(u32, u32)> = out
        .triangles()
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    edges.sort_unstable();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j] == edges[i] {
            j += 1;
        }
        if j - i == 1 {
            boundary[edges[i].0 as usize] = true;
            boundary[edges[i].1 as usize] = true;
        }
        i = j;
    }
    for (v, uv) in uvs.iter().enumerate() {
        let p = ts.texel_of(*uv);
        let colour = if boundary[v] {
            [0u8, 230, 230]
        } else {
            [255u8, 255, 255]
        };
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let (x, y) = (p.x.floor() as i64 + dx - 1, p.y.floor() as i64 + dy - 1);
            if (0..s as i64).contains(&x) && (0..s as i64).contains(&y) {
                samples.put_pixel(x as u32, y as u32, image::Rgb(colour));
            }
        }
    }
    MapImages {
        signal,
        masking: masking_img,
        curvature,
        density: density_img,
        samples,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{LoadOptions, shapes};

    /// An n×n grid per face of the cube [−1, 1]³, each face its own UV island of a 3×2 atlas
    /// (with gaps), so the cube is closed in 3D and cut into six charts in UV.
    fn atlas_cube(n: u32) -> Mesh {
        let mut data = shapes::grid_plane(1).to_data();
        let (mut positions, mut uvs, mut triangles) = (Vec::new(), Vec::new(), Vec::new());
        let axes = [
            (Vec3::X, Vec3::Z, Vec3::Y),
            (-Vec3::X, -Vec3::Z, Vec3::Y),
            (Vec3::Y, Vec3::X, Vec3::Z),
            (-Vec3::Y, Vec3::X, -Vec3::Z),
            (Vec3::Z, -Vec3::X, Vec3::Y),
            (-Vec3::Z, Vec3::X, Vec3::Y),
        ];
        for (f, (normal, u, v)) in axes.into_iter().enumerate() {
            // u × v must point along the normal for counter-clockwise winding from outside.
            let (u, v) = if u.cross(v).dot(normal) > 0.0 {
                (u, v)
            } else {
                (v, u)
            };
            let base = positions.len() as u32;
            let cell = Vec2::new((f % 3) as f32, (f / 3) as f32);
            for j in 0..=n {
                for i in 0..=n {
                    let (s, t) = (i as f32 / n as f32, j as f32 / n as f32);
                    // Integer coordinates first, so that shared edges weld exactly.
                    let k = (
                        n as f32,
                        (2 * i) as f32 - n as f32,
                        (2 * j) as f32 - n as f32,
                    );
                    positions.push((normal * k.0 + u * k.1 + v * k.2) / n as f32);
                    uvs.push((cell + Vec2::new(0.05, 0.05) + Vec2::new(s, t) * 0.9) / 3.0);
                }
            }
            let id = |i: u32, j: u32| base + j * (n + 1) + i;
            for j in 0..n {
                for i in 0..n {
                    triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                    triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
                }
            }
        }
        data.positions = positions;
        data.uvs = Some(uvs);
        data.normals = None;
        data.triangles = triangles;
        data.material_ids = Vec::new();
        Mesh::new(data, &LoadOptions::DEFAULT).unwrap()
    }

    /// Welded edges used by other than two triangles.
    fn open_edges(mesh: &Mesh) -> usize {
        let w = mesh.weld();
        let mut edges: Vec<(u32, u32)> = mesh
            .triangles()
            .iter()
            .flat_map(|t| {
                (0..3).map(move |k| {
                    let (a, b) = (w[t[k] as usize], w[t[(k + 1) % 3] as usize]);
                    (a.min(b), a.max(b))
                })
            })
            .collect();
        edges.sort_unstable();
        let mut bad = 0;
        let mut i = 0;
        while i < edges.len() {
            let mut j = i + 1;
            while j < edges.len() && edges[j] == edges[i] {
                j += 1;
            }
            if j - i != 2 {
                bad += 1;
            }
            i = j;
        }
        bad
    }

    fn small(vertices: usize) -> Options {
        Options {
            map_size: 256,
            ..Options::new(vertices)
        }
    }

    #[test]
    fn the_remeshed_plane_is_the_plane() {
        let mut data = shapes::grid_plane(8).to_data();
        data.uvs = Some(
            data.positions
                .iter()
                .map(|p| Vec2::new(p.x, p.y) / 8.0)
                .collect(),
        );
        let plane = Arc::new(Mesh::new(data, &LoadOptions::DEFAULT).unwrap());
        let r = remesh(&plane, &small(150)).unwrap();
        let m = &r.mesh;
        assert!(m.positions().iter().all(|p| p.z == 0.0));
        // The same square: its corners kept, its area covered exactly once.
        let area: f32 = m
            .triangles()
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions()[i as usize]);
                (b - a).cross(c - a).z * 0.5
            })
            .sum();
        assert!((area - 64.0).abs() < 1e-3, "{area}");
        let bb = m.aabb();
        assert_eq!((bb.min, bb.max), (Vec3::ZERO, Vec3::new(8.0, 8.0, 0.0)));
        // UVs still map the plane linearly.
        let uvs = m.uvs().unwrap();
        for (p, uv) in m.positions().iter().zip(uvs) {
            assert!((Vec2::new(p.x, p.y) / 8.0 - *uv).length() < 1e-4);
        }
        assert!((140..=150).contains(&r.vertices), "{}", r.vertices);
    }

    #[test]
    fn a_closed_textured_mesh_stays_closed_and_its_seams_match() {
        let cube = Arc::new(atlas_cube(6));
        assert_eq!(open_edges(&cube), 0);
        let r = remesh(&cube, &small(300)).unwrap();
        assert_eq!(r.charts, 6);
        assert_eq!(open_edges(&r.mesh), 0, "the remeshed cube has holes");
        // Every vertex lies on the cube's surface.
        for p in r.mesh.positions() {
            assert!((p.abs().max_element() - 1.0).abs() < 1e-5, "{p}");
        }
        // Spot: 13 charts, closed, the same check.
        let spot = Arc::new(
            crate::mesh::load(
                std::path::Path::new(concat!(
                    env!("CARGO_MANIFEST_DIR"),
                    "/reference/models/spot/spot_mtl.obj"
                )),
                &LoadOptions::DEFAULT,
            )
            .unwrap(),
        );
        assert_eq!(open_edges(&spot), 0);
        let r = remesh(&spot, &small(800)).unwrap();
        assert_eq!(open_edges(&r.mesh), 0, "the remeshed Spot has holes");
        assert!((770..=800).contains(&r.vertices), "{}", r.vertices);
    }

    #[test]
    fn the_result_is_identical_for_1_2_and_8_threads() {
        let cube = Arc::new(atlas_cube(5));
        let run = |t| {
            crate::raster::with_threads(t, || {
                let r = remesh(&cube, &small(200)).unwrap();
                (
                    r.mesh.positions().to_vec(),
                    r.mesh.uvs().unwrap().to_vec(),
                    r.mesh.triangles().to_vec(),
                )
            })
            .unwrap()
        };
        let one = run(1);
        assert_eq!(one, run(2));
        assert_eq!(one, run(8));
    }

    #[test]
    fn on_two_density_levels_the_counts_follow_the_integral() {
        // Error diffusion, then Lloyd weighted with ρ² (see the module comment), on a 1 : 3
        // density: three quarters of the samples on the dense half.
        let size = 128;
        let chart = vec![0u32; size * size];
        let density: Vec<f32> = (0..size * size)
            .map(|t| if t % size < 64 { 1.0 } else { 3.0 })
            .collect();
        let mut s = sampling::error_diffusion(size, &chart, &density, &[400]);
        let right = |s: &[Vec2]| s.iter().filter(|p| p.x > 64.0).count();
        assert!((295..=305).contains(&right(&s[0])), "{}", right(&s[0]));
        let texels: Vec<u32> = (0..(size * size) as u32).collect();
        let weights: Vec<f32> = density.iter().map(|d| d * d).collect();
        lloyd::relax(size, &texels, &weights, &|_| true, &[], &mut s[0], 30);
        assert!((285..=315).contains(&right(&s[0])), "{}", right(&s[0]));
    }

    #[test]
    fn the_masking_map_is_flat_on_a_flat_texture_and_high_on_noise() {
        let size = 128;
        let covered = vec![true; size * size];
        let flat = vec![Vec3::splat(0.4); size * size];
        let m = masking::masking_map(size, &flat, &covered, 30.0, Display::DEFAULT, 0.5).unwrap();
        assert!(m.masking.iter().all(|&v| (v - 1.0).abs() < 1e-3));
        // The right half noise around the same mean.
        let mut state = 1u32;
        let noisy: Vec<Vec3> = (0..size * size)
            .map(|i| {
                if i % size < size / 2 {
                    Vec3::splat(0.4)
                } else {
                    state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                    Vec3::splat(0.4 + 0.3 * ((state >> 8) as f32 / (1 << 24) as f32 - 0.5))
                }
            })
            .collect();
        let m = masking::masking_map(size, &noisy, &covered, 30.0, Display::DEFAULT, 0.5).unwrap();
        let half = |right: bool| {
            let v: Vec<f32> = (0..size * size)
                .filter(|i| {
                    let x = i % size;
                    if right {
                        x >= size / 2 + 16
                    } else {
                        x < size / 2 - 16
                    }
                })
                .map(|i| m.masking[i])
                .collect();
            v.iter().sum::<f32>() / v.len() as f32
        };
        assert!(half(false) < 1.1, "{}", half(false));
        assert!(
            half(true) > 2.0 * half(false),
            "{} {}",
            half(true),
            half(false)
        );
    }

    #[test]
    fn overlapping_uv_charts_are_refused() {
        // Every face of the cube on the same UV square.
        let cube = atlas_cube(2);
        let mut data = cube.to_data();
        data.uvs = Some(
            data.uvs
                .unwrap()
                .iter()
                .map(|uv| (*uv * 3.0).fract())
                .collect(),
        );
        let m = Arc::new(Mesh::new(data, &LoadOptions::DEFAULT).unwrap());
        let e = remesh(&m, &small(100)).unwrap_err().to_string();
        assert!(e.contains("covered by more than one triangle"), "{e}");
    }
}
