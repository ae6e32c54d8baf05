//! Figure 3 and §5.1: the simplification loop — collapses in a priority queue ordered by the
//! quadric estimate, each tested for visibility and then for geometric deviation before it is
//! made, postponed with its measured distance when either exceeds the estimate — run on blocks of
//! queue heads, tested in parallel and applied in order of perceivability.
//!
//! Based on: Menzel & Guthe 2010, §3.1 and Figure 3 (the loop; "the operation is postponed with
//! the actual error"; "the collapse is stored along with its perceptual and geometric error and
//! the algorithm repeats until no more collapses are possible"), §5.1 (blocks of the first n
//! queue elements sorted by their target vertex, tested, "the accepted operations are sorted by
//! their perceivability distance. Then they are applied in that order unless they have become
//! invalid due to the collapse of a neighbor vertex"), §6 ("one third of the quadric error as
//! estimate for the Hausdorff distance"). Hugues Hoppe. Progressive Meshes. SIGGRAPH 1996 (the
//! record).
//!
//! Decisions:
//! - Every priority is a distance (model units from the viewer): the split distance beyond which
//!   the collapse is invisible. The quadric's estimate of a collapse is the silhouette distance
//!   (`distance.rs`, Figure 4) of a third of its RMS plane distance; a postponed collapse returns
//!   with the distance its failed test measured.
//! - A collapse is recorded with the running maximum of the priorities applied so far, so the
//!   record's distances never decrease: the LOD for a viewing distance D is the longest prefix
//!   whose distance is at most D (each collapse is invisible beyond its own). Its measured
//!   distances (the larger of the perceptual and geometric one) are kept beside it.
//! - Blocks: the tests of a block read the mesh as it was when the block was taken, in parallel;
//!   the accepted collapses are applied in order of (distance, vertex ids), each unless one of its
//!   vertices or their neighbours was changed by an earlier collapse of the block (it returns to
//!   the queue). The order depends on nothing but the data, so the result is the same for any
//!   thread count. A block of 1 is the paper's sequential loop.
//! - An edge postponed once returns, after a neighbour's collapse renews its entry, no earlier
//!   than its last measured distance rather than at the quadric's estimate (the collapse is
//!   still tested when it pops; only the order of testing changes). Without it each edge was
//!   tested again after every change around it: 10.7 tests per applied collapse on the bunny,
//!   where the paper reports about 2.
//! - A collapse the Hausdorff test postponed returns at 1.1 times the distance it measured. Past
//!   its limit the test stops refining (`hausdorff.rs`), so what it measured is a lower bound,
//!   and the neighbours collapsed before the edge returns move its surface further: returning at
//!   the bound itself, 92 % of Hausdorff tests failed on the bunny (13 per applied collapse).
//!   Measured on the bunny (69 451 triangles to 10 %, 2 threads): 33 s → 25 s, and 6 944 → 6 992
//!   triangles at the same distance (+0.7 %); 1.25 was 21 s but lost 3 % in distance; measuring
//!   the whole deviation of every failed test halved the tests but doubled the time.
//! - The disk-backed queue of §5.1 is not built: meshes that fit the BVH and the mesh structure
//!   in memory fit their queue too.

use glam::Vec3;
use rayon::prelude::*;

use super::distance::Silhouette;
use super::hausdorff::{self, Attached};
use super::perception::Perception;
use super::proposal::{Proposal, propose};
use super::surface::{self, Materials, Original};
use crate::mesh::Mesh;
use crate::mesh::edit::{Adjacency, Local};
use crate::simplify::qem::{Collapse, CollapseCost, Progressive, QemCost};
use crate::simplify::queue::{Keyed, RadixQueue};

/// When the loop stops: once every given goal is reached (with none, when no collapse is left).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stop {
    /// Reached before the first collapse whose split distance exceeds this (model units).
    pub distance: Option<f64>,
    /// Reached at or below this many triangles.
    pub triangles: Option<usize>,
}

