//! Twin of shaders/dfsph.wgsl: divergence-free SPH (Bender & Koschier 2015,
//! "Divergence-free smoothed particle hydrodynamics", SCA; 2017, "Divergence-
//! free SPH for incompressible and viscous fluids", IEEE TVCG 23(3)), the
//! pressure solver of J22 §3.1. SPlisHSPlasH 2.11 and 2.12 were read for the
//! details (not copied).
//!
//! - Boundary: a wall particle b enters a fluid particle's sums with the mass
//!   Ψ_b = ρ0_i V_b at its phase's velocity, V_b = m_b/ρ0_b (the lattice's
//!   volume per particle: the walls are several layers of the fluid's lattice;
//!   Akinci's V_b = 1/Σ_b' W_bb' (J22 (24)), made for one layer, counts the
//!   first wall layer about twice, and a column at rest started 0.9% above ρ0).
//!   Its pressure is mirrored, Adami et al. (2012) style: κ_b/ρ_b = κ_i/ρ_i +
//!   g·(x_b − x_i)/ρ_i. With κ_b = 0 (walls as zero-pressure fluid) the first
//!   row above a floor was pushed into it at 184 m/s² under a hydrostatic κ
//!   and the column's pressure read 1/3 of ρ g (H − y).
//! - Masses (model/mod.rs): ρ0 over the lattice's kernel sum, so the lattice
//!   starts at ρ0 exactly (the quintic's 0.26% at h = Δx in 2D threw the top
//!   of a 0.4 m column up at 0.8 m/s in the first step).
//! - Density and factor (after the sort): ρ_i = m_i Σ_f W_if + ρ0_i Σ_b V_b W_ib,
//!   and α_i = ρ_i / (G·(G + B) + Σ_f |g_f|²) with g_f = m_f ∇W_if,
//!   g_b = Ψ_b ∇W_ib, G = Σ_all g, B = Σ_b g_b: the exact diagonal of the
//!   update below (B&K 2017 (11) with the mirrored wall); 0 when not positive.
//! - Both solves apply Δv_i = −Δt (Σ_f m_f (κ_i/ρ_i + κ_f/ρ_f) ∇W_if +
//!   Σ_b 2 Ψ_b (κ_i/ρ_i) ∇W_ib) with the increment of κ (B&K 2017 (12)), and
//!   Dρ_i/Dt = Σ_f m_f (v_i − v_f)·∇W_if + Σ_b Ψ_b (v_i − v_b)·∇W_ib.
//!   - The iteration is a projected, relaxed Jacobi (SPlisHSPlasH 2.12's):
//!     Σκ_i ← max(Σκ_i + ½ α_i e_i / s, 0), e the divergence error Dρ/Dt
//!     (s = Δt) or the density error ρ + Δt Dρ/Dt − ρ0 (s = Δt²). The sum
//!     stays ≥ 0, so only compression is corrected (a free surface may
//!     separate, J22 §3.1). Plain Jacobi (ω = 1, increments ≥ 0) overshoots:
//!     its iteration matrix reaches 2.6 on the 2D quintic lattice.
//!   - A particle with fewer than `dfsph_min_neighbours` neighbours (a
//!     quarter of the lattice's: spray) has divergence error 0: its α
//!     grows without bound as they near the support's edge
//!     (shaders/dfsph.wgsl `divergence_error`; SPlisHSPlasH's rule too).
//!   - Residuals: the mean of max(e, 0)/ρ0 over the fluid (times Δt for the
//!     divergence), at least two iterations for the density, one for the
//!     divergence. The sum is a fixed two-level tree, the GPU's pairs.
//!   - Warm start (B&K 2017 §4.4): each solve starts from half its last
//!     step's Σκ, rescaled to this Δt (stored as Δt² Σκ and Δt Σκ, sorted).
//! - The walls' head g·(x_b − x_i)/ρ_i does not depend on κ: `wall_head`
//!   applies it once, with the non-pressure forces (v* = v + Δt (a − head)).
//! - The step's pressure: p_i = ρ_i (Σκ_density + Σκ_divergence), both solves'
//!   impulses being WCSPH's Δt p/ρ² ∇W.
//! - The step (B&K 2017 Algorithm 1, in SPlisHSPlasH's order): sort, density and
//!   factors, divergence solve, the non-pressure forces (the forces pass with
//!   p = 0), v*, density solve, x += Δt v*, the CFL step (the time step's
//!   acoustic limit without a sound speed: 0.25 h/|u|).
//! - Measured: the 2D hydrostatic column (0.4 m, Δx = 1 cm) holds its pressure
//!   to 1.2% rms of ρ g H at the default tolerance 1e-3 (1.0% at 1e-4, 7× the
//!   wall time).
//! - J22's implicit viscosity with XSPH, cohesion and adhesion (J22 (14)–(17))
//!   are in dfsph_viscosity.rs. J22's one-layer Akinci boundary
//!   (`dfsph.boundary = "akinci"`) enters through the wall masses: setup
//!   gives each wall particle m_b = ρ0_b V_b with Akinci's V_b (setup.rs,
//!   akinci_wall_masses), so V_b = m_b/ρ0_b above reads it.
//! - Not yet: moving walls and rigid bodies (model/mod.rs refuses them on
//!   DFSPH).

