//! Twin of shaders/forces.wgsl: pressure and viscous forces F22 (23),
//!   F_i = Σ_j (V_i² + V_j²) ( −p̃_ij ∂W/∂r e_ij + η̃_ij u_ij/r_ij ∂W/∂r ),
//!   p̃_ij = (ρ_j p_i + ρ_i p_j)/(ρ_i + ρ_j),  η̃_ij = 2η_iη_j/(η_i + η_j),
//! the transport-velocity background-pressure acceleration (Adami 2013)
//!   a_b,i = −(p_b/m_i) Σ_j (V_i² + V_j²) ∂W/∂r e_ij,
//! and gravity. A wall neighbour enters with the pressure the wall pass extrapolated,
//! the density the fluid's own EOS gives at that pressure, the fluid's mass and
//! viscosity, and the no-slip velocity (no viscous term for free-slip walls).
//! Each pair term is a function in cpu/terms/ (the twin of shaders/terms/), called
//! in the order of backend::terms::PAIR_TERMS: pressure and viscosity (summed into
//! one force, as F22 (23) writes them), background pressure (into acc_b), the
//! interface viscosity F22 (31)–(32), the solid–fluid viscosity F22 (33), the
//! viscous heating (into acc.w) and the wall barrier F22 (34).

use super::neighbors::{for_each_listed, CellTable, NeighborList};
use super::terms;
use crate::backend::terms::{active, TermId};
use crate::kernel;
use crate::model::MAX_PHASES;
use crate::params::{Params, KIND_WALL, PHASE_FREE_SLIP};
use crate::state::State;
use crate::state::{H_TEMPERATURE, S_DELTA};
use rayon::prelude::*;

/// Calls `f::<…>(args)` with one const bool per runtime switch, in order: one
/// monomorphised function per combination, chosen once per call.
macro_rules! monomorphise {
    ($f:ident::<$($done:literal),*>($($arg:expr),*); []) => {
        $f::<$($done),*>($($arg),*)
    };
    ($f:ident::<$($done:literal),*>($($arg:expr),*); [$head:expr $(, $rest:expr)*]) => {
        if $head {
            monomorphise!($f::<$($done,)* true>($($arg),*); [$($rest),*])
        } else {
            monomorphise!($f::<$($done,)* false>($($arg),*); [$($rest),*])
        }
    };
}

/// The sweep with the scene's switchable pair terms compiled in and the others
/// compiled out (backend::terms), one const parameter of `sweep` per switch.
pub fn run(pr: &Params, st: &mut State, grid: &CellTable, list: &NeighborList) {
    #[cfg(target_arch = "x86_64")]
    if super::forces_avx2::applies(pr) {
        let eta = PairViscosity::new(pr);
        return super::forces_avx2::run(pr, st, grid, list, &eta.0);
    }
    scalar(pr, st, grid, list)
}

/// `run` one neighbour at a time, whatever the CPU and scene.
pub(super) fn scalar(pr: &Params, st: &mut State, grid: &CellTable, list: &NeighborList) {
    monomorphise!(sweep::<>(pr, st, grid, list); [
        active(pr, TermId::BackgroundPressure),
        active(pr, TermId::InterfaceViscosity),
        active(pr, TermId::SolidFluidViscosity),
        active(pr, TermId::ViscousHeating),
        active(pr, TermId::Barrier),
        // delta_wcsph: R18's pressure (and the option of its viscosity).
        active(pr, TermId::ShepardPressure)
    ])
}

/// One fused neighbour sweep: BG, IV, SF, VH, BR switch the background pressure,
/// the interface viscosity, the solid–fluid viscosity, the viscous heating and
/// the wall barrier; DF takes R18 (3.17) in place of F22 (23)'s pressure (and,
/// when the scene asks, R18 (3.18) in place of its viscosity).
#[allow(clippy::too_many_arguments)]
fn sweep<
    const BG: bool,
    const IV: bool,
    const SF: bool,
    const VH: bool,
    const BR: bool,
    const DF: bool,
