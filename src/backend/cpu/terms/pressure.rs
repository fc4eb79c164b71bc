//! Pressure term of F22 (23): with p̃ = (ρ_j p_i + ρ_i p_j)/(ρ_i + ρ_j), the force
//! on i along r_ij per (V_i² + V_j²) is −p̃ (∂W/∂r)/r. Twin of
//! shaders/terms/pressure.wgsl.

use crate::lanes::Lane;

/// On one neighbour or on eight (`Lane`), with the same operations.
#[inline(always)]
pub fn pressure<R: Lane>(p_i: R, p_j: R, rho_i: R, rho_j: R, dwdr: R, r: R) -> R {
    let p_avg = (rho_j * p_i + rho_i * p_j) / (rho_i + rho_j);
    -p_avg * dwdr / r
}
