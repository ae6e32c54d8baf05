//! The CPU rasterizer: determinism across thread counts, watertightness, golden images, the CLI.

use std::sync::Arc;

use lodeval::mesh::{self, LoadOptions, Mesh, shapes};
use lodeval::raster::{
    self, Frame, RenderScene, RenderSettings, SamplePattern, Shading, with_threads,
};
use lodeval::scene::{Camera, Rig};

use crate::common::{lodeval, model, root};

fn load(rel: &str) -> Arc<Mesh> {
    Arc::new(mesh::load(&model(rel), &LoadOptions::DEFAULT).unwrap())
}

fn settings(size: u32, shading: Shading) -> RenderSettings {
    let mut s = RenderSettings::DEFAULT;
    s.width = size;
    s.height = size;
    s.shading = shading;
    s
}

/// Every channel as raw bits, so "equal" means byte-identical (−0.0 ≠ +0.0, NaN = NaN).
fn bits(f: &Frame) -> Vec<u32> {
    let mut v: Vec<u32> = f
        .color()
        .iter()
        .flat_map(|c| c.to_array().map(f32::to_bits))
        .collect();
    v.extend(f.depth().iter().map(|d| d.to_bits()));
    v.extend(f.coverage().iter().map(|c| c.to_bits()));
    v.extend_from_slice(f.triangle_ids());
    v
}

#[test]
fn frames_are_byte_identical_for_1_2_and_8_threads_with_every_shading_model() {
    // Spot (textured OBJ) and the barrel (glTF with a normal map), non-square to catch x/y mix-ups.
    for rel in ["spot/spot_mtl.obj", "barrel/barrel.glb"] {
        let scene = RenderScene::of(load(rel));
        let camera = Rig::Dodecahedron.cameras(scene.mesh(), 1.5)[5];
        // Four samples per pixel (tiles) and one (sort-last: every worker its own buffer).
        for (shading, samples) in Shading::ALL.into_iter().flat_map(|m| {
            [
                (m, SamplePattern::Rotated(2)),
                (m, SamplePattern::Ordered(1)),
            ]
        }) {
            let mut s = settings(96, shading);
            s.width = 144;
            s.samples = samples;
            let reference =
                bits(&with_threads(1, || raster::render(&scene, &camera, &s).unwrap()).unwrap());
            for threads in [2, 8, 8] {
                let f =
                    with_threads(threads, || raster::render(&scene, &camera, &s).unwrap()).unwrap();
                assert!(
                    bits(&f) == reference,
                    "{rel} {} {samples:?}: {threads} threads differ from 1",
                    shading.name()
                );
            }
        }
    }
}

/// Coverage counts of a closed mesh from every view of a rig.
fn counts(mesh: Arc<Mesh>, cull: bool, pattern: SamplePattern) -> Vec<Vec<u16>> {
    let scene = RenderScene::of(mesh);
    let mut s = settings(160, Shading::Unlit);
    s.cull_backfaces = cull;
    s.samples = pattern;
    Rig::Icosahedron
        .cameras(scene.mesh(), 1.0)
        .iter()
        .map(|c| raster::coverage_counts(&scene, c, &s).unwrap())
        .collect()
}

#[test]
fn convex_closed_sphere_covers_every_interior_sample_exactly_once() {
    // Seen from outside, every ray through the silhouette of a convex closed surface enters it
    // once and leaves it once. With back faces culled each sample inside is covered exactly once,
    // so any count of 2 is a double hit on a shared edge; without culling every count must be 0 or 2,
    // so a 1 is a crack. A sphere of 20·4⁵ = 20 480 triangles has shared edges everywhere.
    let sphere = Arc::new(shapes::icosphere(5));
    for pattern in [SamplePattern::Rotated(2), SamplePattern::Ordered(3)] {
        for view in counts(sphere.clone(), true, pattern) {
            assert!(view.iter().all(|&c| c <= 1), "double hit with culling");
            assert!(
                view.iter().filter(|&&c| c == 1).count() > 10_000,
                "the sphere is in view"
            );
        }
        for view in counts(sphere.clone(), false, pattern) {
            assert!(
                view.iter().all(|&c| c == 0 || c == 2),
                "crack or double hit without culling"
            );
        }
    }
}

