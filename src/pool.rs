//! The melt pool of a state (issue 29 item 1): the largest connected region of
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
use std::collections::HashMap;

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
pub fn connected_regions(pos: &[[f64; 3]], link: f64, dim: u32) -> (Vec<usize>, usize) {
    let cell_of = |x: &[f64; 3]| x.map(|c| (c / link).floor() as i64);
    let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (k, x) in pos.iter().enumerate() {
        cells.entry(cell_of(x)).or_default().push(k);
    }
    let mut parent: Vec<usize> = (0..pos.len()).collect();
    let dz = if dim == 3 { -1..=1 } else { 0..=0 };
    for (k, x) in pos.iter().enumerate() {
        let c = cell_of(x);
        for ox in -1..=1 {
            for oy in -1..=1 {
                for oz in dz.clone() {
                    let Some(list) = cells.get(&[c[0] + ox, c[1] + oy, c[2] + oz]) else {
                        continue;
                    };
                    for &j in list.iter().filter(|&&j| j > k) {
                        let d2: f64 = (0..3).map(|a| (pos[j][a] - x[a]).powi(2)).sum();
                        if d2 < link * link {
                            let (a, b) = (root(&mut parent, k), root(&mut parent, j));
                            parent[a.max(b)] = a.min(b);
                        }
                    }
                }
            }
        }
    }
    // Roots are each region's lowest index: label them in index order.
    let mut label = vec![usize::MAX; pos.len()];
    let mut n = 0;
    for k in 0..pos.len() {
        let r = root(&mut parent, k);
        if label[r] == usize::MAX {
            label[r] = n;
            n += 1;
        }
        label[k] = label[r];
    }
    (label, n)
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
}
