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
//! and F22 (38), the fluid's reaction (see `forces`), written (as a force, N)
//! into acc; the per-body sums run over the members in
//! ascending id, one thread per body, so the bits do not depend on the thread
//! count (DESIGN rule 5).

use super::neighbors::{for_each_neighbor, CellTable};
use super::terms;
use crate::kernel;
use crate::params::{Params, PHASE_FREE_SLIP};
use crate::state::{Body, State, NO_BODY};
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

/// `body_drift`: first half kick, drift of the centre, free rotation.
pub fn drift(pr: &Params, st: &mut State) {
    let dt = st.sim.dt;
    let g = pr.flow.gravity;
    st.bodies.par_iter_mut().for_each(|b| {
        kick_body(b, 0.5 * dt, g);
        for c in 0..3 {
            b.x[c] += dt * b.v[c];
        }
        rotate_free(b, dt);
    });
}

/// `body_place`: every body particle at X + R r0.
pub fn place(st: &mut State) {
    let n = st.active();
    let (body, offset, bodies, id) = (&st.body, &st.body_offset, &st.bodies, &st.id);
    st.pos[..n].par_iter_mut().enumerate().for_each(|(i, x)| {
        let k = body[id[i] as usize];
        if k == NO_BODY {
            return;
        }
        let b = &bodies[k as usize];
        let o = offset[id[i] as usize];
        let r = rotate(b.q, [o[0], o[1], o[2]]);
        for c in 0..3 {
            x[c] = b.x[c] + r[c];
        }
    });
}

/// `body_forces`: F22 (39)–(40) contact on every body particle, plus F22 (38):
/// minus the pressure and viscous force the forces pass puts on each fluid
/// neighbour from this particle (the same pair term, from this side: the pair's
/// force is the same bits both ways, so momentum is exchanged exactly per pair);
/// the total force (N) into acc.
pub fn forces(pr: &Params, st: &mut State, grid: &CellTable) {
    let n = st.active();
    let (pos, body, phase, bodies, id) = (&st.pos, &st.body, &st.phase, &st.bodies, &st.id);
    let (rho, press, mass, vel) = (&st.rho, &st.press, &st.mass, &st.vel);
    let bp = &pr.bodies;
    let reach2 = bp.contact_distance * bp.contact_distance;
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
                let fp = terms::pressure(press[j], p_r, rho_j, rho_w, dwdr, r);
                let fv = terms::viscosity(terms::pair_viscosity(mat.eta, mat.eta, slip), dwdr, r);
                let v_j = vel[j];
                let dj = [-d[0], -d[1], -d[2]];
                for c in 0..3 {
                    let u = v_j[c] - v_r[c];
                    f[c] -= vv * (fp * dj[c] + fv * u);
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
    let g = pr.flow.gravity;
    st.bodies
        .par_iter_mut()
        .for_each(|b| kick_body(b, 0.5 * dt, g));
}
