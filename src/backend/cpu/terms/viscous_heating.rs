//! Power the pair's viscous force dissipates, −s (V_i² + V_j²) η̃ (∂W/∂r / r)
//! u_ij·w_ij summed over j and divided by m_i (W/kg, acc.w): a fluid pair has
//! w = u_ij and s = ½ (both sides count it); a wall pair w = u_i − U_wall and
//! s = 1, so that heat = wall work − kinetic-energy change exactly. This returns
//! s vv fv u·w for the sweep to subtract. Twin of shaders/terms/viscous_heating.wgsl.

#[inline(always)]
pub fn viscous_heating(
    v_i: [f32; 4],
    v_j: [f32; 4],
    w: [f32; 4],
    share: f32,
    vv: f32,
    fv: f32,
) -> f32 {
    let (ux, uy, uz) = (v_i[0] - v_j[0], v_i[1] - v_j[1], v_i[2] - v_j[2]);
    let (wx, wy, wz) = (v_i[0] - w[0], v_i[1] - w[1], v_i[2] - w[2]);
    let uw = ux * wx + uy * wy + uz * wz;
    share * vv * fv * uw
}
