#!/usr/bin/env python3
"""FLIP's weighted percentiles (weighted median, 1st and 3rd weighted quartiles) for every FLIP
oracle pair in values.json, from NVIDIA's reference command-line tool (`flip`, PyPI package
flip-evaluator 1.7), written to flip_weighted.json.

The tool pools the error map into a 100-bucket histogram over [0, 1], weights each bucket by its
centre value, and interpolates inside the bucket where the weighted fraction is reached. It prints
6 decimals, which bounds how closely any comparison can agree.

Needs: pip install flip-evaluator==1.7. Run from the repository root:
    python3 reference/oracles/make_weighted.py
"""
import csv
import json
import os
import subprocess
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    values = json.load(open(os.path.join(HERE, "values.json")))
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for e in values["flip"]:
            path = os.path.join(tmp, e["name"] + ".csv")
            subprocess.run(["flip", "-r", e["reference"], "-t", e["test"], "-ppd", str(e["ppd"]),
                            "-v", "0", "-c", path], check=True, capture_output=True)
            row = next(csv.DictReader(open(path)))
            out.append({"name": e["name"], "ppd": e["ppd"],
                        "weighted_median": float(row["Weighted median"]),
                        "weighted_q1": float(row["1st weighted quartile"]),
                        "weighted_q3": float(row["3rd weighted quartile"])})
            print(e["name"], out[-1])
    with open(os.path.join(HERE, "flip_weighted.json"), "w") as f:
        json.dump({"generator": "reference/oracles/make_weighted.py", "flip_evaluator": "1.7",
                   "pairs": out}, f, indent=1)


if __name__ == "__main__":
    main()