impl Stop {
    /// Whether the triangle goal is reached (or there is none and a distance goal decides).
    fn triangles_reached(&self, triangles: usize) -> bool {
        match self.triangles {
            Some(n) => triangles <= n,
            None => self.distance.is_some(),
        }
    }

    /// Whether a head of split distance `d` is beyond the distance goal (or there is none and a
    /// triangle goal decides).
    fn distance_reached(&self, d: f64) -> bool {
        match self.distance {
            Some(limit) => d > limit,
            None => self.triangles.is_some(),
        }
    }
}

/// What the loop did (§6 reports about two perception tests per applied collapse).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Counts {
    /// Collapses made.
    pub applied: u64,
    /// Perception tests (one per tested collapse, each comparing its three or more points).
    pub perception_tests: u64,
    /// Collapses postponed because the perceptual distance exceeded the estimate.
    pub postponed_perceptual: u64,
    /// Hausdorff tests.
    pub hausdorff_tests: u64,
    /// Collapses postponed because the geometric distance exceeded the estimate.
    pub postponed_geometric: u64,
    /// Accepted collapses a neighbour's collapse in the same block made stale (requeued).
    pub invalidated: u64,
    /// Coefficients that needed a Newton iteration.
    pub newton_solves: u64,
}

/// The progressive record with its distances and counts.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The record; each collapse's `error` is its split distance (model units, non-decreasing).
    pub progressive: Progressive,
    /// Each collapse's measured distance, the larger of its perceptual and geometric ones.
    pub measured: Vec<f64>,
    /// What the loop did.
    pub counts: Counts,
    /// Seconds spent before the loop (the original's BVH, curvatures, first queue) and in it
    /// (wall clock; reporting only).
    pub seconds: (f64, f64),
}

impl Outcome {
    /// How many collapses the LOD for viewing distance `d` (model units) takes.
    pub fn prefix_for_distance(&self, d: f64) -> usize {
        self.progressive
            .collapses
            .iter()
            .take_while(|c| c.error <= d)
            .count()
    }
}

/// The loop's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Engine {
    /// Queue heads tested together (1: the paper's sequential loop).
    pub block: usize,
    /// Run the perception test; without it only the geometric test bounds a collapse (a QEM
    /// with a guaranteed Hausdorff distance: the baseline of the paper's Table 2).
    pub perception: bool,
}

/// Queue entry, ordered by distance, then vertex ids, then stamp.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Entry {
    /// The distance's bits as f32 (a non-negative float orders like its bits).
    key: u32,
    a: u32,
    b: u32,
    stamp: u32,
}

impl Entry {
    fn current(&self, version: &[u32]) -> bool {
        version[self.a as usize].wrapping_add(version[self.b as usize]) == self.stamp
    }

    fn distance(&self) -> f64 {
        f32::from_bits(self.key) as f64
    }
}

impl Keyed for Entry {
    fn key(&self) -> u32 {
        self.key
    }
    fn raise_key(&mut self, k: u32) {
        self.key = self.key.max(k);
    }
}

/// What testing one queue head found.
enum Verdict {
    /// The collapse is illegal now.
    Illegal,
    /// Postponed with the measured distance; `perceptual` tells which test failed.
    Postpone {
        distance: f64,
        perceptual: bool,
        solves: u32,
    },
    /// Passed both tests.
    Accept {
        proposal: Box<Proposal>,
        distance: f64,
        solves: u32,
    },
}

/// A collapse the Hausdorff test postponed returns at this multiple of the deviation it measured
/// (as a distance). See the module comment.
const MARGIN: f64 = 1.1;

/// The shared, read-only state the tests use.
struct Tests<'a> {
    original: &'a Original,
    original_positions: &'a [Vec3],
    materials: &'a Materials,
    /// None: the geometric test alone ([`Engine::perception`] off).
    perception: Option<&'a Perception>,
    silhouette: &'a Silhouette,
    global: &'a (dyn Fn(u32, usize, f32) -> f32 + Sync),
}

