//! Tile binning: which set-up triangles touch which screen tile.
//!
//! The screen is cut into [`TILE`]×[`TILE`] pixel tiles; each tile gets the list of set-up triangle
//! indices whose bounding box overlaps it, in increasing index order (binning runs over fixed
//! chunks in parallel and concatenates per tile in chunk order). Tiles are then rasterized
//! independently, each owning its pixels, so no two threads ever write the same sample and the
//! result does not depend on scheduling. The region re-render uses the same bins to find the
//! triangles overlapping a rectangle without scanning every triangle.

use rayon::prelude::*;

use super::setup::SetupTri;

/// Tile edge in pixels.
pub const TILE: u32 = 64;

/// Per-tile triangle lists.
#[derive(Debug, Clone)]
pub(crate) struct Bins {
    pub tiles_x: u32,
    pub lists: Vec<Vec<u32>>,
}

impl Bins {
    /// Pixel rectangle `[x0, y0, x1, y1)` of tile `t`.
    pub fn tile_rect(&self, t: usize, width: u32, height: u32) -> [i32; 4] {
        let (tx, ty) = (t as u32 % self.tiles_x, t as u32 / self.tiles_x);
        [
            (tx * TILE) as i32,
            (ty * TILE) as i32,
            ((tx + 1) * TILE).min(width) as i32,
            ((ty + 1) * TILE).min(height) as i32,
        ]
    }
}

/// Bin set-up triangles into tiles.
pub(crate) fn bin(tris: &[SetupTri], width: u32, height: u32) -> Bins {
    let tiles_x = width.div_ceil(TILE);
    let tiles_y = height.div_ceil(TILE);
    let n_tiles = (tiles_x * tiles_y) as usize;
    const CHUNK: usize = 16 * 1024;
    let partial: Vec<Vec<Vec<u32>>> = tris
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let mut lists = vec![Vec::new(); n_tiles];
            for (k, t) in chunk.iter().enumerate() {
                let [x0, y0, x1, y1] = t.bbox;
                let (tx0, ty0) = (x0 as u32 / TILE, y0 as u32 / TILE);
                let (tx1, ty1) = ((x1 as u32 - 1) / TILE, (y1 as u32 - 1) / TILE);
                for ty in ty0..=ty1 {
                    for tx in tx0..=tx1 {
                        lists[(ty * tiles_x + tx) as usize].push((c * CHUNK + k) as u32);
                    }
                }
            }
            lists
        })
        .collect();
    let lists = (0..n_tiles)
        .into_par_iter()
        .map(|t| {
            let total = partial.iter().map(|p| p[t].len()).sum();
            let mut list = Vec::with_capacity(total);
            for p in &partial {
                list.extend_from_slice(&p[t]);
            }
            list
        })
        .collect();
    Bins { tiles_x, lists }
}
