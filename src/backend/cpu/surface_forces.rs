//! Twin of shaders/surface_forces.wgsl. `surface_tension`: CSF surface tension
//! with the Marangoni stress, F22 (24), between the liquid and the gas of `Params::tension`:
//!   a_i = f[T_i] (−α_i κ_i δ_i n_i + α'_i δ_i ∇_t T_i) / ρ_i,
//! added to the acceleration of the forces pass, for liquid particles with an
//! interface normal (F22 (19)–(20), the interface pass). Choices F22 leaves open:
//! - Curvature F22 (25), Morris (2000): κ_i = −Σ_j f_j V_j (n_i − n_j)·e_ij W'_ij /
//!   Σ_j f_j V_j W_ij over the pair's particles j that have a normal (j = i
//!   included in the sum below): Morris' restriction to reliable normals. A
//!   normal of the other phase points the other way (F22 (20): outward from its
//!   own phase) and enters negated, so the field is continuous across the
//!   interface.
//! - The force acts on the liquid side only. F22 applies (24) to gas particles
//!   too, but its δ (19) weights each side by ρ_i/(ρ_i + ρ_j): the gas side holds
//!   ρ_g/(ρ_l + ρ_g) of the flux (Remark 3) and at density ratios ≥ 10 falls
//!   mostly below the normal threshold (20), which drops that share. The
//!   interface pass normalises the liquid side's δ to integrate to 1 across a flat
//!   lattice surface (the laser's flux), so the force per unit area is α κ.
//!   Gas particles still get κ (diagnostics) and lend their normals to the
//!   curvature.
//! - α(T) = max(α0 + α0'(T − T_α0), α_min) (F22 (8)); α' = α0' where α is not
//!   clipped and 0 where it is (α is constant there).
//! - ∇T_i = Σ_j V_j (T_j − T_i) W'_ij e_ij over every neighbour with a temperature
//!   (F22 (26): all phases; Dirichlet walls included), ∇_t T = ∇T − (n·∇T) n.
//! - f = F22 (21) ramp from the liquid's solidus over ΔT_s, in heat scenes whose
//!   liquid melts; 1 otherwise.

use super::neighbors::{for_each_neighbor, CellTable};
use crate::kernel;
use crate::params::{Params, FLAG_HEAT, HEAT_DIRICHLET, PHASE_RECOIL};
use crate::state::State;
use crate::state::{
    H_TEMPERATURE, INTERIOR_SHEPARD, S_COLOUR, S_CURVATURE, S_DELTA, S_RAW_CURVATURE, S_SHEPARD,
    S_THIN,
};
use rayon::prelude::*;

/// F22 (21) f[T, T_m, T_m + ΔT_s]; 1 without a ramp. max then min, as the WGSL
/// twin writes it (clamp differs for NaN).
#[inline(always)]
#[allow(clippy::manual_clamp)]
fn ramp(pr: &Params, t: f32) -> f32 {
    let s = &pr.tension;
    if s.inv_ramp_width == 0.0 {
        return 1.0;
    }
    ((t - s.t_melt) * s.inv_ramp_width).max(0.0).min(1.0)
}

/// Temperature of particle j (0 in scenes without heat).
#[inline(always)]
fn temperature(pr: &Params, st: &State, j: usize) -> f32 {
    if pr.flag(FLAG_HEAT) {
        st.heat[j][H_TEMPERATURE]
    } else {
        0.0
    }
}

/// Carries a temperature for ∇T (F22 (26)): conducting, or a Dirichlet wall.
#[inline(always)]
fn has_temperature(pr: &Params, ph: u32) -> bool {
    pr.conducts(ph) || (pr.flag(FLAG_HEAT) && pr.heat_flags(ph) & HEAT_DIRICHLET != 0)
}

#[inline(always)]
fn in_pair(pr: &Params, ph: u32) -> bool {
    ph == pr.tension.liquid || ph == pr.tension.gas
}

