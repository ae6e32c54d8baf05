"""PSNR oracle for lodeval's `psnr` (8-bit sRGB, all three channels): scikit-image's
`peak_signal_noise_ratio` on the stored 8-bit PNG pairs of `values.json` (data_range 255, the
mean over every pixel and channel), which is also what ffmpeg's psnr filter and idiff report.

    pip install scikit-image==0.26.0 pillow numpy
    python reference/oracles/make_psnr_srgb8.py

Writes reference/oracles/psnr_srgb8.json. Identical pairs are left out (their PSNR is infinite in
scikit-image; lodeval reports its 100 dB ceiling).
"""
import json
import os

import numpy as np
import skimage
from PIL import Image
from skimage.metrics import peak_signal_noise_ratio

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def main():
    with open(os.path.join(HERE, "values.json")) as f:
        values = json.load(f)
    out = {"generator": "reference/oracles/make_psnr_srgb8.py", "scikit_image": skimage.__version__,
           "psnr_srgb8": []}
    for entry in values["flip"]:
        ref = np.asarray(Image.open(os.path.join(ROOT, entry["reference"])).convert("RGB"))
        test = np.asarray(Image.open(os.path.join(ROOT, entry["test"])).convert("RGB"))
        if np.array_equal(ref, test):
            continue
        psnr = peak_signal_noise_ratio(ref, test, data_range=255)
        out["psnr_srgb8"].append({"name": entry["name"], "reference": entry["reference"],
                                  "test": entry["test"], "psnr_db": float(psnr)})
        print(f"{entry['name']}: {psnr:.6f} dB")
    with open(os.path.join(HERE, "psnr_srgb8.json"), "w") as f:
        json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