use super::dfsph_pairs::{for_each_pair, Pair, PairChunk, PairTable};
use super::integrate::{stamp_if_left, wrap_periodic};
use super::neighbors::{with_neighbors, CellTable, ListChunk, NeighborList, LIST_CHUNK};
use super::reduce::tree_total;
use crate::backend::schedule::SolverSlot;
use crate::kernel;
use crate::params::Params;
use crate::state::{State, H_LIQUID};
use rayon::prelude::*;

/// `dfsph_boundary_volume`: V_b = m_b / ρ0_b in dfsph.x of each wall
/// particle; its pressure 0.
pub fn boundary_volume(pr: &Params, st: &mut State) {
    for i in 0..st.active() {
        let ph = st.phase[i];
        if pr.is_wall(ph) {
            st.dfsph[i] = [st.mass[i] / pr.phase(ph).rho0, 0.0, 0.0, 0.0];
            st.press[i] = 0.0;
        }
    }
}

/// The sums of fluid particle i's density and factor (B&K 2017 (11)).
struct FactorSums {
    rho0_i: f32,
    sum_f: f32,
    sum_b: f32,
    sq: f32,
    g: [f32; 3],
    gb: [f32; 3],
}

impl FactorSums {
    fn new(rho0_i: f32) -> Self {
        FactorSums {
            rho0_i,
            sum_f: 0.0,
            sum_b: 0.0,
            sq: 0.0,
            g: [0.0; 3],
            gb: [0.0; 3],
        }
    }

    /// Adds neighbour j at x_ij = d, r² < support², with W(r) = w and
    /// ∂W/∂r / r = dw (unused at r = 0); records the pair j ≠ i.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)] // the pair as the sweep holds it: no struct to build per pair
    fn add(
        &mut self,
        st: &State,
        pr: &Params,
        j: usize,
        d: [f32; 3],
        r2: f32,
        w: f32,
        dw: f32,
        pairs: &mut PairChunk,
    ) {
        if r2 > 0.0 {
            pairs.push_one(Pair {
                j: j as u32,
                d,
                g: dw,
            });
        }
        let (g, gb) = (&mut self.g, &mut self.gb);
        if pr.is_wall(st.phase[j]) {
            let psi = self.rho0_i * st.dfsph[j][0];
            self.sum_b += st.dfsph[j][0] * w;
            if r2 > 0.0 {
                let f = psi * dw;
                for a in 0..3 {
                    g[a] += f * d[a];
                    gb[a] += f * d[a];
                }
            }
        } else {
            self.sum_f += w;
            if r2 > 0.0 {
                let f = st.mass[j] * dw;
                for a in 0..3 {
                    g[a] += f * d[a];
                }
                self.sq += f * f * r2;
            }
        }
    }
}

