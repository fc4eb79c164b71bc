// R18 (3.18), the Monaghan-Gingold viscous term in Marrone's multiphase form:
// a_i = K sum_j m_j mu_ij/(rho_i rho_j) (u_ij . r_ij)/(r_ij^2 + eta^2) grad_i W_ij,
// K = 2 (d + 2), mu_ij = 2 mu_i mu_j/(mu_i + mu_j) (the pair viscosity F22 (23)
// uses: 0 against a free-slip wall). R18 prints mu_i mu_j/(mu_i + mu_j) and a
// scalar (R18 (3.18)); with the harmonic mean it is mu/rho lap(u) for
// one fluid (the Poiseuille check measures it). The force on i is s d. On in
// delta_wcsph scenes with viscosity_form = "marrone", where it replaces F22 (23)'s
// viscous term. Twin of
// src/backend/cpu/terms/marrone_viscosity.rs.
override TERM_MARRONE_VISCOSITY: bool;

fn marrone_viscosity(m_i: f32, m_j: f32, rho_i: f32, rho_j: f32, eta_ij: f32, u: vec3<f32>, d: vec3<f32>, r2: f32, dwdr: f32, r: f32) -> f32 {
    let ud = u.x * d.x + u.y * d.y + u.z * d.z;
    let k = P.solve.viscosity_factor * (m_i * m_j * eta_ij / (rho_i * rho_j));
    return k * (ud / (r2 + P.kernel.eta2)) * (dwdr / r);
}