>(
    pr: &Params,
    st: &mut State,
    grid: &CellTable,
    list: &NeighborList,
) {
    let n = st.active();
    let (pos, vel, rho, p, mass, phase) =
        (&st.pos, &st.vel, &st.rho, &st.press, &st.mass, &st.phase);
    let (surface, heat, cont) = (&st.surface, &st.heat, &st.continuity);
    // Per particle and per phase pair once, what the pair loop would otherwise
    // compute per pair from the same operands: the same bits, fewer divisions.
    let eta_pair = PairViscosity::new(pr);
    // R18 (3.18) in place of F22's viscous term: a δ-SPH option (DF), tested per
    // pair only in the δ sweeps.
    let marrone = active(pr, TermId::MarroneViscosity);
    let vol: Vec<f32> = mass.par_iter().zip(rho).map(|(m, r)| m / r).collect();
    let (acc, acc_b) = (&mut st.acc[..n], &mut st.acc_b[..n]);
    accelerations(pr, phase, mass, acc, acc_b, |i| {
        let ph_i = phase[i];
        let mat_i = pr.phase(ph_i);
        let (rho_i, p_i, m_i) = (rho[i], p[i], mass[i]);
        let v_i = vel[i];
        let vol_i = vol[i];
        let pb = pr.flow.background_pressure;
        let mut f = [0.0f32; 3];
        let mut fb = [0.0f32; 3];
        let mut heating = 0.0f32;
        let alpha_i = if IV {
            terms::interface_viscosity_alpha(pr, surface[i][S_DELTA])
        } else {
            0.0
        };
        let gamma_i = if DF { cont[i][1] } else { 1.0 };
        let alpha_sf_i = if SF {
            terms::solid_fluid_viscosity_alpha(pr, ph_i, heat[i][H_TEMPERATURE])
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
            // The pair terms, in the order of backend::terms::PAIR_TERMS:
            // F22 (23)'s pressure and viscosity, or (DF) R18's pressure
            // and (DF and the scene's option) R18's viscosity.
            let fp = if DF {
                0.0
            } else {
                terms::pressure(p_i, p_j, rho_i, rho_j, dwdr, r)
            };
            let eta_ij = eta_pair.get(ph_i, ph_j);
            let fv = if DF && marrone {
                0.0
            } else {
                terms::viscosity(eta_ij, dwdr, r)
            };
            let v_j = vel[j];
            for a in 0..3 {
                let u = v_i[a] - v_j[a];
                f[a] += vv * (fp * d[a] + fv * u);
            }
            if DF {
                let gamma_j = if wall { 1.0 } else { cont[j][1] };
                let s = terms::shepard_pressure(
                    m_i, m_j, rho_i, rho_j, p_i, p_j, gamma_i, gamma_j, dwdr, r,
                );
                for a in 0..3 {
                    f[a] += s * d[a];
                }
            }
            if DF && marrone {
                let u = [v_i[0] - v_j[0], v_i[1] - v_j[1], v_i[2] - v_j[2]];
                let s =
                    terms::marrone_viscosity(pr, m_i, m_j, rho_i, rho_j, eta_ij, u, d, r2, dwdr, r);
                for a in 0..3 {
                    f[a] += s * d[a];
                }
            }
            if BG {
                let fbg = terms::background_pressure(pb, dwdr, r);
                for a in 0..3 {
                    fb[a] += vv * (fbg * d[a]);
                }
            }
            if IV && !wall {
                let alpha =
                    (alpha_i + terms::interface_viscosity_alpha(pr, surface[j][S_DELTA])) * 0.5;
                let u = [v_i[0] - v_j[0], v_i[1] - v_j[1], v_i[2] - v_j[2]];
                let s = terms::interface_viscosity(
                    pr, m_i, m_j, rho_i, rho_j, mat_i.c2, mat_j.c2, u, d, r2, dwdr, alpha,
                );
                for a in 0..3 {
                    f[a] += s * d[a];
                }
            }
            if SF {
                let alpha_j = if wall {
                    alpha_sf_i
                } else {
                    terms::solid_fluid_viscosity_alpha(pr, ph_j, heat[j][H_TEMPERATURE])
                };
                let alpha = (alpha_sf_i + alpha_j) * 0.5;
                let c2_j = if wall { mat_i.c2 } else { mat_j.c2 };
                let u = [v_i[0] - v_j[0], v_i[1] - v_j[1], v_i[2] - v_j[2]];
                let s = terms::solid_fluid_viscosity(
                    pr, m_i, m_j, rho_i, rho_j, mat_i.c2, c2_j, u, d, r2, dwdr, alpha,
                );
                for a in 0..3 {
                    f[a] += s * d[a];
                }
            }
            if VH {
                let (w, share) = if wall {
                    (mat_j.velocity.to_array(), 1.0)
                } else {
                    (v_j, 0.5)
                };
                heating -= terms::viscous_heating(v_i, v_j, w, share, vv, fv);
            }
            if BR && wall && r < pr.flow.barrier_radius {
                let w = mat_j.velocity;
                let s = terms::barrier(pr, xyz(v_i), [w.x, w.y, w.z], d, r);
                for a in 0..3 {
                    f[a] += s * d[a];
                }
            }
        });
        Sums { f, fb, heating }
    });
}

/// What the sweep sums over one particle's neighbours: the force, the
/// background-pressure force and the viscous heating.
pub(super) struct Sums {
    pub f: [f32; 3],
    pub fb: [f32; 3],
    pub heating: f32,
}

/// For every fluid particle i (walls are skipped), `sums(i)` divided by m_i into
/// acc (with gravity; heating in acc.w) and acc_b: the write both sweeps end with.
pub(super) fn accelerations(
    pr: &Params,
    phase: &[u32],
    mass: &[f32],
    acc: &mut [[f32; 4]],
    acc_b: &mut [[f32; 4]],
    sums: impl Fn(usize) -> Sums + Sync,
) {
    let g = pr.flow.gravity;
    acc.par_iter_mut()
        .zip(acc_b.par_iter_mut())
        .enumerate()
        .for_each(|(i, (acc, acc_b))| {
            if pr.is_wall(phase[i]) {
                return;
            }
            let Sums { f, fb, heating } = sums(i);
            let m_i = mass[i];
            *acc = [
                f[0] / m_i + g[0],
                f[1] / m_i + g[1],
                f[2] / m_i + g[2],
                heating / m_i,
            ];
            *acc_b = [fb[0] / m_i, fb[1] / m_i, fb[2] / m_i, 0.0];
        });
}

/// The first three components.
#[inline(always)]
fn xyz(v: [f32; 4]) -> [f32; 3] {
    [v[0], v[1], v[2]]
}

/// η̃_ij for every (fluid phase i, phase j), from `terms::pair_viscosity`: a wall
/// neighbour takes the fluid's own η, and a free-slip wall gives 0.
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
                *eta = terms::pair_viscosity(eta_i, eta_j, slip);
            }
        }
        PairViscosity(t)
    }
    #[inline(always)]
    fn get(&self, i: u32, j: u32) -> f32 {
        self.0[i as usize][j as usize]
    }
}