/// x_ij and r² of neighbour j (the walk's min_image and sum).
#[inline(always)]
fn geometry(pr: &Params, pi: [f32; 4], pj: [f32; 4]) -> ([f32; 3], f32) {
    let d = super::neighbors::min_image(pr, pi, pj);
    (d, d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
}

/// (ρ_i, α_i) of fluid particle i over its neighbours `js` (walk order);
/// its pairs j ≠ i go to `pairs`. The kernel's values are taken eight
/// neighbours at a time where the CPU has AVX2 (`kernel::w` and `dw` are the
/// same operations on each lane), and added in the walk's order.
fn factor_of(pr: &Params, st: &State, i: usize, js: &[u32], pairs: &mut PairChunk) -> (f32, f32) {
    let mut sums = FactorSums::new(pr.phase(st.phase[i]).rho0);
    let pi = st.pos[i];
    #[cfg(target_arch = "x86_64")]
    if *crate::lanes::AVX2 {
        // SAFETY: the CPU has AVX2 (checked once at run time).
        unsafe { factor_sums_avx2(pr, st, pi, js, pairs, &mut sums) };
    } else {
        factor_sums(pr, st, pi, js, pairs, &mut sums);
    }
    #[cfg(not(target_arch = "x86_64"))]
    factor_sums(pr, st, pi, js, pairs, &mut sums);
    pairs.end();
    let FactorSums {
        sum_f,
        sum_b,
        sq,
        g,
        gb,
        rho0_i,
    } = sums;
    let rho_i = st.mass[i] * sum_f + rho0_i * sum_b;
    let denom = g[0] * (g[0] + gb[0]) + g[1] * (g[1] + gb[1]) + g[2] * (g[2] + gb[2]) + sq;
    let alpha = if denom > 0.0 { rho_i / denom } else { 0.0 };
    (rho_i, alpha)
}

/// `factor_of`'s sums, one neighbour at a time.
fn factor_sums(
    pr: &Params,
    st: &State,
    pi: [f32; 4],
    js: &[u32],
    pairs: &mut PairChunk,
    sums: &mut FactorSums,
) {
    for &j in js {
        let j = j as usize;
        let (d, r2) = geometry(pr, pi, st.pos[j]);
        if r2 >= pr.kernel.support2 {
            continue;
        }
        let r = r2.sqrt();
        let dw = if r2 > 0.0 { kernel::dw(pr, r) / r } else { 0.0 };
        sums.add(st, pr, j, d, r2, kernel::w(pr, r), dw, pairs);
    }
}

/// `factor_of`'s sums with W and ∂W/∂r / r of eight neighbours at once.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn factor_sums_avx2(
    pr: &Params,
    st: &State,
    pi: [f32; 4],
    js: &[u32],
    pairs: &mut PairChunk,
    sums: &mut FactorSums,
) {
    use crate::lanes::{Lane, F8};
    for block in js.chunks(8) {
        let mut geo = [([0.0f32; 3], 0.0f32); 8];
        let mut r2s = [0.0f32; 8];
        for (k, &j) in block.iter().enumerate() {
            geo[k] = geometry(pr, pi, st.pos[j as usize]);
            r2s[k] = geo[k].1;
        }
        // Lanes past the block's end hold r² = 0 (their values unused).
        let r = F8::from_array(r2s).sqrt();
        let w = kernel::w(pr, r).to_array();
        let dw = (kernel::dw(pr, r) / r).to_array();
        for (k, &j) in block.iter().enumerate() {
            let (d, r2) = geo[k];
            if r2 >= pr.kernel.support2 {
                continue;
            }
            sums.add(st, pr, j as usize, d, r2, w[k], dw[k], pairs);
        }
    }
}

