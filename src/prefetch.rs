//! Software prefetch hints, for the hot loops whose next memory accesses are known before they
//! happen but are too scattered for the hardware prefetcher (the image-driven optimizer's pixel
//! and bucket gathers, the edge-collapse engine's ring of re-evaluated edges).

/// Ask for the cache line of `v[i]`, if there is one.
#[inline]
pub(crate) fn prefetch_at<T>(v: &[T], i: u32) {
    if let Some(x) = v.get(i as usize) {
        prefetch(x);
    }
}

/// Ask for the cache line holding `x`.
#[inline]
pub(crate) fn prefetch<T>(x: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is a hint and never faults.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch(x as *const i8, _MM_HINT_T0)
    };
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}