#[test]
fn closed_non_convex_meshes_cover_every_sample_an_even_number_of_times() {
    // A ray entering and leaving a closed surface crosses it an even number of times, so every
    // sample's count is even; a missed or doubly covered sample on a shared edge makes it odd.
    // The closed remesh of the Stanford bunny and a torus (genus 1) are not convex.
    let bunny = load("bunny/bunny_odedstein_3k.obj");
    for mesh in [bunny, Arc::new(shapes::torus(64, 32, 0.35))] {
        for view in counts(mesh, false, SamplePattern::Rotated(2)) {
            let odd = view.iter().filter(|&&c| c % 2 == 1).count();
            assert_eq!(odd, 0, "{odd} samples covered an odd number of times");
            assert!(
                view.iter().any(|&c| c >= 4),
                "some rays cross the surface four times"
            );
        }
    }
}

#[test]
fn top_left_rule_splits_shared_edges_through_sample_centres() {
    // An orthographic square split along its diagonal, exactly aligned with the pixel grid so that
    // both the square's edges and the diagonal pass through sample positions. Every sample inside
    // the square is covered exactly once; those on the square's top and left edges count, those
    // on its bottom and right edges do not.
    let mesh = Arc::new(quad_mesh());
    let scene = RenderScene::of(mesh);
    let mut s = settings(8, Shading::Unlit);
    s.samples = SamplePattern::Ordered(1);
    let camera = Camera {
        eye: glam::Vec3::new(0.0, 0.0, 2.0),
        target: glam::Vec3::ZERO,
        up: glam::Vec3::Y,
        projection: lodeval::scene::Projection::Orthographic { half_height: 4.0 },
        near: 1.0,
        far: 3.0,
    };
    let c = raster::coverage_counts(&scene, &camera, &s).unwrap();
    // One world unit is one pixel; the quad spans pixels [1.5, 6.5] in x and y (y down), so the
    // centres of pixels 1 and 6 (at 1.5 and 6.5) lie exactly on its edges: pixel 1 is on the left
    // and top edges (owned), pixel 6 on the right and bottom edges (not owned), and the diagonal
    // through (k + ½, k + ½) is shared by both triangles and must be owned by exactly one.
    for y in 0..8 {
        for x in 0..8 {
            let inside = (1..=5).contains(&x) && (1..=5).contains(&y);
            assert_eq!(c[y * 8 + x], inside as u16, "pixel ({x}, {y})");
        }
    }
}

fn quad_mesh() -> Mesh {
    use lodeval::mesh::{Format, MeshData, Source};
    let p = |x: f32, y: f32| glam::Vec3::new(x, y, 0.0);
    let data = MeshData {
        positions: vec![p(-2.5, -2.5), p(2.5, -2.5), p(2.5, 2.5), p(-2.5, 2.5)],
        normals: None,
        uvs: None,
        uvs1: None,
        colors: None,
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        material_ids: vec![],
        materials: vec![],
        lights: Vec::new(),
        source: Source {
            path: "<quad>".into(),
            format: Format::Obj,
            file_vertices: 4,
            file_faces: 2,
            file_unreferenced: 0,
            edited: false,
            files: Vec::new(),
            nodes: Vec::new(),
            lod_chain: None,
        },
        warnings: vec![],
    };
    Mesh::new(data, &LoadOptions::DEFAULT).unwrap()
}

