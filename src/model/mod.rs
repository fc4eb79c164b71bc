//! A validated scene: every derived constant the solver needs, checked for physical
//! sense, plus the host-side time-step limits (F22 (42)).

mod bodies;
mod check_inputs;
mod domain;
pub mod expansion;
mod laser;
pub mod limits;
mod phases;
mod tension;
mod thermal;

pub use laser::{
    fresnel_absorptivity, hagen_rubens_index, Laser, RayTracing, ScanTrack, MAX_LASER_POINTS,
};
pub use phases::{Evaporation, PhaseInfo, TemperatureWave, Thermal};
pub use tension::SurfaceTension;

pub use bodies::{BodySource, BodySpec, Contact};
use domain::{
    box_face_warnings, cell_grid, check_walls, domain_box, domain_sites, hydrostatic_axis,
    open_side_flags,
};
pub use domain::{lattice_sites, LATTICE_TOLERANCE};
use phases::{artificial_nu, interface_viscosity_nu, phase_table, solid_fluid_viscosity};
use thermal::thermal_table;
pub use thermal::STEFAN_BOLTZMANN;

use crate::error::InputError;
use crate::scene::{
    CheckDef, Formulation, InitialPressure, KernelKind, PhaseKind, SceneFile, Slip, WatchdogDef,
};

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
    /// 0.1 ρ c_p h²/k over conducting phases; ∞ without heat.
    pub conduction: f64,
    /// F22 (42) 0.22 √(m/k_b) with the lightest fluid particle; ∞ without barrier.
    pub barrier: f64,
    /// F22 (42) 0.25 √(ρ h³/(2π α)), the lighter of the pair's ρ0 and the largest
    /// α the scene can reach; ∞ without surface tension.
    pub capillary: f64,
    /// F22 (42) 0.22 √(m/k_c) with the lightest body particle; ∞ without bodies.
    pub contact: f64,
    /// `run.max_dt` (J22 Table 2a's "CFL max Δt"); ∞ without it.
    pub maximum: f64,
}

