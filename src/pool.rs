//! The melt pool of a state: the largest connected region of
//! melt, and the detached melt beside it (splashed droplets, molten grains not
//! yet joined to the pool). Host side, in f64, from a state read back.
//!
//! - Melt: a particle of a conducting liquid or solid phase with liquid
//!   fraction ≥ ½ (the figures `/diagnostics` and the track have always used).
//! - Connected: two melt particles closer than 1.5 Δx (the lattice's nearest
//!   and diagonal neighbours at 1 and 1.41 Δx; a droplet one spacing clear of
//!   the pool is apart from it).
//! - The pool: the region with the most particles. Every other region is
//!   detached melt (droplets flying or landed on the surface or in the track,
//!   lone molten grains), counted by regions, particles and mass. Tried and
//!   dropped: every region reaching below the initial surface. It keeps a thin
//!   2D pool whole where a keyhole parts it, but on the 3D bare plate the
//!   droplets that land in the sunken track join it (longest 597 µm against
//!   292 µm for the largest region); a 2D pool two or three particles deep does
//!   part at times (line_melt_coarse_2d: 64 to 186 µm from sample to sample).

use crate::model::Model;
use crate::scene::PhaseKind;
use crate::state::State;

/// Link distance between two melt particles of one region, in Δx.
pub const LINK_DX: f64 = 1.5;

/// The melt regions of one state.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeltRegions {
    /// Indices (into the state) of the pool's particles.
    pub pool: Vec<usize>,
    /// Regions other than the pool.
    pub detached_regions: usize,
    pub detached_particles: usize,
    /// kg (per metre of depth in 2D).
    pub detached_mass: f64,
}

/// Is particle i melt?
pub fn is_melt(m: &Model, st: &State, i: usize) -> bool {
    let ph = &m.phases[st.phase[i] as usize];
    ph.conducts() && matches!(ph.kind, PhaseKind::Liquid | PhaseKind::Solid) && st.heat[i][2] >= 0.5
}

/// Union–find root with path halving.
fn root(parent: &mut [usize], mut k: usize) -> usize {
    while parent[k] != k {
        parent[k] = parent[parent[k]];
        k = parent[k];
    }
    k
}

/// Connected regions of points (world coordinates): two points closer than
/// `link` share a region. Returns each point's region label (0, 1, ...; in the
/// order of each region's first point) and the number of regions.
///
/// The points are sorted by cells of side `link` (packed keys, in parallel);
/// each cell is paired once with itself and once with each of its forward
/// neighbours (13 in 3D, 4 in 2D), found by binary search among the occupied
/// cells. Each sample of a run pays it on the host (the watchdog's breakup
/// watch over every dense particle, the pool over the melt): 0.48–0.60 s for
/// 1e6 points on a lattice (link 1.5 spacings) on 2 cores, against 1.12–1.32 s
/// with a hash map of cells probed 27 times per point; at F22's 1.7e7
/// particles about 10 s a sample.
pub fn connected_regions(pos: &[[f64; 3]], link: f64, dim: u32) -> (Vec<usize>, usize) {
    use rayon::prelude::*;
    assert!(pos.len() <= u32::MAX as usize, "point indices are u32");
    let coord = |x: &[f64; 3]| x.map(|c| (c / link).floor() as i64);
    let mut order: Vec<(u64, u32)> = pos
        .par_iter()
        .enumerate()
        .map(|(k, x)| (cell_key(coord(x)), k as u32))
        .collect();
    order.par_sort_unstable();
    // Runs of one key: (key, start, end) in `order`.
    let mut cells: Vec<(u64, usize, usize)> = Vec::new();
    for (k, &(key, _)) in order.iter().enumerate() {
        match cells.last_mut() {
            Some(last) if last.0 == key => last.2 = k + 1,
            _ => cells.push((key, k, k + 1)),
        }
    }
    let mut parent: Vec<usize> = (0..pos.len()).collect();
    let mut join = |a: usize, b: usize| {
        let d2: f64 = (0..3).map(|c| (pos[a][c] - pos[b][c]).powi(2)).sum();
        if d2 < link * link {
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            parent[ra.max(rb)] = ra.min(rb);
        }
    };
    let forward = forward_cells(dim);
    for &(_, s, e) in &cells {
        let points = &order[s..e];
        for (k, &(_, a)) in points.iter().enumerate() {
            for &(_, b) in &points[k + 1..] {
                join(a as usize, b as usize);
            }
        }
        let c = coord(&pos[points[0].1 as usize]);
        for o in &forward {
            let key = cell_key([0, 1, 2].map(|a| c[a].wrapping_add(o[a])));
            let Ok(at) = cells.binary_search_by_key(&key, |cell| cell.0) else {
                continue;
            };
            let (_, s2, e2) = cells[at];
            for &(_, a) in points {
                for &(_, b) in &order[s2..e2] {
                    join(a as usize, b as usize);
                }
            }
        }
    }
    labels(&mut parent)
}

