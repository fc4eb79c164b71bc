//! The pass table: every stage of a step, in one place, with its WGSL entry points,
//! the work each dispatches over, when it runs, and the CPU twin of each. The order
//! of a step is a formulation's schedule (backend::schedule); both backends run
//! whatever the schedule lists, dispatch by dispatch from these rows.

use super::cpu::CpuBackend;
use super::schedule::SolverSlot;
use crate::params::{
    Params, FLAG_BODIES, FLAG_COLOUR_TENSION, FLAG_CONTINUITY, FLAG_FREE_SURFACE_TENSION,
    FLAG_GAS_INTERFACE, FLAG_HEAT, FLAG_INTERFACE, FLAG_RECOIL, FLAG_SOLIDIFICATION,
    FLAG_SURFACE_TENSION, FLAG_WETTING, HEAT_TRAPEZOIDAL, LASER_BEER_LAMBERT, LASER_RAY_TRACED,
    LASER_SURFACE,
};
use crate::state::State;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Half kick, transport-velocity drift, periodic wrap; moving walls drift.
    KickDrift,
    /// Cell keys, stable (cell, index) sort, reorder, cell table.
    Neighbors,
    /// Summation density and equation of state.
    Density,
    /// δ-SPH: the continuity equation's rate (R18 (3.14), (3.53)) and Shepard
    /// sum, then the density update and equation of state.
    Continuity,
    /// Adami (2012) wall pressure and velocity.
    Wall,
    /// Shepard sum, then interface normal and surface delta.
    Interface,
    /// F22 (23) pressure + viscous forces, background pressure, interface
    /// viscosity, viscous heating, gravity.
    Forces,
    /// F22 (24)–(26) CSF surface tension and Marangoni stress, F22 (30) recoil,
    /// added to acc.
    SurfaceForces,
    /// Beer–Lambert absorption with column binning, or the Gaussian surface flux
    /// F22 (17); source (W/kg) in heat.w.
    Laser,
    /// Conduction dh/dt, surface losses and the explicit Euler enthalpy update.
    Heat,
    /// T and liquid fraction from the enthalpy; phase switches; liquidus
    /// crossings on cooling recorded, then their |∇T|.
    Temperature,
    /// Second half kick and the mushy-zone sink.
    Kick,
    /// max |u|, |a| reductions and the F22 (42) time step.
    Timestep,
    /// Rigid bodies: first half kick, drift and free rotation; members placed.
    BodyDrift,
    /// Rigid bodies: F22 (39)–(40) contact on members, per-body force and torque.
    BodyForces,
    /// Rigid bodies: second half kick.
    BodyKick,
    /// Melting rigid bodies: melted members leave (F22 (37)), bodies touched by
    /// solidifying melt bond into the substrate.
    BodyMelt,
    /// Trapezoidal (Crank–Nicolson) heat (R18 Algorithm 3.1): keep h^n and the laser source,
    /// reset the heat solver.
    HeatBegin,
    /// One fixed-point iteration: T of the iterate h^k, the Dirichlet mirrors,
    /// conduction and h^{k+1} = h^n + Δt (ḣ_0 + ḣ_k)/2.
    HeatIterate,
    /// The iteration's residual max|ḣ_k − ḣ_{k−1}| / max|ḣ_0 + ḣ_k| and the
    /// solver's converged flag.
    HeatResidual,
    /// DFSPH: the walls' Akinci volumes, then each fluid particle's density and
    /// factor α (pressure 0 for the non-pressure forces).
    DfsphFactor,
    /// DFSPH divergence-free solve: reset, first errors Dρ/Dt.
    DfsphDivergenceBegin,
    /// One iteration: κ, the velocity correction, the new errors.
    DfsphDivergenceIterate,
    /// The mean divergence error and the converged flag.
    DfsphDivergenceResidual,
    /// DFSPH: v* = v + Δt a.
    DfsphPredict,
    /// DFSPH constant-density solve: reset, first predicted density errors.
    DfsphDensityBegin,
    /// One iteration: κ (summed for the pressure), the velocity correction,
    /// the new errors.
    DfsphDensityIterate,
    /// The mean density error and the converged flag.
    DfsphDensityResidual,
    /// DFSPH: x += Δt v*, the step's pressure.
    DfsphDrift,
    /// DFSPH implicit viscosity: the walls' no-slip velocities from the
    /// fluid's velocity before the explicit forces.
    DfsphViscosityWall,
    /// DFSPH implicit viscosity and XSPH (J22 (17)): CG's residual,
    /// preconditioner and first direction at x0 = v*, the solver reset.
    DfsphViscosityBegin,
    /// One CG product q = A p and the step length.
    DfsphViscosityApply,
    /// The CG update of v and r, the residual and converged flag, the next
    /// direction.
    DfsphViscosityUpdate,
}

