#!/usr/bin/env python3
"""Make the metric oracles: image pairs and the values that reference implementations written by
others compute for them. lodeval's tests (tests/integration/oracles.rs) compare against these.

- FLIP: NVIDIA's reference implementation, PyPI package `flip-evaluator` 1.7 (the C++ code of
  NVlabs/flip with Python bindings), LDR mode, sRGB inputs, explicit pixels per degree.
- SSIM and PSNR: scikit-image 0.26 (`structural_similarity` with the Wang et al. 2004 settings:
  Gaussian weights, sigma 1.5, no sample-covariance correction, data range 1; and
  `peak_signal_noise_ratio` with data range 1).

Run from the repository root:  python3 reference/oracles/make_oracles.py
It renders two pairs with the lodeval binary (cargo build --release first), makes the others
from a fixed seed, writes PNGs under reference/oracles/{flip,ssim}/ and the values to
reference/oracles/values.json. FLIP error maps are stored as 16-bit grey PNGs (value * 65535,
quantisation error <= 7.7e-6, far below the 2e-4 per-pixel tolerance).

Needs: pip install flip-evaluator==1.7 scikit-image==0.26.0 pillow numpy
"""
import json
import os
import subprocess

import flip_evaluator
import numpy as np
import skimage
from PIL import Image
from skimage.metrics import peak_signal_noise_ratio, structural_similarity

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "reference", "oracles")
rng = np.random.default_rng(20261123)


def save_rgb(path, a):
    Image.fromarray(np.clip(np.round(a * 255), 0, 255).astype(np.uint8), "RGB").save(path)


def load_rgb(path):
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.float32) / 255.0


