//! Stage 0 of the VDP: a uniform margin around each image, so that a verdict does not depend on
//! how tightly the image was cropped.
//!
//! The CSF filter (`filter.rs`) works on the image's mirrored extension and removes its mean, and
//! the pyramid (`bands.rs`) mirrors at the borders. On a tight crop both put mirror copies of a
//! change right next to it and take the change's own low frequencies away with the mean: an 8 px
//! disc at 60 pixels per degree needed twice the contrast in a crop of its own size that it needs
//! on a large field (0.064 against 0.031), and the distance search's probes, which are crops
//! around the object, called LODs invisible at sizes where a larger crop saw them.
//!
//! The fix is the one a display gives the eye: the image sits in a surround. Each image gains a
//! margin of [`MARGIN_DEG`] degrees on every side, filled with the median of its own outermost
//! ring of pixels (the background, for a render; robust to a change that touches a few border
//! pixels), every stage runs on the padded field, the pooled sum covers it (a filtered change
//! spreads into the surround, and would in a larger crop too), and the per-pixel maps are cropped
//! back. Two images that share their border get the same surround, so the padding adds no
//! difference of its own. Measured (`tests/integration/vdp.rs`, padding test): thresholds of
//! discs from 8 to 128 px agree between crops of 1× and 3× their size to within 2 %.

use super::bands::Plane;

/// The surround on each side, in degrees of visual angle. Decision: measured, not derived — the
/// threshold of a disc stops changing with the crop once the mirror copies are about a degree
/// away (the CSF has little sensitivity below ½ cycle per degree).
pub const MARGIN_DEG: f64 = 1.0;

/// The margin in pixels at `ppd` pixels per degree.
pub(crate) fn margin(ppd: f64) -> usize {
    (MARGIN_DEG * ppd).ceil() as usize
}

/// The median of the outermost ring of `p`'s pixels.
fn border_median(p: &Plane) -> f32 {
    let (w, h) = (p.w, p.h);
    let mut ring: Vec<f32> = if w <= 2 || h <= 2 {
        p.v.clone()
    } else {
        let rows = p.v[..w].iter().chain(&p.v[(h - 1) * w..]);
        let sides = (1..h - 1).flat_map(|y| [p.v[y * w], p.v[y * w + w - 1]]);
        rows.copied().chain(sides).collect()
    };
    let mid = ring.len() / 2;
    *ring.select_nth_unstable_by(mid, f32::total_cmp).1
}

/// `p` with `m` pixels of its border median on every side.
pub(crate) fn pad(p: &Plane, m: usize) -> Plane {
    if m == 0 {
        return p.clone();
    }
    let (w, h) = (p.w + 2 * m, p.h + 2 * m);
    let mut v = vec![border_median(p); w * h];
    for (y, row) in p.v.chunks(p.w).enumerate() {
        v[(y + m) * w + m..][..p.w].copy_from_slice(row);
    }
    Plane { w, h, v }
}

/// The `w × h` window at offset (`m`, `m`) of a map of the padded size.
pub(crate) fn crop(padded: &[f32], w: usize, h: usize, m: usize) -> Vec<f32> {
    let pw = w + 2 * m;
    (0..h)
        .flat_map(|y| padded[(y + m) * pw + m..][..w].iter().copied())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pad_then_crop_gives_the_image_back_and_the_surround_is_the_border_median() {
        let v: Vec<f32> = (0..12).map(|i| i as f32).collect();
        let p = Plane { w: 4, h: 3, v };
        let q = pad(&p, 2);
        assert_eq!((q.w, q.h), (8, 7));
        assert_eq!(crop(&q.v, 4, 3, 2), p.v);
        // Ring: 0 1 2 3 | 8 9 10 11 | 4 7 → sorted 0 1 2 3 4 7 8 9 10 11, element 5 is 7.
        assert_eq!(q.v[0], 7.0);
        assert_eq!(q.v[q.v.len() - 1], 7.0);
    }
}
