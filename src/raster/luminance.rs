//! Incremental luminance images of an editable mesh: the renderer inside the image-driven
//! optimizer's energy (Lindstrom & Turk 2000, §4.1–4.3).
//!
//! For each of l views it keeps the luminance image of the current mesh, the nearest piece of every
//! pixel and the two behind it (three *layers*), and per triangle its set-up (the rasterizer's
//! `setup.rs`) and the screen tiles its bounding box touches (the paper's triangle buckets). A
//! *trial* takes the triangles a move changed (vertices moved, attributes changed, connectivity
//! edited), sets them up anew and visits only the pixels that can change, R_h of eq. 2:
//! - *holes*, where a changed triangle showed: the nearest layer behind it that belongs to an
//!   unchanged triangle shows there now (where all three are changed, a fold or a silhouette, the
//!   unchanged triangles overlapping the hole are found through the buckets and rasterized);
//! - the changed triangles' new pieces, depth-tested against a hole's fill or the committed depth;
//! - the pixels of re-shaded triangles (same corners, new attributes or light terms);
//!
//! and returns ΔE = Σ_h Σ_{R_h} [(ŷ − y′)² − (ŷ − y)²]. `commit` makes the trial the current state:
//! it renders the region the changed triangles covered before or cover now again, with all three
//! layers, from every triangle there (commits are rare: about one evaluation in a hundred is
//! accepted). `revert` drops the trial. Views are independent and run in parallel.
//!
//! A move on the far side of the mesh often changes nothing in a view: a changed triangle that
//! shows in no pixel opens no hole, and a new piece behind every committed depth of the tiles it
//! touches (while nothing that changed shows) cannot win a pixel. Per-triangle shown-pixel counts
//! and per-tile farthest depths, kept on commit, decide this.
//!
//! Why layers and not a rectangle: the earlier design re-rendered the bounding rectangle of all
//! old and new boxes, filling the holes by rasterizing every unchanged triangle overlapping them
//! (73 on average on the bunny at 256², two thirds of them hidden). The pixels that can change are
//! a third of that rectangle (632 of 1 750 on average), and the layers fill most holes with a
//! look-up; with two layers 46 % of renders still had a hole three changed layers deep, with
//! three 30 % (measured on the bunny, 30 000 evaluations).
//!
//! Decisions:
//! - Luminance is the paper's: NTSC weights (0.299, 0.587, 0.114) on the displayed (sRGB-encoded)
//!   values, computed here from the linear colour as Y = encode(0.299 R + 0.587 G + 0.114 B) and
//!   stored as 16-bit integers. Energies are then exact integer sums, so an incremental ΔE equals the
//!   difference of two full-frame energies *exactly*, whatever the order of summation or the
//!   number of threads; 16 bits keep far finer steps than the paper's 8-bit frame buffer.
//! - One sample at the pixel centre and no anti-aliasing, like the paper's OpenGL renders; shading
//!   is the rasterizer's `gouraud` model (vertex-lit Blinn–Phong with the scene's lights, per-wedge
//!   normals, colours and base-colour texture), with the same set-up, edge functions, fill rule,
//!   interpolation and texture filtering. Pieces of constant albedo (no vertex colours, no
//!   texture) are shaded through a ratio of two screen planes (`LumaPlane`) in f64 rather than
//!   the rasterizer's per-channel f32 barycentric sums, so a full render here equals
//!   `raster::render` at one sample per pixel converted to luminance up to one 16-bit code on a
//!   pixel in ~1 600 (tested); within the optimizer every image is shaded the same way, so energies
//!   stay exact.
//! - Memory is what a trial spends its time on: twenty views' images and set-ups are cold by the
//!   time a view's turn comes. So a committed pixel is one 12-byte record (the layers behind it,
//!   read only in holes, are kept apart), a triangle's first piece is stored in place, the old
//!   and new boxes and the per-vertex and per-triangle entries a trial gathers are prefetched, and
//!   the trial's working buffers (new pieces, stamps, the touched pixels) are per thread, not
//!   per view (`commit` sets the trial up again if they have moved on).
//! - Ties in depth go to the lower piece id, so a pixel's layers do not depend on the order the
//!   pieces are drawn in (a trial and a commit find them in different orders).
//! - Tiles of [`BUCKET`] pixels rather than the paper's per-row/per-column hash tables: one lookup
//!   per tile of R_h instead of an intersection of two unions, and the lists change only where a
//!   triangle's box crosses a tile boundary.

use glam::{Mat4, Vec2, Vec3};
use rayon::prelude::*;
use smallvec::SmallVec;

use super::RenderScene;
use super::clip::ClipPlanes;
use super::crew::Crew;
use super::edge::{self, EMPTY};
use super::plane_run::{self, Plane as LumaPlane, index_of_linear, sq};
use super::setup::{SetupOut, SetupTri, Viewport, XfVertex, setup_one, transform_one};
use super::shade::{ResolvedLight, light_terms, source_barycentrics};
use super::texture::MipTexture;
use super::{camera_setup, fixed, rect_union as union};
use crate::error::{Error, Result};
use crate::mesh::adjacency::Adjacency;
use crate::prefetch::{prefetch, prefetch_at};
use crate::scene::Camera;

/// Tile edge of the triangle buckets, pixels.
pub const BUCKET: u32 = 16;

/// Bits of a pixel id for the piece of its triangle (clipping makes at most 7 pieces).
const PIECE_BITS: u32 = 3;
const PIECE_MASK: u32 = (1 << PIECE_BITS) - 1;
/// Stamp bit of a triangle whose shading, not coverage, changed.
const RESHADE: u32 = 1 << 31;

/// Largest luminance code.
pub const LUMA_MAX: u16 = u16::MAX;

/// One set-up piece of a source triangle (several when clipped) with where its corners lie on it,
/// and how its pixels are shaded.
#[derive(Debug, Clone, Copy)]
struct Piece {
    st: SetupTri,
    corners: super::setup::Corners,
    shading: PieceShading,
}

/// How a piece's pixels are shaded, worked out the first time one is (many of a view's pieces
/// face away or are hidden and are never shaded).
#[derive(Debug, Clone, Copy)]
enum PieceShading {
    /// Not yet known (new piece, or its wedges' light terms changed).
    Unknown,
    /// Barycentrics and interpolated attributes at every pixel (vertex colours or a texture).
    PerPixel,
    /// Constant albedo: the luminance plane ratio.
    Plane(LumaPlane),
}

/// The linear luminance across a piece whose albedo is constant (no vertex colours, no texture):
/// Y(x, y) = N(x, y) / D(x, y) at pixel (x, y)'s centre, with N and D affine.
///
/// Why it holds: the perspective-correct barycentrics are μ_i / Σ μ_k with μ_i = e_i(x, y) / w_i
/// (e_i the edge functions, affine in x and y), and Gouraud-shaded linear luminance is linear in
/// the barycentrics, Y = Σ_i b_i L_i, where L_i is corner i's luminance
/// w·(albedo ⊙ diffuse_i + specular_i) with the NTSC weights w. So N = Σ μ_i L_i and D = Σ μ_i,
/// and a pixel costs two plane evaluations and a division instead of the barycentrics and three
/// interpolated colours. The result differs from `raster::render`'s per-channel f32 arithmetic by
/// rounding only (at most one 16-bit code, tested); within the optimizer every image is shaded
/// this way, so energies stay exact.
impl LumaPlane {
    /// The plane ratio of set-up triangle `st` with source-corner luminances `l`.
    fn new(st: &SetupTri, corners: &super::setup::Corners, l: [f64; 3]) -> LumaPlane {
        use super::setup::Corners;
        // Luminance of each set-up corner: a source corner's, or a clipped corner's blend.
        let lc: [f64; 3] = match corners {
            Corners::Source => l,
            Corners::Swapped => [l[0], l[2], l[1]],
            Corners::Clipped(c) => {
                c.map(|b| b.x as f64 * l[0] + b.y as f64 * l[1] + b.z as f64 * l[2])
            }
        };
        let p = st.v.map(|q| [q[0] as f64 / 256.0, q[1] as f64 / 256.0]);
        let (mut n, mut d) = ([0.0f64; 3], [0.0f64; 3]);
        for i in 0..3 {
            // e_i = (b − a) × (P − a) for the edge a → b opposite corner i, P = (x + ½, y + ½).
            let (a, b) = (p[(i + 1) % 3], p[(i + 2) % 3]);
            let cx = -(b[1] - a[1]);
            let cy = b[0] - a[0];
            let c0 = -cx * a[0] - cy * a[1] + 0.5 * (cx + cy);
            let wi = st.inv_w[i] as f64;
            for (k, e) in [cx, cy, c0].into_iter().enumerate() {
                d[k] += wi * e;
                n[k] += wi * lc[i] * e;
            }
        }
        let flat = ((lc[0] + lc[1] + lc[2]) / 3.0) as f32;
        LumaPlane { n, d, flat }
    }
}

/// What shading needs of a material.
#[derive(Debug, Clone)]
struct LumaMaterial {
    base_color: Vec3,
    specular: Vec3,
    shininess: f32,
    texture: Option<std::sync::Arc<MipTexture>>,
}

/// Shared, read-only state of all views.
#[derive(Debug)]
struct Shared {
    width: u32,
    height: u32,
    materials: Vec<LumaMaterial>,
    ambient: f32,
    background: u16,
    encode: Vec<u16>,
}

/// Per-view state.
#[derive(Debug)]
struct View {
    mvp: Mat4,
    planes: ClipPlanes,
    vp: Viewport,
    lights: Vec<ResolvedLight>,
    xf: Vec<XfVertex>,
    /// Per wedge: Gouraud (diffuse, specular) light terms.
    light: Vec<(Vec3, Vec3)>,
    /// Per source triangle: its pieces, the first in place (a triangle is one piece unless
    /// clipped, and a separate allocation per triangle was one more cache miss on every
    /// triangle a trial touched).
    pieces: Vec<SmallVec<[Piece; 1]>>,
    bbox: Vec<Option<[i32; 4]>>,
    buckets: Vec<Vec<BucketEntry>>,
    tiles_x: u32,
    /// The committed image, row-major.
    px: Vec<Pixel>,
    /// Per pixel: the second- and third-nearest pieces (what shows where the nearer ones are
    /// taken away).
    second: Vec<[Layer; 2]>,
    /// Per source triangle: how many pixels show it.
    shown_count: Vec<u32>,
    /// Per bucket tile: the farthest committed depth in it (infinite where background shows).
    tile_far: Vec<f32>,
    /// Unique in the process: names the scratch contents with the trial serial.
    id: u64,
    trial: Trial,
    /// Counts commits (the fills below hold for one committed state).
    commits: u64,
    /// The last trial's holes and re-shaded pixels with their fills.
    fills: Fills,
}

