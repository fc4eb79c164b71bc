//! Twin of shaders/bodies.wgsl: rigid bodies (F22 §2.2, §3.4) in the
//! kick–drift–kick step of the fluid.
//!
//! Translation: V += ½Δt (F/M + g), X += Δt V, V += ½Δt (F/M + g) with the force
//! of the new positions. Rotation: the world angular momentum L takes the same
//! half kicks from the torque (L += ½Δt τ); in between the free rotation
//! H = Σ l_k²/(2 I_k) (l = Rᵀ L in the principal frame) is split into exact
//! rotations about the principal axes, x(½Δt) y(½Δt) z(Δt) y(½Δt) x(½Δt)
//! (Dullweber, Leimkuhler & McLachlan 1997, symplectic: the energy error stays
//! bounded): each turns the orientation by θ = τ l_k/I_k about body axis k, with
//! l_k from the current orientation. L itself is the state, so a free body keeps
//! it exactly: stored in the body frame and rotated by −θ each turn instead, it
//! shrank by 2e-8 per step in f32 (a turn by a tiny angle keeps the length only
//! to the rounding of its cos/sin pair, with the same sign while the spin is
//! steady: 2e-4 over the 10⁴ steps of the free-rotation check). The turn is a
//! Cayley quaternion (θ/2 e_k, 1)/√(1 + θ²/4), a rotation by 2 atan(θ/2) =
//! θ − θ³/12 + …: the exact flow of a slightly modified H_k, so still
//! symplectic, with no trigonometry (DESIGN rule: no built-in transcendentals on
//! the bit-matched path).
//!
//! Forces on a body particle r: F22 (39)–(40) contact with every particle of
//! another body and with wall and solid particles within Δx,
//!   f = (k_c g + d_c ġ) e if positive,  g = Δx − r,  ġ = −e·(u_r − u_s),
//! and F22 (38), the fluid's reaction (see `forces`: pressure, viscosity and
//! F22 (33)'s solid–fluid viscosity), written (as a force, N)
//! into acc; the per-body sums run over the members in
//! ascending id, one thread per body, so the bits do not depend on the thread
//! count (DESIGN rule 5).

use super::neighbors::{for_each_neighbor, CellTable};
use super::terms;
use crate::kernel;
use crate::params::{Params, PHASE_FREE_SLIP, SHADER_CONSTS};
use crate::state::H_TEMPERATURE;
use crate::state::{Body, State, BODY_BONDED, BODY_LEFT, BODY_SOLIDIFIED, NO_BODY};
use rayon::prelude::*;

pub type V3 = [f32; 3];

