//! The step as data: each formulation (`simulation.formulation`) builds its
//! schedule, a list of nodes, from the scene's features. A node is a stage of the
//! pass table (passes.rs) or a bounded repeat of stages that ends early on a flag
//! the device sets (a solver's residual below its tolerance). Both backends,
//! `compare` and `validate` interpret the same nodes; nothing is read back inside
//! a step: on the GPU every iteration is recorded and each kernel of a finished
//! loop returns at once after reading the flag, on the CPU the twins read the
//! same flag (and the loop stops early, which gives the same state).
//!
//! Adding a formulation: a `Formulation` variant (scene/mod.rs), its row in
//! `FORMULATIONS` with the function that lists its nodes, and its stages' rows
//! in passes.rs.

use super::passes::{Features, Stage};
use crate::params::Params;
use crate::scene::Formulation;
pub use crate::state::{SolverSlot, SOLVER_SLOTS};

/// A bounded repeat: `begin` once (it resets its solver's slot), then up to
/// `max_iterations` rounds of `stages`, the last of which sets the converged flag.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Repeat {
    pub solver: SolverSlot,
    pub begin: Stage,
    pub stages: Vec<Stage>,
    pub max_iterations: u32,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Node {
    Stage(Stage),
    Repeat(Repeat),
}

impl Node {
    /// The stages of this node in the order they first run.
    pub fn stages(&self) -> Vec<Stage> {
        match self {
            Node::Stage(s) => vec![*s],
            Node::Repeat(r) => std::iter::once(r.begin)
                .chain(r.stages.iter().copied())
                .collect(),
        }
    }
    /// Each stage as often as the GPU records it: a repeat's stages
    /// `max_iterations` times (the profiler's timestamp slots).
    pub fn recorded(&self) -> Vec<Stage> {
        match self {
            Node::Stage(s) => vec![*s],
            Node::Repeat(r) => std::iter::once(r.begin)
                .chain((0..r.max_iterations).flat_map(|_| r.stages.iter().copied()))
                .collect(),
        }
    }
}

/// A formulation's step and prime (run once before the first step: the initial
/// accelerations, temperatures and Δt).
pub struct FormulationDef {
    pub formulation: Formulation,
    pub schedule: ScheduleFn,
}

/// Lists a formulation's nodes for a scene's features: (step, prime).
pub type ScheduleFn = fn(&Features, &Params) -> (Vec<Node>, Vec<Node>);

pub const FORMULATIONS: [FormulationDef; 3] = [
    FormulationDef {
        formulation: Formulation::Wcsph,
        schedule: wcsph,
    },
    FormulationDef {
        formulation: Formulation::DeltaWcsph,
        schedule: delta_wcsph,
    },
    FormulationDef {
        formulation: Formulation::Dfsph,
        schedule: dfsph,
    },
];

