//! Twin of shaders/heat.wgsl: heat conduction in enthalpy form (J22 (20)–(22),
//! F22 (41), Cleary & Monaghan 1999) and the temperature of each particle's
//! enthalpy (J22 (19)).
//!
//! wall_temperature: a Dirichlet wall particle w takes T_w = 2 T_wall − T̃_w (T_wall
//!   its own fixed temperature, held in heat.x: a wall has no enthalpy) with
//!   T̃_w = Σ_f T_f W_wf / Σ_f W_wf over conducting neighbours, the temperature
//!   analogue of Adami (2012)'s no-slip velocity: the profile continues through the
//!   wall and crosses T_wall at the wall face. (Holding the layers at T_wall instead
//!   puts the effective surface half a particle spacing inside the wall: conduction_1d
//!   measured 2.2% error that way, first order in Δx.)
//! conduct: for every conducting particle i (liquid, gas, solid)
//!   dh_i/dt = (1/ρ_i) Σ_j V_j k_ij (T_i − T_j) (∇_iW_ij · r_ij)/(r_ij² + η²),
//!   k_ij = 4 k_i k_j/(k_i + k_j) between conducting particles, 2 k_i against a
//!   Dirichlet wall (J22 (25)); adiabatic walls and free surfaces add nothing.
//!   ∇_iW·r_ij = r dW/dr. A laser source (heat.w, left by the laser pass) adds to
//!   the rate, surface losses (evaporation, radiation; `surface_loss`) subtract.
//!   Explicit Euler: h_i += Δt dh_i/dt (J22 (21)); or the trapezoidal rule
//!   (R18 Algorithm 3.1, `begin` and the iteration below). V_j = m_j/ρ_j with
//!   summation density for fluids and ρ0 for solids and walls, which do not
//!   compress. Each pair's flux is antisymmetric, so the total enthalpy Σ m h
//!   changes only through Dirichlet walls and the laser (up to rounding).
//! temperature: T(h) and f_l(h) per material, linear over the melting band, and
//!   the solid ↔ liquid switch at f_l = ½.

use super::neighbors::{
    for_each_neighbor, for_each_neighbor_among, min_image, with_listed, Among, CellTable,
    NeighborList,
};
use crate::backend::SolverSlot;
use crate::kernel;
use crate::lanes::Lane;
use crate::params::{
    law_at, law_segment, Params, FLAG_BODIES, FLAG_CONDUCTIVITY_TABLE, FLAG_INTERFACE,
    FLAG_SOLIDIFICATION, HEAT_DIRICHLET, HEAT_LIQUID, HEAT_MELTS, HEAT_TRAPEZOIDAL, KIND_SOLID,
};
use crate::portable_math::exp as pm_exp;
use crate::state::{State, BODY_SOLIDIFIED};
use crate::state::{H_ENTHALPY, H_LIQUID, H_RATE, H_TEMPERATURE, S_DELTA};
use crate::state::{SOL_COOLING, SOL_COUNT, SOL_GRADIENT, SOL_PENDING, SOL_TIME};
use rayon::prelude::*;

/// Density a particle's volume and heat capacity use: summation density for
/// fluids, ρ0 for solids and walls.
#[inline(always)]
fn heat_density(pr: &Params, rho: &[f32], phase: u32, i: usize) -> f32 {
    if pr.is_wall(phase) {
        pr.phases[phase as usize].rho0
    } else {
        rho[i]
    }
}

