// MSE kernel (src/metric/mse.rs): per image row, the sum of squared Rec. 709 luminance differences,
// compensated (Kahan) in f32; the host adds the rows in order in f64.

struct Dims {
    width: u32,
    height: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> dims: Dims;
@group(0) @binding(1) var<storage, read> a: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> b: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> rows: array<f32>;

fn luminance(c: vec3<f32>) -> f32 {
    return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let y = gid.x;
    if (y >= dims.height) { return; }
    var sum = 0.0;
    var carry = 0.0;
    for (var x = 0u; x < dims.width; x = x + 1u) {
        let i = y * dims.width + x;
        let d = luminance(a[i].xyz) - luminance(b[i].xyz);
        let term = d * d - carry;
        let next = sum + term;
        carry = (next - sum) - term;
        sum = next;
    }
    rows[y] = sum;
}
