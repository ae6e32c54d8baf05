//! §5.2: the first samples — error diffusion of the density over each chart's texels, so that a
//! chart gets exactly its share of the budget and the samples follow the density.
//!
//! Based on: Qu & Meyer §5.2 and Alliez et al. 2002 §3.4 (error diffusion of the importance map
//! for the initial samples, then Lloyd relaxation); Robert Floyd, Louis Steinberg. An Adaptive
//! Algorithm for Spatial Greyscale. 1976 (the 7/16, 3/16, 5/16, 1/16 weights), run serpentine.
//!
//! Decisions: the error of a texel goes only to neighbours of its own chart (the weights that
//! remain renormalised), so charts do not bleed into each other; after the pass each chart's
//! count is made exact by dropping the samples that were closest to not being taken or adding
//! the texels closest to being taken (ties to the lower texel index).

use glam::Vec2;

/// Per chart, the first samples (texel coordinates, centres at half-integers): exactly
/// `targets[c]` for chart c (fewer only where the chart has fewer texels).
pub fn error_diffusion(
    size: usize,
    chart: &[u32],
    density: &[f32],
    targets: &[usize],
) -> Vec<Vec<Vec2>> {
    let charts = targets.len();
    let mut mass = vec![0.0f64; charts];
    for (c, d) in chart.iter().zip(density) {
        if (*c as usize) < charts {
            mass[*c as usize] += *d as f64;
        }
    }
    let scale: Vec<f64> = mass
        .iter()
        .zip(targets)
        .map(|(&m, &t)| if m > 0.0 { t as f64 / m } else { 0.0 })
        .collect();
    let mut err = vec![0.0f64; size * size];
    // (texel, value when visited, taken)
    let mut visited: Vec<(usize, f64, bool)> = Vec::new();
    for y in 0..size {
        let forward = y % 2 == 0;
        for k in 0..size {
            let x = if forward { k } else { size - 1 - k };
            let i = y * size + x;
            let c = chart[i];
            if c as usize >= charts {
                continue;
            }
            let acc = density[i] as f64 * scale[c as usize] + err[i];
            let taken = acc >= 0.5;
            let e = if taken { acc - 1.0 } else { acc };
            visited.push((i, acc, taken));
            let dir: isize = if forward { 1 } else { -1 };
            let targets = [
                (dir, 0isize, 7.0),
                (-dir, 1, 3.0),
                (0, 1, 5.0),
                (dir, 1, 1.0),
            ];
            let mut spread = [(0usize, 0.0f64); 4];
            let mut total = 0.0;
            let mut m = 0;
            for (dx, dy, w) in targets {
                let (nx, ny) = (x as isize + dx, y as isize + dy);
                if nx < 0 || nx >= size as isize || ny >= size as isize {
                    continue;
                }
                let j = ny as usize * size + nx as usize;
                if chart[j] == c {
                    spread[m] = (j, w);
                    total += w;
                    m += 1;
                }
            }
            for &(j, w) in &spread[..m] {
                err[j] += e * w / total;
            }
        }
    }
    // Exact counts per chart.
    let mut out: Vec<Vec<Vec2>> = vec![Vec::new(); charts];
    let mut per_chart: Vec<Vec<(usize, f64, bool)>> = vec![Vec::new(); charts];
    for v in visited {
        per_chart[chart[v.0] as usize].push(v);
    }
    for (c, list) in per_chart.iter_mut().enumerate() {
        let taken = list.iter().filter(|v| v.2).count();
        let want = targets[c].min(list.len());
        if taken > want {
            // Drop the taken texels with the smallest value.
            let mut order: Vec<usize> = (0..list.len()).filter(|&k| list[k].2).collect();
            order.sort_by(|&a, &b| {
                list[a]
                    .1
                    .total_cmp(&list[b].1)
                    .then(list[b].0.cmp(&list[a].0))
            });
            for &k in order.iter().take(taken - want) {
                list[k].2 = false;
            }
        } else if taken < want {
            let mut order: Vec<usize> = (0..list.len()).filter(|&k| !list[k].2).collect();
            order.sort_by(|&a, &b| {
                list[b]
                    .1
                    .total_cmp(&list[a].1)
                    .then(list[a].0.cmp(&list[b].0))
            });
            for &k in order.iter().take(want - taken) {
                list[k].2 = true;
            }
        }
        let mut texels: Vec<usize> = list.iter().filter(|v| v.2).map(|v| v.0).collect();
        texels.sort_unstable();
        out[c] = texels
            .into_iter()
            .map(|i| Vec2::new((i % size) as f32 + 0.5, (i / size) as f32 + 0.5))
            .collect();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_exact_and_follow_the_density() {
        // One chart over a 64² map, the right half four times as dense as the left.
        let size = 64;
        let chart = vec![0u32; size * size];
        let density: Vec<f32> = (0..size * size)
            .map(|i| if i % size < size / 2 { 1.0 } else { 4.0 })
            .collect();
        let s = error_diffusion(size, &chart, &density, &[500]);
        assert_eq!(s[0].len(), 500);
        let right = s[0].iter().filter(|p| p.x > size as f32 / 2.0).count();
        assert!((right as f64 / 500.0 - 0.8).abs() < 0.02, "{right}");
        // Two charts side by side get their own counts.
        let chart: Vec<u32> = (0..size * size)
            .map(|i| u32::from(i % size >= 20))
            .collect();
        let s = error_diffusion(size, &chart, &vec![1.0; size * size], &[37, 201]);
        assert_eq!((s[0].len(), s[1].len()), (37, 201));
        assert!(s[0].iter().all(|p| p.x < 20.0) && s[1].iter().all(|p| p.x > 20.0));
    }
}
