//! F22 (33) solid–fluid artificial viscosity: on particles of a melting liquid,
//!   α_i^sf = α_0^sf f̄[T_i, T_s, T_s + ΔT_d] = α_0^sf (1 − clamp((T_i − T_s)/ΔT_d, 0, 1)),
//! T_s the phase's solidus (F22's T_m; our materials melt over a band), in F22
//! (31)'s form (`interface_viscosity`, linear in α, so F22's α^lg + α^sf is the
//! sum of the two terms). Fluid pairs take ᾱ_ij = (α_i^sf + α_j^sf)/2; a wall or
//! solid neighbour (the substrate the melt freezes onto) takes α_i^sf alone, with
//! the wall treatment's mass, density and no-slip velocity, so the melt near its
//! solidus is damped against the solid as against itself. Its dissipation is not
//! added to the viscous heating. Twin of shaders/terms/solid_fluid_viscosity.wgsl.

use crate::params::{Params, HEAT_MELTS};

/// α_i^sf of a particle of `phase` at temperature `t` (0 unless it melts).
#[inline(always)]
#[allow(clippy::manual_clamp)]
pub fn solid_fluid_viscosity_alpha(pr: &Params, phase: u32, t: f32) -> f32 {
    let ph = pr.phase(phase);
    if ph.flags & HEAT_MELTS == 0 {
        return 0.0;
    }
    let f = ((t - ph.solidus) * pr.flow.solid_fluid_inv_width)
        .max(0.0)
        .min(1.0);
    pr.flow.solid_fluid_viscosity * (1.0 - f)
}

/// The factor of r_ij in the force on i: F22 (31) with ᾱ_ij^sf.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn solid_fluid_viscosity(
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
    super::interface_viscosity(
        pr, m_i, m_j, rho_i, rho_j, c2_i, c2_j, u, d, r2, dwdr, alpha,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::HEAT_MELTS;
    use bytemuck::Zeroable;

    /// F22 (33)'s ramp: α_0^sf at and below the solidus, half way at
    /// T_s + ΔT_d/2, 0 from T_s + ΔT_d on; 0 on a phase that does not melt.
    #[test]
    fn alpha_ramps_down_over_the_band_above_the_solidus() {
        let mut pr = Params::zeroed();
        pr.flow.solid_fluid_viscosity = 1.0;
        pr.flow.solid_fluid_inv_width = 1.0 / 300.0;
        pr.phases[0].flags = HEAT_MELTS;
        pr.phases[0].solidus = 1695.0;
        let a = |t: f32| solid_fluid_viscosity_alpha(&pr, 0, t);
        assert_eq!(a(1500.0), 1.0);
        assert_eq!(a(1695.0), 1.0);
        assert!((a(1845.0) - 0.5).abs() < 1e-6);
        assert_eq!(a(1995.0), 0.0);
        assert_eq!(a(2500.0), 0.0);
        assert_eq!(solid_fluid_viscosity_alpha(&pr, 1, 1500.0), 0.0);
    }
}
