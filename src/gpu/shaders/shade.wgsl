// The shade-and-resolve pass of the GPU mirror: src/raster/resolve.rs and src/raster/shade.rs,
// line for line, as a compute pass over the visibility layers written by visibility.wgsl.
//
// Per pixel, over its samples in the CPU's order: group the samples by triangle; shade each
// triangle once, at its first covered sample; colour = (background × empty samples + Σ shade ×
// samples) / samples in linear light; coverage = covered fraction; depth = nearest covered sample
// (+∞ if none); triangle = the one covering most samples (ties: the one seen first).
//
// Shading: Colour = T ∘ K_d ∘ C_vertex ∘ (k_a + Σ_l c_l·max(N·L_l, 0)) + K_s ∘ Σ_l c_l·max(N·H_l, 0)^n
// (highlight only where N·L_l > 0; Williams et al. 2003 §5.4; OpenGL fixed-function lighting for an
// infinite light and viewer). `gouraud` evaluates the light terms at the three vertices and
// interpolates them; `phong` and `normal-mapped` per shading point. Attributes are interpolated
// with perspective-correct barycentrics solved from the clip-space corners (exact for triangles
// crossing the near plane too, where the CPU interpolates through its clipped corners); texture
// derivatives are the same mapping one pixel right and one pixel down, as on the CPU, and
// textures are the CPU's mip pyramids sampled with its formulas (texture.rs: wrap modes, nearest
// or linear texels, no mip-maps, the nearest level or two), each slot through its own sampler,
// texture transform and UV set.
//
// `pbr` (code 6) is src/raster/pbr.rs: glTF's metallic–roughness BRDF under image-based light
// (the CPU's prefiltered equirectangular chain, irradiance map and BRDF table, uploaded as
// further texture levels) and punctual lights. Every shaded colour but the debug views' passes
// the display transform (tonemap.rs: exposure, then linear / ACES (Hill) / Khronos PBR Neutral).

const MAX_LIGHTS: u32 = 8u;
const PI: f32 = 3.14159265358979;
const MAX_SAMPLES: u32 = 64u;
const NONE: u32 = 0xffffffffu;
const INFINITY_BITS: u32 = 0x7f800000u;
// See render.rs: position (0..3), material index (3, bits), normal (4..7), tangent handedness (7),
// uv (8..10), colour (10..13), tangent (13..16), second uv (16..18).
const VSTRIDE: u32 = 18u;

// A punctual light of the pbr model: kind 0 directional (dir = towards the light, color =
// irradiance), 1 point, 2 spot (dir = the way light travels); range ≤ 0: unbounded.
struct PLight {
    pos_kind: vec4<f32>,
    dir_range: vec4<f32>,
    color_inner: vec4<f32>,
    outer: vec4<f32>,
}

struct Light {
    l: vec4<f32>,
    color: vec4<f32>,
    h: vec4<f32>,
}

struct Globals {
    mvp: mat4x4<f32>,
    lights: array<Light, MAX_LIGHTS>,
    // Sample offsets within the pixel, in pixels (xy), in the CPU's sample order.
    offsets: array<vec4<f32>, MAX_SAMPLES>,
    background: vec4<f32>,
    ambient: f32,
    // 0 unlit, 1 gouraud, 2 phong, 3 normal-mapped, 4 normals, 5 depth
    shading: u32,
    light_count: u32,
    // bit 0: the mesh has UVs, bit 1: vertex colours, bit 2: tangents
    flags: u32,
    near: f32,
    far: f32,
    perspective: u32,
    samples: u32,
    width: u32,
    height: u32,
    pad0: u32,
    pad1: u32,
    plights: array<PLight, MAX_LIGHTS>,
    // xyz eye, w: 1 perspective / 0 orthographic
    eye: vec4<f32>,
    to_eye: vec4<f32>,
    // rows of the world → environment rotation
    env_x: vec4<f32>,
    env_y: vec4<f32>,
    env_z: vec4<f32>,
    // x intensity, y multiple scattering (1/0), z exposure scale, w unused
    env: vec4<f32>,
    // x first level of the prefiltered chain (9 levels, then the irradiance map), y the BRDF
    // table's level, z punctual light count, w tone mapper (0 linear, 1 aces, 2 pbr-neutral)
    ibl: vec4<u32>,
}

