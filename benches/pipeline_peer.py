#!/usr/bin/env python3
"""The pipeline a user would script instead of `lodeval eval`, for the same image pairs: every
original and LOD rendered from the same 20 dodecahedron views at 512² with 4× MSAA on Mesa's
llvmpipe (OpenGL through EGL, via moderngl; per-vertex Blinn–Phong with a headlight, textures),
and every pair scored with NVIDIA's FLIP (`flip-evaluator`, LDR, 67 pixels per degree),
scikit-image's SSIM (sRGB luma, Wang et al.'s settings) and PSNR (8-bit sRGB RGB). Times the
whole of it (loading, rendering, read-back, scoring) and prints one JSON object.

Usage: python3 benches/pipeline_peer.py ORIGINAL:LOD1,LOD2,... [ORIGINAL:LODS...] [--size 512]
Needs: pip install moderngl trimesh numpy flip-evaluator scikit-image pillow;
       Debian libegl1 libegl-mesa0 libgl1-mesa-dri.
"""
import argparse
import json
import math
import sys
import time

import flip_evaluator
import moderngl
import numpy as np
import trimesh
from skimage.metrics import peak_signal_noise_ratio, structural_similarity

VS = """
#version 330
in vec3 in_pos;
in vec3 in_normal;
in vec2 in_uv;
uniform mat4 mvp;
uniform vec3 light_dir, to_eye;
out vec3 v_light;
out float v_spec;
out vec2 v_uv;
void main() {
    gl_Position = mvp * vec4(in_pos, 1.0);
    vec3 n = normalize(in_normal);
    float ndl = dot(n, light_dir);
    v_light = vec3(0.15);
    v_spec = 0.0;
    if (ndl > 0.0) {
        v_light += vec3(0.85) * ndl;
        v_spec = 0.85 * pow(max(dot(n, normalize(light_dir + to_eye)), 0.0), 32.0);
    }
    v_uv = in_uv;
}
"""
FS = """
#version 330
in vec3 v_light;
in float v_spec;
in vec2 v_uv;
uniform sampler2D tex;
uniform vec3 base_color;
uniform bool textured;
out vec4 f_color;
void main() {
    vec3 albedo = textured ? base_color * texture(tex, v_uv).rgb : base_color;
    f_color = vec4(albedo * v_light + vec3(0.1 * v_spec), 1.0);
}
"""

PHI = (1 + 5 ** 0.5) / 2


def dodecahedron():
    """The 20 view directions in lodeval's order (src/scene/rig.rs)."""
    s = (1, -1)
    v = [(x, y, z) for x in s for y in s for z in s]
    v += [(0, p / PHI, q * PHI) for p in s for q in s]
    v += [(p / PHI, q * PHI, 0) for p in s for q in s]
    v += [(p * PHI, 0, q / PHI) for p in s for q in s]
    return [np.array(d, float) / np.linalg.norm(d) for d in v]


