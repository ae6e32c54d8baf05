//! [`LumaViews`]: the luminance images of all views, and the trial, commit and revert the
//! optimizer calls, spread over the crew (see the parent module).

use super::*;

impl LumaViews {
    /// Render `mesh` (with the materials, lights, ambient term and background of `scene`) from
    /// `cameras` at `width`×`height`. `targets` are the images ŷ the energy compares against (one
    /// per camera); `None` compares against the images themselves (energy zero), which is how the
    /// targets are made: render the original and take [`LumaViews::images`].
    pub fn new(
        mesh: &Adjacency,
        scene: &RenderScene,
        cameras: &[Camera],
        width: u32,
        height: u32,
        targets: Option<Vec<Vec<u16>>>,
    ) -> Result<LumaViews> {
        if width == 0 || height == 0 || width > 4096 || height > 4096 {
            return Err(Error::Usage(format!(
                "optimizer image size {width}x{height} is outside 1..4096 pixels per side"
            )));
        }
        let n = (width * height) as usize;
        if let Some(t) = &targets
            && (t.len() != cameras.len() || t.iter().any(|t| t.len() != n))
        {
            return Err(Error::Usage(
                "target images do not match the views (count or size)".into(),
            ));
        }
        let encode: Vec<u16> = (0..=65535).map(encode_code).collect();
        let materials = scene
            .mesh()
            .materials()
            .iter()
            .zip(&scene.prepared().materials)
            .map(|(m, p)| LumaMaterial {
                base_color: m.base_color,
                specular: m.specular,
                shininess: m.shininess,
                texture: p.base.as_ref().map(|s| s.mip.clone()),
            })
            .collect();
        let mut shared = Shared {
            width,
            height,
            materials,
            ambient: scene.ambient,
            background: 0,
            encode,
        };
        shared.background = shared.luma(scene.background);
        let mut wedge_material = vec![u32::MAX; mesh.wedges.len()];
        for t in mesh.live_triangles() {
            for w in mesh.corners(t) {
                if wedge_material[w as usize] == u32::MAX {
                    wedge_material[w as usize] = mesh.material(t);
                }
            }
        }
        let mut targets = targets.map(|t| t.into_iter());
        let mut views: Vec<View> = cameras
            .iter()
            .map(|camera| {
                let target = targets.as_mut().and_then(|t| t.next());
                View::blank(camera, scene, &shared, target)
            })
            .collect();
        // The first render is a trial that changes everything.
        let all_v: Vec<u32> = (0..mesh.positions.len() as u32).collect();
        let all_w: Vec<u32> = (0..mesh.wedges.len() as u32).collect();
        let all_t: Vec<u32> = (0..mesh.triangle_slots() as u32).collect();
        let change = Change {
            vertices: &all_v,
            wedges: &all_w,
            triangles: &all_t,
            reshaded: &[],
        };
        let shared_ref = &shared;
        let wm = &wedge_material;
        let compare_with_self = targets.is_none();
        views.par_iter_mut().for_each(|v| {
            with_scratch(|s| {
                v.trial(shared_ref, mesh, wm, &change, true, s);
                v.commit(shared_ref, mesh, &change, s);
            });
            if compare_with_self {
                v.px.iter_mut().for_each(|p| p.target = p.current);
            }
        });
        Ok(LumaViews {
            shared,
            views,
            wedge_material,
            pending: false,
            pending_triangles: Vec::new(),
            pending_reshaded: Vec::new(),
            crew: None,
        })
    }

    /// The luminance images of `mesh` from `cameras`, as [`LumaViews::new`] then
    /// [`LumaViews::images`] make them (the same codes), holding one view's state per thread
    /// instead of every view's (a dense original's pieces take tens of MB per view).
    pub fn images_of(
        mesh: &Adjacency,
        scene: &RenderScene,
        cameras: &[Camera],
        width: u32,
        height: u32,
    ) -> Result<Vec<Vec<u16>>> {
        cameras
            .par_iter()
            .map(|camera| {
                let one = LumaViews::new(
                    mesh,
                    scene,
                    std::slice::from_ref(camera),
                    width,
                    height,
                    None,
                )?;
                Ok(one.images().swap_remove(0))
            })
            .collect()
    }

    /// Number of views.
    pub fn view_count(&self) -> usize {
        self.views.len()
    }

    /// Image width and height.
    pub fn size(&self) -> (u32, u32) {
        (self.shared.width, self.shared.height)
    }

    /// The current luminance images, row-major, one per view.
    pub fn images(&self) -> Vec<Vec<u16>> {
        self.views
            .iter()
            .map(|v| v.px.iter().map(|p| p.current).collect())
            .collect()
    }

