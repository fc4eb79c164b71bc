//! R18 (3.17), Colagrossi's free-surface pressure gradient with the symmetrised
//! Shepard renormalisation Γ:
//!   a_i = −Σ_j m_j/(ρ_i ρ_j) (p_j/Γ_i + p_i/Γ_j) ∇_iW_ij
//! (R18 prints the right-hand side as ⟨(1/ρ)∇p⟩; it is the acceleration). Returns
//! s with the force on i = s d (d = r_i − r_j). Replaces F22 (23)'s pressure term
//! in `delta_wcsph` scenes: first-order consistent and conservative at a free
//! surface, where Γ < 1. Twin of shaders/terms/shepard_pressure.wgsl.

#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn shepard_pressure(
    m_i: f32,
    m_j: f32,
    rho_i: f32,
    rho_j: f32,
    p_i: f32,
    p_j: f32,
    gamma_i: f32,
    gamma_j: f32,
    dwdr: f32,
    r: f32,
) -> f32 {
    let mm = m_i * m_j / (rho_i * rho_j);
    let pp = p_j / gamma_i + p_i / gamma_j;
    -(mm * pp) * (dwdr / r)
}
