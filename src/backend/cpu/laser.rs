//! Twin of shaders/laser.wgsl: Beer–Lambert laser absorption with column binning
//! (R18 §3.2.2, (3.40)–(3.42)), beam down the last axis.
//!
//! 1. bins: every bin (a cube of side Δx on the domain lattice) gathers the
//!    cloud-in-cell weighted volume of the absorbing particles (liquid, solid)
//!    around it, Σ w V, w = Π_a max(0, 1 − |x_a − c_a|/Δx), V = m/ρ0.
//! 2. columns: per column, top down, the beam power entering the column
//!    I = ζ P(t) s0 exp(−2 d²/r_w²) Δx^(d−1) (F22 (17) / R18 (3.42) Gaussian, d
//!    the lateral distance to the beam centre) loses the fraction
//!    1 − exp(−a Δx V_f) in each bin, V_f = Σ wV/Δx^d its filled fraction; the bin
//!    keeps that power. Written this way the column total telescopes to
//!    I (1 − exp(−a Σ Δx V_f)): no energy appears or vanishes in the binning.
//! 3. deposit: each absorbing particle takes from its neighbouring bins the share
//!    wV/Σ wV of their power, as a source q = P/m (W/kg) in heat.w for the
//!    conduction pass.
//! Portable exp (src/portable_math.rs) keeps it bit-identical to the GPU.
//!
//! surface (the other model, F22 (17)): every liquid or solid particle takes
//! q = ζ ⟨−n·e_l⟩ s_l(x) δ / ρ0 (W/kg) with the interface pass's outward normal n
//! and surface delta δ, e_l = −e_up, s_l = P s0 exp(−2 d²/r_w²).

use super::neighbors::{for_each_near, min_image, CellTable};
use crate::params::{Params, KIND_GAS};
use crate::portable_math::exp as pm_exp;
use crate::state::State;
use crate::state::{H_RATE, S_DELTA};
use rayon::prelude::*;

/// Liquid and solid particles absorb; gas is transparent, walls take no heat.
#[inline(always)]
pub fn absorbs(pr: &Params, phase: u32) -> bool {
    pr.conducts(phase) && pr.phases[phase as usize].kind != KIND_GAS
}

#[inline(always)]
fn bin_centre(pr: &Params, k: [u32; 3]) -> [f32; 4] {
    let (lo, dx) = (pr.laser.lo, pr.laser.bin_size);
    [
        lo[0] + (k[0] as f32 + 0.5) * dx,
        lo[1] + (k[1] as f32 + 0.5) * dx,
        lo[2] + (k[2] as f32 + 0.5) * dx,
        0.0,
    ]
}

/// Cloud-in-cell weight of a particle offset d from a bin centre.
#[inline(always)]
fn cic(pr: &Params, d: [f32; 3]) -> f32 {
    let dx = pr.laser.bin_size;
    let mut w = 1.0f32;
    for a in 0..pr.sizes.dim as usize {
        w *= (1.0 - d[a].abs() / dx).max(0.0);
    }
    w
}

fn bin_index(pr: &Params, b: usize) -> [u32; 3] {
    let nb = pr.laser.bins;
    let b = b as u32;
    [b % nb[0], (b / nb[0]) % nb[1], b / (nb[0] * nb[1])]
}

pub fn n_bins(pr: &Params) -> usize {
    let nb = pr.laser.bins;
    (nb[0] * nb[1] * nb[2]) as usize
}

pub fn bins(pr: &Params, st: &State, grid: &CellTable, bins: &mut Vec<[f32; 2]>) {
    let (pos, mass, phase) = (&st.pos, &st.mass, &st.phase);
    *bins = (0..n_bins(pr))
        .into_par_iter()
        .map(|b| {
            let c = bin_centre(pr, bin_index(pr, b));
            let mut sum = 0.0f32;
            for_each_near(pr, pos, grid, c, |j, d, _| {
                if absorbs(pr, phase[j]) {
                    let v = mass[j] / pr.phases[phase[j] as usize].rho0;
                    sum += cic(pr, d) * v;
                }
            });
            [sum, 0.0]
        })
        .collect();
}

/// Beam centre (lateral, grid-relative) at time t: linear along the path.
#[inline(always)]
pub fn beam_centre(pr: &Params, t: f32) -> [f32; 2] {
    let n = pr.laser.path_points as usize;
    let path = &pr.laser.path;
    if t <= path[0].time {
        return [path[0].x, path[0].y];
    }
    for k in 1..n {
        if t < path[k].time {
            let (p0, p1) = (path[k - 1], path[k]);
            let f = (t - p0.time) / (p1.time - p0.time);
            return [p0.x + f * (p1.x - p0.x), p0.y + f * (p1.y - p0.y)];
        }
    }
    [path[n - 1].x, path[n - 1].y]
}

/// Beam power at time t: each step held from its time on, off before the first.
#[inline(always)]
pub fn beam_power(pr: &Params, t: f32) -> f32 {
    let n = pr.laser.power_steps as usize;
    let mut p = 0.0f32;
    for k in 0..n {
        if pr.laser.power[k].time <= t {
            p = pr.laser.power[k].power;
        }
    }
    p
}

