//! Phases and their materials: flow properties, the phase table, interface
//! viscosity and the phase changes melting and solidification make.

use super::*;

#[derive(Debug, Clone)]
pub struct PhaseInfo {
    pub name: String,
    pub kind: PhaseKind,
    pub material: String,
    pub rho0: f64,
    pub sound_speed: f64,
    pub viscosity: f64,
    pub slip: Slip,
    pub velocity: [f64; 3],
    /// A wall whose particles move with `velocity` (scene key `moves`).
    pub moves: bool,
    /// Particle mass ρ0 Δx^d (F22 Remark 2).
    pub mass: f64,
    pub thermal: Option<Thermal>,
    /// Phase change: the phase a solid becomes when it melts, or a liquid when it
    /// solidifies.
    pub switch_to: Option<usize>,
    /// ρ0(T) (`materials.<m>.density_law`, δ-SPH): `rho0` is then the nominal value.
    pub density_law: Option<super::expansion::DensityLaw>,
}

/// Heat properties of a phase (heat scenes only).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thermal {
    /// Initial temperature, or the fixed temperature of a Dirichlet wall (K).
    pub temperature: f64,
    pub conductivity: f64,
    pub heat_capacity: f64,
    /// (solidus, liquidus, latent heat) when the material melts.
    pub melting: Option<(f64, f64, f64)>,
    /// Liquid-state (conductivity, heat capacity); equal to the solid's unless given.
    pub liquid: (f64, f64),
    /// Surface losses (liquid and solid free surfaces).
    pub evaporation: Option<Evaporation>,
    pub emissivity: f64,
    /// Mushy-zone sink C (1/s), 0 for none.
    pub mushy_damping: f64,
    /// `temperature_wave`: T(x) = temperature + amplitude cos(2π x_axis / wavelength).
    pub wave: Option<TemperatureWave>,
    /// `temperature_program`: T(t) imposed instead of the heat equation.
    pub program: Option<super::expansion::TemperatureProgram>,
    /// `enthalpy_table`: h(T) (J/kg) in place of heat_capacity and latent_heat;
    /// `heat_capacity` then holds its smallest slope and `liquid.1` its last
    /// (the conduction limit and the evaporation loss's c_p).
    pub enthalpy_table: Option<LawTable>,
    /// `conductivity_table`: λ(T); `conductivity` and `liquid.0` then hold its
    /// largest value (the conduction limit).
    pub conductivity_table: Option<LawTable>,
}

/// Most points a material's h(T) or λ(T) table takes (two rows of four in the
/// parameter block, as the density law).
pub const MAX_LAW_POINTS: usize = 8;

/// A piecewise-linear law y(T) through `n` points (T rising).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawTable {
    pub points: [(f64, f64); MAX_LAW_POINTS],
    pub n: usize,
}

impl LawTable {
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points[..self.n]
    }
    /// The slope of segment k (k = n − 1: the last segment's again).
    pub fn slope(&self, k: usize) -> f64 {
        let k = k.min(self.n - 2);
        let (a, b) = (self.points[k], self.points[k + 1]);
        (b.1 - a.1) / (b.0 - a.0)
    }
    /// y(T), continued along the end segments.
    pub fn extrapolated(&self, t: f64) -> f64 {
        let k = (1..self.n).rfind(|&i| t >= self.points[i].0).unwrap_or(0);
        self.points[k].1 + self.slope(k) * (t - self.points[k].0)
    }
    /// y(T), held at the end values beyond.
    pub fn clamped(&self, t: f64) -> f64 {
        let (lo, hi) = (self.points[0], self.points[self.n - 1]);
        if t <= lo.0 {
            lo.1
        } else if t >= hi.0 {
            hi.1
        } else {
            self.extrapolated(t)
        }
    }
}

/// A cosine temperature along one axis (`phases.<name>.temperature_wave`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TemperatureWave {
    pub amplitude: f64,
    pub wavelength: f64,
    pub axis: usize,
}

/// F22 (10), (18) constants: the scenario's table, once validated.
pub use crate::scene::EvaporationDef as Evaporation;

impl Evaporation {
    /// Recoil pressure p_v(T) F22 (10).
    pub fn pressure(&self, t: f64) -> f64 {
        self.pressure_constant
            * (-self.temperature_constant * (1.0 / t - 1.0 / self.boiling_temperature)).exp()
    }
    /// Heat lost per unit area, ṁ (h_v + c_p (T − T_h0)) F22 (18).
    pub fn flux(&self, t: f64, cp: f64) -> f64 {
        let mdot = 0.82 * self.sticking * self.pressure(t) * (self.vapor_constant / t).sqrt();
        mdot * (self.latent_heat + cp * (t - self.enthalpy_reference))
    }
}

