//! Benchmarks users can rerun: `throughput` (cost per particle-step against size),
//! `accuracy` (error against cost over resolution sweeps of the validation scenes)
//! and `stability` (long runs, parameter extremes and seeded random scenes).

pub mod accuracy;
pub mod plot;
mod random_scene;
pub mod stability;
pub mod throughput;

pub use throughput::throughput;

use crate::backend::gpu::{AdapterChoice, GpuContext};
use crate::error::SpatterError;
use crate::run::BackendChoice;

/// `auto` decided once for a whole benchmark: a hardware GPU if there is one, else
/// the CPU (the software adapter is for bit-match tests, not for benchmarks).
pub fn resolve_backend(choice: BackendChoice) -> BackendChoice {
    match choice {
        BackendChoice::Auto => match GpuContext::open(AdapterChoice::HardwareOnly, false) {
            Ok(_) => BackendChoice::Gpu,
            Err(_) => BackendChoice::Cpu,
        },
        c => c,
    }
}

/// Peak resident memory of this process since the last `reset_peak_rss`, in bytes
/// (Linux VmHWM); None where /proc does not say.
pub fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Restart the peak-memory mark (Linux: writing 5 to clear_refs resets VmHWM to the
/// current resident size), so each benchmark case reports its own peak.
pub fn reset_peak_rss() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

fn write_json<T: serde::Serialize>(path: &str, value: &T) -> Result<(), SpatterError> {
    let text =
        serde_json::to_string_pretty(value).map_err(|e| SpatterError::Runtime(e.to_string()))?;
    std::fs::write(path, text)
        .map_err(|e| SpatterError::Runtime(format!("cannot write {path}: {e}")))?;
    println!("wrote {path}");
    Ok(())
}