// One texture slot: tex = (first level, level count (0: none), UV set, sampler bits: wrap s in
// bits 0–1 and t in 2–3 (0 repeat, 1 clamp, 2 mirrored), bit 4 linear magnification, bit 5
// linear minification, bits 6–7 mip-maps (0 none, 1 nearest level, 2 two levels)); m, o: the
// texture transform in lodeval's UV convention, uv' = (m.xy·u + m.zw·v) + o.xy, where o.z = 1.
struct Slot {
    tex: vec4<u32>,
    m: vec4<f32>,
    o: vec4<f32>,
}

struct Material {
    // rgb base colour, a alpha
    base_color: vec4<f32>,
    // rgb: specular colour K_s, w: shininess n
    specular: vec4<f32>,
    // metallic, roughness, normal scale, occlusion strength
    pbr: vec4<f32>,
    // rgb emission (× strength), w double-sided (1/0)
    emission: vec4<f32>,
    // base colour, metallic–roughness, normal, occlusion, emissive
    slots: array<Slot, 5>,
}

// A mip level: texels row-major, top row first, at `offset` in texel page `page`.
struct Level {
    page: u32,
    offset: u32,
    width: u32,
    height: u32,
}

@group(0) @binding(0) var<uniform> g: Globals;
@group(0) @binding(1) var<storage, read> vertices: array<f32>;
@group(0) @binding(2) var<storage, read> tris: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read> materials: array<Material>;
@group(0) @binding(4) var<storage, read> levels: array<Level>;
// Texels in up to eight pages, each within one storage binding's size limit (a PBR asset with
// five 2048² maps needs five at lavapipe's 128 MiB).
@group(0) @binding(5) var<storage, read> page0: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> page1: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> page2: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read> page3: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read> page4: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read> page5: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read> page6: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read> page7: array<vec4<f32>>;
@group(0) @binding(13) var id_tex: texture_2d_array<u32>;
@group(0) @binding(14) var depth_tex: texture_depth_2d_array;
@group(0) @binding(15) var<storage, read_write> out_color: array<vec4<f32>>;
@group(0) @binding(16) var<storage, read_write> out_aux: array<vec2<u32>>;

fn vfetch3(v: u32, at: u32) -> vec3<f32> {
    let b = v * VSTRIDE + at;
    return vec3<f32>(vertices[b], vertices[b + 1u], vertices[b + 2u]);
}

// x^n; integer exponents by square-and-multiply as Rust's powi, others by pow.
fn highlight(x: f32, n: f32) -> f32 {
    if (fract(n) == 0.0 && n >= 0.0 && n <= 4096.0) {
        var e = u32(n);
        var base = x;
        var r = 1.0;
        loop {
            if ((e & 1u) != 0u) { r = r * base; }
            e = e >> 1u;
            if (e == 0u) { break; }
            base = base * base;
        }
        return r;
    }
    return pow(x, n);
}

struct Terms {
    diffuse: vec3<f32>,
    spec: vec3<f32>,
}

fn light_terms(n: vec3<f32>, ks: vec3<f32>, shininess: f32) -> Terms {
    var diffuse = vec3<f32>(g.ambient);
    var spec = vec3<f32>(0.0);
    for (var i = 0u; i < g.light_count; i = i + 1u) {
        let light = g.lights[i];
        let ndl = dot(n, light.l.xyz);
        if (ndl > 0.0) {
            diffuse = diffuse + light.color.xyz * ndl;
            spec = spec + light.color.xyz * highlight(max(dot(n, light.h.xyz), 0.0), shininess);
        }
    }
    return Terms(diffuse, ks * spec);
}

// Texel index i (any integer) wrapped onto 0..n: 0 repeat, 1 clamp to edge, 2 mirrored repeat.
fn wrap_index(i: i32, n: u32, mode: u32) -> u32 {
    let m = i32(n);
    if (i >= 0 && i < m) { return u32(i); }
    if (mode == 1u) { return u32(clamp(i, 0, m - 1)); }
    if (mode == 2u) {
        var k = i % (2 * m);
        if (k < 0) { k = k + 2 * m; }
        if (k < m) { return u32(k); }
        return u32(2 * m - 1 - k);
    }
    var k = i % m;
    if (k < 0) { k = k + m; }
    return u32(k);
}

