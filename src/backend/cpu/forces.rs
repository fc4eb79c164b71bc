//! Twin of shaders/forces.wgsl: pressure and viscous forces F22 (23),
//!   F_i = Σ_j (V_i² + V_j²) ( −p̃_ij ∂W/∂r e_ij + η̃_ij u_ij/r_ij ∂W/∂r ),
//!   p̃_ij = (ρ_j p_i + ρ_i p_j)/(ρ_i + ρ_j),  η̃_ij = 2η_iη_j/(η_i + η_j),
//! the transport-velocity background-pressure acceleration (Adami 2013)
//!   a_b,i = −(p_b/m_i) Σ_j (V_i² + V_j²) ∂W/∂r e_ij,
//! and gravity. A wall neighbour enters with the pressure the wall pass extrapolated,
//! the density the fluid's own EOS gives at that pressure, the fluid's mass and
//! viscosity, and the no-slip velocity (no viscous term for free-slip walls).
//! With viscous heating on, acc.w carries the power the viscous terms dissipate,
//! −Σ_j s_ij (V_i² + V_j²) η̃_ij (∂W/∂r / r_ij) u_ij·w_ij per unit mass: a fluid
//! pair has w = u_ij and s = ½ (both sides count it); a wall pair w = u_i − U_wall
//! and s = 1, so that heat = wall work − kinetic-energy change exactly.
//! With `interface_viscosity` on, fluid pairs add the F22 (31)–(32) interface
//! viscosity, written so that it dissipates (u_ij·r_ij < 0 repels):
//!   F_d,i = m_i Σ_j m_j ᾱ_ij h c̄_ij/ρ̄_ij (u_ij·r_ij)/(r_ij² + 0.01 h²) ∂W/∂r e_ij,
//!   α_i = α_0^lg min(h δ_i, 1) (δ from the interface pass), ᾱ_ij = (α_i + α_j)/2:
//! the pair mean where F22 writes α_i, so that momentum is conserved pairwise, and
//! h δ capped at 1 so that α ≤ α_0^lg, the bound the viscous Δt limit uses
//! (h δ exceeds 1 only at wall–liquid–gas corners: 1.05 measured in two_layer_2d).
//! Its dissipation is not added to the viscous heating.

use super::neighbors::{for_each_listed, CellTable, NeighborList};
use crate::kernel;
use crate::model::MAX_PHASES;
use crate::params::{Params, FLAG_VISCOUS_HEATING, KIND_WALL, PHASE_FREE_SLIP};
use crate::state::State;
use rayon::prelude::*;