/// `dfsph_factor`: ρ, α (dfsph.x) and p = 0 of every fluid particle; also
/// records each fluid particle's neighbours for the forces pass and its
/// pairs for the solves (dfsph_pairs).
pub fn factor(
    pr: &Params,
    st: &mut State,
    grid: &CellTable,
    list: &mut NeighborList,
    table: &mut PairTable,
) {
    let n = st.active();
    let chunks = list.take_chunks(n.div_ceil(LIST_CHUNK));
    let pair_chunks = table.take_chunks(n.div_ceil(LIST_CHUNK));
    let s: &State = st;
    type Chunked = (Vec<(f32, f32)>, (ListChunk, PairChunk));
    type Gathered = (Vec<Vec<(f32, f32)>>, (Vec<ListChunk>, Vec<PairChunk>));
    let (out, (chunks, pair_chunks)): Gathered = (0..n.div_ceil(LIST_CHUNK))
        .into_par_iter()
        .zip(chunks)
        .zip(pair_chunks)
        .map(|((c, mut chunk), mut pairs)| -> Chunked {
            let range = c * LIST_CHUNK..((c + 1) * LIST_CHUNK).min(n);
            let values = range
                .map(|i| {
                    if pr.is_wall(s.phase[i]) {
                        chunk.push(&[]);
                        pairs.end();
                        return (f32::NAN, f32::NAN);
                    }
                    with_neighbors(pr, &s.pos, grid, i, |js, _| {
                        chunk.push(js);
                        factor_of(pr, s, i, js, &mut pairs)
                    })
                })
                .collect();
            (values, (chunk, pairs))
        })
        .unzip();
    list.store(grid, chunks);
    table.store(grid, pair_chunks);
    for (i, (rho, alpha)) in out.into_iter().flatten().enumerate() {
        if pr.is_wall(st.phase[i]) {
            continue;
        }
        st.rho[i] = rho;
        st.press[i] = 0.0;
        st.dfsph[i] = [alpha, 0.0, 0.0, 0.0];
    }
}

/// Dρ_i/Dt over fluid and boundary neighbours, and their number.
fn density_rate(
    pr: &Params,
    st: &State,
    grid: &CellTable,
    table: &PairTable,
    i: usize,
) -> (f32, u32) {
    let rho0_i = pr.phase(st.phase[i]).rho0;
    let v_i = st.vel[i];
    let mut rate = 0.0f32;
    let mut neighbours = 0u32;
    for_each_pair(pr, &st.pos, grid, table, i, |j, d, dw| {
        let (u, w) = if pr.is_wall(st.phase[j]) {
            let u = pr.phase(st.phase[j]).velocity;
            ([u[0], u[1], u[2]], rho0_i * st.dfsph[j][0])
        } else {
            let u = st.vel[j];
            ([u[0], u[1], u[2]], st.mass[j])
        };
        let ud = (v_i[0] - u[0]) * d[0] + (v_i[1] - u[1]) * d[1] + (v_i[2] - u[2]) * d[2];
        rate += w * ud * dw;
        neighbours += 1;
    });
    (rate, neighbours)
}

/// The new velocity of fluid particle i after the κ of dfsph.z.
fn kappa_velocity(
    pr: &Params,
    st: &State,
    grid: &CellTable,
    table: &PairTable,
    i: usize,
) -> [f32; 4] {
    let rho0_i = pr.phase(st.phase[i]).rho0;
    let k_i = st.dfsph[i][2] / st.rho[i];
    let mut dv = [0.0f32; 3];
    for_each_pair(pr, &st.pos, grid, table, i, |j, d, dw| {
        let s = if pr.is_wall(st.phase[j]) {
            let s_b = rho0_i * st.dfsph[j][0] * k_i;
            s_b + s_b
        } else {
            st.mass[j] * (k_i + st.dfsph[j][2] / st.rho[j])
        };
        let f = s * dw;
        for a in 0..3 {
            dv[a] += f * d[a];
        }
    });
    let dt = st.sim.dt;
    let mut v = st.vel[i];
    for a in 0..3 {
        v[a] -= dt * dv[a];
    }
    v
}