fn texel(l: Level, x: u32, y: u32) -> vec3<f32> {
    let i = l.offset + y * l.width + x;
    switch l.page {
        case 0u: { return page0[i].xyz; }
        case 1u: { return page1[i].xyz; }
        case 2u: { return page2[i].xyz; }
        case 3u: { return page3[i].xyz; }
        case 4u: { return page4[i].xyz; }
        case 5u: { return page5[i].xyz; }
        case 6u: { return page6[i].xyz; }
        default: { return page7[i].xyz; }
    }
}

// glam's lerp: a + (b − a)·t.
fn lerp3(a: vec3<f32>, b: vec3<f32>, t: f32) -> vec3<f32> {
    return a + (b - a) * t;
}

// Bilinear (texel centres at half-integers) or nearest (the texel containing uv: the same four
// texels with zero weights, which returns the first exactly); v = 0 is the bottom row. One
// code path for both keeps the shader small (lavapipe compiles every inlined copy).
fn fetch(level: u32, uv: vec2<f32>, linear: bool, bits: u32) -> vec3<f32> {
    let l = levels[level];
    var x = uv.x * f32(l.width);
    var y = (1.0 - uv.y) * f32(l.height);
    if (linear) {
        x = x - 0.5;
        y = y - 0.5;
    }
    let fx = floor(x);
    let fy = floor(y);
    var tx = x - fx;
    var ty = y - fy;
    if (!linear) {
        tx = 0.0;
        ty = 0.0;
    }
    let ws = bits & 3u;
    let wt = (bits >> 2u) & 3u;
    let x0 = wrap_index(i32(fx), l.width, ws);
    let x1 = wrap_index(i32(fx) + 1, l.width, ws);
    let y0 = wrap_index(i32(fy), l.height, wt);
    let y1 = wrap_index(i32(fy) + 1, l.height, wt);
    let top = lerp3(texel(l, x0, y0), texel(l, x1, y0), tx);
    let bottom = lerp3(texel(l, x0, y1), texel(l, x1, y1), tx);
    return lerp3(top, bottom, ty);
}

// A slot's sample at uv with derivatives dx, dy, as texture.rs's sample_with: the level(s) and
// filter are chosen first, then at most two fetches.
fn sample_slot(slot: Slot, uv0: vec2<f32>, dx0: vec2<f32>, dy0: vec2<f32>) -> vec3<f32> {
    var uv = uv0;
    var dx = dx0;
    var dy = dy0;
    if (slot.o.z != 0.0) {
        uv = slot.m.xy * uv0.x + slot.m.zw * uv0.y + slot.o.xy;
        dx = slot.m.xy * dx0.x + slot.m.zw * dx0.y;
        dy = slot.m.xy * dy0.x + slot.m.zw * dy0.y;
    }
    let first = slot.tex.x;
    let count = slot.tex.y;
    let bits = slot.tex.w;
    let base = levels[first];
    let size = vec2<f32>(f32(base.width), f32(base.height));
    let rho = max(length(dx * size), length(dy * size));
    var lod = 0.0;
    if (rho > 1.0) { lod = log2(rho); }
    var la = first;
    var frac = 0.0;
    var linear = (bits & 16u) != 0u;
    if (lod > 0.0) {
        lod = clamp(lod, 0.0, f32(count - 1u));
        linear = (bits & 32u) != 0u;
        let mip = (bits >> 6u) & 3u;
        if (mip == 1u) {
            la = first + u32(floor(lod + 0.5));
        } else if (mip == 2u) {
            let l0 = u32(floor(lod));
            la = first + l0;
            if (l0 + 1u < count) { frac = lod - f32(l0); }
        }
    }
    let a = fetch(la, uv, linear, bits);
    if (frac == 0.0) { return a; }
    return lerp3(a, fetch(la + 1u, uv, linear, bits), frac);
}

fn normalize_or_zero(v: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    if (l > 0.0 && l < 3.4e38) { return v / l; }
    return vec3<f32>(0.0);
}

fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

// Perspective-correct barycentrics of the triangle with clip-space corners c at screen point s
// (pixels): the weights b (Σ b = 1) with Σ b_i·(c_i.xy − ndc·c_i.w) = 0.
fn barycentrics(c: array<vec4<f32>, 3>, s: vec2<f32>) -> vec3<f32> {
    let ndc = vec2<f32>(s.x / f32(g.width) * 2.0 - 1.0, 1.0 - s.y / f32(g.height) * 2.0);
    let q0 = c[0].xy - ndc * c[0].w;
    let q1 = c[1].xy - ndc * c[1].w;
    let q2 = c[2].xy - ndc * c[2].w;
    let b = vec3<f32>(cross2(q1, q2), cross2(q2, q0), cross2(q0, q1));
    let sum = b.x + b.y + b.z;
    if (sum == 0.0) { return vec3<f32>(1.0 / 3.0); }
    return b / sum;
}

