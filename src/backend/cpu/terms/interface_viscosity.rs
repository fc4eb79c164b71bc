//! F22 (31)–(32) interface viscosity between fluid particles, written so that it
//! dissipates (u_ij·r_ij < 0 repels):
//!   F_d,i = m_i Σ_j m_j ᾱ_ij h c̄_ij/ρ̄_ij (u_ij·r_ij)/(r_ij² + 0.01 h²) ∂W/∂r e_ij,
//!   α_i = α_0^lg min(h δ_i, 1) (δ from the interface pass), ᾱ_ij = (α_i + α_j)/2:
//! the pair mean where F22 writes α_i, so that momentum is conserved pairwise, and
//! h δ capped at 1 so that α ≤ α_0^lg, the bound the viscous Δt limit uses
//! (h δ exceeds 1 only at wall–liquid–gas corners: 1.05 measured in two_layer_2d).
//! Its dissipation is not added to the viscous heating. Twin of
//! shaders/terms/interface_viscosity.wgsl.

use crate::params::Params;

/// α_i = α_0^lg min(h δ_i, 1).
#[inline(always)]
pub fn interface_viscosity_alpha(pr: &Params, delta: f32) -> f32 {
    pr.flow.interface_viscosity * (pr.kernel.h * delta).min(1.0)
}

/// The factor of r_ij in the force on i.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn interface_viscosity(
    pr: &Params,
    m_i: f32,
    m_j: f32,
    rho_i: f32,
    rho_j: f32,
    c2_i: f32,
    c2_j: f32,
    u: [f32; 3],
    d: [f32; 3],
    r2: f32,
    dwdr: f32,
    alpha: f32,
) -> f32 {
    let c = (c2_i.sqrt() + c2_j.sqrt()) * 0.5;
    let rho_m = (rho_i + rho_j) * 0.5;
    let ur = u[0] * d[0] + u[1] * d[1] + u[2] * d[2];
    let r = r2.sqrt();
    m_i * m_j * alpha * pr.kernel.h * c / rho_m * ur / (r2 + pr.kernel.eta2) * dwdr / r
}