impl Tests<'_> {
    /// The perceptual distance of `p`: the largest D_max over its test points.
    fn perceptual(&self, p: &Proposal) -> (f64, u32) {
        let Some(perception) = self.perception else {
            return (0.0, 0);
        };
        let floor = 1.0 / (4.0 * p.radius.max(1e-30));
        let mut worst = 0.0f64;
        let mut solves = 0;
        for site in &p.sites {
            let patch = &p.fan[site.patch];
            let mut s = surface::point(patch, site.barycentric, p.curvature, self.materials);
            let Some((t, b, _)) = self.original.closest_near(s.position, p.b) else {
                continue;
            };
            let o = self.original.point(t, b, self.materials);
            s.curvature.torsion = o.curvature.torsion;
            let c = perception.compare(&o, &s, floor, worst, &|ch, f| (self.global)(t, ch, f));
            worst = worst.max(c.distance);
            solves += c.solved;
        }
        (worst, solves)
    }

    /// Test one queue head against the mesh as it is.
    fn verdict(&self, adj: &Adjacency, cost: &QemCost, attached: &Attached, e: &Entry) -> Verdict {
        let Some(proposal) = propose(adj, cost, e.a, e.b) else {
            return Verdict::Illegal;
        };
        let key = e.distance();
        let (perceptual, solves) = self.perceptual(&proposal);
        if perceptual > key {
            return Verdict::Postpone {
                distance: perceptual,
                perceptual: true,
                solves,
            };
        }
        let deviation = hausdorff::deviation(
            &proposal,
            adj,
            attached,
            self.original,
            self.original_positions,
            Some(self.silhouette.deviation(key) as f32),
        );
        let geometric = self.silhouette.distance(deviation as f64);
        if geometric > key {
            return Verdict::Postpone {
                distance: geometric,
                perceptual: false,
                solves,
            };
        }
        Verdict::Accept {
            proposal: Box::new(proposal),
            distance: perceptual.max(geometric),
            solves,
        }
    }
}

/// An edge's key in the memory of measured distances, whichever way round it is given.
fn edge_key(u: u32, v: u32) -> (u32, u32) {
    (u.min(v), u.max(v))
}

/// The queue entry of edge (u, v) with the quadric's estimate: the lower class collapses into the
/// higher one (as in the QEM engine), locked vertices never move.
fn entry(
    adj: &Adjacency,
    cost: &QemCost,
    silhouette: &Silhouette,
    version: &[u32],
    u: u32,
    v: u32,
) -> Option<Entry> {
    let (a, b) = adj.collapse_direction(u, v)?;
    let (_, err) = cost.placement(adj, a, b);
    let estimate = silhouette.distance(err.max(0.0) / 3.0);
    Some(Entry {
        key: (estimate as f32).to_bits(),
        a,
        b,
        stamp: version[a as usize].wrapping_add(version[b as usize]),
    })
}

/// Simplify `mesh` to `stop`. `global(t, c, f)` is the global masker on the original's triangle
/// `t` in channel `c` at surface frequency `f` (0 without global masking).
pub fn run(
    mesh: &Mesh,
    perception: &Perception,
    engine: &Engine,
    stop: Stop,
    global: &(dyn Fn(u32, usize, f32) -> f32 + Sync),
) -> Outcome {
    let start = std::time::Instant::now();
    let mut adj = Adjacency::new(mesh);
    adj.allow_non_manifold_collapses();
    let base = adj.clone();
    let diagonal = mesh.aabb().diagonal() as f64;
    let original = Original::new(mesh, &adj);
    let original_positions = adj.positions.clone();
    let materials = Materials::of(mesh);
    let silhouette = Silhouette::PAPER;
    let mut state = Loop::new(adj, diagonal, silhouette);
    let tests = Tests {
        original: &original,
        original_positions: &original_positions,
        materials: &materials,
        perception: engine.perception.then_some(perception),
        silhouette: &silhouette,
        global,
    };
    let block = engine.block.max(1);
    let setup = start.elapsed().as_secs_f64();
    loop {
        if stop.triangles.is_some()
            && stop.distance.is_none()
            && stop.triangles_reached(state.adj.triangle_count())
        {
            break;
        }
        let (heads, stopped) = state.take_block(block, &stop);
        if heads.is_empty() {
            break;
        }
        let accepted = state.test_block(heads, &tests, engine.perception);
        if state.apply(accepted, &stop) || stopped {
            break;
        }
    }
    Outcome {
        progressive: Progressive {
            base,
            collapses: state.collapses,
            last: state.adj,
        },
        measured: state.measured,
        counts: state.counts,
        seconds: (setup, start.elapsed().as_secs_f64() - setup),
    }
}