fn interp3(v: vec3<u32>, at: u32, b: vec3<f32>) -> vec3<f32> {
    return vfetch3(v.x, at) * b.x + vfetch3(v.y, at) * b.y + vfetch3(v.z, at) * b.z;
}

fn uv_at(v: vec3<u32>, b: vec3<f32>, at: u32) -> vec2<f32> {
    let uv0 = vec2<f32>(vertices[v.x * VSTRIDE + at], vertices[v.x * VSTRIDE + at + 1u]);
    let uv1 = vec2<f32>(vertices[v.y * VSTRIDE + at], vertices[v.y * VSTRIDE + at + 1u]);
    let uv2 = vec2<f32>(vertices[v.z * VSTRIDE + at], vertices[v.z * VSTRIDE + at + 1u]);
    return uv0 * b.x + uv1 * b.y + uv2 * b.z;
}

fn vertex_terms(v: u32) -> Terms {
    let m = materials[bitcast<u32>(vertices[v * VSTRIDE + 3u])];
    return light_terms(vfetch3(v, 4u), m.specular.xyz, m.specular.w);
}

// The UV frames of a shading point: per set, uv and its steps one pixel right and down, and
// whether the mesh has the set.
struct Frames {
    uv: array<vec2<f32>, 2>,
    dx: array<vec2<f32>, 2>,
    dy: array<vec2<f32>, 2>,
    has: array<bool, 2>,
}

// Whether slot k of a material has a texture the mesh has the UV set for.
fn slot_present(slot: Slot, f: Frames) -> bool {
    return slot.tex.y != 0u && f.has[min(slot.tex.z, 1u)];
}

// Every slot's texel (in one loop: one compiled copy of the sampler), 1 where absent.
struct Texels {
    t: array<vec3<f32>, 5>,
}

fn material_texels(material: Material, f: Frames, all: bool) -> Texels {
    var out: Texels;
    for (var k = 0u; k < 5u; k = k + 1u) {
        out.t[k] = vec3<f32>(1.0);
        let slot = material.slots[k];
        // The Blinn–Phong models read the base colour and the normal map only.
        if ((all || k == 0u || k == 2u) && slot_present(slot, f)) {
            let uv_set = min(slot.tex.z, 1u);
            out.t[k] = sample_slot(slot, f.uv[uv_set], f.dx[uv_set], f.dy[uv_set]);
        }
    }
    return out;
}

// The interpolated normal n perturbed by the material's normal map (its texel `nt`, with the
// map's scale).
fn normal_mapped(material: Material, v: vec3<u32>, b: vec3<f32>, f: Frames, n: vec3<f32>, nt: vec3<f32>) -> vec3<f32> {
    let slot = material.slots[2];
    if ((g.flags & 4u) == 0u || !slot_present(slot, f)) { return n; }
    let t3 = interp3(v, 13u, b);
    let tw = vertices[v.x * VSTRIDE + 7u] * b.x + vertices[v.y * VSTRIDE + 7u] * b.y
        + vertices[v.z * VSTRIDE + 7u] * b.z;
    let tt = normalize_or_zero(t3 - n * dot(n, t3));
    var sign = 1.0;
    if (tw < 0.0) { sign = -1.0; }
    let bitangent = cross(n, tt) * sign;
    var m = nt * 2.0 - 1.0;
    let scale = material.pbr.z;
    if (scale != 1.0) {
        let sm = m * vec3<f32>(scale, scale, 1.0);
        let l = length(sm);
        if (l > 0.0) { m = sm / l; } else { m = vec3<f32>(0.0, 0.0, 1.0); }
    }
    let pert = tt * m.x + bitangent * m.y + n * m.z;
    let l = length(pert);
    if (l > 0.0) { return pert / l; }
    return n;
}

// ---- The pbr model (src/raster/pbr.rs, ibl.rs) ----

