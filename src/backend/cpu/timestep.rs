//! Twin of shaders/timestep.wgsl: advance time by the Δt just used, then the next
//! Δt from F22 (42): min{0.25 h/(c+|u|max), 0.125 h²/ν, 0.25 √(h/|a|max)}.
//! Max over floats is exact and order-free, so this plain fold gives the same bits
//! as the GPU's two-level tree.

use crate::model::limits::{toward_end, Limit};
use crate::params::Params;
use crate::state::State;
use rayon::prelude::*;

pub fn run(pr: &Params, st: &mut State) {
    let (umax2, amax2) = (0..st.active())
        .into_par_iter()
        .filter(|&i| !pr.is_wall(st.phase[i]))
        .map(|i| {
            let (v, a) = (st.vel[i], st.acc[i]);
            (
                v[0] * v[0] + v[1] * v[1] + v[2] * v[2],
                a[0] * a[0] + a[1] * a[1] + a[2] * a[2],
            )
        })
        .reduce(|| (0.0f32, 0.0f32), |x, y| (x.0.max(y.0), x.1.max(y.1)));
    let sim = &mut st.sim;
    if sim.dt > 0.0 {
        sim.step += 1;
    }
    sim.time += sim.dt;
    sim.umax2 = umax2;
    sim.amax2 = amax2;
    let (dt, which) = next_dt(pr, umax2, amax2);
    let (dt, which) = match toward_end(sim.end_time, sim.time, dt) {
        Some(d) => (d, Limit::End.code()),
        None => (dt, which),
    };
    sim.dt = dt;
    sim.dt_limit = which;
}

/// The next Δt and the code of the limit that binds (crate::model::limits: the
/// table's rows, compared in its order). A scene without fluid has no acoustic
/// limit (c_max = 0, |u| = 0).
pub fn next_dt(pr: &Params, umax2: f32, amax2: f32) -> (f32, u32) {
    let h = pr.kernel.h;
    let speed = pr.time_step.max_sound_speed + umax2.sqrt();
    let mut dt = f32::MAX;
    if speed > 0.0 {
        dt = 0.25 * h / speed;
    }
    let mut which = Limit::Acoustic;
    if pr.time_step.viscous_limit < dt {
        dt = pr.time_step.viscous_limit;
        which = Limit::Viscous;
    }
    if pr.time_step.conduction_limit < dt {
        dt = pr.time_step.conduction_limit;
        which = Limit::Conduction;
    }
    if pr.time_step.barrier_limit < dt {
        dt = pr.time_step.barrier_limit;
        which = Limit::Barrier;
    }
    if pr.time_step.capillary_limit < dt {
        dt = pr.time_step.capillary_limit;
        which = Limit::Capillary;
    }
    if pr.time_step.contact_limit < dt {
        dt = pr.time_step.contact_limit;
        which = Limit::Contact;
    }
    if amax2 > 0.0 {
        let f = 0.25 * (h / amax2.sqrt()).sqrt();
        if f < dt {
            dt = f;
            which = Limit::Force;
        }
    }
    if pr.time_step.maximum_limit < dt {
        dt = pr.time_step.maximum_limit;
        which = Limit::Maximum;
    }
    if pr.time_step.fixed_dt > 0.0 {
        dt = pr.time_step.fixed_dt;
        which = Limit::Fixed;
    }
    (dt, which.code())
}
