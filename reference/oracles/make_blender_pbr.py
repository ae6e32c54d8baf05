#!/usr/bin/env python3
"""Make the external PBR references: Blender's Cycles renders of the shipped PBR assets with
lodeval's cameras, environment, exposure and tone mapping, committed under
reference/oracles/blender_pbr/ and compared with lodeval by tests/integration/pbr.rs and
results/rendering/README.md.

Needs: Blender's Python module (`pip install bpy==4.2.0 numpy` into a Python 3.11 virtual
environment; a 520 MB wheel) and a release build of lodeval and of the `export_environment`
example. Usage, from the repository root:

    cargo build --release --examples && cargo build --release
    BPY_PYTHON=/path/to/venv/bin/python python3 reference/oracles/make_blender_pbr.py

For each case: `lodeval render MODEL --view V --size 192 --cameras cams.json` (its default pbr
shading, the neutral environment, PBR Neutral tone mapping, 4 samples per pixel), then
blender_side.py renders the same camera with Cycles twice, 512 samples, seed 0, no denoising:
`isolated` (every mesh invisible to secondary rays: each point sees the environment alone, as
image-based lighting in a rasterizer does) and `full` (path tracing: shadows, occlusion,
interreflections). The neutral environment is written for Blender by the export_environment
example, byte for byte the map lodeval lights with. Writes the Blender PNGs, the cameras, and
settings.json (versions, samples, the FLIP lodeval measured at creation).
"""
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "reference", "oracles", "blender_pbr")
LODEVAL = os.path.join(ROOT, "target", "release", "lodeval")
EXPORT_ENV = os.path.join(ROOT, "target", "release", "examples", "export_environment")
SIDE = os.path.join(ROOT, "reference", "oracles", "blender_side.py")
BPY = os.environ.get("BPY_PYTHON", "python3")
SIZE, SAMPLES = 192, 512

# (name, model under reference/models, view of the dodecahedron rig)
CASES = [
    ("spheres", "metal_rough_spheres/MetalRoughSpheresNoTextures.gltf", 0),
    ("spheres-front", "metal_rough_spheres/MetalRoughSpheresNoTextures.gltf", 7),
    ("suzanne", "suzanne_pbr/Suzanne.gltf", 0),
    ("avocado", "avocado/Avocado.gltf", 3),
    ("helmet", "damaged_helmet/DamagedHelmet.gltf", 7),
    ("spot", None, 3),
]


def run(cmd):
    print("+", " ".join(cmd), flush=True)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def flip(a, b):
    out = subprocess.run([LODEVAL, "diff", a, b, "--json"], check=True, capture_output=True, text=True)
    return next(m["value"] for m in json.loads(out.stdout) if m["metric"] == "flip")


def main():
    os.makedirs(OUT, exist_ok=True)
    tmp = os.path.join(OUT, "tmp")
    os.makedirs(tmp, exist_ok=True)
    env = os.path.join(tmp, "neutral.exr")
    run([EXPORT_ENV, "neutral", env])
    # Spot's nvdiffrec PBR material (roughness 0.25) as glTF, which Blender's importer reads.
    spot = os.path.join(tmp, "spot.glb")
    run([LODEVAL, "simplify", os.path.join(ROOT, "reference/models/spot/spot_mtl.obj"), "-o", spot,
         "--method", "meshopt", "--ratio", "0.5", "-q"])
    settings = {"blender": None, "samples": SAMPLES, "size": SIZE, "environment": "neutral",
                "tone_mapping": "pbr-neutral", "exposure": 0, "lodeval_samples": 4, "cases": []}
    for name, rel, view in CASES:
        model = spot if rel is None else os.path.join(ROOT, "reference/models", rel)
        cams = os.path.join(OUT, f"{name}-cameras.json")
        lodeval_png = os.path.join(tmp, f"{name}-lodeval.png")
        run([LODEVAL, "render", model, "-o", lodeval_png, "--view", str(view), "--size", str(SIZE),
             "--cameras", cams, "-q"])
        case = {"name": name, "model": rel or "spot (spot_mtl.obj as glTF, original level)",
                "view": view, "flip": {}}
        for mode, isolate in [("isolated", "1"), ("full", "0")]:
            png = os.path.join(OUT, f"{name}-blender-{mode}.png")
            # bpy can crash on exit after writing its files; the PNG is what counts.
            subprocess.run([BPY, SIDE, "--", model, cams, str(view), env, png, str(SIZE),
                            str(SAMPLES), "pbr-neutral", isolate], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
            if not os.path.exists(png):
                sys.exit(f"Blender wrote no {png}")
            os.remove(png + ".exr")
            case["flip"][mode] = round(flip(lodeval_png, png), 5)
        print(name, case["flip"], flush=True)
        settings["cases"].append(case)
    version = subprocess.run([BPY, "-c", "import bpy; print(bpy.app.version_string)"],
                             capture_output=True, text=True).stdout.strip().splitlines()
    settings["blender"] = version[-1] if version else "unknown"
    with open(os.path.join(OUT, "settings.json"), "w") as f:
        json.dump(settings, f, indent=2)
    for f in os.listdir(tmp):
        os.remove(os.path.join(tmp, f))
    os.rmdir(tmp)


if __name__ == "__main__":
    main()