/// The pixels a trial must visit whatever the new positions are, the holes and the re-shaded
/// pixels, with what fills them: they depend only on which triangles changed and on the committed
/// state, and the downhill simplex tries one vertex set dozens of times in a row, so a view keeps
/// the last trial's and reuses them while both stay the same.
///
/// The re-shaded pixels (those showing a triangle whose corners stay but whose wedges changed:
/// with derived normals, the ring around the moved vertices' ring, about seven in ten of the
/// pixels a trial visits on the bunny) are kept apart from the holes, as runs of the same piece
/// in scan order with their column, row and target. A trial shades a run with the piece's
/// shading worked out once, and needs no per-pixel look-up of the piece, its plane or the
/// committed pixel; their committed values' share of ΔE, Σ (ŷ − y)², is summed once here.
#[derive(Debug, Default)]
struct Fills {
    valid: bool,
    /// The view's commit count they were made at.
    commits: u64,
    changed: Vec<u32>,
    reshaded: Vec<u32>,
    /// The holes, with what shows there once the changed triangles are taken away.
    touched: Vec<Touch>,
    /// The re-shaded pixels, grouped by the piece they show: columns, rows and targets.
    reshaded_x: Vec<u16>,
    reshaded_y: Vec<u16>,
    reshaded_target: Vec<u16>,
    /// Runs of the re-shaded pixels: the piece shown and the end of its run.
    runs: Vec<(u32, u32)>,
    /// Per run of a per-pixel shaded piece: the wedge colours and UVs its pixels' surfaces were
    /// worked out with (see [`surface_key`]); per re-shaded pixel of such a run: its surface.
    /// A trial that re-shades the run with the same colours and UVs (only normals changed, as
    /// around derived normals) lights the kept surfaces instead of sampling the texture again.
    run_keys: Vec<Option<[u32; 15]>>,
    surfaces: Vec<(Vec3, Vec3)>,
    /// Σ over the re-shaded pixels of (ŷ − y)², y the committed luminance.
    reshaded_committed: i64,
}

/// A pixel showing a re-shaded triangle, as a scan finds it: the piece shown, its column, row and
/// target luminance.
type ReshadedPixel = (u32, [u16; 3]);

impl Fills {
    /// Whether they were made for these changed and re-shaded triangles at this commit count.
    fn hold_for(
        &self,
        commits: u64,
        changed: &[(u32, Option<[i32; 4]>)],
        reshaded: &[u32],
    ) -> bool {
        self.valid
            && self.commits == commits
            && self.changed.len() == changed.len()
            && self.changed.iter().zip(changed).all(|(a, b)| *a == b.0)
            && self.reshaded == reshaded
    }

    /// Start the fills of these changed and re-shaded triangles (`touched` and the re-shaded
    /// pixels are filled in by the caller, then [`Fills::group`] closes them).
    fn start(&mut self, commits: u64, changed: &[(u32, Option<[i32; 4]>)], reshaded: &[u32]) {
        self.valid = false;
        self.commits = commits;
        self.changed.clear();
        self.changed.extend(changed.iter().map(|c| c.0));
        self.reshaded.clear();
        self.reshaded.extend_from_slice(reshaded);
        self.touched.clear();
        self.reshaded_x.clear();
        self.reshaded_y.clear();
        self.reshaded_target.clear();
        self.runs.clear();
        self.run_keys.clear();
        self.surfaces.clear();
        self.reshaded_committed = 0;
    }

    /// Group `pixels` (piece shown, pixel) into runs by piece, keeping scan order within a run,
    /// and mark the fills complete.
    fn group(&mut self, pixels: &mut [ReshadedPixel]) {
        pixels.sort_by_key(|&(id, _)| id);
        for (k, &(id, [x, y, target])) in pixels.iter().enumerate() {
            if k > 0 && pixels[k - 1].0 != id {
                self.runs.push((pixels[k - 1].0, k as u32));
            }
            self.reshaded_x.push(x);
            self.reshaded_y.push(y);
            self.reshaded_target.push(target);
        }
        if let Some(&(id, _)) = pixels.last() {
            self.runs.push((id, pixels.len() as u32));
        }
        self.run_keys.resize(self.runs.len(), None);
        self.valid = true;
    }
}

/// A triangle in a bucket, with its box (so the triangles that miss a rectangle are passed over
/// without touching their pieces).
#[derive(Debug, Clone, Copy)]
struct BucketEntry {
    tri: u32,
    bbox: [u16; 4],
}

impl BucketEntry {
    fn new(tri: u32, b: [i32; 4]) -> BucketEntry {
        // Boxes lie within the image, which is at most 4096 pixels per side.
        BucketEntry {
            tri,
            bbox: b.map(|v| v as u16),
        }
    }

    /// Whether its box overlaps rectangle `r`.
    #[inline]
    fn overlaps(&self, r: [i32; 4]) -> bool {
        overlap(self.bbox.map(i32::from), r)
    }
}

/// A pixel of a view's committed image: what a trial reads and writes of it side by side (one
/// cache line holds five; the four separate arrays this replaced cost a miss each per row of a
/// trial's rectangle, and every view's images are cold by the time the next trial reaches it).
#[derive(Debug, Clone, Copy)]
struct Pixel {
    /// Piece shown, as `triangle << PIECE_BITS | piece` ([`EMPTY`]: background).
    shown: u32,
    /// Its depth (infinite on the background).
    depth: f32,
    /// Luminance y.
    current: u16,
    /// Target luminance ŷ.
    target: u16,
}

/// A piece behind a pixel's nearest one, and its depth ([`EMPTY`] and infinite where there is
/// none).
#[derive(Debug, Clone, Copy)]
struct Layer {
    shown: u32,
    depth: f32,
}

impl Layer {
    const NONE: Layer = Layer {
        shown: EMPTY,
        depth: f32::INFINITY,
    };
}

/// A pixel a trial may change, and the piece nearest there as the trial stands.
#[derive(Debug, Clone, Copy)]
struct Touch {
    /// Pixel index, row-major.
    p: u32,
    /// Nearest piece ([`EMPTY`]: background) and its depth.
    id: u32,
    depth: f32,
    /// A hole whose layers behind are changed too: only a rasterization of the unchanged
    /// triangles there can fill it.
    deep: bool,
    /// A pixel of a re-shaded triangle that a new piece won: its run counts it re-shaded, which
    /// the shading loop takes back. (Worked out when the new piece wins it, where the committed
    /// pixel is at hand, so the shading loop needs no stamp look-up per pixel.)
    won_reshaded: bool,
}

/// Whether a fragment (depth, id) is nearer than (depth0, id0): nearer, or as near with a lower
/// id (so the result does not depend on the order pieces are drawn in).
#[inline(always)]
fn nearer(depth: f32, id: u32, depth0: f32, id0: u32) -> bool {
    depth < depth0 || (depth == depth0 && id < id0)
}

/// A view's pending trial: what it changed and what a revert restores.
#[derive(Debug, Default)]
struct Trial {
    /// Counts this view's trials (with the view's id, it names the scratch contents).
    serial: u32,
    saved_xf: Vec<(u32, XfVertex)>,
    saved_light: Vec<(u32, (Vec3, Vec3))>,
    /// Whether the whole image is rendered (the first render).
    everything: bool,
}

/// Per-thread working memory of a trial: the new pieces, the rectangle's samples and luminance
/// and the per-triangle stamps. Shared by every view a thread renders, so it stays in cache
/// (per-view buffers were cold at every trial, each view's turn coming after nineteen others).
#[derive(Debug, Default)]
struct Scratch {
    /// New pieces of the changed triangles (grouped by triangle, in `bbox`'s order).
    pieces: Vec<(u32, Piece)>,
    /// Changed triangles and their new boxes.
    bbox: Vec<(u32, Option<[i32; 4]>)>,
    /// The dirty rectangle (`None`: nothing to render).
    rect: Option<[i32; 4]>,
    /// Whether a changed triangle shows now (then holes open, and no new piece may be passed
    /// over as hidden behind the committed depths).
    shows_now: bool,
    /// Whether the view's kept fills hold for the prepared trial (asked once, by `prepare`).
    fills_hold: bool,
    /// Re-shaded triangles that show now.
    reshaded_shown: Vec<u32>,
    /// The union of the showing changed and re-shaded triangles' old boxes, and their summed
    /// area (the render scans the union where it is no larger).
    old_boxes: (Option<[i32; 4]>, i64),
    setup: SetupOut,
    /// Per image pixel: the render number that touched it, and its entry in `touched` (one
    /// record, so a pixel's check and its entry share a cache line).
    pixel: Vec<[u32; 2]>,
    /// The pixels the render may change, with their nearest pieces (but for the re-shaded
    /// pixels no new piece wins, which the view's [`Fills`] keep).
    touched: Vec<Touch>,
    /// The re-shaded pixels a scan for fills finds, with the pieces they show.
    reshaded_scan: Vec<ReshadedPixel>,
    /// A commit's region: the three nearest (depth, piece) per pixel.
    layers: Vec<[(f32, u32); 3]>,
    /// Per source triangle: the number of the render that changed it (with [`RESHADE`] set when
    /// only its shading changed).
    stamp: Vec<u32>,
    /// Per changed source triangle: index of its first new piece in the trial's `pieces`.
    first_piece: Vec<u32>,
    /// Per source triangle: the render number that already rasterized it.
    visited: Vec<u32>,
    /// Per source triangle: the render number that gave it new entries in `reshading`.
    reshade_at: Vec<u32>,
    /// Unchanged triangles that may fill the holes.
    candidates: Vec<u32>,
    /// The luminance planes of the pieces a render shades ([`PLANE_CACHE`] slots by piece id).
    plane_cache: Vec<PlaneSlot>,
    /// The new shading of re-shaded triangles' pieces (from `first_piece`), made while shading.
    reshading: Vec<PieceShading>,
    number: u32,
    /// The view id and trial serial whose render the buffers hold.
    owner: Option<(u64, u32)>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// Run `f` with this thread's scratch.
fn with_scratch<R>(f: impl FnOnce(&mut Scratch) -> R) -> R {
    SCRATCH.with_borrow_mut(f)
}

/// Source of view ids (unique in the process).
static NEXT_VIEW_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// What a trial changed: every triangle whose corners, corner positions or corner attributes
/// differ from the committed state (including triangles that died or were born), the vertices
/// that moved and the wedges whose attributes changed.
#[derive(Debug, Clone, Copy)]
pub struct Change<'a> {
    /// Moved (or new) welded vertices.
    pub vertices: &'a [u32],
    /// Wedges with changed (or new) attributes.
    pub wedges: &'a [u32],
    /// Changed, born or dead triangles: must include every triangle using a listed vertex.
    pub triangles: &'a [u32],
    /// Triangles whose corners did not move but use a listed wedge (only their shading changes).
    /// Together with `triangles` they must include every triangle using a listed wedge.
    pub reshaded: &'a [u32],
}

/// The luminance images of an editable mesh in a set of views, updated incrementally.
#[derive(Debug)]
pub struct LumaViews {
    shared: Shared,
    views: Vec<View>,
    /// Material of each wedge (for its light terms): that of the first triangle using it.
    wedge_material: Vec<u32>,
    pending: bool,
    /// The pending trial's changed and re-shaded triangles (for a commit; the same in every view).
    pending_triangles: Vec<u32>,
    pending_reshaded: Vec<u32>,
    /// Runs the views of a trial (made at the first trial, as many threads as rayon's pool).
    crew: Option<Crew>,
}

/// The threads the optimizer's trials run on: as many as rayon's pool has, but no more than the
/// machine has cores (a spinning crew worker without a core of its own holds the others up).
pub fn crew_threads() -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    rayon::current_num_threads().min(cores)
}

