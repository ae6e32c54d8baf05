#!/usr/bin/env bash
# The side-by-side figures of results/rendering/README.md: for each case of
# reference/oracles/blender_pbr/settings.json, lodeval's render (its defaults: pbr, the neutral
# environment, PBR Neutral, 4 samples per pixel), Blender's Cycles with each mesh invisible to
# secondary rays (isolated), Cycles path-traced (full), and the FLIP map of lodeval against the
# isolated render (magma, 0 … 1), in one PNG per case; and the FLIP means as a Markdown table.
# Usage, from the repository root: bash results/rendering/make_figures.sh   (needs Pillow)
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --quiet
out=results/rendering
refs=reference/oracles/blender_pbr
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 - "$refs" "$out" "$tmp" <<'PY'
import json, subprocess, sys
from PIL import Image, ImageDraw
refs, out, tmp = sys.argv[1:4]
settings = json.load(open(f"{refs}/settings.json"))
size = settings["size"]
rows = []
for case in settings["cases"]:
    name, view = case["name"], case["view"]
    model = "reference/models/spot/spot_mtl.obj" if case["model"].startswith("spot") else "reference/models/" + case["model"]
    ours = f"{tmp}/{name}-lodeval.png"
    subprocess.run(["target/release/lodeval", "render", model, "-o", ours, "--view", str(view),
                    "--size", str(size), "-q"], check=True)
    flips = {}
    for mode in ["isolated", "full"]:
        m = f"{tmp}/{name}-{mode}-map.png"
        r = subprocess.run(["target/release/lodeval", "diff", ours, f"{refs}/{name}-blender-{mode}.png",
                            "--map", m, "--json"], check=True, capture_output=True, text=True)
        flips[mode] = next(x["value"] for x in json.loads(r.stdout) if x["metric"] == "flip")
    tiles = [Image.open(p).convert("RGB") for p in
             [ours, f"{refs}/{name}-blender-isolated.png", f"{refs}/{name}-blender-full.png",
              f"{tmp}/{name}-isolated-map.png"]]
    captions = ["lodeval (pbr)", "Cycles, isolated", "Cycles, full",
                f"FLIP vs isolated: {flips['isolated']:.3f}"]
    sheet = Image.new("RGB", (4 * size + 12, size + 18), (32, 32, 32))
    draw = ImageDraw.Draw(sheet)
    for i, (t, c) in enumerate(zip(tiles, captions)):
        sheet.paste(t.resize((size, size)), (i * (size + 4), 18))
        draw.text((i * (size + 4) + 4, 3), c, fill=(230, 230, 230))
    sheet.save(f"{out}/{name}.png")
    rows.append(f"| {name} | {case['model']} | {view} | {flips['isolated']:.4f} | {flips['full']:.4f} |")
print("| case | model | view | FLIP vs Cycles isolated | FLIP vs Cycles full |")
print("|---|---|---|---|---|")
print("\n".join(rows))
PY
