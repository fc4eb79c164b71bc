// Viscous term of F22 (23): η̃ (∂W/∂r)/r per (V_i² + V_j²), times u_ij. η̃ is the
// harmonic mean 2 η_i η_j/(η_i + η_j); 0 against a free-slip wall or when both
// are inviscid. Twin of src/backend/cpu/terms/viscosity.rs.
fn pair_viscosity(eta_i: f32, eta_j: f32, slip: bool) -> f32 {
    let eta_sum = eta_i + eta_j;
    if (eta_sum > 0.0 && !slip) {
        return c_two() * eta_i * eta_j / eta_sum;
    }
    return 0.0;
}

fn viscosity(eta_avg: f32, dwdr: f32, r: f32) -> f32 {
    return eta_avg * dwdr / r;
}