pub fn wall_temperature(pr: &Params, st: &mut State, grid: &CellTable) {
    let (pos, phase, heat_in) = (&st.pos, &st.phase, &st.heat);
    // The sums want conducting neighbours only (`for_each_neighbor_among`).
    let conducting = Among::phases(phase, |p| pr.conducts(p));
    let out: Vec<Option<f32>> = (0..st.active())
        .into_par_iter()
        .map(|i| {
            let ph = phase[i];
            if pr.conducts(ph) || pr.heat_flags(ph) & HEAT_DIRICHLET == 0 {
                return None;
            }
            let (mut sw, mut st_) = (0.0f32, 0.0f32);
            for_each_neighbor_among(pr, pos, grid, i, conducting, |j, _, r2| {
                let wk = kernel::w(pr, r2.sqrt());
                sw += wk;
                st_ += heat_in[j][H_TEMPERATURE] * wk;
            });
            let t_wall = heat_in[i][H_ENTHALPY];
            Some(if sw > 0.0 {
                2.0 * t_wall - st_ / sw
            } else {
                t_wall
            })
        })
        .collect();
    for (hv, t) in st.heat.iter_mut().zip(out) {
        if let Some(t) = t {
            hv[H_TEMPERATURE] = t;
        }
    }
}

/// What `rate` reads of every particle, computed once per particle and pass
/// instead of once per pair (the same operations, so the same bits): the
/// conductivity at heat.y and heat.z (0 where the phase does not conduct), and
/// the volume m/ρ with `heat_density`.
struct Conductors {
    k: Vec<f32>,
    vol: Vec<f32>,
}

impl Conductors {
    fn new(pr: &Params, st: &State) -> Self {
        let (rho, mass, phase, heat) = (&st.rho, &st.mass, &st.phase, &st.heat);
        let (k, vol) = (0..st.len())
            .into_par_iter()
            .map(|j| {
                let ph = phase[j];
                let k = if pr.conducts(ph) {
                    conductivity(pr, ph, heat[j][H_TEMPERATURE], heat[j][H_LIQUID])
                } else {
                    0.0
                };
                (k, mass[j] / heat_density(pr, rho, ph, j))
            })
            .unzip();
        Conductors { k, vol }
    }
}

/// dh_i/dt of conducting particle i at the temperatures in heat.y (and the
/// liquid fractions in heat.z): conduction, the laser's source (W/kg), viscous
/// heating, minus the surface losses.
#[inline(always)]
fn rate(
    pr: &Params,
    st: &State,
    grid: &CellTable,
    list: &NeighborList,
    near: &Conductors,
    i: usize,
    laser_source: f32,
) -> f32 {
    let (pos, rho, phase, heat) = (&st.pos, &st.rho, &st.phase, &st.heat);
    let ph_i = phase[i];
    let k_i = near.k[i];
    let t_i = heat[i][H_TEMPERATURE];
    let sum = with_listed(pr, pos, grid, list, i, |js| {
        conduction_sum(pr, st, near, i, k_i, t_i, js)
    });
    let mut source = laser_source;
    if pr.flag(crate::params::FLAG_VISCOUS_HEATING) {
        source += st.acc[i][3];
    }
    let loss = if pr.flag(FLAG_INTERFACE) {
        surface_loss(pr, ph_i, t_i, st.surface[i][S_DELTA])
    } else {
        0.0
    };
    source - loss + sum / heat_density(pr, rho, ph_i, i)
}

