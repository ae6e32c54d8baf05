// ꟻLIP pass 4 (src/metric/flip.rs, Flip::compare_prepared): per pixel, the HyAB colour difference
// raised to qc = 0.7 and remapped with the knee at pc·cmax (pc = 0.4, pt = 0.95), the feature
// difference (max of edge and point differences / √2)^qf (qf = 0.5), and the error
// ΔE_c^(1 − ΔE_f) (paper eq. 11).

struct Params {
    count: u32,
    cmax: f32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> p: Params;
@group(0) @binding(1) var<storage, read> lab_a: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> feat_a: array<vec2<f32>>;
@group(0) @binding(3) var<storage, read> lab_b: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> feat_b: array<vec2<f32>>;
@group(0) @binding(5) var<storage, read_write> map: array<f32>;

const QC: f32 = 0.7;
const PC: f32 = 0.4;
const PT: f32 = 0.95;
const QF: f32 = 0.5;

// x^y as Rust's powf at the ends WGSL leaves undefined: x^0 = 1, 0^y = 0 (y > 0).
fn powf(x: f32, y: f32) -> f32 {
    if (y == 0.0) { return 1.0; }
    if (x <= 0.0) { return 0.0; }
    return pow(x, y);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= p.count) { return; }
    let a = lab_a[i].xyz;
    let b = lab_b[i].xyz;
    let hyab = abs(a.x - b.x) + sqrt((a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
    var dc = powf(hyab, QC);
    let pccmax = PC * p.cmax;
    if (dc < pccmax) {
        dc = dc * (PT / pccmax);
    } else {
        dc = PT + ((dc - pccmax) / (p.cmax - pccmax)) * (1.0 - PT);
    }
    let fa = feat_a[i];
    let fb = feat_b[i];
    let df = powf((1.0 / sqrt(2.0)) * max(abs(fa.x - fb.x), abs(fa.y - fb.y)), QF);
    map[i] = powf(dc, 1.0 - df);
}