/// Run `f` on every view, spread over `crew` (made at the first call, with [`crew_threads`]
/// threads). Trials come thousands of times a
/// second, and the crew stays awake between them (rayon's workers would sleep and be woken for
/// each). The crew takes the views in the same order every time, so each view mostly stays on
/// one core (see `crew.rs`).
fn each_view(crew: &mut Option<Crew>, views: &mut [View], f: &(dyn Fn(&mut View) + Sync)) {
    let crew = crew.get_or_insert_with(|| Crew::new(crew_threads()));
    let ptr = ViewsPtr(views.as_mut_ptr());
    crew.run(views.len(), &|i| {
        // SAFETY: `i` < the number of views, the crew calls each `i` once (so the views
        // borrowed are disjoint), and `run` returns only when every call has.
        f(unsafe { &mut *ptr.at(i) })
    });
}

/// The views of a [`LumaViews`], lent to the crew: each call takes the view of its own index.
#[derive(Clone, Copy)]
struct ViewsPtr(*mut View);

// SAFETY: a `View` is `Send` (checked below), and every index is handed to one call only (see
// `each_view`), so no view is reached from two threads at once.
unsafe impl Sync for ViewsPtr {}
unsafe impl Send for ViewsPtr {}
const _: () = {
    const fn send<T: Send>() {}
    send::<View>();
};

impl ViewsPtr {
    /// View `i` (in bounds by the caller).
    fn at(self, i: usize) -> *mut View {
        // SAFETY: in bounds, as the caller promises.
        unsafe { self.0.add(i) }
    }
}

/// sRGB encoding of a linear value in [0, 1].
fn encode_srgb(x: f64) -> f64 {
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// NTSC luminance weights.
const NTSC: [f32; 3] = [0.299, 0.587, 0.114];

/// Index of a linear colour's NTSC-weighted linear luminance on a 16-bit scale.
fn luma_index(c: Vec3) -> usize {
    index_of_linear(NTSC[0] * c.x + NTSC[1] * c.y + NTSC[2] * c.z)
}

/// The displayed (sRGB-encoded) 16-bit code of linear luminance index `i`.
fn encode_code(i: usize) -> u16 {
    (encode_srgb(i as f64 / 65535.0) * 65535.0).round() as u16
}

impl Shared {
    /// 16-bit luminance code of a linear colour.
    fn luma(&self, c: Vec3) -> u16 {
        self.encode[luma_index(c)]
    }

    /// How to shade piece `st` of source triangle `t`: through its luminance plane where its
    /// material's albedo is constant across it (see [`LumaPlane`]), else per pixel.
    fn piece_shading(
        &self,
        mesh: &Adjacency,
        light: &[(Vec3, Vec3)],
        t: u32,
        st: &SetupTri,
        corners: &super::setup::Corners,
    ) -> PieceShading {
        let m = &self.materials[mesh.material(t) as usize];
        if mesh.has_colors() || (m.texture.is_some() && mesh.has_uvs()) {
            return PieceShading::PerPixel;
        }
        let l = mesh.corners(t).map(|w| {
            let (d, s) = light[w as usize];
            let c = m.base_color * d + s;
            (0..3).map(|k| NTSC[k] as f64 * c[k] as f64).sum::<f64>()
        });
        PieceShading::Plane(LumaPlane::new(st, corners, l))
    }
}

impl LumaViews {
    /// Render `mesh` (with the materials, lights, ambient term and background of `scene`) from
    /// `cameras` at `width`×`height`. `targets` are the images ŷ the energy compares against (one
    /// per camera); `None` compares against the images themselves (energy zero), which is how the
    /// targets are made: render the original and take [`LumaViews::images`].
    pub fn new(
        mesh: &Adjacency,
        scene: &RenderScene,
        cameras: &[Camera],
        width: u32,
        height: u32,
        targets: Option<Vec<Vec<u16>>>,
    ) -> Result<LumaViews> {
        if width == 0 || height == 0 || width > 4096 || height > 4096 {
            return Err(Error::Usage(format!(
                "optimizer image size {width}x{height} is outside 1..4096 pixels per side"
            )));
        }
        let n = (width * height) as usize;
        if let Some(t) = &targets
            && (t.len() != cameras.len() || t.iter().any(|t| t.len() != n))
        {
            return Err(Error::Usage(
                "target images do not match the views (count or size)".into(),
            ));
        }
        let encode: Vec<u16> = (0..=65535).map(encode_code).collect();
        let materials = scene
            .mesh()
            .materials()
            .iter()
            .zip(&scene.prepared().materials)
            .map(|(m, p)| LumaMaterial {
                base_color: m.base_color,
                specular: m.specular,
                shininess: m.shininess,
                texture: p.base.clone(),
            })
            .collect();
        let mut shared = Shared {
            width,
            height,
            materials,
            ambient: scene.ambient,
            background: 0,
            encode,
        };
        shared.background = shared.luma(scene.background);
        let mut wedge_material = vec![u32::MAX; mesh.wedges.len()];
        for t in mesh.live_triangles() {
            for w in mesh.corners(t) {
                if wedge_material[w as usize] == u32::MAX {
                    wedge_material[w as usize] = mesh.material(t);
                }
            }
        }
        let tiles_x = width.div_ceil(BUCKET);
        let n_tiles = (tiles_x * height.div_ceil(BUCKET)) as usize;
        let mut targets = targets.map(|t| t.into_iter());
        let mut views: Vec<View> = cameras
            .iter()
            .map(|camera| {
                let (mvp, _) = camera_setup(camera, width, height);
                let half = fixed::ONE_PIXEL as i32 / 2;
                View {
                    mvp,
                    planes: ClipPlanes::for_viewport(width, height),
                    vp: Viewport {
                        width,
                        height,
                        cull_backfaces: false,
                        sample_span: [half, half, half, half],
                    },
                    lights: ResolvedLight::for_camera(&scene.lights, camera),
                    xf: Vec::new(),
                    light: Vec::new(),
                    pieces: Vec::new(),
                    bbox: Vec::new(),
                    buckets: vec![Vec::new(); n_tiles],
                    tiles_x,
                    px: {
                        let target = targets.as_mut().and_then(|t| t.next());
                        let blank = Pixel {
                            shown: EMPTY,
                            depth: f32::INFINITY,
                            current: shared.background,
                            target: shared.background,
                        };
                        let mut px = vec![blank; n];
                        for (p, t) in px.iter_mut().zip(target.iter().flatten()) {
                            p.target = *t;
                        }
                        px
                    },
                    second: vec![[Layer::NONE; 2]; n],
                    shown_count: Vec::new(),
                    tile_far: vec![f32::INFINITY; n_tiles],
                    id: NEXT_VIEW_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
                    trial: Trial::default(),
                    commits: 0,
                    fills: Fills::default(),
                }
            })
            .collect();
        // The first render is a trial that changes everything.
        let all_v: Vec<u32> = (0..mesh.positions.len() as u32).collect();
        let all_w: Vec<u32> = (0..mesh.wedges.len() as u32).collect();
        let all_t: Vec<u32> = (0..mesh.triangle_slots() as u32).collect();
        let change = Change {
            vertices: &all_v,
            wedges: &all_w,
            triangles: &all_t,
            reshaded: &[],
        };
        let shared_ref = &shared;
        let wm = &wedge_material;
        let compare_with_self = targets.is_none();
        views.par_iter_mut().for_each(|v| {
            with_scratch(|s| {
                v.trial(shared_ref, mesh, wm, &change, true, s);
                v.commit(shared_ref, mesh, &change, s);
            });
            if compare_with_self {
                v.px.iter_mut().for_each(|p| p.target = p.current);
            }
        });
        Ok(LumaViews {
            shared,
            views,
            wedge_material,
            pending: false,
            pending_triangles: Vec::new(),
            pending_reshaded: Vec::new(),
            crew: None,
        })
    }

    /// The luminance images of `mesh` from `cameras`, as [`LumaViews::new`] then
    /// [`LumaViews::images`] make them (the same codes), holding one view's state per thread
    /// instead of every view's (a dense original's pieces take tens of MB per view).
    pub fn images_of(
        mesh: &Adjacency,
        scene: &RenderScene,
        cameras: &[Camera],
        width: u32,
        height: u32,
    ) -> Result<Vec<Vec<u16>>> {
        cameras
            .par_iter()
            .map(|camera| {
                let one = LumaViews::new(
                    mesh,
                    scene,
                    std::slice::from_ref(camera),
                    width,
                    height,
                    None,
                )?;
                Ok(one.images().swap_remove(0))
            })
            .collect()
    }

    /// Number of views.
    pub fn view_count(&self) -> usize {
        self.views.len()
    }

    /// Image width and height.
    pub fn size(&self) -> (u32, u32) {
        (self.shared.width, self.shared.height)
    }

    /// The current luminance images, row-major, one per view.
    pub fn images(&self) -> Vec<Vec<u16>> {
        self.views
            .iter()
            .map(|v| v.px.iter().map(|p| p.current).collect())
            .collect()
    }

    /// Current and target luminance of each pixel of view `h`, row-major.
    pub fn view_pixels(&self, h: usize) -> impl Iterator<Item = (u16, u16)> + '_ {
        self.views[h].px.iter().map(|p| (p.current, p.target))
    }

    /// The view's model-view-projection matrix (for projecting mesh points onto its images).
    pub fn view_matrix(&self, h: usize) -> Mat4 {
        self.views[h].mvp
    }

    /// The energy E = Σ_h Σ_ij (ŷ − y)² of the committed state, in squared 16-bit codes (eq. 1
    /// without the 1/(l·m·n) factor; see [`LumaViews::d_ms`]).
    pub fn energy(&self) -> i64 {
        self.views
            .iter()
            .map(|v| v.px.iter().map(|p| sq(p.target, p.current)).sum::<i64>())
            .sum()
    }

    /// Eq. 1's mean-square difference d_MS for an energy, with luminance scaled to [0, 1].
    pub fn d_ms(&self, energy: i64) -> f64 {
        let lmn = self.views.len() as f64 * self.shared.width as f64 * self.shared.height as f64;
        energy as f64 / (65535.0 * 65535.0) / lmn
    }

    /// Evaluate a change of `mesh` against the committed state: re-render the affected rectangle
    /// of every view and return ΔE (eq. 2). The trial stays pending until [`LumaViews::commit`] or
    /// [`LumaViews::revert`]; a new trial reverts a pending one first.
    pub fn trial(&mut self, mesh: &Adjacency, change: &Change) -> i64 {
        // A pending trial is reverted by each view at the start of its new one, on the crew's
        // threads (reverting all twenty here took 1.3 % of the calling thread's time, while the
        // other thread waited).
        let revert_first = std::mem::take(&mut self.pending);
        for &w in change.wedges {
            let w = w as usize;
            if w >= self.wedge_material.len() {
                self.wedge_material.resize(w + 1, u32::MAX);
            }
        }
        for &t in change.triangles {
            if mesh.is_alive(t) {
                for w in mesh.corners(t) {
                    let m = &mut self.wedge_material[w as usize];
                    if *m == u32::MAX {
                        *m = mesh.material(t);
                    }
                }
            }
        }
        self.pending = true;
        self.pending_triangles.clear();
        self.pending_triangles.extend_from_slice(change.triangles);
        self.pending_reshaded.clear();
        self.pending_reshaded.extend_from_slice(change.reshaded);
        let LumaViews {
            shared,
            views,
            wedge_material: wm,
            crew,
            ..
        } = self;
        let total = std::sync::atomic::AtomicI64::new(0);
        each_view(crew, views, &|v| {
            if revert_first {
                v.revert();
            }
            let d = with_scratch(|s| v.trial(shared, mesh, wm, change, false, s));
            total.fetch_add(d, std::sync::atomic::Ordering::Relaxed);
        });
        // Integer sums: the same total in any order, so for any thread count.
        total.into_inner()
    }

    /// Make the pending trial the committed state; `mesh` must be the mesh of the trial.
    pub fn commit(&mut self, mesh: &Adjacency) {
        if !std::mem::take(&mut self.pending) {
            return;
        }
        let shared = &self.shared;
        let change = Change {
            vertices: &[],
            wedges: &[],
            triangles: &self.pending_triangles,
            reshaded: &self.pending_reshaded,
        };
        each_view(&mut self.crew, &mut self.views, &|v| {
            with_scratch(|s| v.commit(shared, mesh, &change, s));
        });
    }

    /// Drop the pending trial.
    pub fn revert(&mut self) {
        if !std::mem::take(&mut self.pending) {
            return;
        }
        // Restoring a few saved values per view: cheaper than waking the thread pool.
        self.views.iter_mut().for_each(|v| v.revert());
    }
}