#[inline(always)]
pub fn cross3(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// v turned by the unit quaternion q: v + 2 (w c + u × c) with c = u × v, u the
/// vector part, each sum one left-to-right chain (shaders/lib/rigid.wgsl says
/// why) and the doubling as two additions.
#[inline(always)]
pub fn rotate(q: [f32; 4], v: V3) -> V3 {
    let u = [q[0], q[1], q[2]];
    let c = cross3(u, v);
    let s = [
        q[3] * c[0] + u[1] * c[2] - u[2] * c[1],
        q[3] * c[1] + u[2] * c[0] - u[0] * c[2],
        q[3] * c[2] + u[0] * c[1] - u[1] * c[0],
    ];
    [v[0] + s[0] + s[0], v[1] + s[1] + s[1], v[2] + s[2] + s[2]]
}

#[inline(always)]
fn conj(q: [f32; 4]) -> [f32; 4] {
    [-q[0], -q[1], -q[2], q[3]]
}

/// a ⊗ b.
#[inline(always)]
fn quat_mul(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [
        a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
        a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
        a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
        a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
    ]
}

/// ω = R (Rᵀ L / I): the angular velocity (world) from the world angular momentum.
#[inline(always)]
pub fn angular_velocity(b: &Body) -> V3 {
    let lb = rotate(conj(b.q), [b.l[0], b.l[1], b.l[2]]);
    let wb = [
        lb[0] / b.inertia[0],
        lb[1] / b.inertia[1],
        lb[2] / b.inertia[2],
    ];
    rotate(b.q, wb)
}

/// The velocity of the body's material point at x: V + ω × (x − X).
#[inline(always)]
pub fn point_velocity(b: &Body, x: &[f32; 4]) -> V3 {
    let w = angular_velocity(b);
    let r = [x[0] - b.x[0], x[1] - b.x[1], x[2] - b.x[2]];
    [
        b.v[0] + w[1] * r[2] - w[2] * r[1],
        b.v[1] + w[2] * r[0] - w[0] * r[2],
        b.v[2] + w[0] * r[1] - w[1] * r[0],
    ]
}

/// Half kick: V += h (F/M + g), L += h τ.
#[inline(always)]
fn kick_body(b: &mut Body, h: f32, g: [f32; 4]) {
    for c in 0..3 {
        b.v[c] += h * (b.force[c] / b.x[3] + g[c]);
        b.l[c] += h * b.torque[c];
    }
}

/// The exact free rotation about body axis k for time tau (Cayley turn): the
/// spin L_k/I_k from the body-frame momentum Rᵀ L of the current orientation.
#[inline(always)]
fn turn(b: &mut Body, k: usize, tau: f32) {
    let lb = rotate(conj(b.q), [b.l[0], b.l[1], b.l[2]]);
    let half = 0.5 * (tau * (lb[k] / b.inertia[k]));
    let s = 1.0 / (1.0 + half * half).sqrt();
    let mut qr = [0.0f32, 0.0, 0.0, s];
    qr[k] = half * s;
    b.q = quat_mul(b.q, qr);
}

/// Free rotation over dt, split x(½) y(½) z(1) y(½) x(½), then q renormalised.
#[inline(always)]
fn rotate_free(b: &mut Body, dt: f32) {
    let h = 0.5 * dt;
    turn(b, 0, h);
    turn(b, 1, h);
    turn(b, 2, dt);
    turn(b, 1, h);
    turn(b, 0, h);
    let q = b.q;
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    b.q = [q[0] / n, q[1] / n, q[2] / n, q[3] / n];
}

/// `body_drift`: first half kick, drift of the centre, free rotation. A body
/// whose centre is then outside the keep box has left through an open side
/// (BODY_LEFT): it moves no more, and `place` marks its members as leaving.
pub fn drift(pr: &Params, st: &mut State) {
    let dt = st.sim.dt;
    let g = pr.flow.gravity.to_array();
    st.bodies.par_iter_mut().for_each(|b| {
        if !b.moves() {
            return;
        }
        kick_body(b, 0.5 * dt, g);
        for c in 0..3 {
            b.x[c] += dt * b.v[c];
        }
        rotate_free(b, dt);
        if pr.outside_keep_box(&b.x) {
            // It stops where it left (as its removed members do); /bodies then
            // reads it at rest there.
            b.bonded = BODY_LEFT;
            (b.v, b.l, b.force, b.torque) = ([0.0; 4], [0.0; 4], [0.0; 4], [0.0; 4]);
        }
    });
}

/// `body_place`: every body particle at X + R r0; the members of a body that
/// left stay where they are and carry the time it left in w, which the next
/// sort reads as removed (`neighbors::cell_key`).
pub fn place(st: &mut State) {
    let n = st.active();
    let left_at = st.sim.step_end();
    let (body, offset, bodies, id) = (&st.body, &st.body_offset, &st.bodies, &st.id);
    st.pos[..n].par_iter_mut().enumerate().for_each(|(i, x)| {
        let k = body[id[i] as usize];
        if k == NO_BODY {
            return;
        }
        let b = &bodies[k as usize];
        if b.left() {
            x[3] = left_at;
            return;
        }
        let o = offset[id[i] as usize];
        let r = rotate(b.q, [o[0], o[1], o[2]]);
        for c in 0..3 {
            x[c] = b.x[c] + r[c];
        }
    });
}

/// `body_forces`: F22 (39)–(40) contact on every body particle, plus F22 (38):
/// minus every force the forces pass puts on each fluid neighbour from this
/// particle (backend::terms::reaction_terms: pressure, viscosity, the
/// solid–fluid viscosity, the barrier) (the same pair term, from this side: the pair's
/// force is the same bits both ways, so momentum is exchanged exactly per pair);
/// the total force (N) into acc.
pub fn forces(pr: &Params, st: &mut State, grid: &CellTable) {
    let n = st.active();
    let (pos, body, phase, bodies, id) = (&st.pos, &st.body, &st.phase, &st.bodies, &st.id);
    let (rho, press, mass, vel) = (&st.rho, &st.press, &st.mass, &st.vel);
    let bp = &pr.bodies;
    let reach2 = bp.contact_distance * bp.contact_distance;
    let sf = crate::backend::terms::active(pr, crate::backend::terms::TermId::SolidFluidViscosity);
    let br = crate::backend::terms::active(pr, crate::backend::terms::TermId::Barrier);
    let df = crate::backend::terms::active(pr, crate::backend::terms::TermId::ShepardPressure);
    let marrone =
        crate::backend::terms::active(pr, crate::backend::terms::TermId::MarroneViscosity);
    let (heat, cont) = (&st.heat, &st.continuity);
    st.acc[..n].par_iter_mut().enumerate().for_each(|(i, a)| {
        let k = body[id[i] as usize];
        if k == NO_BODY {
            return;
        }
        let ui = point_velocity(&bodies[k as usize], &pos[i]);
        let slip = pr.phase(phase[i]).flags & PHASE_FREE_SLIP != 0;
        let (p_r, v_r) = (press[i], vel[i]);
        let mut f = [0.0f32; 3];
        for_each_neighbor(pr, pos, grid, i, |j, d, r2| {
            let kj = body[id[j] as usize];
            let ph_j = phase[j];
            if r2 > 0.0 && kj == NO_BODY && !pr.is_wall(ph_j) {
                let r = r2.sqrt();
                let dwdr = kernel::dw(pr, r);
                let mat = pr.phase(ph_j);
                let (rho_j, m_j) = (rho[j], mass[j]);
                let vol_j = m_j / rho_j;
                let rho_w = mat.rho0 + p_r / mat.c2;
                let vol_w = m_j / rho_w;
                let vv = vol_j * vol_j + vol_w * vol_w;
                let fp = if df {
                    0.0
                } else {
                    terms::pressure(press[j], p_r, rho_j, rho_w, dwdr, r)
                };
                let eta_jw = terms::pair_viscosity(mat.eta, mat.eta, slip);
                let fv = if marrone {
                    0.0
                } else {
                    terms::viscosity(eta_jw, dwdr, r)
                };
                let v_j = vel[j];
                let dj = [-d[0], -d[1], -d[2]];
                for c in 0..3 {
                    let u = v_j[c] - v_r[c];
                    f[c] -= vv * (fp * dj[c] + fv * u);
                }
                if df {
                    let s = terms::shepard_pressure(
                        m_j, m_j, rho_j, rho_w, press[j], p_r, cont[j][1], 1.0, dwdr, r,
                    );
                    for c in 0..3 {
                        f[c] -= s * dj[c];
                    }
                }
                if marrone {
                    let u = [v_j[0] - v_r[0], v_j[1] - v_r[1], v_j[2] - v_r[2]];
                    let s = terms::marrone_viscosity(
                        pr, m_j, m_j, rho_j, rho_w, eta_jw, u, dj, r2, dwdr, r,
                    );
                    for c in 0..3 {
                        f[c] -= s * dj[c];
                    }
                }
                if sf {
                    // F22 (33) as the forces pass applies it between the melt
                    // and a wall: the fluid's own α^sf, mass and sound speed.
                    let alpha_j =
                        terms::solid_fluid_viscosity_alpha(pr, ph_j, heat[j][H_TEMPERATURE]);
                    let alpha = (alpha_j + alpha_j) * 0.5;
                    let u = [v_j[0] - v_r[0], v_j[1] - v_r[1], v_j[2] - v_r[2]];
                    let s = terms::solid_fluid_viscosity(
                        pr, m_j, m_j, rho_j, rho_w, mat.c2, mat.c2, u, dj, r2, dwdr, alpha,
                    );
                    for c in 0..3 {
                        f[c] -= s * dj[c];
                    }
                }
                if br && r < pr.flow.barrier_radius {
                    // F22 (34) as the forces pass applies it to the fluid from a
                    // wall particle: the wall phase's velocity, not the body's.
                    let w = pr.phase(phase[i]).velocity;
                    let v = [v_j[0], v_j[1], v_j[2]];
                    let s = terms::barrier(pr, v, [w.x, w.y, w.z], dj, r);
                    for c in 0..3 {
                        f[c] -= s * dj[c];
                    }
                }
            }
            if kj == k || r2 >= reach2 || r2 <= 0.0 {
                return;
            }
            if kj == NO_BODY && !pr.is_wall(ph_j) {
                return;
            }
            let uj = if kj != NO_BODY {
                point_velocity(&bodies[kj as usize], &pos[j])
            } else if pr.wall_moves(ph_j) {
                let w = pr.phase(ph_j).velocity;
                [w[0], w[1], w[2]]
            } else {
                [0.0; 3]
            };
            let r = r2.sqrt();
            let e = [d[0] / r, d[1] / r, d[2] / r];
            let gdot = -(e[0] * (ui[0] - uj[0]) + e[1] * (ui[1] - uj[1]) + e[2] * (ui[2] - uj[2]));
            let fn_ = bp.contact_stiffness * (bp.contact_distance - r) + bp.contact_damping * gdot;
            if fn_ > 0.0 {
                for c in 0..3 {
                    f[c] += fn_ * e[c];
                }
            }
        });
        *a = [f[0], f[1], f[2], 0.0];
    });
}

/// `body_slots` + `body_sum`: each body's force and torque, summed over its
/// members in ascending id (the member list) wherever the sort put them.
pub fn sum(st: &mut State) {
    let n = st.active();
    let mut slot = vec![0u32; st.len()];
    for i in 0..n {
        slot[st.id[i] as usize] = i as u32;
    }
    let (pos, acc, members) = (&st.pos, &st.acc, &st.members);
    st.bodies.par_iter_mut().for_each(|b| {
        if !b.moves() {
            return;
        }
        let mut f = [0.0f32; 3];
        let mut t = [0.0f32; 3];
        for &id in &members[b.first as usize..(b.first + b.count) as usize] {
            let i = slot[id as usize] as usize;
            let fi = [acc[i][0], acc[i][1], acc[i][2]];
            let r = [pos[i][0] - b.x[0], pos[i][1] - b.x[1], pos[i][2] - b.x[2]];
            f = [f[0] + fi[0], f[1] + fi[1], f[2] + fi[2]];
            t = [
                t[0] + r[1] * fi[2] - r[2] * fi[1],
                t[1] + r[2] * fi[0] - r[0] * fi[2],
                t[2] + r[0] * fi[1] - r[1] * fi[0],
            ];
        }
        b.force = [f[0], f[1], f[2], 0.0];
        b.torque = [t[0], t[1], t[2], 0.0];
    });
}

/// `body_kick`: the second half kick with the force of the new positions.
pub fn kick(pr: &Params, st: &mut State) {
    let dt = st.sim.dt;
    let g = pr.flow.gravity.to_array();
    st.bodies
        .par_iter_mut()
        .filter(|b| b.moves())
        .for_each(|b| kick_body(b, 0.5 * dt, g));
}

/// Particles that solidified this step bond the bodies they touch: within this
/// reach (in Δx) of a body particle, which covers a lattice's diagonal neighbour
/// (the WGSL twin reads it as `c_one_and_half()`).
pub const BOND_REACH: f32 = 1.5;

/// `body_bond`: a particle that solidified in this step (`BODY_SOLIDIFIED`, set
/// by the temperature pass) flags every body particle within `BOND_REACH` Δx
/// (body_offset.w = 1) and is `NO_BODY` again.
pub fn bond(pr: &Params, st: &mut State, grid: &CellTable) {
    let n = st.active();
    let reach = BOND_REACH * pr.bodies.contact_distance;
    let reach2 = reach * reach;
    let n_bodies = pr.bodies.n_bodies;
    let mut touched = Vec::new();
    for i in 0..n {
        if st.body[st.id[i] as usize] != BODY_SOLIDIFIED {
            continue;
        }
        st.body[st.id[i] as usize] = NO_BODY;
        let (body, id) = (&st.body, &st.id);
        for_each_neighbor(pr, &st.pos, grid, i, |j, _d, r2| {
            if r2 < reach2 && body[id[j] as usize] < n_bodies {
                touched.push(id[j] as usize);
            }
        });
    }
    for id in touched {
        st.body_offset[id][3] = 1.0;
    }
}

/// `body_melt`, F22 (37) and the bonding rule, per body with a member that
/// melted or was touched by solidifying melt (the rest are left as they are):
/// - touched (`body_offset.w` set): the body is bonded into the substrate: its
///   solid members become fixed solid particles (at rest), still listed, and
///   `bonded` stops every body pass;
/// - otherwise the melted members leave: each keeps its material velocity
///   V + ω × r as a fluid particle; the rest are the new body, with its mass,
///   centre and principal axes recomputed from their body-frame offsets, ω
///   unchanged and V the velocity the old motion gave the new centre, so the
///   linear momentum of body plus melt is unchanged (angular momentum up to the
///   departing particle's own spin m I_r ω, which SPH does not carry).
pub fn melt(pr: &Params, st: &mut State) {
    let n = st.active();
    let mut slot = vec![0u32; st.len()];
    for i in 0..n {
        slot[st.id[i] as usize] = i as u32;
    }
    for k in 0..st.bodies.len() {
        let b = st.bodies[k];
        if !b.moves() {
            continue;
        }
        let range = b.first as usize..(b.first + b.count) as usize;
        let mut melted = false;
        let mut touched = false;
        for &id in &st.members[range.clone()] {
            melted |= !pr.is_wall(st.phase[slot[id as usize] as usize]);
            touched |= st.body_offset[id as usize][3] > 0.0;
        }
        if touched {
            bond_body(pr, st, k, &slot);
        } else if melted {
            shed(pr, st, k, &slot);
        }
    }
}

/// A melted member leaves body b: a fluid particle with b's material velocity,
/// taking its own force f of this step (in acc since `bodies.forces`) with it as
/// its acceleration f/m for the second half kick; returns f, which the body
/// no longer gets (with the last member gone it would be lost otherwise).
fn release(st: &mut State, b: &Body, id: u32, i: usize) -> V3 {
    let u = point_velocity(b, &st.pos[i]);
    let f = [st.acc[i][0], st.acc[i][1], st.acc[i][2]];
    let m = st.mass[i];
    st.vel[i] = [u[0], u[1], u[2], st.vel[i][3]];
    st.acc[i] = [f[0] / m, f[1] / m, f[2] / m, 0.0];
    st.acc_b[i] = [0.0; 4];
    st.body[id as usize] = NO_BODY;
    f
}

/// Body k bonds into the substrate: melted members leave, the rest stay put as
/// fixed solid particles and stay listed (`count`, the mass they make), so the
/// body's molten fraction stays readable; `bonded` stops every body pass.
fn bond_body(pr: &Params, st: &mut State, k: usize, slot: &[u32]) {
    let b = st.bodies[k];
    let mut kept = 0u32;
    let mut m_new = 0.0f32;
    for m in b.first..b.first + b.count {
        let id = st.members[m as usize];
        let i = slot[id as usize] as usize;
        st.body[id as usize] = NO_BODY;
        if !pr.is_wall(st.phase[i]) {
            // Its force leaves with it; the rest goes into the substrate.
            release(st, &b, id, i);
            continue;
        }
        st.members[(b.first + kept) as usize] = id;
        kept += 1;
        m_new += st.mass[i];
        st.vel[i] = [0.0, 0.0, 0.0, st.vel[i][3]];
        st.acc[i] = [0.0; 4];
        st.acc_b[i] = [0.0; 4];
    }
    let b = &mut st.bodies[k];
    b.count = kept;
    b.x[3] = m_new;
    b.bonded = BODY_BONDED;
    b.v = [0.0; 4];
    b.l = [0.0; 4];
    b.force = [0.0; 4];
    b.torque = [0.0; 4];
}

/// Body k sheds its melted members (F22 (37)); see `melt`.
fn shed(pr: &Params, st: &mut State, k: usize, slot: &[u32]) {
    let b = st.bodies[k];
    // Melted members leave; the rest are compacted in place, in id order.
    let mut kept = 0u32;
    let mut m_new = 0.0f32;
    let mut s = [0.0f32; 3];
    // The force and torque (about the old centre) of the members that stay.
    let (mut f, mut t) = (
        [b.force[0], b.force[1], b.force[2]],
        [b.torque[0], b.torque[1], b.torque[2]],
    );
    for m in b.first..b.first + b.count {
        let id = st.members[m as usize];
        let i = slot[id as usize] as usize;
        if !pr.is_wall(st.phase[i]) {
            let x = st.pos[i];
            let fk = release(st, &b, id, i);
            let r = [x[0] - b.x[0], x[1] - b.x[1], x[2] - b.x[2]];
            f = [f[0] - fk[0], f[1] - fk[1], f[2] - fk[2]];
            t = [
                t[0] - r[1] * fk[2] + r[2] * fk[1],
                t[1] - r[2] * fk[0] + r[0] * fk[2],
                t[2] - r[0] * fk[1] + r[1] * fk[0],
            ];
            continue;
        }
        st.members[(b.first + kept) as usize] = id;
        kept += 1;
        let (mi, r0) = (st.mass[i], st.body_offset[id as usize]);
        m_new += mi;
        for c in 0..3 {
            s[c] += mi * r0[c];
        }
    }
    let mut nb = b;
    nb.count = kept;
    if kept == 0 {
        nb.x[3] = 0.0;
        nb.v = [0.0; 4];
        nb.l = [0.0; 4];
        nb.force = [0.0; 4];
        nb.torque = [0.0; 4];
        st.bodies[k] = nb;
        return;
    }
    // The new centre in the body frame, and the inertia tensor about it.
    let c0 = [s[0] / m_new, s[1] / m_new, s[2] / m_new];
    let ip = b.inertia[3];
    let mut a = [[0.0f32; 3]; 3];
    for m in b.first..b.first + kept {
        let id = st.members[m as usize];
        let mi = st.mass[slot[id as usize] as usize];
        let o = st.body_offset[id as usize];
        let r = [o[0] - c0[0], o[1] - c0[1], o[2] - c0[2]];
        let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        for p in 0..3 {
            a[p][p] += mi * (ip + r2 - r[p] * r[p]);
        }
        a[0][1] -= mi * (r[0] * r[1]);
        a[0][2] -= mi * (r[0] * r[2]);
        a[1][2] -= mi * (r[1] * r[2]);
    }
    a[1][0] = a[0][1];
    a[2][0] = a[0][2];
    a[2][1] = a[1][2];
    let (moments, axes) = jacobi(a);
    // New body frame: old frame turned by the principal axes; offsets Qᵀ (r0 − c0).
    for m in b.first..b.first + kept {
        let id = st.members[m as usize] as usize;
        let o = st.body_offset[id];
        let r = [o[0] - c0[0], o[1] - c0[1], o[2] - c0[2]];
        let t = transpose_times(&axes, r);
        st.body_offset[id] = [t[0], t[1], t[2], 0.0];
    }
    let w = angular_velocity(&b);
    let cw = rotate(b.q, c0);
    let q = normalized(quat_mul(b.q, quaternion_of(&axes)));
    let lb = rotate(conj(q), w);
    let l = rotate(
        q,
        [lb[0] * moments[0], lb[1] * moments[1], lb[2] * moments[2]],
    );
    nb.x = [b.x[0] + cw[0], b.x[1] + cw[1], b.x[2] + cw[2], m_new];
    nb.q = q;
    nb.v = [
        b.v[0] + w[1] * cw[2] - w[2] * cw[1],
        b.v[1] + w[2] * cw[0] - w[0] * cw[2],
        b.v[2] + w[0] * cw[1] - w[1] * cw[0],
        0.0,
    ];
    nb.l = [l[0], l[1], l[2], 0.0];
    nb.inertia = [moments[0], moments[1], moments[2], ip];
    // The torque about the new centre: τ − c × F.
    nb.force = [f[0], f[1], f[2], 0.0];
    nb.torque = [
        t[0] - cw[1] * f[2] + cw[2] * f[1],
        t[1] - cw[2] * f[0] + cw[0] * f[2],
        t[2] - cw[0] * f[1] + cw[1] * f[0],
        0.0,
    ];
    st.bodies[k] = nb;
}

#[inline(always)]
fn normalized(q: [f32; 4]) -> [f32; 4] {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    [q[0] / n, q[1] / n, q[2] / n, q[3] / n]
}

type M3 = [[f32; 3]; 3];

/// a b, each entry one left-to-right chain.
fn mat_mul(a: &M3, b: &M3) -> M3 {
    let mut c = [[0.0f32; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    c
}

fn transpose(a: &M3) -> M3 {
    let mut t = [[0.0f32; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = a[j][i];
        }
    }
    t
}

/// Qᵀ r.
fn transpose_times(q: &M3, r: V3) -> V3 {
    [0, 1, 2].map(|j| q[0][j] * r[0] + q[1][j] * r[1] + q[2][j] * r[2])
}

/// Sweeps of `jacobi`: each squares the off-diagonal's relative size, so 6 take
/// any f32 tensor to its rounding.
const JACOBI_SWEEPS: u32 = 6;

/// Eigen-decomposition of a symmetric 3×3 tensor in f32 by cyclic Jacobi
/// rotations with the algebraic angle (tan φ from cot 2φ, square roots only: no
/// trigonometry on the bit-matched path): (moments, Q) with the axes as Q's
/// columns, Q a proper rotation. An entry at or below 1e-7 of its diagonal pair
/// is f32 rounding and is left; an exact zero (a planar body's xz, yz) is never
/// rotated, so z stays a principal axis.
pub fn jacobi(a: M3) -> (V3, M3) {
    let mut a = a;
    let mut q: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..JACOBI_SWEEPS {
        for (p, r) in [(0usize, 1usize), (0, 2), (1, 2)] {
            let apr = a[p][r];
            if apr.abs() <= SHADER_CONSTS.jacobi_floor * (a[p][p].abs() + a[r][r].abs()) {
                continue;
            }
            let theta = (a[r][r] - a[p][p]) / (apr + apr);
            let t_abs = 1.0 / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta < 0.0 { -t_abs } else { t_abs };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            let mut g: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            g[p][p] = c;
            g[r][r] = c;
            g[p][r] = s;
            g[r][p] = -s;
            a = mat_mul(&transpose(&g), &mat_mul(&a, &g));
            a[p][r] = 0.0;
            a[r][p] = 0.0;
            q = mat_mul(&q, &g);
        }
    }
    ([a[0][0], a[1][1], a[2][2]], q)
}

/// The unit quaternion of a rotation matrix (Shepperd: the largest of the four
/// squared components first), f32 twin of `crate::bodies::quaternion_of`.
pub fn quaternion_of(r: &M3) -> [f32; 4] {
    let t = r[0][0] + r[1][1] + r[2][2];
    let q = if t > r[0][0].max(r[1][1]).max(r[2][2]) {
        let w = 0.5 * (1.0 + t).sqrt();
        let f = 0.25 / w;
        [
            (r[2][1] - r[1][2]) * f,
            (r[0][2] - r[2][0]) * f,
            (r[1][0] - r[0][1]) * f,
            w,
        ]
    } else if r[0][0] >= r[1][1] && r[0][0] >= r[2][2] {
        let x = 0.5 * (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt();
        let f = 0.25 / x;
        [
            x,
            (r[0][1] + r[1][0]) * f,
            (r[0][2] + r[2][0]) * f,
            (r[2][1] - r[1][2]) * f,
        ]
    } else if r[1][1] >= r[2][2] {
        let y = 0.5 * (1.0 - r[0][0] + r[1][1] - r[2][2]).sqrt();
        let f = 0.25 / y;
        [
            (r[0][1] + r[1][0]) * f,
            y,
            (r[1][2] + r[2][1]) * f,
            (r[0][2] - r[2][0]) * f,
        ]
    } else {
        let z = 0.5 * (1.0 - r[0][0] - r[1][1] + r[2][2]).sqrt();
        let f = 0.25 / z;
        [
            (r[0][2] + r[2][0]) * f,
            (r[1][2] + r[2][1]) * f,
            z,
            (r[1][0] - r[0][1]) * f,
        ]
    };
    normalized(q)
}
