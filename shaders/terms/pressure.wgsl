// Pressure term of F22 (23): with p̃ = (ρ_j p_i + ρ_i p_j)/(ρ_i + ρ_j), the force on
// i along r_ij per (V_i² + V_j²) is −p̃ (∂W/∂r)/r. Twin of src/backend/cpu/terms/pressure.rs.
fn pressure(p_i: f32, p_j: f32, rho_i: f32, rho_j: f32, dwdr: f32, r: f32) -> f32 {
    let p_avg = (rho_j * p_i + rho_i * p_j) / (rho_i + rho_j);
    return -p_avg * dwdr / r;
}