/// Ask for the cache lines of `rect`'s pixels in row-major `px` (`w` per row) at once: every
/// view's images are cold when its turn comes, and rows fetched one miss at a time were most of
/// a trial's time.
fn prefetch_rect<T>(px: &[T], w: usize, [x0, y0, x1, y1]: [i32; 4]) {
    let line = 64 / std::mem::size_of::<T>().max(1);
    for y in y0..y1 {
        let row = y as usize * w;
        let (a, b) = (row + x0 as usize, row + x1 as usize);
        for i in (a..b).step_by(line) {
            prefetch(&px[i]);
        }
        // The row's last line, when the stride skipped it.
        prefetch(&px[b - 1]);
    }
}

/// Pixels in rectangle `r` (`[x0, y0, x1, y1)`).
#[inline]
fn area(r: [i32; 4]) -> i64 {
    (r[2] - r[0]) as i64 * (r[3] - r[1]) as i64
}

/// Whether pixel rectangles `a` and `b` (`[x0, y0, x1, y1)`) share a pixel.
#[inline]
fn overlap(a: [i32; 4], b: [i32; 4]) -> bool {
    a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]
}

/// Whether triangle `t` shows in any committed pixel, by the view's per-triangle counts.
#[inline]
fn shows(shown_count: &[u32], t: u32) -> bool {
    shown_count.get(t as usize).is_some_and(|&c| c > 0)
}

/// Whether set-up triangle `st` is farther than every committed pixel in the tiles its box
/// touches (`tile_far`: the farthest depth per tile), so it can win no depth test against them.
fn hidden(tile_far: &[f32], tiles_x: u32, st: &SetupTri) -> bool {
    // Interpolated depths are rounded once from f64 and so stay within a relative 1e-6 of the
    // corners' range.
    let near = st.z[0].min(st.z[1]).min(st.z[2]);
    let near = near - near.abs() * 1e-6 - 1e-7;
    tiles(tiles_x, st.bbox()).all(|tile| near > tile_far[tile])
}

/// What the shading of a touched pixel whose plane is not cached reads and fills in: the
/// render's scratch (see [`View::shade_touched`]).
struct ShadeRest<'a> {
    number: u32,
    stamp: &'a [u32],
    new_pieces: &'a mut [(u32, Piece)],
    first_piece: &'a mut [u32],
    reshade_at: &'a mut [u32],
    reshading: &'a mut Vec<PieceShading>,
    plane_cache: &'a mut [PlaneSlot],
}

impl ShadeRest<'_> {
    /// The slot in `reshading` of piece `piece` of re-shaded triangle `t` (which has `pieces`
    /// pieces): the triangle's slots are made, all unknown, the first time the render asks.
    fn reshading_slot(&mut self, t: usize, pieces: usize, piece: usize) -> usize {
        if self.reshade_at[t] != self.number {
            self.reshade_at[t] = self.number;
            self.first_piece[t] = self.reshading.len() as u32;
            self.reshading
                .extend((0..pieces).map(|_| PieceShading::Unknown));
        }
        self.first_piece[t] as usize + piece
    }
}

/// Slots of the render's plane cache (a power of two).
const PLANE_CACHE: usize = 64;

/// A cached luminance plane: piece `id`'s in the render numbered `number`.
#[derive(Debug, Clone, Copy)]
struct PlaneSlot {
    number: u32,
    id: u32,
    plane: LumaPlane,
}

impl Default for PlaneSlot {
    fn default() -> PlaneSlot {
        PlaneSlot {
            number: 0,
            id: EMPTY,
            plane: LumaPlane {
                n: [0.0; 3],
                d: [0.0; 3],
                flat: 0.0,
            },
        }
    }
}

impl PlaneSlot {
    /// The plane, if the slot holds piece `id`'s of render `number`.
    #[inline(always)]
    fn get(&self, number: u32, id: u32) -> Option<&LumaPlane> {
        (self.number == number && self.id == id).then_some(&self.plane)
    }
}

/// Whether a pixel now showing piece `id` keeps its committed luminance: it showed that piece
/// before, and the piece's triangle (stamped `s`) is neither changed nor re-shaded in render
/// `number` (its corners and attributes are as committed).
#[inline(always)]
fn keeps_committed(id: u32, old_shown: u32, s: u32, number: u32) -> bool {
    id == old_shown && s != number && s != (number | RESHADE)
}

/// Plane-cache slot of piece `id` (its triangle's low bits, mixed with the piece number).
#[inline(always)]
fn plane_slot(id: u32) -> usize {
    ((id >> PIECE_BITS) ^ (id << 3)) as usize & (PLANE_CACHE - 1)
}

/// Column and row of row-major pixel `p` in an image `width` pixels wide. In u32: a u64 → f64
/// conversion is a branchy sequence of about ten instructions on x86-64, a u32 one is one
/// (this runs for every shaded pixel).
#[inline(always)]
fn column_row(p: u32, width: u32) -> (f64, f64) {
    ((p % width) as f64, (p / width) as f64)
}

/// Bucket tiles (row-major, `tiles_x` per row) overlapped by a pixel rectangle.
fn tiles(tiles_x: u32, r: [i32; 4]) -> impl Iterator<Item = usize> {
    let b = BUCKET as i32;
    let (x0, y0, x1, y1) = (r[0] / b, r[1] / b, (r[2] - 1) / b, (r[3] - 1) / b);
    let tx = tiles_x as usize;
    (y0..=y1).flat_map(move |y| (x0..=x1).map(move |x| y as usize * tx + x as usize))
}

impl Scratch {
    /// Size the per-pixel marks for an image of `n` pixels.
    fn pixels_for(&mut self, n: usize) {
        if self.pixel.len() < n {
            self.pixel.resize(n, [0, 0]);
        }
    }

    /// A fresh trial number for stamping `slots` source triangles.
    fn next_number(&mut self, slots: usize) -> u32 {
        if self.stamp.len() < slots {
            self.stamp.resize(slots, 0);
            self.first_piece.resize(slots, 0);
            self.visited.resize(slots, 0);
            self.reshade_at.resize(slots, 0);
        }
        self.number = (self.number + 1) & !RESHADE;
        if self.number == 0 {
            // Wrapped: forget every old stamp.
            self.stamp.iter_mut().for_each(|s| *s = 0);
            self.visited.iter_mut().for_each(|s| *s = 0);
            self.reshade_at.iter_mut().for_each(|s| *s = 0);
            self.pixel.iter_mut().for_each(|s| s[0] = 0);
            self.plane_cache.iter_mut().for_each(|s| s.number = 0);
            self.number = 1;
        }
        self.owner = None;
        self.number
    }
}

impl View {
    /// Apply `change` to this view's transforms, light terms and set-up (saving what a revert
    /// restores), then render the dirty rectangle into `scratch` and return ΔE.
    fn trial(
        &mut self,
        shared: &Shared,
        mesh: &Adjacency,
        wedge_material: &[u32],
        change: &Change,
        everything: bool,
        scratch: &mut Scratch,
    ) -> i64 {
        let tr = &mut self.trial;
        tr.serial = tr.serial.wrapping_add(1);
        tr.saved_xf.clear();
        tr.saved_light.clear();
        tr.everything = everything;
        // Everything below gathers from this view's cold per-vertex, per-wedge and per-triangle
        // arrays: ask for all of it first.
        change
            .vertices
            .iter()
            .for_each(|&v| prefetch_at(&self.xf, v));
        change
            .wedges
            .iter()
            .for_each(|&w| prefetch_at(&self.light, w));
        for &t in change.triangles.iter().chain(change.reshaded) {
            prefetch_at(&self.bbox, t);
            prefetch_at(&self.shown_count, t);
        }
        // New vertex transforms and wedge light terms (old values saved for a revert).
        let grow = |len: &mut usize, need: usize| *len = (*len).max(need);
        let mut nv = self.xf.len();
        change
            .vertices
            .iter()
            .for_each(|&v| grow(&mut nv, v as usize + 1));
        if nv > self.xf.len() {
            let fill = transform_one(Vec3::ZERO, self.mvp, &self.planes, self.vp);
            self.xf.resize(nv, fill);
        }
        for &v in change.vertices {
            if (v as usize) < mesh.positions.len() {
                tr.saved_xf.push((v, self.xf[v as usize]));
                self.xf[v as usize] =
                    transform_one(mesh.positions[v as usize], self.mvp, &self.planes, self.vp);
            }
        }
        let mut nw = self.light.len();
        change
            .wedges
            .iter()
            .for_each(|&w| grow(&mut nw, w as usize + 1));
        self.light
            .resize(nw.max(self.light.len()), (Vec3::ZERO, Vec3::ZERO));
        for &w in change.wedges {
            if (w as usize) < mesh.wedges.len() {
                tr.saved_light.push((w, self.light[w as usize]));
                let m = wedge_material[w as usize];
                let m = &shared.materials[if m == u32::MAX { 0 } else { m as usize }];
                self.light[w as usize] = light_terms(
                    mesh.wedges[w as usize].normal,
                    &self.lights,
                    shared.ambient,
                    m.specular,
                    m.shininess,
                );
            }
        }
        self.build(shared, mesh, change, scratch)
    }

    /// Set up the pending trial's changed triangles and render its rectangle into `scratch`;
    /// return ΔE. A function of the view's state alone, so [`View::commit`] can run it again
    /// when `scratch` has since served another view.
    fn build(
        &mut self,
        shared: &Shared,
        mesh: &Adjacency,
        change: &Change,
        scratch: &mut Scratch,
    ) -> i64 {
        let delta = if self.prepare(shared, mesh, change, scratch) {
            self.render(shared, mesh, scratch)
        } else {
            0
        };
        scratch.owner = Some((self.id, self.trial.serial));
        delta
    }

