// Colour-space pieces shared by the ꟻLIP passes (src/metric/color.rs), prepended to
// flip_color.wgsl and flip_filter_y.wgsl by gpu/metric.rs (WGSL has no includes): D65 white with
// the FLIP reference implementation's digits, linear sRGB ↔ XYZ.

const WHITE: vec3<f32> = vec3<f32>(0.950428545, 1.0, 1.088900371);
const INV_WHITE: vec3<f32> = vec3<f32>(1.052156925, 1.0, 0.918357670);

fn rgb_to_xyz(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        (10135552.0 / 24577794.0) * c.x + (8788810.0 / 24577794.0) * c.y + (4435075.0 / 24577794.0) * c.z,
        (2613072.0 / 12288897.0) * c.x + (8788810.0 / 12288897.0) * c.y + (887015.0 / 12288897.0) * c.z,
        (1425312.0 / 73733382.0) * c.x + (8788810.0 / 73733382.0) * c.y + (70074185.0 / 73733382.0) * c.z,
    );
}

fn xyz_to_rgb(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        3.241003275 * c.x + -1.537398934 * c.y + -0.498615861 * c.z,
        -0.969224334 * c.x + 1.875930071 * c.y + 0.041554224 * c.z,
        0.055639423 * c.x + -0.204011202 * c.y + 1.057148933 * c.z,
    );
}
