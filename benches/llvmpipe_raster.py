#!/usr/bin/env python3
"""Render the scene exported by `lodeval bench raster --export DIR` with Mesa's llvmpipe (OpenGL
through EGL, via moderngl) and time it the same way: every view once after one warm-up frame,
colour read back to memory, with the same matrices, light and material. `--shading gouraud`:
per-vertex Blinn-Phong (lodeval's `gouraud`); `--shading pbr`: lodeval's `pbr` model per
fragment in GLSL — glTF's BRDF under the same image-based light (lodeval's own prefiltered
equirectangular levels, irradiance map and BRDF table, exported beside the mesh, as float
textures with linear filtering), the dominant-direction lookup, multiple scattering, Khronos PBR
Neutral tone mapping — so both renderers do the same work per shaded sample. Prints one Markdown
table row per sample count.

Usage: python3 benches/llvmpipe_raster.py DIR [--size 1024] [--samples 1,4] [--shading pbr]
Needs: pip install moderngl numpy; Debian libegl1 libegl-mesa0 libgl1-mesa-dri.
"""
import argparse
import json
import os
import time

import moderngl
import numpy as np

VS = """
#version 330
in vec3 in_pos;
in vec3 in_normal;
uniform mat4 mvp;
uniform vec3 light_dir, light_color, to_eye, base_color, specular;
uniform float ambient, shininess;
out vec3 v_color;
void main() {
    gl_Position = mvp * vec4(in_pos, 1.0);
    vec3 n = normalize(in_normal);
    float ndl = dot(n, light_dir);
    vec3 diffuse = vec3(ambient);
    vec3 spec = vec3(0.0);
    if (ndl > 0.0) {
        diffuse += light_color * ndl;
        vec3 h = normalize(light_dir + to_eye);
        spec += light_color * pow(max(dot(n, h), 0.0), shininess);
    }
    v_color = base_color * diffuse + specular * spec;
}
"""
FS = """
#version 330
in vec3 v_color;
out vec4 f_color;
void main() { f_color = vec4(v_color, 1.0); }
"""


PBR_VS = """
#version 330
in vec3 in_pos;
in vec3 in_normal;
uniform mat4 mvp;
out vec3 v_pos;
out vec3 v_normal;
void main() {
    gl_Position = mvp * vec4(in_pos, 1.0);
    v_pos = in_pos;
    v_normal = in_normal;
}
"""
PBR_FS = """
#version 330
in vec3 v_pos;
in vec3 v_normal;
uniform vec3 eye, base_color;
uniform float metallic, roughness;
uniform sampler2D level[9];
uniform sampler2D irradiance;
uniform sampler2D brdf;
out vec4 f_color;
const float PI = 3.14159265358979;
vec2 equirect(vec3 d) {
    d = normalize(d);
    return vec2(0.5 + atan(d.z, d.x) / (2.0 * PI), acos(clamp(d.y, -1.0, 1.0)) / PI);
}
vec3 specular(vec3 r, float rough) {
    float lod = clamp(rough, 0.0, 1.0) * 8.0;
    int l0 = int(floor(lod));
    float f = lod - float(l0);
    vec2 uv = equirect(r);
    int l1 = min(l0 + 1, 8);
    vec3 a = vec3(0.0), b = vec3(0.0);
    LEVEL_LOOKUPS
    return mix(a, b, f);
}
vec3 fresnel_ibl(vec3 f0, float nv, float rough, vec2 ab) {
    vec3 fr = max(vec3(1.0 - rough), f0) - f0;
    vec3 ks = f0 + fr * pow(1.0 - nv, 5.0);
    vec3 fss = ks * ab.x + ab.y;
    float ems = 1.0 - (ab.x + ab.y);
    vec3 favg = f0 + (1.0 - f0) / 21.0;
    return fss + fss * favg * ems / (1.0 - favg * ems);
}
vec3 neutral(vec3 c) {
    float start = 0.76;
    float x = min(c.r, min(c.g, c.b));
    float offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    c -= offset;
    float peak = max(c.r, max(c.g, c.b));
    if (peak < start) return c;
    float d = 1.0 - start;
    float np = 1.0 - d * d / (peak + d - start);
    c *= np / peak;
    float g = 1.0 - 1.0 / (0.15 * (peak - np) + 1.0);
    return mix(c, vec3(np), g);
}
void main() {
    vec3 n = normalize(v_normal);
    vec3 v = normalize(eye - v_pos);
    float nv = clamp(dot(n, v), 0.0, 1.0);
    vec3 r = normalize(mix(reflect(-v, n), n, roughness * roughness));
    vec3 diffuse = texture(irradiance, equirect(n)).rgb * base_color;
    vec3 spec = specular(r, roughness);
    vec2 ab = texture(brdf, vec2(nv, roughness)).rg;
    vec3 metal = fresnel_ibl(base_color, nv, roughness, ab) * spec;
    vec3 diel = mix(diffuse, spec, fresnel_ibl(vec3(0.04), nv, roughness, ab));
    f_color = vec4(clamp(neutral(mix(diel, metal, metallic)), 0.0, 1.0), 1.0);
}
"""


# GLSL 3.30 indexes sampler arrays with constants only: one lookup per level, written out.
PBR_FS = PBR_FS.replace("LEVEL_LOOKUPS", "\n    ".join(
    f"if (l0 == {k}) a = texture(level[{k}], uv).rgb; if (l1 == {k}) b = texture(level[{k}], uv).rgb;"
    for k in range(9)))


