//! Tests of the incremental luminance images against the rasterizer and full re-renders.

use super::*;
use crate::mesh::shapes;
use crate::raster::{RenderSettings, SamplePattern, Shading, render};
use crate::scene::Rig;
use std::sync::Arc;

/// Renders that had a hole three changed layers deep (so the tests can tell the path ran).
pub(super) static DEEP_RENDERS: std::sync::atomic::AtomicUsize =
    std::sync::atomic::AtomicUsize::new(0);

fn cameras(mesh: &crate::mesh::Mesh, n: u32) -> Vec<Camera> {
    Rig::Fibonacci(n)
        .directions()
        .into_iter()
        .map(|d| {
            Camera::frame_sphere(
                mesh.bounding_sphere(),
                d,
                Camera::DEFAULT_FOV_Y_DEG,
                1.0,
                Camera::DEFAULT_MARGIN,
            )
        })
        .collect()
}

/// A level-3 icosphere's scene, `n` cameras around it and its adjacency.
fn icosphere_views(n: u32) -> (RenderScene, Vec<Camera>, Adjacency) {
    let mesh = Arc::new(shapes::icosphere(3));
    let cams = cameras(&mesh, n);
    let adj = Adjacency::new(&mesh);
    (RenderScene::of(mesh), cams, adj)
}

#[test]
fn linear_luminance_indices_clamp_and_send_nan_to_zero() {
    assert_eq!(index_of_linear(f32::NAN), 0);
    assert_eq!(index_of_linear(-1.0), 0);
    assert_eq!(index_of_linear(f32::NEG_INFINITY), 0);
    assert_eq!(index_of_linear(2.0), 65535);
    assert_eq!(index_of_linear(f32::INFINITY), 65535);
    assert_eq!(index_of_linear(0.5), 32768);
    assert_eq!(index_of_linear(1.0 / 65535.0), 1);
}

#[test]
fn full_render_equals_the_rasterizer_at_one_sample() {
    let (scene, cams, adj) = icosphere_views(3);
    let views = LumaViews::new(&adj, &scene, &cams, 64, 48, None).unwrap();
    let settings = RenderSettings {
        width: 64,
        height: 48,
        samples: SamplePattern::Ordered(1),
        shading: Shading::Gouraud,
        ..RenderSettings::DEFAULT
    };
    // The same coverage and visibility, and shading equal up to rounding: untextured pieces
    // are shaded through their luminance planes (f64) rather than the rasterizer's per-channel
    // f32 colours, which moves a value across a 16-bit code boundary now and then.
    let (mut differ, mut total, mut shaded) = (0usize, 0usize, 0usize);
    for (h, cam) in cams.iter().enumerate() {
        let frame = render(&scene, cam, &settings).unwrap();
        let expect: Vec<u16> = frame.color().iter().map(|&c| luma_of(c)).collect();
        let got: Vec<u16> = views.view_pixels(h).map(|(y, _)| y).collect();
        let bg = views.shared.background;
        for (i, (&g, &e)) in got.iter().zip(&expect).enumerate() {
            assert_eq!(g == bg, e == bg, "view {h} pixel {i}: coverage differs");
            assert!(g.abs_diff(e) <= 1, "view {h} pixel {i}: {g} against {e}");
            differ += usize::from(g != e);
            shaded += usize::from(e != bg);
        }
        total += got.len();
    }
    eprintln!("{differ} of {shaded} shaded pixels ({total} in all) one code apart");
    assert!(shaded > total / 10);
    assert!(differ * 100 <= shaded, "{differ} of {shaded} pixels differ");
}

#[test]
fn images_view_by_view_equal_the_images_of_all_views() {
    // `images_of` (one view's state per thread) gives every view's codes as a LumaViews of
    // all views does.
    let (scene, cams, adj) = icosphere_views(5);
    let all = LumaViews::new(&adj, &scene, &cams, 40, 30, None)
        .unwrap()
        .images();
    let one_by_one = LumaViews::images_of(&adj, &scene, &cams, 40, 30).unwrap();
    assert_eq!(all.len(), 5);
    assert!(all.iter().all(|im| im.iter().any(|&y| y != all[0][0])));
    assert_eq!(one_by_one, all);
}

