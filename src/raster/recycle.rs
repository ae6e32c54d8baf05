//! Recycled frame channels: a dropped [`Frame`](super::Frame) gives its large channel buffers back
//! here, and the next render of the same size takes them instead of allocating.
//!
//! Why: a 1024² frame is 24 MB of channels. Allocated afresh per render, that memory comes from
//! the kernel as new pages (glibc returns big freed blocks to it), and faulting them in cost more
//! than a third of a 10 000-triangle frame's time (42.7 → 26.2 ms in alternating runs; see
//! results/BENCHMARKS.md). Rendering many views in a loop — what `eval` and `bench` do — frees one
//! frame and allocates the next of the same size, so a few kept buffers remove the faults.
//!
//! The sort-last path's per-worker key buffers (`sort_last.rs`, 8 MB each at 1024²) are kept
//! the same way.
//!
//! A recycled buffer keeps its old values: only callers that overwrite every entry may take one
//! (`draw` in `mod.rs` does: every pixel belongs to exactly one tile, which writes it; the sort-last
//! scan fills a kept key buffer before using it). Outputs therefore never depend on what the
//! pool holds. The pool is bounded ([`KEEP_FRAMES`] frames' worth of buffers, each at least
//! [`MIN_LEN`] entries).

use std::sync::Mutex;

use glam::Vec3;

/// Frames' worth of buffers kept (two frames — an original and its LOD — in flight, twice): at
/// most 4 × 24 MB at 1024².
const KEEP_FRAMES: usize = 4;
/// Smaller buffers are not kept: they are not where the page faults are.
const MIN_LEN: usize = 1 << 16;

/// Kept buffers by element type.
pub(crate) struct Pool {
    color: Vec<Vec<Vec3>>,
    scalar: Vec<Vec<f32>>,
    id: Vec<Vec<u32>>,
    key: Vec<Vec<u64>>,
}

static POOL: Mutex<Pool> = Mutex::new(Pool::new());

/// Element types the pool keeps.
pub(crate) trait Recyclable: Copy + Send + Sync + 'static {
    /// Channels of this type in a frame.
    const PER_FRAME: usize;
    /// This type's list in the pool.
    fn list(pool: &mut Pool) -> &mut Vec<Vec<Self>>;
}

impl Recyclable for Vec3 {
    const PER_FRAME: usize = 1; // colour
    fn list(pool: &mut Pool) -> &mut Vec<Vec<Self>> {
        &mut pool.color
    }
}

impl Recyclable for f32 {
    const PER_FRAME: usize = 2; // depth, coverage
    fn list(pool: &mut Pool) -> &mut Vec<Vec<Self>> {
        &mut pool.scalar
    }
}

impl Recyclable for u32 {
    const PER_FRAME: usize = 1; // triangle id
    fn list(pool: &mut Pool) -> &mut Vec<Vec<Self>> {
        &mut pool.id
    }
}

impl Recyclable for u64 {
    // The sort-last workers' depth-and-id buffers (`sort_last.rs`): one per worker, two on the
    // machines CI runs on.
    const PER_FRAME: usize = 2;
    fn list(pool: &mut Pool) -> &mut Vec<Vec<Self>> {
        &mut pool.key
    }
}

impl Pool {
    const fn new() -> Pool {
        Pool {
            color: Vec::new(),
            scalar: Vec::new(),
            id: Vec::new(),
            key: Vec::new(),
        }
    }

    /// A kept buffer of exactly `n` entries, if any.
    fn take<T: Recyclable>(&mut self, n: usize) -> Option<Vec<T>> {
        let list = T::list(self);
        let i = list.iter().position(|v| v.len() == n)?;
        Some(list.swap_remove(i))
    }

    /// Keep `buffer` unless it is small; when full, the oldest kept buffer goes (a loop that
    /// changes image size soon holds only buffers of the new size).
    fn give<T: Recyclable>(&mut self, buffer: Vec<T>) {
        if buffer.len() < MIN_LEN {
            return;
        }
        let list = T::list(self);
        if list.len() == KEEP_FRAMES * T::PER_FRAME {
            list.remove(0);
        }
        list.push(buffer);
    }
}

/// Run `f` on the shared pool. A panic elsewhere while the lock was held leaves only spare
/// buffers behind, so a poisoned lock is used as it is.
fn with_pool<R>(f: impl FnOnce(&mut Pool) -> R) -> R {
    let mut guard = POOL.lock().unwrap_or_else(|e| e.into_inner());
    f(&mut guard)
}

