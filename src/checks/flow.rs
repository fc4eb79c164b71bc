//! Flow checks: hydrostatic pressure under gravity, and the start-up Poiseuille
//! and Couette velocity profiles against their series solutions.

use super::{g_mag, liquid_rho0, particles, Check, Verdict};
use crate::model::Model;
use crate::scene::PhaseKind;
use crate::state::State;
use std::f64::consts::PI;

/// Hydrostatic pressure below a free surface at height `surface`.
pub struct Hydrostatic {
    pub surface: f64,
    /// Particles closer than this to the surface are left out (m).
    pub exclude: f64,
}

impl Check for Hydrostatic {
    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        hydrostatic(m, st, self.surface, self.exclude).into()
    }
}

impl Check for Profile {
    fn verdict(&mut self, m: &Model, st: &State) -> Verdict {
        profile_error(m, st, *self).into()
    }
}

/// RMS deviation from p = ρ0 g (H − z), relative to ρ0 g H, over liquid particles
/// deeper than `exclude` below the surface (summation density is deficient within
/// one kernel support of a free surface: docs/physics.md, formulation `wcsph`).
fn hydrostatic(m: &Model, st: &State, surface: f64, exclude: f64) -> (String, f64, Vec<String>) {
    let ax = m.dim as usize - 1;
    let rho0 = liquid_rho0(m);
    let g = g_mag(m);
    let depth = surface - m.domain_lo[ax];
    let (mut se, mut n) = (0.0, 0usize);
    for p in particles(m, st).filter(|p| p.kind == PhaseKind::Liquid && p.x[ax] < surface - exclude)
    {
        let reference = rho0 * g * (surface - p.x[ax]);
        se += (p.p - reference).powi(2);
        n += 1;
    }
    let err = (se / n.max(1) as f64).sqrt() / (rho0 * g * depth);
    let details = vec![format!(
        "  {n} particles compared; bottom pressure reference {:.4e} Pa",
        rho0 * g * depth
    )];
    ("rms pressure error / (rho g H)".into(), err, details)
}

/// The start-up profile between plates at y = 0 and y = L.
#[derive(Clone, Copy)]
pub enum Profile {
    Poiseuille,
    Couette,
}

/// Relative L2 error of u_x(y, t) over all liquid particles against the series
/// solutions (Morris et al. 1997), plates at y = 0 and y = L.
fn profile_error(m: &Model, st: &State, which: Profile) -> (String, f64, Vec<String>) {
    let t = st.sim.time as f64;
    let l = m.domain_hi[1] - m.domain_lo[1];
    let liquid = m
        .phases
        .iter()
        .find(|p| p.kind == PhaseKind::Liquid)
        .unwrap();
    let nu = liquid.viscosity / liquid.rho0;
    let lid = m
        .phases
        .iter()
        .filter(|p| p.kind == PhaseKind::Wall)
        .map(|p| p.velocity[0])
        .fold(0.0, |a: f64, v| if v.abs() > a.abs() { v } else { a });
    let f = m.gravity[0];
    let reference = |y: f64| -> f64 {
        let mut u = match which {
            Profile::Poiseuille => f / (2.0 * nu) * y * (l - y),
            Profile::Couette => lid * y / l,
        };
        for k in 0..200 {
            let kk = k as f64;
            u += match which {
                Profile::Poiseuille => {
                    let n = 2.0 * kk + 1.0;
                    -4.0 * f * l * l / (nu * PI.powi(3) * n.powi(3))
                        * (n * PI * y / l).sin()
                        * (-(n * n) * PI * PI * nu * t / (l * l)).exp()
                }
                Profile::Couette => {
                    let n = kk + 1.0;
                    2.0 * lid / (n * PI)
                        * (-1f64).powi(n as i32)
                        * (n * PI * y / l).sin()
                        * (-(n * n) * PI * PI * nu * t / (l * l)).exp()
                }
            };
        }
        u
    };
    let (mut num, mut den) = (0.0, 0.0);
    for p in particles(m, st).filter(|p| p.kind == PhaseKind::Liquid) {
        let y = p.x[1] - m.domain_lo[1];
        let r = reference(y);
        num += (p.v[0] - r).powi(2);
        den += r * r;
    }
    let name = match which {
        Profile::Poiseuille => "velocity profile L2 error vs series",
        Profile::Couette => "velocity profile L2 error vs series",
    };
    let centre = reference(0.5 * l);
    (
        name.into(),
        (num / den).sqrt(),
        vec![format!(
            "  t = {t:.4e} s, reference centre-line velocity {centre:.4e} m/s"
        )],
    )
}
