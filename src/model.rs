//! A validated scene: every derived constant the solver needs, checked for physical
//! sense, plus the host-side time-step limits (F22 (42)).

use crate::error::InputError;
use crate::scene::{
    CheckDef, Formulation, InitialPressure, KernelKind, PhaseKind, SceneFile, Slip, WatchdogDef,
};

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
    /// between, where the latent heat is spread linearly too.
    pub fn enthalpy(&self, t: f64) -> f64 {
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
    /// Liquid or gas: moves with the flow.
    pub fn is_fluid(&self) -> bool {
        matches!(self.kind, PhaseKind::Liquid | PhaseKind::Gas)
    }
    /// Carries a temperature that evolves (fluids and solids in heat scenes).
    pub fn conducts(&self) -> bool {
        self.kind != PhaseKind::Wall && self.thermal.is_some()
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EndCondition {
    Time(f64),
    Steps(u64),
}

/// Host-side F22 (42) limits with zero velocity; the device recomputes the acoustic
/// and force limits every step from the current maxima.
#[derive(Debug, Clone, Copy)]
pub struct DtLimits {
    pub acoustic: f64,
    pub viscous: f64,
    pub body_force: f64,
    /// 0.1 ρ c_p h²/k over conducting phases (issue 4); ∞ without heat.
    pub conduction: f64,
}

impl DtLimits {
    pub fn min(&self) -> (f64, &'static str) {
        let mut best = (self.acoustic, "acoustic CFL 0.25 h/(c+|u|)");
        if self.viscous < best.0 {
            best = (self.viscous, "viscous 0.125 h^2/nu");
        }
        if self.body_force < best.0 {
            best = (self.body_force, "body force 0.25 sqrt(h/|b|)");
        }
        if self.conduction < best.0 {
            best = (self.conduction, "conduction 0.1 rho c_p h^2/k");
        }
        best
    }
}

#[derive(Debug, Clone)]
pub struct Model {
    pub file: String,
    pub resolved_toml: String,
    pub dim: u32,
    pub formulation: Formulation,
    pub kernel: KernelKind,
    pub dx: f64,
    pub h: f64,
    pub support: f64,
    pub domain_lo: [f64; 3],
    pub domain_hi: [f64; 3],
    /// Origin of the cell grid; particle positions are stored relative to it.
    pub origin: [f64; 3],
    pub periodic: [bool; 3],
    /// Sides without wall layers, by axis then (min, max).
    pub open_sides: [[bool; 2]; 3],
    pub grid: [u32; 3],
    pub cell_size: [f64; 3],
    pub wall_layers: u32,
    pub gravity: [f64; 3],
    pub background_pressure: f64,
    pub pressure_floor: bool,
    /// Gravity axis when the fluid starts hydrostatic (`simulation.initial_pressure`).
    pub hydrostatic_axis: Option<usize>,
    /// F22 (32) α_0^lg (0 = off).
    pub interface_viscosity: f64,
    pub viscous_heating: bool,
    pub ambient_temperature: f64,
    pub jitter: f64,
    pub seed: u64,
    pub phases: Vec<PhaseInfo>,
    pub fixed_dt: Option<f64>,
    pub end: EndCondition,
    pub output_interval: f64,
    pub diagnostics_interval: f64,
    pub check: Option<CheckDef>,
    pub watchdog: WatchdogDef,
    pub laser: Option<Laser>,
    pub limits: DtLimits,
}

pub const MAX_PHASES: usize = 8;

impl Model {
    pub fn max_sound_speed(&self) -> f64 {
        self.phases
            .iter()
            .filter(|p| p.is_fluid())
            .map(|p| p.sound_speed)
            .fold(0.0, f64::max)
    }
    pub fn max_kinematic_viscosity(&self) -> f64 {
        self.phases
            .iter()
            .filter(|p| p.is_fluid())
            .map(|p| p.viscosity / p.rho0)
            .fold(0.0, f64::max)
    }
    /// A heat scene: some phase carries a temperature.
    /// Scenes whose physics needs interface normals and the surface delta: the
    /// surface laser and surface losses (evaporation, radiation).
    pub fn needs_interface(&self) -> bool {
        let surface_laser = self
            .laser
            .as_ref()
            .is_some_and(|l| l.model == crate::scene::LaserModel::GaussianSurface);
        surface_laser || self.has_surface_losses() || self.interface_viscosity > 0.0
    }
    pub fn has_surface_losses(&self) -> bool {
        self.phases
            .iter()
            .filter_map(|p| p.thermal)
            .any(|t| t.evaporation.is_some() || t.emissivity > 0.0)
    }
    pub fn is_thermal(&self) -> bool {
        self.phases.iter().any(|p| p.thermal.is_some())
    }
    pub fn n_cells(&self) -> u64 {
        self.grid.iter().map(|&g| g as u64).product()
    }
    pub fn phase_index(&self, name: &str) -> Option<usize> {
        self.phases.iter().position(|p| p.name == name)
    }
    /// Convert an absolute position to the stored (grid-relative) one.
    pub fn to_local(&self, x: [f64; 3]) -> [f64; 3] {
        [
            x[0] - self.origin[0],
            x[1] - self.origin[1],
            x[2] - self.origin[2],
        ]
    }
}

struct Ctx<'a> {
    file: &'a str,
}

impl Ctx<'_> {
    fn err(&self, key: &str, msg: impl Into<String>) -> InputError {
        InputError::new(self.file, key, msg)
    }
    fn positive(&self, key: &str, v: f64) -> Result<f64, InputError> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(key, format!("must be a positive finite number (got {v})")))
        }
    }
    fn non_negative(&self, key: &str, v: f64) -> Result<f64, InputError> {
        if v.is_finite() && v >= 0.0 {
            Ok(v)
        } else {
            Err(self.err(key, format!("must be zero or positive (got {v})")))
        }
    }
    fn vector(&self, key: &str, v: &[f64], dim: u32) -> Result<[f64; 3], InputError> {
        if v.len() != dim as usize {
            return Err(self.err(
                key,
                format!(
                    "needs {dim} components for a {dim}D scene (got {})",
                    v.len()
                ),
            ));
        }
        if v.iter().any(|x| !x.is_finite()) {
            return Err(self.err(key, "components must be finite numbers"));
        }
        let mut out = [0.0; 3];
        out[..v.len()].copy_from_slice(v);
        Ok(out)
    }
}