/// The free-surface form's tension acts on particles with a normal, but not on
/// those inside the liquid by both measures: a Shepard sum Γ (surface[n + j]
/// [S_SHEPARD]) of a full support and a weak colour gradient, δ below
/// `Surfaces::interior_delta` (|g| h < `INTERIOR_GRADIENT`; 0, skipping none,
/// except on continuity density: `Model::csf_skips_interior`). Particle disorder
/// gives particles inside the liquid normals in random directions (|g| h up to
/// 0.24 at 0.1Δx of disorder, 0.5 at 0.2Δx; a planar surface row reads 1.06),
/// and a force on them breaks the drop (docs/physics.md, free-surface form,
/// "Disorder"). A concave surface (melt between grains, a keyhole) can read a
/// full support with a strong gradient: it keeps its tension (R18's track at
/// Δx = 4 µm lost 417 particles without that exception, 11 with it). Summation
/// density compacts the surface row to a full support, where the rule would
/// silence the tension (R = 10Δx disc: −99%), so it keeps R18's threshold alone.
#[inline(always)]
fn bears_tension(pr: &Params, s: &State, n: usize, j: usize) -> bool {
    let delta = s.surface[j][S_DELTA];
    delta != 0.0
        && (s.surface[n + j][S_SHEPARD] < INTERIOR_SHEPARD || delta >= pr.surfaces.interior_delta)
}

pub fn surface_tension(pr: &Params, st: &mut State, grid: &CellTable) {
    let (n, active) = (st.len(), st.active());
    let heated = pr.flag(FLAG_HEAT);
    let s: &State = st;
    let temperature = |j: usize| temperature(pr, s, j);
    let has_temperature = |ph: u32| has_temperature(pr, ph);
    let volume = |j: usize| {
        let ph = s.phase[j];
        if pr.is_wall(ph) {
            s.mass[j] / pr.phases[ph as usize].rho0
        } else {
            s.mass[j] / s.rho[j]
        }
    };
    // Per particle of the pair: its acceleration (None without a normal) and κ.
    let out: Vec<Option<(Option<[f32; 3]>, f32)>> = (0..active)
        .into_par_iter()
        .map(|i| {
            let ph_i = s.phase[i];
            if !in_pair(pr, ph_i) {
                return None;
            }
            let n_i = s.surface[i];
            if n_i[S_DELTA] == 0.0 {
                return Some((None, 0.0));
            }
            let liquid_i = ph_i == pr.tension.liquid;
            let t_i = temperature(i);
            let (mut num, mut den) = (0.0f32, 0.0f32);
            let mut gt = [0.0f32; 3];
            for_each_neighbor(pr, &s.pos, grid, i, |j, d, r2| {
                let ph_j = s.phase[j];
                let r = r2.sqrt();
                let n_j = s.surface[j];
                if in_pair(pr, ph_j) && n_j[3] != 0.0 {
                    let v_j = s.mass[j] / s.rho[j];
                    let fv = ramp(pr, temperature(j)) * v_j;
                    den += fv * kernel::w(pr, r);
                    if r2 > 0.0 {
                        let sign = if (ph_j == pr.tension.liquid) != liquid_i {
                            -1.0
                        } else {
                            1.0
                        };
                        let nj = [sign * n_j[0], sign * n_j[1], sign * n_j[2]];
                        let dn = (n_i[0] - nj[0]) * d[0]
                            + (n_i[1] - nj[1]) * d[1]
                            + (n_i[2] - nj[2]) * d[2];
                        num += fv * (dn / r) * kernel::dw(pr, r);
                    }
                }
                if heated && r2 > 0.0 && has_temperature(ph_j) {
                    let g = volume(j) * (s.heat[j][H_TEMPERATURE] - t_i) * kernel::dw(pr, r) / r;
                    for a in 0..3 {
                        gt[a] += g * d[a];
                    }
                }
            });
            let kappa = if den > 0.0 { -(num / den) } else { 0.0 };
            if !liquid_i {
                return Some((None, kappa));
            }
            Some((Some(force(pr, n_i, t_i, kappa, gt, s.rho[i])), kappa))
        })
        .collect();
    add_forces(st, n, out);
}