/// One velocity-Verlet (kick–drift–kick) step, F22 §3.4 with heat (J22, F22 §3.2)
/// inside it: heat is explicit Euler, conduction reading the temperatures of the
/// previous step, then the temperatures following the new enthalpies; or R18's
/// trapezoidal rule (`[heat] integrator`), a repeat in place of the conduction.
const WCSPH_STEP: [Stage; 16] = [
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

const WCSPH_PRIME: [Stage; 10] = [
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

fn wcsph(f: &Features, p: &Params) -> (Vec<Node>, Vec<Node>) {
    let step = WCSPH_STEP
        .iter()
        .filter(|s| needed(**s, f))
        .map(|&s| match s {
            Stage::Heat if f.implicit_heat => implicit_heat(p),
            s => Node::Stage(s),
        })
        .collect();
    (step, stage_nodes(&WCSPH_PRIME, f))
}

/// R18's δ-SPH (§3.1.2): F22's step with the continuity density in place of the
/// summation density; the forces pass takes R18 (3.17) and (3.18) (terms.rs).
fn delta_wcsph(f: &Features, p: &Params) -> (Vec<Node>, Vec<Node>) {
    let swap = |nodes: Vec<Node>| -> Vec<Node> {
        nodes
            .into_iter()
            .map(|n| match n {
                Node::Stage(Stage::Density) => Node::Stage(Stage::Continuity),
                n => n,
            })
            .collect()
    };
    // The density stage is `needed` by fluid alone: build with it, then swap.
    let (step, prime) = wcsph(f, p);
    (swap(step), swap(prime))
}

/// Divergence-free SPH (Bender & Koschier 2017 Algorithm 1, in SPlisHSPlasH's
/// order; J22 Algorithm 1): the sort, density and factors, the divergence-free
/// solve, the non-pressure forces and heat, v* = v + Δt a, the implicit
/// viscosity and XSPH (J22 (17), conjugate gradients), the constant-density
/// solve, the drift, the CFL step (the time step's acoustic limit without a
/// sound speed). backend/cpu/dfsph.rs and dfsph_viscosity.rs have the equations.
const DFSPH_STEP: [Stage; 15] = [
    Stage::Neighbors,
    Stage::DfsphFactor,
    Stage::DfsphDivergenceBegin, // a repeat (DFSPH_DIVERGENCE)
    Stage::Interface,
    Stage::Forces,
    Stage::SurfaceForces,
    Stage::Laser,
    Stage::Heat,
    Stage::Temperature,
    Stage::DfsphViscosityWall,
    Stage::DfsphPredict,
    Stage::DfsphViscosityBegin, // a repeat (conjugate gradients)
    Stage::DfsphDensityBegin,   // a repeat (DFSPH_DENSITY)
    Stage::DfsphDrift,
    Stage::Timestep,
];

fn dfsph(f: &Features, p: &Params) -> (Vec<Node>, Vec<Node>) {
    let repeat = |solver, begin, iterate, residual| {
        Node::Repeat(Repeat {
            solver,
            begin,
            stages: vec![iterate, residual],
            max_iterations: p.solve.dfsph_max_iterations,
        })
    };
    let step = DFSPH_STEP
        .iter()
        .filter(|s| needed(**s, f))
        .map(|&s| match s {
            Stage::DfsphDivergenceBegin => repeat(
                SolverSlot::Divergence,
                s,
                Stage::DfsphDivergenceIterate,
                Stage::DfsphDivergenceResidual,
            ),
            Stage::DfsphDensityBegin => repeat(
                SolverSlot::Density,
                s,
                Stage::DfsphDensityIterate,
                Stage::DfsphDensityResidual,
            ),
            Stage::DfsphViscosityBegin => Node::Repeat(Repeat {
                solver: SolverSlot::Viscosity,
                begin: s,
                stages: vec![Stage::DfsphViscosityApply, Stage::DfsphViscosityUpdate],
                max_iterations: p.solve.dfsph_viscosity_max_iterations,
            }),
            Stage::Heat if f.implicit_heat => implicit_heat(p),
            s => Node::Stage(s),
        })
        .collect();
    let prime = [
        Stage::Neighbors,
        Stage::DfsphFactor,
        Stage::Interface,
        Stage::Forces,
        Stage::SurfaceForces,
        Stage::Temperature,
        Stage::Timestep,
    ];
    (step, stage_nodes(&prime, f))
}

/// R18 Algorithm 3.1: the enthalpy update by the trapezoidal rule, solved
/// by fixed-point iteration until the relative change is below the tolerance.
fn implicit_heat(p: &Params) -> Node {
    Node::Repeat(Repeat {
        solver: SolverSlot::Heat,
        begin: Stage::HeatBegin,
        stages: vec![Stage::HeatIterate, Stage::HeatResidual],
        max_iterations: p.solve.heat_max_iterations,
    })
}

fn needed(s: Stage, f: &Features) -> bool {
    (s.def().needed)(f)
}

fn stage_nodes(list: &[Stage], f: &Features) -> Vec<Node> {
    list.iter()
        .filter(|s| needed(**s, f))
        .map(|&s| Node::Stage(s))
        .collect()
}

/// The formulation's row.
pub fn formulation(f: Formulation) -> &'static FormulationDef {
    FORMULATIONS
        .iter()
        .find(|d| d.formulation == f)
        .expect("every formulation has a row in FORMULATIONS")
}

/// What a scene runs: its features and its formulation's schedule (docs/design.md:
/// only what its physics needs; a scene without wall particles has no wall
/// pass, a scene without temperature no heat pass and no heat buffers).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pipeline {
    pub features: Features,
    pub formulation: Formulation,
    pub step: Vec<Node>,
    pub prime: Vec<Node>,
}

