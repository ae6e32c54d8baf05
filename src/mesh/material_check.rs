//! The material rules every loader's output is held to: each factor finite and inside the range
//! the glTF 2.0 specification gives it (§3.9.2 and §5.19: base colour, metallic, roughness,
//! occlusion strength and emissive in 0..1; alpha cutoff ≥ 0; `KHR_materials_emissive_strength`
//! ≥ 0; the normal scale finite), and the Blinn–Phong fields finite and non-negative.
//!
//! Decision: an out-of-range factor is an input error, not clamped: a metallic factor of 7 is a
//! broken export, and rendering it as 1 would score a different asset from the one the user ships.
//! The message names the material and the glTF property (or the MTL key for Blinn–Phong fields).

use std::path::Path;

use super::Material;
use crate::error::{Error, Location, Result};

const FIX: &str = "set the value inside its range in the authoring tool and re-export \
                   (glTF 2.0 §3.9: factors lie in 0..1)";

/// Check every material of a mesh loaded from `path`.
pub(crate) fn check(path: &Path, materials: &[Material]) -> Result<()> {
    for m in materials {
        check_one(path, m)?;
    }
    Ok(())
}

fn check_one(path: &Path, m: &Material) -> Result<()> {
    let bad = |what: &str, value: String, range: &str| {
        Err(Error::input_at(
            path,
            Location::Element(format!("material '{}'", m.name)),
            format!("{what} is {value}, outside {range}"),
            FIX,
        ))
    };
    let unit = |v: f32| v.is_finite() && (0.0..=1.0).contains(&v);
    let c = m.base_color;
    for (what, values) in [
        ("baseColorFactor", vec![c.x, c.y, c.z, m.base_alpha]),
        ("metallicFactor", vec![m.metallic]),
        ("roughnessFactor", vec![m.roughness]),
        ("occlusionTexture.strength", vec![m.occlusion_strength]),
        ("emissiveFactor", m.emissive.to_array().to_vec()),
    ] {
        if !values.iter().all(|&v| unit(v)) {
            return bad(what, format!("{values:?}"), "0..1");
        }
    }
    let non_negative = |v: f32| v.is_finite() && v >= 0.0;
    if !non_negative(m.alpha_cutoff) {
        return bad("alphaCutoff", m.alpha_cutoff.to_string(), "0..∞");
    }
    if !non_negative(m.emissive_strength) {
        return bad(
            "KHR_materials_emissive_strength.emissiveStrength",
            m.emissive_strength.to_string(),
            "0..∞",
        );
    }
    if !m.normal_scale.is_finite() {
        return bad(
            "normalTexture.scale",
            m.normal_scale.to_string(),
            "the finite numbers",
        );
    }
    let s = m.specular;
    if ![s.x, s.y, s.z, m.shininess]
        .iter()
        .all(|&v| non_negative(v))
    {
        return bad(
            "the specular colour (Ks) or exponent (Ns)",
            format!("{:?}, {}", s.to_array(), m.shininess),
            "0..∞",
        );
    }
    for (slot, t) in m.slots() {
        if let Some(tr) = t.and_then(|t| t.transform)
            && !(tr.offset.is_finite() && tr.rotation.is_finite() && tr.scale.is_finite())
        {
            return bad(
                &format!("{slot}'s KHR_texture_transform"),
                format!("{tr:?}"),
                "the finite numbers",
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn a_metallic_factor_of_seven_or_nan_is_refused_naming_the_material() {
        for bad in [7.0, f32::NAN, -0.5] {
            let mut m = Material::metallic_roughness("visor", Vec3::ONE, 0.0, 0.5);
            m.metallic = bad;
            let e = check(Path::new("helmet.gltf"), &[m])
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("helmet.gltf") && e.contains("material 'visor'"),
                "{e}"
            );
            assert!(e.contains("metallicFactor"), "{e}");
        }
        let good = Material::metallic_roughness("visor", Vec3::ONE, 1.0, 0.0);
        assert!(check(Path::new("helmet.gltf"), &[good]).is_ok());
    }
}
