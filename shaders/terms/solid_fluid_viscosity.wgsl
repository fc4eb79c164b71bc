// F22 (33) solid-fluid artificial viscosity in F22 (31)'s form (the force is
// `interface_viscosity` with this alpha; the CPU twin,
// src/backend/cpu/terms/solid_fluid_viscosity.rs, explains the pairs). On when
// alpha_0^sf > 0.
override TERM_SOLID_FLUID_VISCOSITY: bool;

// alpha_i^sf = alpha_0^sf (1 - clamp((T_i - T_s) / dT_d, 0, 1)) on melting phases.
fn solid_fluid_viscosity_alpha(ph: u32, t: f32) -> f32 {
    if ((P.phases[ph].flags & HEAT_MELTS) == 0u) {
        return 0.0;
    }
    let f = min(max((t - P.phases[ph].solidus) * P.flow.solid_fluid_inv_width, 0.0), c_one());
    return P.flow.solid_fluid_viscosity * (c_one() - f);
}

// The factor of r_ij in the force on i: F22 (31) with the pair's mean alpha^sf.
fn solid_fluid_viscosity(m_i: f32, m_j: f32, rho_i: f32, rho_j: f32, c2_i: f32, c2_j: f32,
                         u: vec3<f32>, d: vec3<f32>, r2: f32, dwdr: f32, alpha: f32) -> f32 {
    return interface_viscosity(m_i, m_j, rho_i, rho_j, c2_i, c2_j, u, d, r2, dwdr, alpha);
}
