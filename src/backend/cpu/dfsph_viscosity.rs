//! Twin of shaders/dfsph_viscosity.wgsl: DFSPH's implicit velocity system,
//! J22 (17): the viscosity, XSPH (J22 (14)) and the cohesion and adhesion
//! terms (J22 (15)–(16)) solved together for v^{t+1} by matrix-free
//! conjugate gradients (Jacobi preconditioned), after v* = v + Δt a (the
//! explicit forces) and before the constant-density solve.
//!
//! - The system, multiplied by m_i so that the matrix is symmetric:
//!   m_i v_i + Σ_j [K_ij (v_i − v_j) + s_ij (v_i − v_j)] = m_i v*_i + c_i,
//!   with the viscous pair block K_ij either F22 (23)'s isotropic
//!   −Δt μ_ij (V_i² + V_j²) (∂W/∂r / r) I (the default) or Weiler et al.
//!   (2018)'s projected −Δt 2(d+2) μ_ij V_i V_j (∂W/∂r / r) x_ij x_ijᵀ
//!   / (r² + 0.01 h²) (J22 (4) and (17); `viscosity_form = "marrone"`),
//!   s_ij = α m_i m_j W_ij / ρ̄_ij (ρ̄ the mean, α J22's XSPH factor) and
//!   c_i the cohesion and adhesion impulse. The pair blocks are positive
//!   semi-definite and the masses make the matrix positive definite, so CG
//!   converges. Weiler's form is 0.83 of the Laplacian at h = Δx with the
//!   quintic (terms/marrone_viscosity.rs): Poiseuille 18% off, against 0.17%
//!   with F22's.
//! - μ_ij = 2 μ_i μ_j / (μ_i + μ_j) (the explicit viscosity's mean); J22 has
//!   one fluid. XSPH takes m_j / ρ̄_ij where J22 has m̄_ij / ρ̄_ij (the same for
//!   one material): with it the matrix stays symmetric and the pair impulses
//!   stay equal and opposite.
//! - Walls (multi-layer, volume V_b of the factor pass): no-slip, the
//!   viscosity pair against Adami et al. (2012)'s extrapolated wall velocity
//!   u_b = 2 u_w − ũ_b, ũ_b from the fluid's velocity before the explicit
//!   forces (a constant part of the right side, lagged by one step); none
//!   against a free-slip wall phase (`free_slip`). No XSPH against walls (J22
//!   (14) sums over the fluid). With u_b = u_w instead, the fluid saw three
//!   layers at rest and the Poiseuille channel ran 14.5% fast; with ũ_b from
//!   v* = v + Δt a the wall moved at −Δt a and at Δt = 100× the explicit
//!   limit the channel ran 13% fast.
//! - CG from x0 = v*: r = b − A x0 = −Σ_j (pair terms at v*), z = r / diag(A),
//!   p = z; each iteration q = A p, α = r·z / p·q, v += α p, r −= α q,
//!   β = r·z_new / r·z, p = z + β p. Dot products by the fixed tree
//!   (super::reduce). Converged when |r| ≤ tolerance |r0| (the viscous and
//!   XSPH impulse at v*), |·| the Euclidean norm over all fluid components;
//!   at once when r0 = 0 (no viscosity, no XSPH). Against |b| = |m v*|
//!   instead, a column at rest (v* = Δt g everywhere, the viscous part 1% of
//!   it) stopped after 2 iterations with its noise modes half solved, and its
//!   pressure error swung between 20% and 150% (0.5-1.8% with the explicit
//!   viscosity).
//! - Scalars in the solver's slot: r·z, r0·r0, α, β.
//! - J22's cohesion (15) and adhesion (16) as printed: on the right side,
//!   with this step's positions (J22 does not say whether it predicts
//!   them: its text says "implicit", its equation depends on x^t only).
//!   γ is read per unit mass, in 1/s² (J22 prints N/m): J22's γ = 200 then
//!   gives about 2e-5 m/s² at Δx = 0.8 µm, nothing against a 200 m/s impact,
//!   so J22's value is not the scene's (docs/physics.md, DFSPH).