// scene/environment.rs's atan2: a degree-11 odd polynomial on [0, 1], octants by swaps/signs.
fn poly_atan2(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    let ay = abs(y);
    let swap = ay > ax;
    let num = select(ay, ax, swap);
    let den = select(ax, ay, swap);
    if (den == 0.0) { return 0.0; }
    let z = num / den;
    let z2 = z * z;
    var a = z * (0.9999773 + z2 * (-0.3326235 + z2 * (0.1935435 + z2 * (-0.1164329
        + z2 * (0.0526533 - z2 * 0.0117212)))));
    if (swap) { a = 1.5707964 - a; }
    if (x < 0.0) { a = PI - a; }
    if (y < 0.0) { return -a; }
    return a;
}

// scene/environment.rs's acos (Abramowitz & Stegun 4.4.46).
fn poly_acos(y: f32) -> f32 {
    let a = min(abs(y), 1.0);
    let p = 1.5707963 + a * (-0.2145988 + a * (0.08897899 + a * (-0.0501743
        + a * (0.03089188 + a * (-0.0170881 + a * (0.00667009 - a * 0.001262491))))));
    let r = sqrt(1.0 - a) * p;
    if (y < 0.0) { return PI - r; }
    return r;
}

// Map coordinates of a direction in the environment's frame (scene/environment.rs's uv_of).
fn equirect_uv(d: vec3<f32>) -> vec2<f32> {
    let l = length(d);
    if (!(l > 0.0)) { return vec2<f32>(0.5, 0.0); }
    let u = 0.5 + poly_atan2(d.z, d.x) * (0.5 / PI);
    let v = poly_acos(d.y / l) * (1.0 / PI);
    return vec2<f32>(u, v);
}

// Bilinear in an equirectangular level: u wraps, v clamps (ibl.rs's EquirectMap::sample_uv).
fn equirect(level: u32, uv: vec2<f32>) -> vec3<f32> {
    let l = levels[level];
    let x = uv.x * f32(l.width) - 0.5;
    let y = clamp(uv.y * f32(l.height) - 0.5, 0.0, f32(l.height - 1u));
    let fx = floor(x);
    let fy = floor(y);
    let tx = x - fx;
    let ty = y - fy;
    let x0 = wrap_index(i32(fx), l.width, 0u);
    let x1 = wrap_index(i32(fx) + 1, l.width, 0u);
    let y0 = u32(fy);
    let y1 = min(y0 + 1u, l.height - 1u);
    let top = lerp3(texel(l, x0, y0), texel(l, x1, y0), tx);
    let bottom = lerp3(texel(l, x0, y1), texel(l, x1, y1), tx);
    return lerp3(top, bottom, ty);
}

fn to_map(d: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(g.env_x.xyz, d), dot(g.env_y.xyz, d), dot(g.env_z.xyz, d));
}

fn ibl_specular(r: vec3<f32>, roughness: f32) -> vec3<f32> {
    let lod = clamp(roughness, 0.0, 1.0) * 8.0;
    let l0 = u32(floor(lod));
    let frac = lod - f32(l0);
    let uv = equirect_uv(r);
    let a = equirect(g.ibl.x + l0, uv);
    if (frac == 0.0 || l0 + 1u >= 9u) { return a; }
    return lerp3(a, equirect(g.ibl.x + l0 + 1u, uv), frac);
}

// The BRDF table (32 × 32, N·V across, roughness down; stored as a texture level).
fn brdf_lut(n_dot_v: f32, roughness: f32) -> vec2<f32> {
    let l = levels[g.ibl.y];
    let n = f32(l.width);
    let x = clamp(clamp(n_dot_v, 0.0, 1.0) * n - 0.5, 0.0, n - 1.0);
    let y = clamp(clamp(roughness, 0.0, 1.0) * n - 0.5, 0.0, n - 1.0);
    let x0 = u32(floor(x));
    let y0 = u32(floor(y));
    let x1 = min(x0 + 1u, l.width - 1u);
    let y1 = min(y0 + 1u, l.height - 1u);
    let tx = x - f32(x0);
    let ty = y - f32(y0);
    let top = lerp3(texel(l, x0, y0), texel(l, x1, y0), tx);
    let bottom = lerp3(texel(l, x0, y1), texel(l, x1, y1), tx);
    return lerp3(top, bottom, ty).xy;
}

