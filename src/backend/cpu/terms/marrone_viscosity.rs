//! R18 (3.18), the Monaghan–Gingold viscous term in Marrone's multiphase form:
//!   a_i = K Σ_j m_j μ_ij/(ρ_i ρ_j) (u_ij·r_ij)/(r_ij² + η²) ∇_iW_ij,
//! K = 2 (d + 2), μ_ij = 2 μ_i μ_j/(μ_i + μ_j) (F22 (23)'s pair viscosity: 0
//! against a free-slip wall), η² = 0.01 h². R18 prints μ_i μ_j/(μ_i + μ_j) and
//! a scalar where an acceleration is meant; with the harmonic mean the term is
//! (μ/ρ)(∇²u + 2∇(∇·u)) in the continuum, by its fourth kernel moment; on a
//! lattice that moment converges slowly with h/Δx: for u = (y², 0) the sum
//! gives 0.83 ∇²u at h = Δx (quintic), 0.92 at 1.2 Δx, 0.97 at 1.5 Δx, 0.99 at
//! 2 Δx, where F22's (Morris) form gives 1.001 at h = Δx (poiseuille_2d under
//! delta_wcsph: 13% L2 error with this term, 0.44% with Morris's). So it is an
//! option (`simulation.viscosity_form = "marrone"`), not the default. Returns s
//! with the force on i = s d. Twin of shaders/terms/marrone_viscosity.wgsl.

use crate::params::Params;

#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn marrone_viscosity(
    pr: &Params,
    m_i: f32,
    m_j: f32,
    rho_i: f32,
    rho_j: f32,
    eta_ij: f32,
    u: [f32; 3],
    d: [f32; 3],
    r2: f32,
    dwdr: f32,
    r: f32,
) -> f32 {
    let ud = u[0] * d[0] + u[1] * d[1] + u[2] * d[2];
    let k = pr.solve.viscosity_factor * (m_i * m_j * eta_ij / (rho_i * rho_j));
    k * (ud / (r2 + pr.kernel.eta2)) * (dwdr / r)
}
