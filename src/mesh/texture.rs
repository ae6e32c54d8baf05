//! Decoded texture images and the shared texture cache used by the loaders.
//!
//! A texture is decoded once and shared by `Arc` between every material that names the same file
//! (the architecture contract in the README: "textures decoded once and shared"). Pixels stay 8-bit RGBA with their colour space
//! tagged; linearisation belongs to the renderer's mip-pyramid build (`raster/texture.rs`).
//!
//! Decision: texture file names from MTL files are resolved relative to the MTL file, with
//! Windows separators (`.\tex.jpg`) accepted and, when the exact name is absent, a file differing
//! only in letter case accepted too (assets authored on Windows often disagree on case).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{Error, Result};

/// How a texture's 8-bit values encode light.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ColorSpace {
    /// sRGB-encoded colour (base-colour / albedo textures).
    Srgb,
    /// Linear data (normal maps).
    Linear,
}

/// The file bytes a texture was decoded from, kept so that an exporter writes the image as the
/// input had it (a JPEG stays the same JPEG; a 16-bit PNG keeps its 16 bits).
#[derive(Debug, Clone, PartialEq)]
pub struct EncodedImage {
    /// The encoded bytes.
    pub bytes: Arc<[u8]>,
    /// `image/png` or `image/jpeg`.
    pub mime: &'static str,
    /// The image's name in the file (glTF `images[i].name`), or its file stem.
    pub name: Option<String>,
}

impl EncodedImage {
    /// The encoded image for `bytes` if they are a PNG or a JPEG (by their signature), else
    /// `None` (the exporter then writes the decoded texels as PNG).
    pub fn sniff(bytes: &[u8], name: Option<String>) -> Option<EncodedImage> {
        let mime = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
            "image/png"
        } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
            "image/jpeg"
        } else {
            return None;
        };
        Some(EncodedImage {
            bytes: bytes.into(),
            mime,
            name,
        })
    }
}

/// A decoded texture.
///
/// # Guarantees
/// - `width() >= 1`, `height() >= 1`, and `rgba().len() == 4 * width * height`.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    label: String,
    width: u32,
    height: u32,
    rgba: Vec<u8>,
    space: ColorSpace,
    encoded: Option<EncodedImage>,
}

impl Texture {
    /// A texture from RGBA8 pixels in row-major order, top row first; `None` if the sizes disagree
    /// or either dimension is zero.
    pub fn new(
        label: String,
        width: u32,
        height: u32,
        rgba: Vec<u8>,
        space: ColorSpace,
    ) -> Option<Texture> {
        let expected = (width as usize)
            .checked_mul(height as usize)?
            .checked_mul(4)?;
        (width >= 1 && height >= 1 && rgba.len() == expected).then_some(Texture {
            label,
            width,
            height,
            rgba,
            space,
            encoded: None,
        })
    }

    /// The texture with the file bytes it was decoded from.
    pub fn with_encoded(mut self, encoded: Option<EncodedImage>) -> Texture {
        self.encoded = encoded;
        self
    }

    /// The file bytes the texture was decoded from, where they were kept.
    pub fn encoded(&self) -> Option<&EncodedImage> {
        self.encoded.as_ref()
    }

    /// Whether any texel's alpha is below 255.
    pub fn has_alpha(&self) -> bool {
        self.rgba.chunks_exact(4).any(|p| p[3] < 255)
    }

    /// Where the texture came from (a path, or a glTF image index).
    pub fn label(&self) -> &str {
        &self.label
    }
    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }
    /// RGBA8 texels, row-major, top row first.
    pub fn rgba(&self) -> &[u8] {
        &self.rgba
    }
    /// Colour space of the stored values.
    pub fn color_space(&self) -> ColorSpace {
        self.space
    }

    /// Decode an in-memory image (PNG or JPEG), keeping its bytes for export.
    pub fn decode(
        label: &str,
        bytes: &[u8],
        space: ColorSpace,
    ) -> std::result::Result<Texture, String> {
        let img = image::load_from_memory(bytes).map_err(|e| e.to_string())?;
        let name = std::path::Path::new(label)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned());
        Ok(Texture::from_image(label, img, space)?.with_encoded(EncodedImage::sniff(bytes, name)))
    }

    /// Convert a decoded `image` into a texture.
    pub fn from_image(
        label: &str,
        img: image::DynamicImage,
        space: ColorSpace,
    ) -> std::result::Result<Texture, String> {
        let rgba = img.into_rgba8();
        let (w, h) = rgba.dimensions();
        Texture::new(label.to_string(), w, h, rgba.into_raw(), space)
            .ok_or_else(|| format!("the image has zero size ({w}x{h})"))
    }
}