def smooth_noise(h, w, scale):
    """Band-limited noise: bilinear upsampling of a coarse random grid."""
    gh, gw = max(2, h // scale + 2), max(2, w // scale + 2)
    g = rng.random((gh, gw, 3))
    ys = np.linspace(0, gh - 1.001, h)
    xs = np.linspace(0, gw - 1.001, w)
    y0, x0 = ys.astype(int), xs.astype(int)
    ty, tx = (ys - y0)[:, None, None], (xs - x0)[None, :, None]
    a = g[y0][:, x0] * (1 - tx) + g[y0][:, x0 + 1] * tx
    b = g[y0 + 1][:, x0] * (1 - tx) + g[y0 + 1][:, x0 + 1] * tx
    return a * (1 - ty) + b * ty


def pairs():
    """(name, reference array, test array, ppd) for the synthetic pairs."""
    out = []
    # Random colour noise, test = reference + small noise (dense, every pixel differs).
    r = rng.random((64, 48, 3))
    out.append(("noise_64x48", r, np.clip(r + rng.normal(0, 0.05, r.shape), 0, 1), 67.0206))
    # Smooth gradients with a shifted edge (non-square, wide).
    h, w = 40, 130
    x = np.linspace(0, 1, w)[None, :, None] * np.ones((h, 1, 3))
    ref = x * np.array([1.0, 0.6, 0.2])
    test = ref.copy()
    test[:, 60:] = np.clip(test[:, 60:] + 0.15, 0, 1)
    out.append(("gradient_step_130x40", ref, test, 67.0206))
    # Tiny images, smaller than the filter kernels.
    out.append(("tiny_3x2", rng.random((2, 3, 3)), rng.random((2, 3, 3)), 67.0206))
    out.append(("tiny_1x1", np.array([[[0.2, 0.5, 0.9]]]), np.array([[[0.25, 0.4, 0.9]]]), 67.0206))
    # Chromatic change only (equal luminance is not enforced, but hue rotates).
    s = smooth_noise(80, 80, 16)
    out.append(("hue_shift_80", s, s[:, :, [1, 2, 0]], 67.0206))
    # Blur of detailed content at different viewing distances.
    d = rng.random((96, 96, 3)) ** 2
    blurred = (d + np.roll(d, 1, 0) + np.roll(d, 1, 1) + np.roll(np.roll(d, 1, 0), 1, 1)) / 4
    out.append(("blur_96_ppd67", d, blurred, 67.0206))
    out.append(("blur_96_ppd20", d, blurred, 20.0))
    out.append(("blur_96_ppd120", d, blurred, 120.0))
    # Identical images (must be exactly 0) and black versus white.
    s2 = smooth_noise(33, 17, 5)
    out.append(("identical_17x33", s2, s2.copy(), 67.0206))
    out.append(("black_white_16", np.zeros((16, 16, 3)), np.ones((16, 16, 3)), 67.0206))
    # Thin lines added (feature detector).
    base = np.full((70, 70, 3), 0.5)
    lines = base.copy()
    lines[::7, :, :] = 0.9
    out.append(("lines_70", base, lines, 67.0206))
    return out


def rendered_pairs():
    """A 1024² LOD-style pair rendered by lodeval: the Stanford bunny vs its 3k remesh."""
    exe = os.path.join(ROOT, "target", "release", "lodeval")
    res = []
    for name, model in [("bunny_1024_ref", "bunny/stanford-bunny.obj"), ("bunny_1024_test", "bunny/bunny_odedstein_3k.obj")]:
        path = os.path.join(OUT, "flip", name + ".png")
        subprocess.run([exe, "render", os.path.join(ROOT, "reference", "models", model), "-o", path,
                        "--size", "1024", "--view", "0", "-q"], check=True)
        res.append(path)
    return [("bunny_lod_1024", res[0], res[1], 67.0206)]


def main():
    values = {"generator": "reference/oracles/make_oracles.py",
              "flip_evaluator": "1.7", "scikit_image": skimage.__version__, "flip": [], "ssim": []}
    todo = []
    for name, ref, test, ppd in pairs():
        rp = os.path.join(OUT, "flip", name + "_ref.png")
        tp = os.path.join(OUT, "flip", name + "_test.png")
        save_rgb(rp, ref)
        save_rgb(tp, test)
        todo.append((name, rp, tp, ppd))
    todo += rendered_pairs()
    for name, rp, tp, ppd in todo:
        # Evaluate the PNG files as stored (8-bit), exactly what lodeval reads.
        ref, test = load_rgb(rp), load_rgb(tp)
        emap, mean32, _ = flip_evaluator.evaluate(ref, test, "LDR", inputsRGB=True, applyMagma=False,
                                                  computeMeanError=True, parameters={"ppd": ppd})
        emap = np.asarray(emap, dtype=np.float32).reshape(ref.shape[0], ref.shape[1])
        map_path = os.path.join(OUT, "flip", name + "_flipmap.png")
        Image.fromarray(np.round(np.clip(emap, 0, 1) * 65535).astype(np.uint16)).save(map_path)
        values["flip"].append({
            "name": name, "reference": os.path.relpath(rp, ROOT), "test": os.path.relpath(tp, ROOT),
            "ppd": ppd, "width": ref.shape[1], "height": ref.shape[0],
            "mean_f64": float(np.mean(emap.astype(np.float64))), "mean_reported_f32": float(mean32),
            "max": float(emap.max()), "map": os.path.relpath(map_path, ROOT),
        })
        # SSIM/PSNR on the same pairs where they are defined (7x7 minimum side for the 11-tap
        # Gaussian window is not required by skimage's gaussian mode, but sides >= 7 are).
        # SSIM on Rec. 709 luma of the sRGB-encoded values (lodeval's default), needs sides >= 11
        # for the cropped mean; PSNR on Rec. 709 luminance of linear values (lodeval's MSE).
        r64, t64 = ref.astype(np.float64), test.astype(np.float64)
        luma = lambda a: 0.2126 * a[..., 0] + 0.7152 * a[..., 1] + 0.0722 * a[..., 2]
        lin = lambda a: np.where(a <= 0.04045, a / 12.92, ((a + 0.055) / 1.055) ** 2.4)
        entry = {"name": name}
        if min(ref.shape[:2]) >= 11:
            entry["ssim_luma_srgb"] = float(structural_similarity(luma(r64), luma(t64), gaussian_weights=True, sigma=1.5,
                                                                  use_sample_covariance=False, data_range=1.0))
        if not np.array_equal(ref, test):
            entry["psnr_linear_luminance"] = float(peak_signal_noise_ratio(luma(lin(r64)), luma(lin(t64)), data_range=1.0))
        values["ssim"].append(entry)
        print(f"{name}: FLIP mean {values['flip'][-1]['mean_f64']:.6f}")
    with open(os.path.join(OUT, "values.json"), "w") as f:
        json.dump(values, f, indent=1)


if __name__ == "__main__":
    main()