/// A collapse a block's tests accepted: its measured distance, its entry and where it goes.
type Accepted = (f64, Entry, Box<Proposal>);

/// The loop's state: the mesh as collapsed so far and everything that follows it.
struct Loop {
    adj: Adjacency,
    cost: QemCost,
    silhouette: Silhouette,
    heap: RadixQueue<Entry>,
    /// Per vertex, bumped by every collapse that moves it (stale entries carry an old sum).
    version: Vec<u32>,
    attached: Attached,
    counts: Counts,
    collapses: Vec<Collapse>,
    measured: Vec<f64>,
    /// The largest priority applied so far: each collapse's recorded split distance.
    running: f64,
    ring: Local<u32>,
    /// The last measured distance of each postponed edge (looked up, never iterated).
    measured_before: std::collections::HashMap<(u32, u32), u32>,
}

impl Loop {
    /// The state before the first collapse, with every edge queued at the quadric's estimate.
    fn new(adj: Adjacency, diagonal: f64, silhouette: Silhouette) -> Loop {
        let cost = QemCost::with_attributes(&adj, diagonal);
        let version = vec![0u32; adj.positions.len()];
        let heap = RadixQueue::from_vec(initial_entries(&adj, &cost, &silhouette, &version));
        Loop {
            attached: Attached::new(adj.positions.len()),
            adj,
            cost,
            silhouette,
            heap,
            version,
            counts: Counts::default(),
            collapses: Vec::new(),
            measured: Vec::new(),
            running: 0.0,
            ring: Local::new(),
            measured_before: Default::default(),
        }
    }

    /// Up to `block` current queue heads, each edge once; `true` when a head was beyond the goal
    /// (the loop ends after this block).
    fn take_block(&mut self, block: usize, stop: &Stop) -> (Vec<Entry>, bool) {
        let mut heads: Vec<Entry> = Vec::with_capacity(block);
        while heads.len() < block {
            let Some(e) = self.heap.pop(|e| e.current(&self.version)) else {
                break;
            };
            if stop.distance_reached(e.distance())
                && stop.triangles_reached(self.adj.triangle_count())
            {
                return (heads, true);
            }
            if !heads.iter().any(|h| h.a == e.a && h.b == e.b) {
                heads.push(e);
            }
        }
        (heads, false)
    }