/// Validate a parsed scene and derive all constants.
pub fn build(file: &str, scene: &SceneFile, resolved_toml: &str) -> Result<Model, InputError> {
    let cx = Ctx { file };
    let sim = &scene.simulation;
    if sim.dimension != 2 && sim.dimension != 3 {
        return Err(cx.err(
            "simulation.dimension",
            format!("must be 2 or 3 (got {})", sim.dimension),
        ));
    }
    let dim = sim.dimension;
    let dx = cx.positive("simulation.dx", sim.dx)?;
    let h_over_dx = sim.h_over_dx.unwrap_or(sim.kernel.default_h_over_dx());
    cx.positive("simulation.h_over_dx", h_over_dx)?;
    if !(0.5..=3.0).contains(&h_over_dx) {
        return Err(cx.err(
            "simulation.h_over_dx",
            format!("must lie in [0.5, 3] (got {h_over_dx})"),
        ));
    }
    let h = h_over_dx * dx;
    let support = sim.kernel.support_factor() * h;
    let gravity = if sim.gravity.is_empty() {
        [0.0; 3]
    } else {
        cx.vector("simulation.gravity", &sim.gravity, dim)?
    };
    cx.non_negative("simulation.background_pressure", sim.background_pressure)?;
    if !(0.0..=0.5).contains(&sim.jitter) {
        return Err(cx.err(
            "simulation.jitter",
            format!("must lie in [0, 0.5] (fraction of dx, got {})", sim.jitter),
        ));
    }

    let (domain_lo, domain_hi, periodic) = domain_box(&cx, scene, dim)?;
    let hydrostatic_axis = match sim.initial_pressure {
        InitialPressure::Zero => None,
        InitialPressure::Hydrostatic => Some(hydrostatic_axis(&cx, gravity, periodic)?),
    };
    let phases = phase_table(&cx, scene, dim, dx)?;
    let wall_layers = (support / dx - 1e-9).ceil() as u32;
    let (origin, grid, cell_size) = cell_grid(
        &cx,
        dim,
        domain_lo,
        domain_hi,
        periodic,
        support,
        dx,
        wall_layers,
    )?;
    check_walls(&cx, scene, &phases, dim, periodic)?;

    let fluid: Vec<&PhaseInfo> = phases.iter().filter(|p| p.is_fluid()).collect();
    if fluid.is_empty() && !phases.iter().any(|p| p.conducts()) {
        return Err(cx.err("phases", "the scene has no liquid, gas or solid phase"));
    }
    let conduction = phases
        .iter()
        .filter(|p| p.conducts())
        .map(|p| {
            let t = p.thermal.unwrap();
            0.1 * p.rho0 * t.heat_capacity * h * h / t.conductivity
        })
        .fold(f64::INFINITY, f64::min);
    let c_max = fluid.iter().map(|p| p.sound_speed).fold(0.0, f64::max);
    let nu_max = fluid
        .iter()
        .map(|p| p.viscosity / p.rho0)
        .fold(interface_viscosity_nu(&cx, sim, &fluid, dim, h)?, f64::max);
    let g = (gravity[0] * gravity[0] + gravity[1] * gravity[1] + gravity[2] * gravity[2]).sqrt();
    let limits = DtLimits {
        acoustic: if c_max > 0.0 {
            0.25 * h / c_max
        } else {
            f64::INFINITY
        },
        viscous: if nu_max > 0.0 {
            0.125 * h * h / nu_max
        } else {
            f64::INFINITY
        },
        body_force: if g > 0.0 {
            0.25 * (h / g).sqrt()
        } else {
            f64::INFINITY
        },
        conduction,
    };

    let run = &scene.run;
    let fixed_dt = match run.dt {
        Some(dt) => {
            cx.positive("run.dt", dt)?;
            let (lim, which) = limits.min();
            if dt > lim && run.dt_check.unwrap_or(true) {
                return Err(cx.err(
                    "run.dt",
                    format!(
                        "fixed time step {dt:e} s exceeds the stability limit {lim:e} s ({which})"
                    ),
                ));
            }
            Some(dt)
        }
        None => None,
    };
    let end = match (run.end_time, run.steps) {
        (Some(_), Some(_)) => return Err(cx.err("run", "give end_time or steps, not both")),
        (Some(t), None) => EndCondition::Time(cx.positive("run.end_time", t)?),
        (None, Some(n)) => EndCondition::Steps(n),
        (None, None) => return Err(cx.err("run", "needs end_time or steps")),
    };
    let output_interval = match run.output_interval {
        Some(v) => cx.positive("run.output_interval", v)?,
        None => match end {
            EndCondition::Time(t) => t / 20.0,
            EndCondition::Steps(_) => f64::INFINITY,
        },
    };
    let diagnostics_interval = match run.diagnostics_interval {
        Some(v) => cx.positive("run.diagnostics_interval", v)?,
        None => output_interval,
    };
    if let Some(c) = &scene.check {
        cx.positive("check.tolerance", c.tolerance)?;
    }
    let laser = laser(&cx, scene, dim, &phases)?;
    let wd = &scene.watchdog;
    cx.positive("watchdog.min_density_ratio", wd.min_density_ratio)?;
    cx.positive("watchdog.min_dt_ratio", wd.min_dt_ratio)?;
    cx.positive("watchdog.wall_penetration", wd.wall_penetration)?;
    if !(wd.max_density_ratio > 1.0 && wd.max_density_ratio.is_finite()) {
        return Err(cx.err(
            "watchdog.max_density_ratio",
            format!(
                "must be a finite number above 1 (got {})",
                wd.max_density_ratio
            ),
        ));
    }
    if wd.min_density_ratio >= 1.0 {
        return Err(cx.err(
            "watchdog.min_density_ratio",
            format!("must be below 1 (got {})", wd.min_density_ratio),
        ));
    }

    Ok(Model {
        file: file.to_string(),
        resolved_toml: resolved_toml.to_string(),
        dim,
        formulation: sim.formulation,
        kernel: sim.kernel,
        dx,
        h,
        support,
        domain_lo,
        domain_hi,
        origin,
        periodic,
        open_sides: open_side_flags(scene),
        grid,
        cell_size,
        wall_layers,
        gravity,
        background_pressure: sim.background_pressure,
        viscous_heating: sim.viscous_heating,
        ambient_temperature: cx
            .positive("simulation.ambient_temperature", sim.ambient_temperature)?,
        pressure_floor: sim.pressure_floor,
        hydrostatic_axis,
        interface_viscosity: sim.interface_viscosity,
        jitter: sim.jitter,
        seed: sim.seed,
        phases,
        fixed_dt,
        end,
        output_interval,
        diagnostics_interval,
        check: scene.check.clone(),
        watchdog: scene.watchdog.clone(),
        laser,
        limits,
    })
}

