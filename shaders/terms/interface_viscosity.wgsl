// F22 (31)-(32) interface viscosity between fluid particles (the CPU twin,
// src/backend/cpu/terms/interface_viscosity.rs, explains the form). On when
// α_0^lg > 0.
override TERM_INTERFACE_VISCOSITY: bool;

// α_i = α_0^lg min(h δ_i, 1).
fn interface_viscosity_alpha(delta: f32) -> f32 {
    return P.flow.interface_viscosity * min(P.kernel.h * delta, c_one());
}

// The factor of r_ij in the force on i.
fn interface_viscosity(m_i: f32, m_j: f32, rho_i: f32, rho_j: f32, c2_i: f32, c2_j: f32,
                       u: vec3<f32>, d: vec3<f32>, r2: f32, dwdr: f32, alpha: f32) -> f32 {
    let c = (sqrt(c2_i) + sqrt(c2_j)) * c_half();
    let rho_m = (rho_i + rho_j) * c_half();
    let ur = u.x * d.x + u.y * d.y + u.z * d.z;
    let r = sqrt(r2);
    return m_i * m_j * alpha * P.kernel.h * c / rho_m * ur / (r2 + P.kernel.eta2) * dwdr / r;
}