/// R18 (3.28)–(3.29), the free-surface form's raw curvature (first of its two
/// dispatches): Morris' κ_i = −Σ_j f_j V_j δ_j (n_i − n_j)·e_ij W'_ij /
/// Σ_j f_j V_j δ_j W_ij over the liquid's particles j with a normal that
/// `bears_tension` keeps, for such particles i (j = i in the
/// denominator), V = m/ρ0 (the interface pass's volume: summation density is short
/// at a free surface), f = F22 (21)'s ramp as in the gas form; capped at
/// |κ| ≤ 1/support (R18's κ_max = 1/(2h) for Wendland, whose support is 2h; both
/// signs: a concave corner is as unreliable as a convex one). To surface[n + i].z.
/// The weight δ_j (the surface measure: Σ V δ g ≈ ∫ g dA) is ours, not R18's: the
/// Shepard-corrected gradient also gives a normal to the row under the surface,
/// whose gradient barely passes the threshold and whose direction is noise; with
/// R18's 0/1 mask those rows reached the cap within 0.01 s on the free disc and
/// their κ spread into the surface row through the smoothing (Laplace jump at
/// R = 20Δx +459% with the mask, +285% with δ; +206% and +211% at 10Δx: neither
/// is right, see laplace_free_disc_2d in docs/validation.md).
pub fn tension_curvature(pr: &Params, st: &mut State, grid: &CellTable) {
    let (n, active) = (st.len(), st.active());
    let s: &State = st;
    let liquid = pr.tension.liquid;
    let weight = |j: usize| {
        ramp(pr, temperature(pr, s, j))
            * (s.mass[j] / pr.phase(liquid).rho0)
            * s.surface[j][S_DELTA]
    };
    let kmax = pr.tension.kappa_max;
    let thin_depth = pr.tension.thin_layer_depth;
    let kappa: Vec<(f32, bool)> = (0..active)
        .into_par_iter()
        .map(|i| {
            let n_i = s.surface[i];
            if s.phase[i] != liquid || !bears_tension(pr, s, n, i) {
                return (0.0, false);
            }
            let (mut num, mut den) = (0.0f32, 0.0f32);
            let mut deep = false;
            for_each_neighbor(pr, &s.pos, grid, i, |j, d, r2| {
                let n_j = s.surface[j];
                if s.phase[j] == liquid
                    && d[0] * n_i[0] + d[1] * n_i[1] + d[2] * n_i[2] >= thin_depth
                {
                    deep = true;
                }
                if s.phase[j] != liquid || !bears_tension(pr, s, n, j) {
                    return;
                }
                let r = r2.sqrt();
                let fv = weight(j);
                den += fv * kernel::w(pr, r);
                if r2 > 0.0 {
                    let dn = (n_i[0] - n_j[0]) * d[0]
                        + (n_i[1] - n_j[1]) * d[1]
                        + (n_i[2] - n_j[2]) * d[2];
                    num += fv * (dn / r) * kernel::dw(pr, r);
                }
            });
            let k = if den > 0.0 { -(num / den) } else { 0.0 };
            (k.max(-kmax).min(kmax), thin_depth > 0.0 && !deep)
        })
        .collect();
    for (i, (k, thin)) in kappa.into_iter().enumerate() {
        st.surface[n + i][S_RAW_CURVATURE] = k;
        if thin {
            st.surface[n + i][S_THIN] = 1.0;
        }
    }
}

/// The free-surface form's force (second dispatch): the raw curvature smoothed,
/// R18 (3.30), κ_i = Σ_j f_j V_j δ_j κ_j W_ij / Σ_j f_j V_j δ_j W_ij over the same
/// neighbours and weights (to surface[n + i].y); the temperature gradient Shepard-corrected,
/// R18 (3.34) (garbled as printed) read as ∇T_i = Σ_j V_j (T_j − T_i) W'_ij e_ij
/// / Σ_j V_j W_ij over the neighbours with a temperature (the missing outside
/// would bias the plain sum at the surface); then F22 (24)'s force, as in the gas
/// form, a_i = f[T_i] δ_i (α'_i ∇_t T_i − α_i κ_i n_i)/ρ0 (R18 (3.31), (3.35)).
pub fn tension_smooth(pr: &Params, st: &mut State, grid: &CellTable) {
    let (n, active) = (st.len(), st.active());
    let heated = pr.flag(FLAG_HEAT);
    let s: &State = st;
    let liquid = pr.tension.liquid;
    let rho0 = pr.phase(liquid).rho0;
    let temperature = |j: usize| temperature(pr, s, j);
    let has_temperature = |ph: u32| has_temperature(pr, ph);
    let volume = |j: usize| s.mass[j] / pr.phase(s.phase[j]).rho0;
    let out: Vec<Option<([f32; 3], f32, bool)>> = (0..active)
        .into_par_iter()
        .map(|i| {
            let n_i = s.surface[i];
            if s.phase[i] != liquid || !bears_tension(pr, s, n, i) {
                return None;
            }
            let t_i = temperature(i);
            let (mut num, mut den, mut shepard) = (0.0f32, 0.0f32, 0.0f32);
            let mut gt = [0.0f32; 3];
            for_each_neighbor(pr, &s.pos, grid, i, |j, d, r2| {
                let ph_j = s.phase[j];
                let r = r2.sqrt();
                let w = kernel::w(pr, r);
                if ph_j == liquid && bears_tension(pr, s, n, j) {
                    let fv = ramp(pr, temperature(j)) * volume(j) * s.surface[j][S_DELTA];
                    den += fv * w;
                    num += fv * s.surface[n + j][S_RAW_CURVATURE] * w;
                }
                if heated && has_temperature(ph_j) {
                    shepard += volume(j) * w;
                    if r2 > 0.0 {
                        let g =
                            volume(j) * (s.heat[j][H_TEMPERATURE] - t_i) * kernel::dw(pr, r) / r;
                        for a in 0..3 {
                            gt[a] += g * d[a];
                        }
                    }
                }
            });
            let kappa = if den > 0.0 { num / den } else { 0.0 };
            if shepard > 0.0 {
                gt = [gt[0] / shepard, gt[1] / shepard, gt[2] / shepard];
            }
            // R18 §4.4: none on a layer of thin_layer_rows particles or fewer.
            let thin = s.surface[n + i][S_THIN] != 0.0;
            let a = if thin {
                [0.0; 3]
            } else {
                force(pr, n_i, t_i, kappa, gt, rho0)
            };
            Some((a, kappa, thin))
        })
        .collect();
    for (i, o) in out.into_iter().enumerate() {
        let Some((a, kappa, thin)) = o else { continue };
        if !thin {
            for c in 0..3 {
                st.acc[i][c] += a[c];
            }
        }
        st.surface[n + i][S_CURVATURE] = kappa;
    }
}