    /// Triangle `t`'s committed box, if it shows anywhere in this view.
    fn old_box(&self, t: u32) -> Option<[i32; 4]> {
        self.bbox
            .get(t as usize)
            .copied()
            .flatten()
            .filter(|_| shows(&self.shown_count, t))
    }

    /// The committed boxes of the changed triangles and the re-shaded ones that show: the
    /// pixels a trial re-visits first (prefetched by `prepare`, scanned by `render`).
    fn old_boxes<'a>(
        &'a self,
        changed: impl Iterator<Item = u32> + 'a,
        reshaded_shown: &'a [u32],
    ) -> impl Iterator<Item = [i32; 4]> + 'a {
        changed
            .chain(reshaded_shown.iter().copied())
            .filter_map(|t| self.old_box(t))
    }

    /// New set-up of the changed triangles and the dirty rectangle; false if it is empty.
    fn prepare(
        &self,
        shared: &Shared,
        mesh: &Adjacency,
        change: &Change,
        scratch: &mut Scratch,
    ) -> bool {
        let tr = &self.trial;
        let number = scratch.next_number(mesh.triangle_slots().max(self.pieces.len()));
        let reshade = number | RESHADE;
        scratch.pieces.clear();
        scratch.reshading.clear();
        scratch.bbox.clear();
        scratch.reshaded_shown.clear();
        scratch.rect = None;
        // The pixels that can change: those showing a changed or re-shaded triangle now (its
        // old box, when it shows at all) and those a new piece covers.
        let mut rect: Option<[i32; 4]> = None;
        let mut shows_now = false;
        let mut box_area = 0i64;
        for &t in change.triangles {
            scratch.stamp[t as usize] = number;
            if let Some(b) = self.old_box(t) {
                rect = Some(union(rect, b));
                box_area += area(b);
                shows_now = true;
            }
        }
        // The holes' boxes alone (the changed triangles' old boxes).
        let holes = (rect, box_area);
        // Triangles that only need shading anew (their wedges changed, not their corners).
        for &t in change.reshaded {
            let tu = t as usize;
            if scratch.stamp[tu] != number && scratch.stamp[tu] != reshade {
                scratch.stamp[tu] = reshade;
                if let Some(b) = self.old_box(t) {
                    rect = Some(union(rect, b));
                    box_area += area(b);
                    shows_now = true;
                    scratch.reshaded_shown.push(t);
                }
            }
        }
        scratch.old_boxes = (rect, box_area);
        for &t in change.triangles {
            let mut bb: Option<[i32; 4]> = None;
            if mesh.is_alive(t) {
                let setup = &mut scratch.setup;
                setup.tris.clear();
                setup.clipped.clear();
                setup_one(t, mesh.triangle(t), &self.xf, &self.planes, self.vp, setup);
                for st in &setup.tris {
                    let corners = super::setup::Corners::decode(st.corners, &setup.clipped);
                    scratch.pieces.push((
                        t,
                        Piece {
                            st: *st,
                            corners,
                            shading: PieceShading::Unknown,
                        },
                    ));
                    bb = Some(union(bb, st.bbox()));
                }
            }
            scratch.bbox.push((t, bb));
        }
        // Where nothing that changed shows now, the committed depths stay, and a new piece
        // behind all of them in every tile it touches (the far side of a closed mesh) cannot
        // change a pixel: the view then often has nothing to render at all.
        let mut new_box: Option<[i32; 4]> = None;
        for (_, p) in &scratch.pieces {
            if shows_now || !hidden(&self.tile_far, self.tiles_x, &p.st) {
                new_box = Some(union(new_box, p.st.bbox()));
            }
        }
        // Ask for the committed pixels the render reads: those of the old boxes (scanned for
        // holes and re-shaded pixels) and of the new pieces' box (their depth tests). The boxes
        // overlap around a moved vertex, so one rectangle around them all is asked for where the
        // old boxes' union is no larger than the boxes together, else box by box.
        // (Asked for here, once the set-up is done, rather than the old boxes before it and the
        // new box after: 4.7-5.4 % less trial time in an in-process A/B whose partition alone
        // gives 3.5-4.8 %, so about 0-1.5 %. Asking for the second and third layers or the
        // render's pixel marks as well measured slower.)
        // Where the view's kept fills hold for this trial (the simplex trying the same vertex set
        // again), its re-shaded pixels' runs carry all the render needs of them, and only the
        // holes' and the new pieces' pixels are read.
        let w = shared.width as usize;
        let runs_kept = self
            .fills
            .hold_for(self.commits, &scratch.bbox, &scratch.reshaded_shown);
        let (read, read_area, reshaded): (_, _, &[u32]) = if runs_kept {
            (holes.0, holes.1, &[])
        } else {
            (rect, box_area, &scratch.reshaded_shown)
        };
        match read {
            Some(u) if area(u) > read_area => self
                .old_boxes(change.triangles.iter().copied(), reshaded)
                .chain(new_box)
                .for_each(|b| prefetch_rect(&self.px, w, b)),
            _ => new_box
                .map_or(read, |b| Some(union(read, b)))
                .into_iter()
                .for_each(|a| prefetch_rect(&self.px, w, a)),
        }
        rect = new_box.map_or(rect, |b| Some(union(rect, b)));
        let pieces = &scratch.pieces;
        for (k, &(t, _)) in pieces.iter().enumerate() {
            if k == 0 || pieces[k - 1].0 != t {
                scratch.first_piece[t as usize] = k as u32;
            }
        }
        scratch.shows_now = shows_now;
        scratch.fills_hold = runs_kept;
        scratch.rect = if tr.everything {
            Some([0, 0, shared.width as i32, shared.height as i32])
        } else {
            rect
        };
        scratch.rect.is_some()
    }

    /// Render the pixels the prepared trial can change and return ΔE. Only those pixels are
    /// visited, not the rectangle around them:
    /// 1. *holes*, where a changed triangle showed: the nearest layer behind it of an unchanged
    ///    triangle shows there now (where all three are changed, a rasterization of the unchanged
    ///    triangles there finds it), and the pixels of re-shaded triangles (kept as runs by piece,
    ///    see [`Fills`]);
    /// 2. the changed triangles' new pieces, depth-tested against the holes' fill or the
    ///    committed depth;
    ///
    /// then each of them is shaded (where its piece is new, changed or re-shaded) and compared.
    fn render(&mut self, shared: &Shared, mesh: &Adjacency, scratch: &mut Scratch) -> i64 {
        if scratch.rect.is_none() || self.trial.everything {
            // Nothing to render, or the first render (which only a commit makes).
            return 0;
        }
        let number = scratch.number;
        let reshade = number | RESHADE;
        let w = shared.width as usize;
        scratch.pixels_for(self.px.len());
        let Scratch {
            pieces: new_pieces,
            bbox: changed,
            reshaded_shown,
            shows_now,
            fills_hold,
            stamp,
            first_piece,
            visited,
            reshade_at,
            candidates,
            reshading,
            pixel,
            touched,
            reshaded_scan,
            old_boxes,
            plane_cache,
            ..
        } = scratch;
        touched.clear();
        let changed_piece = |id: u32| id != EMPTY && stamp[(id >> PIECE_BITS) as usize] == number;
        if *fills_hold {
            // The same triangles changed as in the last trial, on the same committed state.
            touched.extend_from_slice(&self.fills.touched);
            for (i, e) in touched.iter().enumerate() {
                pixel[e.p as usize] = [number, i as u32];
            }
        } else {
            // 1. Holes, the pixels a changed triangle showed (the second layer shows there now),
            //    and the pixels of re-shaded triangles (their pieces stay, their shading changes):
            //    found in the old boxes of those that show anywhere, visited once each. One pass over
            //    the boxes' union where that is smaller than the boxes together (they overlap around
            //    a moved vertex), else box by box.
            self.fills.start(self.commits, changed, reshaded_shown);
            reshaded_scan.clear();
            let mut reshaded_committed = 0i64;
            let mut deep: Option<[i32; 4]> = None;
            let (union_box, box_area) = *old_boxes;
            let mut visit = |p: usize, x: i32, y: i32| {
                let c = &self.px[p];
                if c.shown == EMPTY || pixel[p][0] == number {
                    return;
                }
                let s = stamp[(c.shown >> PIECE_BITS) as usize];
                let touch = if s == number {
                    let [second, third] = self.second[p];
                    let second = if changed_piece(second.shown) {
                        third
                    } else {
                        second
                    };
                    if changed_piece(second.shown) {
                        deep = Some(union(deep, [x, y, x + 1, y + 1]));
                        Touch {
                            p: p as u32,
                            id: EMPTY,
                            depth: f32::INFINITY,
                            deep: true,
                            won_reshaded: false,
                        }
                    } else {
                        Touch {
                            p: p as u32,
                            id: second.shown,
                            depth: second.depth,
                            deep: false,
                            won_reshaded: false,
                        }
                    }
                } else if s == reshade {
                    // Marked for this scan only (a trial marks the holes alone).
                    pixel[p][0] = number;
                    reshaded_committed += sq(c.target, c.current);
                    reshaded_scan.push((c.shown, [x as u16, y as u16, c.target]));
                    return;
                } else {
                    return;
                };
                pixel[p] = [number, touched.len() as u32];
                touched.push(touch);
            };
            let mut scan = |b: [i32; 4]| {
                for y in b[1]..b[3] {
                    let row = y as usize * w;
                    for x in b[0]..b[2] {
                        visit(row + x as usize, x, y);
                    }
                }
            };
            match union_box {
                Some(u) if area(u) <= box_area => scan(u),
                _ => self
                    .old_boxes(changed.iter().map(|&(t, _)| t), reshaded_shown)
                    .for_each(scan),
            }
            for &(_, [x, y, _]) in reshaded_scan.iter() {
                pixel[y as usize * w + x as usize][0] = 0;
            }
            // Holes three changed layers deep (a fold, a silhouette): the unchanged triangles there,
            // through the buckets, each once.
            if let Some(h) = deep {
                #[cfg(test)]
                tests::DEEP_RENDERS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                candidates.clear();
                for tile in tiles(self.tiles_x, h) {
                    for entry in &self.buckets[tile] {
                        let tu = entry.tri as usize;
                        if entry.overlaps(h) && stamp[tu] != number && visited[tu] != number {
                            visited[tu] = number;
                            candidates.push(entry.tri);
                        }
                    }
                }
                for &t in candidates.iter() {
                    for (k, p) in self.pieces[t as usize].iter().enumerate() {
                        let id = (t << PIECE_BITS) | k as u32;
                        edge::rasterize_each(&p.st, h, |x, y, depth| {
                            let at = y as usize * w + x as usize;
                            if pixel[at][0] == number {
                                let e = &mut touched[pixel[at][1] as usize];
                                if e.deep && nearer(depth, id, e.depth, e.id) {
                                    (e.depth, e.id) = (depth, id);
                                }
                            }
                        });
                    }
                }
            }
            self.fills.touched.extend_from_slice(touched);
            self.fills.reshaded_committed = reshaded_committed;
            self.fills.group(reshaded_scan);
        }
        // 2. The changed triangles' new pieces. Where nothing that changed shows, no hole
        //    opened, so a piece behind every committed depth of its tiles changes nothing.
        let full = [0, 0, shared.width as i32, shared.height as i32];
        for (k, (t, p)) in new_pieces.iter().enumerate() {
            if !*shows_now && hidden(&self.tile_far, self.tiles_x, &p.st) {
                continue;
            }
            let id = (t << PIECE_BITS) | (k as u32 - first_piece[*t as usize]);
            // The closure takes its scalars by value and the pixel marks as a slice: captured by
            // reference, they were loaded through a pointer at every pixel.
            let (pixel, touched, committed) = (&mut pixel[..], &mut *touched, &self.px[..]);
            let stamp = &stamp[..];
            edge::rasterize_each(&p.st, full, move |x, y, depth| {
                let at = y as usize * w + x as usize;
                if pixel[at][0] == number {
                    let e = &mut touched[pixel[at][1] as usize];
                    if nearer(depth, id, e.depth, e.id) {
                        (e.depth, e.id) = (depth, id);
                    }
                } else {
                    // Not a hole: the committed piece is unchanged and competes.
                    let c = &committed[at];
                    if nearer(depth, id, c.depth, c.shown) {
                        pixel[at] = [number, touched.len() as u32];
                        let won_reshaded =
                            c.shown != EMPTY && stamp[(c.shown >> PIECE_BITS) as usize] == reshade;
                        touched.push(Touch {
                            p: at as u32,
                            id,
                            depth,
                            deep: false,
                            won_reshaded,
                        });
                    }
                }
            });
        }
        // Shade and compare. A pixel that still shows the same piece of an unchanged triangle
        // keeps its value (its corners and attributes are as committed); only pixels showing a
        // changed or re-shaded triangle, or another piece than before, are shaded.
        // The touched pixels come in scan order of the old boxes, so neighbouring entries
        // alternate between the pieces of a ring: the constant-albedo pieces' planes are kept in
        // a small cache by piece id (a pixel of a cached piece costs a plane evaluation, not a
        // look-up of its piece and its shading).
        let mut delta = 0i64;
        plane_cache.resize(PLANE_CACHE, PlaneSlot::default());
        let mut rest = ShadeRest {
            number,
            stamp,
            new_pieces,
            first_piece,
            reshade_at,
            reshading,
            plane_cache,
        };
        for e in touched.iter() {
            let old = self.px[e.p as usize];
            // Most pixels show a piece whose plane is cached: that path is kept short (the rest
            // is out of line). A cached plane is taken even where the same unchanged piece
            // still shows, whose committed value was made by the same plane at the same pixel.
            let luma = if let Some(plane) = rest.plane_cache[plane_slot(e.id)].get(number, e.id) {
                let (x, y) = column_row(e.p, shared.width);
                shared.encode[index_of_linear(plane.at(x, y))]
            } else {
                self.shade_touched(shared, mesh, &mut rest, e, old)
            };
            delta += sq(old.target, luma) - sq(old.target, old.current);
            if e.won_reshaded {
                // A re-shaded pixel a new piece won: its run below counts it re-shaded.
                delta -= self.reshaded_excess(shared, mesh, &mut rest, e.p, old);
            }
        }
        // The re-shaded pixels, run by run.
        delta -= self.fills.reshaded_committed;
        let mut start = 0;
        for k in 0..self.fills.runs.len() {
            let (id, end) = self.fills.runs[k];
            let run = start..end as usize;
            start = end as usize;
            let shading = self.reshaded_shading(shared, mesh, &mut rest, id);
            delta += match shading {
                PieceShading::Plane(plane) => {
                    let f = &self.fills;
                    let run = plane_run::Run::new(
                        &f.reshaded_x[run.clone()],
                        &f.reshaded_y[run.clone()],
                        &f.reshaded_target[run],
                    );
                    plane_run::sum_sq(&plane, &shared.encode, run)
                }
                _ => self.surface_run(shared, mesh, k, id, run),
            };
        }
        delta
    }

    /// Σ (ŷ − y′)² over run `k` of the re-shaded pixels (`run` into the fills' pixels), which
    /// shows piece `id` of a per-pixel shaded triangle: its pixels' surfaces are worked out (and
    /// kept) unless the fills hold them for the triangle's present colours and UVs, then lit.
    fn surface_run(
        &mut self,
        shared: &Shared,
        mesh: &Adjacency,
        k: usize,
        id: u32,
        run: std::ops::Range<usize>,
    ) -> i64 {
        let t = id >> PIECE_BITS;
        let key = surface_key(mesh, t);
        let f = &mut self.fills;
        if f.run_keys[k] != Some(key) {
            let piece = &self.pieces[t as usize][(id & PIECE_MASK) as usize];
            f.surfaces
                .resize(f.reshaded_x.len(), (Vec3::ZERO, Vec3::ZERO));
            for i in run.clone() {
                let (x, y) = (f.reshaded_x[i] as f64 + 0.5, f.reshaded_y[i] as f64 + 0.5);
                f.surfaces[i] = surface(shared, mesh, t, &piece.st, &piece.corners, x, y);
            }
            f.run_keys[k] = Some(key);
        }
        let l = corner_light(mesh, &self.light, t);
        run.map(|i| {
            let (b, albedo) = f.surfaces[i];
            sq(f.reshaded_target[i], lit_by(shared, l, b, albedo))
        })
        .sum()
    }

    /// The new shading of re-shaded piece `id` (worked out the first time a render asks).
    fn reshaded_shading(
        &mut self,
        shared: &Shared,
        mesh: &Adjacency,
        rest: &mut ShadeRest,
        id: u32,
    ) -> PieceShading {
        let (t, piece) = ((id >> PIECE_BITS) as usize, (id & PIECE_MASK) as usize);
        let i = rest.reshading_slot(t, self.pieces[t].len(), piece);
        let p = &self.pieces[t][piece];
        let shading = &mut rest.reshading[i];
        if let PieceShading::Unknown = shading {
            *shading = shared.piece_shading(mesh, &self.light, t as u32, &p.st, &p.corners);
        }
        *shading
    }

    /// What the re-shaded runs count at pixel `p` (committed as `old`, showing a re-shaded
    /// triangle) that a new piece has won instead: (ŷ − y′)² − (ŷ − y)² with y′ its re-shaded
    /// luminance.
    #[cold]
    #[inline(never)]
    fn reshaded_excess(
        &mut self,
        shared: &Shared,
        mesh: &Adjacency,
        rest: &mut ShadeRest,
        p: u32,
        old: Pixel,
    ) -> i64 {
        let e = Touch {
            p,
            id: old.shown,
            depth: old.depth,
            deep: false,
            won_reshaded: false,
        };
        let luma = self.shade_touched(shared, mesh, rest, &e, old);
        sq(old.target, luma) - sq(old.target, old.current)
    }

    /// The luminance of touched pixel `e` (committed as `old`) when its piece's plane is not in
    /// the render's cache: the background, the committed value (the same unchanged piece still
    /// shows), or the piece's shading (worked out first, and its plane cached).
    // Out of line: inlined, its registers spilled the cached path's (9 % more instructions per
    // evaluation on the bunny). `#[cold]` lays the cached path out straight (1.6 % fewer
    // instructions again); on a textured mesh, where every pixel comes here, it measured no
    // slower (Spot, 3 000 evaluations).
    #[cold]
    #[inline(never)]
    fn shade_touched(
        &mut self,
        shared: &Shared,
        mesh: &Adjacency,
        rest: &mut ShadeRest,
        e: &Touch,
        old: Pixel,
    ) -> u16 {
        let id = e.id;
        if id == EMPTY {
            return shared.background;
        }
        let number = rest.number;
        let reshade = number | RESHADE;
        let t = id >> PIECE_BITS;
        let s = rest.stamp[t as usize];
        if keeps_committed(id, old.shown, s, number) {
            return old.current;
        }
        let (piece, tu) = ((id & PIECE_MASK) as usize, t as usize);
        let (st, corners, shading) = if s == number {
            let p = &mut rest.new_pieces[rest.first_piece[tu] as usize + piece].1;
            (&p.st, &p.corners, &mut p.shading)
        } else if s == reshade {
            // Its geometry as committed, its shading anew.
            let i = rest.reshading_slot(tu, self.pieces[tu].len(), piece);
            let p = &self.pieces[tu][piece];
            (&p.st, &p.corners, &mut rest.reshading[i])
        } else {
            let p = &mut self.pieces[tu][piece];
            (&p.st, &p.corners, &mut p.shading)
        };
        if let PieceShading::Unknown = shading {
            *shading = shared.piece_shading(mesh, &self.light, t, st, corners);
        }
        if let PieceShading::Plane(plane) = shading {
            rest.plane_cache[plane_slot(id)] = PlaneSlot {
                number,
                id,
                plane: *plane,
            };
        }
        let (x, y) = column_row(e.p, shared.width);
        let piece = ShadedPiece {
            st,
            corners,
            shading,
        };
        shade(shared, mesh, &self.light, t, piece, x + 0.5, y + 0.5)
    }

    /// Make the pending trial the committed state. The region any changed triangle covered
    /// before or covers now is rendered again with all three layers: a trial keeps only what its
    /// ΔE needs, and commits are rare (one evaluation in a hundred or so is accepted). The
    /// re-shaded triangles' pixels outside it are only shaded again (their pieces, and so every
    /// pixel's layers, stay as they were).
    fn commit(
        &mut self,
        shared: &Shared,
        mesh: &Adjacency,
        change: &Change,
        scratch: &mut Scratch,
    ) {
        if scratch.owner != Some((self.id, self.trial.serial)) {
            // The scratch has served another view since: set the trial up again (its stamps
            // and new pieces are what a commit needs).
            self.prepare(shared, mesh, change, scratch);
            scratch.owner = Some((self.id, self.trial.serial));
        }
        let everything = self.trial.everything;
        // The region: old and new boxes of the changed triangles. (The re-shaded ones keep their
        // pieces, so their layers stand; only their pixels are shaded again, below.)
        let mut region: Option<[i32; 4]> = None;
        for &(t, bb) in &scratch.bbox {
            if let Some(&Some(o)) = self.bbox.get(t as usize) {
                region = Some(union(region, o));
            }
            if let Some(n) = bb {
                region = Some(union(region, n));
            }
        }
        if everything {
            region = Some([0, 0, shared.width as i32, shared.height as i32]);
        }
        // Pieces and buckets of the changed triangles (all of them, the first time: room for
        // all at once, not grown one by one).
        if everything {
            let slots = mesh.triangle_slots();
            self.pieces
                .reserve_exact(slots.saturating_sub(self.pieces.len()));
            self.bbox
                .reserve_exact(slots.saturating_sub(self.bbox.len()));
        }
        let mut k = 0;
        for &(t, bb) in &scratch.bbox {
            let t_us = t as usize;
            if t_us >= self.pieces.len() {
                self.pieces.resize(t_us + 1, SmallVec::new());
                self.bbox.resize(t_us + 1, None);
            }
            self.pieces[t_us].clear();
            while k < scratch.pieces.len() && scratch.pieces[k].0 == t {
                self.pieces[t_us].push(scratch.pieces[k].1);
                k += 1;
            }
            let old = self.bbox[t_us];
            if old != bb {
                if let Some(o) = old {
                    for tile in tiles(self.tiles_x, o) {
                        let list = &mut self.buckets[tile];
                        if let Some(p) = list.iter().position(|e| e.tri == t) {
                            list.swap_remove(p);
                        }
                    }
                }
                if let Some(n) = bb {
                    for tile in tiles(self.tiles_x, n) {
                        self.buckets[tile].push(BucketEntry::new(t, n));
                    }
                }
                self.bbox[t_us] = bb;
            }
        }
        for &t in change.reshaded {
            for p in self.pieces.get_mut(t as usize).into_iter().flatten() {
                p.shading = PieceShading::Unknown;
            }
        }
        if self.shown_count.len() < self.pieces.len() {
            self.shown_count.resize(self.pieces.len(), 0);
        }
        if let Some(rect) = region {
            self.render_layers(shared, mesh, rect, scratch);
        }
        // The pixels showing a re-shaded triangle outside the region (inside, the render above
        // shaded them): each is visited in the box of the triangle it shows.
        let w = shared.width as usize;
        let inside = |x: i32, y: i32| region.is_some_and(|r| overlap(r, [x, y, x + 1, y + 1]));
        for &t in &scratch.reshaded_shown {
            let Some(b) = self.bbox[t as usize] else {
                continue;
            };
            for y in b[1]..b[3] {
                for x in b[0]..b[2] {
                    let p = y as usize * w + x as usize;
                    let id = self.px[p].shown;
                    if id != EMPTY && id >> PIECE_BITS == t && !inside(x, y) {
                        self.px[p].current = self.shade_committed(shared, mesh, id, x, y);
                    }
                }
            }
        }
        self.commits += 1;
        self.trial.saved_xf.clear();
        self.trial.saved_light.clear();
        // What the scratch holds is committed now, not a pending trial.
        scratch.owner = None;
    }

    /// Render `rect` of the committed state from scratch with all three layers: the three nearest
    /// pieces of every pixel (from every triangle overlapping it), the luminance
    /// where the nearest piece is changed, re-shaded or another than before (by the stamps of
    /// the trial being committed), the shown counts and the tiles' farthest depths.
    fn render_layers(
        &mut self,
        shared: &Shared,
        mesh: &Adjacency,
        rect: [i32; 4],
        scratch: &mut Scratch,
    ) {
        let number = scratch.number;
        let [x0, y0, x1, y1] = rect;
        let (w, rw) = (shared.width as usize, (x1 - x0) as usize);
        let layers = &mut scratch.layers;
        layers.clear();
        layers.resize(rw * (y1 - y0) as usize, [(f32::INFINITY, EMPTY); 3]);
        // Every triangle overlapping the rectangle, once.
        let candidates = &mut scratch.candidates;
        candidates.clear();
        for tile in tiles(self.tiles_x, rect) {
            for entry in &self.buckets[tile] {
                if entry.overlaps(rect) {
                    candidates.push(entry.tri);
                }
            }
        }
        candidates.sort_unstable();
        candidates.dedup();
        for &t in candidates.iter() {
            for (k, p) in self.pieces[t as usize].iter().enumerate() {
                let id = (t << PIECE_BITS) | k as u32;
                edge::rasterize_each(&p.st, rect, |x, y, depth| {
                    let l = &mut layers[(y - y0) as usize * rw + (x - x0) as usize];
                    if nearer(depth, id, l[0].0, l[0].1) {
                        l[2] = l[1];
                        l[1] = l[0];
                        l[0] = (depth, id);
                    } else if nearer(depth, id, l[1].0, l[1].1) {
                        l[2] = l[1];
                        l[1] = (depth, id);
                    } else if nearer(depth, id, l[2].0, l[2].1) {
                        l[2] = (depth, id);
                    }
                });
            }
        }
        let stamp = &scratch.stamp;
        for y in y0..y1 {
            for x in x0..x1 {
                let p = y as usize * w + x as usize;
                let [(depth, id), (depth2, id2), (depth3, id3)] =
                    layers[(y - y0) as usize * rw + (x - x0) as usize];
                let old = self.px[p];
                let current = if id == EMPTY {
                    shared.background
                } else {
                    let t = id >> PIECE_BITS;
                    let s = stamp[t as usize];
                    if keeps_committed(id, old.shown, s, number) {
                        old.current
                    } else {
                        self.shade_committed(shared, mesh, id, x, y)
                    }
                };
                if old.shown != id {
                    if old.shown != EMPTY {
                        self.shown_count[(old.shown >> PIECE_BITS) as usize] -= 1;
                    }
                    if id != EMPTY {
                        self.shown_count[(id >> PIECE_BITS) as usize] += 1;
                    }
                }
                let px = &mut self.px[p];
                (px.current, px.shown, px.depth) = (current, id, depth);
                self.second[p] = [
                    Layer {
                        shown: id2,
                        depth: depth2,
                    },
                    Layer {
                        shown: id3,
                        depth: depth3,
                    },
                ];
            }
        }
        // The farthest depth of every tile the rectangle touched.
        let b = BUCKET as i32;
        let (wi, hi) = (shared.width as i32, shared.height as i32);
        for tile in tiles(self.tiles_x, rect) {
            let (tx, ty) = (
                (tile as u32 % self.tiles_x) as i32,
                (tile as u32 / self.tiles_x) as i32,
            );
            let mut far = f32::NEG_INFINITY;
            for y in ty * b..((ty + 1) * b).min(hi) {
                let row = y as usize * w;
                for x in tx * b..((tx + 1) * b).min(wi) {
                    far = far.max(self.px[row + x as usize].depth);
                }
            }
            self.tile_far[tile] = far;
        }
    }

    /// The luminance of committed piece `id` at pixel (x, y) (its shading worked out first if
    /// it is not known).
    fn shade_committed(
        &mut self,
        shared: &Shared,
        mesh: &Adjacency,
        id: u32,
        x: i32,
        y: i32,
    ) -> u16 {
        let t = id >> PIECE_BITS;
        let piece = &mut self.pieces[t as usize][(id & PIECE_MASK) as usize];
        if let PieceShading::Unknown = piece.shading {
            piece.shading = shared.piece_shading(mesh, &self.light, t, &piece.st, &piece.corners);
        }
        let shaded = ShadedPiece {
            st: &piece.st,
            corners: &piece.corners,
            shading: &piece.shading,
        };
        shade(
            shared,
            mesh,
            &self.light,
            t,
            shaded,
            x as f64 + 0.5,
            y as f64 + 0.5,
        )
    }

    fn revert(&mut self) {
        let tr = &mut self.trial;
        for &(v, x) in tr.saved_xf.iter().rev() {
            self.xf[v as usize] = x;
        }
        for &(w, l) in tr.saved_light.iter().rev() {
            self.light[w as usize] = l;
        }
        tr.saved_xf.clear();
        tr.saved_light.clear();
    }
}