impl Thermal {
    /// The initial (or, on a Dirichlet wall, fixed) temperature at position x.
    pub fn temperature_at(&self, x: [f64; 3]) -> f64 {
        match self.wave {
            None => self.temperature,
            Some(w) => {
                self.temperature
                    + w.amplitude * (std::f64::consts::TAU * x[w.axis] / w.wavelength).cos()
            }
        }
    }
    /// The lowest temperature the phase starts with.
    pub fn coldest(&self) -> f64 {
        self.temperature - self.wave.map_or(0.0, |w| w.amplitude)
    }
    /// The temperature whose enthalpy is stored as zero: the solidus for a melting
    /// material (so phases that switch into each other share it), else the phase's
    /// initial temperature. Particles store h − h(T_ref): f32 then resolves the
    /// enthalpy changes a run makes far more finely than absolute enthalpies near
    /// c_p T (adiabatic_box with temperature-dependent properties drifted 2.8e-6
    /// over 10^4 steps with absolute enthalpies).
    pub fn reference_temperature(&self) -> f64 {
        self.melting.map_or(self.temperature, |m| m.0)
    }
    /// h(T_ref), added back to the stored enthalpy for totals and output.
    pub fn reference_enthalpy(&self) -> f64 {
        self.enthalpy(self.reference_temperature())
    }
    /// Specific enthalpy h(T) = ∫_0^T c_p dT + L f_l(T) (J22 (19)): c_p is the
    /// solid's below the solidus, the liquid's above the liquidus and linear in
    /// between, where the latent heat is spread linearly too; or the material's
    /// `enthalpy_table`.
    pub fn enthalpy(&self, t: f64) -> f64 {
        if let Some(table) = &self.enthalpy_table {
            return table.extrapolated(t);
        }
        let cs = self.heat_capacity;
        let Some((ts, tl, l)) = self.melting else {
            return cs * t;
        };
        let cl = self.liquid.1;
        let dt = tl - ts;
        if t <= ts {
            cs * t
        } else if t < tl {
            let x = t - ts;
            cs * t + (cl - cs) * x * x / (2.0 * dt) + l * x / dt
        } else {
            cs * tl + (cl - cs) * dt / 2.0 + l + cl * (t - tl)
        }
    }
}

impl PhaseInfo {
    /// The reference density at temperature t: the density law's, else ρ0.
    pub fn rho0_at(&self, t: f64) -> f64 {
        self.density_law.as_ref().map_or(self.rho0, |l| l.at(t))
    }
    /// The evaporation law of a liquid phase that takes the F22 (30) recoil.
    pub fn recoil(&self) -> Option<Evaporation> {
        self.thermal
            .and_then(|t| t.evaporation)
            .filter(|e| e.recoil && self.kind == PhaseKind::Liquid)
    }
    /// Liquid or gas: moves with the flow.
    pub fn is_fluid(&self) -> bool {
        matches!(self.kind, PhaseKind::Liquid | PhaseKind::Gas)
    }
    /// Carries a temperature that evolves (fluids and solids in heat scenes).
    pub fn conducts(&self) -> bool {
        self.kind != PhaseKind::Wall && self.thermal.is_some()
    }
}

pub(super) fn phase_table(
    cx: &Ctx,
    scene: &SceneFile,
    dim: u32,
    dx: f64,
) -> Result<Vec<PhaseInfo>, InputError> {
    if scene.phases.len() > MAX_PHASES {
        return Err(cx.err(
            "phases",
            format!("at most {MAX_PHASES} phases are supported"),
        ));
    }
    let mut out = Vec::new();
    for (name, p) in &scene.phases {
        let key = |k: &str| format!("phases.{name}.{k}");
        let Some(mat) = scene.materials.get(&p.material) else {
            return Err(cx.err(
                &key("material"),
                format!("no material named `{}`", p.material),
            ));
        };
        let mkey = |k: &str| format!("materials.{}.{k}", p.material);
        let rho0 = cx.positive(&mkey("density"), mat.density)?;
        let viscosity = cx.non_negative(&mkey("viscosity"), mat.viscosity)?;
        let sound_speed = match (mat.sound_speed, mat.reference_pressure) {
            (Some(c), None) => cx.positive(&mkey("sound_speed"), c)?,
            (None, Some(p0)) => (cx.positive(&mkey("reference_pressure"), p0)? / rho0).sqrt(),
            (Some(_), Some(_)) => {
                return Err(cx.err(
                    &mkey("sound_speed"),
                    "give sound_speed or reference_pressure, not both",
                ))
            }
            (None, None) => {
                return Err(cx.err(
                    &mkey("sound_speed"),
                    "missing: give sound_speed or reference_pressure",
                ))
            }
        };
        let sound_speed = match p.sound_speed {
            None => sound_speed,
            Some(c) if matches!(p.kind, PhaseKind::Liquid | PhaseKind::Gas) => {
                cx.positive(&key("sound_speed"), c)?
            }
            Some(_) => {
                return Err(cx.err(
                    &key("sound_speed"),
                    "only fluid (liquid, gas) phases compress: solids and walls have no sound speed of their own",
                ))
            }
        };
        let velocity = match &p.velocity {
            Some(v) if p.kind == PhaseKind::Wall => cx.vector(&key("velocity"), v, dim)?,
            Some(_) => {
                return Err(cx.err(
                    &key("velocity"),
                    "only wall phases take a prescribed velocity",
                ))
            }
            None => [0.0; 3],
        };
        if p.moves && (p.kind != PhaseKind::Wall || p.velocity.is_none()) {
            return Err(cx.err(&key("moves"), "only a wall phase with a velocity can move"));
        }
        out.push(PhaseInfo {
            name: name.clone(),
            kind: p.kind,
            material: p.material.clone(),
            rho0,
            sound_speed,
            viscosity,
            slip: p.slip,
            velocity,
            moves: p.moves,
            mass: rho0 * dx.powi(dim as i32),
            thermal: None,
            switch_to: None,
            density_law: None,
        });
    }
    thermal_table(cx, scene, &mut out)?;
    phase_changes(cx, scene, &mut out)?;
    super::expansion::expansion_table(cx, scene, &mut out)?;
    Ok(out)
}

