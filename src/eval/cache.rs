//! The render cache (`eval --cache DIR`, off by default): the originals' frames of a run kept on
//! disk under a content hash of everything that decides them, so a nightly run over unchanged
//! assets renders only the LODs. What comes out of the cache is the frame's linear colour, the
//! only part of the original's frame a score or a contact sheet uses, so outputs are byte for
//! byte those of a run without it.
//!
//! The key (SHA-256) covers: the bytes of every file the mesh was loaded from (mesh, material
//! libraries, textures, glTF buffers), the scene (lights, background, ambient), the render
//! settings, the camera, the renderer's description, and this lodeval build (its version and the
//! size and time of its executable, so a rebuilt renderer never meets an old frame). An entry
//! that cannot be read back whole is a miss: it is rendered again and rewritten.

use std::path::{Path, PathBuf};

use glam::Vec3;
use sha2::{Digest, Sha256};

use crate::error::{Error, Result};
use crate::raster::{RenderScene, RenderSettings};
use crate::scene::Camera;

/// Magic and version of an entry file.
const MAGIC: &[u8; 8] = b"LODEVRC1";

/// A cache folder and the part of the key every entry of this process shares.
#[derive(Debug, Clone)]
pub struct RenderCache {
    dir: PathBuf,
    build: Vec<u8>,
}

/// An original's part of the key: its files' contents and its scene.
#[derive(Debug, Clone)]
pub struct SceneKey(Vec<u8>);

impl RenderCache {
    /// The cache in `dir` (created if missing).
    pub fn open(dir: &Path) -> Result<RenderCache> {
        std::fs::create_dir_all(dir).map_err(|e| {
            Error::input(
                dir,
                format!("cannot create the render cache folder: {e}"),
                "give a --cache folder you can write to",
            )
        })?;
        let mut build = env!("CARGO_PKG_VERSION").as_bytes().to_vec();
        if let Ok(meta) = std::env::current_exe().and_then(std::fs::metadata) {
            build.extend_from_slice(&meta.len().to_le_bytes());
            if let Ok(t) = meta.modified()
                && let Ok(d) = t.duration_since(std::time::UNIX_EPOCH)
            {
                build.extend_from_slice(&d.as_nanos().to_le_bytes());
            }
        }
        Ok(RenderCache {
            dir: dir.to_path_buf(),
            build,
        })
    }

    /// The key part of `scene` (hashes the files it was loaded from).
    pub fn scene_key(&self, scene: &RenderScene) -> Result<SceneKey> {
        let mut h = Sha256::new();
        let mesh = scene.scene().mesh();
        for f in &mesh.source().files {
            let bytes = crate::io::read_input(
                f,
                "cached mesh input",
                crate::limits::MESH_BYTES,
                "check the file",
            )?;
            h.update(f.to_string_lossy().as_bytes());
            h.update((bytes.len() as u64).to_le_bytes());
            h.update(&bytes);
        }
        let s = scene.scene();
        h.update(
            format!(
                "{:?}|{:?}|{:?}|{}|{}|{}",
                s.lights,
                s.background,
                s.ambient,
                s.environment.key(),
                s.environment_rotation_deg,
                s.environment_intensity
            )
            .as_bytes(),
        );
        Ok(SceneKey(h.finalize().to_vec()))
    }

    fn path(
        &self,
        scene: &SceneKey,
        settings: &RenderSettings,
        camera: &Camera,
        renderer: &str,
    ) -> PathBuf {
        let mut h = Sha256::new();
        h.update(&self.build);
        h.update(&scene.0);
        h.update(format!("{settings:?}|{camera:?}|{renderer}").as_bytes());
        let hex: String = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
        self.dir.join(&hex[..2]).join(format!("{hex}.frame"))
    }

    /// The cached colour of a frame, if there is a whole one.
    pub fn get(
        &self,
        scene: &SceneKey,
        settings: &RenderSettings,
        camera: &Camera,
        renderer: &str,
    ) -> Option<Vec<Vec3>> {
        let n = (settings.width as usize).checked_mul(settings.height as usize)?;
        let size = n.checked_mul(12)?.checked_add(8)?;
        // Through the bounded reader of regular files: a planted FIFO or an oversized file is a
        // miss, never a hang or an unbounded read.
        let bytes = crate::io::read_input(
            &self.path(scene, settings, camera, renderer),
            "render cache entry",
            size as u64,
            "delete the cache folder",
        )
        .ok()?;
        if bytes.len() != size || &bytes[..8] != MAGIC {
            return None;
        }
        let f = |i: usize| f32::from_le_bytes(bytes[i..i + 4].try_into().unwrap_or([0; 4]));
        let px: Vec<Vec3> = (0..n)
            .map(|k| {
                let o = 8 + 12 * k;
                Vec3::new(f(o), f(o + 4), f(o + 8))
            })
            .collect();
        px.iter().all(|p| p.is_finite()).then_some(px)
    }

    /// Keep a frame's colour.
    pub fn put(
        &self,
        scene: &SceneKey,
        settings: &RenderSettings,
        camera: &Camera,
        renderer: &str,
        color: &[Vec3],
    ) -> Result<()> {
        let mut bytes = Vec::with_capacity(8 + color.len() * 12);
        bytes.extend_from_slice(MAGIC);
        for p in color {
            for v in p.to_array() {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
        crate::io::write_atomic(&self.path(scene, settings, camera, renderer), &bytes)
    }
}