/// Compare with a golden PNG under reference/golden/raster/, or write it when LODEVAL_BLESS=1.
#[track_caller]
fn assert_golden(name: &str, frame: &Frame) {
    let path = root()
        .join("reference/golden/raster")
        .join(format!("{name}.png"));
    let actual = frame.to_srgb8();
    if std::env::var_os("LODEVAL_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        actual.save(&path).unwrap();
        return;
    }
    let expected = image::open(&path)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e} (run with LODEVAL_BLESS=1 to create it)",
                path.display()
            )
        })
        .into_rgb8();
    assert_eq!(expected.dimensions(), actual.dimensions(), "{name}: size");
    if let Some((i, (e, a))) = expected
        .pixels()
        .zip(actual.pixels())
        .enumerate()
        .find(|(_, (e, a))| e != a)
    {
        let w = expected.width() as usize;
        panic!(
            "{name}: first differing pixel ({}, {}): expected {:?}, got {:?}",
            i % w,
            i / w,
            e.0,
            a.0
        );
    }
}

#[test]
fn golden_images() {
    let spot = RenderScene::of(load("spot/spot_mtl.obj"));
    let barrel = RenderScene::of(load("barrel/barrel.glb"));
    let sphere = RenderScene::of(Arc::new(shapes::icosphere(2)));
    let cases: [(&str, &RenderScene, Shading, usize); 5] = [
        ("spot-gouraud-v3", &spot, Shading::Gouraud, 3),
        ("spot-unlit-v0", &spot, Shading::Unlit, 0),
        ("barrel-normal-mapped-v1", &barrel, Shading::NormalMapped, 1),
        ("sphere-phong-v0", &sphere, Shading::Phong, 0),
        ("sphere-depth-v0", &sphere, Shading::Depth, 0),
    ];
    for (name, scene, shading, view) in cases {
        let camera = Rig::Dodecahedron.cameras(scene.mesh(), 1.0)[view];
        assert_golden(
            name,
            &raster::render(scene, &camera, &settings(64, shading)).unwrap(),
        );
    }
}

