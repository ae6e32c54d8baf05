#!/usr/bin/env python3
"""Make the ModelFest oracle: the 43 stimuli and the observers' detection thresholds.

ModelFest (Carney et al. 1999, "Development of an image/threshold database for designing and
testing human vision models", Proc. SPIE 3644; analysed in Watson & Ahumada 2005, "A standard
model for foveal detection of spatial contrast", Journal of Vision 5(9):6) is the standard set of
foveal detection thresholds for spatial vision models: 43 achromatic stimuli, 256 x 256 pixels at
120 pixels per degree (2.133 deg square), shown on a uniform 30 cd/m^2 field, thresholds of 16
observers in 4 sessions each at the 84 %-correct point of a two-interval forced choice, given as
log10 contrast sensitivity (log10 of 1 / peak contrast).

Source: the PyPI package stimupy 1.2.0, whose stimupy.papers.modelfest regenerates every
stimulus (the noise and natural-scene images ship with it as TIFFs) and ships the threshold table
(modelfest_data.csv: one row per observer, 43 x 4 session columns in stimulus order).

Note: stimupy's own per-stimulus accessor for Noise35 points at the columns of stimulus 43
(v = 169 instead of 137). This script reads the table itself, by position (stimulus i has
columns 4(i-1)+1 .. 4(i-1)+4), so Noise35 gets its own thresholds.

Writes, beside this script:
- NN-Name.png: the contrast pattern s(x) in [-1, 1] (luminance = L0 * (1 + c * s)) as a 16-bit grey
  PNG of round((s + 1) / 2 * 65535): quantisation step 3.1e-5 in s, below 1 % of the lowest
  threshold contrast times the smallest pattern values that matter.
- thresholds.csv: id, name, observed (mean over observers of each observer's mean over
  sessions, log10 sensitivity), sd (standard deviation over the 16 observer means), observers,
  file.
- observers.csv: every observer's mean per stimulus (for the single-observer comparison).

Run from anywhere:  python3 reference/oracles/modelfest/make_modelfest.py
Needs: pip install stimupy==1.2.0 numpy pillow
"""
import csv
import os
import warnings

import numpy as np
import stimupy
import stimupy.papers.modelfest as mf
from PIL import Image

OUT = os.path.dirname(os.path.abspath(__file__))
assert stimupy.__version__ == "1.2.0", stimupy.__version__


def main():
    warnings.filterwarnings("ignore")  # stimupy warns about rounding 2.1333 deg to whole pixels
    stims = mf.gen_all(ppd=mf.PPD)
    names = list(stims.keys())
    assert len(names) == 43, names
    table = mf.df.iloc[:, 1:].to_numpy(float)
    assert table.shape == (16, 172), table.shape
    per_observer = table.reshape(16, 43, 4).mean(axis=2)
    observed = per_observer.mean(axis=0)
    sd = per_observer.std(axis=0, ddof=1)
    rows = []
    for i, name in enumerate(names):
        img = np.asarray(stims[name]["img"], dtype=np.float64)
        assert img.shape == (256, 256), (name, img.shape)
        s = np.clip(2.0 * img - 1.0, -1.0, 1.0)
        q = np.round((s + 1.0) / 2.0 * 65535.0).astype(np.uint16)
        file = f"{i + 1:02d}-{name}.png"
        Image.fromarray(q).save(os.path.join(OUT, file))
        rows.append((i + 1, name, observed[i], sd[i], 16, file))
    with open(os.path.join(OUT, "thresholds.csv"), "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["id", "name", "observed", "sd", "observers", "file"])
        for r in rows:
            w.writerow([r[0], r[1], f"{r[2]:.4f}", f"{r[3]:.4f}", r[4], r[5]])
    with open(os.path.join(OUT, "observers.csv"), "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["observer"] + [f"{i + 1:02d}" for i in range(43)])
        for o, name in enumerate(mf.participants):
            w.writerow([name] + [f"{v:.4f}" for v in per_observer[o]])
    rms = np.sqrt(((per_observer - observed) ** 2).mean())
    print(f"wrote 43 stimuli; a single observer's mean differs from the group's by {rms:.3f} log10 RMS")


if __name__ == "__main__":
    main()
