//! Twin of shaders/density.wgsl: summation density ρ_i = m_i Σ_j W_ij over all
//! neighbours (F22 §3.3, exact mass, multiphase-safe) and the EOS p = c²(ρ − ρ0)
//! (F22 (3)), clamped at p ≥ 0 when the scene asks for a pressure floor.

use super::neighbors::{with_neighbor_r2, CellTable};
use crate::kernel;
use crate::params::{Params, FLAG_PRESSURE_FLOOR};
use crate::state::State;
use rayon::prelude::*;

pub fn run(pr: &Params, st: &mut State, grid: &CellTable) {
    let (pos, mass, phase) = (&st.pos, &st.mass, &st.phase);
    st.rho
        .par_iter_mut()
        .zip(st.p.par_iter_mut())
        .enumerate()
        .for_each(|(i, (rho, p))| {
            let ph = phase[i];
            if pr.is_wall(ph) {
                return;
            }
            let sum = with_neighbor_r2(pr, pos, grid, i, |r2| kernel::sum_w(pr, r2));
            let r = mass[i] * sum;
            *rho = r;
            *p = equation_of_state(pr, ph, r);
        });
}

#[inline(always)]
pub fn equation_of_state(pr: &Params, phase: u32, rho: f32) -> f32 {
    let m = pr.phase_a[phase as usize];
    let p = m[1] * (rho - m[0]);
    if pr.grid[3] & FLAG_PRESSURE_FLOOR != 0 {
        p.max(0.0)
    } else {
        p
    }
}
