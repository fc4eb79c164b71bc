//! The pass table: every stage of a step, in one place, with its WGSL entry points
//! and the work each dispatches over, the scene features that need it, and its CPU
//! twin. `STEP` and `PRIME` give the order; `Pipeline::for_scene` keeps the stages
//! a scene needs; both backends run whatever the pipeline lists.

use super::cpu::CpuBackend;
use crate::params::{
    Params, FLAG_BODIES, FLAG_FREE_SURFACE_TENSION, FLAG_GAS_INTERFACE, FLAG_HEAT, FLAG_INTERFACE,
    FLAG_RECOIL, FLAG_SURFACE_TENSION, FLAG_WETTING, LASER_BEER_LAMBERT, LASER_SURFACE,
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
    /// T and liquid fraction from the enthalpy; phase switches.
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
}

/// One velocity-Verlet (kick–drift–kick) step, F22 §3.4 with heat (J22, F22 §3.2)
/// inside it: heat is explicit Euler, conduction reading the temperatures of the
/// previous step, then the temperatures following the new enthalpies.
pub const STEP: [Stage; 16] = [
    Stage::KickDrift,     // v += Δt/2 a, x += Δt ṽ (transport velocity)
    Stage::BodyDrift,     // bodies: V, L += Δt/2 (F, τ); X += Δt V; rotate; place
    Stage::Neighbors,     // sort by cell, cell table
    Stage::Density,       // ρ = m Σ W, p = c² (ρ − ρ0)
    Stage::Wall,          // wall pressure and velocity extrapolated from the fluid
    Stage::Interface,     // interface normals and surface delta
    Stage::Forces,        // pressure, viscous forces, barrier; gravity
    Stage::SurfaceForces, // surface tension, Marangoni stress, recoil
    Stage::BodyForces,    // contact on body particles; per-body F, τ
    Stage::Laser,         // absorbed laser power
    Stage::Heat,          // conduction and surface losses, enthalpy update
    Stage::Temperature,   // T and f_l from h; melting and solidification
    Stage::BodyMelt,      // bodies: melted members leave, solidified melt bonds
    Stage::Kick,          // v += Δt/2 a
    Stage::BodyKick,      // bodies: V, L += Δt/2 (F, τ)
    Stage::Timestep,      // Δt for the next step
];

/// Run once before the first step: accelerations, temperatures and Δt of the
/// initial state.
pub const PRIME: [Stage; 10] = [
    Stage::Neighbors,
    Stage::Density,
    Stage::Wall,
    Stage::Interface,
    Stage::Forces,
    Stage::SurfaceForces,
    Stage::BodyForces,
    Stage::Temperature,
    Stage::BodyMelt,
    Stage::Timestep,
];

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
    /// F22 (24)–(26) surface tension.
    pub surface_tension: bool,
    /// Its free-surface form (R18): the curvature is smoothed in a second dispatch.
    pub free_surface_tension: bool,
    /// F22 (27)–(29) wetting: the interface pass prescribes the normal near solids.
    pub wetting: bool,
    /// F22 (30) recoil pressure.
    pub recoil: bool,
    /// Rigid bodies (F22 §2.2).
    pub bodies: bool,
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
            surface_tension: params.flag(FLAG_SURFACE_TENSION),
            free_surface_tension: params.flag(FLAG_FREE_SURFACE_TENSION),
            wetting: params.flag(FLAG_WETTING),
            recoil: params.flag(FLAG_RECOIL),
            bodies: params.flag(FLAG_BODIES),
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
    /// One workgroup per `REDUCE_WG` particles.
    Reduction,
    /// A single workgroup.
    Single,
    /// One thread per rigid body.
    Bodies,
}

/// One GPU entry point of a stage, dispatched when `when` holds.
pub struct Dispatch {
    pub entry: &'static str,
    pub work: Work,
    pub when: fn(&Features) -> bool,
}

const fn always(entry: &'static str, work: Work) -> Dispatch {
    Dispatch {
        entry,
        work,
        when: |_| true,
    }
}

/// One stage: its name (timings, `compare`, `validate`), its WGSL file, the
/// features that need it, its GPU entry points in dispatch order and its CPU twin.
pub struct StageDef {
    pub stage: Stage,
    pub name: &'static str,
    pub file: &'static str,
    pub needed: fn(&Features) -> bool,
    pub gpu: &'static [Dispatch],
    pub cpu: fn(&mut CpuBackend),
}

