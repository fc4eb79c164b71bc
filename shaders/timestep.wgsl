// uses: params consts grid phase
// reads: vel acc phase
// writes: sim partials
// Max |u|² and |a|² over fluid particles by a fixed two-level tree (per-workgroup,
// then one workgroup over the partials), then the F22 (42) time step: the
// smallest of the limits of src/model/limits.rs, in its order.
// Twin of src/backend/cpu/timestep.rs.

const RWG: u32 = 256u;
var<workgroup> red: array<vec2<f32>, 256>;

fn tree_max(t: u32) {
    for (var s = RWG / 2u; s > 0u; s = s / 2u) {
        workgroupBarrier();
        if (t < s) {
            red[t] = max(red[t], red[t + s]);
        }
    }
    workgroupBarrier();
}

@compute @workgroup_size(256)
fn reduce(@builtin(local_invocation_index) t: u32, @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let g = wid.x + wid.y * nwg.x;
    let i = g * RWG + t;
    var m = vec2<f32>(0.0, 0.0);
    if (i < active_particles() && !is_wall(phase[i])) {
        let v = vel[i];
        let a = acc[i];
        m = vec2<f32>(v.x * v.x + v.y * v.y + v.z * v.z, a.x * a.x + a.y * a.y + a.z * a.z);
    }
    red[t] = m;
    tree_max(t);
    if (t == 0u) {
        partials[g] = red[0];
    }
}

@compute @workgroup_size(256)
fn finalize(@builtin(local_invocation_index) t: u32) {
    let groups = (P.sizes.n_particles + RWG - 1u) / RWG;
    var m = vec2<f32>(0.0, 0.0);
    for (var g = t; g < groups; g += RWG) {
        m = max(m, partials[g]);
    }
    red[t] = m;
    tree_max(t);
    if (t != 0u) { return; }
    let umax2 = red[0].x;
    let amax2 = red[0].y;
    if (sim.dt > 0.0) {
        sim.step = sim.step + 1u;
    }
    sim.time = sim.time + sim.dt;
    sim.umax2 = umax2;
    sim.amax2 = amax2;
    let h = P.kernel.h;
    let speed = P.time_step.max_sound_speed + sqrt(umax2);
    var dt = 3.40282347e38;
    if (speed > 0.0) {
        dt = c_quarter() * h / speed;
    }
    var which = DT_ACOUSTIC;
    if (P.time_step.viscous_limit < dt) {
        dt = P.time_step.viscous_limit;
        which = DT_VISCOUS;
    }
    if (P.time_step.conduction_limit < dt) {
        dt = P.time_step.conduction_limit;
        which = DT_CONDUCTION;
    }
    if (P.time_step.barrier_limit < dt) {
        dt = P.time_step.barrier_limit;
        which = DT_BARRIER;
    }
    if (P.time_step.capillary_limit < dt) {
        dt = P.time_step.capillary_limit;
        which = DT_CAPILLARY;
    }
    if (P.time_step.contact_limit < dt) {
        dt = P.time_step.contact_limit;
        which = DT_CONTACT;
    }
    if (amax2 > 0.0) {
        let f = c_quarter() * sqrt(h / sqrt(amax2));
        if (f < dt) {
            dt = f;
            which = DT_FORCE;
        }
    }
    if (P.time_step.maximum_limit < dt) {
        dt = P.time_step.maximum_limit;
        which = DT_MAXIMUM;
    }
    if (P.time_step.fixed_dt > 0.0) {
        dt = P.time_step.fixed_dt;
        which = DT_FIXED;
    }
    // Within one step of the run's end, the time left; within END_STEPS steps,
    // the time left in equal steps that land on it (model/limits.rs toward_end).
    let end = sim.end_time;
    let left = end - sim.time;
    if (end > 0.0 && left > c_end_slack() * end) {
        if (left <= dt) {
            dt = left;
            which = DT_END;
        } else {
            let reach = dt * c_end_stretch();
            if (left <= c_end_steps() * reach) {
                dt = left / ceil(left / reach);
                which = DT_END;
            }
        }
    }
    sim.dt = dt;
    sim.dt_limit = which;
}