/// J22 (5), the first dispatch of `model = "muller"`: the colour
/// c_i = Σ_j (m_j/ρ_j) W_ij over the liquid's particles, j = i included, to
/// surface[n + i][S_COLOUR]. J22 sums "over j" and its only phase is the droplet;
/// here the liquid alone, so a wall under the drop does not read as more liquid.
/// ρ_j is the state's density as printed: on summation density a surface
/// particle's short ρ_j lengthens its volume, and c stays nearer 1 than
/// Γ = Σ m_j/ρ0 W_ij would.
pub fn tension_colour(pr: &Params, st: &mut State, grid: &CellTable) {
    let (n, active) = (st.len(), st.active());
    let s: &State = st;
    let liquid = pr.tension.liquid;
    let colour: Vec<Option<f32>> = (0..active)
        .into_par_iter()
        .map(|i| {
            if s.phase[i] != liquid {
                return None;
            }
            let mut c = 0.0f32;
            for_each_neighbor(pr, &s.pos, grid, i, |j, _d, r2| {
                if s.phase[j] == liquid {
                    c += s.mass[j] / s.rho[j] * kernel::w(pr, r2.sqrt());
                }
            });
            Some(c)
        })
        .collect();
    for (i, c) in colour.into_iter().enumerate() {
        if let Some(c) = c {
            st.surface[n + i][S_COLOUR] = c;
        }
    }
}

/// J22 (6)–(8) after Müller et al. 2003, the second dispatch: over the liquid's
/// neighbours j ≠ i, with V_j = m_j/ρ_j,
///   n_i = Σ_j V_j (c_j − c_i) ∇_i W_ij                        (6)
///   ∇²c_i = −Σ_j V_j (c_i − c_j) 2 |∇_i W_ij| / (r_ij + ε)      (7)
///   a_i = −σ ∇²c_i n_i / (|n_i| ρ_i)                            (8) and (3)
/// where |n_i| > 0.1/h, the interface pass's threshold (J22 prints none; without
/// one the bulk's noise gradient sets a direction). ε = 0.01 h (J22: unstated;
/// pairs closer than h/10 do not occur at rest). n = ∇c points into the liquid,
/// so with κ = −∇²c/|n| (to surface[n + i][S_CURVATURE]) the force is σ κ n/ρ:
/// inward where κ > 0, CSF's sign. σ is the constant coefficient times F22 (21)'s
/// ramp where the liquid melts. At a free surface the colour only falls to
/// about ½ and the outer row's Laplacian is one-sided: see docs/physics.md for
/// what the Laplace disc measures.
pub fn tension_laplacian(pr: &Params, st: &mut State, grid: &CellTable) {
    let (n, active) = (st.len(), st.active());
    let s: &State = st;
    let liquid = pr.tension.liquid;
    let eps = pr.kernel.h * pr.consts.tenth * pr.consts.tenth;
    // Per liquid particle: its acceleration (None below the threshold: the
    // GPU twin adds nothing there, so −0.0 stays −0.0) and κ.
    let out: Vec<Option<(Option<[f32; 3]>, f32)>> = (0..active)
        .into_par_iter()
        .map(|i| {
            if s.phase[i] != liquid {
                return None;
            }
            let c_i = s.surface[n + i][S_COLOUR];
            let mut g = [0.0f32; 3];
            let mut lap = 0.0f32;
            for_each_neighbor(pr, &s.pos, grid, i, |j, d, r2| {
                if r2 <= 0.0 || s.phase[j] != liquid {
                    return;
                }
                let r = r2.sqrt();
                let v_j = s.mass[j] / s.rho[j];
                let dc = s.surface[n + j][S_COLOUR] - c_i;
                let dw = kernel::dw(pr, r);
                let f = v_j * dc * dw / r;
                for a in 0..3 {
                    g[a] += f * d[a];
                }
                lap += v_j * dc * pr.consts.two * dw.abs() / (r + eps);
            });
            let gl = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            if gl <= pr.consts.tenth * pr.kernel.inv_h {
                return Some((None, 0.0));
            }
            let kappa = -(lap / gl);
            let t_i = temperature(pr, s, i);
            let scale = pr.tension.alpha0 * ramp(pr, t_i) * kappa / s.rho[i];
            Some((Some([scale * g[0], scale * g[1], scale * g[2]]), kappa))
        })
        .collect();
    add_forces(st, n, out);
}

