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
//! (`Params::gets_interface`).
//!
//! With gas particles in the scene the interface is the condensed–gas one of
//! F22 (19)–(20) instead, for every conducting particle i (every fluid particle
//! with the interface viscosity on, `Params::gets_interface`) over neighbours j of the
//! other class (condensed: liquid, solid, wall; or gas):
//!   ∇c_i = (1/V_i) Σ_j (V_i² + V_j²) ρ_i/(ρ_i + ρ_j) ∂W/∂r e_ij,
//!   δ_i = |∇c_i|/κ_F22,  n_i = ∇c_i/|∇c_i| (outward with respect to i's phase),
//! V = m/ρ (summation density for fluids, ρ0 for solids and walls), κ_F22 the
//! same planar-lattice normalisation of the condensed side's δ.

use super::neighbors::{for_each_neighbor, min_image, with_listed, CellTable, NeighborList};
use crate::kernel;
use crate::lanes::Lane;
use crate::params::{Params, FLAG_GAS_INTERFACE, KIND_GAS};
use crate::state::State;
use crate::state::{H_TEMPERATURE, S_DELTA, S_SHEPARD};
use rayon::prelude::*;

#[inline(always)]
pub fn condensed(pr: &Params, phase: u32) -> bool {
    pr.phases[phase as usize].kind != KIND_GAS
}

/// `shepard` (free-surface form): Γ_i = Σ_j V_j W_ij over condensed neighbours
/// (V = m/ρ0), into surface[n + i].x (y, z zeroed) for the particles still in the
/// simulation.
pub fn shepard(pr: &Params, st: &mut State, grid: &CellTable, list: &NeighborList) {
    let (n, active) = (st.len(), st.active());
    let (pos, phase) = (&st.pos, &st.phase);
    // V_j once per particle, 0 for gas (not once per pair: a division).
    let vol = condensed_volumes(pr, st);
    let gamma: Vec<f32> = (0..active)
        .into_par_iter()
        .map(|i| {
            if !condensed(pr, phase[i]) {
                return 0.0;
            }
            with_listed(pr, pos, grid, list, i, |js| {
                shepard_sum(pr, pos, &vol, i, js)
            })
        })
        .collect();
    for (s, g) in st.surface[n..n + active].iter_mut().zip(gamma) {
        *s = [g, 0.0, 0.0, 0.0];
    }
}

/// V_j = m_j/ρ0 of every condensed particle (the volume the free-surface sums
/// weigh with), and 0 for a gas particle (which they leave out).
fn condensed_volumes(pr: &Params, st: &State) -> Vec<f32> {
    (0..st.len())
        .into_par_iter()
        .map(|j| {
            let ph = st.phase[j];
            if condensed(pr, ph) {
                st.mass[j] / pr.phases[ph as usize].rho0
            } else {
                0.0
            }
        })
        .collect()
}

/// Σ_j V_j W_ij over the neighbours `js` in their order (a gas neighbour's
/// V_j is 0: it adds +0). Eight kernels at a time (`kernel::weighted_w8`),
/// added in order, so the same bits as adding V_j W_ij one neighbour at a time.
#[inline(always)]
fn shepard_sum(pr: &Params, pos: &[[f32; 4]], vol: &[f32], i: usize, js: &[u32]) -> f32 {
    let pi = pos[i];
    let mut sum = 0.0f32;
    for block in js.chunks(8) {
        let (mut r2, mut wt) = ([0.0f32; 8], [0.0f32; 8]);
        for (k, &j) in block.iter().enumerate() {
            let j = j as usize;
            let d = min_image(pr, pi, pos[j]);
            r2[k] = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            wt[k] = vol[j];
        }
        let terms = kernel::weighted_w8(pr, &r2, &wt, block.len());
        for &t in &terms[..block.len()] {
            sum += t;
        }
    }
    sum
}