#[test]
fn incremental_delta_equals_full_energy_difference() {
    // Move a vertex: ΔE from the trial equals E(after) − E(before) from full renders.
    let original = Arc::new(shapes::icosphere(3));
    let scene = RenderScene::of(original.clone());
    let cams = cameras(&original, 4);
    let targets = LumaViews::new(&Adjacency::new(&original), &scene, &cams, 64, 64, None)
        .unwrap()
        .images();
    let coarse = Arc::new(shapes::icosphere(1));
    let mut adj = Adjacency::new(&coarse);
    let mut views = LumaViews::new(&adj, &scene, &cams, 64, 64, Some(targets.clone())).unwrap();
    let e0 = views.energy();
    assert!(e0 > 0);
    let v = 5u32;
    adj.positions[v as usize] *= 1.2;
    let tris: Vec<u32> = adj.vertex_triangles(v).to_vec();
    let change = Change {
        vertices: &[v],
        wedges: &[],
        triangles: &tris,
        reshaded: &[],
    };
    let delta = views.trial(&adj, &change);
    views.commit(&adj);
    let full = LumaViews::new(&adj, &scene, &cams, 64, 64, Some(targets)).unwrap();
    assert_eq!(views.images(), full.images());
    assert_eq!(e0 + delta, full.energy());
    assert_eq!(views.energy(), full.energy());
    assert_ne!(delta, 0);
}

#[test]
fn random_moves_keep_the_layers_and_images_of_a_fresh_render() {
    random_moves_match_a_fresh_render(false);
}

#[test]
fn random_moves_keep_the_layers_and_images_of_a_fresh_render_with_vertex_colours() {
    // Vertex colours shade every pixel through its barycentrics, not a luminance plane: the
    // other path of the holes, the new pieces and the re-shaded runs.
    random_moves_match_a_fresh_render(true);
}

