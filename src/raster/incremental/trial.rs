//! A view's trial: the changed triangles set up anew, the holes they leave filled from the
//! layers behind them, their new pieces depth-tested, and ΔE over the pixels that can change.

use super::*;

impl View {
    /// Apply `change` to this view's transforms, light terms and set-up (saving what a revert
    /// restores), then render the dirty rectangle into `scratch` and return ΔE.
    pub(super) fn trial(
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
    pub(super) fn build(
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
    pub(super) fn old_box(&self, t: u32) -> Option<[i32; 4]> {
        self.bbox
            .get(t as usize)
            .copied()
            .flatten()
            .filter(|_| shows(&self.shown_count, t))
    }

    /// The committed boxes of the changed triangles and the re-shaded ones that show: the
    /// pixels a trial re-visits first (prefetched by `prepare`, scanned by `render`).
    pub(super) fn old_boxes<'a>(
        &'a self,
        changed: impl Iterator<Item = u32> + 'a,
        reshaded_shown: &'a [u32],
    ) -> impl Iterator<Item = [i32; 4]> + 'a {
        changed
            .chain(reshaded_shown.iter().copied())
            .filter_map(|t| self.old_box(t))
    }

    /// The changed triangles set up anew into `scratch.pieces` (a triangle clipped into
    /// several pieces gets each), with each triangle's new box in `scratch.bbox`.
    fn set_up_changed(&self, mesh: &Adjacency, change: &Change, scratch: &mut Scratch) {
        for &t in change.triangles {
            let mut bb: Option<[i32; 4]> = None;
            if mesh.is_alive(t) {
                let setup = &mut scratch.setup;
                setup.tris.clear();
                setup.clipped.clear();
                setup_one(t, mesh.triangle(t), &self.xf, &self.planes, self.vp, setup);
                for st in &setup.tris {
                    let corners = crate::raster::setup::Corners::decode(st.corners, &setup.clipped);
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
    }

    /// New set-up of the changed triangles and the dirty rectangle; false if it is empty.
    pub(super) fn prepare(
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
        self.set_up_changed(mesh, change, scratch);
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
    pub(super) fn render(
        &mut self,
        shared: &Shared,
        mesh: &Adjacency,
        scratch: &mut Scratch,
    ) -> i64 {
        if scratch.rect.is_none() || self.trial.everything {
            // Nothing to render, or the first render (which only a commit makes).
            return 0;
        }
        scratch.pixels_for(self.px.len());
        scratch.touched.clear();
        if scratch.fills_hold {
            // The same triangles changed as in the last trial, on the same committed state.
            scratch.touched.extend_from_slice(&self.fills.touched);
            for (i, e) in scratch.touched.iter().enumerate() {
                scratch.pixel[e.p as usize] = [scratch.number, i as u32];
            }
        } else {
            // 1. The holes and the re-shaded pixels.
            let (deep, reshaded_committed) = self.find_holes(shared, scratch);
            if let Some(h) = deep {
                self.fill_deep_holes(shared, scratch, h);
            }
            self.fills.touched.extend_from_slice(&scratch.touched);
            self.fills.reshaded_committed = reshaded_committed;
            self.fills.group(&mut scratch.reshaded_scan);
        }
        // 2. The changed triangles' new pieces.
        self.scan_new_pieces(shared, scratch);
        // 3. Shade and compare.
        self.shade_and_compare(shared, mesh, scratch)
    }

    /// Step 1 of [`View::render`]: the holes, pixels a changed triangle showed (the second layer
    /// shows there now), and the pixels of re-shaded triangles (their pieces stay, their shading
    /// changes), found in the old boxes of those that show anywhere, visited once each. One pass
    /// over the boxes' union where that is smaller than the boxes together (they overlap around
    /// a moved vertex), else box by box. Returns the box of the holes three changed layers deep
    /// and the committed error of the re-shaded pixels.
    fn find_holes(&mut self, shared: &Shared, scratch: &mut Scratch) -> (Option<[i32; 4]>, i64) {
        let number = scratch.number;
        let reshade = number | RESHADE;
        let w = shared.width as usize;
        let Scratch {
            bbox: changed,
            reshaded_shown,
            stamp,
            pixel,
            touched,
            reshaded_scan,
            old_boxes,
            ..
        } = scratch;
        let changed_piece = |id: u32| id != EMPTY && stamp[(id >> PIECE_BITS) as usize] == number;
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
        (deep, reshaded_committed)
    }

    /// Holes three changed layers deep (a fold, a silhouette), inside `h`: the unchanged
    /// triangles there, through the buckets, each once.
    fn fill_deep_holes(&self, shared: &Shared, scratch: &mut Scratch, h: [i32; 4]) {
        let number = scratch.number;
        let w = shared.width as usize;
        let Scratch {
            stamp,
            visited,
            candidates,
            pixel,
            touched,
            ..
        } = scratch;
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

    /// Step 2 of [`View::render`]: the changed triangles' new pieces. Where nothing that changed
    /// shows, no hole opened, so a piece behind every committed depth of its tiles changes
    /// nothing.
    fn scan_new_pieces(&self, shared: &Shared, scratch: &mut Scratch) {
        let number = scratch.number;
        let reshade = number | RESHADE;
        let w = shared.width as usize;
        let Scratch {
            pieces: new_pieces,
            shows_now,
            stamp,
            first_piece,
            pixel,
            touched,
            ..
        } = scratch;
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
    }

    /// Step 3 of [`View::render`]: shade and compare; returns ΔE.
    fn shade_and_compare(
        &mut self,
        shared: &Shared,
        mesh: &Adjacency,
        scratch: &mut Scratch,
    ) -> i64 {
        let number = scratch.number;
        let Scratch {
            pieces: new_pieces,
            stamp,
            first_piece,
            reshade_at,
            reshading,
            touched,
            plane_cache,
            ..
        } = scratch;
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
                    let run = super::plane_run::Run::new(
                        &f.reshaded_x[run.clone()],
                        &f.reshaded_y[run.clone()],
                        &f.reshaded_target[run],
                    );
                    super::plane_run::sum_sq(&plane, &shared.encode, run)
                }
                _ => self.surface_run(shared, mesh, k, id, run),
            };
        }
        delta
    }
}