/// Per particle of a tension dispatch: its acceleration added (none where
/// the GPU twin adds nothing, so −0.0 stays −0.0) and its curvature stored.
fn add_forces(st: &mut State, n: usize, out: Vec<Option<(Option<[f32; 3]>, f32)>>) {
    for (i, o) in out.into_iter().enumerate() {
        let Some((a, kappa)) = o else { continue };
        if let Some(a) = a {
            for c in 0..3 {
                st.acc[i][c] += a[c];
            }
        }
        st.surface[n + i][S_CURVATURE] = kappa;
    }
}

/// F22 (24) per unit mass on a liquid particle with normal and δ `n_i`,
/// temperature `t_i`, curvature κ and temperature gradient ∇T:
/// f[T_i] δ (α' ∇_t T − α κ n)/ρ, α(T) and α' from F22 (8) with R18 (4.2)'s
/// solute term (`Params::tension_law`; α' = 0 where clipped).
#[inline(always)]
fn force(pr: &Params, n_i: [f32; 4], t_i: f32, kappa: f32, gt: [f32; 3], rho: f32) -> [f32; 3] {
    let (alpha, slope) = pr.tension_law(t_i);
    let nt = n_i[0] * gt[0] + n_i[1] * gt[1] + n_i[2] * gt[2];
    let tan = [
        gt[0] - nt * n_i[0],
        gt[1] - nt * n_i[1],
        gt[2] - nt * n_i[2],
    ];
    let scale = ramp(pr, t_i) * n_i[S_DELTA] / rho;
    let normal = alpha * kappa;
    [
        scale * (slope * tan[0] - normal * n_i[0]),
        scale * (slope * tan[1] - normal * n_i[1]),
        scale * (slope * tan[2] - normal * n_i[2]),
    ]
}

/// F22 (30) recoil: the vapour's pressure p_v(T) (F22 (10), the law of the
/// evaporation loss, `heat::vapour_pressure`) pushes a liquid particle at the
/// surface inward, a −= p_v δ n / ρ0 (F = −V p_v n δ), for phases with
/// PHASE_RECOIL and a normal. V = m/ρ0, the lattice volume the interface pass
/// normalises δ with (as the evaporation loss and the laser do): F22's m/ρ_i
/// takes the summation density, which a free surface without gas leaves ~20%
/// short, and the recoil impulse then came out 21% high (recoil_layer_2d).
pub fn recoil(pr: &Params, st: &mut State) {
    let n = st.active();
    let State {
        acc,
        phase,
        surface,
        heat,
        ..
    } = st;
    acc[..n].par_iter_mut().enumerate().for_each(|(i, a)| {
        let ph = phase[i];
        if pr.phase(ph).flags & PHASE_RECOIL == 0 {
            return;
        }
        let s = surface[i];
        if s[3] == 0.0 {
            return;
        }
        let f =
            super::heat::vapour_pressure(pr, ph, heat[i][H_TEMPERATURE]) * s[3] / pr.phase(ph).rho0;
        for c in 0..3 {
            a[c] -= f * s[c];
        }
    });
}
