# Runs with Blender's Python module (`bpy` 4.2 from PyPI: `python blender_side.py -- ARGS`; or
# inside a Blender, `blender -b --factory-startup -P blender_side.py -- ARGS`): renders one view of
# a glTF or OBJ file with Cycles the way lodeval renders it, and writes what a display shows, as an
# 8-bit sRGB PNG. Called by make_blender_pbr.py, which documents the settings. Blender 4's
# Principled BSDF (v2: Lambertian diffuse under an energy-conserving dielectric layer) is glTF's
# model; 3.4's (v1: Disney diffuse, no layering) renders a matte white sphere 13 % darker.
#
# ARGS: MODEL CAMERAS.json VIEW ENVIRONMENT.exr OUT.png SIZE SAMPLES TONE_MAPPING ISOLATE
#
# - ISOLATE = 1: every mesh object is invisible to secondary (diffuse, glossy, shadow,
#   transmission) rays, so each surface point sees the environment alone, as a rasterizer's
#   image-based lighting does: the BRDF and the IBL compared in isolation. ISOLATE = 0: Cycles'
#   full path tracing (shadows, occlusion, interreflections).
# - The camera is lodeval's (`lodeval render --cameras`), moved from glTF's Y-up into Blender's
#   Z-up frame (x, y, z) -> (x, -z, y), as Blender's glTF importer moves the model.
# - The world is the environment map on an Environment Texture node (equirectangular, linear
#   interpolation) at strength 1: lodeval's map orientation is Blender's by construction.
# - Cycles on the CPU, fixed seed 0, no denoising, a 1-pixel box filter, a transparent film; every
#   Principled BSDF uses multiple-scattering GGX (lodeval's energy compensation).
# - The linear result is tone-mapped here with the same operator as lodeval (Khronos PBR Neutral
#   or a clamp) and composited over lodeval's mid-grey background in display-linear light, then
#   sRGB-encoded.
import json
import math
import sys
import zlib
import struct

import numpy

# Blender 3.4's glTF importer predates numpy 1.24, which removed numpy.bool.
if not hasattr(numpy, "bool"):
    numpy.bool = bool

import bpy  # noqa: E402
import mathutils  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:]
model, cameras, view, env_path, out, size, samples, tone, isolate = argv
view, size, samples = int(view), int(size), int(samples)

bpy.ops.wm.read_factory_settings(use_empty=True)
if model.lower().endswith((".gltf", ".glb")):
    bpy.ops.import_scene.gltf(filepath=model)
    # Blender imports the coarser levels of an MSFT_lod chain as objects of their own (a reader
    # without the extension must show the finest only): remove them.
    raw = open(model, "rb").read()
    doc = json.loads(raw[20:20 + struct.unpack("<I", raw[12:16])[0]] if raw[:4] == b"glTF" else raw)
    lods = {i for n in doc.get("nodes", []) for i in n.get("extensions", {}).get("MSFT_lod", {}).get("ids", [])}
    for i in lods:
        obj = bpy.data.objects.get(doc["nodes"][i].get("name", ""))
        if obj is not None:
            bpy.data.objects.remove(obj)
else:
    bpy.ops.wm.obj_import(filepath=model, forward_axis="NEGATIVE_Z", up_axis="Y")

for mat in bpy.data.materials:
    if mat.node_tree is None:
        continue
    for node in mat.node_tree.nodes:
        if node.type == "BSDF_PRINCIPLED":
            node.distribution = "MULTI_GGX"

if isolate == "1":
    for obj in bpy.data.objects:
        if obj.type == "MESH":
            obj.visible_diffuse = False
            obj.visible_glossy = False
            obj.visible_shadow = False
            obj.visible_transmission = False

cam_json = json.load(open(cameras))[view]


def to_blender(p):
    return mathutils.Vector((p[0], -p[2], p[1]))


eye, target, up = (to_blender(cam_json[k]) for k in ("eye", "target", "up"))
forward = (target - eye).normalized()
right = forward.cross(up).normalized()
true_up = right.cross(forward)
rot = mathutils.Matrix((right, true_up, -forward)).transposed()
cam_data = bpy.data.cameras.new("lodeval")
cam_data.sensor_fit = "VERTICAL"
cam_data.angle_y = math.radians(cam_json["fov_y_deg"])
cam_data.clip_start = cam_json["near"]
cam_data.clip_end = cam_json["far"]
cam = bpy.data.objects.new("lodeval", cam_data)
cam.matrix_world = mathutils.Matrix.Translation(eye) @ rot.to_4x4()
bpy.context.scene.collection.objects.link(cam)
scene = bpy.context.scene
scene.camera = cam

world = bpy.data.worlds.new("environment")
world.use_nodes = True
nodes, links = world.node_tree.nodes, world.node_tree.links
tex = nodes.new("ShaderNodeTexEnvironment")
tex.image = bpy.data.images.load(env_path)
try:
    tex.image.colorspace_settings.name = "Linear Rec.709"  # Blender 4
except TypeError:
    tex.image.colorspace_settings.name = "Linear"  # Blender 3
tex.interpolation = "Linear"
tex.projection = "EQUIRECTANGULAR"
background = nodes["Background"]
background.inputs["Strength"].default_value = 1.0
links.new(tex.outputs["Color"], background.inputs["Color"])
scene.world = world

scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = samples
scene.cycles.seed = 0
scene.cycles.use_denoising = False
scene.cycles.use_adaptive_sampling = False
# No clamping (Blender 4 clamps indirect light at 10 by default: an unbiased reference).
scene.cycles.sample_clamp_direct = 0.0
scene.cycles.sample_clamp_indirect = 0.0
scene.cycles.pixel_filter_type = "BOX"
scene.cycles.filter_width = 1.0
scene.render.film_transparent = True
scene.render.resolution_x = size
scene.render.resolution_y = size
scene.render.resolution_percentage = 100
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
exr = out + ".exr"
scene.render.filepath = exr
bpy.ops.render.render(write_still=True)

img = bpy.data.images.load(exr)
px = numpy.array(img.pixels[:], dtype=numpy.float32).reshape(size, size, 4)[::-1]
alpha = px[..., 3:4]
straight = numpy.where(alpha > 0, px[..., :3] / numpy.maximum(alpha, 1e-8), 0.0)


def pbr_neutral(c):
    start, desat = 0.8 - 0.04, 0.15
    x = c.min(axis=-1, keepdims=True)
    offset = numpy.where(x < 0.08, x - 6.25 * x * x, 0.04)
    c = c - offset
    peak = c.max(axis=-1, keepdims=True)
    d = 1.0 - start
    new_peak = 1.0 - d * d / (peak + d - start)
    scaled = c * (new_peak / numpy.maximum(peak, 1e-8))
    g = 1.0 - 1.0 / (desat * (peak - new_peak) + 1.0)
    mapped = scaled + (new_peak - scaled) * g
    return numpy.where(peak < start, c, mapped)


mapped = straight.clip(0.0, None)
if tone == "pbr-neutral":
    mapped = pbr_neutral(mapped)
mapped = mapped.clip(0.0, 1.0)
grey = ((0.5 + 0.055) / 1.055) ** 2.4
shown = mapped * alpha + grey * (1.0 - alpha)
enc = numpy.where(shown <= 0.0031308, shown * 12.92, 1.055 * numpy.power(shown, 1 / 2.4) - 0.055)
rgb = (enc.clip(0.0, 1.0) * 255.0 + 0.5).astype(numpy.uint8)
raw = b"".join(b"\x00" + row.tobytes() for row in rgb)


def chunk(tag, data):
    return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)


png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0))
png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
open(out, "wb").write(png)