#[test]
fn render_cli_writes_pngs_and_rejects_bad_requests() {
    let dir = tempfile::tempdir().unwrap();
    let spot = model("spot/spot_mtl.obj");
    let out = dir.path().join("spot.png");
    let r = lodeval([
        "render".as_ref(),
        spot.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--size".as_ref(),
        "32".as_ref(),
        "--exr".as_ref(),
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert_eq!(
        image::open(&out).unwrap().into_rgb8().dimensions(),
        (32, 32)
    );
    assert!(out.with_extension("exr").exists());
    let views = dir.path().join("views");
    let r = lodeval([
        "render".as_ref(),
        spot.as_os_str(),
        "--all-views".as_ref(),
        "--out-dir".as_ref(),
        views.as_os_str(),
        "--size".as_ref(),
        "16".as_ref(),
        "--rig".as_ref(),
        "fibonacci:5".as_ref(),
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert_eq!(std::fs::read_dir(&views).unwrap().count(), 5);
    for (args, expect) in [
        (vec!["--size", "0"], "'0' for '--size"),
        // Past the 16-bit pixel boxes of the set-up records (setup.rs): src/limits.rs.
        (vec!["--size", "16385"], "'16385' for '--size"),
        // Flag values clap parses: the message names the flag and the value.
        (vec!["--rig", "cube"], "'cube' for '--rig"),
        (vec!["--shading", "toon"], "'toon' for '--shading"),
        (vec!["--samples", "3"], "'3' for '--samples"),
        (vec!["--view", "20"], "--view 20"),
    ] {
        let bad = dir.path().join("bad.png");
        let mut full = vec![
            "render".to_string(),
            spot.display().to_string(),
            "-o".into(),
            bad.display().to_string(),
        ];
        full.extend(args.iter().map(|s| s.to_string()));
        let r = lodeval(&full);
        assert_eq!(r.code, 2, "{args:?}: {}", r.stderr);
        assert!(r.stderr.contains(expect), "{args:?}: {}", r.stderr);
        assert!(!bad.exists(), "{args:?}: no output on error");
    }
}

/// Ray-cast the camera's pixel centres with an independent BVH (obvhs, Möller–Trumbore) and
/// return (compared surface pixels, mismatching ones, surface pixels within a pixel of an edge,
/// mismatching ones among those).
fn raycast_agreement(scene: &RenderScene, camera: &Camera, size: u32) -> [usize; 4] {
    use obvhs::{
        BvhBuildParams,
        cwbvh::builder::build_cwbvh_from_tris,
        ray::{Ray, RayHit},
        triangle::Triangle,
    };
    let mesh = scene.mesh();
    let tris: Vec<Triangle> = mesh
        .triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| glam::Vec3A::from(mesh.positions()[i as usize]));
            Triangle {
                v0: a,
                v1: b,
                v2: c,
            }
        })
        .collect();
    let bvh = build_cwbvh_from_tris(
        &tris,
        BvhBuildParams::medium_build(),
        &mut std::time::Duration::default(),
    );
    let inv = (camera.projection(1.0) * camera.view()).inverse();
    let mut cast = vec![u32::MAX; (size * size) as usize];
    for y in 0..size {
        for x in 0..size {
            let ndc = glam::Vec2::new(
                (x as f32 + 0.5) / size as f32 * 2.0 - 1.0,
                1.0 - (y as f32 + 0.5) / size as f32 * 2.0,
            );
            let near = inv.project_point3(ndc.extend(0.0));
            let far = inv.project_point3(ndc.extend(1.0));
            let ray = Ray::new_inf(near.into(), (far - near).normalize().into());
            let mut hit = RayHit::none();
            if bvh.ray_traverse(ray, &mut hit, |r, id| {
                tris[bvh.primitive_indices[id] as usize].intersect(r)
            }) {
                cast[(y * size + x) as usize] = bvh.primitive_indices[hit.primitive_id as usize];
            }
        }
    }
    let mut s = settings(size, Shading::Unlit);
    s.samples = SamplePattern::Ordered(1);
    let frame = raster::render(scene, camera, &s).unwrap();
    let ids = frame.triangle_ids();
    let [mut compared, mut bad, mut excluded, mut bad_near_edge] = [0; 4];
    for y in 1..size - 1 {
        for x in 1..size - 1 {
            let i = (y * size + x) as usize;
            // Within one pixel of an edge or silhouette: some 3×3 neighbour sees another triangle.
            let near_edge = (-1i32..=1).any(|dy| {
                (-1i32..=1).any(|dx| {
                    cast[((y as i32 + dy) as u32 * size + (x as i32 + dx) as u32) as usize]
                        != cast[i]
                })
            });
            if cast[i] == u32::MAX && ids[i] == u32::MAX {
                continue; // background in both
            }
            if near_edge {
                excluded += 1;
                bad_near_edge += (ids[i] != cast[i]) as usize;
                continue;
            }
            compared += 1;
            bad += (ids[i] != cast[i]) as usize;
        }
    }
    [compared, bad, excluded, bad_near_edge]
}

#[test]
fn triangle_ids_match_an_independent_ray_caster_away_from_edges() {
    // At pixel centres the rasterizer (fixed-point edge functions, depth buffer) and a ray caster
    // (floating-point Möller–Trumbore on a BVH) must see the same nearest triangle, except within a
    // pixel of an edge, where the 1/256-pixel snapping may legitimately move the boundary.
    for (rel, size) in [
        ("spot/spot_mtl.obj", 768),
        ("bunny/bunny_odedstein_3k.obj", 768),
        ("bunny/stanford-bunny.obj", 1024),
    ] {
        let scene = RenderScene::of(load(rel));
        let mut t = [0; 4];
        for camera in Rig::Icosahedron.cameras(scene.mesh(), 1.0).iter().take(6) {
            let r = raycast_agreement(&scene, camera, size);
            (0..4).for_each(|k| t[k] += r[k]);
        }
        eprintln!(
            "{rel}: {} surface pixels compared, {} differ; {} within a pixel of an edge, {} of them differ",
            t[0], t[1], t[2], t[3]
        );
        assert!(
            t[0] > 10_000,
            "{rel}: too few interior pixels to mean anything"
        );
        assert_eq!(t[1], 0, "{rel}: triangle ids differ from the ray caster");
    }
}
