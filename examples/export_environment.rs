//! Write an environment map lodeval lights with as OpenEXR (linear float RGB, equirectangular,
//! row 0 at the top, lodeval's orientation = Blender's world mapping), so another renderer can be
//! lit by exactly the same map: the built-in neutral room, which exists only as code, or any
//! `.hdr`/`.exr` after lodeval's checks.
//!
//! Usage: `cargo run --release --example export_environment -- neutral|axes|PATH OUT.exr`
//! (used by `reference/oracles/make_blender_pbr.py`). `axes` is an orientation test pattern:
//! red where x > 0, green where z > 0, blue where y > 0 (glTF's axes), 256 × 128.

use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [source, out] = args.as_slice() else {
        return Err("usage: export_environment neutral|PATH OUT.exr".into());
    };
    let env = if source == "axes" {
        let texels = (0..256 * 128)
            .map(|i| {
                let uv = glam::Vec2::new(
                    ((i % 256) as f32 + 0.5) / 256.0,
                    ((i / 256) as f32 + 0.5) / 128.0,
                );
                let d = lodeval::scene::Environment::direction_of(uv);
                glam::Vec3::new(
                    f32::from(u8::from(d.x > 0.0)),
                    f32::from(u8::from(d.z > 0.0)),
                    f32::from(u8::from(d.y > 0.0)),
                )
            })
            .collect();
        std::sync::Arc::new(
            lodeval::scene::Environment::from_texels("axes", 256, texels).ok_or("axes")?,
        )
    } else {
        lodeval::scene::Lighting::new(source, Path::new("."), 0.0, 1.0)?.environment
    };
    let px: Vec<f32> = env.texels().iter().flat_map(|t| t.to_array()).collect();
    let img = image::Rgb32FImage::from_raw(env.width() as u32, env.height() as u32, px)
        .ok_or("the map's size")?;
    image::DynamicImage::ImageRgb32F(img).save(out)?;
    println!("{} ({}×{}) → {out}", env.label(), env.width(), env.height());
    Ok(())
}