/// Each point's region label from a union–find forest whose roots are each
/// region's lowest index: regions numbered in index order, and their count.
fn labels(parent: &mut [usize]) -> (Vec<usize>, usize) {
    let mut label = vec![usize::MAX; parent.len()];
    let mut n = 0;
    for k in 0..parent.len() {
        let r = root(parent, k);
        if label[r] == usize::MAX {
            label[r] = n;
            n += 1;
        }
        label[k] = label[r];
    }
    (label, n)
}

/// A cell's coordinates packed 21 bits each. Cells more than 2^20 apart can
/// share a key; the distance test keeps that from joining anything.
fn cell_key(c: [i64; 3]) -> u64 {
    const MASK: i64 = (1 << 21) - 1;
    let f = |v: i64| (v.wrapping_add(1 << 20) & MASK) as u64;
    (f(c[2]) << 42) | (f(c[1]) << 21) | f(c[0])
}

/// The neighbour cells after a cell in key order (z, then y, then x): each
/// pair of neighbouring cells is visited once.
fn forward_cells(dim: u32) -> Vec<[i64; 3]> {
    let zs: &[i64] = if dim == 3 { &[-1, 0, 1] } else { &[0] };
    let mut out = Vec::new();
    for &z in zs {
        for y in -1..=1 {
            for x in -1..=1 {
                if (z, y, x) > (0, 0, 0) {
                    out.push([x, y, z]);
                }
            }
        }
    }
    out
}

/// The melt regions of `st` (empty outside heat scenes).
pub fn melt_regions(m: &Model, st: &State) -> MeltRegions {
    if st.heat.is_empty() {
        return MeltRegions::default();
    }
    let melt: Vec<usize> = (0..st.active()).filter(|&i| is_melt(m, st, i)).collect();
    let pos: Vec<[f64; 3]> = melt.iter().map(|&i| m.to_world(st.pos[i])).collect();
    let (label, n) = connected_regions(&pos, LINK_DX * m.dx, m.dim);
    if n == 0 {
        return MeltRegions::default();
    }
    let mut size = vec![(0usize, 0.0f64); n];
    for (k, &r) in label.iter().enumerate() {
        size[r].0 += 1;
        size[r].1 += st.mass[melt[k]] as f64;
    }
    // The largest region; ties to the first.
    let pool = (0..n).fold(0, |best, r| if size[r].0 > size[best].0 { r } else { best });
    MeltRegions {
        pool: (0..melt.len())
            .filter(|&k| label[k] == pool)
            .map(|k| melt[k])
            .collect(),
        detached_regions: n - 1,
        detached_particles: melt.len() - size[pool].0,
        detached_mass: size.iter().map(|s| s.1).sum::<f64>() - size[pool].1,
    }
}

/// The melt pool's figures at one state (`/diagnostics`, crate::pool).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PoolFigures {
    pub depth: f64,
    pub width: f64,
    pub length: f64,
    pub volume: f64,
    pub detached_regions: u64,
    pub detached_particles: u64,
    pub detached_mass: f64,
}

impl PoolFigures {
    /// From the state's melt regions; `depth` below the initial surface where
    /// the caller knows it (the track), else the pool's height.
    pub fn of(m: &Model, st: &State, r: &MeltRegions, depth: Option<f64>) -> PoolFigures {
        let mut f = PoolFigures {
            detached_regions: r.detached_regions as u64,
            detached_particles: r.detached_particles as u64,
            detached_mass: r.detached_mass,
            ..PoolFigures::default()
        };
        if let Some(e) = PoolExtent::of(m, st, &r.pool) {
            let up = m.dim as usize - 1;
            f.length = e.size(0, m.dx);
            f.width = if m.dim == 3 { e.size(1, m.dx) } else { 0.0 };
            f.depth = depth.unwrap_or(e.size(up, m.dx));
            f.volume = r.pool.len() as f64 * m.dx.powi(m.dim as i32);
        }
        f
    }
}

