// Power the pair's viscous force dissipates (W per particle i, to be divided by
// m_i): fluid pairs share F.(u_i - u_j) (share 1/2); against a wall it is
// F.(u_i - U_wall) with the wall's real velocity w (share 1; the mirrored velocity
// is a ghost). The forces pass subtracts it from acc.w. On with
// FLAG_VISCOUS_HEATING. Twin of src/backend/cpu/terms/viscous_heating.rs.
override TERM_VISCOUS_HEATING: bool;

fn viscous_heating(v_i: vec4<f32>, v_j: vec4<f32>, w: vec3<f32>, share: f32, vv: f32, fv: f32) -> f32 {
    let ux = v_i.x - v_j.x;
    let uy = v_i.y - v_j.y;
    let uz = v_i.z - v_j.z;
    let wx = v_i.x - w.x;
    let wy = v_i.y - w.y;
    let wz = v_i.z - w.z;
    let uw = ux * wx + uy * wy + uz * wz;
    return share * vv * fv * uw;
}
