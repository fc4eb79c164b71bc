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

use super::neighbors::{for_each_neighbor, CellTable};
use crate::kernel;
use crate::params::{Params, FLAG_VISCOUS_HEATING};
use crate::state::State;
use rayon::prelude::*;

pub fn run(pr: &Params, st: &mut State, grid: &CellTable) {
    let (pos, vel, rho, p, mass, phase) = (&st.pos, &st.vel, &st.rho, &st.p, &st.mass, &st.phase);
    st.acc
        .par_iter_mut()
        .zip(st.acc_b.par_iter_mut())
        .enumerate()
        .for_each(|(i, (acc, acc_b))| {
            let ph_i = phase[i];
            if pr.is_wall(ph_i) {
                return;
            }
            let mat_i = pr.phase_a[ph_i as usize];
            let (rho_i, p_i, m_i, eta_i) = (rho[i], p[i], mass[i], mat_i[2]);
            let v_i = vel[i];
            let vol_i = m_i / rho_i;
            let pb = pr.gravity[3];
            let mut f = [0.0f32; 3];
            let mut fb = [0.0f32; 3];
            let mut heating = 0.0f32;
            let viscous_heating = pr.grid[3] & FLAG_VISCOUS_HEATING != 0;
            for_each_neighbor(pr, pos, grid, i, |j, d, r2| {
                if r2 <= 0.0 {
                    return;
                }
                let r = r2.sqrt();
                let dwdr = kernel::dw(pr, r);
                let ph_j = phase[j];
                let mat_j = pr.phase_a[ph_j as usize];
                let wall = mat_j[3] >= crate::params::KIND_WALL;
                let p_j = p[j];
                let (rho_j, m_j, eta_j) = if wall {
                    (mat_i[0] + p_j / mat_i[1], m_i, eta_i)
                } else {
                    (rho[j], mass[j], mat_j[2])
                };
                let slip = wall && pr.phase_b[ph_j as usize][3] != 0.0;
                let vol_j = m_j / rho_j;
                let vv = vol_i * vol_i + vol_j * vol_j;
                let p_avg = (rho_j * p_i + rho_i * p_j) / (rho_i + rho_j);
                let eta_sum = eta_i + eta_j;
                let eta_avg = if eta_sum > 0.0 && !slip {
                    2.0 * eta_i * eta_j / eta_sum
                } else {
                    0.0
                };
                let fp = -p_avg * dwdr / r;
                let fv = eta_avg * dwdr / r;
                let fbg = -pb * dwdr / r;
                let v_j = vel[j];
                for a in 0..3 {
                    let u = v_i[a] - v_j[a];
                    f[a] += vv * (fp * d[a] + fv * u);
                    fb[a] += vv * (fbg * d[a]);
                }
                if viscous_heating {
                    // Power the pair's viscous force dissipates: fluid pairs share
                    // F·(u_i − u_j); against a wall it is F·(u_i − U_wall) with the
                    // wall's real velocity (the mirrored one is a ghost).
                    let (w, share) = if wall {
                        (pr.phase_b[ph_j as usize], 1.0)
                    } else {
                        (v_j, 0.5)
                    };
                    let (ux, uy, uz) = (v_i[0] - v_j[0], v_i[1] - v_j[1], v_i[2] - v_j[2]);
                    let (wx, wy, wz) = (v_i[0] - w[0], v_i[1] - w[1], v_i[2] - w[2]);
                    let uw = ux * wx + uy * wy + uz * wz;
                    heating -= share * vv * fv * uw;
                }
            });
            let g = pr.gravity;
            *acc = [
                f[0] / m_i + g[0],
                f[1] / m_i + g[1],
                f[2] / m_i + g[2],
                heating / m_i,
            ];
            *acc_b = [fb[0] / m_i, fb[1] / m_i, fb[2] / m_i, 0.0];
        });
}
