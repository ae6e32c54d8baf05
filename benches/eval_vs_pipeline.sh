#!/usr/bin/env bash
# Side by side, in one run: `lodeval eval` and the pipeline a user would script for the same
# work (benches/pipeline_peer.py: Mesa llvmpipe renders through moderngl, NVIDIA's flip-evaluator,
# scikit-image's SSIM and PSNR) on the demo's image pairs — the bunny and Spot, meshoptimizer's
# LODs at 50/25/10/5/2 %, 20 dodecahedron views at 512², 4 samples per pixel — three rounds in
# turns. lodeval runs the same metrics (FLIP, SSIM, PSNR) with nothing else (no VDP, no distances,
# no images, no geometric error); the full demo (`configs/demo.toml`) is timed once beside them.
# Usage: bash benches/eval_vs_pipeline.sh [ROUNDS]   (from the repository root; needs the
# packages listed in benches/pipeline_peer.py)
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-3}
cargo build --release --quiet
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
lods=()
for m in bunny/stanford-bunny spot/spot_mtl; do
  n=$(basename "$m")
  target/release/lodeval simplify "reference/models/$m.obj" -o "$dir/$n.obj" --method meshopt \
    --chain 0.5,0.25,0.1,0.05,0.02 >/dev/null
  files=$(printf "$dir/$n-r%s.obj," 50 25 10 5 2)
  lods+=("$PWD/reference/models/$m.obj:${files%,}")
done
{
  echo 'out = "out"'
  echo 'metrics = ["flip", "ssim", "psnr"]'
  echo 'geometry_samples = 0'
  echo '[render]'
  echo 'size = 512'
  echo 'samples = 4'
  echo 'rig = "dodecahedron"'
  echo '[distance]'
  echo 'enabled = false'
  echo '[images]'
  echo 'heatmaps = "none"'
  echo 'contact_sheets = false'
  for spec in "${lods[@]}"; do
    orig=${spec%%:*}
    echo '[[asset]]'
    echo "name = \"$(basename "$orig" .obj)\""
    echo "mesh = \"$orig\""
    printf 'lods = ['
    IFS=, read -ra files <<<"${spec#*:}"
    for f in "${files[@]}"; do printf '{ mesh = "%s" }, ' "$f"; done
    echo ']'
  done
} >"$dir/peer.toml"
echo "| round | lodeval eval (FLIP, SSIM, PSNR) s | scripted llvmpipe + flip-evaluator + scikit-image s | pairs | ratio |"
echo "|---|---|---|---|---|"
for r in $(seq 1 "$rounds"); do
  rm -rf "$dir/out"
  t0=$(date +%s.%N)
  target/release/lodeval eval "$dir/peer.toml" --quiet >/dev/null
  t1=$(date +%s.%N)
  peer=$(python3 benches/pipeline_peer.py "${lods[@]}")
  python3 - "$t0" "$t1" "$peer" "$r" <<'PY'
import json, sys
t0, t1, peer, r = float(sys.argv[1]), float(sys.argv[2]), json.loads(sys.argv[3]), sys.argv[4]
ours = t1 - t0
print(f"| {r} | {ours:.1f} | {peer['seconds']:.1f} (render {peer['stages']['render']:.1f}, "
      f"FLIP {peer['stages']['flip']:.1f}, SSIM {peer['stages']['ssim']:.1f}, PSNR "
      f"{peer['stages']['psnr']:.1f}) | {peer['pairs']} | {peer['seconds'] / ours:.1f}× |")
PY
done
t0=$(date +%s.%N)
target/release/lodeval eval configs/demo.toml --quiet --out "$dir/demo" >/dev/null
t1=$(date +%s.%N)
python3 -c "import sys; print(f'full demo (every metric, the VDP, distances, heat maps, sheets, geometric error): {float(sys.argv[2]) - float(sys.argv[1]):.1f} s')" "$t0" "$t1"
