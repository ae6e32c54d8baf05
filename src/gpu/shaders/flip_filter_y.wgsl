// ꟻLIP pass 3 (src/metric/flip.rs, Flip::prepare, the vertical halves): finishes the CSF filter
// and maps the result back to linear RGB (clamped to [0, 1]), CIELAB and Hunt-adjusted CIELAB;
// finishes the feature filters into edge and point magnitudes.

struct Dims {
    width: u32,
    height: u32,
    radius: u32,
    feature_radius: u32,
}

@group(0) @binding(0) var<uniform> dims: Dims;
@group(0) @binding(1) var<storage, read> mid_color: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> mid_features: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> spatial: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> features: array<vec4<f32>>;
// Hunt-adjusted L, a, b, and the (edge, point) feature magnitudes
@group(0) @binding(5) var<storage, read_write> lab: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> feat: array<vec2<f32>>;


fn lab_f(v: f32) -> f32 {
    let delta = 6.0 / 29.0;
    let delta_cube = delta * delta * delta;
    if (v > delta_cube) { return pow(v, 1.0 / 3.0); }
    return (1.0 / (3.0 * delta * delta)) * v + 4.0 / 29.0;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let y = i32(gid.y);
    if (gid.x >= dims.width || gid.y >= dims.height) { return; }
    let h = i32(dims.height);
    let w = dims.width;
    var acc = vec4<f32>(0.0);
    let r = i32(dims.radius);
    for (var k = 0; k <= 2 * r; k = k + 1) {
        let m = mid_color[u32(clamp(y + k - r, 0, h - 1)) * w + gid.x];
        acc = acc + spatial[k] * m;
    }
    let filtered = vec3<f32>(acc.x, acc.y, acc.z + acc.w);
    let yy = (filtered.x + 16.0) / 116.0;
    let xyz = vec3<f32>(yy + filtered.y / 500.0, yy, yy - filtered.z / 200.0) * WHITE;
    let rgb = clamp(xyz_to_rgb(xyz), vec3<f32>(0.0), vec3<f32>(1.0));
    let c = rgb_to_xyz(rgb) * INV_WHITE;
    let fx = lab_f(c.x);
    let fy = lab_f(c.y);
    let fz = lab_f(c.z);
    let l = 116.0 * fy - 16.0;
    let i = gid.y * w + gid.x;
    lab[i] = vec4<f32>(l, 0.01 * l * (500.0 * (fx - fy)), 0.01 * l * (200.0 * (fy - fz)), 0.0);

    var dx = 0.0;
    var ddx = 0.0;
    var dy = 0.0;
    var ddy = 0.0;
    let fr = i32(dims.feature_radius);
    for (var k = 0; k <= 2 * fr; k = k + 1) {
        let m = mid_features[u32(clamp(y + k - fr, 0, h - 1)) * w + gid.x];
        let t = features[k];
        dx = dx + t.x * m.x;
        ddx = ddx + t.x * m.y;
        dy = dy + t.y * m.z;
        ddy = ddy + t.z * m.z;
    }
    feat[i] = vec2<f32>(sqrt(dx * dx + dy * dy), sqrt(ddx * ddx + ddy * ddy));
}
