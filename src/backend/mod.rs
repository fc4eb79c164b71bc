//! The two backends behind one interface. A step is a formulation's schedule
//! (schedule.rs: nodes, each a stage or a bounded repeat) over the pass table
//! (passes.rs: each stage's WGSL entry points, when each runs, and its CPU twin).

pub mod cpu;
pub mod gpu;

mod passes;
mod schedule;
pub mod terms;

pub use passes::{entry_points, Dispatch, Features, Stage, StageDef, Twin, Work, STAGES};
pub use schedule::{
    formulation, FormulationDef, Node, Pipeline, Repeat, SolverSlot, FORMULATIONS, SOLVER_SLOTS,
};

use crate::state::{Sim, State};

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
    /// One node of the schedule. A repeat runs its begin stage, then its stages
    /// `max_iterations` times: after the solver's flag is set every kernel of the
    /// loop returns at once (both backends), so running them all gives the state
    /// an early stop gives (the CPU stops early).
    fn run_node(&mut self, node: &Node) {
        match node {
            Node::Stage(s) => self.run_stage(*s),
            Node::Repeat(r) => {
                self.run_stage(r.begin);
                for _ in 0..r.max_iterations {
                    for &s in &r.stages {
                        self.run_stage(s);
                    }
                }
            }
        }
    }
    /// Run `n` whole steps without reading anything back.
    fn run_steps(&mut self, n: u32) {
        let step = self.pipeline().step.clone();
        for _ in 0..n {
            for node in &step {
                self.run_node(node);
            }
        }
    }
    fn prime(&mut self) {
        for node in self.pipeline().prime.clone() {
            self.run_node(&node);
        }
    }
    fn read_state(&mut self) -> Result<State, DeviceLost>;
    /// Replace the device state with `st` (same particle count): resume from a
    /// checkpoint, or rewind to the last good state when the watchdog trips.
    fn load_state(&mut self, st: &State);
    fn read_sim(&mut self) -> Result<Sim, DeviceLost>;
    /// Replace the Sim block alone (the run loop sets its end time).
    fn write_sim(&mut self, sim: &Sim);
    /// Milliseconds per pass summed since the last call, where the backend measures them.
    fn take_pass_times(&mut self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
}
