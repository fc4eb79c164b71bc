//! Twin of shaders/neighbors.wgsl: cell keys, the (cell, index) sort, reordering of
//! every particle array by cell, the cell start/end table and the count of
//! particles that have left (sorted last, in no cell).
//! Keys are unique, so any correct sort gives the one order the GPU's bitonic sort gives.
//!
//! The grid (grid.rs), the neighbour walks (walks.rs) and their SIMD sweeps
//! (simd.rs) are beside this file.

mod grid;
mod simd;
mod walks;

use grid::cell_key;
pub use grid::{cell_coord, cell_index, fluid_nearby, min_image, CellTable};
pub use walks::{
    for_each_listed, for_each_near, for_each_neighbor, for_each_neighbor_among, with_listed,
    with_neighbors, Among, ListChunk, NeighborList, LIST_CHUNK,
};

use crate::fields::{Held, FIELDS};
use crate::params::Params;
use crate::state::State;
use rayon::prelude::*;

pub fn run(pr: &Params, st: &mut State, grid: &mut CellTable) {
    let n = st.len();
    let (mut keys, mut perm) = (
        std::mem::take(&mut grid.keys),
        std::mem::take(&mut grid.perm),
    );
    st.pos
        .par_iter()
        .enumerate()
        .map(|(i, p)| (cell_key(pr, p, st.phase[i]), i as u32))
        .collect_into_vec(&mut keys);
    keys.par_sort_unstable();
    keys.par_iter()
        .map(|k| k.1 as usize)
        .collect_into_vec(&mut perm);
    // Every sorted field the scene holds (crate::fields); the others are
    // recomputed after the sort.
    let held = Held::of_state(st);
    for f in FIELDS.iter().filter(|f| f.sorted_in(held)) {
        (f.permute)(st, &perm);
    }
    let n_cells = pr.sizes.n_cells as usize;
    grid.invalidate();
    grid.start.clear();
    grid.start.resize(n_cells, 0);
    grid.end.clear();
    grid.end.resize(n_cells, 0);
    grid.fluid.clear();
    grid.fluid.resize(n_cells, false);
    let gone = pr.sizes.n_cells;
    st.sim.removed = keys.iter().rev().take_while(|k| k.0 == gone).count() as u32;
    for k in 0..n - st.sim.removed as usize {
        let c = keys[k].0;
        if k == 0 || keys[k - 1].0 != c {
            grid.start[c as usize] = k as u32;
        }
        if k == n - 1 || keys[k + 1].0 != c {
            grid.end[c as usize] = k as u32 + 1;
        }
        if !pr.is_wall(st.phase[k]) {
            grid.fluid[c as usize] = true;
        }
    }
    (grid.keys, grid.perm) = (keys, perm);
}

#[cfg(test)]
mod tests {
    use super::grid::floor_to_i32;
    #[cfg(target_arch = "x86_64")]
    use super::simd::{compact_avx2, compact_avx512, AVX512};
    use super::walks::{listed, Candidates};
    use super::*;
    use crate::backend::cpu::recorded::RETRY_STEPS;

    type Visit = (usize, [u32; 3], u32);

    fn bits(j: usize, d: [f32; 3], r2: f32) -> Visit {
        (j, d.map(f32::to_bits), r2.to_bits())
    }

    /// The pairs a walk reports, in its order, as bits.
    fn visits(walk: impl FnOnce(&mut dyn FnMut(usize, [f32; 3], f32))) -> Vec<Visit> {
        let mut seen = Vec::new();
        walk(&mut |j, d, r2| seen.push(bits(j, d, r2)));
        seen
    }

