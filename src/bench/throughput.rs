//! `spatter bench throughput`: the 3D dam break at several sizes on each backend.
//! Reports particle-steps/s (GPUSPH's MIPPS unit ×1e6), pair interactions/s
//! (DualSPHysics' PIPS), per-pass milliseconds and memory per particle, then per
//! backend how the cost of a particle-step grows from the smallest size to the
//! largest.

use crate::backend::cpu::CpuBackend;
use crate::backend::gpu::{AdapterChoice, GpuBackend, GpuContext};
use crate::backend::Backend;
use crate::error::SpatterError;
use crate::params::Params;
use crate::run::{BackendChoice, Loaded};
use crate::{model, scene, setup};
use std::time::Instant;

const SCENE: &str = include_str!("../../scenarios/validation/dam_break_3d.toml");
const SCENE_NAME: &str = "scenarios/validation/dam_break_3d.toml";
/// Software adapters run ~1000× slower than a GPU; larger sizes would take hours.
const SOFTWARE_MAX_PARTICLES: usize = 150_000;

#[derive(serde::Serialize)]
pub struct BenchRow {
    pub backend: String,
    pub particles: usize,
    pub dx: f64,
    pub steps: u32,
    pub wall_s: f64,
    pub particle_steps_per_s: f64,
    pub pair_interactions_per_s: f64,
    pub neighbours_per_fluid_particle: f64,
    /// Device (or host) memory the scene takes per particle: its fields and their
    /// reorder scratch, sort keys, and the cell table spread over the particles
    /// (setup::memory_estimate).
    pub bytes_per_particle: f64,
    pub pass_ms: Vec<(String, f64)>,
}

fn load_at(dx: f64) -> Result<Loaded, SpatterError> {
    let sets = [format!("dx={dx}")];
    let (sc, resolved) = scene::parse_str(SCENE_NAME, SCENE, &sets)?;
    let model = model::build(SCENE_NAME, &sc, &resolved)?;
    let state = setup::generate(&model, &sc)?;
    Ok(Loaded { model, state })
}

/// Scene with about `target` particles: Δx scaled by the cube root of the count ratio.
fn scene_of_size(target: f64) -> Result<Loaded, SpatterError> {
    let (sc, resolved) = scene::parse_str(SCENE_NAME, SCENE, &[])?;
    let mut dx = model::build(SCENE_NAME, &sc, &resolved)?.dx;
    let mut l = load_at(dx)?;
    for _ in 0..4 {
        let ratio = l.state.len() as f64 / target;
        if (ratio - 1.0).abs() < 0.1 {
            break;
        }
        dx *= ratio.cbrt();
        l = load_at(dx)?;
    }
    Ok(l)
}

fn measure(
    l: &Loaded,
    backend: &mut dyn Backend,
    steps: u32,
    pairs: u64,
) -> Result<BenchRow, SpatterError> {
    let lost = |e: crate::backend::DeviceLost| SpatterError::Runtime(e.to_string());
    backend.prime();
    backend.run_steps(2);
    backend.read_sim().map_err(lost)?;
    backend.take_pass_times();
    let t0 = Instant::now();
    backend.run_steps(steps);
    backend.read_sim().map_err(lost)?;
    let wall_s = t0.elapsed().as_secs_f64();
    let n = l.state.len();
    let fluid = l
        .state
        .phase
        .iter()
        .filter(|&&p| l.model.phases[p as usize].is_fluid())
        .count()
        .max(1);
    Ok(BenchRow {
        backend: backend.describe(),
        particles: n,
        dx: l.model.dx,
        steps,
        wall_s,
        particle_steps_per_s: n as f64 * steps as f64 / wall_s,
        pair_interactions_per_s: pairs as f64 * steps as f64 / wall_s,
        neighbours_per_fluid_particle: pairs as f64 / fluid as f64,
        bytes_per_particle: setup::memory_estimate(&l.model, n as f64) / n as f64,
        pass_ms: Vec::new(),
    })
}