/// What a scene has; it decides which stages and dispatches run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Features {
    /// Wall (or solid) particles.
    pub walls: bool,
    /// Fluid particles now, or later: a solid that melts becomes fluid.
    pub fluid: bool,
    /// Temperature.
    pub heat: bool,
    /// Interface normals and surface deltas.
    pub interface: bool,
    /// F22's gas-interface form (no Shepard sums).
    pub gas_interface: bool,
    /// Beer–Lambert laser with column bins.
    pub laser_bins: bool,
    /// Gaussian surface-flux laser.
    pub laser_surface: bool,
    /// Ray-traced laser (bins, rays, deposit).
    pub laser_rays: bool,
    /// F22 (24)–(26) surface tension.
    pub surface_tension: bool,
    /// Its free-surface form (R18): the curvature is smoothed in a second dispatch.
    pub free_surface_tension: bool,
    /// Its colour-Laplacian model (J22 (5)–(8), `model = "muller"`) in place of CSF.
    pub colour_tension: bool,
    /// F22 (27)–(29) wetting: the interface pass prescribes the normal near solids.
    pub wetting: bool,
    /// F22 (30) recoil pressure.
    pub recoil: bool,
    /// Rigid bodies (F22 §2.2).
    pub bodies: bool,
    /// Heat integrated by the trapezoidal rule (R18 Algorithm 3.1).
    pub implicit_heat: bool,
    /// δ-SPH: the density is continuity state (R18 §3.1.2).
    pub continuity: bool,
    /// A phase melts: liquidus crossings on cooling are recorded with |∇T|.
    pub solidification: bool,
    /// Divergence-free SPH (implicit pressure).
    pub dfsph: bool,
    /// DFSPH with the implicit viscosity and XSPH solve.
    pub dfsph_viscosity: bool,
}

impl Features {
    /// From the block's named flags and phase table (both computed from the model
    /// in `Params::new`) and the particles the setup placed.
    pub fn of(params: &Params, st: &State) -> Features {
        let phases = crate::model::MAX_PHASES as u32;
        Features {
            walls: st.phase.iter().any(|&p| params.is_wall(p)),
            fluid: st.phase.iter().any(|&p| !params.is_wall(p))
                || (0..phases).any(|p| params.switch_target(p).is_some()),
            heat: params.flag(FLAG_HEAT),
            interface: params.flag(FLAG_INTERFACE),
            gas_interface: params.flag(FLAG_GAS_INTERFACE),
            laser_bins: params.laser.model == LASER_BEER_LAMBERT,
            laser_surface: params.laser.model == LASER_SURFACE,
            laser_rays: params.laser.model == LASER_RAY_TRACED,
            surface_tension: params.flag(FLAG_SURFACE_TENSION),
            free_surface_tension: params.flag(FLAG_FREE_SURFACE_TENSION),
            colour_tension: params.flag(FLAG_COLOUR_TENSION),
            wetting: params.flag(FLAG_WETTING),
            recoil: params.flag(FLAG_RECOIL),
            bodies: params.flag(FLAG_BODIES),
            implicit_heat: params.flag(FLAG_HEAT)
                && params.solve.heat_integrator == HEAT_TRAPEZOIDAL,
            continuity: params.flag(FLAG_CONTINUITY),
            solidification: params.flag(FLAG_SOLIDIFICATION),
            dfsph: params.solve.formulation == crate::scene::Formulation::Dfsph.code(),
            dfsph_viscosity: params.solve.formulation == crate::scene::Formulation::Dfsph.code()
                && params.solve.dfsph_viscosity_max_iterations > 0,
        }
    }
}