fn ibl_fresnel(f0: vec3<f32>, n_dot_v: f32, roughness: f32, ab: vec2<f32>) -> vec3<f32> {
    let fr = max(vec3<f32>(1.0 - roughness), f0) - f0;
    let k_s = f0 + fr * pow(1.0 - n_dot_v, 5.0);
    let fss_ess = k_s * ab.x + vec3<f32>(ab.y);
    if (g.env.y == 0.0) { return fss_ess; }
    let e_ms = 1.0 - (ab.x + ab.y);
    let f_avg = f0 + (vec3<f32>(1.0) - f0) / 21.0;
    let fms_ems = fss_ess * f_avg * e_ms / (vec3<f32>(1.0) - f_avg * e_ms);
    return fss_ess + fms_ems;
}

fn ggx_d(n_dot_h: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let f = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    return a2 / (PI * f * f);
}

fn smith_visibility(n_dot_l: f32, n_dot_v: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let ggxv = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
    let ggxl = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
    let s = ggxv + ggxl;
    if (s > 0.0) { return 0.5 / s; }
    return 0.0;
}

fn schlick(f0: vec3<f32>, v_dot_h: f32) -> vec3<f32> {
    return f0 + (vec3<f32>(1.0) - f0) * pow(1.0 - clamp(v_dot_h, 0.0, 1.0), 5.0);
}

// Direction towards light i from p (xyz) and the irradiance there (returned in `e`).
struct LightAt {
    l: vec3<f32>,
    e: vec3<f32>,
}

fn light_at(i: u32, p: vec3<f32>) -> LightAt {
    let light = g.plights[i];
    let kind = light.pos_kind.w;
    if (kind < 0.5) { return LightAt(light.dir_range.xyz, light.color_inner.xyz); }
    let to = light.pos_kind.xyz - p;
    let d2 = max(dot(to, to), 1e-12);
    var l = vec3<f32>(0.0);
    if (dot(to, to) > 0.0) { l = normalize(to); }
    let range = light.dir_range.w;
    var falloff = 1.0 / d2;
    if (range > 0.0) {
        let q = d2 / (range * range);
        falloff = clamp(1.0 - q * q, 0.0, 1.0) / d2;
    }
    var cone = 1.0;
    if (kind > 1.5) {
        let c = dot(light.dir_range.xyz, -l);
        let cos_inner = light.color_inner.w;
        let cos_outer = light.outer.x;
        if (c <= cos_outer) {
            cone = 0.0;
        } else if (c < cos_inner) {
            let t = (c - cos_outer) / max(cos_inner - cos_outer, 1e-6);
            cone = t * t;
        }
    }
    return LightAt(l, light.color_inner.xyz * (falloff * cone));
}

fn pbr_shade(base: vec3<f32>, metallic: f32, roughness: f32, n: vec3<f32>, v: vec3<f32>,
             p: vec3<f32>, occlusion: f32, emission: vec3<f32>) -> vec3<f32> {
    let n_dot_v = clamp(dot(n, v), 0.0, 1.0);
    let f0d = vec3<f32>(0.04);
    var r = 2.0 * dot(n, v) * n - v;
    let rl = length(r);
    if (rl > 0.0) { r = r / rl; } else { r = n; }
    // The rough lobe's dominant direction (pbr.rs).
    r = r + (n - r) * (roughness * roughness);
    let rl2 = length(r);
    if (rl2 > 0.0) { r = r / rl2; } else { r = n; }
    let diffuse = ibl_diffuse_at(to_map(n)) * g.env.x * base;
    let specular = ibl_specular(to_map(r), roughness) * g.env.x;
    let ab = brdf_lut(n_dot_v, roughness);
    let metal = ibl_fresnel(base, n_dot_v, roughness, ab) * specular;
    let dielectric_f = ibl_fresnel(f0d, n_dot_v, roughness, ab);
    let dielectric = diffuse + (specular - diffuse) * dielectric_f;
    var color = (dielectric + (metal - dielectric) * metallic) * occlusion;
    let rr = max(roughness, 0.045);
    let alpha = rr * rr;
    for (var i = 0u; i < g.ibl.z; i = i + 1u) {
        let la = light_at(i, p);
        let n_dot_l = dot(n, la.l);
        if (n_dot_l <= 0.0 || all(la.e == vec3<f32>(0.0))) { continue; }
        var h = la.l + v;
        let hl = length(h);
        if (hl > 0.0) { h = h / hl; } else { h = n; }
        let n_dot_h = clamp(dot(n, h), 0.0, 1.0);
        let v_dot_h = abs(dot(v, h));
        let spec = ggx_d(n_dot_h, alpha) * smith_visibility(n_dot_l, n_dot_v, alpha);
        let lambert = base * (1.0 / PI);
        let fd = schlick(f0d, v_dot_h);
        let l_dielectric = lambert + (vec3<f32>(spec) - lambert) * fd;
        let l_metal = schlick(base, v_dot_h) * spec;
        color = color + la.e * n_dot_l * (l_dielectric + (l_metal - l_dielectric) * metallic);
    }
    return color + emission;
}