def look_at(eye, target, up):
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.identity(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def perspective(fov_y, near, far):
    f = 1 / math.tan(math.radians(fov_y) / 2)
    m = np.zeros((4, 4))
    m[0, 0], m[1, 1] = f, f
    m[2, 2], m[2, 3] = (far + near) / (near - far), 2 * far * near / (near - far)
    m[3, 2] = -1
    return m


def cameras(mesh):
    lo, hi = mesh.bounds
    centre = (lo + hi) / 2
    r = np.linalg.norm(mesh.vertices - centre, axis=1).max() * 1.05
    dist = r / math.sin(math.radians(15))
    out = []
    for d in dodecahedron():
        up = np.array([0, 1, 0]) if abs(d[1]) <= 0.999 else np.array([0, 0, 1])
        eye = centre + d * dist
        out.append((perspective(30, dist - r, dist + r) @ look_at(eye, centre, up), d))
    return out


def load(ctx, prog, path):
    scene = trimesh.load(path, process=False)
    mesh = scene if isinstance(scene, trimesh.Trimesh) else scene.dump(concatenate=True)
    v = mesh.vertices[mesh.faces].reshape(-1, 3).astype("f4")
    n = mesh.vertex_normals[mesh.faces].reshape(-1, 3).astype("f4")
    uv = getattr(mesh.visual, "uv", None)
    tex = None
    if uv is not None and getattr(mesh.visual.material, "image", None) is not None:
        uv = uv[mesh.faces].reshape(-1, 2).astype("f4")
        # sRGB texels decoded to linear light before filtering, as lodeval does.
        img = np.asarray(mesh.visual.material.image.convert("RGB"))[::-1] / 255.0
        lin = np.where(img <= 0.04045, img / 12.92, ((img + 0.055) / 1.055) ** 2.4).astype("f4")
        tex = ctx.texture((img.shape[1], img.shape[0]), 3, lin.tobytes(), dtype="f4")
        tex.build_mipmaps()
    else:
        uv = np.zeros((len(v), 2), "f4")
    data = np.hstack([v, n, uv]).astype("f4").tobytes()
    vao = ctx.vertex_array(prog, [(ctx.buffer(data), "3f 3f 2f", "in_pos", "in_normal", "in_uv")])
    return mesh, vao, tex


def render(ctx, prog, fbo_ms, fbo, vao, tex, mvp, d, size):
    fbo_ms.use()
    ctx.clear(0.214, 0.214, 0.214)
    prog["mvp"].write(mvp.T.astype("f4").tobytes())
    prog["light_dir"].value = tuple(d)
    prog["to_eye"].value = tuple(d)
    prog["base_color"].value = (1.0, 1.0, 1.0) if tex else (0.8, 0.8, 0.8)
    prog["textured"].value = tex is not None
    if tex:
        tex.use(0)
    vao.render(moderngl.TRIANGLES)
    ctx.copy_framebuffer(fbo, fbo_ms)
    lin = np.frombuffer(fbo.read(components=3, dtype="f4"), "f4").reshape(size, size, 3)[::-1]
    lin = np.clip(lin, 0, 1)
    return np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * lin ** (1 / 2.4) - 0.055)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("assets", nargs="+")
    ap.add_argument("--size", type=int, default=512)
    a = ap.parse_args()
    start = time.perf_counter()
    ctx = moderngl.create_standalone_context(backend="egl")
    prog = ctx.program(vertex_shader=VS, fragment_shader=FS)
    size = a.size
    fbo_ms = ctx.framebuffer(ctx.renderbuffer((size, size), 4, samples=4, dtype="f4"),
                             ctx.depth_renderbuffer((size, size), samples=4))
    fbo = ctx.framebuffer(ctx.renderbuffer((size, size), 4, dtype="f4"))
    ctx.enable(moderngl.DEPTH_TEST)
    pairs, seconds = [], {"render": 0.0, "flip": 0.0, "ssim": 0.0, "psnr": 0.0}
    for spec in a.assets:
        original, lods = spec.split(":", 1)
        mesh, vao, tex = load(ctx, prog, original)
        cams = cameras(mesh)
        t = time.perf_counter()
        refs = [render(ctx, prog, fbo_ms, fbo, vao, tex, m, d, size) for m, d in cams]
        seconds["render"] += time.perf_counter() - t
        for lod in lods.split(","):
            _, lvao, ltex = load(ctx, prog, lod)
            for v, (m, d) in enumerate(cams):
                t = time.perf_counter()
                test = render(ctx, prog, fbo_ms, fbo, lvao, ltex, m, d, size)
                seconds["render"] += time.perf_counter() - t
                ref = refs[v]
                t = time.perf_counter()
                _, flip_mean, _ = flip_evaluator.evaluate(ref.astype("f4"), test.astype("f4"), "LDR",
                                                          inputsRGB=True, applyMagma=False,
                                                          computeMeanError=True,
                                                          parameters={"ppd": 67.0206})
                seconds["flip"] += time.perf_counter() - t
                t = time.perf_counter()
                luma = lambda x: x @ np.array([0.2126, 0.7152, 0.0722])
                ssim = structural_similarity(luma(ref), luma(test), data_range=1.0,
                                             gaussian_weights=True, sigma=1.5,
                                             use_sample_covariance=False)
                seconds["ssim"] += time.perf_counter() - t
                t = time.perf_counter()
                q = lambda x: np.round(x * 255).astype(np.uint8)
                psnr = peak_signal_noise_ratio(q(ref), q(test), data_range=255)
                seconds["psnr"] += time.perf_counter() - t
                pairs.append({"original": original, "lod": lod, "view": v, "flip": float(flip_mean),
                              "ssim": float(ssim), "psnr": float(psnr)})
    total = time.perf_counter() - start
    json.dump({"pairs": len(pairs), "seconds": total, "stages": seconds,
               "renderer": ctx.info["GL_RENDERER"]}, sys.stdout)
    print()


if __name__ == "__main__":
    main()