/// What one GPU dispatch runs over: its thread count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Work {
    /// One thread per particle.
    Particles,
    /// One thread per sort key (particles padded to a power of two).
    SortKeys,
    /// The bitonic sort's dispatches (the sort schedules them).
    Sort,
    /// One thread per laser bin.
    LaserBins,
    /// One thread per laser column.
    LaserColumns,
    /// One thread per ray of the ray-traced laser.
    LaserRays,
    /// One workgroup per `REDUCE_WG` particles.
    Reduction,
    /// A single workgroup.
    Single,
    /// One thread per rigid body.
    Bodies,
}

/// The CPU twin of one dispatch.
#[derive(Clone, Copy)]
pub enum Twin {
    /// This function computes what the dispatch computes.
    Run(fn(&mut CpuBackend)),
    /// The twin of an earlier dispatch of the same stage already did this work
    /// (the sort inside `neighbors`, the second level of a reduction); the row
    /// says which in a comment.
    InPrevious,
}

/// One GPU entry point of a stage, dispatched when `when` holds, and its CPU twin
/// (run under the same condition).
pub struct Dispatch {
    pub entry: &'static str,
    pub work: Work,
    pub when: fn(&Features) -> bool,
    pub cpu: Twin,
}

const fn always(entry: &'static str, work: Work, cpu: fn(&mut CpuBackend)) -> Dispatch {
    Dispatch {
        entry,
        work,
        when: |_| true,
        cpu: Twin::Run(cpu),
    }
}

const fn when(
    entry: &'static str,
    work: Work,
    when: fn(&Features) -> bool,
    cpu: fn(&mut CpuBackend),
) -> Dispatch {
    Dispatch {
        entry,
        work,
        when,
        cpu: Twin::Run(cpu),
    }
}

/// A dispatch whose CPU work the stage's previous twin did.
const fn within(entry: &'static str, work: Work) -> Dispatch {
    Dispatch {
        entry,
        work,
        when: |_| true,
        cpu: Twin::InPrevious,
    }
}

/// One stage: its name (timings, `compare`, `validate`), its WGSL file, the
/// features that need it, and its dispatches in order with their CPU twins.
pub struct StageDef {
    pub stage: Stage,
    pub name: &'static str,
    pub file: &'static str,
    pub needed: fn(&Features) -> bool,
    pub dispatches: &'static [Dispatch],
}