/// The bounding box of a set of particles (world coordinates).
pub struct PoolExtent(pub [[f64; 2]; 3]);

impl PoolExtent {
    pub fn of(m: &Model, st: &State, members: &[usize]) -> Option<PoolExtent> {
        if members.is_empty() {
            return None;
        }
        let mut b = [[f64::INFINITY, f64::NEG_INFINITY]; 3];
        for &i in members {
            let x = m.to_world(st.pos[i]);
            for a in 0..3 {
                b[a] = [b[a][0].min(x[a]), b[a][1].max(x[a])];
            }
        }
        Some(PoolExtent(b))
    }
    /// The extent along axis a, counting each particle as Δx wide.
    pub fn size(&self, a: usize, dx: f64) -> f64 {
        self.0[a][1] - self.0[a][0] + dx
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_droplet_one_spacing_clear_is_its_own_region() {
        // A row of 5 at spacing 1, a diagonal neighbour, and a droplet 2.5 away.
        let mut pos: Vec<[f64; 3]> = (0..5).map(|k| [k as f64, 0.0, 0.0]).collect();
        pos.push([4.0 + 1.0, 1.0, 0.0]);
        pos.push([5.0 + 2.5, 1.0, 0.0]);
        let (label, n) = connected_regions(&pos, 1.5, 2);
        assert_eq!(n, 2);
        assert_eq!(label, vec![0, 0, 0, 0, 0, 0, 1]);
    }

    /// The cell sweep gives the regions of the all-pairs definition, on
    /// scattered points in 2D and 3D (negative coordinates included).
    #[test]
    fn regions_match_every_pair_compared() {
        for dim in [2u32, 3] {
            let mut r = crate::random::SplitMix(7 + dim as u64);
            let pos: Vec<[f64; 3]> = (0..1500)
                .map(|_| {
                    let mut x = [0.0; 3];
                    for c in x.iter_mut().take(dim as usize) {
                        *c = 24.0 * r.next_f64() - 12.0;
                    }
                    x
                })
                .collect();
            let link = if dim == 3 { 1.1 } else { 0.5 };
            let (label, n) = connected_regions(&pos, link, dim);
            let mut parent: Vec<usize> = (0..pos.len()).collect();
            for a in 0..pos.len() {
                for b in a + 1..pos.len() {
                    let d2: f64 = (0..3).map(|c| (pos[a][c] - pos[b][c]).powi(2)).sum();
                    if d2 < link * link {
                        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                        parent[ra.max(rb)] = ra.min(rb);
                    }
                }
            }
            let (want, m) = labels(&mut parent);
            assert!(n > 20 && n < pos.len() - 20, "dim {dim}: {n} regions");
            assert_eq!((n, &label), (m, &want), "dim {dim}");
        }
    }

    /// Edge cases: nothing; two points on one spot; exactly `link` apart (not
    /// linked: the test is strict); 2^21 cells apart, where the packed cell
    /// keys coincide (not linked); and a linked pair across the keys' wrap.
    #[test]
    fn regions_at_the_edges() {
        assert_eq!(connected_regions(&[], 1.0, 3), (vec![], 0));
        let same = [[0.5, 0.5, 0.5]; 2];
        assert_eq!(connected_regions(&same, 1.0, 3), (vec![0, 0], 1));
        let apart = [[0.0; 3], [1.0, 0.0, 0.0]];
        assert_eq!(connected_regions(&apart, 1.0, 3), (vec![0, 1], 2));
        let far = (1u64 << 21) as f64;
        let aliased = [[0.2, 0.0, 0.0], [far + 0.3, 0.0, 0.0]];
        assert_eq!(connected_regions(&aliased, 1.0, 3), (vec![0, 1], 2));
        let wrap = (1u64 << 20) as f64;
        let across = [
            [wrap - 0.1, 0.0, 0.0],
            [wrap + 0.1, 0.0, 0.0],
            [1e300, 0.0, 0.0],
        ];
        assert_eq!(connected_regions(&across, 1.0, 3), (vec![0, 0, 1], 2));
    }
}
