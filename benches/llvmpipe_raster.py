#!/usr/bin/env python3
"""Render the scene exported by `lodeval bench raster --export DIR` with Mesa's llvmpipe (OpenGL
through EGL, via moderngl) and time it the same way: every view once after one warm-up frame,
colour read back to memory, per-vertex Blinn-Phong (the `gouraud` model) with the same matrices,
light and material. Prints one Markdown table row per sample count.

Usage: python3 benches/llvmpipe_raster.py DIR [--size 1024] [--samples 1,4]
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
    args = ap.parse_args()
    pos = np.fromfile(os.path.join(args.dir, "positions.f32"), dtype="<f4")
    nrm = np.fromfile(os.path.join(args.dir, "normals.f32"), dtype="<f4")
    idx = np.fromfile(os.path.join(args.dir, "indices.u32"), dtype="<u4")
    views = json.load(open(os.path.join(args.dir, "views.json")))
    ctx = moderngl.create_standalone_context(backend="egl")
    renderer = ctx.info["GL_RENDERER"]
    prog = ctx.program(vertex_shader=VS, fragment_shader=FS)
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
        print(f"| llvmpipe ({renderer}) | {tris} | {args.size} | {samples} | {len(views)} | {os.cpu_count()} | {secs*1e3:.1f} | {1/secs:.2f} | {tris/secs/1e6:.1f} |")


if __name__ == "__main__":
    main()