    /// `floor_to_i32` is `floor` then the saturating `as i32`, at the integers,
    /// between them, at the ends of the i32 range and past them, and for a NaN.
    #[test]
    fn floor_to_i32_is_floor() {
        let mut xs = vec![
            0.0,
            -0.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            f32::MIN,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            2147483648.0,
            -2147483648.0,
            -2147483904.0,
            16777217.0,
            -8388607.5,
        ];
        for k in -2000..2000 {
            let x = k as f32 * 0.37;
            xs.extend([x, x.next_up(), x.next_down(), k as f32]);
        }
        for x in xs {
            assert_eq!(floor_to_i32(x), x.floor() as i32, "x = {x:e}");
        }
    }

    /// The sixteen-lane sweeps (AVX-512F) find the neighbours and r² the
    /// eight-lane ones (AVX2) find, in the same order, with the same bits:
    /// on every particle's gathered candidates of a jittered 3D scene, less
    /// the last i mod 16 of them for particle i, so that every tail length
    /// occurs. Where the CPU lacks AVX-512F there is nothing to compare (the
    /// eight-lane sweep is the one that runs).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn sixteen_lane_sweeps_match_the_eight_lane_ones() {
        if !*AVX512 {
            eprintln!("no AVX-512F here: only the eight-lane sweeps run");
            return;
        }
        let (pr, st, grid) = jittered("dam_break_3d");
        let mut near = Candidates::default();
        let mut tails = [false; 16];
        for i in 0..st.len() {
            near.gather(&pr, &st.pos, &grid, &st.pos[i], Among::All);
            let keep = near.j.len().saturating_sub(i % 16);
            near.j.truncate(keep);
            near.x.truncate(keep);
            near.y.truncate(keep);
            near.z.truncate(keep);
            near.key = Default::default(); // gather afresh for the next one
            tails[keep % 16] = true;
            // SAFETY: AVX-512F (checked above) implies the AVX2 of `AVX512`.
            let narrow = unsafe { near.neighbours_avx2(&pr, st.pos[i]) };
            let eight = (
                near.hit_j[..narrow].to_vec(),
                bits_of(&near.hit_r2[..narrow]),
            );
            let wide = unsafe { near.neighbours_avx512(&pr, st.pos[i]) };
            let sixteen = (near.hit_j[..wide].to_vec(), bits_of(&near.hit_r2[..wide]));
            assert_eq!(eight, sixteen, "neighbours of particle {i}");
            near.differences(&pr, st.pos[i]);
            let n = near.j.len();
            let (hits, hit_r2) = (&mut near.hits, &mut near.hit_r2);
            let support2 = pr.kernel.support2;
            let narrow = unsafe { compact_avx2(&near.r2[..n], support2, hits, hit_r2) };
            let eight = (hits[..narrow].to_vec(), bits_of(&hit_r2[..narrow]));
            let wide = unsafe { compact_avx512(&near.r2[..n], support2, hits, hit_r2) };
            let sixteen = (hits[..wide].to_vec(), bits_of(&hit_r2[..wide]));
            assert_eq!(eight, sixteen, "compaction of particle {i}");
        }
        assert!(tails.iter().all(|&t| t), "tail lengths seen: {tails:?}");
    }

    fn bits_of(v: &[f32]) -> Vec<u32> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// A scene with jittered particles (irregular distances), sorted into cells.
    fn jittered(scene: &str) -> (Params, State, CellTable) {
        let path = format!(
            "{}/scenarios/validation/{scene}.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let l = crate::load::load(&path, &["jitter=0.3".into()]).unwrap();
        let pr = Params::new(&l.model, 2);
        let mut st = l.state.clone();
        let mut grid = CellTable::default();
        run(&pr, &mut st, &mut grid);
        (pr, st, grid)
    }

    /// The cached sweep (`for_each_neighbor`), the recorded list
    /// (`for_each_listed`) and the list's fallback after `invalidate` visit exactly
    /// the pairs of the plain cell walk (`for_each_near`), in its order, with the
    /// same bits of d and r²: periodic 2D and walled 3D.
    #[test]
    fn sweep_and_list_match_the_plain_walk() {
        for scene in ["poiseuille_2d", "dam_break_3d"] {
            let (pr, mut st, mut grid) = jittered(scene);
            let mut list = NeighborList::default();
            super::super::density::run(&pr, &mut st, &grid, &mut list);
            let pos = &st.pos;
            let mut pairs = 0;
            for i in 0..pos.len() {
                let walk = visits(|f| for_each_near(&pr, pos, &grid, pos[i], f));
                let swept = visits(|f| for_each_neighbor(&pr, pos, &grid, i, f));
                assert_eq!(walk, swept, "{scene}: sweep of particle {i}");
                if !pr.is_wall(st.phase[i]) {
                    let listed = visits(|f| for_each_listed(&pr, pos, &grid, &list, i, f));
                    assert_eq!(walk, listed, "{scene}: list of particle {i}");
                    assert!(walks::listed(&list, &grid, i).is_some());
                }
                pairs += walk.len();
            }
            assert!(pairs > 10 * pos.len(), "{scene}: {pairs} pairs");
            grid.invalidate();
            let i = (0..pos.len()).find(|&i| !pr.is_wall(st.phase[i])).unwrap();
            assert!(listed(&list, &grid, i).is_none(), "stale list used");
            let walk = visits(|f| for_each_near(&pr, pos, &grid, pos[i], f));
            let listed = visits(|f| for_each_listed(&pr, pos, &grid, &list, i, f));
            assert_eq!(walk, listed, "{scene}: fallback sweep");
        }
    }

    /// A list over its bound is dropped and not recorded again for
    /// RETRY_STEPS steps (the passes sweep the cells meanwhile, with the same
    /// neighbours), then recorded again.
    #[test]
    fn a_list_over_its_bound_waits_before_it_is_recorded_again() {
        let (pr, mut st, grid) = jittered("dam_break_3d");
        let fluid = (0..st.len()).find(|&i| !pr.is_wall(st.phase[i])).unwrap();
        let mut list = NeighborList::default();
        let chunks = list.take_chunks(st.active().div_ceil(LIST_CHUNK));
        let mut filled = chunks;
        for (c, chunk) in filled.iter_mut().enumerate() {
            for i in c * LIST_CHUNK..((c + 1) * LIST_CHUNK).min(st.active()) {
                with_neighbors(&pr, &st.pos, &grid, i, |js, _| chunk.push(js));
            }
        }
        list.store_within(&grid, filled, 10);
        assert!(
            listed(&list, &grid, fluid).is_none(),
            "a list over its bound was kept"
        );
        for step in 0..RETRY_STEPS {
            super::super::density::run(&pr, &mut st, &grid, &mut list);
            assert!(
                listed(&list, &grid, fluid).is_none(),
                "recorded again at step {step}"
            );
        }
        super::super::density::run(&pr, &mut st, &grid, &mut list);
        assert!(
            listed(&list, &grid, fluid).is_some(),
            "never recorded again"
        );
    }

    /// A walk from inside a neighbour callback (the thread's candidate cache is
    /// held) sees the same neighbours as a plain walk, and leaves the outer walk's
    /// cache intact.
    #[test]
    fn nested_walks_match_the_plain_walk() {
        let (pr, st, grid) = jittered("dam_break_3d");
        let pos = &st.pos;
        let i = pos.len() / 2;
        let mut outer: Vec<Visit> = Vec::new();
        let mut nested = 0;
        for_each_neighbor(&pr, pos, &grid, i, |j, d, r2| {
            outer.push(bits(j, d, r2));
            let walk = visits(|f| for_each_near(&pr, pos, &grid, pos[j], f));
            let inner = visits(|f| for_each_neighbor(&pr, pos, &grid, j, f));
            assert_eq!(walk, inner, "nested walk from particle {j}");
            nested += 1;
        });
        let walk = visits(|f| for_each_near(&pr, pos, &grid, pos[i], f));
        assert_eq!(walk, outer, "outer walk of particle {i}");
        assert!(nested > 10, "{nested} neighbours");
    }
}
