#!/usr/bin/env bash
# Side by side, in one run: lodeval's CPU rasterizer and Mesa llvmpipe on the same 1M-triangle
# scene (torus, 20 Fibonacci views, 1024², 1 and 4 samples per pixel).
#   bash benches/raster_vs_llvmpipe.sh          Gouraud (per-vertex Blinn–Phong) on both
#   bash benches/raster_vs_llvmpipe.sh pbr      lodeval's pbr model on both (llvmpipe runs the
#                                               same BRDF and image-based light in GLSL), and
#                                               lodeval's Gouraud beside it for the pbr/Gouraud
#                                               ratio
# From the repository root; needs moderngl (see benches/llvmpipe_raster.py).
set -euo pipefail
cd "$(dirname "$0")/.."
shading="${1:-gouraud}"
cargo build --release --quiet
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
echo "| renderer | triangles | size | samples | views | threads | ms/frame | frames/s | Mtri/s |"
echo "|---|---|---|---|---|---|---|---|---|"
rows() {
  python3 - "$1" "$2" <<'PY'
import json, sys
for r in json.load(open(sys.argv[1])):
    cells = [f"lodeval cpu {sys.argv[2]}", r["triangles"], r["size"], r["samples"], r["views"],
             r["threads"], f"{r['ms_per_frame']:.1f}", f"{r['frames_per_s']:.2f}", f"{r['mtri_per_s']:.1f}"]
    print("| " + " | ".join(str(c) for c in cells) + " |")
PY
}
if [ "$shading" = pbr ]; then
  target/release/lodeval bench raster --shading gouraud --json -q > "$dir/gouraud.json"
  rows "$dir/gouraud.json" gouraud
fi
target/release/lodeval bench raster --shading "$shading" --export "$dir" --json -q > "$dir/lodeval.json"
rows "$dir/lodeval.json" "$shading"
python3 benches/llvmpipe_raster.py "$dir" --shading "$shading"
/usr/bin/time -f "lodeval peak RSS: %M KiB" target/release/lodeval bench raster --samples 4 --views 20 --shading "$shading" -q >/dev/null
