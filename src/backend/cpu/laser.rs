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
//!
//! Portable exp (src/portable_math.rs) keeps it bit-identical to the GPU.
//!
//! ray_traced: bins as above (with the volume-weighted optical constants
//! Σ wV n, Σ wV k), then
//! 1. rays: the beam as a square (3D) or line (2D) of rays spaced Δx/rays_per_dx
//!    around its centre, each carrying P g / Σ g (g the profile at the ray) as a
//!    u32 count of `power_unit`s, down the last axis from the top of the bin box.
//!    A ray marches in steps of Δx/4 through the filled fraction V_f,
//!    interpolated (bi/trilinear) between bin centres, until V_f ≥ ½: the
//!    surface. Four bisections place the hit; the outward normal is −∇V_f/|∇V_f|
//!    there, ∇V_f by central differences at the bin centres, interpolated (the
//!    interpolant's own gradient zig-zags along a staircase of particles). The bin of the largest V_f among the eight (four) around the hit
//!    takes A(θ) of the ray's power, A the Fresnel absorptivity of its
//!    volume-weighted (n, k) at the angle θ between the ray and the normal
//!    (`fresnel`); the rest reflects specularly from the last point outside and
//!    marches on, until it leaves the bin box, or its power is spent, or it has
//!    made `max_bounces` hits (then the last hit takes all it still carries).
//!    Counts are integers, so a bin's sum is the same in any thread order, and
//!    incident = absorbed + leaving exactly (`State::laser_rays`).
//! 2. ray_bins: each bin's count becomes its power, count × power_unit;
//! 3. deposit as above.
//!
//! surface (the other model, F22 (17)): every liquid or solid particle takes
//! q = ζ ⟨−n·e_l⟩ s_l(x) δ / ρ0 (W/kg) with the interface pass's outward normal n
//! and surface delta δ, e_l = −e_up, s_l = P s0 exp(−2 d²/r_w²).

use super::neighbors::{for_each_near, min_image, CellTable};
use crate::params::{Params, KIND_GAS, LASER_RAY_TRACED, PROFILE_GAUSSIAN};
use crate::portable_math::exp as pm_exp;
use crate::state::State;
use crate::state::{H_RATE, RAYS_ABSORBED, RAYS_AT_LIMIT, RAYS_INCIDENT, RAYS_LEAVING, S_DELTA};
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

