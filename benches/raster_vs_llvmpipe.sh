#!/usr/bin/env bash
# Side by side, in one run: lodeval's CPU rasterizer and Mesa llvmpipe on the same 1M-triangle
# scene (torus, 20 Fibonacci views, 1024², Gouraud), 1 and 4 samples per pixel.
# Usage: bash benches/raster_vs_llvmpipe.sh   (from the repository root; needs moderngl, see the .py)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
echo "| renderer | triangles | size | samples | views | threads | ms/frame | frames/s | Mtri/s |"
echo "|---|---|---|---|---|---|---|---|---|"
target/release/lodeval bench raster --export "$dir" --json > "$dir/lodeval.json"
python3 - "$dir/lodeval.json" <<'PY'
import json, sys
for r in json.load(open(sys.argv[1])):
    cells = ["lodeval cpu", r["triangles"], r["size"], r["samples"], r["views"], r["threads"],
             f"{r['ms_per_frame']:.1f}", f"{r['frames_per_s']:.2f}", f"{r['mtri_per_s']:.1f}"]
    print("| " + " | ".join(str(c) for c in cells) + " |")
PY
python3 benches/llvmpipe_raster.py "$dir"
/usr/bin/time -f "lodeval peak RSS: %M KiB" target/release/lodeval bench raster --samples 4 --views 20 >/dev/null