/// Fluid particles still in the simulation.
fn fluid(pr: &Params, st: &State) -> Vec<usize> {
    (0..st.active())
        .filter(|&i| !pr.is_wall(st.phase[i]))
        .collect()
}

fn converged(st: &State, slot: SolverSlot) -> bool {
    st.solvers[slot as usize].converged != 0
}

/// The solve's error (dfsph.y) of every fluid particle: the divergence's
/// Dρ/Dt (0 with fewer than `dfsph_min_neighbours`: spray, shaders/dfsph.wgsl
/// `divergence_error`), or the density's ρ + Δt Dρ/Dt − ρ0.
fn errors(pr: &Params, st: &mut State, grid: &CellTable, table: &PairTable, slot: SolverSlot) {
    let s: &State = st;
    let dt = s.sim.dt;
    let out: Vec<(usize, f32)> = fluid(pr, s)
        .into_par_iter()
        .map(|i| {
            let (rate, neighbours) = density_rate(pr, s, grid, table, i);
            let e = match slot {
                SolverSlot::Divergence if neighbours < pr.solve.dfsph_min_neighbours => 0.0,
                SolverSlot::Divergence => rate,
                _ => s.rho[i] + dt * rate - pr.phase(s.phase[i]).rho0,
            };
            (i, e)
        })
        .collect();
    for (i, e) in out {
        st.dfsph[i][1] = e;
    }
}

/// `dfsph_*_begin`: the solver reset, the first errors and the warm start:
/// κ = ½ K / Δt² (density; K = Δt² Σκ of the last step) or ½ K / Δt
/// (divergence; K = Δt Σκ) for every fluid particle (SPlisHSPlasH 2.11
/// applies it only where the particle is compressed now; here K ≥ 0 is
/// applied everywhere and the relaxation's projection takes back what is
/// not needed), in dfsph.z (the stage's velocity and error dispatches apply
/// it) and dfsph.w.
pub fn begin(pr: &Params, st: &mut State, grid: &CellTable, table: &PairTable, slot: SolverSlot) {
    st.solvers[slot as usize] = st.solvers[slot as usize].reset();
    errors(pr, st, grid, table, slot);
    let dt = st.sim.dt;
    for i in fluid(pr, st) {
        let (stored, scale) = match slot {
            SolverSlot::Divergence => (st.dfsph_warm[i][1], dt),
            _ => (st.dfsph_warm[i][0], dt * dt),
        };
        let e = &mut st.dfsph[i];
        let k = 0.5 * stored / scale;
        e[2] = k;
        e[3] = k;
    }
}

/// `dfsph_*_kappa`: κ_i from the error; the density solve sums it in dfsph.w.
pub fn kappa(pr: &Params, st: &mut State, slot: SolverSlot) {
    if converged(st, slot) {
        return;
    }
    let dt = st.sim.dt;
    for i in fluid(pr, st) {
        let e = &mut st.dfsph[i];
        let scale = if slot == SolverSlot::Divergence {
            dt
        } else {
            dt * dt
        };
        let next = (e[3] + 0.5 * e[0] * e[1] / scale).max(0.0);
        e[2] = next - e[3];
        e[3] = next;
    }
}

/// `dfsph_*_velocity`: every fluid velocity after the κ just computed.
pub fn velocity(
    pr: &Params,
    st: &mut State,
    grid: &CellTable,
    table: &PairTable,
    slot: SolverSlot,
) {
    if converged(st, slot) {
        return;
    }
    let s: &State = st;
    let out: Vec<(usize, [f32; 4])> = fluid(pr, s)
        .into_par_iter()
        .map(|i| (i, kappa_velocity(pr, s, grid, table, i)))
        .collect();
    for (i, v) in out {
        st.vel[i] = v;
    }
}