/// Textures already decoded during one load, keyed by resolved path and colour space.
#[derive(Debug, Default)]
pub(crate) struct TextureCache {
    decoded: BTreeMap<(PathBuf, bool), Arc<Texture>>,
}

impl TextureCache {
    /// The files decoded so far, each once, in path order.
    pub fn paths(&self) -> Vec<PathBuf> {
        let mut p: Vec<PathBuf> = self.decoded.keys().map(|(p, _)| p.clone()).collect();
        p.dedup();
        p
    }

    /// Decode the image at `path` once; later calls return the same `Arc`.
    /// `referrer` is the file that named the texture, for the error message.
    pub fn load(
        &mut self,
        path: &Path,
        space: ColorSpace,
        referrer: &Path,
    ) -> Result<Arc<Texture>> {
        let key = (path.to_path_buf(), space == ColorSpace::Srgb);
        if let Some(t) = self.decoded.get(&key) {
            return Ok(t.clone());
        }
        // The error names the file that referred to the texture, and the texture in its text.
        let bytes = crate::io::read_input(
            path,
            "texture",
            crate::limits::IMAGE_BYTES,
            "put the image there, fix the path in the file, or pass --missing-assets warn to render with the base colour",
        )
        .map_err(|e| match e {
            Error::Input { problem, fix, .. } => Error::input(
                referrer,
                format!("texture '{}': {problem}", path.display()),
                fix,
            ),
            other => other,
        })?;
        let tex = Texture::decode(&path.display().to_string(), &bytes, space).map_err(|e| {
            Error::input(
                path,
                format!("texture cannot be decoded: {e}"),
                "re-save it as PNG or JPEG, or pass --missing-assets warn to render with the base colour",
            )
        })?;
        let tex = Arc::new(tex);
        self.decoded.insert(key, tex.clone());
        Ok(tex)
    }
}

/// Resolve a texture or library name written in a file: Windows separators become `/`, map
/// options (`-bm 0.5 file.png`) are skipped, and the result is relative to `base_dir`. If the exact
/// file does not exist but one differing only in letter case does, that one is returned.
pub(crate) fn resolve_asset_path(base_dir: &Path, written: &str) -> PathBuf {
    let mut name = written.trim();
    if name.starts_with('-') {
        // MTL map statements may carry options before the file name; the name is the last token.
        name = name.split_whitespace().last().unwrap_or(name);
    }
    let normalized = name.replace('\\', "/");
    let rel = normalized.trim_start_matches("./");
    let candidate = base_dir.join(rel);
    if candidate.exists() {
        return candidate;
    }
    let (Some(parent), Some(file)) = (candidate.parent(), candidate.file_name()) else {
        return candidate;
    };
    let Ok(entries) = std::fs::read_dir(parent) else {
        return candidate;
    };
    let mut matches: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().eq_ignore_ascii_case(file))
        .map(|e| e.path())
        .collect();
    // Sorted, so the choice does not depend on directory order.
    matches.sort();
    if let Some(first) = matches.into_iter().next() {
        return first;
    }
    candidate
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_size_texture_is_rejected() {
        assert!(Texture::new("x".into(), 0, 4, vec![], ColorSpace::Srgb).is_none());
        assert!(Texture::new("x".into(), 2, 2, vec![0; 15], ColorSpace::Srgb).is_none());
        assert!(Texture::new("x".into(), 2, 2, vec![0; 16], ColorSpace::Srgb).is_some());
    }

    #[test]
    fn windows_paths_and_options_resolve() {
        let dir = Path::new("/nonexistent-dir");
        assert_eq!(
            resolve_asset_path(dir, ".\\SpiderTex.jpg"),
            dir.join("SpiderTex.jpg")
        );
        assert_eq!(
            resolve_asset_path(dir, "-bm 0.5 tex\\n.png"),
            dir.join("tex/n.png")
        );
    }
}