/// A piece's geometry and the shading to use for it (a re-shaded triangle's comes from the
/// trial, not from the piece).
struct ShadedPiece<'a> {
    st: &'a SetupTri,
    corners: &'a super::setup::Corners,
    shading: &'a PieceShading,
}

/// Gouraud shading of source triangle `t` (one of its pieces) at screen point (x, y), as luminance.
fn shade(
    shared: &Shared,
    mesh: &Adjacency,
    light: &[(Vec3, Vec3)],
    t: u32,
    ShadedPiece {
        st,
        corners,
        shading,
    }: ShadedPiece,
    x: f64,
    y: f64,
) -> u16 {
    if let PieceShading::Plane(plane) = shading {
        return shared.encode[index_of_linear(plane.at(x - 0.5, y - 0.5))];
    }
    let (b, albedo) = surface(shared, mesh, t, st, corners, x, y);
    lit(shared, mesh, light, t, b, albedo)
}

/// What a per-pixel shaded piece of source triangle `t` shows at screen point (x, y) before
/// lighting: the source barycentrics and the albedo (material colour, vertex colours, texture).
/// It depends on the piece's geometry and its wedges' colours and UVs, not on their normals.
fn surface(
    shared: &Shared,
    mesh: &Adjacency,
    t: u32,
    st: &SetupTri,
    corners: &super::setup::Corners,
    x: f64,
    y: f64,
) -> (Vec3, Vec3) {
    let b = source_barycentrics(st, corners, x, y);
    let wd = mesh.corners(t).map(|w| &mesh.wedges[w as usize]);
    let m = &shared.materials[mesh.material(t) as usize];
    let mut albedo = m.base_color;
    if mesh.has_colors() {
        albedo *= wd[0].color * b.x + wd[1].color * b.y + wd[2].color * b.z;
    }
    if let (Some(tex), true) = (&m.texture, mesh.has_uvs()) {
        let uv_at = |bb: Vec3| -> Vec2 { wd[0].uv * bb.x + wd[1].uv * bb.y + wd[2].uv * bb.z };
        let uv = uv_at(b);
        let dx = uv_at(source_barycentrics(st, corners, x + 1.0, y)) - uv;
        let dy = uv_at(source_barycentrics(st, corners, x, y + 1.0)) - uv;
        albedo *= tex.sample(uv, dx, dy);
    }
    (b, albedo)
}