impl Pipeline {
    pub fn for_scene(params: &Params, st: &crate::state::State) -> Pipeline {
        let features = Features::of(params, st);
        let formulation = Formulation::from_code(params.solve.formulation);
        let (step, prime) = (self::formulation(formulation).schedule)(&features, params);
        Pipeline {
            features,
            formulation,
            step,
            prime,
        }
    }
    /// Every stage of the step, each once, in the order they first run.
    pub fn step_stages(&self) -> Vec<Stage> {
        let mut out: Vec<Stage> = Vec::new();
        for s in self.step.iter().flat_map(Node::stages) {
            if !out.contains(&s) {
                out.push(s);
            }
        }
        out
    }
    /// The step's stages as the GPU records them (a repeat's `max_iterations` times).
    pub fn recorded_step(&self) -> Vec<Stage> {
        self.step.iter().flat_map(Node::recorded).collect()
    }
    /// Whether the solver slots exist (a repeat in the step).
    pub fn has_solvers(&self) -> bool {
        self.step.iter().any(|n| matches!(n, Node::Repeat(_)))
    }
    /// The optional fields and tables the scene holds.
    pub fn held(&self) -> crate::fields::Held {
        let f = &self.features;
        crate::fields::Held {
            heat: f.heat,
            interface: f.interface,
            bodies: f.bodies,
            implicit_heat: f.implicit_heat,
            solvers: self.has_solvers(),
            continuity: f.continuity,
            solidification: f.solidification,
            dfsph: f.dfsph,
        }
    }
    /// Leave `stage` out of every later step (bench throughput).
    pub fn skip(&mut self, stage: Stage) {
        self.step.retain(|n| *n != Node::Stage(stage));
        for n in &mut self.step {
            if let Node::Repeat(r) = n {
                r.stages.retain(|s| *s != stage);
            }
        }
    }
    /// Pass names (WGSL files), each once, in the pass table's order, for
    /// `spatter validate`.
    pub fn pass_names(&self) -> Vec<&'static str> {
        let stages = self.step_stages();
        let mut names: Vec<&'static str> = Vec::new();
        for d in super::STAGES.iter().filter(|d| stages.contains(&d.stage)) {
            if !names.contains(&d.file) {
                names.push(d.file);
            }
        }
        names
    }
    /// The step as `validate` prints it: stage names in order, a repeat as
    /// `repeat ≤N [a, b]` after its begin stage.
    pub fn describe_step(&self) -> String {
        self.step
            .iter()
            .map(|n| match n {
                Node::Stage(s) => s.name().to_string(),
                Node::Repeat(r) => format!(
                    "{}, repeat <= {} until converged [{}]",
                    r.begin.name(),
                    r.max_iterations,
                    r.stages
                        .iter()
                        .map(|s| s.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_formulation_has_one_row() {
        for (k, d) in FORMULATIONS.iter().enumerate() {
            assert!(!FORMULATIONS[k + 1..]
                .iter()
                .any(|o| o.formulation == d.formulation));
        }
    }

    #[test]
    fn solver_slots_are_numbered_in_order() {
        for (k, (slot, _)) in SOLVER_SLOTS.iter().enumerate() {
            assert_eq!(*slot as usize, k);
        }
    }
}
