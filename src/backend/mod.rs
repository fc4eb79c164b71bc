//! The two backends behind one interface. A step is a fixed sequence of stages
//! (passes.rs: the pass table, its order and the features that select stages);
//! each stage has WGSL entry points and a Rust twin of the same name.

pub mod cpu;
pub mod gpu;

mod passes;
pub mod terms;

pub use passes::{entry_points, Dispatch, Features, Stage, StageDef, Work, PRIME, STAGES, STEP};

use crate::params::Params;
use crate::state::{Sim, State};

/// The stages a scene runs: only what its physics needs (DESIGN.md). A scene
/// without wall particles has no wall pass, a scene without fluid no flow passes,
/// a scene without temperature no heat pass (and no heat buffers).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pipeline {
    pub features: Features,
    pub step: Vec<Stage>,
    pub prime: Vec<Stage>,
}

impl Pipeline {
    pub fn for_scene(params: &Params, st: &State) -> Pipeline {
        let features = Features::of(params, st);
        let needed = |s: &&Stage| (s.def().needed)(&features);
        Pipeline {
            features,
            step: STEP.iter().filter(needed).copied().collect(),
            prime: PRIME.iter().filter(needed).copied().collect(),
        }
    }
    /// Pass names (WGSL files), each once, in the pass table's order, for
    /// `spatter validate`.
    pub fn pass_names(&self) -> Vec<&'static str> {
        let mut names: Vec<&'static str> = Vec::new();
        for d in STAGES.iter().filter(|d| self.step.contains(&d.stage)) {
            if !names.contains(&d.file) {
                names.push(d.file);
            }
        }
        names
    }
}

/// The device stopped answering: lost, or a readback that never completed. The
/// run that meets it closes its outputs at the last state it read back.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DeviceLost(pub String);

impl std::fmt::Display for DeviceLost {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl std::error::Error for DeviceLost {}

pub trait Backend {
    /// "cpu (2 threads)" or "gpu: <adapter> (<driver>)".
    fn describe(&self) -> String;
    /// True for a software rasteriser (lavapipe): bit-identical results are expected.
    fn is_software(&self) -> bool;
    /// The stages this scene runs.
    fn pipeline(&self) -> &Pipeline;
    /// Leave `stage` out of every later step. For `bench throughput` only, which
    /// measures what an optional pass costs by running the same scene with and
    /// without it: what the steps then compute is not the scene's physics.
    fn skip_stage(&mut self, stage: Stage);
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
    fn read_state(&mut self) -> Result<State, DeviceLost>;
    /// Replace the device state with `st` (same particle count): resume from a
    /// checkpoint, or rewind to the last good state when the watchdog trips.
    fn load_state(&mut self, st: &State);
    fn read_sim(&mut self) -> Result<Sim, DeviceLost>;
    /// Milliseconds per pass summed since the last call, where the backend measures them.
    fn take_pass_times(&mut self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
}
