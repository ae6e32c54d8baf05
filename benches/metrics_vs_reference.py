#!/usr/bin/env python3
"""Time the reference implementations on an image pair, the way `lodeval bench metrics` times
lodeval's: images already decoded, one warm-up, mean of RUNS runs. FLIP: NVIDIA's flip-evaluator
(C++ through Python bindings; its OpenMP threads follow OMP_NUM_THREADS). SSIM: scikit-image with
lodeval's settings on Rec. 709 luma of the sRGB values.

Usage: python3 benches/metrics_vs_reference.py REF.png TEST.png [RUNS]
"""
import sys
import time

import flip_evaluator
import numpy as np
from PIL import Image
from skimage.metrics import structural_similarity

ref = np.asarray(Image.open(sys.argv[1]).convert("RGB"), dtype=np.float32) / 255.0
test = np.asarray(Image.open(sys.argv[2]).convert("RGB"), dtype=np.float32) / 255.0
runs = int(sys.argv[3]) if len(sys.argv) > 3 else 5
luma = lambda a: (0.2126 * a[..., 0] + 0.7152 * a[..., 1] + 0.0722 * a[..., 2]).astype(np.float64)


def timed(f):
    f()
    start = time.perf_counter()
    for _ in range(runs):
        f()
    return (time.perf_counter() - start) * 1e3 / runs


flip_ms = timed(lambda: flip_evaluator.evaluate(ref, test, "LDR", inputsRGB=True, applyMagma=False,
                                                computeMeanError=True, parameters={"ppd": 67.0206}))
ssim_ms = timed(lambda: structural_similarity(luma(ref), luma(test), gaussian_weights=True, sigma=1.5,
                                              use_sample_covariance=False, data_range=1.0))
print(f"flip-evaluator 1.7 (C++): {flip_ms:.1f} ms per pair")
print(f"scikit-image SSIM: {ssim_ms:.1f} ms per pair")
