#!/usr/bin/env python3
"""Two lodeval builds against each other, in alternating rounds.

The 2-core VM these benchmarks run on changes speed by up to 1.6x within an hour (other tenants of
the host), more than most changes are worth. Runs of one build and then the other measure the
drift, not the change. Here every round runs both builds back to back, the order alternating from
round to round, and the figure is the median of the per-round ratios (B over A), with their
geometric mean and range: the drift between rounds cancels, the drift within a round averages out
over the rounds. This is how the optimizer's and the QEM engine's changes in results/BENCHMARKS.md
are measured since the sixteenth session.

    python3 benches/ab_builds.py optimize BIN_A BIN_B [--rounds 10] [--evals 20000] [--threads 2]
    python3 benches/ab_builds.py simplify BIN_A BIN_B [--rounds 6] [--runs 3]

`optimize`: the image-driven optimizer's steady rate (evaluations per second from the energy CSV,
the set-up left out) on the shipped bunny and its 1 400-triangle QEM LOD, as `lodeval bench
optimize` measures it. `simplify`: the best of `--runs` runs of each simplifier at 50, 10 and 1 %
of the bunny (`lodeval bench simplify --json`, one thread), as seconds (lower is better).

Only the standard library; the builds are any two lodeval binaries (e.g. `git worktree add` the
old commit and `cargo build --release` there).
"""

import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
BUNNY = os.path.join(HERE, "..", "reference", "models", "bunny", "stanford-bunny.obj")


def run(cmd):
    out = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if out.returncode != 0:
        sys.exit(f"{' '.join(cmd)} exited with {out.returncode}:\n{out.stderr.strip()}")
    return out.stdout


def optimize_rate(binary, lod, evals, threads, tmp):
    """Evaluations per second after the set-up (first to last row of the energy CSV)."""
    energy = os.path.join(tmp, "energy.csv")
    run([binary, "optimize", BUNNY, lod, "-o", os.path.join(tmp, "out.obj"), "--evals",
         str(evals), "--threads", str(threads), "--energy-csv", energy, "--quiet"])
    with open(energy, newline="") as f:
        rows = list(csv.DictReader(f))
    seconds = float(rows[-1]["seconds"]) - float(rows[0]["seconds"])
    return {"evaluations/s": evals / seconds}


def simplify_seconds(binary, runs, tmp):
    """Best seconds of each simplifier and ratio."""
    rows = json.loads(run([binary, "bench", "simplify", BUNNY, "--threads", "1", "--runs",
                           str(runs), "--json", "--quiet"]))
    return {f"{r['method']} {r['ratio']:g} s": r["seconds"] for r in rows}


def summary(label, a, b):
    ratios = [y / x for x, y in zip(a, b)]
    geo = math.exp(sum(math.log(r) for r in ratios) / len(ratios))
    print(f"{label:>24}: A median {statistics.median(a):.5g}, B median {statistics.median(b):.5g}; "
          f"B/A median {statistics.median(ratios):.3f}, geometric mean {geo:.3f}, "
          f"range {min(ratios):.3f}-{max(ratios):.3f} ({len(ratios)} rounds)")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("what", choices=["optimize", "simplify"])
    p.add_argument("a", help="build A (the reference)")
    p.add_argument("b", help="build B (the change)")
    p.add_argument("--rounds", type=int)
    p.add_argument("--evals", type=int, default=20000)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--runs", type=int, default=3)
    args = p.parse_args()
    rounds = args.rounds or (10 if args.what == "optimize" else 6)
    with tempfile.TemporaryDirectory() as tmp:
        if args.what == "optimize":
            # One LOD for both builds (A's), so both optimize the same input.
            lod = os.path.join(tmp, "lod.obj")
            run([args.a, "simplify", BUNNY, "-o", lod, "--method", "qem", "--triangles", "1400"])
            measure = lambda binary: optimize_rate(binary, lod, args.evals, args.threads, tmp)
        else:
            measure = lambda binary: simplify_seconds(binary, args.runs, tmp)
        results = {"a": [], "b": []}
        for r in range(rounds):
            order = ["a", "b"] if r % 2 == 0 else ["b", "a"]
            for which in order:
                results[which].append(measure(getattr(args, which)))
            line = ", ".join(f"{k} {results['a'][-1][k]:.5g} -> {results['b'][-1][k]:.5g}"
                             for k in results["a"][-1])
            print(f"round {r + 1}: {line}", flush=True)
        for key in results["a"][0]:
            summary(key, [x[key] for x in results["a"]], [x[key] for x in results["b"]])


if __name__ == "__main__":
    main()