pub fn run(pr: &Params, st: &mut State, grid: &CellTable, list: &NeighborList) {
    let (pos, vel, rho, p, mass, phase) = (&st.pos, &st.vel, &st.rho, &st.p, &st.mass, &st.phase);
    let surface = &st.surface;
    // Per particle and per phase pair once, what the pair loop would otherwise
    // compute per pair from the same operands: the same bits, fewer divisions.
    let eta_pair = PairViscosity::new(pr);
    let vol: Vec<f32> = mass.par_iter().zip(rho).map(|(m, r)| m / r).collect();
    let background = pr.flow.background_pressure != 0.0;
    st.acc
        .par_iter_mut()
        .zip(st.acc_b.par_iter_mut())
        .enumerate()
        .for_each(|(i, (acc, acc_b))| {
            let ph_i = phase[i];
            if pr.is_wall(ph_i) {
                return;
            }
            let mat_i = pr.phase(ph_i);
            let (rho_i, p_i, m_i) = (rho[i], p[i], mass[i]);
            let v_i = vel[i];
            let vol_i = vol[i];
            let pb = pr.flow.background_pressure;
            let mut f = [0.0f32; 3];
            let mut fb = [0.0f32; 3];
            let mut heating = 0.0f32;
            let viscous_heating = pr.flag(FLAG_VISCOUS_HEATING);
            let (h, alpha0) = (pr.kernel.h, pr.flow.interface_viscosity);
            let alpha_i = if alpha0 > 0.0 {
                alpha0 * (h * surface[i][3]).min(1.0)
            } else {
                0.0
            };
            for_each_listed(pr, pos, grid, list, i, |j, d, r2| {
                if r2 <= 0.0 {
                    return;
                }
                let r = r2.sqrt();
                let dwdr = kernel::dw(pr, r);
                let ph_j = phase[j];
                let mat_j = pr.phase(ph_j);
                let wall = mat_j.kind >= KIND_WALL;
                let p_j = p[j];
                let (rho_j, m_j, vol_j) = if wall {
                    let rho_j = mat_i.rho0 + p_j / mat_i.c2;
                    (rho_j, m_i, m_i / rho_j)
                } else {
                    (rho[j], mass[j], vol[j])
                };
                let vv = vol_i * vol_i + vol_j * vol_j;
                let p_avg = (rho_j * p_i + rho_i * p_j) / (rho_i + rho_j);
                let eta_avg = eta_pair.get(ph_i, ph_j);
                let fp = -p_avg * dwdr / r;
                let fv = eta_avg * dwdr / r;
                let v_j = vel[j];
                for a in 0..3 {
                    let u = v_i[a] - v_j[a];
                    f[a] += vv * (fp * d[a] + fv * u);
                }
                // With p_b = 0 every term is ±0 and the sum stays +0: skipped.
                if background {
                    let fbg = -pb * dwdr / r;
                    for a in 0..3 {
                        fb[a] += vv * (fbg * d[a]);
                    }
                }
                if alpha0 > 0.0 && !wall {
                    let alpha = (alpha_i + alpha0 * (h * surface[j][3]).min(1.0)) * 0.5;
                    let pair = Pair {
                        m: [m_i, m_j],
                        rho: [rho_i, rho_j],
                        c2: [mat_i.c2, mat_j.c2],
                        u: [v_i[0] - v_j[0], v_i[1] - v_j[1], v_i[2] - v_j[2]],
                    };
                    let s = interface_viscosity(pr, &pair, d, r2, dwdr, alpha);
                    for a in 0..3 {
                        f[a] += s * d[a];
                    }
                }
                if viscous_heating {
                    // Power the pair's viscous force dissipates: fluid pairs share
                    // F·(u_i − u_j); against a wall it is F·(u_i − U_wall) with the
                    // wall's real velocity (the mirrored one is a ghost).
                    let (w, share) = if wall {
                        (mat_j.velocity, 1.0)
                    } else {
                        (v_j, 0.5)
                    };
                    let (ux, uy, uz) = (v_i[0] - v_j[0], v_i[1] - v_j[1], v_i[2] - v_j[2]);
                    let (wx, wy, wz) = (v_i[0] - w[0], v_i[1] - w[1], v_i[2] - w[2]);
                    let uw = ux * wx + uy * wy + uz * wz;
                    heating -= share * vv * fv * uw;
                }
            });
            let g = pr.flow.gravity;
            *acc = [
                f[0] / m_i + g[0],
                f[1] / m_i + g[1],
                f[2] / m_i + g[2],
                heating / m_i,
            ];
            *acc_b = [fb[0] / m_i, fb[1] / m_i, fb[2] / m_i, 0.0];
        });
}

/// η̃_ij = 2η_iη_j/(η_i + η_j) for every (fluid phase i, phase j): a wall
/// neighbour takes the fluid's own η, and a free-slip wall or η_i + η_j = 0 gives 0.
struct PairViscosity([[f32; MAX_PHASES]; MAX_PHASES]);

impl PairViscosity {
    fn new(pr: &Params) -> Self {
        let mut t = [[0.0f32; MAX_PHASES]; MAX_PHASES];
        for (i, row) in t.iter_mut().enumerate() {
            let eta_i = pr.phases[i].eta;
            for (j, eta) in row.iter_mut().enumerate() {
                let wall = pr.phases[j].kind >= KIND_WALL;
                let slip = wall && pr.phases[j].flags & PHASE_FREE_SLIP != 0;
                let eta_j = if wall { eta_i } else { pr.phases[j].eta };
                let eta_sum = eta_i + eta_j;
                *eta = if eta_sum > 0.0 && !slip {
                    2.0 * eta_i * eta_j / eta_sum
                } else {
                    0.0
                };
            }
        }
        PairViscosity(t)
    }
    #[inline(always)]
    fn get(&self, i: u32, j: u32) -> f32 {
        self.0[i as usize][j as usize]
    }
}

/// What F22 (31) needs of a fluid pair i, j: masses, densities, c², u_i − u_j.
struct Pair {
    m: [f32; 2],
    rho: [f32; 2],
    c2: [f32; 2],
    u: [f32; 3],
}

/// F22 (31) for one fluid pair: the factor of r_ij in the force on i.
#[inline(always)]
fn interface_viscosity(pr: &Params, q: &Pair, d: [f32; 3], r2: f32, dwdr: f32, alpha: f32) -> f32 {
    let c = (q.c2[0].sqrt() + q.c2[1].sqrt()) * 0.5;
    let rho = (q.rho[0] + q.rho[1]) * 0.5;
    let ur = q.u[0] * d[0] + q.u[1] * d[1] + q.u[2] * d[2];
    let r = r2.sqrt();
    q.m[0] * q.m[1] * alpha * pr.kernel.h * c / rho * ur / (r2 + pr.kernel.eta2) * dwdr / r
}