/// `dfsph_*_error`: the errors at the corrected velocities.
pub fn error(pr: &Params, st: &mut State, grid: &CellTable, table: &PairTable, slot: SolverSlot) {
    if converged(st, slot) {
        return;
    }
    errors(pr, st, grid, table, slot);
}

/// The mean error over fluid particles by the GPU's two-level tree.
fn mean_error(pr: &Params, st: &State) -> f32 {
    let total = tree_total(pr.n(), |i| {
        if i < st.active() && !pr.is_wall(st.phase[i]) {
            [st.dfsph[i][1].max(0.0) / pr.phase(st.phase[i]).rho0, 1.0]
        } else {
            [0.0, 0.0]
        }
    });
    if total[1] > 0.0 {
        total[0] / total[1]
    } else {
        0.0
    }
}

/// `dfsph_*_residual`: the mean error (the divergence's times Δt), the
/// iteration count and the converged flag (at least 1 / 2 iterations).
pub fn residual(pr: &Params, st: &mut State, slot: SolverSlot) {
    if converged(st, slot) {
        return;
    }
    let mean = mean_error(pr, st);
    let (value, tolerance, min_iterations) = match slot {
        SolverSlot::Divergence => (mean * st.sim.dt, pr.solve.dfsph_divergence_tolerance, 1),
        _ => (mean, pr.solve.dfsph_density_tolerance, 2),
    };
    let s = &mut st.solvers[slot as usize];
    let converged = value <= tolerance && s.iterations + 1 >= min_iterations;
    s.finish(value, converged, pr.solve.dfsph_max_iterations);
}

/// The walls' hydrostatic head (Adami et al. 2012's extrapolation, the part
/// that does not depend on κ): a wall particle b holds κ_b/ρ_b = κ_i/ρ_i +
/// g·(x_b − x_i)/ρ_i; the κ_i part is in `kappa_velocity`, this is
/// Σ_b Ψ_b (g·(x_b − x_i)/ρ_i) ∇W_ib, applied once per step. Without it the
/// first row above a floor sinks at about g/2 under a hydrostatic κ.
fn wall_head(pr: &Params, st: &State, grid: &CellTable, table: &PairTable, i: usize) -> [f32; 3] {
    let rho0_i = pr.phase(st.phase[i]).rho0;
    let g = pr.flow.gravity;
    let rho_i = st.rho[i];
    let mut h = [0.0f32; 3];
    for_each_pair(pr, &st.pos, grid, table, i, |j, d, dw| {
        if !pr.is_wall(st.phase[j]) {
            return;
        }
        let gd = 0.0 - g[0] * d[0] - g[1] * d[1] - g[2] * d[2];
        let f = rho0_i * st.dfsph[j][0] * (gd / rho_i) * dw;
        for a in 0..3 {
            h[a] += f * d[a];
        }
    });
    h
}

/// `dfsph_predict`: v* = v + Δt (a − the walls' head), then the mushy-zone
/// sink v*/(1 + Δt C (1 − f_l)); the divergence solve's store Δt Σκ.
pub fn predict(pr: &Params, st: &mut State, grid: &CellTable, table: &PairTable) {
    let dt = st.sim.dt;
    let s: &State = st;
    let heads: Vec<(usize, [f32; 3])> = fluid(pr, s)
        .into_par_iter()
        .map(|i| (i, wall_head(pr, s, grid, table, i)))
        .collect();
    for (i, b) in heads {
        st.dfsph_warm[i][1] = dt * st.dfsph[i][3];
        let a = st.acc[i];
        let sink = pr.phase(st.phase[i]).mushy_damping;
        let liquid = if sink > 0.0 {
            st.heat[i][H_LIQUID]
        } else {
            1.0
        };
        let v = &mut st.vel[i];
        for c in 0..3 {
            v[c] = v[c] + dt * a[c] - dt * b[c];
        }
        // The mushy-zone sink J22 (11)–(13), as the WCSPH kick has it.
        if sink > 0.0 {
            let damp = 1.0 + dt * sink * (1.0 - liquid);
            for c in v.iter_mut().take(3) {
                *c /= damp;
            }
        }
    }
}

