//! The two backends behind one interface. A step is a fixed sequence of stages; each
//! stage is one pass with a WGSL file and a Rust twin of the same name.

pub mod cpu;
pub mod gpu;

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
            Stage::Kick => "integrate.kick",
            Stage::Timestep => "timestep",
        }
    }
}

/// One velocity-Verlet (kick–drift–kick) step.
pub const STEP: [Stage; 7] = [
    Stage::KickDrift,
    Stage::Neighbors,
    Stage::Density,
    Stage::Wall,
    Stage::Forces,
    Stage::Kick,
    Stage::Timestep,
];

/// Run once before the first step: accelerations and Δt of the initial state.
pub const PRIME: [Stage; 5] = [
    Stage::Neighbors,
    Stage::Density,
    Stage::Wall,
    Stage::Forces,
    Stage::Timestep,
];

/// The compute passes of a WCSPH scene, as `spatter validate` lists them.
pub const WCSPH_PASSES: [&str; 6] = [
    "neighbors",
    "density",
    "wall",
    "forces",
    "integrate",
    "timestep",
];

pub trait Backend {
    /// "cpu (2 threads)" or "gpu: <adapter> (<driver>)".
    fn describe(&self) -> String;
    /// True for a software rasteriser (lavapipe): bit-identical results are expected.
    fn is_software(&self) -> bool;
    fn run_stage(&mut self, stage: Stage);
    /// Run `n` whole steps without reading anything back.
    fn run_steps(&mut self, n: u32) {
        for _ in 0..n {
            for s in STEP {
                self.run_stage(s);
            }
        }
    }
    fn prime(&mut self) {
        for s in PRIME {
            self.run_stage(s);
        }
    }
    fn read_state(&mut self) -> State;
    fn read_sim(&mut self) -> Sim;
    /// Milliseconds per pass summed since the last call, where the backend measures them.
    fn take_pass_times(&mut self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
}