fn random_moves_match_a_fresh_render(coloured: bool) {
    // Vertex moves large enough to fold the surface over itself (holes several changed layers
    // deep), normal changes (re-shaded triangles), and both at once (a move that re-shades
    // the triangles around a neighbour, beyond the moved ones' boxes, as derived normals
    // do), each tried a few times in a row with
    // other values (as the simplex does: the views reuse their holes' fills) and then
    // accepted or reverted at random: the incremental state equals a fresh render of the
    // final mesh, all three layers of every pixel included, and the accepted ΔE add up to its
    // energy exactly.
    let original = Arc::new(shapes::icosphere(3));
    let scene = RenderScene::of(original.clone());
    let cams = cameras(&original, 5);
    let (w, h) = (48, 40);
    let targets = LumaViews::new(&Adjacency::new(&original), &scene, &cams, w, h, None)
        .unwrap()
        .images();
    let mut coarse = shapes::icosphere(1);
    if coloured {
        let mut data = coarse.to_data();
        data.colors = Some(
            data.positions
                .iter()
                .map(|p| (*p * 0.5 + Vec3::splat(0.5)).clamp(Vec3::ZERO, Vec3::ONE))
                .collect(),
        );
        coarse = crate::mesh::Mesh::new(data, &Default::default()).unwrap();
    }
    let mut adj = Adjacency::new(&coarse);
    assert_eq!(adj.has_colors(), coloured);
    let mut views = LumaViews::new(&adj, &scene, &cams, w, h, Some(targets.clone())).unwrap();
    let mut energy = views.energy();
    let mut next = crate::raster::xorshift(0x2545_f491_4f6c_dd1du64);
    let unit = |r: u64| (r % 2001) as f32 / 1000.0 - 1.0;
    let deep_before = DEEP_RENDERS.load(std::sync::atomic::Ordering::Relaxed);
    let mut accepted = 0;
    let mut v = 0;
    for _ in 0..80 {
        // Now and then the same vertex again, after an accept too (the fills must not
        // outlive the committed state they were made on).
        if !next().is_multiple_of(3) {
            v = (next() % adj.positions.len() as u64) as u32;
        }
        let tris: Vec<u32> = adj.vertex_triangles(v).to_vec();
        let w0 = adj.single_wedge(v).unwrap();
        let (old_p, old_n) = (adj.positions[v as usize], adj.wedges[w0 as usize].normal);
        let old_colour = adj.wedges[w0 as usize].color;
        let normal = next().is_multiple_of(3);
        // A neighbour whose normal changes with the move (half the moves).
        let u = adj.neighbours(v)[0];
        let wu = adj.single_wedge(u).unwrap();
        let old_nu = adj.wedges[wu as usize].normal;
        let with_neighbour = next().is_multiple_of(2);
        let around_u: Vec<u32> = adj
            .vertex_triangles(u)
            .iter()
            .copied()
            .filter(|t| !tris.contains(t))
            .collect();
        let mut delta = 0;
        for _ in 0..1 + next() % 3 {
            delta = if normal {
                // A new normal: the same corners, new shading.
                let n = Vec3::new(unit(next()), unit(next()), unit(next()));
                adj.wedges[w0 as usize].normal = (n + old_n).normalize_or(old_n);
                if coloured && next().is_multiple_of(2) {
                    // A new colour as well: the re-shaded pixels' surfaces change too.
                    let c = Vec3::new(unit(next()), unit(next()), unit(next()));
                    adj.wedges[w0 as usize].color = (c * 0.5 + Vec3::splat(0.5)).abs();
                }
                let change = Change {
                    vertices: &[],
                    wedges: &[w0],
                    triangles: &[],
                    reshaded: &tris,
                };
                views.trial(&adj, &change)
            } else {
                let d = Vec3::new(unit(next()), unit(next()), unit(next()));
                adj.positions[v as usize] = old_p + 0.6 * d;
                let (wedges, reshaded): (&[u32], &[u32]) = if with_neighbour {
                    let n = Vec3::new(unit(next()), unit(next()), unit(next()));
                    adj.wedges[wu as usize].normal = (n + old_nu).normalize_or(old_nu);
                    (&[wu], &around_u)
                } else {
                    (&[], &[])
                };
                let change = Change {
                    vertices: &[v],
                    wedges,
                    triangles: &tris,
                    reshaded,
                };
                views.trial(&adj, &change)
            };
        }
        if next().is_multiple_of(2) {
            views.commit(&adj);
            energy += delta;
            accepted += 1;
        } else {
            views.revert();
            adj.positions[v as usize] = old_p;
            adj.wedges[w0 as usize].normal = old_n;
            adj.wedges[w0 as usize].color = old_colour;
            adj.wedges[wu as usize].normal = old_nu;
        }
    }
    assert!(accepted > 20, "{accepted} accepted");
    assert!(
        DEEP_RENDERS.load(std::sync::atomic::Ordering::Relaxed) > deep_before,
        "no move made a hole three changed layers deep"
    );
    let fresh = LumaViews::new(&adj, &scene, &cams, w, h, Some(targets)).unwrap();
    assert_eq!(views.energy(), energy);
    assert_eq!(energy, fresh.energy());
    assert_eq!(views.images(), fresh.images());
    for (k, (a, b)) in views.views.iter().zip(&fresh.views).enumerate() {
        for p in 0..a.px.len() {
            let key = |l: Layer| (l.shown, l.depth.to_bits());
            let nearest = |v: &View| {
                key(Layer {
                    shown: v.px[p].shown,
                    depth: v.px[p].depth,
                })
            };
            assert_eq!(nearest(a), nearest(b), "view {k} pixel {p}: nearest");
            assert_eq!(
                a.second[p].map(key),
                b.second[p].map(key),
                "view {k} pixel {p}: layers behind"
            );
        }
    }
}