/// The luminance code of `albedo` lit by triangle `t`'s corners' Gouraud terms, interpolated
/// with source barycentrics `b`.
#[inline]
fn lit(
    shared: &Shared,
    mesh: &Adjacency,
    light: &[(Vec3, Vec3)],
    t: u32,
    b: Vec3,
    albedo: Vec3,
) -> u16 {
    lit_by(shared, corner_light(mesh, light, t), b, albedo)
}

/// Triangle `t`'s corners' Gouraud (diffuse, specular) terms.
#[inline]
fn corner_light(mesh: &Adjacency, light: &[(Vec3, Vec3)], t: u32) -> [(Vec3, Vec3); 3] {
    mesh.corners(t).map(|w| light[w as usize])
}

/// [`lit`] with the corners' terms at hand.
#[inline(always)]
fn lit_by(shared: &Shared, l: [(Vec3, Vec3); 3], b: Vec3, albedo: Vec3) -> u16 {
    let d = l[0].0 * b.x + l[1].0 * b.y + l[2].0 * b.z;
    let s = l[0].1 * b.x + l[1].1 * b.y + l[2].1 * b.z;
    shared.luma(albedo * d + s)
}

/// The wedge attributes a triangle's [`surface`] depends on (colours and UVs), as bits.
fn surface_key(mesh: &Adjacency, t: u32) -> [u32; 15] {
    let mut key = [0u32; 15];
    for (k, w) in mesh.corners(t).into_iter().enumerate() {
        let wd = &mesh.wedges[w as usize];
        let bits = wd.color.to_array().map(f32::to_bits);
        key[5 * k..5 * k + 3].copy_from_slice(&bits);
        key[5 * k + 3] = wd.uv.x.to_bits();
        key[5 * k + 4] = wd.uv.y.to_bits();
    }
    key
}

