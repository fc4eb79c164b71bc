//! Twin of shaders/continuity.wgsl: the δ-SPH density of R18 §3.1.2. The density
//! is state, advanced by the continuity equation with Antuono et al.'s density
//! diffusion written on the excess over the reference density (R18 (3.53)),
//!   dρ_i/dt = ρ_i Σ_j V_j (u_i − u_j)·∇_iW_ij + δ h c0 Σ_j V_j ψ_ij·∇_iW_ij,
//!   ψ_ij = 2 (ρ̄_j − ρ̄_i) (r_j − r_i)/|r_ij|² − (⟨∇ρ̄⟩_i + ⟨∇ρ̄⟩_j),  ρ̄ = ρ − ρ0,
//! so ψ_ij·∇_iW_ij = −(2 (ρ̄_j − ρ̄_i) + (⟨∇ρ̄⟩_i + ⟨∇ρ̄⟩_j)·r_ij) (∂W/∂r)/r, with
//! Antuono et al. (2010)'s renormalised gradient (`gradients`; R18's optional
//! f_l). R18 (3.14) prints the diffusion
//! inside the velocity bracket, multiplied by ρ (dimensionally odd);
//! this is Antuono's form. Diffusing the excess, not ρ, keeps a temperature-
//! dependent ρ0 from driving a flux (R18 §3.4). The diffusion acts between
//! particles of the same phase only: across a liquid–gas interface a liquid's
//! excess (1% of 7000 kg/m³) is many times the gas's whole density, and
//! diffusing it blew the gas up within 60–150 steps (two_layer_2d,
//! sessile_drop_2d); R18 has no gas particles, and its two-fluid column (Test 3)
//! asks for no diffusion across the interface. `density_diffusion = "raw"`
//! (FLAG_RAW_DENSITY_DIFFUSION) is R18 Test 4's incompatible variant: the term on
//! ρ itself between every pair of fluid particles, kept to compare against.
//! c0 is the scene's largest sound speed (one δ h c0
//! for every pair, so each pair's exchange is antisymmetric).
//!
//! A wall or body neighbour enters as in the forces pass: the fluid's mass and
//! the density its EOS gives at the pressure the wall pass extrapolated; in the
//! divergence with its real velocity (the wall phase's, or the body's at that
//! point), not the wall pass's no-slip ghost.
//!
//! Γ_i = Σ_j V_j W_ij over every neighbour (R18 (3.17)'s renormalisation, read by
//! the Shepard pressure term), 1 for walls.
//!
//! Time integration, in F22's kick–drift–kick step: after the drift and the
//! sort, dρ/dt from x^{n+1}, u^{n+½} and ρ^n, then ρ^{n+1} = ρ^n + Δt dρ/dt and
//! p = c²(ρ − ρ0). The velocity is the half step's (second order), the
//! positions the new ones (first order in Δt; the acoustic Δt makes it
//! negligible against the spatial error: see the check scenes). R18's leap-frog
//! (3.55) is the same kick–drift–kick split for the velocity; keeping F22's lets
//! every other pass (bodies, heat, the transport velocity) stay as it is.

use super::bodies::point_velocity;
use super::density::equation_of_state_about;
use super::neighbors::{
    for_each_neighbor, min_image, with_neighbors, CellTable, ListChunk, NeighborList, LIST_CHUNK,
};
use crate::kernel;
use crate::params::{Params, FLAG_BODIES, FLAG_RAW_DENSITY_DIFFUSION, PHASE_DENSITY_LAW};
use crate::state::{State, H_TEMPERATURE, NO_BODY};
use rayon::prelude::*;

/// Particle i's reference density: its phase's density law at its temperature
/// (the previous step's: the heat passes run after this one), else ρ0. R18
/// (3.52)–(3.53): the EOS and the diffusion act on ρ − ρ0(T).
#[inline(always)]
fn particle_rho0(pr: &Params, heat: &[[f32; 4]], ph: u32, i: usize) -> f32 {
    if pr.phase(ph).flags & PHASE_DENSITY_LAW != 0 {
        return pr.reference_density(ph, heat[i][H_TEMPERATURE]);
    }
    pr.phase(ph).rho0
}

