//! Transport-velocity background pressure (Adami 2013):
//!   a_b,i = −(p_b/m_i) Σ_j (V_i² + V_j²) ∂W/∂r e_ij,
//! this being the factor −p_b (∂W/∂r)/r of r_ij. Used only when p_b ≠ 0: with
//! p_b = 0 every term is ±0 and the sum stays +0. Twin of
//! shaders/terms/background_pressure.wgsl.

use crate::lanes::Lane;

/// On one neighbour or on eight (`Lane`), with the same operations.
#[inline(always)]
pub fn background_pressure<R: Lane>(pb: R, dwdr: R, r: R) -> R {
    -pb * dwdr / r
}
