//! Shading the pixels a trial touches: the re-shaded runs, the per-piece plane cache, and the
//! Gouraud luminance of a piece at a pixel.

use super::*;

/// What the shading of a touched pixel whose plane is not cached reads and fills in: the
/// render's scratch (see [`View::shade_touched`]).
pub(super) struct ShadeRest<'a> {
    pub(super) number: u32,
    pub(super) stamp: &'a [u32],
    pub(super) new_pieces: &'a mut [(u32, Piece)],
    pub(super) first_piece: &'a mut [u32],
    pub(super) reshade_at: &'a mut [u32],
    pub(super) reshading: &'a mut Vec<PieceShading>,
    pub(super) plane_cache: &'a mut [PlaneSlot],
}

impl ShadeRest<'_> {
    /// The slot in `reshading` of piece `piece` of re-shaded triangle `t` (which has `pieces`
    /// pieces): the triangle's slots are made, all unknown, the first time the render asks.
    pub(super) fn reshading_slot(&mut self, t: usize, pieces: usize, piece: usize) -> usize {
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
pub(super) const PLANE_CACHE: usize = 64;

/// A cached luminance plane: piece `id`'s in the render numbered `number`.
#[derive(Debug, Clone, Copy)]
pub(super) struct PlaneSlot {
    pub(super) number: u32,
    pub(super) id: u32,
    pub(super) plane: LumaPlane,
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
    pub(super) fn get(&self, number: u32, id: u32) -> Option<&LumaPlane> {
        (self.number == number && self.id == id).then_some(&self.plane)
    }
}

/// Whether a pixel now showing piece `id` keeps its committed luminance: it showed that piece
/// before, and the piece's triangle (stamped `s`) is neither changed nor re-shaded in render
/// `number` (its corners and attributes are as committed).
#[inline(always)]
pub(super) fn keeps_committed(id: u32, old_shown: u32, s: u32, number: u32) -> bool {
    id == old_shown && s != number && s != (number | RESHADE)
}

/// Plane-cache slot of piece `id` (its triangle's low bits, mixed with the piece number).
#[inline(always)]
pub(super) fn plane_slot(id: u32) -> usize {
    ((id >> PIECE_BITS) ^ (id << 3)) as usize & (PLANE_CACHE - 1)
}

impl View {
    /// Σ (ŷ − y′)² over run `k` of the re-shaded pixels (`run` into the fills' pixels), which
    /// shows piece `id` of a per-pixel shaded triangle: its pixels' surfaces are worked out (and
    /// kept) unless the fills hold them for the triangle's present colours and UVs, then lit.
    pub(super) fn surface_run(
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
    pub(super) fn reshaded_shading(
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
    pub(super) fn reshaded_excess(
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
    pub(super) fn shade_touched(
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
}

/// A piece's geometry and the shading to use for it (a re-shaded triangle's comes from the
/// trial, not from the piece).
pub(super) struct ShadedPiece<'a> {
    pub(super) st: &'a SetupTri,
    pub(super) corners: &'a crate::raster::setup::Corners,
    pub(super) shading: &'a PieceShading,
}

/// Gouraud shading of source triangle `t` (one of its pieces) at screen point (x, y), as luminance.
pub(super) fn shade(
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
pub(super) fn surface(
    shared: &Shared,
    mesh: &Adjacency,
    t: u32,
    st: &SetupTri,
    corners: &crate::raster::setup::Corners,
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
pub(super) fn lit(
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
pub(super) fn corner_light(mesh: &Adjacency, light: &[(Vec3, Vec3)], t: u32) -> [(Vec3, Vec3); 3] {
    mesh.corners(t).map(|w| light[w as usize])
}

/// [`lit`] with the corners' terms at hand.
#[inline(always)]
pub(super) fn lit_by(shared: &Shared, l: [(Vec3, Vec3); 3], b: Vec3, albedo: Vec3) -> u16 {
    let d = l[0].0 * b.x + l[1].0 * b.y + l[2].0 * b.z;
    let s = l[0].1 * b.x + l[1].1 * b.y + l[2].1 * b.z;
    shared.luma(albedo * d + s)
}

/// The wedge attributes a triangle's [`surface`] depends on (colours and UVs), as bits.
pub(super) fn surface_key(mesh: &Adjacency, t: u32) -> [u32; 15] {
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
