//! Twin of shaders/integrate.wgsl: velocity Verlet (kick–drift–kick) with the
//! transport velocity of Adami (2013):
//!   u^{n+½} = u^n + ½Δt a^n,   r^{n+1} = r^n + Δt (u^{n+½} + ½Δt a_b^n),
//!   u^{n+1} = u^{n+½} + ½Δt a^{n+1}.
//! Walls stay in place, except those of a moving phase (`moves`), which drift
//! with their prescribed velocity: r^{n+1} = r^n + Δt u_wall. Positions wrap on
//! periodic axes.

use crate::params::Params;
use crate::state::State;
use crate::state::H_LIQUID;
use rayon::prelude::*;

pub fn kick_drift(pr: &Params, st: &mut State) {
    let dt = st.sim.dt;
    let hdt = 0.5 * dt;
    let left_at = st.sim.step_end();
    let n = st.active();
    let (acc, acc_b, phase) = (&st.acc, &st.acc_b, &st.phase);
    st.pos[..n]
        .par_iter_mut()
        .zip(st.vel[..n].par_iter_mut())
        .enumerate()
        .for_each(|(i, (x, v))| {
            let ph = phase[i];
            if pr.is_wall(ph) {
                if pr.wall_moves(ph) {
                    let w = pr.phase(ph).velocity;
                    for c in 0..3 {
                        x[c] += dt * w[c];
                        wrap_periodic(pr, x, c);
                    }
                }
                return;
            }
            let a = acc[i];
            let ab = acc_b[i];
            for c in 0..3 {
                v[c] += hdt * a[c];
                x[c] += dt * (v[c] + hdt * ab[c]);
                wrap_periodic(pr, x, c);
            }
            stamp_if_left(pr, x, left_at);
        });
}

/// A fluid particle that has just left the keep box carries the time it left in
/// w; the neighbour pass then sorts it last and the passes stop before it.
/// Walls are never removed.
#[inline(always)]
pub(super) fn stamp_if_left(pr: &Params, x: &mut [f32; 4], left_at: f32) {
    if pr.outside_keep_box(x) {
        x[3] = left_at;
    }
}

/// Brings coordinate `c` back into [0, period) on a periodic axis.
#[inline(always)]
pub(super) fn wrap_periodic(pr: &Params, x: &mut [f32; 4], c: usize) {
    if pr.sizes.flags & (1 << c) != 0 {
        if x[c] >= pr.grid.period[c] {
            x[c] -= pr.grid.period[c];
        } else if x[c] < 0.0 {
            x[c] += pr.grid.period[c];
        }
    }
}

/// Second half kick, then the mushy-zone sink of J22 (11)–(13) for liquids in a
/// melting band: v ← v / (1 + Δt C (1 − f_l)), semi-implicit so a large C only
/// stops the particle, never reverses it.
pub fn kick(pr: &Params, st: &mut State) {
    let dt = st.sim.dt;
    let hdt = 0.5 * dt;
    let n = st.active();
    let (acc, phase, heat) = (&st.acc, &st.phase, &st.heat);
    st.vel[..n].par_iter_mut().enumerate().for_each(|(i, v)| {
        if pr.is_wall(phase[i]) {
            return;
        }
        let a = acc[i];
        for c in 0..3 {
            v[c] += hdt * a[c];
        }
        let sink = pr.phases[phase[i] as usize].mushy_damping;
        if sink > 0.0 {
            let damp = 1.0 + dt * sink * (1.0 - heat[i][H_LIQUID]);
            for c in v.iter_mut().take(3) {
                *c /= damp;
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use crate::params::Params;
    use crate::state::H_LIQUID;

    /// A moving wall particle drifts by Δt u_wall whatever its acceleration, and
    /// wraps on a periodic axis; a standing wall particle keeps its place.
    #[test]
    fn moving_wall_drifts_with_its_velocity_and_wraps() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/validation/couette_2d.toml"
        );
        let sets = [
            "phases.lid.moves=true".to_string(),
            "phases.lid.velocity=[2.0e-3, 0.0]".to_string(),
        ];
        let l = crate::load::load(path, &sets).unwrap();
        let pr = Params::new(&l.model, l.state.len() as u32);
        let lid = l.model.phase_index("lid").unwrap() as u32;
        let wall = l.model.phase_index("wall").unwrap() as u32;
        let mut st = l.state.clone();
        st.sim.dt = 0.01;
        let (a, b) = (
            (0..st.len()).find(|&i| st.phase[i] == lid).unwrap(),
            (0..st.len()).find(|&i| st.phase[i] == wall).unwrap(),
        );
        st.pos[a][0] = pr.grid.period[0] - 1.0e-5;
        st.acc[a] = [1.0; 4];
        st.acc_b[a] = [1.0; 4];
        let (xa, xb) = (st.pos[a], st.pos[b]);
        super::kick_drift(&pr, &mut st);
        assert_eq!(st.pos[a][0], (xa[0] + 0.01f32 * 2.0e-3) - pr.grid.period[0]);
        assert_eq!(st.pos[a][1], xa[1]);
        assert_eq!(st.pos[b], xb);
    }

    /// J22 (12): with no force, a liquid particle at liquid fraction f_l leaves the
    /// kick with v / (1 + Δt C (1 − f_l)); fully liquid particles keep v.
    #[test]
    fn mushy_sink_divides_velocity_by_the_semi_implicit_factor() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/validation/melt_block_3d.toml"
        );
        let l = crate::load::load(path, &[]).unwrap();
        let pr = Params::new(&l.model, l.state.len() as u32);
        let melt = l.model.phase_index("melt").unwrap() as u32;
        let mut st = l.state.clone();
        st.sim.dt = 5.0e-7;
        for (k, fl) in [(0usize, 0.5f32), (1, 1.0)] {
            st.phase[k] = melt;
            st.vel[k] = [1.0, -2.0, 0.5, 0.0];
            st.acc[k] = [0.0; 4];
            st.heat[k][H_LIQUID] = fl;
        }
        super::kick(&pr, &mut st);
        let damp = 1.0 + 5.0e-7f32 * 1.0e6 * 0.5;
        assert_eq!(st.vel[0][0], 1.0 / damp);
        assert_eq!(st.vel[0][1], -2.0 / damp);
        assert_eq!(st.vel[1], [1.0, -2.0, 0.5, 0.0]);
    }
}
