//! Surface-force figures of a `/diagnostics` record.

use crate::model::Model;
use crate::scene::PhaseKind;
use crate::state::State;
use serde::Serialize;

/// Surface-force diagnostics: the liquid's surface as the interface
/// pass sees it (Σ V δ over liquid particles with a normal: m² in 3D, m per metre
/// of depth in 2D), its δ-weighted mean curvature (1/m; scenes with surface
/// tension, 0 otherwise; on δ-SPH without gas over the particles the tension
/// acts on), the power the recoil pressure does on the liquid,
/// Σ V p_v δ (−n·u) (W; W/m in 2D; 0 without recoil), and the largest liquid
/// speed as a capillary number η|u|/α0 (the spurious currents of a scene at
/// rest; 0 without surface tension). In the free-surface form (no gas phase),
/// `interior_normals`: the share of `surface_area` (Σ V δ) on liquid particles
/// whose Shepard sum Γ = Σ V_j W_ij is at least `INTERIOR_SHEPARD`, a full
/// support: particles inside the liquid that particle disorder gave a normal
/// (docs/physics.md, free-surface form, "Disorder"); 0 in the gas form.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SurfaceDiagnostics {
    pub surface_area: f64,
    pub mean_curvature: f64,
    pub recoil_power: f64,
    pub capillary_number: f64,
    pub interior_normals: f64,
}

pub use crate::state::INTERIOR_SHEPARD;

/// The surface figures of `st`; None in scenes without surface tension or recoil.
pub fn surface_diagnostics(m: &Model, st: &State) -> Option<SurfaceDiagnostics> {
    let any_recoil = m.phases.iter().any(|p| p.recoil().is_some());
    if st.surface.is_empty() || (m.surface_tension.is_none() && !any_recoil) {
        return None;
    }
    let n = st.len();
    let mut d = SurfaceDiagnostics {
        surface_area: 0.0,
        mean_curvature: 0.0,
        recoil_power: 0.0,
        capillary_number: 0.0,
        interior_normals: 0.0,
    };
    let mut interior_area = 0.0f64;
    let mut curvature_area = 0.0f64;
    let skips_interior = m.csf_skips_interior();
    let mut fastest: f64 = 0.0;
    for i in 0..st.active() {
        let ph = &m.phases[st.phase[i] as usize];
        let s = st.surface[i];
        if ph.kind == PhaseKind::Liquid {
            let v = st.vel[i];
            fastest = fastest.max((0..3).map(|a| (v[a] as f64).powi(2)).sum::<f64>().sqrt());
        }
        if ph.kind != PhaseKind::Liquid || s[3] == 0.0 {
            continue;
        }
        let area = st.mass[i] as f64 / ph.rho0 * s[3] as f64;
        let curvature = st.surface[n + i][crate::state::S_CURVATURE];
        let interior = st.surface[n + i][crate::state::S_SHEPARD] >= INTERIOR_SHEPARD;
        if interior {
            interior_area += area;
        }
        d.surface_area += area;
        // On δ-SPH the tension skips most interior particles
        // (backend::cpu::surface_forces::bears_tension), and their curvature
        // slot stays at the 0 the Shepard pass wrote: not part of the mean.
        if !(skips_interior && interior && curvature == 0.0) {
            curvature_area += area;
            d.mean_curvature += area * curvature as f64;
        }
        if let Some(e) = ph.recoil() {
            let v = st.vel[i];
            let un = (0..3).map(|a| s[a] as f64 * v[a] as f64).sum::<f64>();
            d.recoil_power -= area * e.pressure(st.heat[i][1] as f64) * un;
        }
    }
    if m.surface_tension.is_some() && curvature_area > 0.0 {
        d.mean_curvature /= curvature_area;
    } else {
        d.mean_curvature = 0.0;
    }
    if m.free_surface_interface() && d.surface_area > 0.0 {
        d.interior_normals = interior_area / d.surface_area;
    }
    if let Some(t) = &m.surface_tension {
        d.capillary_number = m.phases[t.liquid].viscosity * fastest / t.coefficient;
    }
    Some(d)
}