fn ibl_diffuse_at(n: vec3<f32>) -> vec3<f32> {
    return equirect(g.ibl.x + 9u, equirect_uv(n));
}

// ---- The display transform (src/raster/tonemap.rs) ----

fn pbr_neutral(c0: vec3<f32>) -> vec3<f32> {
    let start = 0.8 - 0.04;
    let x = min(c0.x, min(c0.y, c0.z));
    var offset = 0.04;
    if (x < 0.08) { offset = x - 6.25 * x * x; }
    var c = c0 - offset;
    let peak = max(c.x, max(c.y, c.z));
    if (peak < start) { return c; }
    let d = 1.0 - start;
    let new_peak = 1.0 - d * d / (peak + d - start);
    c = c * (new_peak / peak);
    let gg = 1.0 - 1.0 / (0.15 * (peak - new_peak) + 1.0);
    return c + (vec3<f32>(new_peak) - c) * gg;
}

fn aces_hill(c: vec3<f32>) -> vec3<f32> {
    let i = vec3<f32>(
        0.59719 * c.x + 0.35458 * c.y + 0.04823 * c.z,
        0.07600 * c.x + 0.90834 * c.y + 0.01566 * c.z,
        0.02840 * c.x + 0.13383 * c.y + 0.83777 * c.z,
    );
    let a = i * (i + 0.0245786) - 0.000090537;
    let b = i * (0.983729 * i + 0.4329510) + 0.238081;
    let v = a / b;
    return vec3<f32>(
        1.60475 * v.x - 0.53108 * v.y - 0.07367 * v.z,
        -0.10208 * v.x + 1.10813 * v.y - 0.00605 * v.z,
        -0.00327 * v.x - 0.07276 * v.y + 1.07602 * v.z,
    );
}

fn display(c: vec3<f32>) -> vec3<f32> {
    var x = max(c * g.env.z, vec3<f32>(0.0));
    if (g.ibl.w == 1u) { x = aces_hill(x); }
    if (g.ibl.w == 2u) { x = pbr_neutral(x); }
    return clamp(x, vec3<f32>(0.0), vec3<f32>(1.0));
}

