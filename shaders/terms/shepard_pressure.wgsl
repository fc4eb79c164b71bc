// R18 (3.17), Colagrossi's free-surface pressure gradient with the symmetrised
// Shepard renormalisation: a_i = -sum_j m_j/(rho_i rho_j) (p_j/G_i + p_i/G_j)
// grad_i W_ij (R18 prints it as <(1/rho) grad p>; it is the acceleration). The
// force on i is s d with the s returned (d = r_i - r_j). On in delta_wcsph
// scenes, where it replaces F22 (23)'s pressure term. Twin of
// src/backend/cpu/terms/shepard_pressure.rs.
override TERM_SHEPARD_PRESSURE: bool;

fn shepard_pressure(m_i: f32, m_j: f32, rho_i: f32, rho_j: f32, p_i: f32, p_j: f32, gamma_i: f32, gamma_j: f32, dwdr: f32, r: f32) -> f32 {
    let mm = m_i * m_j / (rho_i * rho_j);
    let pp = p_j / gamma_i + p_i / gamma_j;
    return -(mm * pp) * (dwdr / r);
}
