// The visibility pass of the GPU mirror: one draw per anti-aliasing sample, each into its own
// layer, the projection shifted so that the CPU's sample position (src/raster/mod.rs,
// SamplePattern) falls on the pixel centre. It writes only what the CPU's scan stage writes
// (src/raster/edge.rs): the nearest triangle id and its depth per sample. Shading happens in
// shade.wgsl, once per triangle per pixel, as on the CPU.
//
// Vertex pulling: `vertex_index` / 3 is the source triangle, so the id needs no extra feature.

struct Globals {
    mvp: mat4x4<f32>,
}

// This pass's sample: the clip-space shift that moves the sample position onto the pixel centre.
struct Jitter {
    ndc: vec2<f32>,
    pad: vec2<f32>,
}

// See render.rs: 18 floats per vertex, position first.
const VSTRIDE: u32 = 18u;

@group(0) @binding(0) var<uniform> g: Globals;
@group(0) @binding(1) var<storage, read> vertices: array<f32>;
@group(0) @binding(2) var<storage, read> tris: array<vec4<u32>>;
@group(0) @binding(3) var<uniform> jitter: Jitter;

struct VOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) tri: u32,
}

@vertex
fn vs(@builtin(vertex_index) vi: u32) -> VOut {
    let tri = vi / 3u;
    let b = tris[tri][vi % 3u] * VSTRIDE;
    let clip = g.mvp * vec4<f32>(vertices[b], vertices[b + 1u], vertices[b + 2u], 1.0);
    var out: VOut;
    // Depth and 1/w stay those of the unshifted projection; only the sample grid moves.
    out.clip = vec4<f32>(clip.xy + jitter.ndc * clip.w, clip.zw);
    out.tri = tri;
    return out;
}

@fragment
fn fs(in: VOut) -> @location(0) u32 {
    return in.tri;
}
