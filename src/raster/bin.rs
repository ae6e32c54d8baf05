//! Triangle set-up fused with tile binning, per chunk of source triangles.
//!
//! The source triangles are cut into fixed chunks of [`CHUNK`]; each chunk (one parallel task) sets
//! up its triangles (`setup.rs`) and counting-sorts them by the [`TILE`]×[`TILE`] screen tiles their
//! bounding boxes touch, keeping triangle order within each tile. A tile's triangle list is the
//! concatenation of its slice in every chunk, in chunk order — so it is in source-triangle order,
//! whatever the thread count, without ever copying the set-up triangles into one array.
//! Set-up triangle ids are `chunk << 16 | index within chunk` (a chunk of 4096 source triangles
//! yields at most 7 × 4096 < 2^16 clipped triangles).
//!
//! Tiles are then rasterized independently, each owning its pixels, so no two threads write the
//! same sample.

use glam::Vec3;
use rayon::prelude::*;

use super::clip::ClipPlanes;
use super::setup::{Corners, SetupOut, SetupTri, Viewport, XfVertex, setup_one};

/// Tile edge in pixels.
pub const TILE: u32 = 64;
/// How many triangles ahead [`Binned::tile`] asks for a record.
const LOOKAHEAD: usize = 4;
/// Source triangles per set-up chunk.
pub(crate) const CHUNK: usize = 4096;

/// The set-up triangles of one chunk, sorted by tile.
#[derive(Debug, Clone)]
pub(crate) struct SetupChunk {
    tris: Vec<SetupTri>,
    clipped: Vec<[Vec3; 3]>,
    /// `items[tile_start[t]..tile_start[t + 1]]` are the triangles (indices into `tris`) of tile t.
    tile_start: Vec<u32>,
    items: Vec<u16>,
}

/// All set-up triangles of a frame, binned.
#[derive(Debug, Clone)]
pub(crate) struct Binned {
    chunks: Vec<SetupChunk>,
}

impl Binned {
    /// The set-up triangle with id `id`.
    pub fn get(&self, id: u32) -> &SetupTri {
        &self.chunks[(id >> 16) as usize].tris[(id & 0xFFFF) as usize]
    }

    /// Where the corners of set-up triangle `id` lie on its source triangle.
    pub fn corners(&self, id: u32) -> Corners {
        let clipped = &self.chunks[(id >> 16) as usize].clipped;
        Corners::decode(self.get(id).corners, clipped)
    }

    /// The set-up triangles touching tile `t`, as (id, triangle), in source-triangle order.
    ///
    /// Each triangle's record is asked for a few triangles ahead ([`LOOKAHEAD`]): the records of
    /// a frame (64 bytes per triangle) are far larger than the caches, and a tile reads them
    /// scattered over every chunk, so waiting for each one was a visible share of the scan.
    pub fn tile(&self, t: usize) -> impl Iterator<Item = (u32, &SetupTri)> {
        self.chunks.iter().enumerate().flat_map(move |(c, chunk)| {
            let range = chunk.tile_start[t] as usize..chunk.tile_start[t + 1] as usize;
            let items = &chunk.items[range];
            items.iter().enumerate().map(move |(j, &k)| {
                if let Some(&ahead) = items.get(j + LOOKAHEAD) {
                    crate::prefetch::prefetch(&chunk.tris[ahead as usize]);
                }
                (setup_id(c, k as usize), &chunk.tris[k as usize])
            })
        })
    }
}

/// Number of tiles of a `width` × `height` frame.
pub fn tile_count(width: u32, height: u32) -> usize {
    (width.div_ceil(TILE) * height.div_ceil(TILE)) as usize
}

/// Pixel rectangle `[x0, y0, x1, y1)` of tile `t` (row-major) of a `width` × `height` frame.
pub fn tile_rect(t: usize, width: u32, height: u32) -> [i32; 4] {
    let tiles_x = width.div_ceil(TILE);
    let (tx, ty) = (t as u32 % tiles_x, t as u32 / tiles_x);
    [
        (tx * TILE) as i32,
        (ty * TILE) as i32,
        ((tx + 1) * TILE).min(width) as i32,
        ((ty + 1) * TILE).min(height) as i32,
    ]
}

/// The set-up triangles of chunks of [`CHUNK`] source triangles (chunk c's output of
/// [`setup_one`] is `outs[c]`), unbinned: their ids are those of [`setup_and_bin`], and every
/// tile's list is empty.
pub(crate) fn unbinned(outs: Vec<SetupOut>, n_tiles: usize) -> Binned {
    let chunks = outs
        .into_iter()
        .map(|SetupOut { tris, clipped }| SetupChunk {
            tris,
            clipped,
            tile_start: vec![0; n_tiles + 1],
            items: Vec::new(),
        })
        .collect();
    Binned { chunks }
}

/// Set up chunk `c` of the source triangles (`chunk`, from triangle `c * CHUNK`), in order.
pub(crate) fn setup_chunk(
    c: usize,
    chunk: &[[u32; 3]],
    xf: &[XfVertex],
    planes: &ClipPlanes,
    vp: Viewport,
) -> SetupOut {
    let mut out = SetupOut {
        tris: Vec::with_capacity(chunk.len()),
        clipped: Vec::new(),
    };
    for (k, t) in chunk.iter().enumerate() {
        setup_one((c * CHUNK + k) as u32, *t, xf, planes, vp, &mut out);
    }
    out
}

/// The id of triangle `k` of chunk `c`'s set-up output.
#[inline]
pub(crate) fn setup_id(c: usize, k: usize) -> u32 {
    ((c as u32) << 16) | k as u32
}

/// Set up and bin every triangle.
pub(crate) fn setup_and_bin(
    triangles: &[[u32; 3]],
    xf: &[XfVertex],
    planes: &ClipPlanes,
    vp: Viewport,
) -> Binned {
    let tiles_x = vp.width.div_ceil(TILE);
    let n_tiles = tile_count(vp.width, vp.height);
    let chunks = triangles
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let SetupOut { tris, clipped } = setup_chunk(c, chunk, xf, planes, vp);
            // Counting sort by tile: count, prefix-sum, scatter (keeps triangle order per tile).
            // Explicit loops: most triangles touch one tile, and nested iterator adapters here
            // cost more than the counting itself.
            let tile_range = |t: &SetupTri| {
                let [x0, y0, x1, y1] = t.bbox();
                [
                    x0 as u32 / TILE,
                    y0 as u32 / TILE,
                    (x1 as u32 - 1) / TILE,
                    (y1 as u32 - 1) / TILE,
                ]
            };
            let mut tile_start = vec![0u32; n_tiles + 1];
            for t in &tris {
                let [tx0, ty0, tx1, ty1] = tile_range(t);
                for ty in ty0..=ty1 {
                    for tx in tx0..=tx1 {
                        tile_start[(ty * tiles_x + tx) as usize + 1] += 1;
                    }
                }
            }
            for i in 0..n_tiles {
                tile_start[i + 1] += tile_start[i];
            }
            let mut fill = tile_start.clone();
            let mut items = vec![0u16; tile_start[n_tiles] as usize];
            for (k, t) in tris.iter().enumerate() {
                let [tx0, ty0, tx1, ty1] = tile_range(t);
                for ty in ty0..=ty1 {
                    for tx in tx0..=tx1 {
                        let tile = (ty * tiles_x + tx) as usize;
                        items[fill[tile] as usize] = k as u16;
                        fill[tile] += 1;
                    }
                }
            }
            SetupChunk {
                tris,
                clipped,
                tile_start,
                items,
            }
        })
        .collect();
    Binned { chunks }
}