fn domain_box(
    cx: &Ctx,
    scene: &SceneFile,
    dim: u32,
) -> Result<([f64; 3], [f64; 3], [bool; 3]), InputError> {
    let lo = cx.vector("domain.min", &scene.domain.min, dim)?;
    let hi = cx.vector("domain.max", &scene.domain.max, dim)?;
    for a in 0..dim as usize {
        if hi[a] <= lo[a] {
            return Err(cx.err(
                "domain.max",
                format!("must exceed domain.min on every axis (axis {a})"),
            ));
        }
    }
    let mut periodic = [false; 3];
    if !scene.domain.periodic.is_empty() {
        if scene.domain.periodic.len() != dim as usize {
            return Err(cx.err("domain.periodic", format!("needs {dim} entries")));
        }
        periodic[..dim as usize].copy_from_slice(&scene.domain.periodic);
    }
    Ok((lo, hi, periodic))
}

/// The kinematic viscosity F22 (31) acts with at most: the artificial-viscosity
/// term equals a shear viscosity ν = α h c/(2(d + 2)) (Monaghan 2005), and
/// α = α_0^lg min(h δ, 1) ≤ α_0^lg (backend/cpu/forces.rs), so the viscous limit
/// 0.125 h²/ν covers it.
fn interface_viscosity_nu(
    cx: &Ctx,
    sim: &crate::scene::Simulation,
    fluid: &[&PhaseInfo],
    dim: u32,
    h: f64,
) -> Result<f64, InputError> {
    let key = "simulation.interface_viscosity";
    let alpha = cx.non_negative(key, sim.interface_viscosity)?;
    if alpha == 0.0 {
        return Ok(0.0);
    }
    let has = |k: PhaseKind| fluid.iter().any(|p| p.kind == k);
    if !has(PhaseKind::Liquid) || !has(PhaseKind::Gas) {
        return Err(cx.err(
            key,
            "acts at a liquid–gas interface: the scene needs a liquid and a gas phase",
        ));
    }
    let c_max = fluid.iter().map(|p| p.sound_speed).fold(0.0, f64::max);
    Ok(alpha * h * c_max / (2.0 * (dim as f64 + 2.0)))
}

