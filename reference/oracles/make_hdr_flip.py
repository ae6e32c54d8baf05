"""HDR-FLIP oracle: NVIDIA's flip-evaluator on a few linear EXR pairs, with the exposure range it
chose, for lodeval's `diff` on EXR inputs (src/metric/hdr_flip.rs).

    pip install flip-evaluator==1.7 OpenEXR==3.5.3 numpy
    python reference/oracles/make_hdr_flip.py

Writes reference/oracles/hdr/*.exr (32-bit float RGB, small) and reference/oracles/hdr_flip.json.
"""
import json
import os

import numpy as np
import OpenEXR
import flip_evaluator

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
OUT = os.path.join(HERE, "hdr")


def save_exr(path, rgb):
    rgb = rgb.astype(np.float32)
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    channels = {"RGB": rgb}
    with OpenEXR.File(header, channels) as f:
        f.write(path)


def load_exr(path):
    with OpenEXR.File(path) as f:
        return np.asarray(f.channels()["RGB"].pixels, dtype=np.float32)


def pairs():
    rng = np.random.default_rng(7)
    h, w = 48, 64
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    # A sky gradient from 0.05 to 20 with a sun of 400, and the same with the sun moved and dimmed.
    sky = np.stack([0.05 + 20 * x / w, 0.05 + 10 * x / w, 0.1 + 5 * y / h], axis=-1)
    sun = np.exp(-((x - 40) ** 2 + (y - 12) ** 2) / 8.0)[..., None] * 400.0
    sun2 = np.exp(-((x - 42) ** 2 + (y - 13) ** 2) / 8.0)[..., None] * 300.0
    yield "sky_sun", sky + sun, sky + sun2, 67.0206
    # Noise over four decades, against the same with 10 % multiplicative noise.
    base = 10 ** rng.uniform(-2, 2, size=(h, w, 1)) * np.array([1.0, 0.8, 0.6])
    yield "decades_noise", base, base * (1 + 0.1 * rng.standard_normal((h, w, 3))).clip(0), 40.0
    # A dim interior (median 0.02) with a bright window, against a blurred copy.
    room = np.full((h, w, 3), 0.02, np.float32)
    room[10:30, 20:44] = [30.0, 28.0, 25.0]
    k = np.ones(5) / 5
    blurred = room.copy()
    for axis in (0, 1):
        blurred = np.apply_along_axis(lambda v: np.convolve(v, k, mode="same"), axis, blurred)
    yield "room_window", room, blurred, 67.0206


def main():
    os.makedirs(OUT, exist_ok=True)
    out = {"generator": "reference/oracles/make_hdr_flip.py", "flip_evaluator": "1.7", "hdr": []}
    for name, ref, test, ppd in pairs():
        rp, tp = os.path.join(OUT, name + "_ref.exr"), os.path.join(OUT, name + "_test.exr")
        save_exr(rp, ref)
        save_exr(tp, test)
        # Evaluate what the files hold (half floats), as lodeval reads them.
        r, t = load_exr(rp), load_exr(tp)
        emap, mean, params = flip_evaluator.evaluate(r, t, "HDR", inputsRGB=False, applyMagma=False,
                                                     computeMeanError=True, parameters={"ppd": ppd})
        emap = np.asarray(emap, dtype=np.float64).reshape(r.shape[0], r.shape[1])
        out["hdr"].append({
            "name": name, "reference": os.path.relpath(rp, ROOT), "test": os.path.relpath(tp, ROOT),
            "ppd": ppd, "mean_f64": float(emap.mean()), "mean_reported": float(mean),
            "max": float(emap.max()),
            "start_exposure": float(params["startExposure"]),
            "stop_exposure": float(params["stopExposure"]),
            "num_exposures": int(params["numExposures"]),
        })
        print(name, out["hdr"][-1])
    with open(os.path.join(HERE, "hdr_flip.json"), "w") as f:
        json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
