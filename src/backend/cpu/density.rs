//! Twin of shaders/density.wgsl: summation density ρ_i = m_i Σ_j W_ij over all
//! neighbours (F22 §3.3, exact mass, multiphase-safe) and the EOS p = c²(ρ − ρ0)
//! (F22 (3)), clamped at p ≥ 0 when the scene asks for a pressure floor.

use super::neighbors::{with_neighbors, CellTable, ListChunk, NeighborList, LIST_CHUNK};
use crate::kernel;
use crate::params::{Params, FLAG_PRESSURE_FLOOR};
use crate::state::State;
use rayon::prelude::*;

/// Also records each fluid particle's neighbours in `list` for the forces pass
/// (and each conducting solid's, `record_solid`).
pub fn run(pr: &Params, st: &mut State, grid: &CellTable, list: &mut NeighborList) {
    let n = st.active();
    let (pos, mass, phase) = (&st.pos, &st.mass, &st.phase);
    let chunks = list.take_chunks(n.div_ceil(LIST_CHUNK));
    let chunks: Vec<ListChunk> = st.rho[..n]
        .par_chunks_mut(LIST_CHUNK)
        .zip(st.press[..n].par_chunks_mut(LIST_CHUNK))
        .zip(chunks)
        .enumerate()
        .map(|(c, ((rho, p), mut chunk))| {
            for k in 0..rho.len() {
                let i = c * LIST_CHUNK + k;
                let ph = phase[i];
                if pr.is_wall(ph) {
                    record_solid(pr, pos, grid, i, ph, &mut chunk);
                    continue;
                }
                let sum = with_neighbors(pr, pos, grid, i, |js, r2| {
                    chunk.push(js);
                    kernel::sum_w(pr, r2)
                });
                let r = mass[i] * sum;
                rho[k] = r;
                p[k] = equation_of_state(pr, ph, r);
            }
            chunk
        })
        .collect();
    list.store(grid, chunks);
}

/// The list entry of wall-kind particle i: a conducting solid's neighbours,
/// which the interface pass (twice) and conduction sweep later in the step,
/// so that they read the list instead of sweeping the cells three times (the
/// same neighbours in the same order, so the same bits); none for a wall.
#[inline(always)]
pub fn record_solid(
    pr: &Params,
    pos: &[[f32; 4]],
    grid: &CellTable,
    i: usize,
    phase: u32,
    chunk: &mut ListChunk,
) {
    if pr.conducts(phase) {
        with_neighbors(pr, pos, grid, i, |js, _| chunk.push(js));
    } else {
        chunk.push(&[]);
    }
}

#[inline(always)]
pub fn equation_of_state(pr: &Params, phase: u32, rho: f32) -> f32 {
    equation_of_state_about(pr, phase, rho, pr.phase(phase).rho0)
}

/// p = c²(ρ − ρ0) about a given reference density (δ-SPH's ρ0(T)), clamped at 0
/// with the pressure floor.
#[inline(always)]
pub fn equation_of_state_about(pr: &Params, phase: u32, rho: f32, rho0: f32) -> f32 {
    let p = pr.phase(phase).c2 * (rho - rho0);
    if pr.flag(FLAG_PRESSURE_FLOOR) {
        p.max(0.0)
    } else {
        p
    }
}