/// Σ_j V_j k_ij (T_i − T_j) W'(r) r/(r² + η²) over the neighbours `js` of
/// conducting particle i in their order, leaving out j = i (r = 0) and
/// neighbours that neither conduct nor are Dirichlet walls. The terms of a
/// block of eight are computed at once (eight lanes with AVX2,
/// `conduction_terms`) and added one at a time in order; a neighbour left out
/// adds +0, which leaves the sum's bits as they are (it starts at +0 and is
/// never −0). The same bits as skipping it, and as the WGSL loop.
#[inline(always)]
fn conduction_sum(
    pr: &Params,
    st: &State,
    near: &Conductors,
    i: usize,
    k_i: f32,
    t_i: f32,
    js: &[u32],
) -> f32 {
    let (pos, phase, heat) = (&st.pos, &st.phase, &st.heat);
    let pi = pos[i];
    let mut sum = 0.0f32;
    for block in js.chunks(8) {
        // per neighbour: r², V_j, T_j, the ordered conductivities and their
        // sum, and which k_ij applies (0: both conduct, 1: Dirichlet wall,
        // 2: none, or j = i)
        let mut b = [[0.0f32; 8]; 7];
        for (k, &j) in block.iter().enumerate() {
            let j = j as usize;
            let d = min_image(pr, pi, pos[j]);
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let ph_j = phase[j];
            let (lo, hi, ksum, which) = if pr.conducts(ph_j) {
                let k_j = near.k[j];
                // Ordered operands: i and j compute the same bits, so the
                // pair's fluxes cancel exactly in the total enthalpy.
                (k_i.min(k_j), k_i.max(k_j), k_i + k_j, 0.0)
            } else if pr.heat_flags(ph_j) & HEAT_DIRICHLET != 0 {
                (0.0, 0.0, 1.0, 1.0)
            } else {
                (0.0, 0.0, 1.0, 2.0)
            };
            b[0][k] = r2;
            b[1][k] = near.vol[j];
            b[2][k] = heat[j][H_TEMPERATURE];
            b[3][k] = lo;
            b[4][k] = hi;
            b[5][k] = ksum;
            b[6][k] = if r2 <= 0.0 { 2.0 } else { which };
        }
        let terms = conduction_terms(pr, k_i, t_i, &b, block.len());
        for &t in &terms[..block.len()] {
            sum += t;
        }
    }
    sum
}

