// ꟻLIP pass 2 (src/metric/flip.rs, Flip::prepare, the horizontal halves of both separable
// filters, clamped borders): the CSF filters on (Y, Cx, Cz, Cz) — the blue–yellow channel as two
// √-weighted Gaussians — and the feature filters on the achromatic channel (first derivative,
// second derivative, Gaussian). Taps are the CPU's, computed on the host.

struct Dims {
    width: u32,
    height: u32,
    radius: u32,
    feature_radius: u32,
}

@group(0) @binding(0) var<uniform> dims: Dims;
@group(0) @binding(1) var<storage, read> ycxcz: array<vec4<f32>>;
// per tap: (Y weight, Cx weight, Cz first Gaussian, Cz second Gaussian)
@group(0) @binding(2) var<storage, read> spatial: array<vec4<f32>>;
// per tap: (Gaussian, first derivative, second derivative, 0)
@group(0) @binding(3) var<storage, read> features: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> mid_color: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> mid_features: array<vec4<f32>>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let x = i32(gid.x);
    let y = gid.y;
    if (gid.x >= dims.width || y >= dims.height) { return; }
    let w = i32(dims.width);
    let row = y * dims.width;
    var acc = vec4<f32>(0.0);
    let r = i32(dims.radius);
    for (var k = 0; k <= 2 * r; k = k + 1) {
        let c = ycxcz[row + u32(clamp(x + k - r, 0, w - 1))];
        let t = spatial[k];
        acc = acc + vec4<f32>(t.x * c.x, t.y * c.y, t.z * c.z, t.w * c.z);
    }
    var f = vec3<f32>(0.0);
    let fr = i32(dims.feature_radius);
    for (var k = 0; k <= 2 * fr; k = k + 1) {
        let v = ycxcz[row + u32(clamp(x + k - fr, 0, w - 1))].w;
        let t = features[k];
        f = f + vec3<f32>(t.y * v, t.z * v, t.x * v);
    }
    let i = row + gid.x;
    mid_color[i] = acc;
    mid_features[i] = vec4<f32>(f, 0.0);
}
