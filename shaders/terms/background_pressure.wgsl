// Transport-velocity background pressure (Adami 2013): −p_b (∂W/∂r)/r per
// (V_i² + V_j²) along r_ij, summed into acc_b. Off (removed from the pipeline)
// when p_b = 0, where every term is ±0 and the sum stays +0. Twin of
// src/backend/cpu/terms/background_pressure.rs.
override TERM_BACKGROUND_PRESSURE: bool;

fn background_pressure(pb: f32, dwdr: f32, r: f32) -> f32 {
    return -pb * dwdr / r;
}