/// The axis a hydrostatic start stacks the fluid along: gravity must point along
/// exactly one axis, and that axis must not be periodic (no top to hang from).
fn hydrostatic_axis(cx: &Ctx, gravity: [f64; 3], periodic: [bool; 3]) -> Result<usize, InputError> {
    let key = "simulation.initial_pressure";
    let axes: Vec<usize> = (0..3).filter(|&a| gravity[a] != 0.0).collect();
    let &[a] = axes.as_slice() else {
        return Err(cx.err(
            key,
            format!(
                "\"hydrostatic\" needs simulation.gravity along exactly one axis (got {gravity:?})"
            ),
        ));
    };
    if periodic[a] {
        return Err(cx.err(
            key,
            format!("\"hydrostatic\" needs a non-periodic gravity axis (axis {a} is periodic)"),
        ));
    }
    Ok(a)
}

fn phase_table(
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
        });
    }
    thermal_table(cx, scene, &mut out)?;
    phase_changes(cx, scene, &mut out)?;
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

/// Heat properties: a scene is a heat scene when any phase has a temperature.
/// Then every non-wall phase needs a temperature, conductivity and heat capacity.
fn thermal_table(cx: &Ctx, scene: &SceneFile, phases: &mut [PhaseInfo]) -> Result<(), InputError> {
    let heat_scene = scene.phases.values().any(|p| p.temperature.is_some());
    for ph in phases.iter_mut() {
        let def = &scene.phases[&ph.name];
        let mat = &scene.materials[&def.material];
        let mkey = |k: &str| format!("materials.{}.{k}", def.material);
        let tkey = format!("phases.{}.temperature", ph.name);
        let Some(t) = def.temperature else {
            if heat_scene && ph.kind != PhaseKind::Wall {
                return Err(cx.err(&tkey, "missing: a heat scene needs the initial temperature of every liquid, gas and solid phase"));
            }
            if ph.kind == PhaseKind::Solid {
                return Err(cx.err(
                    &tkey,
                    "missing: solid phases conduct heat and need a temperature",
                ));
            }
            continue;
        };
        cx.positive(&tkey, t)?;
        if ph.kind == PhaseKind::Wall {
            // A Dirichlet wall takes the conducting particle's own k (J22 (25)).
            ph.thermal = Some(Thermal {
                temperature: t,
                conductivity: 0.0,
                heat_capacity: 0.0,
                melting: None,
                liquid: (0.0, 0.0),
                evaporation: None,
                emissivity: 0.0,
                mushy_damping: 0.0,
            });
            continue;
        }
        let need = |k: &str, v: Option<f64>| -> Result<f64, InputError> {
            match v {
                Some(v) => cx.positive(&mkey(k), v),
                None => Err(cx.err(&mkey(k), "missing: needed by a phase with a temperature")),
            }
        };
        let conductivity = need("conductivity", mat.conductivity)?;
        let heat_capacity = need("heat_capacity", mat.heat_capacity)?;
        let melting = match (mat.solidus, mat.liquidus, mat.latent_heat) {
            (None, None, None) => None,
            (Some(ts), Some(tl), Some(l)) => {
                cx.positive(&mkey("solidus"), ts)?;
                if !(tl > ts && tl.is_finite()) {
                    return Err(cx.err(
                        &mkey("liquidus"),
                        format!("must exceed the solidus {ts} K (got {tl})"),
                    ));
                }
                Some((ts, tl, cx.non_negative(&mkey("latent_heat"), l)?))
            }
            _ => {
                return Err(cx.err(
                    &mkey("solidus"),
                    "give solidus, liquidus and latent_heat together",
                ))
            }
        };
        let evaporation = match &mat.evaporation {
            None => None,
            Some(_) if ph.kind != PhaseKind::Liquid => None,
            Some(e) => {
                let k = |n: &str| mkey(&format!("evaporation.{n}"));
                cx.positive(&k("pressure_constant"), e.pressure_constant)?;
                cx.positive(&k("temperature_constant"), e.temperature_constant)?;
                cx.positive(&k("boiling_temperature"), e.boiling_temperature)?;
                cx.positive(&k("latent_heat"), e.latent_heat)?;
                cx.non_negative(&k("enthalpy_reference"), e.enthalpy_reference)?;
                cx.positive(&k("vapor_constant"), e.vapor_constant)?;
                cx.positive(&k("sticking"), e.sticking)?;
                Some(*e)
            }
        };
        let emissivity = match mat.emissivity {
            Some(e) if !(0.0..=1.0).contains(&e) => {
                return Err(cx.err(&mkey("emissivity"), format!("must lie in [0, 1] (got {e})")))
            }
            Some(e) => e,
            None => 0.0,
        };
        let mushy_damping = match mat.mushy_damping {
            Some(_) if melting.is_none() => {
                return Err(cx.err(
                    &mkey("mushy_damping"),
                    "needs a melting band (solidus, liquidus, latent_heat)",
                ));
            }
            Some(c) => cx.non_negative(&mkey("mushy_damping"), c)?,
            None => 0.0,
        };
        let liquid = match (mat.liquid_conductivity, mat.liquid_heat_capacity) {
            (None, None) => (conductivity, heat_capacity),
            _ if melting.is_none() => {
                return Err(cx.err(
                    &mkey("liquid_conductivity"),
                    "liquid properties need a melting band (solidus, liquidus, latent_heat)",
                ))
            }
            (k, c) => (
                match k {
                    Some(k) => cx.positive(&mkey("liquid_conductivity"), k)?,
                    None => conductivity,
                },
                match c {
                    Some(c) => cx.positive(&mkey("liquid_heat_capacity"), c)?,
                    None => heat_capacity,
                },
            ),
        };
        ph.thermal = Some(Thermal {
            temperature: t,
            conductivity,
            heat_capacity,
            melting,
            liquid,
            evaporation,
            emissivity,
            mushy_damping,
        });
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn cell_grid(
    cx: &Ctx,
    dim: u32,
    lo: [f64; 3],
    hi: [f64; 3],
    periodic: [bool; 3],
    support: f64,
    dx: f64,
    wall_layers: u32,
) -> Result<([f64; 3], [u32; 3], [f64; 3]), InputError> {
    let mut origin = [0.0; 3];
    let mut grid = [1u32; 3];
    let mut cell = [1.0; 3];
    for a in 0..dim as usize {
        let len = hi[a] - lo[a];
        if periodic[a] {
            // Cells tile the period exactly so wrapped neighbours land in whole cells.
            let n = (len / support).floor();
            if n < 3.0 {
                return Err(cx.err(
                    "domain.max",
                    format!("periodic axis {a} must span at least 3 kernel supports ({:.3e} m), got {len:.3e} m", 3.0 * support),
                ));
            }
            let sites = len / dx;
            if (sites - sites.round()).abs() > 1e-6 * sites.max(1.0) {
                return Err(cx.err(
                    "simulation.dx",
                    format!("periodic length {len:e} m along axis {a} is not a multiple of dx"),
                ));
            }
            origin[a] = lo[a];
            grid[a] = n as u32;
            cell[a] = len / n;
        } else {
            let pad = (wall_layers as f64 + 1.0) * dx;
            origin[a] = lo[a] - pad;
            let n = ((len + 2.0 * pad) / support).ceil().max(1.0);
            if n > 1.0e6 {
                return Err(cx.err(
                    "simulation.dx",
                    format!("cell grid too large along axis {a} ({n} cells)"),
                ));
            }
            grid[a] = n as u32;
            cell[a] = support;
        }
    }
    let total: f64 = grid.iter().map(|&g| g as f64).product();
    if total > 4.0e8 {
        return Err(cx.err(
            "simulation.dx",
            format!("cell grid of {total:e} cells does not fit in memory"),
        ));
    }
    Ok((origin, grid, cell))
}

fn check_walls(
    cx: &Ctx,
    scene: &SceneFile,
    phases: &[PhaseInfo],
    dim: u32,
    periodic: [bool; 3],
) -> Result<(), InputError> {
    let is_wall = |name: &str| {
        phases
            .iter()
            .any(|p| p.name == name && p.kind == PhaseKind::Wall)
    };
    let needs_walls = (0..dim as usize).any(|a| !periodic[a]);
    match &scene.domain.wall_phase {
        Some(w) if !is_wall(w) => {
            return Err(cx.err(
                "domain.wall_phase",
                format!("`{w}` is not a phase of kind \"wall\""),
            ))
        }
        None if needs_walls => {
            return Err(cx.err(
                "domain.wall_phase",
                "a domain with a non-periodic axis needs wall_phase",
            ))
        }
        _ => {}
    }
    for side in &scene.domain.open_sides {
        check_side(cx, "domain.open_sides", side, dim, periodic)?;
    }
    for (side, w) in &scene.domain.wall_sides {
        let key = format!("domain.wall_sides.{side}");
        check_side(cx, &key, side, dim, periodic)?;
        if !is_wall(w) {
            return Err(cx.err(&key, format!("`{w}` is not a phase of kind \"wall\"")));
        }
    }
    Ok(())
}

/// Most path points and power steps the parameter block holds.
pub const MAX_LASER_POINTS: usize = 8;

/// A validated laser source (issue 4). Lateral coordinates are absolute.
#[derive(Debug, Clone)]
pub struct Laser {
    pub model: crate::scene::LaserModel,
    pub absorptivity: f64,
    pub radius: f64,
    pub absorption: f64,
    /// (time, power) steps.
    pub power: Vec<(f64, f64)>,
    /// (time, lateral position) of the beam centre; unused lateral axes are 0.
    pub path: Vec<(f64, [f64; 2])>,
}

impl Laser {
    /// Beam power at time t (held from each step's time on; off before the first).
    pub fn power_at(&self, t: f64) -> f64 {
        self.power
            .iter()
            .rev()
            .find(|p| p.0 <= t)
            .map_or(0.0, |p| p.1)
    }
    /// Energy the beam delivers over [0, t] (J; J per metre of depth in 2D).
    pub fn energy_until(&self, t: f64) -> f64 {
        let mut e = 0.0;
        for (k, &(t0, p)) in self.power.iter().enumerate() {
            let t1 = self.power.get(k + 1).map_or(f64::INFINITY, |n| n.0).min(t);
            if t1 > t0 {
                e += p * (t1 - t0);
            }
        }
        e
    }
}

fn laser(
    cx: &Ctx,
    scene: &SceneFile,
    dim: u32,
    phases: &[PhaseInfo],
) -> Result<Option<Laser>, InputError> {
    let Some(l) = &scene.laser else {
        return Ok(None);
    };
    if !phases.iter().any(|p| p.conducts()) {
        return Err(cx.err(
            "laser",
            "a laser needs a heat scene (phases with a temperature)",
        ));
    }
    let absorptivity = cx.positive("laser.absorptivity", l.absorptivity)?;
    if absorptivity > 1.0 {
        return Err(cx.err(
            "laser.absorptivity",
            format!("must lie in (0, 1] (got {absorptivity})"),
        ));
    }
    let radius = cx.positive("laser.radius", l.radius)?;
    let absorption = match (l.model, l.absorption_coefficient) {
        (_, Some(a)) => cx.positive("laser.absorption_coefficient", a)?,
        (crate::scene::LaserModel::BeerLambert, None) => {
            return Err(cx.err(
                "laser.absorption_coefficient",
                "missing: the beer_lambert model needs it (1/m)",
            ))
        }
        (crate::scene::LaserModel::GaussianSurface, None) => 0.0,
    };
    let points =
        |key: &str, list: &Vec<Vec<f64>>, width: usize| -> Result<Vec<Vec<f64>>, InputError> {
            if list.is_empty() || list.len() > MAX_LASER_POINTS {
                return Err(cx.err(key, format!("give 1 to {MAX_LASER_POINTS} entries")));
            }
            let mut last = f64::NEG_INFINITY;
            for (k, e) in list.iter().enumerate() {
                if e.len() != width || e.iter().any(|v| !v.is_finite()) {
                    return Err(cx.err(
                        &format!("{key}[{k}]"),
                        format!("expected {width} finite numbers"),
                    ));
                }
                if e[0] < 0.0 || e[0] <= last {
                    return Err(cx.err(
                        &format!("{key}[{k}]"),
                        "times must start at >= 0 and increase",
                    ));
                }
                last = e[0];
            }
            Ok(list.clone())
        };
    let power = points("laser.power", &l.power, 2)?
        .iter()
        .map(|e| (e[0], e[1]))
        .collect::<Vec<_>>();
    if let Some(k) = power.iter().position(|p| p.1 < 0.0) {
        return Err(cx.err(&format!("laser.power[{k}]"), "power must be >= 0"));
    }
    let path = points("laser.path", &l.path, dim as usize)?
        .iter()
        .map(|e| (e[0], [e[1], if dim == 3 { e[2] } else { 0.0 }]))
        .collect();
    Ok(Some(Laser {
        model: l.model,
        absorptivity,
        radius,
        absorption,
        power,
        path,
    }))
}

fn open_side_flags(scene: &SceneFile) -> [[bool; 2]; 3] {
    let mut open = [[false; 2]; 3];
    for (a, pair) in crate::scene::SIDE_NAMES.iter().enumerate() {
        for (k, name) in pair.iter().enumerate() {
            open[a][k] = scene.domain.open_sides.iter().any(|s| s == name);
        }
    }
    open
}

/// A side named in the domain must exist and have walls (not absent, not periodic).
fn check_side(
    cx: &Ctx,
    key: &str,
    side: &str,
    dim: u32,
    periodic: [bool; 3],
) -> Result<(), InputError> {
    let Some(axis) = crate::scene::side_axis(side) else {
        return Err(cx.err(
            key,
            format!("unknown side `{side}` (use x_min, x_max, y_min, y_max, z_min, z_max)"),
        ));
    };
    if axis >= dim as usize || periodic[axis] {
        return Err(cx.err(
            key,
            format!("side `{side}` has no wall (axis absent or periodic)"),
        ));
    }
    Ok(())
}
