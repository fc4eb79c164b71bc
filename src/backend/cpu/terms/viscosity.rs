//! Viscous term of F22 (23): η̃ (∂W/∂r)/r per (V_i² + V_j²), times u_ij, with
//! η̃ = 2η_iη_j/(η_i + η_j), 0 against a free-slip wall or when both are inviscid.
//! Twin of shaders/terms/viscosity.wgsl. The CPU sweep reads η̃ from a table built
//! with `pair_viscosity` per phase pair (same operands, same bits).

use crate::lanes::Lane;

#[inline(always)]
pub fn pair_viscosity(eta_i: f32, eta_j: f32, slip: bool) -> f32 {
    let eta_sum = eta_i + eta_j;
    if eta_sum > 0.0 && !slip {
        2.0 * eta_i * eta_j / eta_sum
    } else {
        0.0
    }
}

/// On one neighbour or on eight (`Lane`), with the same operations.
#[inline(always)]
pub fn viscosity<R: Lane>(eta_avg: R, dwdr: R, r: R) -> R {
    eta_avg * dwdr / r
}