/// `dfsph_drift`: x += Δt v*, wrapped and stamped if it left; p = ρ Σκ.
pub fn drift(pr: &Params, st: &mut State) {
    let dt = st.sim.dt;
    let left_at = st.sim.step_end();
    for i in fluid(pr, st) {
        let v = st.vel[i];
        let x = &mut st.pos[i];
        for c in 0..3 {
            x[c] += dt * v[c];
            wrap_periodic(pr, x, c);
        }
        stamp_if_left(pr, x, left_at);
        let k = st.dfsph[i][3];
        st.press[i] = (k + st.dfsph_warm[i][1] / dt) * st.rho[i];
        st.dfsph_warm[i][0] = dt * dt * k;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::cpu::neighbors;

    /// The factor pass's sums and recorded pairs, with the kernel taken eight
    /// neighbours at a time, give the bits of the one-at-a-time loop, on the
    /// 2D spray droplet (fluid and wall neighbours, r = 0, neighbour counts
    /// that are not multiples of eight) and the 3D DFSPH dam break.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn eight_wide_factor_sums_match_the_scalar_loop() {
        if !*crate::lanes::AVX2 {
            return;
        }
        for scene in ["spray/j22_fluent_case_2d", "validation/dam_break_3d"] {
            let path = format!("{}/scenarios/{scene}.toml", env!("CARGO_MANIFEST_DIR"));
            let sets = [
                "formulation=\"dfsph\"".to_string(),
                "pressure_floor=false".into(),
                "initial_pressure=\"zero\"".into(),
                "jitter=0.3".into(),
            ];
            let l = crate::load::load(&path, &sets).unwrap();
            let pr = Params::new(&l.model, l.state.len() as u32);
            let mut st = l.state.clone();
            let mut grid = CellTable::default();
            neighbors::run(&pr, &mut st, &mut grid);
            boundary_volume(&pr, &mut st);
            let (mut checked, mut lengths) = (0, std::collections::BTreeSet::new());
            for i in 0..st.active() {
                if pr.is_wall(st.phase[i]) {
                    continue;
                }
                let js = with_neighbors(&pr, &st.pos, &grid, i, |js, _| js.to_vec());
                let run = |wide: bool| {
                    let mut chunk = PairTable::default().take_chunks(1).remove(0);
                    let mut sums = FactorSums::new(pr.phase(st.phase[i]).rho0);
                    if wide {
                        // SAFETY: AVX2 checked above.
                        unsafe {
                            factor_sums_avx2(&pr, &st, st.pos[i], &js, &mut chunk, &mut sums)
                        };
                    } else {
                        factor_sums(&pr, &st, st.pos[i], &js, &mut chunk, &mut sums);
                    }
                    let mut bits: Vec<u32> = [sums.sum_f, sums.sum_b, sums.sq]
                        .into_iter()
                        .chain(sums.g)
                        .chain(sums.gb)
                        .map(f32::to_bits)
                        .collect();
                    for p in &chunk.items {
                        bits.extend([p.j, p.g.to_bits()]);
                        bits.extend(p.d.map(f32::to_bits));
                    }
                    bits
                };
                assert_eq!(run(true), run(false), "{scene}: particle {i}");
                checked += 1;
                lengths.insert(js.len() % 8);
            }
            assert!(
                checked > 100 && lengths.len() > 1,
                "{scene}: {checked} {lengths:?}"
            );
        }
    }
}