/// The luminance code of a linear colour, as the optimizer's images store it (for comparing a
/// full `raster::render` frame with these images).
pub fn luma_of(color: Vec3) -> u16 {
    encode_code(luma_index(color))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::raster::{RenderSettings, SamplePattern, Shading, render};
    use crate::scene::Rig;
    use std::sync::Arc;

    /// Renders that had a hole three changed layers deep (so the tests can tell the path ran).
    pub(super) static DEEP_RENDERS: std::sync::atomic::AtomicUsize =
        std::sync::atomic::AtomicUsize::new(0);

    fn cameras(mesh: &crate::mesh::Mesh, n: u32) -> Vec<Camera> {
        Rig::Fibonacci(n)
            .directions()
            .into_iter()
            .map(|d| {
                Camera::frame_sphere(
                    mesh.bounding_sphere(),
                    d,
                    Camera::DEFAULT_FOV_Y_DEG,
                    1.0,
                    Camera::DEFAULT_MARGIN,
                )
            })
            .collect()
    }

    /// A level-3 icosphere's scene, `n` cameras around it and its adjacency.
    fn icosphere_views(n: u32) -> (RenderScene, Vec<Camera>, Adjacency) {
        let mesh = Arc::new(shapes::icosphere(3));
        let cams = cameras(&mesh, n);
        let adj = Adjacency::new(&mesh);
        (RenderScene::of(mesh), cams, adj)
    }

    #[test]
    fn linear_luminance_indices_clamp_and_send_nan_to_zero() {
        assert_eq!(index_of_linear(f32::NAN), 0);
        assert_eq!(index_of_linear(-1.0), 0);
        assert_eq!(index_of_linear(f32::NEG_INFINITY), 0);
        assert_eq!(index_of_linear(2.0), 65535);
        assert_eq!(index_of_linear(f32::INFINITY), 65535);
        assert_eq!(index_of_linear(0.5), 32768);
        assert_eq!(index_of_linear(1.0 / 65535.0), 1);
    }

    #[test]
    fn full_render_equals_the_rasterizer_at_one_sample() {
        let (scene, cams, adj) = icosphere_views(3);
        let views = LumaViews::new(&adj, &scene, &cams, 64, 48, None).unwrap();
        let settings = RenderSettings {
            width: 64,
            height: 48,
            samples: SamplePattern::Ordered(1),
            shading: Shading::Gouraud,
            ..RenderSettings::DEFAULT
        };
        // The same coverage and visibility, and shading equal up to rounding: untextured pieces
        // are shaded through their luminance planes (f64) rather than the rasterizer's per-channel
        // f32 colours, which moves a value across a 16-bit code boundary now and then.
        let (mut differ, mut total, mut shaded) = (0usize, 0usize, 0usize);
        for (h, cam) in cams.iter().enumerate() {
            let frame = render(&scene, cam, &settings).unwrap();
            let expect: Vec<u16> = frame.color().iter().map(|&c| luma_of(c)).collect();
            let got: Vec<u16> = views.view_pixels(h).map(|(y, _)| y).collect();
            let bg = views.shared.background;
            for (i, (&g, &e)) in got.iter().zip(&expect).enumerate() {
                assert_eq!(g == bg, e == bg, "view {h} pixel {i}: coverage differs");
                assert!(g.abs_diff(e) <= 1, "view {h} pixel {i}: {g} against {e}");
                differ += usize::from(g != e);
                shaded += usize::from(e != bg);
            }
            total += got.len();
        }
        eprintln!("{differ} of {shaded} shaded pixels ({total} in all) one code apart");
        assert!(shaded > total / 10);
        assert!(differ * 100 <= shaded, "{differ} of {shaded} pixels differ");
    }

    #[test]
    fn images_view_by_view_equal_the_images_of_all_views() {
        // `images_of` (one view's state per thread) gives every view's codes as a LumaViews of
        // all views does.
        let (scene, cams, adj) = icosphere_views(5);
        let all = LumaViews::new(&adj, &scene, &cams, 40, 30, None)
            .unwrap()
            .images();
        let one_by_one = LumaViews::images_of(&adj, &scene, &cams, 40, 30).unwrap();
        assert_eq!(all.len(), 5);
        assert!(all.iter().all(|im| im.iter().any(|&y| y != all[0][0])));
        assert_eq!(one_by_one, all);
    }

    #[test]
    fn incremental_delta_equals_full_energy_difference() {
        // Move a vertex: ΔE from the trial equals E(after) − E(before) from full renders.
        let original = Arc::new(shapes::icosphere(3));
        let scene = RenderScene::of(original.clone());
        let cams = cameras(&original, 4);
        let targets = LumaViews::new(&Adjacency::new(&original), &scene, &cams, 64, 64, None)
            .unwrap()
            .images();
        let coarse = Arc::new(shapes::icosphere(1));
        let mut adj = Adjacency::new(&coarse);
        let mut views = LumaViews::new(&adj, &scene, &cams, 64, 64, Some(targets.clone())).unwrap();
        let e0 = views.energy();
        assert!(e0 > 0);
        let v = 5u32;
        adj.positions[v as usize] *= 1.2;
        let tris: Vec<u32> = adj.vertex_triangles(v).to_vec();
        let change = Change {
            vertices: &[v],
            wedges: &[],
            triangles: &tris,
            reshaded: &[],
        };
        let delta = views.trial(&adj, &change);
        views.commit(&adj);
        let full = LumaViews::new(&adj, &scene, &cams, 64, 64, Some(targets)).unwrap();
        assert_eq!(views.images(), full.images());
        assert_eq!(e0 + delta, full.energy());
        assert_eq!(views.energy(), full.energy());
        assert_ne!(delta, 0);
    }

    #[test]
    fn random_moves_keep_the_layers_and_images_of_a_fresh_render() {
        random_moves_match_a_fresh_render(false);
    }

    #[test]
    fn random_moves_keep_the_layers_and_images_of_a_fresh_render_with_vertex_colours() {
        // Vertex colours shade every pixel through its barycentrics, not a luminance plane: the
        // other path of the holes, the new pieces and the re-shaded runs.
        random_moves_match_a_fresh_render(true);
    }

    fn random_moves_match_a_fresh_render(coloured: bool) {
        // Vertex moves large enough to fold the surface over itself (holes several changed layers
        // deep), normal changes (re-shaded triangles), and both at once (a move that re-shades
        // the triangles around a neighbour, beyond the moved ones' boxes, as derived normals
        // do), each tried a few times in a row with
        // other values (as the simplex does: the views reuse their holes' fills) and then
        // accepted or reverted at random: the incremental state equals a fresh render of the
        // final mesh, all three layers of every pixel included, and the accepted ΔE add up to its
        // energy exactly.
        let original = Arc::new(shapes::icosphere(3));
        let scene = RenderScene::of(original.clone());
        let cams = cameras(&original, 5);
        let (w, h) = (48, 40);
        let targets = LumaViews::new(&Adjacency::new(&original), &scene, &cams, w, h, None)
            .unwrap()
            .images();
        let mut coarse = shapes::icosphere(1);
        if coloured {
            let mut data = coarse.to_data();
            data.colors = Some(
                data.positions
                    .iter()
                    .map(|p| (*p * 0.5 + Vec3::splat(0.5)).clamp(Vec3::ZERO, Vec3::ONE))
                    .collect(),
            );
            coarse = crate::mesh::Mesh::new(data, &Default::default()).unwrap();
        }
        let mut adj = Adjacency::new(&coarse);
        assert_eq!(adj.has_colors(), coloured);
        let mut views = LumaViews::new(&adj, &scene, &cams, w, h, Some(targets.clone())).unwrap();
        let mut energy = views.energy();
        let mut next = crate::raster::xorshift(0x2545_f491_4f6c_dd1du64);
        let unit = |r: u64| (r % 2001) as f32 / 1000.0 - 1.0;
        let deep_before = DEEP_RENDERS.load(std::sync::atomic::Ordering::Relaxed);
        let mut accepted = 0;
        let mut v = 0;
        for _ in 0..80 {
            // Now and then the same vertex again, after an accept too (the fills must not
            // outlive the committed state they were made on).
            if !next().is_multiple_of(3) {
                v = (next() % adj.positions.len() as u64) as u32;
            }
            let tris: Vec<u32> = adj.vertex_triangles(v).to_vec();
            let w0 = adj.single_wedge(v).unwrap();
            let (old_p, old_n) = (adj.positions[v as usize], adj.wedges[w0 as usize].normal);
            let old_colour = adj.wedges[w0 as usize].color;
            let normal = next().is_multiple_of(3);
            // A neighbour whose normal changes with the move (half the moves).
            let u = adj.neighbours(v)[0];
            let wu = adj.single_wedge(u).unwrap();
            let old_nu = adj.wedges[wu as usize].normal;
            let with_neighbour = next().is_multiple_of(2);
            let around_u: Vec<u32> = adj
                .vertex_triangles(u)
                .iter()
                .copied()
                .filter(|t| !tris.contains(t))
                .collect();
            let mut delta = 0;
            for _ in 0..1 + next() % 3 {
                delta = if normal {
                    // A new normal: the same corners, new shading.
                    let n = Vec3::new(unit(next()), unit(next()), unit(next()));
                    adj.wedges[w0 as usize].normal = (n + old_n).normalize_or(old_n);
                    if coloured && next().is_multiple_of(2) {
                        // A new colour as well: the re-shaded pixels' surfaces change too.
                        let c = Vec3::new(unit(next()), unit(next()), unit(next()));
                        adj.wedges[w0 as usize].color = (c * 0.5 + Vec3::splat(0.5)).abs();
                    }
                    let change = Change {
                        vertices: &[],
                        wedges: &[w0],
                        triangles: &[],
                        reshaded: &tris,
                    };
                    views.trial(&adj, &change)
                } else {
                    let d = Vec3::new(unit(next()), unit(next()), unit(next()));
                    adj.positions[v as usize] = old_p + 0.6 * d;
                    let (wedges, reshaded): (&[u32], &[u32]) = if with_neighbour {
                        let n = Vec3::new(unit(next()), unit(next()), unit(next()));
                        adj.wedges[wu as usize].normal = (n + old_nu).normalize_or(old_nu);
                        (&[wu], &around_u)
                    } else {
                        (&[], &[])
                    };
                    let change = Change {
                        vertices: &[v],
                        wedges,
                        triangles: &tris,
                        reshaded,
                    };
                    views.trial(&adj, &change)
                };
            }
            if next().is_multiple_of(2) {
                views.commit(&adj);
                energy += delta;
                accepted += 1;
            } else {
                views.revert();
                adj.positions[v as usize] = old_p;
                adj.wedges[w0 as usize].normal = old_n;
                adj.wedges[w0 as usize].color = old_colour;
                adj.wedges[wu as usize].normal = old_nu;
            }
        }
        assert!(accepted > 20, "{accepted} accepted");
        assert!(
            DEEP_RENDERS.load(std::sync::atomic::Ordering::Relaxed) > deep_before,
            "no move made a hole three changed layers deep"
        );
        let fresh = LumaViews::new(&adj, &scene, &cams, w, h, Some(targets)).unwrap();
        assert_eq!(views.energy(), energy);
        assert_eq!(energy, fresh.energy());
        assert_eq!(views.images(), fresh.images());
        for (k, (a, b)) in views.views.iter().zip(&fresh.views).enumerate() {
            for p in 0..a.px.len() {
                let key = |l: Layer| (l.shown, l.depth.to_bits());
                let nearest = |v: &View| {
                    key(Layer {
                        shown: v.px[p].shown,
                        depth: v.px[p].depth,
                    })
                };
                assert_eq!(nearest(a), nearest(b), "view {k} pixel {p}: nearest");
                assert_eq!(
                    a.second[p].map(key),
                    b.second[p].map(key),
                    "view {k} pixel {p}: layers behind"
                );
            }
        }
    }
}