/// ζ s_l at point p: ζ P s0 exp(−2 d²/r_w²), d the lateral distance from the beam
/// centre (F22 (17), R18 (3.42)); both laser models share it.
#[inline(always)]
fn irradiance(pr: &Params, p: &[f32; 4], centre: [f32; 2], power: f32) -> f32 {
    let d0 = p[0] - centre[0];
    let d1 = if pr.sizes.dim == 3 {
        p[1] - centre[1]
    } else {
        0.0
    };
    let r2 = d0 * d0 + d1 * d1;
    let (zeta, rw) = (pr.laser.absorptivity, pr.laser.radius);
    zeta * power * pr.laser.peak_per_watt * pm_exp(-(2.0 * r2 / (rw * rw)))
}

/// Store each conducting particle's laser source q (W/kg) in heat.w.
/// The source of the first q.len() particles (the ones still in the simulation).
fn write_source(pr: &Params, st: &mut State, q: &[f32]) {
    let phase = &st.phase;
    for (i, hv) in st.heat[..q.len()].iter_mut().enumerate() {
        if pr.conducts(phase[i]) {
            hv[H_RATE] = q[i];
        }
    }
}

pub fn columns(pr: &Params, t: f32, bins: &mut [[f32; 2]]) {
    let nb = pr.laser.bins;
    let dim = pr.sizes.dim as usize;
    let (nx, ny) = (nb[0] as usize, nb[1] as usize);
    let (n_cols, depth) = if dim == 3 {
        (nx * ny, nb[2] as usize)
    } else {
        (nx, ny)
    };
    let stride = if dim == 3 { nx * ny } else { nx };
    let centre = beam_centre(pr, t);
    let power = beam_power(pr, t);
    let a = pr.laser.absorption;
    let l = &pr.laser;
    let (dx, vbin, area) = (l.bin_size, l.bin_volume, l.column_area);
    let out: Vec<Vec<(usize, f32)>> = (0..n_cols)
        .into_par_iter()
        .map(|c| {
            let top = bin_centre(
                pr,
                [
                    (c % nx) as u32,
                    if dim == 3 { (c / nx) as u32 } else { 0 },
                    0,
                ],
            );
            let mut i = irradiance(pr, &top, centre, power) * area;
            let mut col = Vec::with_capacity(depth);
            for k in (0..depth).rev() {
                let b = c + k * stride;
                let vf = bins[b][0] / vbin;
                let trans = pm_exp(-(a * dx * vf));
                col.push((b, i * (1.0 - trans)));
                i *= trans;
            }
            col
        })
        .collect();
    for (b, p) in out.into_iter().flatten() {
        bins[b][1] = p;
    }
}

pub fn deposit(pr: &Params, st: &mut State, bins: &[[f32; 2]]) {
    let (pos, mass, phase) = (&st.pos, &st.mass, &st.phase);
    let nb = pr.laser.bins;
    let dim = pr.sizes.dim as usize;
    let dx = pr.laser.bin_size;
    let q: Vec<f32> = (0..st.active())
        .into_par_iter()
        .map(|i| {
            if !absorbs(pr, phase[i]) {
                return 0.0;
            }
            let p = pos[i];
            let v = mass[i] / pr.phases[phase[i] as usize].rho0;
            let mut k = [0i32; 3];
            for a in 0..3 {
                let f = ((p[a] - pr.laser.lo[a]) / dx).floor();
                k[a] = (f as i32).clamp(0, nb[a] as i32 - 1);
            }
            let zr = if dim == 3 { 1 } else { 0 };
            let mut sum = 0.0f32;
            for oz in -zr..=zr {
                for oy in -1..=1 {
                    for ox in -1..=1 {
                        let Some(idx) = bin_at(pr, [k[0] + ox, k[1] + oy, k[2] + oz]) else {
                            continue;
                        };
                        let b = (idx[0] + nb[0] * (idx[1] + nb[1] * idx[2])) as usize;
                        let w = cic(pr, min_image(pr, p, bin_centre(pr, idx)));
                        if w > 0.0 && bins[b][0] > 0.0 {
                            sum += bins[b][1] * (w * v) / bins[b][0];
                        }
                    }
                }
            }
            sum / mass[i]
        })
        .collect();
    write_source(pr, st, &q);
}

/// Bin coordinates wrapped on periodic axes; None outside the grid.
#[inline(always)]
fn bin_at(pr: &Params, k: [i32; 3]) -> Option<[u32; 3]> {
    let mut out = [0u32; 3];
    for a in 0..3 {
        let n = pr.laser.bins[a] as i32;
        out[a] = if k[a] >= 0 && k[a] < n {
            k[a] as u32
        } else if pr.sizes.flags & (1 << a) != 0 {
            ((k[a] + n) % n) as u32
        } else {
            return None;
        };
    }
    Some(out)
}

pub fn surface(pr: &Params, st: &mut State) {
    let n = st.active();
    let up = pr.sizes.dim as usize - 1;
    let centre = beam_centre(pr, st.sim.time);
    let power = beam_power(pr, st.sim.time);
    let (pos, phase, surf) = (&st.pos, &st.phase, &st.surface);
    let q: Vec<f32> = (0..n)
        .into_par_iter()
        .map(|i| {
            if !absorbs(pr, phase[i]) {
                return 0.0;
            }
            let cos = surf[i][up].max(0.0);
            irradiance(pr, &pos[i], centre, power) * cos * surf[i][S_DELTA]
                / pr.phases[phase[i] as usize].rho0
        })
        .collect();
    write_source(pr, st, &q);
}