/// `normals`: F22's gas-interface form, or the free-surface form R18 (3.25)–(3.27)
/// from the Shepard sums `shepard` left in surface[n + j].x.
pub fn normals(pr: &Params, st: &mut State, grid: &CellTable, list: &NeighborList) {
    if pr.flag(FLAG_GAS_INTERFACE) {
        return gas_interface(pr, st, grid);
    }
    let (n, active) = (st.len(), st.active());
    let (pos, phase, surface) = (&st.pos, &st.phase, &st.surface);
    // V_j and 1/Γ_j once per particle instead of once per pair (divisions;
    // the same operations, so the same bits); both 0 for a gas particle, which
    // the sum leaves out (its term is then +0: `colour_gradient`).
    let vol = condensed_volumes(pr, st);
    let inv_gamma: Vec<f32> = (0..n)
        .into_par_iter()
        .map(|j| {
            if condensed(pr, phase[j]) {
                1.0 / surface[n + j][S_SHEPARD]
            } else {
                0.0
            }
        })
        .collect();
    let inv_h = pr.kernel.inv_h;
    let normals: Vec<[f32; 4]> = (0..active)
        .into_par_iter()
        .map(|i| {
            if !condensed(pr, phase[i]) || !pr.gets_interface(phase[i]) {
                return [0.0; 4];
            }
            let g = with_listed(pr, pos, grid, list, i, |js| {
                colour_gradient(pr, pos, &vol, &inv_gamma, i, js)
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
}

/// g_i = Σ_j V_j (1/Γ_i + 1/Γ_j) ∇_iW_ij over the neighbours `js` in their
/// order, leaving out j = i (r = 0) and gas (V_j = 1/Γ_j = 0). The factor
/// V_j (1/Γ_i + 1/Γ_j) W'(r)/r of a block of eight neighbours is computed at
/// once (eight lanes with AVX2, `colour_factors`), and the terms added one
/// neighbour at a time in order; a neighbour left out adds +0, which leaves
/// the sum's bits as they are (it is +0 or non-zero, never −0). The same bits
/// as skipping it, and as the WGSL loop.
#[inline(always)]
fn colour_gradient(
    pr: &Params,
    pos: &[[f32; 4]],
    vol: &[f32],
    inv_gamma: &[f32],
    i: usize,
    js: &[u32],
) -> [f32; 3] {
    let mut g = [0.0f32; 3];
    let pi = pos[i];
    for block in js.chunks(8) {
        let mut b = [[0.0f32; 8]; 6];
        for (k, &j) in block.iter().enumerate() {
            let j = j as usize;
            let d = min_image(pr, pi, pos[j]);
            b[0][k] = d[0];
            b[1][k] = d[1];
            b[2][k] = d[2];
            b[3][k] = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            b[4][k] = vol[j];
            b[5][k] = inv_gamma[j];
        }
        let f = colour_factors(pr, inv_gamma[i], &b[3], &b[4], &b[5], block.len());
        for k in 0..block.len() {
            for a in 0..3 {
                g[a] += f[k] * b[a][k];
            }
        }
    }
    g
}

/// V_j (1/Γ_i + 1/Γ_j) W'(r)/r for up to eight neighbours (r² > 0; 0 at
/// r = 0), the scalar operations lane by lane.
#[inline(always)]
fn colour_factors(
    pr: &Params,
    inv_gamma_i: f32,
    r2: &[f32; 8],
    vol: &[f32; 8],
    inv_gamma: &[f32; 8],
    len: usize,
) -> [f32; 8] {
    #[cfg(target_arch = "x86_64")]
    if len == 8 && *crate::lanes::AVX2 {
        // SAFETY: the CPU has AVX2 (checked once at run time).
        return unsafe { colour_factors_avx2(pr, inv_gamma_i, r2, vol, inv_gamma) };
    }
    let mut f = [0.0f32; 8];
    for k in 0..len {
        f[k] = colour_factor(pr, inv_gamma_i, r2[k], vol[k], inv_gamma[k]);
    }
    f
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn colour_factors_avx2(
    pr: &Params,
    inv_gamma_i: f32,
    r2: &[f32; 8],
    vol: &[f32; 8],
    inv_gamma: &[f32; 8],
) -> [f32; 8] {
    use crate::lanes::F8;
    colour_factor(
        pr,
        inv_gamma_i,
        F8::from_array(*r2),
        F8::from_array(*vol),
        F8::from_array(*inv_gamma),
    )
    .to_array()
}

#[inline(always)]
fn colour_factor<R: Lane>(pr: &Params, inv_gamma_i: f32, r2: R, vol: R, inv_gamma: R) -> R {
    let r = r2.sqrt();
    let f = vol * (R::splat(inv_gamma_i) + inv_gamma) * kernel::dw(pr, r) / r;
    (-r2).where_lt(0.0, f, R::splat(0.0))
}

/// `wetting`: the prescribed normal near walls and solids, F22 (27)–(29), on the
/// tension pair's particles with a normal.
pub fn wetting(pr: &Params, st: &mut State, grid: &CellTable) {
    let n = st.active();
    let s: &State = st;
    let wetted: Vec<[f32; 4]> = (0..n)
        .into_par_iter()
        .map(|i| {
            let ph = s.phase[i];
            let n_i = s.surface[i];
            if n_i[S_DELTA] == 0.0 || (ph != pr.tension.liquid && ph != pr.tension.gas) {
                return n_i;
            }
            wet(pr, s, grid, i, n_i)
        })
        .collect();
    st.surface[..n].copy_from_slice(&wetted);
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

/// F22's χ_j of a wall or solid neighbour for the solid colour field: f̄[T_j,
/// T_m − ΔT_s, T_m] for a conducting (solid) particle in a scene with the
/// tension ramp, 1 otherwise (walls, isothermal scenes).
#[inline(always)]
#[allow(clippy::manual_clamp)]
fn solid_weight(pr: &Params, st: &State, j: usize) -> f32 {
    let t = &pr.tension;
    if t.inv_ramp_width == 0.0 || !pr.conducts(st.phase[j]) {
        return 1.0;
    }
    1.0 - ((st.heat[j][H_TEMPERATURE] - t.t_melt) * t.inv_ramp_width + 1.0)
        .max(0.0)
        .min(1.0)
}

/// Wetting by a prescribed normal, F22 (27)–(29), for a particle i of the
/// tension pair with the standard normal ñ (`n`): the solid colour c^sf = Σ_j V_j
/// χ_j W_ij and its gradient Σ_j V_j χ_j ∇_iW_ij over wall and solid neighbours
/// (V = m/ρ0) give n^sf (towards the solid; kept ñ where |∇c^sf| ≤ 0.1/h); the
/// tangent t = ñ − (ñ·n^sf) n^sf normalised (F22 (28)
/// prints n̂ there, which is circular), n̂ = t sin θ − n^sf cos θ with θ = θ0 for
/// the liquid and π − θ0 for the gas (its normal points the other way), and
/// n = normalise(f n̂ + (1 − f) ñ), f = f[c^sf, 0, 0.2] (F22's c1, c2); δ kept.
/// θ0 per wall or solid phase (F22: per liquid–solid pair): near several, the
/// direction (cos θ0, sin θ0) averaged with the solid colour's weights V χ W and
/// normalised (one phase: its own angle, to rounding).
fn wet(pr: &Params, st: &State, grid: &CellTable, i: usize, n: [f32; 4]) -> [f32; 4] {
    let (mut c, mut g) = (0.0f32, [0.0f32; 3]);
    let (mut cw, mut sw) = (0.0f32, 0.0f32);
    for_each_neighbor(pr, &st.pos, grid, i, |j, d, r2| {
        let ph = st.phase[j];
        if r2 <= 0.0 || !pr.is_wall(ph) {
            return;
        }
        let r = r2.sqrt();
        let v = st.mass[j] / pr.phase(ph).rho0 * solid_weight(pr, st, j);
        let wv = v * kernel::w(pr, r);
        c += wv;
        cw += wv * pr.phase(ph).contact_cos;
        sw += wv * pr.phase(ph).contact_sin;
        let f = v * kernel::dw(pr, r) / r;
        for a in 0..3 {
            g[a] += f * d[a];
        }
    });
    let gl = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    if gl <= 0.1 * pr.kernel.inv_h {
        return n;
    }
    let ns = [g[0] / gl, g[1] / gl, g[2] / gl];
    let nn = n[0] * ns[0] + n[1] * ns[1] + n[2] * ns[2];
    let mut t = [n[0] - nn * ns[0], n[1] - nn * ns[1], n[2] - nn * ns[2]];
    let tl = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
    t = if tl > 1e-6 {
        [t[0] / tl, t[1] / tl, t[2] / tl]
    } else {
        [0.0; 3]
    };
    let al = (cw * cw + sw * sw).sqrt();
    if al <= 0.0 {
        return n; // only neighbours with χ = 0 (molten solid)
    }
    let (cos, sin) = if st.phase[i] == pr.tension.liquid {
        (cw / al, sw / al)
    } else {
        (-(cw / al), sw / al)
    };
    #[allow(clippy::manual_clamp)]
    let f = (c * 5.0).max(0.0).min(1.0);
    let mut m = [0.0f32; 3];
    for a in 0..3 {
        let prescribed = t[a] * sin - ns[a] * cos;
        m[a] = f * prescribed + (1.0 - f) * n[a];
    }
    let ml = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
    if ml > 1e-6 {
        [m[0] / ml, m[1] / ml, m[2] / ml, n[3]]
    } else {
        [0.0, 0.0, 0.0, n[3]]
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
            if !pr.gets_interface(phase[i]) {
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