/// `conduction_sum`'s terms of up to eight neighbours, the scalar operations
/// lane by lane.
#[inline(always)]
fn conduction_terms(pr: &Params, k_i: f32, t_i: f32, b: &[[f32; 8]; 7], len: usize) -> [f32; 8] {
    #[cfg(target_arch = "x86_64")]
    if len == 8 && *crate::lanes::AVX2 {
        // SAFETY: the CPU has AVX2 (checked once at run time).
        return unsafe { conduction_terms_avx2(pr, k_i, t_i, b) };
    }
    let mut out = [0.0f32; 8];
    for k in 0..len {
        let lane = |a: usize| b[a][k];
        out[k] = conduction_term(pr, k_i, t_i, [0, 1, 2, 3, 4, 5, 6].map(lane));
    }
    out
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn conduction_terms_avx2(pr: &Params, k_i: f32, t_i: f32, b: &[[f32; 8]; 7]) -> [f32; 8] {
    use crate::lanes::F8;
    conduction_term(pr, k_i, t_i, b.map(F8::from_array)).to_array()
}

/// V_j k_ij (T_i − T_j) W'(r) r/(r² + η²) with k_ij = 4 k_i k_j/(k_i + k_j)
/// (ordered operands), 2 k_i against a Dirichlet wall, and 0 where neither
/// applies or r = 0 (b: r², V_j, T_j, min k, max k, k_i + k_j, which).
#[inline(always)]
fn conduction_term<R: Lane>(pr: &Params, k_i: f32, t_i: f32, b: [R; 7]) -> R {
    let c = R::splat;
    let [r2, v_j, t_j, lo, hi, ksum, which] = b;
    let both = c(4.0) * lo * hi / ksum;
    let k_ij = which.where_lt(0.5, both, which.where_lt(1.5, c(2.0) * c(k_i), c(0.0)));
    let r = r2.sqrt();
    let f = kernel::dw(pr, r) * r / (r2 + c(pr.kernel.eta2));
    let term = v_j * k_ij * (c(t_i) - t_j) * f;
    which.where_lt(1.5, term, c(0.0))
}

/// `conduct`: explicit Euler, h_i += Δt dh_i/dt (J22 (21)); the laser pass left
/// its source (W/kg) in heat.w.
pub fn conduct(pr: &Params, st: &mut State, grid: &CellTable, list: &NeighborList) {
    let dt = st.sim.dt;
    let laser_on = pr.laser.model != 0;
    let s: &State = st;
    let near = Conductors::new(pr, s);
    let rates: Vec<f32> = (0..s.active())
        .into_par_iter()
        .map(|i| {
            if !pr.conducts(s.phase[i]) || pr.programmed(s.phase[i]) {
                return 0.0;
            }
            rate(
                pr,
                s,
                grid,
                list,
                &near,
                i,
                if laser_on { s.heat[i][H_RATE] } else { 0.0 },
            )
        })
        .collect();
    let phase = &st.phase;
    st.heat[..rates.len()]
        .par_iter_mut()
        .zip(rates)
        .enumerate()
        .for_each(|(i, (hv, rate))| {
            if pr.conducts(phase[i]) && !pr.programmed(phase[i]) {
                hv[H_ENTHALPY] += dt * rate;
                hv[H_RATE] = rate;
            }
        });
}

/// The trapezoidal rule (Crank–Nicolson) of R18 Algorithm 3.1 (its text says
/// "implicit midpoint"; the algorithm it prints is this),
///   h^{n+1} = h^n + Δt/2 (ḣ(T^n) + ḣ(T(h^{n+1}))),
/// solved by fixed-point iteration h^{k+1} = h^n + Δt/2 (ḣ_0 + ḣ_k),
/// ḣ_k = ḣ(T(h^k)), from h^0 = h^n (so the first iterate is the explicit Euler
/// step) until
///   max|h^{k+1} − h^k| / max|h^{k+1} − h^n| = max|ḣ_k − ḣ_{k−1}| / max|ḣ_0 + ḣ_k|
/// is at most the tolerance (over conducting particles; the first iteration
/// counts 1 unless nothing changes). R18 measures |ΔT|/T instead, which in
/// kelvin stops long before a step's own change has converged. Conduction,
/// surface losses and the Dirichlet mirrors follow T(h^k); the laser source and
/// viscous heating are those of the step. T and f_l of h^{n+1} and the phase
/// switches follow in `temperature` after the loop, as for Euler.
///
/// `heat_begin`: heat_start = (h^n, the laser source, 0, 0), the rate in heat.w
/// zeroed (ḣ_{−1}) and the solver reset.
pub fn begin(pr: &Params, st: &mut State) {
    let n = st.active();
    let laser_on = pr.laser.model != 0;
    let phase = &st.phase;
    st.heat_start[..n]
        .par_iter_mut()
        .zip(st.heat[..n].par_iter_mut())
        .enumerate()
        .for_each(|(i, (hs, hv))| {
            *hs = if pr.conducts(phase[i]) {
                let h = [
                    hv[H_ENTHALPY],
                    if laser_on { hv[H_RATE] } else { 0.0 },
                    0.0,
                    0.0,
                ];
                hv[H_RATE] = 0.0;
                h
            } else {
                [0.0; 4]
            };
        });
    let slot = &mut st.solvers[SolverSlot::Heat as usize];
    *slot = slot.reset();
}

/// The heat solver's flag: the loop's twins return at once once it is set.
pub fn heat_converged(st: &State) -> bool {
    st.solvers[SolverSlot::Heat as usize].converged != 0
}

/// `iterate_temperature`: T and f_l of the iterate h^k.
pub fn iterate_temperature(pr: &Params, st: &mut State) {
    if heat_converged(st) {
        return;
    }
    let n = st.active();
    let phase = &st.phase;
    st.heat[..n].par_iter_mut().enumerate().for_each(|(i, hv)| {
        if pr.conducts(phase[i]) {
            let (t, fl) = temperature_of(pr, phase[i], hv[H_ENTHALPY]);
            hv[H_TEMPERATURE] = t;
            hv[H_LIQUID] = fl;
        }
    });
}

/// `iterate_conduct`: ḣ_k (kept as ḣ_0 in heat_start.z on the first
/// iteration), h^{k+1} = h^n + Δt ((ḣ_0 + ḣ_k)/2), and |ḣ_k − ḣ_{k−1}| into
/// heat_start.w (rates, not enthalpies: lavapipe folds (a + b) − a to b).
pub fn iterate_conduct(pr: &Params, st: &mut State, grid: &CellTable, list: &NeighborList) {
    if heat_converged(st) {
        return;
    }
    let dt = st.sim.dt;
    let first = st.solvers[SolverSlot::Heat as usize].iterations == 0;
    let s: &State = st;
    let near = Conductors::new(pr, s);
    let rates: Vec<f32> = (0..s.active())
        .into_par_iter()
        .map(|i| {
            if !pr.conducts(s.phase[i]) {
                return 0.0;
            }
            rate(pr, s, grid, list, &near, i, s.heat_start[i][1])
        })
        .collect();
    let phase = &st.phase;
    st.heat[..rates.len()]
        .par_iter_mut()
        .zip(st.heat_start[..rates.len()].par_iter_mut())
        .zip(rates)
        .enumerate()
        .for_each(|(i, ((hv, hs), rate))| {
            if pr.conducts(phase[i]) {
                if first {
                    hs[2] = rate;
                }
                hs[3] = (rate - hv[H_RATE]).abs();
                hv[H_ENTHALPY] = hs[0] + dt * ((hs[2] + rate) * 0.5);
                hv[H_RATE] = rate;
            }
        });
}

/// `heat_residual` + `heat_residual_final`: max|ḣ_k − ḣ_{k−1}| / max|ḣ_0 + ḣ_k|
/// over conducting particles (max is exact and order-free: the GPU's tree gives
/// the same bits), one more iteration, and the flag.
pub fn residual(pr: &Params, st: &mut State) {
    if heat_converged(st) {
        return;
    }
    let (dmax, smax) = (0..st.active())
        .into_par_iter()
        .filter(|&i| pr.conducts(st.phase[i]))
        .map(|i| {
            (
                st.heat_start[i][3],
                (st.heat_start[i][2] + st.heat[i][H_RATE]).abs(),
            )
        })
        .reduce(|| (0.0f32, 0.0f32), |a, b| (a.0.max(b.0), a.1.max(b.1)));
    let s = &mut st.solvers[SolverSlot::Heat as usize];
    let residual = if smax == 0.0 {
        0.0
    } else if s.iterations == 0 {
        1.0
    } else {
        dmax / smax
    };
    s.finish(
        residual,
        residual <= pr.solve.heat_tolerance,
        pr.solve.heat_max_iterations,
    );
}

/// Heat lost through the free surface per unit mass (W/kg): evaporation F22 (18)
/// with p_v F22 (10), ṁ (h_v + c_p (T − T_h0)), plus radiation ε σ_B (T⁴ − T_a⁴),
/// both per unit area, times the surface delta δ and divided by ρ0.
#[inline(always)]
pub fn surface_loss(pr: &Params, phase: u32, t: f32, delta: f32) -> f32 {
    let m = pr.phase(phase);
    let mut flux = 0.0f32;
    if m.evap_pressure > 0.0 {
        let pv = vapour_pressure(pr, phase, t);
        let mdot = m.recondensation * pv * (m.vapor_constant / t).sqrt();
        flux +=
            mdot * (m.evap_latent_heat + m.liquid_heat_capacity * (t - m.evap_enthalpy_reference));
    }
    if m.emissivity_sb > 0.0 {
        flux += m.emissivity_sb * (t * t * t * t - pr.surfaces.ambient_t4);
    }
    flux * delta / m.rho0
}

/// The vapour's pressure p_v(T) = C_p exp(−C_T (1/T − 1/T_v)), F22 (10): the
/// evaporation loss and the recoil (cpu/surface_forces.rs) both use it. Twin of
/// shaders/lib/vapour.wgsl.
#[inline(always)]
pub fn vapour_pressure(pr: &Params, phase: u32, t: f32) -> f32 {
    let m = pr.phase(phase);
    m.evap_pressure * pm_exp(-(m.evap_temperature * (1.0 / t - m.inv_boiling_temperature)))
}

/// Temperature and liquid fraction of the stored enthalpy h = h(T) − h(T_ref) for
/// a phase: the inverse of `Thermal::enthalpy`. T_ref is the solidus for a melting
/// material: below it T = T_s + h/c_s; in the band h = b x + a x² with
/// x = T − T_s, solved as x = 2h/(b + √(b² + 4ah)) (exact for a = 0, no
/// cancellation); above it T = T_l + (h − h_band)/c_l.
#[inline(always)]
pub fn temperature_of(pr: &Params, phase: u32, h: f32) -> (f32, f32) {
    let m = pr.phase(phase);
    if m.enthalpy_points > 0 {
        return table_temperature_of(pr, phase, h);
    }
    let flags = m.flags;
    if flags & HEAT_MELTS == 0 {
        let fl = if flags & HEAT_LIQUID != 0 { 1.0 } else { 0.0 };
        return (m.reference_temperature + h / m.heat_capacity, fl);
    }
    if h <= 0.0 {
        (m.solidus + h / m.heat_capacity, 0.0)
    } else if h >= m.band_enthalpy {
        (
            m.liquidus + (h - m.band_enthalpy) / m.liquid_heat_capacity,
            1.0,
        )
    } else {
        let b = m.band_capacity;
        let x = 2.0 * h / (b + (b * b + 4.0 * m.capacity_slope * h).sqrt());
        (m.solidus + x, x / (m.liquidus - m.solidus))
    }
}

/// (T, f_l) of the stored enthalpy on the phase's `enthalpy_table` (J22 (19),
/// tabulated): T = T_k + (h − h_k)/s_k on the last segment k whose point h_k
/// the enthalpy reaches (k = 0 below the first, the last segment continued
/// above); f_l = (T − T_s)/(T_l − T_s) clamped to [0, 1] for a melting
/// material (the table holds the latent heat; the band only says how liquid).
#[inline(always)]
fn table_temperature_of(pr: &Params, phase: u32, h: f32) -> (f32, f32) {
    let m = pr.phase(phase);
    let (row, c) = law_segment(&m.enthalpy, m.enthalpy_points, h, |r| r.value);
    let t = row.temperature[c] + (h - row.value[c]) / row.slope[c];
    if m.flags & HEAT_MELTS != 0 {
        let fl = (t - m.solidus) / (m.liquidus - m.solidus);
        // min(max()) as the WGSL twin writes it (clamp differs on NaN).
        #[allow(clippy::manual_clamp)]
        return (t, fl.max(0.0).min(1.0));
    }
    (t, if m.flags & HEAT_LIQUID != 0 { 1.0 } else { 0.0 })
}

/// Conductivity at temperature t and liquid fraction f_l: the phase's
/// `conductivity_table` λ(T), linear between its points and held at its end
/// values; else the solid's plus f_l times the liquid's excess.
#[inline(always)]
pub fn conductivity(pr: &Params, phase: u32, t: f32, fl: f32) -> f32 {
    let m = &pr.phases[phase as usize];
    if pr.flag(FLAG_CONDUCTIVITY_TABLE) && m.conductivity_points > 0 {
        let law = &m.conductivity_law;
        let tt = t.max(law[0].temperature[0]);
        return law_at(law, m.conductivity_points, tt);
    }
    let ks = m.conductivity;
    ks + fl * (m.liquid_conductivity - ks)
}

/// T and f_l from h; then the phase change of F22 §3.2 with a fixed substrate: a
/// solid whose liquid fraction reaches ½ becomes its liquid phase (at rest), a
/// A PHASE_PROGRAM particle (no melting band): the enthalpy of its programmed
/// temperature at the end of the step, h = c (T(t) − T_ref); T and f_l follow
/// from it as for every particle (T to within an ULP of the program).
fn impose_program(pr: &Params, ph: u32, now: f32, hv: &mut [f32; 4]) {
    let p = pr.phase(ph);
    let t = pr.programmed_temperature(ph, now);
    hv[H_ENTHALPY] = p.heat_capacity * (t - p.reference_temperature);
}

/// liquid whose liquid fraction falls below ½ becomes its solid phase, frozen in
/// place (velocity and accelerations zeroed). With rigid bodies, a particle that
/// solidified is marked `BODY_SOLIDIFIED` for `bodies.melt`, which bonds the
/// bodies it touches. With a melting phase, a liquidus crossing on cooling is
/// recorded (`record_crossing`).
pub fn temperature(pr: &Params, st: &mut State) {
    let n = st.active();
    let now = st.sim.step_end();
    let (time, dt) = (st.sim.time, st.sim.dt);
    let trapezoidal = pr.solve.heat_integrator == HEAT_TRAPEZOIDAL;
    let records = pr.flag(FLAG_SOLIDIFICATION);
    let State {
        heat,
        phase,
        vel,
        acc,
        acc_b,
        body,
        id,
        pos,
        heat_start,
        solidification,
        ..
    } = st;
    let bodies = pr.flag(FLAG_BODIES);
    let heat_start: &[[f32; 4]] = heat_start;
    let found: Vec<(usize, Found)> = heat[..n]
        .par_iter_mut()
        .zip(phase[..n].par_iter_mut())
        .zip(
            vel[..n]
                .par_iter_mut()
                .zip(acc[..n].par_iter_mut().zip(acc_b[..n].par_iter_mut())),
        )
        .enumerate()
        .filter_map(|(i, ((hv, ph), (v, (a, ab))))| {
            if !pr.conducts(*ph) {
                return None;
            }
            if pr.programmed(*ph) {
                impose_program(pr, *ph, now, hv);
            }
            let t_prev = hv[H_TEMPERATURE];
            let (t, fl) = temperature_of(pr, *ph, hv[H_ENTHALPY]);
            hv[H_TEMPERATURE] = t;
            hv[H_LIQUID] = fl;
            let mut f = Found::default();
            if records && pr.heat_flags(*ph) & HEAT_MELTS != 0 {
                let t_start = if trapezoidal {
                    temperature_of(pr, *ph, heat_start[i][0]).0
                } else {
                    t_prev
                };
                let t_l = pr.phases[*ph as usize].liquidus;
                if !(t_start < t_l || t >= t_l) {
                    f.crossing = Some(Crossing {
                        time: time + dt * ((t_start - t_l) / (t_start - t)),
                        cooling: -hv[H_RATE] / pr.phases[*ph as usize].liquid_heat_capacity,
                    });
                }
            }
            if let Some(target) = pr.switch_target(*ph) {
                let solid = pr.phases[*ph as usize].kind == KIND_SOLID;
                if solid && fl >= 0.5 {
                    *ph = target;
                } else if !solid && fl < 0.5 {
                    *ph = target;
                    *v = [0.0; 4];
                    *a = [0.0; 4];
                    *ab = [0.0; 4];
                    // Only rigid-body scenes need to know (bodies.melt).
                    f.solidified = bodies;
                }
            }
            (f.solidified || f.crossing.is_some()).then_some((i, f))
        })
        .collect();
    let total = solidification.len() / 2;
    for (i, f) in found {
        let k = id[i] as usize;
        if f.solidified {
            body[k] = BODY_SOLIDIFIED;
        }
        if let Some(c) = f.crossing {
            record_crossing(&mut solidification[k], c);
            let p = pos[i];
            solidification[total + k] = [p[0], p[1], p[2], 1.0];
        }
    }
}

/// What `temperature` found for a particle that changes arrays indexed by id
/// (written after the parallel sweep).
#[derive(Default)]
struct Found {
    /// Solidified in a rigid-body scene: `bodies.melt` bonds what it touches.
    solidified: bool,
    crossing: Option<Crossing>,
}

/// A liquidus crossing on cooling in this step (the solidification
/// record; twin of record_liquidus_crossing in shaders/heat.wgsl): t_start ≥ T_l
/// > T at the step's end, t_start the step's first temperature (the trapezoidal
/// > iterates overwrote heat.y: T(h^n) then). The time is linear in T within the
/// > step, the cooling rate −(dh/dt)/c_l the liquid side's at the step's rate.
struct Crossing {
    time: f32,
    cooling: f32,
}

/// (time, |∇T| pending (−1), cooling rate, crossings + 1).
fn record_crossing(r: &mut [f32; 4], c: Crossing) {
    r[SOL_TIME] = c.time;
    r[SOL_GRADIENT] = -1.0;
    r[SOL_COOLING] = c.cooling;
    r[SOL_COUNT] += 1.0;
}

/// `solidification_gradient`: |∇T| of each particle whose liquidus crossing in
/// this step left it pending, once every temperature of the step is final, by
/// the renormalised gradient (first-order consistent at a free surface too)
///   ∇T_i = M_i⁻¹ Σ_j V_j (T_j − T_i) ∇_iW_ij,  M_i = Σ_j V_j (r_j − r_i) ⊗ ∇_iW_ij,
/// over conducting neighbours and Dirichlet walls (their mirror temperatures),
/// V_j = m_j/ρ_j as in the conduction; 0 where M is near singular (a particle
/// with too few neighbours: a lone droplet).
pub fn solidification_gradient(pr: &Params, st: &mut State, grid: &CellTable) {
    let total = st.solidification.len() / 2;
    let s: &State = st;
    let out: Vec<(usize, f32)> = (0..s.active())
        .into_par_iter()
        .filter_map(|i| {
            let k = s.id[i] as usize;
            if s.solidification[total + k][SOL_PENDING] == 0.0 {
                return None;
            }
            let g = temperature_gradient(pr, s, grid, i);
            Some((k, (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt()))
        })
        .collect();
    for (k, g) in out {
        st.solidification[k][SOL_GRADIENT] = g;
        st.solidification[total + k][SOL_PENDING] = 0.0;
    }
}

fn temperature_gradient(pr: &Params, s: &State, grid: &CellTable, i: usize) -> [f32; 3] {
    let t_i = s.heat[i][H_TEMPERATURE];
    let (mut m, mut b) = ([0.0f32; 6], [0.0f32; 3]);
    for_each_neighbor(pr, &s.pos, grid, i, |j, d, r2| {
        let ph_j = s.phase[j];
        if r2 <= 0.0 || !(pr.conducts(ph_j) || pr.heat_flags(ph_j) & HEAT_DIRICHLET != 0) {
            return;
        }
        let r = r2.sqrt();
        let vf = s.mass[j] / heat_density(pr, &s.rho, ph_j, j) * (kernel::dw(pr, r) / r);
        m[0] -= vf * d[0] * d[0];
        m[1] -= vf * d[0] * d[1];
        m[2] -= vf * d[0] * d[2];
        m[3] -= vf * d[1] * d[1];
        m[4] -= vf * d[1] * d[2];
        m[5] -= vf * d[2] * d[2];
        let db = (s.heat[j][H_TEMPERATURE] - t_i) * vf;
        for a in 0..3 {
            b[a] += db * d[a];
        }
    });
    crate::portable_math::solve_symmetric(pr.sizes.dim, m, b)
}

#[cfg(test)]
mod tests {
    use crate::params::Params;

    /// T(h(T)) = T across the melting band for a material whose liquid heat
    /// capacity differs from the solid's (adiabatic_box: c_s 1000, c_l 1200, band
    /// 340–360 K, L = 5e4 J/kg), and f_l is linear in T in the band.
    #[test]
    fn temperature_inverts_enthalpy_across_the_band() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/validation/adiabatic_box.toml"
        );
        let l = crate::load::load(path, &[]).unwrap();
        let pr = Params::new(&l.model, l.state.len() as u32);
        let hot = l.model.phase_index("hot").unwrap();
        let th = l.model.phases[hot].thermal.unwrap();
        for t in [300.0, 339.0, 341.0, 350.0, 355.5, 359.9, 361.0, 450.0] {
            let h = (th.enthalpy(t) - th.reference_enthalpy()) as f32;
            let (tt, fl) = super::temperature_of(&pr, hot as u32, h);
            assert!((tt as f64 - t).abs() < 1e-4, "T({t}) -> {tt}");
            let expect = ((t - 340.0) / 20.0).clamp(0.0, 1.0);
            assert!((fl as f64 - expect).abs() < 1e-4, "f_l({t}) = {fl}");
        }
    }
}