    /// Current and target luminance of each pixel of view `h`, row-major.
    pub fn view_pixels(&self, h: usize) -> impl Iterator<Item = (u16, u16)> + '_ {
        self.views[h].px.iter().map(|p| (p.current, p.target))
    }

    /// The view's model-view-projection matrix (for projecting mesh points onto its images).
    pub fn view_matrix(&self, h: usize) -> Mat4 {
        self.views[h].mvp
    }

    /// The energy E = Σ_h Σ_ij (ŷ − y)² of the committed state, in squared 16-bit codes (eq. 1
    /// without the 1/(l·m·n) factor; see [`LumaViews::d_ms`]).
    pub fn energy(&self) -> i64 {
        self.views
            .iter()
            .map(|v| v.px.iter().map(|p| sq(p.target, p.current)).sum::<i64>())
            .sum()
    }

    /// Eq. 1's mean-square difference d_MS for an energy, with luminance scaled to [0, 1].
    pub fn d_ms(&self, energy: i64) -> f64 {
        let lmn = self.views.len() as f64 * self.shared.width as f64 * self.shared.height as f64;
        energy as f64 / (65535.0 * 65535.0) / lmn
    }

    /// Evaluate a change of `mesh` against the committed state: re-render the affected rectangle
    /// of every view and return ΔE (eq. 2). The trial stays pending until [`LumaViews::commit`] or
    /// [`LumaViews::revert`]; a new trial reverts a pending one first.
    pub fn trial(&mut self, mesh: &Adjacency, change: &Change) -> i64 {
        // A pending trial is reverted by each view at the start of its new one, on the crew's
        // threads (reverting all twenty here took 1.3 % of the calling thread's time, while the
        // other thread waited).
        let revert_first = std::mem::take(&mut self.pending);
        for &w in change.wedges {
            let w = w as usize;
            if w >= self.wedge_material.len() {
                self.wedge_material.resize(w + 1, u32::MAX);
            }
        }
        for &t in change.triangles {
            if mesh.is_alive(t) {
                for w in mesh.corners(t) {
                    let m = &mut self.wedge_material[w as usize];
                    if *m == u32::MAX {
                        *m = mesh.material(t);
                    }
                }
            }
        }
        self.pending = true;
        self.pending_triangles.clear();
        self.pending_triangles.extend_from_slice(change.triangles);
        self.pending_reshaded.clear();
        self.pending_reshaded.extend_from_slice(change.reshaded);
        let LumaViews {
            shared,
            views,
            wedge_material: wm,
            crew,
            ..
        } = self;
        let total = std::sync::atomic::AtomicI64::new(0);
        each_view(crew, views, &|v| {
            if revert_first {
                v.revert();
            }
            let d = with_scratch(|s| v.trial(shared, mesh, wm, change, false, s));
            total.fetch_add(d, std::sync::atomic::Ordering::Relaxed);
        });
        // Integer sums: the same total in any order, so for any thread count.
        total.into_inner()
    }

    /// Make the pending trial the committed state; `mesh` must be the mesh of the trial.
    pub fn commit(&mut self, mesh: &Adjacency) {
        if !std::mem::take(&mut self.pending) {
            return;
        }
        let shared = &self.shared;
        let change = Change {
            vertices: &[],
            wedges: &[],
            triangles: &self.pending_triangles,
            reshaded: &self.pending_reshaded,
        };
        each_view(&mut self.crew, &mut self.views, &|v| {
            with_scratch(|s| v.commit(shared, mesh, &change, s));
        });
    }

    /// Drop the pending trial.
    pub fn revert(&mut self) {
        if !std::mem::take(&mut self.pending) {
            return;
        }
        // Restoring a few saved values per view: cheaper than waking the thread pool.
        self.views.iter_mut().for_each(|v| v.revert());
    }
}

impl View {
    /// A view from `camera` with nothing rendered yet: every pixel the background, its target
    /// the given image's (or the background until the first render sets it).
    fn blank(
        camera: &Camera,
        scene: &RenderScene,
        shared: &Shared,
        target: Option<Vec<u16>>,
    ) -> View {
        let (width, height) = (shared.width, shared.height);
        let n = (width * height) as usize;
        let tiles_x = width.div_ceil(BUCKET);
        let n_tiles = (tiles_x * height.div_ceil(BUCKET)) as usize;
        let (mvp, _) = camera_setup(camera, width, height);
        let half = fixed::ONE_PIXEL as i32 / 2;
        View {
            mvp,
            planes: ClipPlanes::for_viewport(width, height),
            vp: Viewport {
                width,
                height,
                cull_backfaces: false,
                sample_span: [half, half, half, half],
            },
            lights: ResolvedLight::for_camera(&scene.lights_for(false), camera),
            xf: Vec::new(),
            light: Vec::new(),
            pieces: Vec::new(),
            bbox: Vec::new(),
            buckets: vec![Vec::new(); n_tiles],
            tiles_x,
            px: {
                let blank = Pixel {
                    shown: EMPTY,
                    depth: f32::INFINITY,
                    current: shared.background,
                    target: shared.background,
                };
                let mut px = vec![blank; n];
                for (p, t) in px.iter_mut().zip(target.iter().flatten()) {
                    p.target = *t;
                }
                px
            },
            second: vec![[Layer::NONE; 2]; n],
            shown_count: Vec::new(),
            tile_far: vec![f32::INFINITY; n_tiles],
            id: NEXT_VIEW_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            trial: Trial::default(),
            commits: 0,
            fills: Fills::default(),
        }
    }
}
