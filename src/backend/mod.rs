//! The two backends behind one interface. A step is a fixed sequence of stages; each
//! stage is one pass with a WGSL file and a Rust twin of the same name.

pub mod cpu;
pub mod gpu;

use crate::params::Params;
use crate::state::{Sim, State};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// integrate.wgsl `kick_drift`: half kick, transport-velocity drift, periodic wrap.
    KickDrift,
    /// neighbors.wgsl: cell keys, stable (cell, index) sort, reorder, cell table.
    Neighbors,
    /// density.wgsl: summation density and equation of state.
    Density,
    /// wall.wgsl: Adami (2012) wall pressure and velocity.
    Wall,
    /// forces.wgsl: F22 (23) pressure + viscous forces, background pressure, gravity.
    Forces,
    /// interface.wgsl: Shepard sum, then interface normal and surface delta.
    Interface,
    /// laser.wgsl: Beer–Lambert absorption with column binning, or the Gaussian
    /// surface flux F22 (17); source (W/kg) in heat.w.
    Laser,
    /// heat.wgsl `conduct`: conduction dh/dt and the explicit Euler enthalpy update.
    Heat,
    /// heat.wgsl `temperature`: T and liquid fraction from the enthalpy.
    Temperature,
    /// integrate.wgsl `kick`: second half kick.
    Kick,
    /// timestep.wgsl: max |u|, |a| reductions and the F22 (42) time step.
    Timestep,
}

impl Stage {
    pub fn name(self) -> &'static str {
        match self {
            Stage::KickDrift => "integrate.kick_drift",
            Stage::Neighbors => "neighbors",
            Stage::Density => "density",
            Stage::Wall => "wall",
            Stage::Forces => "forces",
            Stage::Interface => "interface",
            Stage::Laser => "laser",
            Stage::Heat => "heat.conduct",
            Stage::Temperature => "heat.temperature",
            Stage::Kick => "integrate.kick",
            Stage::Timestep => "timestep",
        }
    }
    /// The compute pass (WGSL file) a stage belongs to.
    pub fn pass(self) -> &'static str {
        match self {
            Stage::KickDrift | Stage::Kick => "integrate",
            Stage::Heat | Stage::Temperature => "heat",
            other => other.name(),
        }
    }
}

/// One velocity-Verlet (kick–drift–kick) step with every stage a scene can need.
/// Heat is explicit Euler inside the step: conduction reads the temperatures of the
/// previous step, then the temperatures follow the new enthalpies.
pub const STEP: [Stage; 11] = [
    Stage::KickDrift,
    Stage::Neighbors,
    Stage::Density,
    Stage::Wall,
    Stage::Interface,
    Stage::Forces,
    Stage::Laser,
    Stage::Heat,
    Stage::Temperature,
    Stage::Kick,
    Stage::Timestep,
];

/// Run once before the first step: accelerations, temperatures and Δt of the
/// initial state.
pub const PRIME: [Stage; 7] = [
    Stage::Neighbors,
    Stage::Density,
    Stage::Wall,
    Stage::Interface,
    Stage::Forces,
    Stage::Temperature,
    Stage::Timestep,
];

/// The compute passes in the order `spatter validate` lists them.
const PASS_ORDER: [&str; 9] = [
    "neighbors",
    "density",
    "wall",
    "interface",
    "forces",
    "laser",
    "heat",
    "integrate",
    "timestep",
];

/// The stages a scene runs: only what its physics needs (DESIGN.md). A scene
/// without wall particles has no wall pass, a scene without fluid no flow passes,
/// a scene without temperature no heat pass (and no heat buffers).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pipeline {
    pub step: Vec<Stage>,
    pub prime: Vec<Stage>,
}

impl Pipeline {
    pub fn for_scene(params: &Params, st: &State) -> Pipeline {
        let walls = st.phase.iter().any(|&p| params.is_wall(p));
        // Fluid now, or later: a solid that melts becomes fluid.
        let fluid = st.phase.iter().any(|&p| !params.is_wall(p))
            || (0..crate::model::MAX_PHASES as u32).any(|p| params.switch_target(p).is_some());
        let heat = params.heat[2] != 0.0;
        let needed = |s: &&Stage| match **s {
            Stage::Wall => walls && fluid,
            Stage::KickDrift | Stage::Density | Stage::Forces | Stage::Kick => fluid,
            Stage::Heat | Stage::Temperature => heat,
            Stage::Laser => params.laser[3] != 0.0,
            Stage::Interface => params.heat[3] != 0.0,
            Stage::Neighbors | Stage::Timestep => true,
        };
        Pipeline {
            step: STEP.iter().filter(needed).copied().collect(),
            prime: PRIME.iter().filter(needed).copied().collect(),
        }
    }
    /// Pass names, each once, for `spatter validate`.
    pub fn pass_names(&self) -> Vec<&'static str> {
        PASS_ORDER
            .iter()
            .copied()
            .filter(|n| self.step.iter().any(|s| s.pass() == *n))
            .collect()
    }
}

pub trait Backend {
    /// "cpu (2 threads)" or "gpu: <adapter> (<driver>)".
    fn describe(&self) -> String;
    /// True for a software rasteriser (lavapipe): bit-identical results are expected.
    fn is_software(&self) -> bool;
    /// The stages this scene runs.
    fn pipeline(&self) -> &Pipeline;
    fn run_stage(&mut self, stage: Stage);
    /// Run `n` whole steps without reading anything back.
    fn run_steps(&mut self, n: u32) {
        let step = self.pipeline().step.clone();
        for _ in 0..n {
            for &s in &step {
                self.run_stage(s);
            }
        }
    }
    fn prime(&mut self) {
        for s in self.pipeline().prime.clone() {
            self.run_stage(s);
        }
    }
    fn read_state(&mut self) -> State;
    /// Replace the device state with `st` (same particle count): resume from a
    /// checkpoint, or rewind to the last good state when the watchdog trips.
    fn load_state(&mut self, st: &State);
    fn read_sim(&mut self) -> Sim;
    /// Milliseconds per pass summed since the last call, where the backend measures them.
    fn take_pass_times(&mut self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
}