    /// §5.1: the heads sorted by target vertex, tested in parallel against the mesh as it is;
    /// postponed ones go back to the queue at their measured distance, the accepted ones come
    /// back in order of perceivability.
    fn test_block(
        &mut self,
        mut heads: Vec<Entry>,
        tests: &Tests,
        perception: bool,
    ) -> Vec<Accepted> {
        heads.sort_by_key(|e| (e.b, e.a, e.key));
        let verdicts: Vec<Verdict> = {
            let (adj, cost, attached) = (&self.adj, &self.cost, &self.attached);
            heads
                .par_iter()
                .map(|e| tests.verdict(adj, cost, attached, e))
                .collect()
        };
        let counts = &mut self.counts;
        let mut accepted = Vec::new();
        for (e, v) in heads.iter().zip(verdicts) {
            match v {
                Verdict::Illegal => {}
                Verdict::Postpone {
                    distance,
                    perceptual,
                    solves,
                } => {
                    counts.perception_tests += u64::from(perception);
                    counts.newton_solves += solves as u64;
                    if perceptual {
                        counts.postponed_perceptual += 1;
                    } else {
                        counts.hausdorff_tests += 1;
                        counts.postponed_geometric += 1;
                    }
                    // Strictly later: a distance just past the key can round back to it in
                    // single precision (for positive floats the next bit pattern is the next
                    // float), and the edge would come back for ever.
                    let margin = if perceptual { 1.0 } else { MARGIN };
                    let key = ((distance * margin) as f32)
                        .to_bits()
                        .max((e.key + 1).min(f32::INFINITY.to_bits()));
                    self.measured_before.insert(edge_key(e.a, e.b), key);
                    self.heap.push(Entry { key, ..*e });
                }
                Verdict::Accept {
                    proposal,
                    distance,
                    solves,
                } => {
                    counts.perception_tests += u64::from(perception);
                    counts.hausdorff_tests += 1;
                    counts.newton_solves += solves as u64;
                    accepted.push((distance, *e, proposal));
                }
            }
        }
        // In order of perceivability, unless a neighbour's collapse changed them.
        accepted.sort_by(|x, y| {
            x.0.total_cmp(&y.0)
                .then((x.1.a, x.1.b).cmp(&(y.1.a, y.1.b)))
        });
        accepted
    }

    /// Apply a block's accepted collapses in order, each unless an earlier one changed one of
    /// its vertices or their neighbours (it returns to the queue). `true` when the triangle goal
    /// was reached (the loop ends).
    fn apply(&mut self, accepted: Vec<Accepted>, stop: &Stop) -> bool {
        let mut dirty: Vec<u32> = Vec::new();
        for (distance, e, proposal) in accepted {
            let touched = |v: u32| dirty.binary_search(&v).is_ok();
            if touched(e.a)
                || touched(e.b)
                || self
                    .adj
                    .ring(e.a)
                    .iter()
                    .chain(self.adj.ring(e.b).iter())
                    .any(|&v| touched(v))
            {
                self.counts.invalidated += 1;
                let renewed = entry(
                    &self.adj,
                    &self.cost,
                    &self.silhouette,
                    &self.version,
                    e.a,
                    e.b,
                );
                if let Some(n) = renewed {
                    self.heap.push(Entry {
                        key: n.key.max(e.key),
                        ..n
                    });
                }
                continue;
            }
            if stop.distance.is_none() && stop.triangles_reached(self.adj.triangle_count()) {
                return true;
            }
            if self.collapse(distance, &e, &proposal) {
                for v in [proposal.a, proposal.b]
                    .into_iter()
                    .chain(self.ring.iter().copied())
                {
                    if let Err(i) = dirty.binary_search(&v) {
                        dirty.insert(i, v);
                    }
                }
            }
        }
        false
    }

    /// Make one accepted collapse, record it and queue the edges around its survivor; `false`
    /// when the mesh refused it.
    fn collapse(&mut self, distance: f64, e: &Entry, proposal: &Proposal) -> bool {
        let (a, b) = (proposal.a, proposal.b);
        let Ok(map) = self
            .adj
            .collapse_for_good(a, b, proposal.position, &mut self.ring)
        else {
            return false;
        };
        let attributes = self.cost.collapsed(&mut self.adj, a, b, &map);
        self.version[a as usize] += 1;
        self.version[b as usize] += 1;
        self.attached.merge(a, b);
        self.running = self.running.max(e.distance());
        self.collapses.push(Collapse {
            from: a,
            to: b,
            position: proposal.position,
            error: self.running,
            triangles: self.adj.triangle_count(),
            attributes,
        });
        self.measured.push(distance);
        self.counts.applied += 1;
        self.measured_before.remove(&edge_key(a, b));
        for &n in &self.ring {
            if let Some(mut x) = entry(&self.adj, &self.cost, &self.silhouette, &self.version, b, n)
            {
                // An edge postponed before returns no earlier than its last measurement: a
                // collapse next to it rarely changes it much, and testing it again at the
                // quadric's estimate would only postpone it again.
                if let Some(&k) = self.measured_before.get(&edge_key(b, n)) {
                    x.key = x.key.max(k);
                }
                self.heap.push(x);
            }
        }
        true
    }
}

