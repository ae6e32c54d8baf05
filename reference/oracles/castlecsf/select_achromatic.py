"""Select the achromatic, static, foveal detection thresholds from castleCSF's aggregated data.

Input: castleCSF's `data/` folder (GitHub gfxdisp/castleCSF, commit f4b0b72, MIT licence, see
LICENSE here): data_aggregated.csv, color_directions.csv, backgrounds.csv, datasets.json.
Output: achromatic.csv beside this script, one row per stimulus condition.

Rule: a row is kept when its dataset is one of the spatial-frequency x luminance x area datasets
castleCSF's authors fit in their "comparison-1" (below), its temporal frequency is 0, its
eccentricity is 0, and its modulation direction in LMS lies within 8.1 degrees of the background's
own LMS direction (cos >= 0.99): a luminance modulation, which an achromatic model can be held to.
That keeps hdr_csf's, hdr_csf_disc's, colorfest's and kim2013's achromatic directions (0.9992,
0.9992, 0.9992, 0.9905) and drops the near-achromatic colour directions (colorfest 7 and 8: 0.988
and 0.982; kim2013 C7: 0.983). For an achromatic modulation, castleCSF's cone contrast is the
Michelson luminance contrast (its ModelFest rows equal ModelFest's published sensitivities).

Usage: python3 select_achromatic.py PATH/TO/castleCSF/data
"""

import csv
import json
import math
import sys
from pathlib import Path

DATASETS = [
    "hdr_csf", "hdrvdp_csf", "rovamo1993", "kim2013", "modelfest", "colorfest",
    "hdr_csf_disc", "virsu1979", "wright1983",
]
MIN_COS = 0.99


def main(src: Path) -> None:
    directions = {r["col_dir_id"]: r for r in csv.DictReader(open(src / "color_directions.csv"))}
    backgrounds = {r["bkg_id"]: r for r in csv.DictReader(open(src / "backgrounds.csv"))}
    meta = json.load(open(src / "datasets.json"))["datasets"]
    out = []
    for r in csv.DictReader(open(src / "data_aggregated.csv")):
        if r["dataset"] not in DATASETS:
            continue
        if float(r["t_frequency"]) != 0 or float(r["eccentricity"]) != 0:
            continue
        d = [float(directions[r["col_dir_id"]][k + "_delta"]) for k in "LMS"]
        b = [float(backgrounds[r["bkg_id"]][k]) for k in "LMS"]
        cos = sum(x * y for x, y in zip(d, b)) / math.sqrt(
            sum(x * x for x in d) * sum(y * y for y in b))
        if cos < MIN_COS:
            continue
        aperture = meta[r["dataset"]].get("aperture", "gauss")
        out.append({
            "dataset": r["dataset"],
            "stimulus": r["stimulus"],
            "aperture": aperture,
            "luminance": r["luminance"],
            "frequency": r["s_frequency"],
            "sigma": r["ge_sigma"],
            "area": r["area"],
            "orientation": r["orientation"],
            "log_sensitivity": f"{-float(r['log_cone_contrast']):.6f}",
        })
    out.sort(key=lambda r: (r["dataset"], float(r["luminance"]), float(r["frequency"]),
                            float(r["area"]), float(r["orientation"])))
    with open(Path(__file__).with_name("achromatic.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(out[0].keys()))
        w.writeheader()
        w.writerows(out)
    print(len(out), "rows")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
