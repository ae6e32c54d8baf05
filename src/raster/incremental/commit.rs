//! Making a trial the committed state: the changed region rendered again with its three layers,
//! the per-triangle shown counts and per-tile far depths; and `revert`.

use super::*;

impl View {
    /// Make the pending trial the committed state. The region any changed triangle covered
    /// before or covers now is rendered again with all three layers: a trial keeps only what its
    /// ΔE needs, and commits are rare (one evaluation in a hundred or so is accepted). The
    /// re-shaded triangles' pixels outside it are only shaded again (their pieces, and so every
    /// pixel's layers, stay as they were).
    pub(super) fn commit(
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
    pub(super) fn render_layers(
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
    pub(super) fn shade_committed(
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

    pub(super) fn revert(&mut self) {
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