/// Every stage, listed pass file by pass file in the order `spatter validate`
/// prints them.
pub const STAGES: [StageDef; 16] = [
    StageDef {
        stage: Stage::Neighbors,
        name: "neighbors",
        file: "neighbors",
        needed: |_| true,
        // Cell keys, stable (cell, index) sort, reorder, cell table; the buffer
        // copies between them are encoded by the GPU backend.
        gpu: &[
            always("cell_keys", Work::SortKeys),
            always("bitonic_local", Work::Sort),
            always("bitonic_global", Work::Sort),
            always("reorder", Work::Particles),
            always("cell_bounds", Work::Particles),
        ],
        cpu: |b| b.neighbors(),
    },
    StageDef {
        stage: Stage::Density,
        name: "density",
        file: "density",
        needed: |f| f.fluid,
        gpu: &[always("density", Work::Particles)],
        cpu: |b| b.density(),
    },
    StageDef {
        stage: Stage::Wall,
        name: "wall",
        file: "wall",
        needed: |f| f.walls && f.fluid,
        gpu: &[always("wall", Work::Particles)],
        cpu: |b| b.wall(),
    },
    StageDef {
        stage: Stage::Interface,
        name: "interface",
        file: "interface",
        needed: |f| f.interface,
        gpu: &[
            Dispatch {
                entry: "shepard",
                work: Work::Particles,
                when: |f| !f.gas_interface,
            },
            always("normals", Work::Particles),
            Dispatch {
                entry: "wetting",
                work: Work::Particles,
                when: |f| f.wetting,
            },
        ],
        cpu: |b| b.interface(),
    },
    StageDef {
        stage: Stage::Forces,
        name: "forces",
        file: "forces",
        needed: |f| f.fluid,
        gpu: &[always("forces", Work::Particles)],
        cpu: |b| b.forces(),
    },
    StageDef {
        stage: Stage::SurfaceForces,
        name: "surface_forces",
        file: "surface_forces",
        needed: |f| f.surface_tension || f.recoil,
        gpu: &[
            Dispatch {
                entry: "surface_tension",
                work: Work::Particles,
                when: |f| f.surface_tension && !f.free_surface_tension,
            },
            Dispatch {
                entry: "tension_curvature",
                work: Work::Particles,
                when: |f| f.free_surface_tension,
            },
            Dispatch {
                entry: "tension_smooth",
                work: Work::Particles,
                when: |f| f.free_surface_tension,
            },
            Dispatch {
                entry: "recoil",
                work: Work::Particles,
                when: |f| f.recoil,
            },
        ],
        cpu: |b| b.surface_forces(),
    },
    StageDef {
        stage: Stage::Laser,
        name: "laser",
        file: "laser",
        needed: |f| f.laser_bins || f.laser_surface,
        gpu: &[
            Dispatch {
                entry: "laser_surface",
                work: Work::Particles,
                when: |f| f.laser_surface,
            },
            Dispatch {
                entry: "laser_bins",
                work: Work::LaserBins,
                when: |f| f.laser_bins,
            },
            Dispatch {
                entry: "laser_columns",
                work: Work::LaserColumns,
                when: |f| f.laser_bins,
            },
            Dispatch {
                entry: "laser_deposit",
                work: Work::Particles,
                when: |f| f.laser_bins,
            },
        ],
        cpu: |b| b.laser(),
    },
    StageDef {
        stage: Stage::Heat,
        name: "heat.conduct",
        file: "heat",
        needed: |f| f.heat,
        gpu: &[
            always("wall_temperature", Work::Particles),
            always("conduct", Work::Particles),
        ],
        cpu: |b| b.conduct(),
    },
    StageDef {
        stage: Stage::Temperature,
        name: "heat.temperature",
        file: "heat",
        needed: |f| f.heat,
        gpu: &[always("temperature", Work::Particles)],
        cpu: |b| b.temperature(),
    },
    StageDef {
        stage: Stage::KickDrift,
        name: "integrate.kick_drift",
        file: "integrate",
        needed: |f| f.fluid,
        gpu: &[always("kick_drift", Work::Particles)],
        cpu: |b| b.kick_drift(),
    },
    StageDef {
        stage: Stage::Kick,
        name: "integrate.kick",
        file: "integrate",
        needed: |f| f.fluid,
        gpu: &[always("kick", Work::Particles)],
        cpu: |b| b.kick(),
    },
    StageDef {
        stage: Stage::Timestep,
        name: "timestep",
        file: "timestep",
        needed: |_| true,
        gpu: &[
            always("reduce", Work::Reduction),
            always("finalize", Work::Single),
        ],
        cpu: |b| b.timestep(),
    },
    StageDef {
        stage: Stage::BodyDrift,
        name: "bodies.drift",
        file: "bodies",
        needed: |f| f.bodies,
        gpu: &[
            always("body_drift", Work::Bodies),
            always("body_place", Work::Particles),
        ],
        cpu: |b| b.body_drift(),
    },
    StageDef {
        stage: Stage::BodyForces,
        name: "bodies.forces",
        file: "bodies",
        needed: |f| f.bodies,
        gpu: &[
            always("body_forces", Work::Particles),
            always("body_slots", Work::Particles),
            always("body_sum", Work::Bodies),
        ],
        cpu: |b| b.body_forces(),
    },
    StageDef {
        stage: Stage::BodyKick,
        name: "bodies.kick",
        file: "bodies",
        needed: |f| f.bodies,
        gpu: &[always("body_kick", Work::Bodies)],
        cpu: |b| b.body_kick(),
    },
    StageDef {
        stage: Stage::BodyMelt,
        name: "bodies.melt",
        file: "bodies",
        needed: |f| f.bodies && f.heat,
        gpu: &[
            always("body_bond", Work::Particles),
            always("body_melt", Work::Bodies),
        ],
        cpu: |b| b.body_melt(),
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
        .flat_map(|d| d.gpu.iter().map(move |g| (g.entry, d.file)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_stage_has_one_row_and_every_entry_point_one_stage() {
        for s in STEP.iter().chain(PRIME.iter()) {
            assert_eq!(STAGES.iter().filter(|d| d.stage == *s).count(), 1, "{s:?}");
        }
        let e = entry_points();
        for (k, (entry, _)) in e.iter().enumerate() {
            assert!(!e[k + 1..].iter().any(|(o, _)| o == entry), "{entry} twice");
        }
        assert_eq!(e.len(), 34);
    }
}