/// What the density diffusion subtracts from particle i's density: its
/// reference density (R18 (3.53)), or nothing with `density_diffusion = "raw"`.
#[inline(always)]
fn diffusion_reference(pr: &Params, heat: &[[f32; 4]], ph: u32, i: usize) -> f32 {
    if pr.flag(FLAG_RAW_DENSITY_DIFFUSION) {
        return 0.0;
    }
    particle_rho0(pr, heat, ph, i)
}

/// Whether the diffusion acts between phases ph_i and ph_j: one phase (R18
/// (3.53) here), or any two fluids with `density_diffusion = "raw"`.
#[inline(always)]
fn diffuses_with(pr: &Params, ph_i: u32, ph_j: u32) -> bool {
    ph_j == ph_i || (pr.flag(FLAG_RAW_DENSITY_DIFFUSION) && !pr.is_wall(ph_j))
}

/// The real velocity of wall or body particle j (not the wall pass's ghost).
#[inline(always)]
fn solid_velocity(pr: &Params, st: &State, j: usize) -> [f32; 3] {
    if pr.flag(FLAG_BODIES) {
        let k = st.body[st.id[j] as usize];
        if k != NO_BODY {
            return point_velocity(&st.bodies[k as usize], &st.pos[j]);
        }
    }
    let w = pr.phase(st.phase[j]).velocity;
    [w[0], w[1], w[2]]
}

/// `continuity_gradient`: the renormalised gradient of the excess density over
/// the particle's own phase (Antuono et al. 2010, the f_l of R18 (3.53)),
///   ⟨∇ρ̄⟩_i = M_i⁻¹ Σ_j V_j (ρ̄_j − ρ̄_i) ∇_iW_ij,  M_i = Σ_j V_j (r_j − r_i) ⊗ ∇_iW_ij,
/// so that ψ_ij·∇_iW_ij vanishes for a linear ρ̄ (a hydrostatic column, or the
/// truncated support at a free surface, where the plain term diffuses towards
/// the surface). 0 where |det M| ≤ 1e-3 (M ≈ I in a full support).
pub fn gradients(pr: &Params, st: &mut State, grid: &CellTable) {
    let n = st.active();
    let s: &State = st;
    let out: Vec<[f32; 4]> = (0..n)
        .into_par_iter()
        .map(|i| {
            let ph_i = s.phase[i];
            if pr.is_wall(ph_i) {
                return [0.0; 4];
            }
            let excess_i = s.rho[i] - diffusion_reference(pr, &s.heat, ph_i, i);
            let (mut m, mut b) = ([0.0f32; 6], [0.0f32; 3]);
            for_each_neighbor(pr, &s.pos, grid, i, |j, d, r2| {
                if r2 <= 0.0 || !diffuses_with(pr, ph_i, s.phase[j]) {
                    return;
                }
                let r = r2.sqrt();
                let vf = s.mass[j] / s.rho[j] * (kernel::dw(pr, r) / r);
                m[0] -= vf * d[0] * d[0];
                m[1] -= vf * d[0] * d[1];
                m[2] -= vf * d[0] * d[2];
                m[3] -= vf * d[1] * d[1];
                m[4] -= vf * d[1] * d[2];
                m[5] -= vf * d[2] * d[2];
                let db = (s.rho[j] - diffusion_reference(pr, &s.heat, ph_i, j) - excess_i) * vf;
                for a in 0..3 {
                    b[a] += db * d[a];
                }
            });
            let g = crate::portable_math::solve_symmetric(pr.sizes.dim, m, b);
            [g[0], g[1], g[2], 0.0]
        })
        .collect();
    st.density_gradient[..n].copy_from_slice(&out);
}

