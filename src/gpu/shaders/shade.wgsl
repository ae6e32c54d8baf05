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
// textures are the CPU's mip pyramids sampled with its trilinear formula (texture.rs).

const MAX_LIGHTS: u32 = 8u;
const MAX_SAMPLES: u32 = 64u;
const NONE: u32 = 0xffffffffu;
const INFINITY_BITS: u32 = 0x7f800000u;
// See render.rs: position (0..3), material index (3, bits), normal (4..7), tangent handedness (7),
// uv (8..10), colour (10..13), tangent (13..16).
const VSTRIDE: u32 = 16u;

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
}

struct Material {
    base_color: vec4<f32>,
    // rgb: specular colour K_s, w: shininess n
    specular: vec4<f32>,
    // first level and level count of the base-colour texture, then of the normal map (count 0: none)
    tex: vec4<u32>,
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
// Texels in up to four pages, each within one storage binding's size limit.
@group(0) @binding(5) var<storage, read> page0: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> page1: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> page2: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read> page3: array<vec4<f32>>;
@group(0) @binding(9) var id_tex: texture_2d_array<u32>;
@group(0) @binding(10) var depth_tex: texture_depth_2d_array;
@group(0) @binding(11) var<storage, read_write> out_color: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read_write> out_aux: array<vec2<u32>>;

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

fn wrap(i: f32, n: u32) -> u32 {
    let m = i32(n);
    let k = i32(i) % m;
    return u32(select(k, k + m, k < 0));
}

fn texel(l: Level, x: u32, y: u32) -> vec3<f32> {
    let i = l.offset + y * l.width + x;
    switch l.page {
        case 0u: { return page0[i].xyz; }
        case 1u: { return page1[i].xyz; }
        case 2u: { return page2[i].xyz; }
        default: { return page3[i].xyz; }
    }
}

// glam's lerp: a + (b − a)·t.
fn lerp3(a: vec3<f32>, b: vec3<f32>, t: f32) -> vec3<f32> {
    return a + (b - a) * t;
}

// Bilinear with repeat wrapping; texel centres at half-integers; v = 0 is the bottom row.
fn bilinear(l: Level, uv: vec2<f32>) -> vec3<f32> {
    let x = uv.x * f32(l.width) - 0.5;
    let y = (1.0 - uv.y) * f32(l.height) - 0.5;
    let fx = floor(x);
    let fy = floor(y);
    let tx = x - fx;
    let ty = y - fy;
    let x0 = wrap(fx, l.width);
    let x1 = wrap(fx + 1.0, l.width);
    let y0 = wrap(fy, l.height);
    let y1 = wrap(fy + 1.0, l.height);
    let top = lerp3(texel(l, x0, y0), texel(l, x1, y0), tx);
    let bottom = lerp3(texel(l, x0, y1), texel(l, x1, y1), tx);
    return lerp3(top, bottom, ty);
}

// Trilinear sample, level from the larger UV derivative in texels (OpenGL 4.6 §8.14).
fn sample_tex(first: u32, count: u32, uv: vec2<f32>, dx: vec2<f32>, dy: vec2<f32>) -> vec3<f32> {
    let base = levels[first];
    let size = vec2<f32>(f32(base.width), f32(base.height));
    let rho = max(length(dx * size), length(dy * size));
    var lod = 0.0;
    if (rho > 1.0) { lod = log2(rho); }
    lod = clamp(lod, 0.0, f32(count - 1u));
    let l0 = u32(floor(lod));
    let frac = lod - f32(l0);
    let a = bilinear(levels[first + l0], uv);
    if (frac == 0.0 || l0 + 1u >= count) { return a; }
    return lerp3(a, bilinear(levels[first + l0 + 1u], uv), frac);
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

fn uv_at(v: vec3<u32>, b: vec3<f32>) -> vec2<f32> {
    let uv0 = vec2<f32>(vertices[v.x * VSTRIDE + 8u], vertices[v.x * VSTRIDE + 9u]);
    let uv1 = vec2<f32>(vertices[v.y * VSTRIDE + 8u], vertices[v.y * VSTRIDE + 9u]);
    let uv2 = vec2<f32>(vertices[v.z * VSTRIDE + 8u], vertices[v.z * VSTRIDE + 9u]);
    return uv0 * b.x + uv1 * b.y + uv2 * b.z;
}

fn vertex_terms(v: u32) -> Terms {
    let m = materials[bitcast<u32>(vertices[v * VSTRIDE + 3u])];
    return light_terms(vfetch3(v, 4u), m.specular.xyz, m.specular.w);
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
    let has_uv = (g.flags & 1u) != 0u;
    var uv = vec2<f32>(0.0);
    var dx = vec2<f32>(0.0);
    var dy = vec2<f32>(0.0);
    if (has_uv) {
        uv = uv_at(v, b);
        dx = uv_at(v, barycentrics(c, s + vec2<f32>(1.0, 0.0))) - uv;
        dy = uv_at(v, barycentrics(c, s + vec2<f32>(0.0, 1.0))) - uv;
    }
    var albedo = material.base_color.xyz;
    if ((g.flags & 2u) != 0u) { albedo = albedo * interp3(v, 10u, b); }
    if (has_uv && material.tex.y > 0u) {
        albedo = albedo * sample_tex(material.tex.x, material.tex.y, uv, dx, dy);
    }
    if (g.shading == 0u) { return albedo; }
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
        var n = normalize_or_zero(interp3(v, 4u, b));
        if (g.shading == 3u && has_uv && material.tex.w > 0u && (g.flags & 4u) != 0u) {
            let t3 = interp3(v, 13u, b);
            let tw = vertices[v.x * VSTRIDE + 7u] * b.x + vertices[v.y * VSTRIDE + 7u] * b.y
                + vertices[v.z * VSTRIDE + 7u] * b.z;
            let tt = normalize_or_zero(t3 - n * dot(n, t3));
            var sign = 1.0;
            if (tw < 0.0) { sign = -1.0; }
            let bitangent = cross(n, tt) * sign;
            let m = sample_tex(material.tex.z, material.tex.w, uv, dx, dy) * 2.0 - 1.0;
            let pert = tt * m.x + bitangent * m.y + n * m.z;
            let l = length(pert);
            if (l > 0.0) { n = pert / l; }
        }
        terms = light_terms(n, material.specular.xyz, material.specular.w);
    }
    return albedo * terms.diffuse + terms.spec;
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