// Shade triangle `tri` at screen point s (pixels) — shade.rs's ShadeContext::shade.
fn shade(tri: u32, s: vec2<f32>) -> vec3<f32> {
    let t = tris[tri];
    let v = t.xyz;
    var c: array<vec4<f32>, 3>;
    c[0] = g.mvp * vec4<f32>(vfetch3(v.x, 0u), 1.0);
    c[1] = g.mvp * vec4<f32>(vfetch3(v.y, 0u), 1.0);
    c[2] = g.mvp * vec4<f32>(vfetch3(v.z, 0u), 1.0);
    let b = barycentrics(c, s);
    if (g.shading == 4u) {
        return normalize_or_zero(interp3(v, 4u, b)) * 0.5 + 0.5;
    }
    if (g.shading == 5u) {
        var d = b.x * c[0].z / c[0].w + b.y * c[1].z / c[1].w + b.z * c[2].z / c[2].w;
        if (g.perspective != 0u) {
            d = (b.x * c[0].w + b.y * c[1].w + b.z * c[2].w - g.near) / (g.far - g.near);
        }
        return vec3<f32>(1.0 - clamp(d, 0.0, 1.0));
    }
    let material = materials[t.w];
    var f: Frames;
    f.has[0] = (g.flags & 1u) != 0u;
    f.has[1] = (g.flags & 8u) != 0u;
    if (f.has[0] || f.has[1]) {
        let bx = barycentrics(c, s + vec2<f32>(1.0, 0.0));
        let by = barycentrics(c, s + vec2<f32>(0.0, 1.0));
        for (var k = 0u; k < 2u; k = k + 1u) {
            if (f.has[k]) {
                let at = select(16u, 8u, k == 0u);
                let uv = uv_at(v, b, at);
                f.uv[k] = uv;
                f.dx[k] = uv_at(v, bx, at) - uv;
                f.dy[k] = uv_at(v, by, at) - uv;
            }
        }
    }
    let tx = material_texels(material, f, g.shading == 6u);
    var albedo = material.base_color.xyz;
    if ((g.flags & 2u) != 0u) { albedo = albedo * interp3(v, 10u, b); }
    albedo = albedo * tx.t[0];
    if (g.shading == 0u) { return display(albedo); }
    var n = normalize_or_zero(interp3(v, 4u, b));
    if (g.shading == 6u) {
        let p = interp3(v, 0u, b);
        var view = g.to_eye.xyz;
        if (g.eye.w != 0.0) {
            let d = g.eye.xyz - p;
            if (length(d) > 0.0) { view = normalize(d); }
        }
        let p0 = vfetch3(v.x, 0u);
        let face = cross(vfetch3(v.y, 0u) - p0, vfetch3(v.z, 0u) - p0);
        if (material.emission.w != 0.0 && dot(face, view) < 0.0) { n = -n; }
        n = normal_mapped(material, v, b, f, n, tx.t[2]);
        let roughness = clamp(material.pbr.y * tx.t[1].y, 0.0, 1.0);
        let metallic = clamp(material.pbr.x * tx.t[1].z, 0.0, 1.0);
        var occlusion = 1.0;
        if (slot_present(material.slots[3], f)) {
            occlusion = 1.0 + material.pbr.w * (tx.t[3].x - 1.0);
        }
        let emission = material.emission.xyz * tx.t[4];
        return display(pbr_shade(albedo, metallic, roughness, n, view, p, occlusion, emission));
    }
    var terms: Terms;
    if (g.shading == 1u) {
        let t0 = vertex_terms(v.x);
        let t1 = vertex_terms(v.y);
        let t2 = vertex_terms(v.z);
        terms = Terms(
            t0.diffuse * b.x + t1.diffuse * b.y + t2.diffuse * b.z,
            t0.spec * b.x + t1.spec * b.y + t2.spec * b.z,
        );
    } else {
        if (g.shading == 3u) { n = normal_mapped(material, v, b, f, n, tx.t[2]); }
        terms = light_terms(n, material.specular.xyz, material.specular.w);
    }
    return display(albedo * terms.diffuse + terms.spec);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= g.width || gid.y >= g.height) { return; }
    let at = vec2<i32>(gid.xy);
    let s = g.samples;
    // (triangle, first sample, count) of the distinct triangles in this pixel.
    var ids: array<u32, MAX_SAMPLES>;
    var firsts: array<u32, MAX_SAMPLES>;
    var counts: array<u32, MAX_SAMPLES>;
    var groups = 0u;
    var empty = 0u;
    var depth = 0.0;
    for (var k = 0u; k < s; k = k + 1u) {
        let id = textureLoad(id_tex, at, i32(k), 0).x;
        if (id == NONE) {
            empty = empty + 1u;
            continue;
        }
        let d = textureLoad(depth_tex, at, i32(k), 0);
        // k == empty: the first covered sample.
        if (k == empty || d < depth) { depth = d; }
        var j = 0u;
        loop {
            if (j == groups) {
                ids[j] = id;
                firsts[j] = k;
                counts[j] = 1u;
                groups = groups + 1u;
                break;
            }
            if (ids[j] == id) {
                counts[j] = counts[j] + 1u;
                break;
            }
            j = j + 1u;
        }
    }
    var color = g.background.xyz * f32(empty);
    var best = NONE;
    var best_count = 0u;
    for (var j = 0u; j < groups; j = j + 1u) {
        let o = g.offsets[firsts[j]].xy;
        color = color + shade(ids[j], vec2<f32>(f32(gid.x) + o.x, f32(gid.y) + o.y)) * f32(counts[j]);
        if (counts[j] > best_count) {
            best = ids[j];
            best_count = counts[j];
        }
    }
    let i = gid.y * g.width + gid.x;
    out_color[i] = vec4<f32>(color / f32(s), f32(s - empty) / f32(s));
    var depth_bits = INFINITY_BITS;
    if (groups > 0u) { depth_bits = bitcast<u32>(depth); }
    out_aux[i] = vec2<u32>(depth_bits, best);
}
