//! Twin of shaders/wall.wgsl: generalized wall boundary (Adami, Hu & Adams 2012).
//! Each wall particle w gathers from its fluid neighbours f:
//!   p_w = (Σ p_f W_wf + g·Σ ρ_f r_wf W_wf) / Σ W_wf        (stationary wall, a_w = 0)
//!   ũ_w = Σ u_f W_wf / Σ W_wf,  u_w = 2 u_wall − ũ_w        (no-slip velocity)
//! with Σ W_wf + ε as the divisor (see `run`), so u_w = u_wall + (u_wall Σ W − Σ u W)/(Σ W + ε).
//! The wall's displayed density is its material's EOS inverted at p_w.

use super::neighbors::{fluid_nearby, for_each_neighbor, CellTable};

#[inline(always)]
fn for_each_neighbor_if(
    gather: bool,
    pr: &Params,
    pos: &[[f32; 4]],
    grid: &CellTable,
    i: usize,
    f: impl FnMut(usize, [f32; 3], f32),
) {
    if gather {
        for_each_neighbor(pr, pos, grid, i, f);
    }
}
use crate::kernel;
use crate::params::{Params, FLAG_PRESSURE_FLOOR};
use crate::state::State;
use rayon::prelude::*;

pub fn run(pr: &Params, st: &mut State, grid: &CellTable) {
    let n = st.len();
    let (pos, phase) = (&st.pos, &st.phase);
    let (rho_in, p_in, vel_in) = (&st.rho, &st.p, &st.vel);
    let out: Vec<Option<(f32, f32, [f32; 4])>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let ph = phase[i];
            if !pr.is_wall(ph) {
                return None;
            }
            let mut sw = 0.0f32;
            let mut sp = 0.0f32;
            let mut sr = [0.0f32; 3];
            let mut sv = [0.0f32; 3];
            // Without fluid in the cells around, the sums stay zero: skip the loop
            // (most of a substrate in a heat scene).
            let gather = fluid_nearby(pr, grid, &pos[i]);
            for_each_neighbor_if(gather, pr, pos, grid, i, |j, d, r2| {
                if pr.is_wall(phase[j]) {
                    return;
                }
                let wk = kernel::w(pr, r2.sqrt());
                sw += wk;
                sp += p_in[j] * wk;
                let rw = rho_in[j] * wk;
                let v = vel_in[j];
                for a in 0..3 {
                    sr[a] += rw * d[a];
                    sv[a] += v[a] * wk;
                }
            });
            let b = pr.phase_b[ph as usize];
            let m = pr.phase_a[ph as usize];
            // Regularised Shepard division: Σ W + ε instead of Σ W, ε = 1e-9 W(0).
            // At an exact lattice tie a fluid particle sits at the edge of the
            // support, where W is 0 or a few ULP above it depending on rounding; a
            // plain division then jumps between p = 0 (nothing gathered) and a full
            // extrapolated pressure (tiny/tiny), and a GPU that fuses r² differently
            // picks the other side. With ε the result goes to 0 continuously as
            // Σ W -> 0, and for Σ W ≥ 1e-4 W(0) (every fluid neighbour closer than
            // 2.6h with the quintic) ε changes it by at most 1e-5 relative.
            let g = pr.gravity;
            let den = sw + pr.wall[0];
            let mut p = (sp + (g[0] * sr[0] + g[1] * sr[1] + g[2] * sr[2])) / den;
            let v = [
                b[0] + (b[0] * sw - sv[0]) / den,
                b[1] + (b[1] * sw - sv[1]) / den,
                b[2] + (b[2] * sw - sv[2]) / den,
                0.0,
            ];
            if pr.grid[3] & FLAG_PRESSURE_FLOOR != 0 {
                p = p.max(0.0);
            }
            Some((m[0] + p / m[1], p, v))
        })
        .collect();
    for (i, o) in out.into_iter().enumerate() {
        if let Some((rho, p, v)) = o {
            st.rho[i] = rho;
            st.p[i] = p;
            st.vel[i] = v;
        }
    }
}
