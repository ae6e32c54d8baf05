//! Position welding: the map from (seam-split) vertices back to distinct positions.
//!
//! Exact equality of coordinates, with −0 treated as +0. Indices of welded positions are assigned
//! in order of first appearance, so the map is deterministic and independent of hashing.

use std::collections::HashMap;

use glam::Vec3;

/// The bit pattern that identifies a position (−0 folded into +0).
fn key(p: Vec3) -> [u32; 3] {
    [
        (p.x + 0.0).to_bits(),
        (p.y + 0.0).to_bits(),
        (p.z + 0.0).to_bits(),
    ]
}

/// Returns `(weld, count)`: `weld[v]` is the welded index of vertex `v`, `count` the number of
/// distinct positions.
pub(crate) fn by_position(positions: &[Vec3]) -> (Vec<u32>, usize) {
    let mut first: HashMap<[u32; 3], u32> = HashMap::with_capacity(positions.len());
    let mut weld = Vec::with_capacity(positions.len());
    for &p in positions {
        let next = first.len() as u32;
        weld.push(*first.entry(key(p)).or_insert(next));
    }
    (weld, first.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seam_copies_share_a_welded_index_and_signed_zero_is_one_position() {
        let p = [
            Vec3::new(0.0, 1.0, 2.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(-0.0, 1.0, 2.0),
        ];
        let (weld, count) = by_position(&p);
        assert_eq!(weld, vec![0, 1, 0]);
        assert_eq!(count, 2);
    }
}
