//! Twin of shaders/interface.wgsl: interface normal and surface delta of the
//! condensed material (liquid, solid and wall particles; gas and empty space
//! count as outside), R18 (3.25)–(3.27), the Shepard-corrected colour gradient that
//! works at a free surface without gas particles:
//!   Γ_i = Σ_j V_j W_ij,
//!   g_i = Σ_j V_j (1/Γ_i + 1/Γ_j) ∇_iW_ij        (c = 1 inside, 0 outside),
//!   δ_i = |g_i|/κ,  n_i = −g_i/|g_i| (outward) where |g_i| > 0.1/h, else n = 0
//!   and δ = 0 (F22 (20)'s tolerance: such particles are not at the interface, and
//!   surface fluxes must not reach them),
//! κ the planar-lattice normalisation (params::surface_delta_integral),
//! over condensed neighbours j, V = m/ρ0. Stored for liquid and solid particles.

use super::neighbors::{for_each_neighbor, CellTable};
use crate::kernel;
use crate::params::{Params, KIND_GAS};
use crate::state::State;
use rayon::prelude::*;

#[inline(always)]
pub fn condensed(pr: &Params, phase: u32) -> bool {
    pr.phase_a[phase as usize][3] != KIND_GAS
}

pub fn run(pr: &Params, st: &mut State, grid: &CellTable) {
    let n = st.len();
    let (pos, mass, phase) = (&st.pos, &st.mass, &st.phase);
    let vol = |j: usize| mass[j] / pr.phase_a[phase[j] as usize][0];
    let gamma: Vec<f32> = (0..n)
        .into_par_iter()
        .map(|i| {
            if !condensed(pr, phase[i]) {
                return 0.0;
            }
            let mut g = 0.0f32;
            for_each_neighbor(pr, pos, grid, i, |j, _, r2| {
                if condensed(pr, phase[j]) {
                    g += vol(j) * kernel::w(pr, r2.sqrt());
                }
            });
            g
        })
        .collect();
    let inv_h = pr.kernel[1];
    let normals: Vec<[f32; 4]> = (0..n)
        .into_par_iter()
        .map(|i| {
            if !condensed(pr, phase[i]) || !pr.conducts(phase[i]) {
                return [0.0; 4];
            }
            let mut g = [0.0f32; 3];
            for_each_neighbor(pr, pos, grid, i, |j, d, r2| {
                if r2 <= 0.0 || !condensed(pr, phase[j]) {
                    return;
                }
                let r = r2.sqrt();
                let f = vol(j) * (1.0 / gamma[i] + 1.0 / gamma[j]) * kernel::dw(pr, r) / r;
                for a in 0..3 {
                    g[a] += f * d[a];
                }
            });
            let delta = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            if delta > 0.1 * inv_h {
                let scaled = delta * pr.interface[0];
                [-g[0] / delta, -g[1] / delta, -g[2] / delta, scaled]
            } else {
                [0.0; 4]
            }
        })
        .collect();
    st.surface[..n].copy_from_slice(&normals);
    for (s, g) in st.surface[n..].iter_mut().zip(gamma) {
        *s = [g, 0.0, 0.0, 0.0];
    }
}