/// Solid ↔ liquid pairs from `melts_into`: same material, one that melts.
fn phase_changes(cx: &Ctx, scene: &SceneFile, phases: &mut [PhaseInfo]) -> Result<(), InputError> {
    for s in 0..phases.len() {
        let def = &scene.phases[&phases[s].name];
        let Some(target) = &def.melts_into else {
            continue;
        };
        let key = format!("phases.{}.melts_into", phases[s].name);
        if phases[s].kind != PhaseKind::Solid {
            return Err(cx.err(&key, "only solid phases melt"));
        }
        let Some(l) = phases.iter().position(|p| &p.name == target) else {
            return Err(cx.err(&key, format!("no phase named `{target}`")));
        };
        if phases[l].kind != PhaseKind::Liquid {
            return Err(cx.err(&key, format!("`{target}` is not a liquid phase")));
        }
        if phases[l].material != phases[s].material {
            return Err(cx.err(
                &key,
                "the solid and the liquid must share a material (one melting band)",
            ));
        }
        if phases[s].thermal.and_then(|t| t.melting).is_none() {
            return Err(cx.err(
                &key,
                format!(
                    "material `{}` has no solidus/liquidus/latent_heat",
                    phases[s].material
                ),
            ));
        }
        if phases[l].switch_to.is_some_and(|o| o != s) {
            return Err(cx.err(
                &key,
                format!("`{target}` already solidifies into another phase"),
            ));
        }
        phases[s].switch_to = Some(l);
        phases[l].switch_to = Some(s);
    }
    Ok(())
}

/// The kinematic viscosity F22 (31) acts with at most: the artificial-viscosity
/// term equals a shear viscosity ν = α h c/(2(d + 2)) (Monaghan 2005), and
/// α = α_0^lg min(h δ, 1) ≤ α_0^lg (backend/cpu/forces.rs), so the viscous limit
/// 0.125 h²/ν covers it.
/// The kinematic viscosity F22 (31) with coefficient α amounts to, α h c/(2(d + 2))
/// (Monaghan 2005), at the fastest fluid's sound speed: the viscous Δt limit's.
pub(super) fn artificial_nu(alpha: f64, fluid: &[&PhaseInfo], dim: u32, h: f64) -> f64 {
    let c_max = fluid.iter().map(|p| p.sound_speed).fold(0.0, f64::max);
    alpha * h * c_max / (2.0 * (dim as f64 + 2.0))
}

/// `simulation.solid_fluid_viscosity`: F22 (33), for heat scenes with a liquid
/// that melts.
pub(super) fn solid_fluid_viscosity(
    cx: &Ctx,
    sim: &crate::scene::Simulation,
    phases: &[PhaseInfo],
) -> Result<Option<(f64, f64)>, InputError> {
    let Some(d) = sim.solid_fluid_viscosity else {
        return Ok(None);
    };
    let key = "simulation.solid_fluid_viscosity";
    let alpha = cx.positive(&format!("{key}.coefficient"), d.coefficient)?;
    let width = cx.positive(&format!("{key}.width"), d.width)?;
    let melts = phases
        .iter()
        .any(|p| p.kind == PhaseKind::Liquid && p.thermal.and_then(|t| t.melting).is_some());
    if !melts {
        return Err(cx.err(
            key,
            "acts on a melting liquid between its solidus and solidus + width: the scene needs a liquid phase whose material melts (heat scene)",
        ));
    }
    Ok(Some((alpha, width)))
}

pub(super) fn interface_viscosity_nu(
    cx: &Ctx,
    sim: &crate::scene::Simulation,
    fluid: &[&PhaseInfo],
    dim: u32,
    h: f64,
    dx: f64,
) -> Result<f64, InputError> {
    let key = "simulation.interface_viscosity";
    let alpha = cx.non_negative(key, sim.interface_viscosity.alpha(dx))?;
    if alpha == 0.0 {
        return Ok(0.0);
    }
    // F22 (31)-(32) at the liquid-gas interface, or at the liquid's free surface
    // in a scene without gas (δ of the free-surface form).
    if !fluid.iter().any(|p| p.kind == PhaseKind::Liquid) {
        return Err(cx.err(
            key,
            "acts at a liquid's surface (with gas or free): the scene needs a liquid phase",
        ));
    }
    Ok(artificial_nu(alpha, fluid, dim, h))
}