/// A buffer of exactly `n` entries whose contents the caller will overwrite entirely: a kept one
/// (old contents) if there is one of that length, otherwise `n` copies of `fill`.
pub(crate) fn take<T: Recyclable>(n: usize, fill: T) -> Vec<T> {
    take_kept(n).unwrap_or_else(|| filled(n, fill))
}

/// A kept buffer of exactly `n` entries (old contents), if there is one. Unlike [`take`] it
/// never starts parallel work, so a caller may hold a lock across it.
pub(crate) fn take_kept<T: Recyclable>(n: usize) -> Option<Vec<T>> {
    with_pool(|p| p.take(n))
}

/// Give `buffer` back for a later [`take`].
pub(crate) fn give<T: Recyclable>(buffer: Vec<T>) {
    with_pool(|p| p.give(buffer));
}

/// `n` copies of `value`, written in parallel (a serial fill of the 12 MB colour channel of a
/// 1024² frame was a visible share of a frame's time).
fn filled<T: Copy + Send + Sync>(n: usize, value: T) -> Vec<T> {
    use rayon::prelude::*;
    let mut out = Vec::with_capacity(n);
    out.par_extend(rayon::iter::repeat_n(value, n));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_kept_buffer_comes_back_for_its_length_only() {
        let mut pool = Pool::new();
        let n = MIN_LEN + 5;
        let mut v = vec![7u32; n];
        v[0] = 42;
        pool.give(v);
        assert!(
            pool.take::<u32>(n + 1).is_none(),
            "other lengths are not handed out"
        );
        assert!(
            pool.take::<f32>(n).is_none(),
            "other element types are not handed out"
        );
        let back = pool.take::<u32>(n).expect("kept");
        assert_eq!(
            back[0], 42,
            "handed out again with the contents it was left with"
        );
        assert!(pool.take::<u32>(n).is_none(), "and only once");
    }

    #[test]
    fn small_buffers_are_not_kept_and_the_pool_is_bounded() {
        let mut pool = Pool::new();
        pool.give(vec![0.0f32; 16]);
        assert!(pool.take::<f32>(16).is_none());
        let keep = KEEP_FRAMES * f32::PER_FRAME;
        for k in 0..keep + 3 {
            pool.give(vec![0.0f32; MIN_LEN + k]);
        }
        assert_eq!(pool.scalar.len(), keep);
        // The oldest went first.
        assert!(pool.take::<f32>(MIN_LEN).is_none());
        assert!(pool.take::<f32>(MIN_LEN + keep + 2).is_some());
    }

    #[test]
    fn a_render_on_recycled_garbage_equals_one_on_fresh_buffers() {
        use crate::raster::RenderScene;
        use crate::raster::{RenderSettings, SamplePattern, Shading, render};
        use crate::scene::Rig;
        use std::sync::Arc;
        // A size no other test renders at, so no other thread takes or gives these buffers.
        let (w, h) = (263, 257);
        let n = (w * h) as usize;
        let scene = RenderScene::of(Arc::new(crate::mesh::shapes::icosphere(3)));
        let camera = Rig::Dodecahedron.cameras(scene.mesh(), 1.0)[4];
        let drain = || {
            while with_pool(|p| {
                let found = p.take::<Vec3>(n).is_some() | p.take::<f32>(n).is_some();
                found | p.take::<u32>(n).is_some() | p.take::<u64>(n).is_some()
            }) {}
        };
        // Four samples per pixel (tiles) and one (sort-last, which also takes key buffers).
        for samples in [SamplePattern::Rotated(2), SamplePattern::Ordered(1)] {
            let mut settings = RenderSettings::DEFAULT;
            (settings.width, settings.height, settings.shading) = (w, h, Shading::Phong);
            settings.samples = samples;
            drain();
            let fresh = render(&scene, &camera, &settings).unwrap();
            drain();
            for _ in 0..2 {
                give(vec![Vec3::splat(f32::NAN); n]);
                give(vec![f32::NAN; n]);
                give(vec![f32::NAN; n]);
                give(vec![0xDEAD_BEEFu32; n]);
                // Keys that would beat every triangle if they were not cleared.
                give(vec![0u64; n]);
            }
            assert_eq!(
                render(&scene, &camera, &settings).unwrap(),
                fresh,
                "{samples:?}"
            );
        }
    }

    #[test]
    fn fresh_buffers_are_filled() {
        // A length no render uses, so nothing kept can be handed out here.
        let n = MIN_LEN + 12_347;
        assert_eq!(take(n, 3u32), vec![3u32; n]);
    }
}