use super::dfsph_pairs::{for_each_pair, Pair, PairTable};
use super::neighbors::{for_each_neighbor, for_each_neighbor_among, Among, CellTable, LIST_CHUNK};
use super::reduce::tree_total;
use super::terms::pair_viscosity;
use crate::backend::schedule::SolverSlot;
use crate::kernel;
use crate::lanes::Lane;
use crate::params::{Params, PHASE_FREE_SLIP};
use crate::state::{Solver, State};
use rayon::prelude::*;

const SLOT: usize = SolverSlot::Viscosity as usize;
/// Entries of `dfsph_cg` per particle: residual r, direction p, A p, diag(A).
const R: usize = 0;
const P: usize = 1;
const Q: usize = 2;
const DIAG: usize = 3;

/// What the coefficients of fluid particle i's pairs share.
struct RowOf {
    mu_i: f32,
    vol_i: f32,
    m_i: f32,
    rho_i: f32,
}

impl RowOf {
    fn new(pr: &Params, st: &State, i: usize) -> Self {
        RowOf {
            mu_i: pr.phase(st.phase[i]).implicit_eta,
            vol_i: st.mass[i] / st.rho[i],
            m_i: st.mass[i],
            rho_i: st.rho[i],
        }
    }
}

/// What the coefficients take of neighbour j, in the order of `coefficients`'
/// lanes: μ_ij, V_j, m_j, ρ_j, g, r², and 1 for a fluid j (0 for a wall).
#[inline(always)]
fn gather(pr: &Params, st: &State, row: &RowOf, j: usize, d: [f32; 3], g: f32) -> [f32; 7] {
    let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let ph_j = st.phase[j];
    let wall = pr.is_wall(ph_j);
    let (mu, vol_j) = if wall {
        let slip = pr.phase(ph_j).flags & PHASE_FREE_SLIP != 0;
        (pair_viscosity(row.mu_i, row.mu_i, slip), st.dfsph[j][0])
    } else {
        let mu = pair_viscosity(row.mu_i, pr.phase(ph_j).implicit_eta, false);
        (mu, st.mass[j] / st.rho[j])
    };
    let fluid = if wall { 0.0 } else { 1.0 };
    [mu, vol_j, st.mass[j], st.rho[j], g, r2, fluid]
}

/// The pair's coefficients (k_p, k_i, s) from `gather`'s values, on one pair
/// or on eight (`Lane`, the same operations): the projected viscosity's −k_ij
/// (Weiler; `viscosity_form = "marrone"`) or the isotropic one's (F22 (23)),
/// both ≤ 0, and XSPH's s_ij (0 against a wall).
#[inline(always)]
fn coefficients<R: Lane>(pr: &Params, dt: f32, row: &RowOf, q: [R; 7]) -> [R; 3] {
    let [mu, vol_j, m_j, rho_j, g, r2, fluid] = q;
    let c = R::splat;
    let (vol_i, zero) = (c(row.vol_i), c(0.0));
    let (mut kp, mut ki) = (zero, zero);
    if pr.solve.dfsph_viscosity_form == 1 {
        let f = c(dt * pr.solve.viscosity_factor);
        kp = f * mu * vol_i * vol_j * g / (r2 + c(pr.solve.dfsph_viscosity_eps));
    } else {
        ki = c(dt) * mu * (vol_i * vol_i + vol_j * vol_j) * g;
    }
    let s = c(pr.solve.dfsph_xsph) * c(row.m_i) * m_j * kernel::w(pr, r2.sqrt())
        / ((c(row.rho_i) + rho_j) * c(0.5));
    [kp, ki, fluid.where_lt(0.5, zero, s)]
}

/// One pair's coefficients (k_p, k_i, s), x_ij = d, g = ∂W/∂r / r.
#[inline(always)]
fn pair(pr: &Params, st: &State, row: &RowOf, j: usize, d: [f32; 3], g: f32) -> [f32; 3] {
    coefficients(pr, st.sim.dt, row, gather(pr, st, row, j, d, g))
}

