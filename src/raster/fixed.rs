//! Sub-pixel fixed-point coordinates for the rasterizer.
//!
//! Screen positions are snapped to 1/256 pixel ([`Fx24_8`]: 24 integer bits, 8 fraction bits) so
//! that edge functions are evaluated exactly in integers: every sample is classified identically
//! for the two triangles sharing an edge, which is what makes the top-left rule watertight and the
//! output independent of evaluation order (ARCHITECTURE.md, "Determinism").
//!
//! Range: clipping keeps vertices within [`GUARD_BAND_PX`] of the viewport, so coordinates stay
//! below 2^15·2^8 = 2^23 in magnitude and an edge function (a difference of two products of such
//! numbers) below 2^48, well inside `i64`.

/// Fraction bits of [`Fx24_8`].
pub const SUBPIXEL_BITS: u32 = 8;
/// One pixel in [`Fx24_8`] units.
pub const ONE_PIXEL: i64 = 1 << SUBPIXEL_BITS;
/// How far outside the viewport (in pixels) geometry may reach before it is clipped; chosen so the
/// edge-function products cannot overflow (module docs).
pub const GUARD_BAND_PX: f32 = 8192.0;

/// A 24.8 fixed-point screen coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct Fx24_8(pub i32);

impl Fx24_8 {
    /// Round a pixel coordinate to the nearest 1/256 pixel (halves away from zero). Written out
    /// because `f32::round` is a libm call on baseline x86-64 and set-up calls this 3× per triangle.
    pub fn from_px(v: f32) -> Fx24_8 {
        let x = v * ONE_PIXEL as f32;
        Fx24_8((x + 0.5f32.copysign(x)) as i32)
    }
}