fn per_step(times: Vec<(&'static str, f64)>, steps: u32) -> Vec<(String, f64)> {
    times
        .into_iter()
        .map(|(n, ms)| (n.to_string(), ms / steps as f64))
        .collect()
}

pub fn throughput(
    sizes: &[f64],
    steps: u32,
    backends: &[BackendChoice],
    json: Option<&str>,
) -> Result<(), SpatterError> {
    let want_cpu = backends.is_empty() || backends.contains(&BackendChoice::Cpu);
    let want_gpu = backends.is_empty() || backends.iter().any(|b| *b != BackendChoice::Cpu);
    let mut rows = Vec::new();
    println!("bench throughput: {SCENE_NAME}, {steps} timed steps per size after 2 warm-up steps");
    for &target in sizes {
        let l = scene_of_size(target)?;
        let params = Params::new(&l.model, l.state.len() as u32);
        let mut cpu = CpuBackend::new(params, l.state.clone());
        cpu.prime();
        let pairs = cpu.pair_count();
        if want_cpu {
            let mut cpu = CpuBackend::new(params, l.state.clone());
            let mut row = measure(&l, &mut cpu, steps, pairs)?;
            row.pass_ms = per_step(cpu.take_pass_times(), steps);
            print_row(&row);
            rows.push(row);
        }
        if want_gpu {
            let Ok(ctx) = GpuContext::open(AdapterChoice::AnyGpu, false) else {
                println!("gpu: no Vulkan adapter; skipped");
                continue;
            };
            if ctx.is_software() && l.state.len() > SOFTWARE_MAX_PARTICLES {
                println!(
                    "{}: {} particles skipped (software adapter)",
                    ctx.describe(),
                    l.state.len()
                );
                continue;
            }
            let mut gpu =
                GpuBackend::new(ctx, params, &l.state, false).map_err(SpatterError::Runtime)?;
            let mut row = measure(&l, &mut gpu, steps, pairs)?;
            // Per-pass times from a separate timestamped run: timestamps need one
            // submission per step, which would slow the throughput figure.
            if let Ok(ctx) = GpuContext::open(AdapterChoice::AnyGpu, true) {
                if let Ok(mut prof) = GpuBackend::new(ctx, params, &l.state, true) {
                    prof.prime();
                    let k = steps.clamp(1, 5);
                    prof.run_steps(k);
                    row.pass_ms = per_step(prof.take_pass_times(), k);
                }
            }
            print_row(&row);
            rows.push(row);
        }
    }
    print_growth(&rows);
    if let Some(path) = json {
        super::write_json(path, &rows)?;
    }
    Ok(())
}

/// Per backend, how the cost of a particle-step grows from the smallest size
/// measured to the largest (DESIGN.md asks for at most 20% from 1e4 to 1e7).
fn print_growth(rows: &[BenchRow]) {
    let mut backends: Vec<&str> = Vec::new();
    for r in rows {
        if !backends.contains(&r.backend.as_str()) {
            backends.push(&r.backend);
        }
    }
    for b in backends {
        let mine: Vec<&BenchRow> = rows.iter().filter(|r| r.backend == b).collect();
        let (Some(small), Some(large)) = (
            mine.iter().min_by_key(|r| r.particles),
            mine.iter().max_by_key(|r| r.particles),
        ) else {
            continue;
        };
        if small.particles == large.particles {
            continue;
        }
        let ns = |r: &BenchRow| 1e9 / r.particle_steps_per_s;
        println!(
            "{b}: cost per particle-step {:.1} ns at {} particles, {:.1} ns at {} ({:+.0}%)",
            ns(small),
            small.particles,
            ns(large),
            large.particles,
            100.0 * (ns(large) / ns(small) - 1.0)
        );
    }
}

fn print_row(r: &BenchRow) {
    println!(
        "{} | {} particles (dx {:.3e} m, {:.1} neighbours, {:.0} B/particle) | {:.3e} particle-steps/s | {:.3e} pair interactions/s | {:.3} s for {} steps",
        r.backend, r.particles, r.dx, r.neighbours_per_fluid_particle, r.bytes_per_particle, r.particle_steps_per_s, r.pair_interactions_per_s, r.wall_s, r.steps
    );
    if !r.pass_ms.is_empty() {
        let parts: Vec<String> = r
            .pass_ms
            .iter()
            .map(|(n, ms)| format!("{n} {ms:.3}"))
            .collect();
        println!("    ms/step: {}", parts.join(", "));
    }
}