pub fn bins(pr: &Params, st: &State, grid: &CellTable, bins: &mut Vec<[f32; 4]>) {
    let (pos, mass, phase) = (&st.pos, &st.mass, &st.phase);
    let traced = pr.laser.model == LASER_RAY_TRACED;
    *bins = (0..n_bins(pr))
        .into_par_iter()
        .map(|b| {
            let c = bin_centre(pr, bin_index(pr, b));
            let (mut sum, mut sn, mut sk) = (0.0f32, 0.0f32, 0.0f32);
            for_each_near(pr, pos, grid, c, |j, d, _| {
                if absorbs(pr, phase[j]) {
                    let ph = &pr.phases[phase[j] as usize];
                    let v = mass[j] / ph.rho0;
                    let wv = cic(pr, d) * v;
                    sum += wv;
                    if traced {
                        sn += wv * ph.optical_n;
                        sk += wv * ph.optical_k;
                    }
                }
            });
            [sum, 0.0, sn, sk]
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

pub fn columns(pr: &Params, t: f32, bins: &mut [[f32; 4]]) {
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

pub fn deposit(pr: &Params, st: &mut State, bins: &[[f32; 4]]) {
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

/// Filled fraction V_f of bin k (wrapped on periodic axes; 0 outside the box).
#[inline(always)]
fn fill(pr: &Params, bins: &[[f32; 4]], k: [i32; 3]) -> (f32, usize) {
    match bin_at(pr, k) {
        Some(idx) => {
            let nb = pr.laser.bins;
            let b = (idx[0] + nb[0] * (idx[1] + nb[1] * idx[2])) as usize;
            (bins[b][0] / pr.laser.bin_volume, b)
        }
        None => (0.0, usize::MAX),
    }
}

/// The interpolation cell of x: the lower corner's bin coordinates and the
/// fractions along each axis (axes past the dimension: 0 and 0).
#[inline(always)]
fn cell_of(pr: &Params, x: [f32; 3]) -> ([i32; 3], [f32; 3]) {
    let dx = pr.laser.bin_size;
    let mut k = [0i32; 3];
    let mut f = [0.0f32; 3];
    for a in 0..pr.sizes.dim as usize {
        let u = (x[a] - pr.laser.lo[a]) / dx - 0.5;
        let fl = u.floor();
        k[a] = fl as i32;
        f[a] = u - fl;
    }
    (k, f)
}

/// Weight of corner c (bits 0, 1, 2 for x, y, z) in the interpolation.
#[inline(always)]
fn corner_weight(pr: &Params, f: [f32; 3], c: u32) -> f32 {
    let w = |a: usize| if c >> a & 1 == 1 { f[a] } else { 1.0 - f[a] };
    let wz = if pr.sizes.dim == 3 { w(2) } else { 1.0 };
    w(0) * w(1) * wz
}

#[inline(always)]
fn corners(pr: &Params) -> u32 {
    if pr.sizes.dim == 3 {
        8
    } else {
        4
    }
}

#[inline(always)]
fn corner(k: [i32; 3], c: u32) -> [i32; 3] {
    [
        k[0] + (c & 1) as i32,
        k[1] + (c >> 1 & 1) as i32,
        k[2] + (c >> 2 & 1) as i32,
    ]
}

/// V_f at x, interpolated between bin centres (trilinear; bilinear in 2D).
fn value(pr: &Params, bins: &[[f32; 4]], x: [f32; 3]) -> f32 {
    let (k, f) = cell_of(pr, x);
    let mut v = 0.0f32;
    for c in 0..corners(pr) {
        v += corner_weight(pr, f, c) * fill(pr, bins, corner(k, c)).0;
    }
    v
}

/// At a hit x: ∇V_f (up to a positive factor: central differences at the
/// corners, interpolated; a staircase of particles at 45° gives the plane's
/// normal exactly) and the bin of the largest corner value (the first on ties).
fn surface_at(pr: &Params, bins: &[[f32; 4]], x: [f32; 3]) -> ([f32; 3], usize) {
    let (k, f) = cell_of(pr, x);
    let dim = pr.sizes.dim as usize;
    let mut g = [0.0f32; 3];
    let (mut best_v, mut best) = (0.0f32, usize::MAX);
    for c in 0..corners(pr) {
        let kc = corner(k, c);
        let (vc, b) = fill(pr, bins, kc);
        if vc > best_v {
            best_v = vc;
            best = b;
        }
        let w = corner_weight(pr, f, c);
        for a in 0..dim {
            let (mut hi, mut lo) = (kc, kc);
            hi[a] += 1;
            lo[a] -= 1;
            let d = fill(pr, bins, hi).0 - fill(pr, bins, lo).0;
            g[a] += w * d;
        }
    }
    (g, best)
}

/// Fresnel absorptivity 1 − (R_s + R_p)/2 for unpolarised light, complex index
/// n + ik, incidence cosine c (model::laser::fresnel_absorptivity in f32).
#[inline(always)]
pub fn fresnel(n: f32, k: f32, cos: f32) -> f32 {
    let c = cos.clamp(1e-6, 1.0);
    let s2 = 1.0 - c * c;
    // (n² − s²) − k², in this order: lavapipe reassociates n² − k² − s²
    let a_ = (n * n - s2) - k * k;
    let b_ = (a_ * a_ + 4.0 * (n * n) * (k * k)).sqrt();
    let a = (0.5 * (b_ + a_)).sqrt();
    let b2 = 0.5 * (b_ - a_);
    let rs = ((a - c) * (a - c) + b2) / ((a + c) * (a + c) + b2);
    let st = s2 / c;
    let rp = rs * (((a - st) * (a - st) + b2) / ((a + st) * (a + st) + b2));
    1.0 - 0.5 * (rs + rp)
}

/// x on the bin box: wrapped on periodic axes; None once it has left the box.
#[inline(always)]
fn in_box(pr: &Params, mut x: [f32; 3]) -> Option<[f32; 3]> {
    for a in 0..pr.sizes.dim as usize {
        let lo = pr.laser.lo[a];
        let len = pr.laser.bins[a] as f32 * pr.laser.bin_size;
        if x[a] < lo || x[a] > lo + len {
            if pr.sizes.flags & (1 << a) == 0 {
                return None;
            }
            x[a] = if x[a] < lo { x[a] + len } else { x[a] - len };
        }
    }
    Some(x)
}

#[inline(always)]
fn along(x: [f32; 3], d: [f32; 3], s: f32) -> [f32; 3] {
    [x[0] + d[0] * s, x[1] + d[1] * s, x[2] + d[2] * s]
}

/// x − d s.
#[inline(always)]
fn back(x: [f32; 3], d: [f32; 3], s: f32) -> [f32; 3] {
    [x[0] - d[0] * s, x[1] - d[1] * s, x[2] - d[2] * s]
}

/// One ray's fate: its deposits (bin, count) and its incident, leaving and
/// bounce-limit counts.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct RayPath {
    pub deposits: Vec<(usize, u32)>,
    pub incident: u32,
    pub leaving: u32,
    pub at_limit: u32,
}

/// Ray r of the bundle at beam centre `centre` and power `power`.
pub fn trace(pr: &Params, bins: &[[f32; 4]], r: u32, centre: [f32; 2], power: f32) -> RayPath {
    let l = &pr.laser;
    let dim = pr.sizes.dim as usize;
    let up = dim - 1;
    let n = l.rays_per_side;
    let half = (n / 2) as i32;
    let ox = ((r % n) as i32 - half) as f32 * l.ray_spacing;
    let oy = if dim == 3 {
        ((r / n) as i32 - half) as f32 * l.ray_spacing
    } else {
        0.0
    };
    let r2 = ox * ox + oy * oy;
    let rw = l.radius;
    let g = if l.profile == PROFILE_GAUSSIAN {
        pm_exp(-(2.0 * r2 / (rw * rw)))
    } else if r2 <= rw * rw {
        1.0
    } else {
        0.0
    };
    let q0 = (power * g * l.ray_norm / l.power_unit + 0.5).floor() as u32;
    let mut out = RayPath {
        incident: q0,
        ..Default::default()
    };
    let mut q = q0;
    if q == 0 {
        return out;
    }
    let mut x = [0.0f32; 3];
    let mut d = [0.0f32; 3];
    x[0] = centre[0] + ox;
    if dim == 3 {
        x[1] = centre[1] + oy;
    }
    x[up] = l.lo[up] + l.bins[up] as f32 * l.bin_size;
    d[up] = -1.0;
    let h = l.march_step;
    for bounce in 0..l.max_bounces {
        // march to the first point with V_f ≥ ½
        let mut a = x;
        let mut hit = None;
        for _ in 0..l.march_steps {
            let Some(b) = in_box(pr, along(a, d, h)) else {
                break;
            };
            if value(pr, bins, b) >= 0.5 {
                hit = Some(b);
                break;
            }
            a = b;
        }
        let Some(_) = hit else {
            out.leaving += q;
            return out;
        };
        // bisect the step from a (outside) for the crossing
        let (mut t0, mut t1) = (0.0f32, h);
        for _ in 0..4 {
            let tm = 0.5 * (t0 + t1);
            let inside = in_box(pr, along(a, d, tm)).is_some_and(|m| value(pr, bins, m) >= 0.5);
            if inside {
                t1 = tm;
            } else {
                t0 = tm;
            }
        }
        let b = in_box(pr, along(a, d, t1)).unwrap_or(a);
        let (g, best) = surface_at(pr, bins, b);
        // n = ±∇V_f/|∇V_f|; d·∇V_f > 0 for a ray going in. Written without a
        // negated sum (lavapipe reassociates −(x + y + z) and x·x − y·y − z)
        // and dividing by |∇V_f|² itself (it turns √x √x into x)
        let gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        let len = gg.sqrt();
        let dg = d[0] * g[0] + d[1] * g[1] + d[2] * g[2];
        let cos = if len > 0.0 { dg.abs() / len } else { 1.0 };
        let bin = &bins[best];
        let absorbed = fresnel(bin[2] / bin[0], bin[3] / bin[0], cos);
        let mut dq = ((q as f32 * absorbed + 0.5).floor() as u32).min(q);
        if bounce + 1 == l.max_bounces {
            out.at_limit += q - dq;
            dq = q;
        }
        if dq > 0 {
            out.deposits.push((best, dq));
        }
        q -= dq;
        if q == 0 {
            return out;
        }
        // reflect d − 2 (d·n) n = d − 2 (d·∇V_f/|∇V_f|²) ∇V_f, renormalised,
        // from half a bin off the surface on the ray's side (the ½ contour of
        // the interpolated staircase is wavy at a tenth of Δx: a ray leaving
        // from on it would meet the same face again), or where that lies
        // inside, from the last point found outside
        let out_pt = in_box(pr, along(a, d, t0)).unwrap_or(a);
        let (off, r) = if len > 0.0 {
            let k = 0.5 * l.bin_size / len;
            let off = if dg > 0.0 {
                back(b, g, k)
            } else {
                along(b, g, k)
            };
            (off, back(d, g, 2.0 * dg / gg))
        } else {
            (back(b, d, 0.5 * l.bin_size), [-d[0], -d[1], -d[2]])
        };
        x = match in_box(pr, off) {
            Some(o) if value(pr, bins, o) < 0.5 => o,
            _ => out_pt,
        };
        let rl = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
        d = [r[0] / rl, r[1] / rl, r[2] / rl];
    }
    out
}

/// Rays in the bundle.
pub fn n_rays(pr: &Params) -> usize {
    let n = pr.laser.rays_per_side as usize;
    if pr.sizes.dim == 3 {
        n * n
    } else {
        n
    }
}

/// Trace every ray at time t: each bin's absorbed count into `acc`, the
/// step's split into `split` (state::RAYS_*). Integer sums: any order gives them.
pub fn rays(pr: &Params, t: f32, bins: &[[f32; 4]], acc: &mut Vec<u32>, split: &mut [u32]) {
    let centre = beam_centre(pr, t);
    let power = beam_power(pr, t);
    let paths: Vec<RayPath> = (0..n_rays(pr) as u32)
        .into_par_iter()
        .map(|r| trace(pr, bins, r, centre, power))
        .collect();
    acc.clear();
    acc.resize(n_bins(pr), 0);
    split.fill(0);
    for p in &paths {
        for &(b, dq) in &p.deposits {
            acc[b] = acc[b].wrapping_add(dq);
            split[RAYS_ABSORBED] = split[RAYS_ABSORBED].wrapping_add(dq);
        }
        split[RAYS_INCIDENT] = split[RAYS_INCIDENT].wrapping_add(p.incident);
        split[RAYS_LEAVING] = split[RAYS_LEAVING].wrapping_add(p.leaving);
        split[RAYS_AT_LIMIT] = split[RAYS_AT_LIMIT].wrapping_add(p.at_limit);
    }
}

/// Each bin's absorbed power from its count.
pub fn ray_bins(pr: &Params, acc: &[u32], bins: &mut [[f32; 4]]) {
    for (b, c) in bins.iter_mut().zip(acc) {
        b[1] = *c as f32 * pr.laser.power_unit;
    }
}
