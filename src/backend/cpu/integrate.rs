//! Twin of shaders/integrate.wgsl: velocity Verlet (kick–drift–kick) with the
//! transport velocity of Adami (2013):
//!   u^{n+½} = u^n + ½Δt a^n,   r^{n+1} = r^n + Δt (u^{n+½} + ½Δt a_b^n),
//!   u^{n+1} = u^{n+½} + ½Δt a^{n+1}.
//! Walls do not move. Positions wrap on periodic axes.

use crate::params::Params;
use crate::state::State;
use rayon::prelude::*;

pub fn kick_drift(pr: &Params, st: &mut State) {
    let dt = st.sim.dt;
    let hdt = 0.5 * dt;
    let (acc, acc_b, phase) = (&st.acc, &st.acc_b, &st.phase);
    st.pos
        .par_iter_mut()
        .zip(st.vel.par_iter_mut())
        .enumerate()
        .for_each(|(i, (x, v))| {
            if pr.is_wall(phase[i]) {
                return;
            }
            let a = acc[i];
            let ab = acc_b[i];
            for c in 0..3 {
                v[c] += hdt * a[c];
                x[c] += dt * (v[c] + hdt * ab[c]);
                if pr.grid[3] & (1 << c) != 0 {
                    if x[c] >= pr.period[c] {
                        x[c] -= pr.period[c];
                    } else if x[c] < 0.0 {
                        x[c] += pr.period[c];
                    }
                }
            }
        });
}

pub fn kick(pr: &Params, st: &mut State) {
    let hdt = 0.5 * st.sim.dt;
    let (acc, phase) = (&st.acc, &st.phase);
    st.vel.par_iter_mut().enumerate().for_each(|(i, v)| {
        if pr.is_wall(phase[i]) {
            return;
        }
        let a = acc[i];
        for c in 0..3 {
            v[c] += hdt * a[c];
        }
    });
}
