//! The render cache (`eval --cache DIR`, off by default): the originals' frames of a run kept on
//! disk under a content hash of everything that decides them, so a nightly run over unchanged
//! assets renders only the LODs. What comes out of the cache is the frame's linear colour, the
//! only part of the original's frame a score or a contact sheet uses, so outputs are byte for
//! byte those of a run without it.
//!
//! The key (SHA-256) covers: the bytes of every file the mesh was loaded from (mesh, material
//! libraries, textures, glTF buffers), the scene (lights, background, ambient), the render
//! settings, the camera, the renderer's description, and this lodeval build (its version and the
//! size and time of its executable, so a rebuilt renderer never meets an old frame).
//!
//! Decisions:
//! - An entry proves it is what its key says: it holds its own key and the SHA-256 of its
//!   pixels, both checked on read. A swapped, linked, forged, truncated or foreign entry is a
//!   miss: the frame is rendered again and rewritten, and the run says once how many entries it
//!   did not trust.
//! - The cache is an optimisation, never a reason to fail: a folder that cannot be created or
//!   written (read-only, full) is a warning, and the run renders without it.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::Vec3;
use sha2::{Digest, Sha256};

use crate::error::Result;
use crate::raster::{RenderScene, RenderSettings};
use crate::scene::Camera;

/// Magic and version of an entry file.
const MAGIC: &[u8; 8] = b"LODEVRC2";

/// Magic, key, content hash: the header before the pixels.
const HEADER: usize = 8 + 32 + 32;

/// A cache folder and the part of the key every entry of this process shares.
#[derive(Debug)]
pub struct RenderCache {
    dir: PathBuf,
    build: Vec<u8>,
    /// Entries read and not trusted (wrong key, wrong content, wrong size).
    distrusted: AtomicUsize,
    /// The first failure to write an entry (later ones are not tried).
    unwritable: Mutex<Option<String>>,
}

/// An original's part of the key: its files' contents and its scene.
#[derive(Debug, Clone)]
pub struct SceneKey(Vec<u8>);

impl RenderCache {
    /// The cache in `dir` (created if missing), or `None` with a warning where it cannot be
    /// created: the run renders without it.
    pub fn open(dir: &Path) -> (Option<RenderCache>, Option<String>) {
        if let Err(e) = std::fs::create_dir_all(dir) {
            return (
                None,
                Some(format!(
                    "render cache {}: cannot create the folder ({e}); rendering without it",
                    dir.display()
                )),
            );
        }
        let mut build = env!("CARGO_PKG_VERSION").as_bytes().to_vec();
        if let Ok(meta) = std::env::current_exe().and_then(std::fs::metadata) {
            build.extend_from_slice(&meta.len().to_le_bytes());
            if let Ok(t) = meta.modified()
                && let Ok(d) = t.duration_since(std::time::UNIX_EPOCH)
            {
                build.extend_from_slice(&d.as_nanos().to_le_bytes());
            }
        }
        let cache = RenderCache {
            dir: dir.to_path_buf(),
            build,
            distrusted: AtomicUsize::new(0),
            unwritable: Mutex::new(None),
        };
        (Some(cache), None)
    }

    /// What the run should be told about the cache, once: entries not trusted, writes that
    /// failed.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        let n = self.distrusted.load(Ordering::Relaxed);
        if n > 0 {
            out.push(format!(
                "render cache {}: {n} entries did not prove to be the frames their keys name \
                 (swapped, linked, edited or truncated); they were rendered again and rewritten",
                self.dir.display()
            ));
        }
        if let Some(e) = self.unwritable.lock().ok().and_then(|u| u.clone()) {
            out.push(format!(
                "render cache {}: cannot write an entry ({e}); the rest of the run renders \
                 without storing frames",
                self.dir.display()
            ));
        }
        out
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
        // Levels of one glTF MSFT_lod chain share every file: the level tells them apart.
        if let Some(chain) = &mesh.source().lod_chain {
            h.update(format!("MSFT_lod level {:?}", chain.level.unwrap_or(0)).as_bytes());
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

    /// The entry's key (SHA-256 of everything that decides the frame) and its file.
    fn key(
        &self,
        scene: &SceneKey,
        settings: &RenderSettings,
        camera: &Camera,
        renderer: &str,
    ) -> ([u8; 32], PathBuf) {
        let mut h = Sha256::new();
        h.update(&self.build);
        h.update(&scene.0);
        h.update(format!("{settings:?}|{camera:?}|{renderer}").as_bytes());
        let key: [u8; 32] = h.finalize().into();
        let hex: String = key.iter().map(|b| format!("{b:02x}")).collect();
        (key, self.dir.join(&hex[..2]).join(format!("{hex}.frame")))
    }

    /// The cached colour of a frame, if an entry proves to be it.
    pub fn get(
        &self,
        scene: &SceneKey,
        settings: &RenderSettings,
        camera: &Camera,
        renderer: &str,
    ) -> Option<Vec<Vec3>> {
        let n = (settings.width as usize).checked_mul(settings.height as usize)?;
        let size = n.checked_mul(12)?.checked_add(HEADER)?;
        let (key, path) = self.key(scene, settings, camera, renderer);
        if std::fs::symlink_metadata(&path).is_err() {
            return None; // not there: a plain miss
        }
        // Through the bounded reader of regular files: a planted FIFO or an oversized file is a
        // miss, never a hang or an unbounded read.
        let bytes =
            crate::io::read_input(&path, "render cache entry", size as u64, "delete the cache")
                .ok();
        let trusted = bytes.as_deref().filter(|b| {
            b.len() == size
                && &b[..8] == MAGIC
                && b[8..40] == key
                && b[40..72] == <[u8; 32]>::from(Sha256::digest(&b[HEADER..]))
        });
        let Some(bytes) = trusted else {
            self.distrusted.fetch_add(1, Ordering::Relaxed);
            return None;
        };
        let f = |i: usize| f32::from_le_bytes(bytes[i..i + 4].try_into().unwrap_or([0; 4]));
        let px: Vec<Vec3> = (0..n)
            .map(|k| {
                let o = HEADER + 12 * k;
                Vec3::new(f(o), f(o + 4), f(o + 8))
            })
            .collect();
        if px.iter().all(|p| p.is_finite()) {
            Some(px)
        } else {
            self.distrusted.fetch_add(1, Ordering::Relaxed);
            None
        }
    }

    /// Keep a frame's colour. A failure is remembered for [`RenderCache::warnings`], and no
    /// later entry is tried.
    pub fn put(
        &self,
        scene: &SceneKey,
        settings: &RenderSettings,
        camera: &Camera,
        renderer: &str,
        color: &[Vec3],
    ) {
        match self.unwritable.lock() {
            Ok(u) if u.is_none() => {}
            _ => return, // an earlier write failed: said once, not tried again
        }
        let (key, path) = self.key(scene, settings, camera, renderer);
        let mut pixels = Vec::with_capacity(color.len() * 12);
        for p in color {
            for v in p.to_array() {
                pixels.extend_from_slice(&v.to_le_bytes());
            }
        }
        let mut bytes = Vec::with_capacity(HEADER + pixels.len());
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&key);
        bytes.extend_from_slice(&Sha256::digest(&pixels));
        bytes.extend_from_slice(&pixels);
        // A link planted where the entry goes is replaced, never written through.
        let _ = std::fs::remove_file(&path);
        // The lock is not held while writing: threads store their frames side by side.
        if let Err(e) = crate::io::write_atomic(&path, &bytes)
            && let Ok(mut u) = self.unwritable.lock()
        {
            u.get_or_insert(e.to_string());
        }
    }
}