/// Every stage, listed pass file by pass file in the order `spatter validate`
/// prints them.
pub const STAGES: [StageDef; 33] = [
    StageDef {
        stage: Stage::Neighbors,
        name: "neighbors",
        file: "neighbors",
        needed: |_| true,
        // Cell keys, stable (cell, index) sort, reorder, cell table; the buffer
        // copies between them are encoded by the GPU backend. The CPU sorts and
        // builds the cell table in one twin.
        dispatches: &[
            always("cell_keys", Work::SortKeys, |b| b.neighbors()),
            within("bitonic_local", Work::Sort),
            within("bitonic_global", Work::Sort),
            within("reorder", Work::Particles),
            within("cell_bounds", Work::Particles),
        ],
    },
    StageDef {
        stage: Stage::Density,
        name: "density",
        file: "density",
        needed: |f| f.fluid,
        dispatches: &[always("density", Work::Particles, |b| b.density())],
    },
    StageDef {
        stage: Stage::Continuity,
        name: "continuity",
        file: "continuity",
        needed: |f| f.fluid && f.continuity,
        dispatches: &[
            always("continuity_gradient", Work::Particles, |b| {
                b.continuity_gradient()
            }),
            always("continuity_rate", Work::Particles, |b| b.continuity_rate()),
            always("continuity_update", Work::Particles, |b| {
                b.continuity_update()
            }),
        ],
    },
    StageDef {
        stage: Stage::DfsphFactor,
        name: "dfsph.factor",
        file: "dfsph",
        needed: |f| f.dfsph,
        dispatches: &[
            when(
                "dfsph_boundary_volume",
                Work::Particles,
                |f| f.walls,
                |b| b.dfsph_boundary_volume(),
            ),
            always("dfsph_factor", Work::Particles, |b| b.dfsph_factor()),
        ],
    },
    StageDef {
        stage: Stage::DfsphDivergenceBegin,
        name: "dfsph.divergence_begin",
        file: "dfsph",
        needed: |f| f.dfsph,
        // The warm start's κ applied to the velocities, then the errors again.
        dispatches: &[
            always("dfsph_divergence_begin", Work::Particles, |b| {
                b.dfsph_begin(SolverSlot::Divergence)
            }),
            always("dfsph_divergence_warm_velocity", Work::Particles, |b| {
                b.dfsph_velocity(SolverSlot::Divergence)
            }),
            always("dfsph_divergence_warm_error", Work::Particles, |b| {
                b.dfsph_error(SolverSlot::Divergence)
            }),
        ],
    },
    StageDef {
        stage: Stage::DfsphDivergenceIterate,
        name: "dfsph.divergence_iterate",
        file: "dfsph",
        needed: |f| f.dfsph,
        dispatches: &[
            always("dfsph_divergence_kappa", Work::Particles, |b| {
                b.dfsph_kappa(SolverSlot::Divergence)
            }),
            always("dfsph_divergence_velocity", Work::Particles, |b| {
                b.dfsph_velocity(SolverSlot::Divergence)
            }),
            always("dfsph_divergence_error", Work::Particles, |b| {
                b.dfsph_error(SolverSlot::Divergence)
            }),
        ],
    },
    StageDef {
        stage: Stage::DfsphDivergenceResidual,
        name: "dfsph.divergence_residual",
        file: "dfsph",
        needed: |f| f.dfsph,
        // One twin for both levels of the sum tree.
        dispatches: &[
            always("dfsph_divergence_residual", Work::Reduction, |b| {
                b.dfsph_residual(SolverSlot::Divergence)
            }),
            within("dfsph_divergence_residual_final", Work::Single),
        ],
    },
    StageDef {
        stage: Stage::DfsphPredict,
        name: "dfsph.predict",
        file: "dfsph",
        needed: |f| f.dfsph,
        dispatches: &[always("dfsph_predict", Work::Particles, |b| {
            b.dfsph_predict()
        })],
    },
    StageDef {
        stage: Stage::DfsphDensityBegin,
        name: "dfsph.density_begin",
        file: "dfsph",
        needed: |f| f.dfsph,
        // The warm start's κ applied to the velocities, then the errors again.
        dispatches: &[
            always("dfsph_density_begin", Work::Particles, |b| {
                b.dfsph_begin(SolverSlot::Density)
            }),
            always("dfsph_density_warm_velocity", Work::Particles, |b| {
                b.dfsph_velocity(SolverSlot::Density)
            }),
            always("dfsph_density_warm_error", Work::Particles, |b| {
                b.dfsph_error(SolverSlot::Density)
            }),
        ],
    },
    StageDef {
        stage: Stage::DfsphDensityIterate,
        name: "dfsph.density_iterate",
        file: "dfsph",
        needed: |f| f.dfsph,
        dispatches: &[
            always("dfsph_density_kappa", Work::Particles, |b| {
                b.dfsph_kappa(SolverSlot::Density)
            }),
            always("dfsph_density_velocity", Work::Particles, |b| {
                b.dfsph_velocity(SolverSlot::Density)
            }),
            always("dfsph_density_error", Work::Particles, |b| {
                b.dfsph_error(SolverSlot::Density)
            }),
        ],
    },
    StageDef {
        stage: Stage::DfsphDensityResidual,
        name: "dfsph.density_residual",
        file: "dfsph",
        needed: |f| f.dfsph,
        // One twin for both levels of the sum tree.
        dispatches: &[
            always("dfsph_density_residual", Work::Reduction, |b| {
                b.dfsph_residual(SolverSlot::Density)
            }),
            within("dfsph_density_residual_final", Work::Single),
        ],
    },
    StageDef {
        stage: Stage::DfsphViscosityWall,
        name: "dfsph.viscosity_wall",
        file: "dfsph_viscosity",
        needed: |f| f.dfsph_viscosity && f.walls,
        dispatches: &[always("dfsph_viscosity_wall", Work::Particles, |b| {
            b.dfsph_viscosity_wall()
        })],
    },
    StageDef {
        stage: Stage::DfsphViscosityBegin,
        name: "dfsph.viscosity_begin",
        file: "dfsph_viscosity",
        needed: |f| f.dfsph_viscosity,
        // One twin for the sweep and both levels of the sum tree.
        dispatches: &[
            always("dfsph_viscosity_begin", Work::Particles, |b| {
                b.dfsph_viscosity_begin()
            }),
            within("dfsph_viscosity_begin_sum", Work::Reduction),
            within("dfsph_viscosity_begin_final", Work::Single),
        ],
    },
    StageDef {
        stage: Stage::DfsphViscosityApply,
        name: "dfsph.viscosity_apply",
        file: "dfsph_viscosity",
        needed: |f| f.dfsph_viscosity,
        dispatches: &[
            always("dfsph_viscosity_apply", Work::Particles, |b| {
                b.dfsph_viscosity_apply()
            }),
            within("dfsph_viscosity_apply_sum", Work::Reduction),
            within("dfsph_viscosity_apply_final", Work::Single),
        ],
    },
    StageDef {
        stage: Stage::DfsphViscosityUpdate,
        name: "dfsph.viscosity_update",
        file: "dfsph_viscosity",
        needed: |f| f.dfsph_viscosity,
        dispatches: &[
            always("dfsph_viscosity_update", Work::Particles, |b| {
                b.dfsph_viscosity_update()
            }),
            within("dfsph_viscosity_update_sum", Work::Reduction),
            within("dfsph_viscosity_update_final", Work::Single),
            within("dfsph_viscosity_direction", Work::Particles),
        ],
    },
    StageDef {
        stage: Stage::DfsphDrift,
        name: "dfsph.drift",
        file: "dfsph",
        needed: |f| f.dfsph,
        dispatches: &[always("dfsph_drift", Work::Particles, |b| b.dfsph_drift())],
    },
    StageDef {
        stage: Stage::Wall,
        name: "wall",
        file: "wall",
        needed: |f| f.walls && f.fluid,
        dispatches: &[always("wall", Work::Particles, |b| b.wall())],
    },
    StageDef {
        stage: Stage::Interface,
        name: "interface",
        file: "interface",
        needed: |f| f.interface,
        dispatches: &[
            when(
                "shepard",
                Work::Particles,
                |f| !f.gas_interface,
                |b| b.shepard(),
            ),
            always("normals", Work::Particles, |b| b.normals()),
            when("wetting", Work::Particles, |f| f.wetting, |b| b.wetting()),
        ],
    },
    StageDef {
        stage: Stage::Forces,
        name: "forces",
        file: "forces",
        needed: |f| f.fluid,
        dispatches: &[always("forces", Work::Particles, |b| b.forces())],
    },
    StageDef {
        stage: Stage::SurfaceForces,
        name: "surface_forces",
        file: "surface_forces",
        needed: |f| f.surface_tension || f.recoil,
        dispatches: &[
            when(
                "surface_tension",
                Work::Particles,
                |f| f.surface_tension && !f.free_surface_tension,
                |b| b.surface_tension(),
            ),
            when(
                "tension_curvature",
                Work::Particles,
                |f| f.free_surface_tension && !f.colour_tension,
                |b| b.tension_curvature(),
            ),
            when(
                "tension_smooth",
                Work::Particles,
                |f| f.free_surface_tension && !f.colour_tension,
                |b| b.tension_smooth(),
            ),
            when(
                "tension_colour",
                Work::Particles,
                |f| f.colour_tension,
                |b| b.tension_colour(),
            ),
            when(
                "tension_laplacian",
                Work::Particles,
                |f| f.colour_tension,
                |b| b.tension_laplacian(),
            ),
            when("recoil", Work::Particles, |f| f.recoil, |b| b.recoil()),
        ],
    },
    StageDef {
        stage: Stage::Laser,
        name: "laser",
        file: "laser",
        needed: |f| f.laser_bins || f.laser_surface || f.laser_rays,
        dispatches: &[
            when(
                "laser_surface",
                Work::Particles,
                |f| f.laser_surface,
                |b| b.laser_surface(),
            ),
            when(
                "laser_bins",
                Work::LaserBins,
                |f| f.laser_bins || f.laser_rays,
                |b| b.laser_bins(),
            ),
            when(
                "laser_columns",
                Work::LaserColumns,
                |f| f.laser_bins,
                |b| b.laser_columns(),
            ),
            when(
                "laser_rays",
                Work::LaserRays,
                |f| f.laser_rays,
                |b| b.laser_rays(),
            ),
            when(
                "laser_ray_bins",
                Work::LaserBins,
                |f| f.laser_rays,
                |b| b.laser_ray_bins(),
            ),
            when(
                "laser_deposit",
                Work::Particles,
                |f| f.laser_bins || f.laser_rays,
                |b| b.laser_deposit(),
            ),
        ],
    },
    StageDef {
        stage: Stage::Heat,
        name: "heat.conduct",
        file: "heat",
        needed: |f| f.heat,
        dispatches: &[
            always("wall_temperature", Work::Particles, |b| {
                b.wall_temperature()
            }),
            always("conduct", Work::Particles, |b| b.conduct()),
        ],
    },
    StageDef {
        stage: Stage::HeatBegin,
        name: "heat.begin",
        file: "heat",
        needed: |f| f.implicit_heat,
        dispatches: &[always("heat_begin", Work::Particles, |b| b.heat_begin())],
    },
    StageDef {
        stage: Stage::HeatIterate,
        name: "heat.iterate",
        file: "heat",
        needed: |f| f.implicit_heat,
        dispatches: &[
            always("iterate_temperature", Work::Particles, |b| {
                b.iterate_temperature()
            }),
            always("iterate_wall_temperature", Work::Particles, |b| {
                b.iterate_wall_temperature()
            }),
            always("iterate_conduct", Work::Particles, |b| b.iterate_conduct()),
        ],
    },
    StageDef {
        stage: Stage::HeatResidual,
        name: "heat.residual",
        file: "heat",
        needed: |f| f.implicit_heat,
        // One twin for both levels of the max tree.
        dispatches: &[
            always("heat_residual", Work::Reduction, |b| b.heat_residual()),
            within("heat_residual_final", Work::Single),
        ],
    },
    StageDef {
        stage: Stage::Temperature,
        name: "heat.temperature",
        file: "heat",
        needed: |f| f.heat,
        dispatches: &[
            always("temperature", Work::Particles, |b| b.temperature()),
            when(
                "solidification_gradient",
                Work::Particles,
                |f| f.solidification,
                |b| b.solidification_gradient(),
            ),
        ],
    },
    StageDef {
        stage: Stage::KickDrift,
        name: "integrate.kick_drift",
        file: "integrate",
        needed: |f| f.fluid,
        dispatches: &[always("kick_drift", Work::Particles, |b| b.kick_drift())],
    },
    StageDef {
        stage: Stage::Kick,
        name: "integrate.kick",
        file: "integrate",
        needed: |f| f.fluid,
        dispatches: &[always("kick", Work::Particles, |b| b.kick())],
    },
    StageDef {
        stage: Stage::Timestep,
        name: "timestep",
        file: "timestep",
        needed: |_| true,
        // One twin for both levels of the max tree and the limits.
        dispatches: &[
            always("reduce", Work::Reduction, |b| b.timestep()),
            within("finalize", Work::Single),
        ],
    },
    StageDef {
        stage: Stage::BodyDrift,
        name: "bodies.drift",
        file: "bodies",
        needed: |f| f.bodies,
        dispatches: &[
            always("body_drift", Work::Bodies, |b| b.body_drift()),
            always("body_place", Work::Particles, |b| b.body_place()),
        ],
    },
    StageDef {
        stage: Stage::BodyForces,
        name: "bodies.forces",
        file: "bodies",
        needed: |f| f.bodies,
        // The CPU sums by particle id directly (its twin of body_sum builds the
        // id -> index map that body_slots writes on the GPU).
        dispatches: &[
            always("body_forces", Work::Particles, |b| b.body_forces()),
            within("body_slots", Work::Particles),
            always("body_sum", Work::Bodies, |b| b.body_sum()),
        ],
    },
    StageDef {
        stage: Stage::BodyKick,
        name: "bodies.kick",
        file: "bodies",
        needed: |f| f.bodies,
        dispatches: &[always("body_kick", Work::Bodies, |b| b.body_kick())],
    },
    StageDef {
        stage: Stage::BodyMelt,
        name: "bodies.melt",
        file: "bodies",
        needed: |f| f.bodies && f.heat,
        dispatches: &[
            always("body_bond", Work::Particles, |b| b.body_bond()),
            always("body_melt", Work::Bodies, |b| b.body_melt()),
        ],
    },
];