impl DtLimits {
    /// The scene's constant limits with their rows of `limits::LIMITS` (∞ where
    /// the scene lacks the physics; the force limit here is gravity's).
    pub fn rows(&self) -> [(limits::Limit, f64); 8] {
        use limits::Limit;
        [
            (Limit::Acoustic, self.acoustic),
            (Limit::Viscous, self.viscous),
            (Limit::Force, self.body_force),
            (Limit::Conduction, self.conduction),
            (Limit::Barrier, self.barrier),
            (Limit::Capillary, self.capillary),
            (Limit::Contact, self.contact),
            (Limit::Maximum, self.maximum),
        ]
    }
    /// The smallest limit and its label (the first of equal ones).
    pub fn min(&self) -> (f64, &'static str) {
        let rows = self.rows();
        let mut best = (rows[0].1, rows[0].0.def().label);
        for (limit, v) in &rows[1..] {
            if *v < best.0 {
                best = (*v, limit.def().label);
            }
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
    /// Lattice sites per axis inside the domain (1 beyond the dimension).
    pub sites: [u64; 3],
    /// Input that is valid but probably not what was meant, each naming file, key
    /// and what to change; `run` and `validate` print them.
    pub warnings: Vec<String>,
    pub h: f64,
    pub support: f64,
    pub domain_lo: [f64; 3],
    pub domain_hi: [f64; 3],
    /// Origin of the cell grid; particle positions are stored relative to it.
    pub origin: [f64; 3],
    pub periodic: [bool; 3],
    /// Sides without wall layers, by axis then (min, max).
    pub open_sides: [[bool; 2]; 3],
    pub open_sides_policy: crate::scene::OpenSidesPolicy,
    pub grid: [u32; 3],
    pub cell_size: [f64; 3],
    pub wall_layers: u32,
    /// DFSPH's single-layer Akinci boundary (`simulation.dfsph.boundary`): one
    /// wall layer, and setup gives each wall particle the mass ρ0 V_b with
    /// V_b = 1/Σ_b' W_bb' (J22 (24)).
    pub akinci_walls: bool,
    pub gravity: [f64; 3],
    pub background_pressure: f64,
    pub pressure_floor: bool,
    /// Gravity axis when the fluid starts hydrostatic (`simulation.initial_pressure`).
    pub hydrostatic_axis: Option<usize>,
    /// F22 (32) α_0^lg (0 = off).
    pub interface_viscosity: f64,
    /// F22 (33) (α_0^sf, ΔT_d).
    pub solid_fluid_viscosity: Option<(f64, f64)>,
    pub viscous_heating: bool,
    pub ambient_temperature: f64,
    pub jitter: f64,
    pub seed: u64,
    pub phases: Vec<PhaseInfo>,
    pub fixed_dt: Option<f64>,
    pub end: EndCondition,
    pub output_interval: f64,
    pub diagnostics_interval: f64,
    /// `run.stop_when = "solidified"`: (the time the beam goes off for good,
    /// the grace after it: ∞ without `run.stop_grace`).
    pub stop_when_solidified: Option<(f64, f64)>,
    pub check: Option<CheckDef>,
    pub watchdog: WatchdogDef,
    pub laser: Option<Laser>,
    /// F22 (34) barrier between fluid and walls.
    pub barrier: Option<Barrier>,
    /// F22 (24)–(26) surface tension between a liquid and a gas phase.
    pub surface_tension: Option<SurfaceTension>,
    /// The poured `[powder]` bed.
    pub powder: Option<crate::powder::PowderBed>,
    /// Rigid bodies, in body order (`shapes` with `body = true`).
    pub bodies: Vec<BodySpec>,
    /// F22 (39)–(40) contact between bodies and with walls (scenes with bodies).
    pub contact: Option<Contact>,
    /// `[heat]`: the energy equation's time integration (heat scenes).
    pub heat: HeatIntegration,
    /// δ-SPH: the density diffusion coefficient δ (Some exactly when the
    /// formulation is `delta_wcsph`).
    pub delta: Option<f64>,
    /// The viscous term (δ-SPH may take R18 (3.18)'s).
    pub viscosity_form: crate::scene::ViscosityForm,
    /// δ-SPH: what the density diffusion smooths (R18 (3.53) or the raw ρ).
    pub density_diffusion: crate::scene::DensityDiffusion,
    /// DFSPH: the solves' tolerances and bound (defaults elsewhere).
    pub dfsph: crate::scene::DfsphDef,
    pub limits: DtLimits,
}

/// `[heat]`, validated: Euler, or R18's trapezoidal rule with its fixed-point
/// iteration's tolerance and cap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeatIntegration {
    pub integrator: crate::scene::HeatIntegrator,
    pub tolerance: f64,
    pub max_iterations: u32,
}

/// The most fixed-point iterations a step may record (each is a conduction
/// sweep; the GPU records all of them whether or not they run).
pub const MAX_HEAT_ITERATIONS: u32 = 64;

fn heat_integration(
    cx: &Ctx,
    scene: &SceneFile,
    thermal: bool,
) -> Result<HeatIntegration, InputError> {
    let Some(h) = scene.heat else {
        return Ok(HeatIntegration {
            integrator: crate::scene::HeatIntegrator::Euler,
            tolerance: 0.0,
            max_iterations: 0,
        });
    };
    if !thermal {
        return Err(cx.err("heat", "the scene has no conducting phase (no temperature)"));
    }
    let tolerance = cx.positive("heat.tolerance", h.tolerance)?;
    if !(1..=MAX_HEAT_ITERATIONS).contains(&h.max_iterations) {
        return Err(cx.err(
            "heat.max_iterations",
            format!(
                "must be 1 to {MAX_HEAT_ITERATIONS} (got {})",
                h.max_iterations
            ),
        ));
    }
    Ok(HeatIntegration {
        integrator: h.integrator,
        tolerance,
        max_iterations: h.max_iterations,
    })
}

pub const MAX_PHASES: usize = 8;

impl Model {
    /// `watchdog.on_dispersion`, or its default: "warn" where a phase melts (a
    /// melt pool sheds spatter, single particles under gas, small pieces
    /// without), "stop" elsewhere.
    pub fn dispersion_action(&self) -> crate::scene::DispersionAction {
        use crate::scene::DispersionAction;
        match (self.watchdog.on_dispersion, self.melts()) {
            (Some(a), _) => a,
            (None, true) => DispersionAction::Warn,
            (None, false) => DispersionAction::Stop,
        }
    }
    /// DFSPH with its implicit viscosity and XSPH solve.
    pub fn implicit_viscosity(&self) -> bool {
        self.formulation == crate::scene::Formulation::Dfsph
            && self.dfsph.viscosity == crate::scene::DfsphViscosity::Implicit
    }
    /// The sound speed of the acoustic limit: none under DFSPH, whose
    /// pressure is implicit (the flow's CFL limit 0.25 h/|u| remains).
    pub fn max_sound_speed(&self) -> f64 {
        if self.formulation == crate::scene::Formulation::Dfsph {
            return 0.0;
        }
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
        surface_laser
            || self.has_surface_losses()
            || self.interface_viscosity > 0.0
            || self.surface_tension.is_some()
    }
    /// The interface pass takes the free-surface form (R18 (3.25)–(3.27)): the
    /// scene has no gas phase (with one, `Params::new` picks F22's gas form).
    pub fn free_surface_interface(&self) -> bool {
        !self
            .phases
            .iter()
            .any(|p| p.kind == crate::scene::PhaseKind::Gas)
    }
    /// R18's free-surface CSF: surface tension without gas, not J22's colour
    /// Laplacian.
    pub fn free_surface_csf(&self) -> bool {
        self.surface_tension
            .as_ref()
            .is_some_and(|t| !t.colour_laplacian)
            && self.free_surface_interface()
    }
    /// That CSF skips the particles inside the liquid (full support, weak
    /// gradient: backend::cpu::surface_forces::bears_tension) on continuity
    /// density (δ-SPH); on summation density it keeps R18's threshold alone.
    pub fn csf_skips_interior(&self) -> bool {
        self.free_surface_csf() && self.delta.is_some()
    }
    pub fn has_surface_losses(&self) -> bool {
        self.phases
            .iter()
            .filter_map(|p| p.thermal)
            .any(|t| t.evaporation.is_some() || t.emissivity > 0.0)
    }
    /// Depth behind a wall face (in Δx) at which the watchdog stops a run: the
    /// scene's `watchdog.wall_penetration`, else the whole wall-layer band.
    pub fn wall_stop_depth(&self) -> f64 {
        self.watchdog
            .wall_penetration
            .unwrap_or(self.wall_layers as f64)
    }
    /// The box a particle must stay in along axis `a`, grid-relative: an open
    /// face bounds it; behind a walled face, the edge of the grid's padding
    /// ((wall_layers + 1) Δx, one layer past the walls, so a leak through every
    /// layer is seen by the watchdog before the particle is gone). Unbounded on
    /// periodic and absent axes.
    pub fn keep_box(&self, a: usize) -> (f64, f64) {
        if a >= self.dim as usize || self.periodic[a] {
            return (-(f32::MAX as f64), f32::MAX as f64);
        }
        let pad = (self.wall_layers as f64 + 1.0) * self.dx;
        let (lo, hi) = (
            self.domain_lo[a] - self.origin[a],
            self.domain_hi[a] - self.origin[a],
        );
        let [open_lo, open_hi] = self.open_sides[a];
        (
            if open_lo { lo } else { lo - pad },
            if open_hi { hi } else { hi + pad },
        )
    }
    /// Closed wall faces and a phase that flows: fluid can leak into the walls.
    pub fn has_walls_and_fluid(&self) -> bool {
        let closed = (0..self.dim as usize)
            .any(|a| !self.periodic[a] && self.open_sides[a].iter().any(|open| !open));
        closed && self.phases.iter().any(|p| p.is_fluid())
    }
    /// The scene has rigid bodies.
    pub fn has_bodies(&self) -> bool {
        !self.bodies.is_empty()
    }
    pub fn is_thermal(&self) -> bool {
        self.phases.iter().any(|p| p.thermal.is_some())
    }
    /// A phase melts. The run then records where and how the metal solidifies
    /// (`State::solidification`, `/solidification`).
    pub fn melts(&self) -> bool {
        self.phases
            .iter()
            .any(|p| p.thermal.and_then(|t| t.melting).is_some())
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
    /// World (absolute) coordinates of a stored position (a particle's `pos`, a
    /// body's `x`): the grid-relative f32 value plus the grid origin, summed in
    /// f64, so no figure loses the position's bits to a second rounding; 0 on the
    /// axes beyond the scene's dimension. Every host-side reader goes through it
    /// (frames round it once to f32, `output::position_channels`).
    pub fn to_world(&self, p: [f32; 4]) -> [f64; 3] {
        std::array::from_fn(|a| {
            if a < self.dim as usize {
                p[a] as f64 + self.origin[a]
            } else {
                0.0
            }
        })
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

/// Validate a parsed scene and derive all constants: an assembly in which each
/// section's owner validates its keys (resolution, domain, phases, the forces,
/// the time-step limits, the run, the laser, the check, the watchdog), then
/// the Model literal, one line per field (why it runs past 80 lines).
pub fn build(file: &str, scene: &SceneFile, resolved_toml: &str) -> Result<Model, InputError> {
    let cx = Ctx { file };
    let sim = &scene.simulation;
    let Resolution {
        dim,
        dx,
        h,
        support,
        gravity,
    } = resolution(&cx, sim)?;

    let (domain_lo, domain_hi, periodic) = domain_box(&cx, scene, dim)?;
    let hydrostatic_axis = match sim.initial_pressure {
        InitialPressure::Zero => None,
        InitialPressure::Hydrostatic => Some(hydrostatic_axis(&cx, gravity, periodic)?),
    };
    let mut warnings = Vec::new();
    let sites = domain_sites(&cx, dim, domain_lo, domain_hi, dx, &mut warnings);
    box_face_warnings(&cx, scene, dim, domain_lo, dx, &mut warnings);
    let phases = phase_table(&cx, scene, dim, dx)?;
    let akinci_walls = sim.formulation == crate::scene::Formulation::Dfsph
        && sim
            .dfsph
            .is_some_and(|d| d.boundary == crate::scene::DfsphBoundary::Akinci);
    let wall_layers = if akinci_walls {
        1
    } else {
        (support / dx - 1e-9).ceil() as u32
    };
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

    let has_body =
        scene.shapes.iter().any(|s| s.body) || scene.powder.as_ref().is_some_and(|p| p.rigid);
    if !phases.iter().any(|p| p.is_fluid() || p.conducts()) && !has_body {
        return Err(cx.err(
            "phases",
            "the scene has no liquid, gas or solid phase nor a rigid body",
        ));
    }
    let solid_fluid = solid_fluid_viscosity(&cx, sim, &phases)?;
    let barrier = barrier_def(&cx, sim, h, dx)?;
    let powder = powder_bed(&cx, scene, dim, &phases)?;
    let (bodies, contact) = bodies::bodies(&cx, scene, &phases, dim, periodic, powder.as_ref())?;
    let surface_tension = tension::surface_tension(&cx, scene, &phases, support, dx)?;
    let limits = dt_limits(
        &cx,
        scene,
        &phases,
        (dim, dx, h),
        gravity,
        solid_fluid,
        barrier.as_ref(),
        surface_tension.as_ref(),
        (&bodies, contact),
    )?;

    let run = &scene.run;
    let (fixed_dt, end, output_interval, diagnostics_interval) = run_timing(&cx, run, &limits)?;
    let laser = laser::laser_source(&cx, scene, dim, &phases)?;
    if let Some(c) = &scene.check {
        let around = check_inputs::Around {
            dim,
            phases: &phases,
            surface_tension: surface_tension.as_ref(),
            has_laser: laser.is_some(),
        };
        check_inputs::validate(&cx, scene, c, &around)?;
    }
    let stop_when_solidified = stop_when(&cx, run, laser.as_ref(), &phases)?;
    let heat = heat_integration(&cx, scene, phases.iter().any(|p| p.thermal.is_some()))?;
    let delta = delta_coefficient(&cx, sim)?;
    let dfsph = dfsph_def(&cx, scene)?;
    warnings.extend(risk_warnings(
        file,
        sim,
        &phases,
        surface_tension.as_ref(),
        (dim, dx, h),
    ));
    watchdog_inputs(&cx, &scene.watchdog)?;
    if let (Some(l), Some(t_end), Some(_)) = (&laser, run.end_time, &scene.scan) {
        let last = l.power.last().map_or(0.0, |p| p.0);
        if last > t_end {
            warnings.push(format!(
                "{file}: key `run.end_time`: the run ends at {t_end:.4e} s, before the scan's \
                 last track ends at {last:.4e} s"
            ));
        }
    }

    Ok(Model {
        file: file.to_string(),
        resolved_toml: resolved_toml.to_string(),
        dim,
        formulation: sim.formulation,
        kernel: sim.kernel,
        dx,
        sites,
        warnings,
        h,
        support,
        domain_lo,
        domain_hi,
        origin,
        periodic,
        open_sides: open_side_flags(scene),
        open_sides_policy: scene.domain.open_sides_policy,
        grid,
        cell_size,
        wall_layers,
        akinci_walls,
        gravity,
        background_pressure: sim.background_pressure,
        viscous_heating: sim.viscous_heating,
        ambient_temperature: cx
            .positive("simulation.ambient_temperature", sim.ambient_temperature)?,
        pressure_floor: sim.pressure_floor,
        hydrostatic_axis,
        interface_viscosity: sim.interface_viscosity.alpha(dx),
        solid_fluid_viscosity: solid_fluid,
        jitter: sim.jitter,
        seed: sim.seed,
        phases,
        fixed_dt,
        end,
        output_interval,
        diagnostics_interval,
        stop_when_solidified,
        check: scene.check.clone(),
        watchdog: scene.watchdog.clone(),
        laser,
        barrier,
        surface_tension,
        powder,
        bodies,
        contact,
        heat,
        delta,
        viscosity_form: sim.viscosity_form,
        density_diffusion: sim.density_diffusion,
        dfsph,
        limits,
    })
}

/// The resolution and the frame: dimension, Δx, the smoothing length and
/// support, gravity; the background pressure and the start's jitter.
struct Resolution {
    dim: u32,
    dx: f64,
    h: f64,
    support: f64,
    gravity: [f64; 3],
}

fn resolution(cx: &Ctx, sim: &crate::scene::Simulation) -> Result<Resolution, InputError> {
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
    Ok(Resolution {
        dim,
        dx,
        h,
        support,
        gravity,
    })
}

/// The scene's constant time-step limits, F22 (42) with zero velocity: acoustic,
/// viscous (the fluids', the interface and solid–fluid viscosities'), body
/// force, conduction, barrier, capillary, contact and `run.max_dt`.
#[allow(clippy::too_many_arguments)] // each limit's own inputs, built before it
fn dt_limits(
    cx: &Ctx,
    scene: &SceneFile,
    phases: &[PhaseInfo],
    (dim, dx, h): (u32, f64, f64),
    gravity: [f64; 3],
    solid_fluid: Option<(f64, f64)>,
    barrier: Option<&Barrier>,
    surface_tension: Option<&SurfaceTension>,
    (bodies, contact): (&[BodySpec], Option<Contact>),
) -> Result<DtLimits, InputError> {
    let sim = &scene.simulation;
    let fluid: Vec<&PhaseInfo> = phases.iter().filter(|p| p.is_fluid()).collect();
    let conduction = phases
        .iter()
        .filter(|p| p.conducts())
        .map(|p| {
            // the stiffer of the solid and liquid states: a melt whose
            // conductivity is scaled (R18 §4.4's x10) diffuses faster
            let t = p.thermal.unwrap();
            let limit = |c: f64, k: f64| 0.1 * p.rho0 * c * h * h / k;
            limit(t.heat_capacity, t.conductivity).min(limit(t.liquid.1, t.liquid.0))
        })
        .fold(f64::INFINITY, f64::min);
    // DFSPH's pressure is implicit: no acoustic limit (the flow's CFL remains).
    let c_max = if sim.formulation == crate::scene::Formulation::Dfsph {
        0.0
    } else {
        fluid.iter().map(|p| p.sound_speed).fold(0.0, f64::max)
    };
    // DFSPH's implicit viscosity has no time-step limit (the artificial
    // viscosities stay explicit).
    let implicit_viscosity = sim.formulation == crate::scene::Formulation::Dfsph
        && sim.dfsph.unwrap_or_default().viscosity == crate::scene::DfsphViscosity::Implicit;
    let nu_max = fluid
        .iter()
        .filter(|_| !implicit_viscosity)
        .map(|p| p.viscosity / p.rho0)
        .fold(
            interface_viscosity_nu(cx, sim, &fluid, dim, h, dx)?
                + solid_fluid.map_or(0.0, |(a, _)| artificial_nu(a, &fluid, dim, h)),
            f64::max,
        );
    let g = (gravity[0] * gravity[0] + gravity[1] * gravity[1] + gravity[2] * gravity[2]).sqrt();
    Ok(DtLimits {
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
        barrier: match barrier {
            Some(b) => {
                let m_min = fluid.iter().map(|p| p.mass).fold(f64::INFINITY, f64::min);
                0.22 * (m_min / b.stiffness).sqrt()
            }
            None => f64::INFINITY,
        },
        capillary: surface_tension.map_or(f64::INFINITY, |s| {
            let rho = s.gas.map_or(phases[s.liquid].rho0, |g| {
                phases[s.liquid].rho0.min(phases[g].rho0)
            });
            0.25 * (rho * h * h * h / (2.0 * std::f64::consts::PI * s.max_coefficient(phases)))
                .sqrt()
        }),
        contact: bodies::contact_limit(bodies, phases, contact),
        maximum: match scene.run.max_dt {
            Some(_) if scene.run.dt.is_some() => {
                return Err(cx.err("run.max_dt", "give dt (fixed) or max_dt (a cap), not both"));
            }
            Some(v) => cx.positive("run.max_dt", v)?,
            None => f64::INFINITY,
        },
    })
}

/// What `validate` can predict will go wrong, as warnings: a liquid that
/// disperses into its gas, a sound speed too low for the recoil, a metal melt
/// that breaks up, a pressure floor on δ-SPH, J22's colour Laplacian.
fn risk_warnings(
    file: &str,
    sim: &crate::scene::Simulation,
    phases: &[PhaseInfo],
    surface_tension: Option<&SurfaceTension>,
    (dim, dx, h): (u32, f64, f64),
) -> Vec<String> {
    let mut warnings = Vec::new();
    if let Some(w) = dispersion_risk(file, sim, phases, surface_tension) {
        warnings.push(w);
    }
    if let Some(w) = recoil_risk(file, phases) {
        warnings.push(w);
    }
    if let Some(w) = breakup_risk(file, sim, phases, surface_tension, (dim, dx, h)) {
        warnings.push(w);
    }
    if sim.formulation == Formulation::DeltaWcsph && sim.pressure_floor {
        warnings.push(format!(
            "{file}: key `simulation.pressure_floor`: on formulation = \"delta_wcsph\" the \
             continuity density does not fall short at a free surface, and the floor takes \
             away the tension that holds surface particles (a melting grain lost 2 particles \
             and 8.5e-3 of its momentum with it, none and 9.4e-7 without); set it false"
        ));
    }
    if surface_tension.is_some_and(|s| s.colour_laplacian) {
        warnings.push(format!(
            "{file}: key `surface_tension.model`: J22 (5)-(8) as printed holds no drop together \
             at a free surface. On the Laplace disc (R = 20 dx) summation density (wcsph, dfsph) \
             leaves the colour at 0.99 on the surface and no force (jump -99.997%); on \
             delta_wcsph the outer row is pushed outward (-98.8%, 40 of 1264 particles blown \
             off). It is here to reproduce J22; model = \"csf\" is the surface tension"
        ));
    }
    warnings
}

/// `[run]`: a fixed step (within the stability limits unless `dt_check` is
/// false), the end, the output and diagnostics intervals.
fn run_timing(
    cx: &Ctx,
    run: &crate::scene::RunDef,
    limits: &DtLimits,
) -> Result<(Option<f64>, EndCondition, f64, f64), InputError> {
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
    Ok((fixed_dt, end, output_interval, diagnostics_interval))
}

/// `[watchdog]`: the bounds an unstable run is stopped at.
fn watchdog_inputs(cx: &Ctx, wd: &WatchdogDef) -> Result<(), InputError> {
    cx.positive("watchdog.min_density_ratio", wd.min_density_ratio)?;
    cx.positive("watchdog.min_dt_ratio", wd.min_dt_ratio)?;
    if let Some(depth) = wd.wall_penetration {
        cx.positive("watchdog.wall_penetration", depth)?;
    }
    if !(wd.liquid_dispersion > 0.0 && wd.liquid_dispersion <= 1.0) {
        return Err(cx.err(
            "watchdog.liquid_dispersion",
            format!("must be a share in (0, 1] (got {})", wd.liquid_dispersion),
        ));
    }
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
    Ok(())
}

/// `simulation.delta` (δ-SPH only): 0 ≤ δ ≤ 1.
fn delta_coefficient(cx: &Ctx, sim: &crate::scene::Simulation) -> Result<Option<f64>, InputError> {
    use crate::scene::Formulation;
    match (sim.formulation, sim.delta) {
        (Formulation::DeltaWcsph, d) => {
            let d = d.unwrap_or(0.1);
            if !(0.0..=1.0).contains(&d) {
                return Err(cx.err(
                    "simulation.delta",
                    format!("must be between 0 and 1 (got {d}; Antuono et al. use 0.1)"),
                ));
            }
            if sim.viscous_heating {
                return Err(cx.err(
                    "simulation.viscous_heating",
                    "is F22's dissipation of its own viscous term; formulation = \"delta_wcsph\" uses R18 (3.18)'s: not built for it yet",
                ));
            }
            Ok(Some(d))
        }
        _ if sim.density_diffusion != crate::scene::DensityDiffusion::Excess => Err(cx.err(
            "simulation.density_diffusion",
            "is the δ-SPH density diffusion's form: set formulation = \"delta_wcsph\" or leave it out",
        )),
        (Formulation::Dfsph, None)
            if sim.viscosity_form == crate::scene::ViscosityForm::Marrone
                && sim.dfsph.unwrap_or_default().viscosity
                    == crate::scene::DfsphViscosity::Implicit =>
        {
            Ok(None)
        }
        _ if sim.viscosity_form != crate::scene::ViscosityForm::Morris => Err(cx.err(
            "simulation.viscosity_form",
            "\"marrone\" is R18 (3.18) (Weiler et al. 2018's in J22 (17)), built for \
             formulation = \"delta_wcsph\" and for the implicit viscosity of \"dfsph\" only",
        )),
        (_, Some(_)) => Err(cx.err(
            "simulation.delta",
            "is the δ-SPH density diffusion: set formulation = \"delta_wcsph\" or leave it out",
        )),
        (_, None) => Ok(None),
    }
}

/// `run.stop_when = "solidified"`: a laser scene with a
/// melting phase whose power table ends at 0 W; (beam off from, grace).
fn stop_when(
    cx: &Ctx,
    run: &crate::scene::RunDef,
    laser: Option<&laser::Laser>,
    phases: &[PhaseInfo],
) -> Result<Option<(f64, f64)>, InputError> {
    let grace = match run.stop_grace {
        Some(g) => cx.positive("run.stop_grace", g)?,
        None => f64::INFINITY,
    };
    let Some(crate::scene::StopWhen::Solidified) = run.stop_when else {
        if run.stop_grace.is_some() {
            return Err(cx.err("run.stop_grace", "needs run.stop_when = \"solidified\""));
        }
        return Ok(None);
    };
    let melts = phases
        .iter()
        .any(|p| p.thermal.and_then(|t| t.melting).is_some());
    let Some(l) = laser.filter(|_| melts) else {
        return Err(cx.err(
            "run.stop_when",
            "\"solidified\" needs a [laser] and a phase that melts",
        ));
    };
    match l.power.last() {
        Some(&(t_off, 0.0)) => Ok(Some((t_off, grace))),
        _ => Err(cx.err(
            "run.stop_when",
            "\"solidified\": the beam never turns off (laser.power must end with a [time, 0.0] point)",
        )),
    }
}

/// Surface tension with gas at a density ratio of 10 or more and no
/// liquid–gas interface viscosity: such a drop disperses into its gas within a
/// few oscillations (measured at ratio 100: square_drop_2d with its viscosities
/// cut, 14 of 256 particles alone in the gas by 0.28 s); F22 damps the
/// interface with α^lg (Table 1, molten steel: 7.2; Table 4, binder: 1.8).
fn dispersion_risk(
    file: &str,
    sim: &crate::scene::Simulation,
    phases: &[PhaseInfo],
    tension: Option<&tension::SurfaceTension>,
) -> Option<String> {
    let t = tension?;
    let ratio = phases[t.liquid].rho0 / phases[t.gas?].rho0;
    (ratio >= 10.0 && matches!(sim.interface_viscosity, crate::scene::InterfaceViscosityDef::Alpha(a) if a == 0.0)).then(|| {
        format!(
            "{file}: key `simulation.interface_viscosity`: surface tension with gas at a density \
             ratio of {ratio:.0} and no liquid-gas interface viscosity: the liquid can disperse \
             into its gas (the watchdog stops such a run, watchdog.on_dispersion); F22 uses \
             7.2 for molten steel (Table 1) and 1.8 for a liquid binder (Table 4)"
        )
    })
}

/// The share of ρ0 c² the recoil pressure may reach at the boiling point: the
/// F22 (30) law p_r = C_p exp(−C_T (1/T − 1/T_v)) is C_p there and grows e-fold
/// every T_v²/C_T (about 200 K for metals) above it, and the weakly compressible
/// melt gives way by p/(ρ0 c²): at 1% at T_v it is 5-15% a few hundred kelvin
/// above, where the melt under a beam goes (a sound speed of 5 m/s took a 3D
/// bare-plate melt through its floor).
const RECOIL_SHARE_AT_BOILING: f64 = 0.01;

/// A warning for a liquid with the recoil whose sound speed is too low for it.
fn recoil_risk(file: &str, phases: &[PhaseInfo]) -> Option<String> {
    phases.iter().find_map(|p| {
        let e = p.recoil()?;
        let stiffness = p.rho0 * p.sound_speed * p.sound_speed;
        let share = e.pressure_constant / stiffness;
        let e_fold = e.boiling_temperature * e.boiling_temperature / e.temperature_constant;
        (share > RECOIL_SHARE_AT_BOILING).then(|| {
            format!(
                "{file}: key `materials.{}.sound_speed` (or `reference_pressure`): the recoil pressure at the boiling point \
                 ({:.3e} Pa, rising e-fold every {e_fold:.0} K above it) is {:.1}% of rho0 c^2 = \
                 {stiffness:.3e} Pa on phase `{}`: the melt under the beam compresses by as much; \
                 keep it below {:.0}% (a sound speed of at least {:.1} m/s)",
                p.material,
                e.pressure_constant,
                100.0 * share,
                p.name,
                100.0 * RECOIL_SHARE_AT_BOILING,
                (e.pressure_constant / (RECOIL_SHARE_AT_BOILING * p.rho0)).sqrt()
            )
        })
    })
}

/// The grid Ohnesorge number μ/√(ρ σ Δx) under which a free surface held by the
/// free-surface CSF breaks up. A 2D disc of molten steel at rest (R = 6.25 Δx,
/// σ = 1.8 N/m, δ-SPH, 0.2 ms): particles at 3-5 m/s and the disc scattered at
/// 0.026 and 0.087 (μ = 6 and 20 mPa s at Δx = 4 µm), the noise growing at 0.26,
/// steady at 0.52; at Δx = 1 µm (R = 25 Δx, 0.052) it scattered faster.
const BREAKUP_OHNESORGE: f64 = 0.5;

/// A warning for free-surface tension (no gas) on a liquid whose viscosity, with
/// the interface viscosity F22 (31)-(32)'s α h c/(2(d + 2)), is below
/// `BREAKUP_OHNESORGE` on the grid: the CSF's spurious currents, which F22 damps
/// with that term, grow until particles leave the surface. DFSPH (no sound speed
/// in the term) is left out.
fn breakup_risk(
    file: &str,
    sim: &crate::scene::Simulation,
    phases: &[PhaseInfo],
    tension: Option<&tension::SurfaceTension>,
    (dim, dx, h): (u32, f64, f64),
) -> Option<String> {
    let t = tension?;
    if t.gas.is_some() || t.colour_laplacian || sim.formulation == crate::scene::Formulation::Dfsph
    {
        return None;
    }
    let liquid = &phases[t.liquid];
    let nu_art = artificial_nu(sim.interface_viscosity.alpha(dx), &[liquid], dim, h);
    let mu = liquid.viscosity + liquid.rho0 * nu_art;
    let oh = mu / (liquid.rho0 * t.max_coefficient(phases) * dx).sqrt();
    (oh < BREAKUP_OHNESORGE).then(|| {
        format!(
            "{file}: key `simulation.interface_viscosity`: free-surface tension on `{}` at a grid \
             Ohnesorge number mu/sqrt(rho sigma dx) = {oh:.3} (interface viscosity included): \
             below {BREAKUP_OHNESORGE} the surface's spurious currents grow until particles \
             leave it (a 2D drop of molten steel at rest, R = 6.25 dx, scattered within \
             0.1 ms); F22 (31)-(32)'s interface viscosity damps them: F22 uses 7.2 for \
             molten steel (Table 1) and 1.8 for a binder (Table 4)",
            liquid.name
        )
    })
}

/// `[powder]`: the grains' phase (solid or wall), a box inside the domain, then
/// the bed poured.
fn powder_bed(
    cx: &Ctx,
    scene: &SceneFile,
    dim: u32,
    phases: &[PhaseInfo],
) -> Result<Option<crate::powder::PowderBed>, InputError> {
    let Some(def) = &scene.powder else {
        return Ok(None);
    };
    let phase = phases
        .iter()
        .position(|p| p.name == def.phase)
        .ok_or_else(|| cx.err("powder.phase", format!("no phase named `{}`", def.phase)))?;
    if !matches!(phases[phase].kind, PhaseKind::Solid | PhaseKind::Wall) {
        return Err(cx.err(
            "powder.phase",
            format!("`{}` must be a solid or wall phase", def.phase),
        ));
    }
    let spec = crate::powder::spec(cx.file, def, phase, dim as usize)?;
    let d = &scene.domain;
    for k in 0..dim as usize {
        if spec.lo[k] < d.min[k] || spec.hi[k] > d.max[k] {
            return Err(cx.err("powder.box", "must lie inside the domain"));
        }
    }
    let bed = crate::powder::pour(spec, dim as usize);
    let up = dim as usize - 1;
    if bed.spec.lo[up] + bed.thickness > d.max[up] {
        return Err(cx.err(
            "powder.max_grains",
            format!(
                "the bed of {} grains rises to {:.4e} m, above the domain's top {:.4e} m",
                bed.grains.len(),
                bed.spec.lo[up] + bed.thickness,
                d.max[up]
            ),
        ));
    }
    Ok(Some(bed))
}

/// F22 (34) barrier: radius r_b (m), stiffness k_b (kg/s²), damping d_b (kg/(m s)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Barrier {
    pub radius: f64,
    pub stiffness: f64,
    pub damping: f64,
}

/// `simulation.barrier`: 0 < r_b < h (F22 §3.3.6), k_b > 0, d_b ≥ 0.
fn barrier_def(
    cx: &Ctx,
    sim: &crate::scene::Simulation,
    h: f64,
    dx: f64,
) -> Result<Option<Barrier>, InputError> {
    let Some(b) = sim.barrier else {
        return Ok(None);
    };
    let (key, radius) = match (b.radius, b.radius_dx) {
        (Some(r), None) => (
            "simulation.barrier.radius",
            cx.positive("simulation.barrier.radius", r)?,
        ),
        (None, Some(k)) => (
            "simulation.barrier.radius_dx",
            cx.positive("simulation.barrier.radius_dx", k)? * dx,
        ),
        _ => {
            return Err(cx.err(
                "simulation.barrier",
                "give radius (m) or radius_dx (in dx), one of them",
            ))
        }
    };
    if radius >= h {
        return Err(cx.err(
            key,
            format!(
                "r_b = {radius:e} m must be below the smoothing length h = {h:e} m (F22 §3.3.6)"
            ),
        ));
    }
    Ok(Some(Barrier {
        radius,
        stiffness: cx.positive("simulation.barrier.stiffness", b.stiffness)?,
        damping: cx.non_negative("simulation.barrier.damping", b.damping)?,
    }))
}

/// `simulation.dfsph` and what DFSPH does not take yet.
fn dfsph_def(cx: &Ctx, scene: &SceneFile) -> Result<crate::scene::DfsphDef, InputError> {
    let sim = &scene.simulation;
    if sim.formulation != crate::scene::Formulation::Dfsph {
        if sim.dfsph.is_some() {
            return Err(cx.err("simulation.dfsph", "needs formulation = \"dfsph\""));
        }
        return Ok(crate::scene::DfsphDef::default());
    }
    let d = sim.dfsph.unwrap_or_default();
    cx.positive("simulation.dfsph.density_tolerance", d.density_tolerance)?;
    cx.positive(
        "simulation.dfsph.divergence_tolerance",
        d.divergence_tolerance,
    )?;
    if !(1..=200).contains(&d.viscosity_max_iterations) {
        return Err(cx.err(
            "simulation.dfsph.viscosity_max_iterations",
            format!(
                "must lie in 1..=200: the GPU records every iteration (got {})",
                d.viscosity_max_iterations
            ),
        ));
    }
    cx.positive(
        "simulation.dfsph.viscosity_tolerance",
        d.viscosity_tolerance,
    )?;
    if !(d.xsph.is_finite() && (0.0..=1.0).contains(&d.xsph)) {
        return Err(cx.err(
            "simulation.dfsph.xsph",
            format!("must lie in [0, 1] (J22: 0.1 to 0.3), got {}", d.xsph),
        ));
    }
    for (key, v) in [
        ("simulation.dfsph.cohesion", d.cohesion),
        ("simulation.dfsph.adhesion", d.adhesion),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(cx.err(key, format!("must be finite and >= 0 (1/s^2), got {v}")));
        }
        if v > 0.0 && d.viscosity == crate::scene::DfsphViscosity::Explicit {
            return Err(cx.err(
                key,
                "is solved with the implicit viscosity: set viscosity = \"implicit\"",
            ));
        }
    }
    if d.boundary == crate::scene::DfsphBoundary::Akinci
        && !(sim.kernel == crate::scene::KernelKind::Cubic && sim.h_over_dx == Some(1.0))
    {
        // A flat layer weighted by 1/ΣW stands for the wall behind it only when
        // the kernel reaches two spacings: under the quintic's three, the first
        // fluid row of a column at rest read 16% dense (the layer's weight 1.79
        // lattice volumes at 0.5 dx where three layers give 47.3σ, one 81.9σ)
        // and the column blew up at step 7.
        return Err(cx.err(
            "simulation.dfsph.boundary",
            "\"akinci\" (one boundary layer) needs a kernel that reaches two spacings: \
             J22's cubic spline at h = dx (kernel = \"cubic\", h_over_dx = 1.0); under the \
             quintic's three the first fluid row reads 16% dense",
        ));
    }
    if d.xsph > 0.0 && d.viscosity == crate::scene::DfsphViscosity::Explicit {
        return Err(cx.err(
            "simulation.dfsph.xsph",
            "is solved with the implicit viscosity: set viscosity = \"implicit\"",
        ));
    }
    if !(1..=200).contains(&d.max_iterations) {
        return Err(cx.err(
            "simulation.dfsph.max_iterations",
            format!(
                "must lie in 1..=200: the GPU records every iteration (got {})",
                d.max_iterations
            ),
        ));
    }
    let refuse = |key: &str, why: &str| Err(cx.err(key, format!("formulation = \"dfsph\": {why}")));
    if sim.pressure_floor {
        return refuse(
            "simulation.pressure_floor",
            "its pressure is never negative (only compression is corrected); set it false",
        );
    }
    // The relaxed Jacobi (ω = ½) converges while ω times the largest
    // eigenvalue of D⁻¹A stays below 2: 2.6 for the quintic at h = Δx in 2D.
    // Larger supports have more neighbours and a larger eigenvalue: on the
    // hydrostatic column Wendland C2 at h = 2Δx blew up at step 1 and the cubic
    // at 1.5Δx after 240 steps (ω = ¼ held them, with errors of 8-18% and
    // 4-8%).
    let at_dx = |k| sim.kernel == k && sim.h_over_dx.is_some_and(|r| r == 1.0);
    let quintic_at_dx = (sim.kernel == crate::scene::KernelKind::Quintic
        && sim.h_over_dx.is_none_or(|r| r == 1.0))
        || at_dx(crate::scene::KernelKind::Cubic);
    if !quintic_at_dx {
        return refuse(
            "simulation.kernel",
            "only the quintic or the cubic (J22's) at h = dx yet (the pressure solve \
             diverges with the larger supports of wendland_c2 and of cubic at 1.5 dx)",
        );
    }
    if sim.initial_pressure != crate::scene::InitialPressure::Zero {
        return refuse(
            "simulation.initial_pressure",
            "the fluid starts at rho0 and the solves give its pressure; set it \"zero\"",
        );
    }
    if sim.background_pressure != 0.0 {
        return refuse(
            "simulation.background_pressure",
            "no transport velocity yet; set it 0",
        );
    }
    if scene.shapes.iter().any(|s| s.body) || scene.powder.as_ref().is_some_and(|p| p.rigid) {
        return refuse("shapes", "no rigid bodies yet");
    }
    if let Some((name, _)) = scene.phases.iter().find(|(_, p)| p.moves) {
        return refuse(
            &format!("phases.{name}.moves"),
            "its boundary particles do not move yet",
        );
    }
    Ok(d)
}