/// (dρ/dt, Γ) of fluid particle i over the neighbours `js` (walk order).
fn rate(pr: &Params, st: &State, i: usize, js: &[u32]) -> [f32; 2] {
    let ph_i = st.phase[i];
    let mat_i = pr.phase(ph_i);
    let (rho_i, m_i) = (st.rho[i], st.mass[i]);
    let rho0_i = particle_rho0(pr, &st.heat, ph_i, i);
    let excess_i = rho_i - diffusion_reference(pr, &st.heat, ph_i, i);
    let g_i = st.density_gradient[i];
    let v_i = st.vel[i];
    let pi = st.pos[i];
    let (mut div, mut diff, mut gamma) = (0.0f32, 0.0f32, 0.0f32);
    for &j in js {
        let j = j as usize;
        let d = min_image(pr, pi, st.pos[j]);
        let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let r = r2.sqrt();
        let ph_j = st.phase[j];
        if pr.is_wall(ph_j) {
            let rho_w = rho0_i + st.press[j] / mat_i.c2;
            let vol_w = m_i / rho_w;
            gamma += vol_w * kernel::w(pr, r);
            if r2 > 0.0 {
                let u = solid_velocity(pr, st, j);
                let ud = (v_i[0] - u[0]) * d[0] + (v_i[1] - u[1]) * d[1] + (v_i[2] - u[2]) * d[2];
                div += vol_w * ud * (kernel::dw(pr, r) / r);
            }
        } else {
            let rho_j = st.rho[j];
            let vol_j = st.mass[j] / rho_j;
            gamma += vol_j * kernel::w(pr, r);
            if r2 > 0.0 {
                let v_j = st.vel[j];
                let f = kernel::dw(pr, r) / r;
                let ud =
                    (v_i[0] - v_j[0]) * d[0] + (v_i[1] - v_j[1]) * d[1] + (v_i[2] - v_j[2]) * d[2];
                div += vol_j * ud * f;
                if diffuses_with(pr, ph_i, ph_j) {
                    let dr = rho_j - diffusion_reference(pr, &st.heat, ph_i, j) - excess_i;
                    let g_j = st.density_gradient[j];
                    let gd = (g_i[0] + g_j[0]) * d[0]
                        + (g_i[1] + g_j[1]) * d[1]
                        + (g_i[2] + g_j[2]) * d[2];
                    diff -= vol_j * (dr + dr + gd) * f;
                }
            }
        }
    }
    [rho_i * div + pr.solve.delta_hc * diff, gamma]
}

/// `continuity_rate`: (dρ/dt, Γ) per particle; also records each fluid
/// particle's neighbours in `list` for the forces pass (as the density pass does,
/// and each conducting solid's: `density::record_solid`).
pub fn rates(pr: &Params, st: &mut State, grid: &CellTable, list: &mut NeighborList) {
    let n = st.active();
    let chunks = list.take_chunks(n.div_ceil(LIST_CHUNK));
    let mut out = std::mem::take(&mut st.continuity);
    let s: &State = st;
    let chunks: Vec<ListChunk> = out[..n]
        .par_chunks_mut(LIST_CHUNK)
        .zip(chunks)
        .enumerate()
        .map(|(c, (rates, mut chunk))| {
            for (k, out) in rates.iter_mut().enumerate() {
                let i = c * LIST_CHUNK + k;
                if pr.is_wall(s.phase[i]) {
                    super::density::record_solid(pr, &s.pos, grid, i, s.phase[i], &mut chunk);
                    *out = [0.0, 1.0];
                    continue;
                }
                *out = with_neighbors(pr, &s.pos, grid, i, |js, _| {
                    chunk.push(js);
                    rate(pr, s, i, js)
                });
            }
            chunk
        })
        .collect();
    st.continuity = out;
    list.store(grid, chunks);
}

/// `continuity_update`: ρ += Δt dρ/dt and the EOS p = c²(ρ − ρ0(T)), fluid
/// particles.
pub fn update(pr: &Params, st: &mut State) {
    let n = st.active();
    let dt = st.sim.dt;
    let (phase, rates, heat) = (&st.phase, &st.continuity, &st.heat);
    st.rho[..n]
        .par_iter_mut()
        .zip(st.press[..n].par_iter_mut())
        .enumerate()
        .for_each(|(i, (rho, p))| {
            let ph = phase[i];
            if pr.is_wall(ph) {
                return;
            }
            let r = *rho + dt * rates[i][0];
            *rho = r;
            *p = equation_of_state_about(pr, ph, r, particle_rho0(pr, heat, ph, i));
        });
}
