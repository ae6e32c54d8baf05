// ꟻLIP pass 1 (src/metric/flip.rs, Flip::prepare): linear RGB → YCxCz (Zhang & Wandell's
// linearised CIELAB, D65 with the reference implementation's white point digits), and the
// normalised achromatic channel for the feature detectors, (Y + 16)/116, in w.

struct Dims {
    width: u32,
    height: u32,
    radius: u32,
    pad: u32,
}

@group(0) @binding(0) var<uniform> dims: Dims;
@group(0) @binding(1) var<storage, read> image: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> ycxcz: array<vec4<f32>>;


@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= dims.width * dims.height) { return; }
    let c = rgb_to_xyz(image[i].xyz) * INV_WHITE;
    let y = 116.0 * c.y - 16.0;
    ycxcz[i] = vec4<f32>(y, 500.0 * (c.x - c.y), 200.0 * (c.y - c.z), y * (1.0 / 116.0) + 16.0 / 116.0);
}
