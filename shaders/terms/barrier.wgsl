// F22 (34) barrier between a fluid particle i and a wall particle j closer than
// r_b: F = (k_b g + d_b g ġ) e_ij with g = r_b − r, ġ = −e_ij·(u_i − U_wall),
// U_wall the wall's real velocity (the wall pass's mirrored velocity is a ghost
// for the viscous term). Returns s with F = s d (d = r_i − r_j, e_ij = d/r); the
// forces pass adds s d to the force. On when the scene sets simulation.barrier.
// Twin of src/backend/cpu/terms/barrier.rs.
override TERM_BARRIER: bool;

fn barrier(v_i: vec4<f32>, w: vec4<f32>, d: vec3<f32>, r: f32) -> f32 {
    let g = P.flow.barrier_radius - r;
    let un = d.x * (v_i.x - w.x) + d.y * (v_i.y - w.y) + d.z * (v_i.z - w.z);
    let g_dot = -(un / r);
    let stiff = P.flow.barrier_stiffness * g;
    let damp = (P.flow.barrier_damping * g) * g_dot;
    return (stiff + damp) / r;
}
