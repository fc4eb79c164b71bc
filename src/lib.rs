//! spatter: SPH for additive-manufacturing process physics, with a GPU path (wgpu)
//! and a bit-matched CPU reference path.

pub mod backend;
pub mod bench;
pub mod bodies;
pub mod checkpoint;
pub mod checks;
pub mod compare;
pub mod diagnostics;
pub mod error;
pub mod fields;
pub mod gpu_layout;
pub mod host;
pub mod inspect;
pub mod kernel;
pub mod lanes;
pub mod load;
pub mod model;
pub mod outflow;
pub mod output;
pub mod params;
pub mod pool;
pub mod portable_math;
pub mod powder;
pub mod random;
pub mod run;
pub mod scene;
pub mod setup;
pub mod solidification;
pub mod state;
pub mod sweep;
pub mod track;
pub mod watchdog;
