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
//! over condensed neighbours j, V = m/ρ0. Stored for conducting liquid and solid
//! particles, and for liquid ones with surface tension
//! (`Params::gets_free_surface_normal`).
//!
//! With gas particles in the scene the interface is the condensed–gas one of
//! F22 (19)–(20) instead, for every conducting particle i (every fluid particle
//! with the interface viscosity on, `Params::gets_gas_interface`) over neighbours j of the
//! other class (condensed: liquid, solid, wall; or gas):
//!   ∇c_i = (1/V_i) Σ_j (V_i² + V_j²) ρ_i/(ρ_i + ρ_j) ∂W/∂r e_ij,
//!   δ_i = |∇c_i|/κ_F22,  n_i = ∇c_i/|∇c_i| (outward with respect to i's phase),
//! V = m/ρ (summation density for fluids, ρ0 for solids and walls), κ_F22 the
//! same planar-lattice normalisation of the condensed side's δ.

use super::neighbors::{for_each_neighbor, CellTable};
use crate::kernel;
use crate::params::{Params, FLAG_GAS_INTERFACE, KIND_GAS};
use crate::state::State;
use rayon::prelude::*;

#[inline(always)]
pub fn condensed(pr: &Params, phase: u32) -> bool {
    pr.phases[phase as usize].kind != KIND_GAS
}

pub fn run(pr: &Params, st: &mut State, grid: &CellTable) {
    if pr.flag(FLAG_GAS_INTERFACE) {
        return gas_interface(pr, st, grid);
    }
    // Sums of the particles still in the simulation; the Shepard sums follow all n.
    let (n, active) = (st.len(), st.active());
    let (pos, mass, phase) = (&st.pos, &st.mass, &st.phase);
    let vol = |j: usize| mass[j] / pr.phases[phase[j] as usize].rho0;
    let gamma: Vec<f32> = (0..active)
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
    let inv_h = pr.kernel.inv_h;
    let normals: Vec<[f32; 4]> = (0..active)
        .into_par_iter()
        .map(|i| {
            if !condensed(pr, phase[i]) || !pr.gets_free_surface_normal(phase[i]) {
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
                let scaled = delta * pr.surfaces.inv_kappa;
                [-g[0] / delta, -g[1] / delta, -g[2] / delta, scaled]
            } else {
                [0.0; 4]
            }
        })
        .collect();
    st.surface[..active].copy_from_slice(&normals);
    for (s, g) in st.surface[n..n + active].iter_mut().zip(gamma) {
        *s = [g, 0.0, 0.0, 0.0];
    }
}

/// Density of a particle for volumes: summation density for fluids, ρ0 otherwise.
#[inline(always)]
fn density(pr: &Params, st: &State, j: usize) -> f32 {
    let ph = st.phase[j];
    if pr.is_wall(ph) {
        pr.phases[ph as usize].rho0
    } else {
        st.rho[j]
    }
}

/// F22 (19)–(20) between condensed particles and gas particles.
fn gas_interface(pr: &Params, st: &mut State, grid: &CellTable) {
    let n = st.active();
    let inv_h = pr.kernel.inv_h;
    let (pos, mass, phase) = (&st.pos, &st.mass, &st.phase);
    let s: &State = st;
    let normals: Vec<[f32; 4]> = (0..n)
        .into_par_iter()
        .map(|i| {
            if !pr.gets_gas_interface(phase[i]) {
                return [0.0; 4];
            }
            let side = condensed(pr, phase[i]);
            let rho_i = density(pr, s, i);
            let v_i = mass[i] / rho_i;
            let mut g = [0.0f32; 3];
            for_each_neighbor(pr, pos, grid, i, |j, d, r2| {
                if r2 <= 0.0 || condensed(pr, phase[j]) == side {
                    return;
                }
                let rho_j = density(pr, s, j);
                let v_j = mass[j] / rho_j;
                let r = r2.sqrt();
                let f = (v_i * v_i + v_j * v_j) * (rho_i / (rho_i + rho_j)) * kernel::dw(pr, r) / r;
                for a in 0..3 {
                    g[a] += f * d[a];
                }
            });
            let g = [g[0] / v_i, g[1] / v_i, g[2] / v_i];
            let delta = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            if delta > 0.1 * inv_h {
                [
                    g[0] / delta,
                    g[1] / delta,
                    g[2] / delta,
                    delta * pr.surfaces.inv_kappa,
                ]
            } else {
                [0.0; 4]
            }
        })
        .collect();
    st.surface[..n].copy_from_slice(&normals);
}