/// The coefficients of i's pairs `ps`, in their order, onto `out`: eight at
/// a time where the CPU has AVX2 (the same bits: `coefficients` is the same
/// operations on each lane).
fn row_coefficients(pr: &Params, st: &State, i: usize, ps: &[Pair], out: &mut Vec<[f32; 3]>) {
    let row = RowOf::new(pr, st, i);
    #[cfg(target_arch = "x86_64")]
    if *crate::lanes::AVX2 {
        // SAFETY: the CPU has AVX2 (checked once at run time).
        return unsafe { row_coefficients_avx2(pr, st, &row, ps, out) };
    }
    out.extend(
        ps.iter()
            .map(|p| pair(pr, st, &row, p.j as usize, p.d, p.g)),
    );
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn row_coefficients_avx2(
    pr: &Params,
    st: &State,
    row: &RowOf,
    ps: &[Pair],
    out: &mut Vec<[f32; 3]>,
) {
    use crate::lanes::F8;
    let dt = st.sim.dt;
    for block in ps.chunks(8) {
        // Lanes past the block's end repeat its first pair (dropped below).
        let mut q = [[0.0f32; 8]; 7];
        for lane in 0..8 {
            let p = block[if lane < block.len() { lane } else { 0 }];
            let g = gather(pr, st, row, p.j as usize, p.d, p.g);
            for (k, v) in g.into_iter().enumerate() {
                q[k][lane] = v;
            }
        }
        let [kp, ki, s] = coefficients(pr, dt, row, q.map(F8::from_array)).map(F8::to_array);
        out.extend((0..block.len()).map(|lane| [kp[lane], ki[lane], s[lane]]));
    }
}

/// The velocity system's pair coefficients (k_p, k_i, s) of this step, in the
/// order of the pair table's entries (dfsph_pairs; the same offsets): they do
/// not change between `begin` and the last `apply`, so `begin` evaluates them
/// once and each CG iteration only multiplies. Valid for one cell table.
#[derive(Default)]
pub struct Couplings {
    generation: u64,
    chunks: Vec<Vec<[f32; 3]>>,
}

/// Sums of fluid particle i's row: Σ_j [−k_p x_ij (x_ij·u_ij) − k_i u_ij +
/// s_ij u_ij], u_ij the difference of `field` (a wall's value: `wall`),
/// and the diagonal m_i + Σ_j (−k_p x_ij,a² − k_i + s_ij).
struct Row<F, G> {
    acc: [f32; 3],
    dg: [f32; 3],
    f_i: [f32; 3],
    field: F,
    wall: G,
}

impl<F: Fn(usize) -> [f32; 3], G: Fn(usize) -> [f32; 3]> Row<F, G> {
    fn new(st: &State, i: usize, field: F, wall: G) -> Self {
        let m_i = st.mass[i];
        Row {
            acc: [0.0; 3],
            dg: [m_i, m_i, m_i],
            f_i: field(i),
            field,
            wall,
        }
    }

    /// Adds pair (j, x_ij = d) with coefficients (k_p, k_i, s).
    #[inline(always)]
    fn add(&mut self, pr: &Params, st: &State, j: usize, d: [f32; 3], [kp, ki, s]: [f32; 3]) {
        let f_j = if pr.is_wall(st.phase[j]) {
            (self.wall)(j)
        } else {
            (self.field)(j)
        };
        let f_i = self.f_i;
        let u = [f_i[0] - f_j[0], f_i[1] - f_j[1], f_i[2] - f_j[2]];
        let c = kp * (d[0] * u[0] + d[1] * u[1] + d[2] * u[2]);
        let (acc, dg) = (&mut self.acc, &mut self.dg);
        for a in 0..3 {
            acc[a] = acc[a] - c * d[a] - ki * u[a] + s * u[a];
            dg[a] = dg[a] - kp * d[a] * d[a] - ki + s;
        }
    }
}

/// i's row over pairs (j, x_ij, coefficients) already evaluated.
fn sum_pairs(
    pr: &Params,
    st: &State,
    i: usize,
    pairs: impl Iterator<Item = (usize, [f32; 3], [f32; 3])>,
    field: impl Fn(usize) -> [f32; 3],
    wall: impl Fn(usize) -> [f32; 3],
) -> ([f32; 3], [f32; 3]) {
    let mut row = Row::new(st, i, field, wall);
    for (j, d, k) in pairs {
        row.add(pr, st, j, d, k);
    }
    (row.acc, row.dg)
}

/// i's row with each pair's coefficients evaluated here (no couplings
/// recorded this step), in the same order.
fn sweep(
    pr: &Params,
    st: &State,
    grid: &CellTable,
    table: &PairTable,
    i: usize,
    field: impl Fn(usize) -> [f32; 3],
    wall: impl Fn(usize) -> [f32; 3],
) -> ([f32; 3], [f32; 3]) {
    let of = RowOf::new(pr, st, i);
    let mut row = Row::new(st, i, field, wall);
    for_each_pair(pr, &st.pos, grid, table, i, |j, d, g| {
        row.add(pr, st, j, d, pair(pr, st, &of, j, d, g));
    });
    (row.acc, row.dg)
}

/// J22 (15)–(16) as printed, on the right side (positions of this step):
/// m_i Δt a_i with a_i = −γ^f Σ_{j, same phase} (m̄_ij/ρ̄_ij) x_ij W_ij
/// − γ^b Σ_b (m̄_ib/ρ̄_ib) x_ib W_ib, a wall's mass ρ0_i V_b and density ρ0_i.
fn cohesion_impulse(pr: &Params, st: &State, grid: &CellTable, i: usize) -> [f32; 3] {
    let (m_i, rho_i, ph_i) = (st.mass[i], st.rho[i], st.phase[i]);
    let rho0_i = pr.phase(ph_i).rho0;
    let (mut sf, mut sb) = ([0.0f32; 3], [0.0f32; 3]);
    for_each_neighbor(pr, &st.pos, grid, i, |j, d, r2| {
        if r2 <= 0.0 {
            return;
        }
        let w = kernel::w(pr, r2.sqrt());
        if pr.is_wall(st.phase[j]) {
            let m_b = rho0_i * st.dfsph[j][0];
            let f = (m_i + m_b) / (rho_i + rho0_i) * w;
            for a in 0..3 {
                sb[a] += f * d[a];
            }
        } else if st.phase[j] == ph_i {
            let f = (m_i + st.mass[j]) / (rho_i + st.rho[j]) * w;
            for a in 0..3 {
                sf[a] += f * d[a];
            }
        }
    });
    let (gf, gb) = (pr.solve.dfsph_cohesion, pr.solve.dfsph_adhesion);
    let mdt = m_i * st.sim.dt;
    [
        -(gf * sf[0] + gb * sb[0]) * mdt,
        -(gf * sf[1] + gb * sb[1]) * mdt,
        -(gf * sf[2] + gb * sb[2]) * mdt,
    ]
}

fn fluid(pr: &Params, st: &State) -> Vec<usize> {
    (0..st.active())
        .filter(|&i| !pr.is_wall(st.phase[i]))
        .collect()
}

fn converged(st: &State) -> bool {
    st.solvers[SLOT].converged != 0
}

fn xyz(v: [f32; 4]) -> [f32; 3] {
    [v[0], v[1], v[2]]
}

fn dot(a: [f32; 4], b: [f32; 4]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// z = r / diag(A).
fn precondition(cg: &[[f32; 4]], i: usize) -> [f32; 4] {
    let (r, dg) = (cg[4 * i + R], cg[4 * i + DIAG]);
    [r[0] / dg[0], r[1] / dg[1], r[2] / dg[2], 0.0]
}

/// A dot product of fluid entries by the tree (0 elsewhere).
fn tree_dot(pr: &Params, st: &State, value: impl Fn(usize) -> [f32; 2] + Sync) -> [f32; 2] {
    tree_total(pr.n(), |i| {
        if i < st.active() && !pr.is_wall(st.phase[i]) {
            value(i)
        } else {
            [0.0, 0.0]
        }
    })
}

/// `dfsph_viscosity_wall` (before v* = v + Δt a): each wall particle's
/// no-slip velocity in its dfsph_cg[4 b] (Adami et al. 2012, as the wall
/// pass: u_b = 2 u_w − ũ_b, ũ_b the Shepard mean of the fluid's v over its
/// neighbours, the divisor Σ W + ε).
pub fn wall_velocities(pr: &Params, st: &mut State, grid: &CellTable) {
    let s: &State = st;
    // The sums want fluid neighbours only (`for_each_neighbor_among`).
    let fluid = Among::phases(&s.phase, |p| !pr.is_wall(p));
    let rows: Vec<(usize, [f32; 4])> = (0..s.active())
        .into_par_iter()
        .filter(|&b| pr.is_wall(s.phase[b]))
        .map(|b| {
            let (mut sw, mut sv) = (0.0f32, [0.0f32; 3]);
            for_each_neighbor_among(pr, &s.pos, grid, b, fluid, |j, _, r2| {
                let wk = kernel::w(pr, r2.sqrt());
                sw += wk;
                let v = s.vel[j];
                for a in 0..3 {
                    sv[a] += v[a] * wk;
                }
            });
            let u = pr.phase(s.phase[b]).velocity.to_array();
            let den = sw + pr.flow.wall_weight_floor;
            let v = [
                u[0] + (u[0] * sw - sv[0]) / den,
                u[1] + (u[1] * sw - sv[1]) / den,
                u[2] + (u[2] * sw - sv[2]) / den,
                0.0,
            ];
            (b, v)
        })
        .collect();
    for (b, v) in rows {
        st.dfsph_cg[4 * b + R] = v;
    }
}

/// One fluid particle's row at x0 = v*: (i, Σ pair terms, diag(A), the
/// cohesion and adhesion impulse).
type BeginRow = (usize, [f32; 3], [f32; 3], [f32; 3]);

/// `dfsph_viscosity_begin` and its sums: r, diag(A), p = z at x0 = v*; the
/// solver reset with r·z and r0·r0, converged at once when r·z = 0. Records
/// the step's couplings when the pair table holds this step's pairs.
pub fn begin(
    pr: &Params,
    st: &mut State,
    grid: &CellTable,
    table: &PairTable,
    couplings: &mut Couplings,
) {
    let s: &State = st;
    let cohesive = pr.solve.dfsph_cohesion > 0.0 || pr.solve.dfsph_adhesion > 0.0;
    let row = |i: usize, (acc, dg): ([f32; 3], [f32; 3])| -> BeginRow {
        let c = if cohesive {
            cohesion_impulse(pr, s, grid, i)
        } else {
            [0.0; 3]
        };
        (i, acc, dg, c)
    };
    let at_v = |j: usize| xyz(s.vel[j]);
    let wall_v = |j: usize| xyz(s.dfsph_cg[4 * j + R]);
    couplings.generation = 0;
    let rows: Vec<BeginRow> = if let Some(pairs) = table.chunks(grid) {
        let mut chunks = std::mem::take(&mut couplings.chunks);
        chunks.resize_with(pairs.len(), Vec::new);
        let n = s.active();
        let rows: Vec<Vec<BeginRow>> = pairs
            .par_iter()
            .zip(chunks.par_iter_mut())
            .enumerate()
            .map(|(c, (chunk, coef))| {
                coef.clear();
                let range = c * LIST_CHUNK..((c + 1) * LIST_CHUNK).min(n);
                range
                    .filter(|&i| !pr.is_wall(s.phase[i]))
                    .map(|i| {
                        let ps = chunk.of(i % LIST_CHUNK);
                        let base = coef.len();
                        row_coefficients(pr, s, i, ps, coef);
                        let terms = ps
                            .iter()
                            .zip(&coef[base..])
                            .map(|(p, &k)| (p.j as usize, p.d, k));
                        row(i, sum_pairs(pr, s, i, terms, at_v, wall_v))
                    })
                    .collect()
            })
            .collect();
        couplings.chunks = chunks;
        couplings.generation = grid.generation;
        rows.into_iter().flatten().collect()
    } else {
        // No pair table this step: the couplings' memory is given back too.
        couplings.chunks = Vec::new();
        fluid(pr, s)
            .into_par_iter()
            .map(|i| row(i, sweep(pr, s, grid, table, i, at_v, wall_v)))
            .collect()
    };
    for (i, acc, dg, c) in rows {
        // Negated, not 0 − acc: lavapipe folds 0 − x into −x (−0 at x = 0).
        st.dfsph_cg[4 * i + R] = if cohesive {
            [c[0] - acc[0], c[1] - acc[1], c[2] - acc[2], 0.0]
        } else {
            [-acc[0], -acc[1], -acc[2], 0.0]
        };
        st.dfsph_cg[4 * i + DIAG] = [dg[0], dg[1], dg[2], 0.0];
        st.dfsph_cg[4 * i + P] = precondition(&st.dfsph_cg, i);
    }
    let s: &State = st;
    let [rz, rr] = tree_dot(pr, s, |i| {
        let r = s.dfsph_cg[4 * i + R];
        [dot(r, s.dfsph_cg[4 * i + P]), dot(r, r)]
    });
    st.solvers[SLOT] = Solver {
        converged: (rz <= 0.0) as u32,
        scalars: [rz, rr, 0.0, 0.0],
        ..st.solvers[SLOT].reset()
    };
}

/// `dfsph_viscosity_apply` (and its sums): q = A p, α = r·z / p·q; from the
/// step's couplings when `begin` recorded them.
pub fn apply(
    pr: &Params,
    st: &mut State,
    grid: &CellTable,
    table: &PairTable,
    couplings: &Couplings,
) {
    if converged(st) {
        return;
    }
    let s: &State = st;
    let at_p = |j: usize| xyz(s.dfsph_cg[4 * j + P]);
    let zero = |_: usize| [0.0; 3];
    let recorded = table
        .chunks(grid)
        .filter(|_| couplings.generation == grid.generation);
    let rows: Vec<(usize, [f32; 3])> = if let Some(pairs) = recorded {
        fluid(pr, s)
            .into_par_iter()
            .map(|i| {
                let (c, k) = (i / LIST_CHUNK, i % LIST_CHUNK);
                let chunk = &pairs[c];
                let at = chunk.offsets[k] as usize..chunk.offsets[k + 1] as usize;
                let terms = chunk.items[at.clone()]
                    .iter()
                    .zip(&couplings.chunks[c][at])
                    .map(|(p, &k)| (p.j as usize, p.d, k));
                (i, sum_pairs(pr, s, i, terms, at_p, zero).0)
            })
            .collect()
    } else {
        fluid(pr, s)
            .into_par_iter()
            .map(|i| (i, sweep(pr, s, grid, table, i, at_p, zero).0))
            .collect()
    };
    for (i, acc) in rows {
        let m = st.mass[i];
        let p = st.dfsph_cg[4 * i + P];
        st.dfsph_cg[4 * i + Q] = [m * p[0] + acc[0], m * p[1] + acc[1], m * p[2] + acc[2], 0.0];
    }
    let s: &State = st;
    let [pq, _] = tree_dot(pr, s, |i| {
        [dot(s.dfsph_cg[4 * i + P], s.dfsph_cg[4 * i + Q]), 0.0]
    });
    let sc = &mut st.solvers[SLOT].scalars;
    sc[2] = if pq > 0.0 { sc[0] / pq } else { 0.0 };
}

/// `dfsph_viscosity_update` (its sums, the residual and the new direction):
/// v += α p, r −= α q; β, the relative residual |r|/|r0| and the converged
/// flag; p = z + β p.
pub fn update(pr: &Params, st: &mut State) {
    if converged(st) {
        return;
    }
    let alpha = st.solvers[SLOT].scalars[2];
    for i in fluid(pr, st) {
        let (p, q) = (st.dfsph_cg[4 * i + P], st.dfsph_cg[4 * i + Q]);
        let v = &mut st.vel[i];
        let r = &mut st.dfsph_cg[4 * i + R];
        for a in 0..3 {
            v[a] += alpha * p[a];
            r[a] -= alpha * q[a];
        }
    }
    let s: &State = st;
    let [rz, rr] = tree_dot(pr, s, |i| {
        let r = s.dfsph_cg[4 * i + R];
        [dot(r, precondition(&s.dfsph_cg, i)), dot(r, r)]
    });
    let tolerance = pr.solve.dfsph_viscosity_tolerance;
    let sv = &mut st.solvers[SLOT];
    let [rz_old, rr0, _, _] = sv.scalars;
    let beta = if rz_old > 0.0 { rz / rz_old } else { 0.0 };
    sv.scalars[0] = rz;
    sv.scalars[3] = beta;
    let residual = if rr0 > 0.0 { (rr / rr0).sqrt() } else { 0.0 };
    sv.finish(
        residual,
        residual <= tolerance,
        pr.solve.dfsph_viscosity_max_iterations,
    );
    if converged(st) {
        return;
    }
    for i in fluid(pr, st) {
        let z = precondition(&st.dfsph_cg, i);
        let p = &mut st.dfsph_cg[4 * i + P];
        for a in 0..3 {
            p[a] = z[a] + beta * p[a];
        }
    }
}