/// Every edge's queue entry at the quadric's estimate, in parallel over chunks of vertices (the
/// order of the result is the vertices' order, whatever the thread count).
fn initial_entries(
    adj: &Adjacency,
    cost: &QemCost,
    silhouette: &Silhouette,
    version: &[u32],
) -> Vec<Entry> {
    let n = adj.positions.len() as u32;
    let chunks: Vec<Vec<Entry>> = (0..n.div_ceil(512))
        .into_par_iter()
        .map(|c| {
            let mut out = Vec::new();
            for u in c * 512..((c + 1) * 512).min(n) {
                for v in adj.ring(u) {
                    if v > u
                        && let Some(e) = entry(adj, cost, silhouette, version, u, v)
                    {
                        out.push(e);
                    }
                }
            }
            out
        })
        .collect();
    chunks.concat()
}

/// The perceptual and geometric distances (model units) of collapsing the vertex at `from` into
/// the one at `to` (vertices found by position), as the loop's tests measure them.
#[cfg(test)]
pub(crate) fn measure_collapse(
    mesh: &Mesh,
    perception: &Perception,
    from: Vec3,
    to: Vec3,
) -> (f64, f64) {
    let adj = Adjacency::new(mesh);
    let diagonal = mesh.aabb().diagonal() as f64;
    let cost = QemCost::with_attributes(&adj, diagonal);
    let original = Original::new(mesh, &adj);
    let materials = Materials::of(mesh);
    let silhouette = Silhouette::PAPER;
    let nearest = |p: Vec3| {
        (0..adj.positions.len() as u32)
            .min_by(|&x, &y| {
                adj.positions[x as usize]
                    .distance(p)
                    .total_cmp(&adj.positions[y as usize].distance(p))
            })
            .unwrap()
    };
    let (a, b) = (nearest(from), nearest(to));
    let tests = Tests {
        original: &original,
        original_positions: &adj.positions,
        materials: &materials,
        perception: Some(perception),
        silhouette: &silhouette,
        global: &|_, _, _| 0.0,
    };
    let proposal = propose(&adj, &cost, a, b).expect("a legal collapse");
    let attached = Attached::new(adj.positions.len());
    let (perceptual, _) = tests.perceptual(&proposal);
    let deviation =
        hausdorff::deviation(&proposal, &adj, &attached, &original, &adj.positions, None);
    (perceptual, silhouette.distance(deviation as f64))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{LoadOptions, Material, shapes};
    use crate::simplify::menzel_guthe::perception::tests::perception;

    /// `mesh` with every triangle given `material`.
    fn with_material(mesh: &Mesh, material: Material) -> Mesh {
        let mut data = mesh.to_data();
        data.materials = vec![material];
        data.material_ids = vec![0; data.triangles.len()];
        Mesh::new(data, &LoadOptions::DEFAULT).unwrap()
    }

    #[test]
    fn a_collapse_on_a_flat_uniform_region_is_imperceptible_at_any_distance() {
        // Every point of a flat, untextured, uniformly lit plane has the same field in the same
        // frame: nothing differs, whatever the distance; and the plane stays the plane.
        let plane = shapes::grid_plane(8);
        let (perceptual, geometric) = measure_collapse(
            &plane,
            &perception(),
            Vec3::new(4.0, 4.0, 0.0),
            Vec3::new(5.0, 4.0, 0.0),
        );
        assert_eq!(perceptual, 0.0);
        // (The placement is solved in f64 and stored in f32: a deviation of f32 rounding.)
        assert!(geometric < Silhouette::PAPER.distance(1e-6), "{geometric}");
    }

    #[test]
    fn a_collapse_that_moves_a_highlight_is_visible_until_far_away() {
        // A plane (unit squares) with a gentle bump at its centre, 0.3 high: collapsing the bump's
        // top into a neighbour turns the normals around it by up to 30°, which moves the
        // highlight of a shiny material. It stays visible far away (beyond 50 units, six times
        // the plane's width); a matte material changes only its diffuse shading, seen less far.
        let plane = shapes::grid_plane(8);
        let mut data = plane.to_data();
        let top = data
            .positions
            .iter()
            .position(|p| *p == Vec3::new(4.0, 4.0, 0.0))
            .unwrap();
        data.positions[top].z = 0.3;
        data.normals = None;
        let bump = Mesh::new(data, &LoadOptions::DEFAULT).unwrap();
        let material = |specular: f32| Material {
            specular: Vec3::splat(specular),
            shininess: 64.0,
            ..Material::default_material()
        };
        let (shiny, matte) = (
            with_material(&bump, material(0.6)),
            with_material(&bump, material(0.0)),
        );
        let p = perception();
        let (from, to) = (Vec3::new(4.0, 4.0, 0.3), Vec3::new(5.0, 4.0, 0.0));
        let (d_shiny, _) = measure_collapse(&shiny, &p, from, to);
        let (d_matte, _) = measure_collapse(&matte, &p, from, to);
        assert!(d_shiny > 50.0, "shiny: visible only until {d_shiny}");
        assert!(d_shiny > d_matte, "shiny {d_shiny} vs matte {d_matte}");
    }

    #[test]
    fn the_hausdorff_test_rejects_a_collapse_that_moves_the_silhouette() {
        // A plane with a spike of height 2 at its centre: collapsing the spike's tip into a
        // neighbour flattens it, a deviation of over a unit, visible as a silhouette until over
        // 1 700 units (Figure 4: 1 unit subtends 1/30° there); and the loop, asked for what
        // is invisible from 1 000 units on, keeps the spike.
        let plane = shapes::grid_plane(8);
        let mut data = plane.to_data();
        let tip = data
            .positions
            .iter()
            .position(|p| *p == Vec3::new(4.0, 4.0, 0.0))
            .unwrap();
        data.positions[tip].z = 2.0;
        data.normals = None;
        let spiky = Mesh::new(data, &LoadOptions::DEFAULT).unwrap();
        let (_, geometric) = measure_collapse(
            &spiky,
            &perception(),
            Vec3::new(4.0, 4.0, 2.0),
            Vec3::new(5.0, 4.0, 0.0),
        );
        // (The quadric places the merged vertex part way up, so the tip ends about 1.1 from the
        // new surface.)
        assert!(geometric >= Silhouette::PAPER.distance(1.0), "{geometric}");
        let out = run(
            &spiky,
            &perception(),
            &Engine {
                block: 8,
                perception: true,
            },
            Stop {
                distance: Some(1000.0),
                triangles: None,
            },
            &|_, _, _| 0.0,
        );
        let lod = out.progressive.last.to_mesh(&spiky).unwrap();
        let top = lod.positions().iter().map(|p| p.z).fold(f32::MIN, f32::max);
        assert!(top > 1.99, "the spike was flattened to {top}");
        assert!(out.counts.applied > 0, "nothing else was simplified either");
    }

    #[test]
    fn the_record_is_identical_for_any_block_order_and_thread_count() {
        let mesh = shapes::bumpy_sphere(2);
        let p = perception();
        let run_with = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                run(
                    &mesh,
                    &p,
                    &Engine {
                        block: 16,
                        perception: true,
                    },
                    Stop {
                        distance: None,
                        triangles: Some(60),
                    },
                    &|_, _, _| 0.0,
                )
            })
        };
        let one = run_with(1);
        for t in [2, 8] {
            let other = run_with(t);
            assert_eq!(
                one.progressive.collapses, other.progressive.collapses,
                "{t}"
            );
            assert_eq!(one.measured, other.measured);
        }
        assert!(one.counts.applied > 100);
        // Distances never decrease along the record.
        assert!(
            one.progressive
                .collapses
                .windows(2)
                .all(|w| w[0].error <= w[1].error)
        );
    }
}