def ibl_textures(ctx, d):
    """lodeval's prepared environment (`ibl.json`, `ibl-N.f32`, `brdf.f32`) as float textures."""
    meta = json.load(open(os.path.join(d, "ibl.json")))
    maps = []
    for k, (w, h) in enumerate(meta["maps"]):
        texels = np.fromfile(os.path.join(d, f"ibl-{k}.f32"), dtype="<f4").reshape(h, w, 3)
        # Row 0 is the top of the map, v = 0 there: upload as is and sample v from the top.
        t = ctx.texture((w, h), 3, texels.tobytes(), dtype="f4")
        t.filter = (moderngl.LINEAR, moderngl.LINEAR)
        t.repeat_x, t.repeat_y = True, False
        maps.append(t)
    n = meta["lut_size"]
    lut = ctx.texture((n, n), 2, np.fromfile(os.path.join(d, "brdf.f32"), dtype="<f4").tobytes(), dtype="f4")
    lut.filter = (moderngl.LINEAR, moderngl.LINEAR)
    lut.repeat_x, lut.repeat_y = False, False
    return maps, lut


def save_png(path, rgb_f32, size):
    # Linear float RGB, bottom row first (OpenGL) -> sRGB 8-bit PNG, top row first.
    import zlib, struct
    a = np.frombuffer(rgb_f32, dtype="f4").reshape(size, size, 3)[::-1].clip(0, 1)
    a = np.where(a <= 0.0031308, a * 12.92, 1.055 * a ** (1 / 2.4) - 0.055)
    raw = b"".join(b"\x00" + row.tobytes() for row in (a * 255 + 0.5).astype("u1"))
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
    open(path, "wb").write(png)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--samples", default="1,4")
    ap.add_argument("--shading", default="gouraud", choices=["gouraud", "pbr"])
    args = ap.parse_args()
    pos = np.fromfile(os.path.join(args.dir, "positions.f32"), dtype="<f4")
    nrm = np.fromfile(os.path.join(args.dir, "normals.f32"), dtype="<f4")
    idx = np.fromfile(os.path.join(args.dir, "indices.u32"), dtype="<u4")
    views = json.load(open(os.path.join(args.dir, "views.json")))
    ctx = moderngl.create_standalone_context(backend="egl")
    renderer = ctx.info["GL_RENDERER"]
    pbr = args.shading == "pbr"
    prog = ctx.program(vertex_shader=PBR_VS if pbr else VS, fragment_shader=PBR_FS if pbr else FS)
    if pbr:
        maps, lut = ibl_textures(ctx, args.dir)
        for k, t in enumerate(maps[:9]):
            t.use(location=k)
        maps[9].use(location=9)
        lut.use(location=10)
        prog["level"].value = list(range(9))
        prog["irradiance"].value = 9
        prog["brdf"].value = 10
    vbo = ctx.buffer(np.concatenate([pos.reshape(-1, 3), nrm.reshape(-1, 3)], axis=1).astype("f4").tobytes())
    ibo = ctx.buffer(idx.tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "3f 3f", "in_pos", "in_normal")], index_buffer=ibo, index_element_size=4)
    # lodeval's projection maps depth to 0..1 (DirectX/WebGPU); OpenGL clips z to -w..w, so the
    # matrices are remapped: z' = 2z - w.
    remap = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 2, -1], [0, 0, 0, 1]], dtype="f4")
    tris = len(idx) // 3
    for samples in [int(s) for s in args.samples.split(",")]:
        size = (args.size, args.size)
        ms = ctx.framebuffer(
            color_attachments=[ctx.renderbuffer(size, 4, samples=samples if samples > 1 else 0)],
            depth_attachment=ctx.depth_renderbuffer(size, samples=samples if samples > 1 else 0),
        )
        resolved = ctx.framebuffer(color_attachments=[ctx.renderbuffer(size, 4)])
        ctx.enable(moderngl.DEPTH_TEST)

        def frame(v):
            # views.json stores column-major; as a numpy (row-major) matrix that is the transpose.
            mvp = remap @ np.array(v["mvp"], dtype="f4").reshape(4, 4).T
            prog["mvp"].write(np.ascontiguousarray(mvp.T, dtype="f4").tobytes())  # GLSL: column-major
            if pbr:
                prog["eye"].value = tuple(v["eye"])
                prog["base_color"].value = tuple(v["base_color"])
                prog["metallic"].value = v["metallic"]
                prog["roughness"].value = v["roughness"]
            else:
                for k in ["light_dir", "light_color", "to_eye", "base_color", "specular"]:
                    prog[k].value = tuple(v[k])
                prog["ambient"].value = v["ambient"]
                prog["shininess"].value = v["shininess"]
            ms.use()
            ms.clear(*v["background"], 1.0)
            vao.render(moderngl.TRIANGLES)
            if samples > 1:
                ctx.copy_framebuffer(resolved, ms)
                return resolved.read(components=3, dtype="f4")
            return ms.read(components=3, dtype="f4")

        first = frame(views[0])  # warm-up, not timed; saved for a visual check at 1 sample
        if samples == 1:
            save_png(os.path.join(args.dir, "llvmpipe-view0.png"), first, args.size)
        ctx.finish()
        start = time.perf_counter()
        for v in views:
            frame(v)
        ctx.finish()
        secs = (time.perf_counter() - start) / len(views)
        print(f"| llvmpipe {args.shading} ({renderer}) | {tris} | {args.size} | {samples} | {len(views)} | {os.cpu_count()} | {secs*1e3:.1f} | {1/secs:.2f} | {tris/secs/1e6:.1f} |")


if __name__ == "__main__":
    main()
