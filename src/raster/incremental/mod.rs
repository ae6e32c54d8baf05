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

//!
//! Files, one part of the work each: `views.rs` ([`LumaViews`], the public face: build, trial,
//! commit and revert over all views), `trial.rs` (a view's trial: the changed triangles set up
//! anew, the holes and the new pieces, ΔE), `runs.rs` (shading the touched pixels: the re-shaded
//! runs and the plane cache), `commit.rs` (a trial made the committed state: the three layers, the
//! counts and tiles), `plane_run.rs` (re-shaded pixels four at a time), `crew.rs` (the threads that
//! stay awake between trials).

mod commit;
mod crew;
mod plane_run;
mod runs;
#[cfg(test)]
mod tests;
mod trial;
mod views;

use glam::{Mat4, Vec2, Vec3};
use rayon::prelude::*;
use smallvec::SmallVec;

use self::crew::Crew;
use self::plane_run::{Plane as LumaPlane, index_of_linear, sq};
use super::RenderScene;
use super::clip::ClipPlanes;
use super::edge::{self, EMPTY};
use super::setup::{SetupOut, SetupTri, Viewport, XfVertex, setup_one, transform_one};
use super::shade::{ResolvedLight, light_terms, source_barycentrics};
use super::texture::MipTexture;
use super::{camera_setup, fixed, rect_union as union};
use crate::error::{Error, Result};
use crate::mesh::edit::Adjacency;
use crate::prefetch::{prefetch, prefetch_at};
use crate::scene::Camera;

pub use self::runs::luma_of;

// What the parts share (the parent's own items reach them through `use super::*`).
use self::runs::*;

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