impl Stage {
    pub fn def(self) -> &'static StageDef {
        STAGES
            .iter()
            .find(|d| d.stage == self)
            .expect("every stage has a row in STAGES")
    }
    pub fn name(self) -> &'static str {
        self.def().name
    }
    /// The compute pass (WGSL file) a stage belongs to.
    pub fn pass(self) -> &'static str {
        self.def().file
    }
}

/// Every GPU entry point as (entry point, WGSL file), each once.
pub fn entry_points() -> Vec<(&'static str, &'static str)> {
    STAGES
        .iter()
        .flat_map(|d| d.dispatches.iter().map(move |g| (g.entry, d.file)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_stage_has_one_row_and_every_entry_point_one_stage() {
        for (k, d) in STAGES.iter().enumerate() {
            assert!(
                !STAGES[k + 1..].iter().any(|o| o.stage == d.stage),
                "{:?}",
                d.stage
            );
            assert!(
                !STAGES[k + 1..].iter().any(|o| o.name == d.name),
                "{}",
                d.name
            );
        }
        let e = entry_points();
        for (k, (entry, _)) in e.iter().enumerate() {
            assert!(!e[k + 1..].iter().any(|(o, _)| o == entry), "{entry} twice");
        }
    }

    /// A stage's first dispatch has a CPU twin of its own (an `InPrevious` row
    /// needs a previous twin), and every stage has at least one dispatch.
    #[test]
    fn every_stage_starts_with_a_cpu_twin() {
        for d in &STAGES {
            let first = d.dispatches.first().unwrap_or_else(|| panic!("{}", d.name));
            assert!(matches!(first.cpu, Twin::Run(_)), "{}", d.name);
        }
    }
}
