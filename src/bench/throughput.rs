//! `spatter bench throughput`: a fluid-only scene (the 3D dam break), a heat
//! scene (the PBF line melt: conduction, laser, melting) and a rigid-body scene
//! (F22's 500-grain bed, every grain a body in contact) at sizes from 1e4 up to
//! 1e7 particles where memory and time allow, on each backend. Reports
//! particle-steps/s (GPUSPH's MIPPS unit ×1e6), pair interactions/s (DualSPHysics'
//! PIPS), per-pass milliseconds and memory per particle; then, at one size, what
//! each optional pass costs, measured by running the same scene with and without
//! it; and per scene and backend how the cost of a particle-step grows from the
//! smallest size to the largest.

use crate::backend::cpu::CpuBackend;
use crate::backend::gpu::{AdapterChoice, GpuBackend, GpuContext};
use crate::backend::Backend;
use crate::backend::Stage;
use crate::error::{InputError, SpatterError};
use crate::params::Params;
use crate::run::{BackendChoice, Loaded};
use crate::{model, scene, setup};
use std::time::Instant;

/// A scene the benchmark scales.
struct BenchScene {
    /// Name for `--scenes` and the report.
    name: &'static str,
    kind: &'static str,
    label: &'static str,
    text: &'static str,
}

const SCENES: [BenchScene; 3] = [
    BenchScene {
        name: "dam_break_3d",
        kind: "fluid-only",
        label: "scenarios/validation/dam_break_3d.toml",
        text: include_str!("../../scenarios/validation/dam_break_3d.toml"),
    },
    BenchScene {
        name: "line_melt",
        kind: "heat",
        label: "scenarios/pbf/line_melt_bare_plate.toml",
        text: include_str!("../../scenarios/pbf/line_melt_bare_plate.toml"),
    },
    BenchScene {
        name: "powder_bed",
        kind: "rigid bodies",
        label: "scenarios/bench/powder_bed_rigid_3d.toml",
        text: include_str!("../../scenarios/bench/powder_bed_rigid_3d.toml"),
    },
];

/// Stages a scene may or may not have: the ones whose cost is measured by leaving
/// them out.
const OPTIONAL: [Stage; 8] = [
    Stage::BodyDrift,
    Stage::BodyForces,
    Stage::Wall,
    Stage::Interface,
    Stage::SurfaceForces,
    Stage::Laser,
    Stage::Heat,
    Stage::Temperature,
];

/// Software adapters run ~1000× slower than a GPU; larger sizes would take hours.
const SOFTWARE_MAX_PARTICLES: usize = 150_000;
/// A size whose timed steps would take longer than this (projected from the
/// previous size's rate) is skipped with the projection printed.
const TIME_BUDGET_S: f64 = 240.0;
/// Alternations of with/without runs per optional pass (medians are reported).
/// Run-to-run spread on a shared 2-core machine is ±12–20%, so a pass below ~10%
/// of the step is within the noise: the report prints the pass timer beside it.
const PASS_COST_REPEATS: usize = 5;

#[derive(serde::Serialize)]
pub struct BenchRow {
    pub scene: String,
    pub kind: String,
    pub backend: String,
    pub particles: usize,
    pub dx: f64,
    pub steps: u32,
    pub wall_s: f64,
    /// Particles of fluid phases (liquid or gas); the rest are walls and solids,
    /// rigid bodies' members included.
    pub fluid_particles: usize,
    pub particle_steps_per_s: f64,
    pub pair_interactions_per_s: f64,
    pub neighbours_per_fluid_particle: f64,
    /// Device (or host) memory the scene takes per particle: its fields and their
    /// reorder scratch, sort keys, and the cell table spread over the particles
    /// (setup::memory_estimate).
    pub bytes_per_particle: f64,
    /// The CPU backend's neighbour list on top (cpu/neighbors/walks.rs `NeighborList`:
    /// 4 bytes per entry, as primed: a fluid particle's or conducting solid's
    /// neighbours and itself; and an offset per particle),
    /// None on the GPU, which keeps none.
    pub list_bytes_per_particle: Option<f64>,
    pub pass_ms: Vec<(String, f64)>,
}

/// What leaving one optional pass out of the same scene saves.
#[derive(serde::Serialize)]
pub struct PassCost {
    pub scene: String,
    /// The pass's own timer (CPU) or timestamps (GPU) in the full run, ms per step.
    pub timer_ms_per_step: Option<f64>,
    pub backend: String,
    pub particles: usize,
    pub pass: String,
    pub ms_per_step_with: f64,
    pub ms_per_step_without: f64,
    pub ms_per_step: f64,
    pub share_of_step: f64,
}

#[derive(serde::Serialize)]
pub struct ThroughputReport {
    pub rows: Vec<BenchRow>,
    pub pass_costs: Vec<PassCost>,
    pub skipped: Vec<String>,
}

pub struct Options<'a> {
    pub sizes: &'a [f64],
    pub steps: u32,
    pub backends: &'a [BackendChoice],
    pub scenes: &'a [String],
    /// Size (particles) at which the optional passes are costed; None: not costed.
    pub pass_costs_at: Option<f64>,
    pub json: Option<&'a str>,
}

fn load_at(s: &BenchScene, dx: f64) -> Result<Loaded, SpatterError> {
    Ok(crate::run::load_str(
        s.label,
        s.text,
        &[format!("dx={dx}")],
    )?)
}

/// Δx that gives about `target` particles: scaled by the count ratio's root of
/// the scene's dimension. Err(why) when the scene refuses the spacing that
/// size needs (the powder bed's smallest grains cover no lattice site below
/// about 3e4 particles): that size is skipped, the others are measured.
fn scene_of_size(s: &BenchScene, target: f64) -> Result<Result<Loaded, String>, SpatterError> {
    let (sc, resolved) = scene::parse_str(s.label, s.text, &[])?;
    let mut dx = model::build(s.label, &sc, &resolved)?.dx;
    let mut l = load_at(s, dx)?;
    for _ in 0..4 {
        let ratio = l.state.len() as f64 / target;
        if (ratio - 1.0).abs() < 0.1 {
            break;
        }
        dx *= ratio.powf(1.0 / l.model.dim as f64);
        l = match load_at(s, dx) {
            Ok(l) => l,
            Err(SpatterError::Input(e)) => {
                return Ok(Err(format!(
                    "the scene is refused at dx = {dx:.3e} m, the spacing that size needs ({e})"
                )))
            }
            Err(e) => return Err(e),
        };
    }
    Ok(Ok(l))
}

fn lost(e: crate::backend::DeviceLost) -> SpatterError {
    SpatterError::Runtime(e.to_string())
}

/// Seconds for `steps` steps after a warm-up.
fn time_steps(backend: &mut dyn Backend, steps: u32) -> Result<f64, SpatterError> {
    backend.run_steps(2);
    backend.read_sim().map_err(lost)?;
    let t0 = Instant::now();
    backend.run_steps(steps);
    backend.read_sim().map_err(lost)?;
    Ok(t0.elapsed().as_secs_f64())
}

fn measure(
    s: &BenchScene,
    l: &Loaded,
    backend: &mut dyn Backend,
    steps: u32,
    (pairs, listed): (u64, u64),
) -> Result<BenchRow, SpatterError> {
    backend.prime();
    backend.run_steps(2);
    backend.read_sim().map_err(lost)?;
    backend.take_pass_times();
    let wall_s = time_steps(backend, steps)?;
    let n = l.state.len();
    // A heat scene may start without fluid (a solid plate): no fluid pairs to count.
    let fluid = l
        .state
        .phase
        .iter()
        .filter(|&&p| l.model.phases[p as usize].is_fluid())
        .count();
    let per_fluid = |x: f64| if fluid > 0 { x } else { f64::NAN };
    Ok(BenchRow {
        scene: s.name.into(),
        kind: s.kind.into(),
        backend: backend.describe(),
        particles: n,
        fluid_particles: fluid,
        dx: l.model.dx,
        steps,
        wall_s,
        particle_steps_per_s: n as f64 * steps as f64 / wall_s,
        pair_interactions_per_s: per_fluid(pairs as f64 * steps as f64 / wall_s),
        neighbours_per_fluid_particle: per_fluid(pairs as f64 / fluid.max(1) as f64),
        bytes_per_particle: setup::memory_estimate(&l.model, n as f64) / n as f64,
        list_bytes_per_particle: backend
            .describe()
            .starts_with("cpu")
            .then(|| 4.0 * (listed as f64 + n as f64) / n as f64),
        pass_ms: Vec::new(),
    })
}

fn per_step(times: Vec<(&'static str, f64)>, steps: u32) -> Vec<(String, f64)> {
    times
        .into_iter()
        .map(|(n, ms)| (n.to_string(), ms / steps as f64))
        .collect()
}

/// A backend for the scene: "cpu", or the GPU (None when there is none, or a
/// software adapter and a scene too large for it).
type Make<'a> = dyn Fn(&Loaded) -> Result<Option<Box<dyn Backend>>, SpatterError> + 'a;

fn cpu_backend(l: &Loaded) -> Result<Option<Box<dyn Backend>>, SpatterError> {
    let params = Params::new(&l.model, l.state.len() as u32);
    Ok(Some(Box::new(CpuBackend::new(params, l.state.clone()))))
}

fn gpu_backend(l: &Loaded, profile: bool) -> Result<Option<Box<dyn Backend>>, SpatterError> {
    let Ok(ctx) = GpuContext::open(AdapterChoice::AnyGpu, profile) else {
        return Ok(None);
    };
    if ctx.is_software() && l.state.len() > SOFTWARE_MAX_PARTICLES {
        return Ok(None);
    }
    let params = Params::new(&l.model, l.state.len() as u32);
    let b = GpuBackend::new(ctx, params, &l.state, profile).map_err(SpatterError::Runtime)?;
    Ok(Some(Box::new(b)))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// Per optional pass the scene runs: ms per step with it and without it, from
/// alternating runs of the same scene, medians of `PASS_COST_REPEATS`.
fn pass_costs(
    s: &BenchScene,
    l: &Loaded,
    make: &Make,
    steps: u32,
    timers: &[(String, f64)],
) -> Result<Vec<PassCost>, SpatterError> {
    let Some(probe) = make(l)? else {
        return Ok(Vec::new());
    };
    let backend = probe.describe();
    let present: Vec<Stage> = OPTIONAL
        .into_iter()
        .filter(|st| probe.pipeline().step_stages().contains(st))
        .collect();
    drop(probe);
    let mut costs = Vec::new();
    for stage in present {
        let (mut with, mut without) = (Vec::new(), Vec::new());
        for _ in 0..PASS_COST_REPEATS {
            for skip in [false, true] {
                let Some(mut b) = make(l)? else {
                    return Ok(costs);
                };
                b.prime();
                if skip {
                    b.skip_stage(stage);
                }
                let ms = 1e3 * time_steps(b.as_mut(), steps)? / steps as f64;
                if skip { &mut without } else { &mut with }.push(ms);
            }
        }
        let (w, wo) = (median(with), median(without));
        costs.push(PassCost {
            scene: s.name.into(),
            timer_ms_per_step: timers
                .iter()
                .filter(|(n, _)| {
                    let name = stage.def().name;
                    n == name
                        || n.strip_prefix(name)
                            .is_some_and(|rest| rest.starts_with('.'))
                })
                .map(|(_, ms)| ms)
                .copied()
                .reduce(|a, b| a + b),
            backend: backend.clone(),
            particles: l.state.len(),
            pass: stage.def().name.into(),
            ms_per_step_with: w,
            ms_per_step_without: wo,
            ms_per_step: w - wo,
            share_of_step: (w - wo) / w,
        });
    }
    Ok(costs)
}

fn chosen(names: &[String]) -> Result<Vec<&'static BenchScene>, SpatterError> {
    if names.is_empty() {
        return Ok(SCENES.iter().collect());
    }
    names
        .iter()
        .map(|n| {
            SCENES.iter().find(|s| s.name == n).ok_or_else(|| {
                InputError::new(
                    "bench throughput",
                    "--scenes",
                    format!("unknown scene `{n}` (known: dam_break_3d, line_melt, powder_bed)"),
                )
                .into()
            })
        })
        .collect()
}

/// Why a (backend, size) is not measured: memory, or the time it would take.
fn too_big(l: &Loaded, rate: Option<f64>, steps: u32) -> Option<String> {
    let n = l.state.len() as f64;
    // The CPU backend holds the state, its reorder scratch and the initial copy.
    let need = 2.0 * setup::memory_estimate(&l.model, n);
    if let Some(free) = crate::host::available_memory() {
        if need > free {
            return Some(format!(
                "needs {:.1} GiB, {:.1} GiB free",
                need / 1073741824.0,
                free / 1073741824.0
            ));
        }
    }
    let projected = rate.map(|r| n * steps as f64 / r)?;
    (projected > TIME_BUDGET_S).then(|| {
        format!("projected {projected:.0} s for {steps} steps (budget {TIME_BUDGET_S:.0} s)")
    })
}

pub fn throughput(opts: &Options) -> Result<(), SpatterError> {
    let want_cpu = opts.backends.is_empty() || opts.backends.contains(&BackendChoice::Cpu);
    let want_gpu =
        opts.backends.is_empty() || opts.backends.iter().any(|b| *b != BackendChoice::Cpu);
    let mut report = ThroughputReport {
        rows: Vec::new(),
        pass_costs: Vec::new(),
        skipped: Vec::new(),
    };
    let steps = opts.steps;
    for s in chosen(opts.scenes)? {
        println!(
            "bench throughput: {} ({}, {}), {steps} timed steps per size after 2 warm-up steps",
            s.name, s.kind, s.label
        );
        let mut last_rate: [Option<f64>; 2] = [None, None];
        for &target in opts.sizes {
            let l = match scene_of_size(s, target)? {
                Ok(l) => l,
                Err(why) => {
                    let line = format!("{}: about {target:.0} particles skipped: {why}", s.name);
                    println!("{line}");
                    report.skipped.push(line);
                    continue;
                }
            };
            let mut cpu =
                CpuBackend::new(Params::new(&l.model, l.state.len() as u32), l.state.clone());
            cpu.prime();
            let pairs = cpu.pair_count();
            // what one step lists (the density or continuity pass records it)
            cpu.run_steps(1);
            let listed = cpu.listed_count();
            drop(cpu);
            let makers: [(bool, &Make); 2] = [
                (want_cpu, &cpu_backend),
                (want_gpu, &|l: &Loaded| gpu_backend(l, false)),
            ];
            for (k, (wanted, make)) in makers.into_iter().enumerate() {
                if !wanted {
                    continue;
                }
                let which = ["cpu", "gpu"][k];
                if let Some(why) = too_big(&l, if k == 0 { last_rate[0] } else { None }, steps) {
                    let line = format!(
                        "{}: {which} at {} particles skipped: {why}",
                        s.name,
                        l.state.len()
                    );
                    println!("{line}");
                    report.skipped.push(line);
                    continue;
                }
                let Some(mut b) = make(&l)? else {
                    let line = format!("{}: {which} at {} particles skipped: no adapter, or a software adapter above {SOFTWARE_MAX_PARTICLES} particles", s.name, l.state.len());
                    println!("{line}");
                    report.skipped.push(line);
                    continue;
                };
                let mut row = measure(s, &l, b.as_mut(), steps, (pairs, listed))?;
                row.pass_ms = per_step(b.take_pass_times(), steps + 2);
                drop(b);
                if k == 1 {
                    row.pass_ms = gpu_pass_times(&l, steps);
                }
                last_rate[k] = Some(row.particle_steps_per_s);
                print_row(&row);
                report.rows.push(row);
            }
            let costed = opts
                .pass_costs_at
                .is_some_and(|at| (l.state.len() as f64 / at - 1.0).abs() < 0.35);
            if costed {
                let makers: [(bool, &Make); 2] = [
                    (want_cpu, &cpu_backend),
                    (want_gpu, &|l: &Loaded| gpu_backend(l, false)),
                ];
                for (k, (wanted, make)) in makers.into_iter().enumerate() {
                    if wanted {
                        let timers = report
                            .rows
                            .iter()
                            .rev()
                            .find(|r| {
                                r.scene == s.name
                                    && r.particles == l.state.len()
                                    && r.backend.starts_with(["cpu", "gpu"][k])
                            })
                            .map(|r| r.pass_ms.clone())
                            .unwrap_or_default();
                        let costs = pass_costs(s, &l, make, steps, &timers)?;
                        print_costs(&costs);
                        report.pass_costs.extend(costs);
                    }
                }
            }
        }
    }
    print_growth(&report.rows);
    for line in heat_ratio_lines(&report.rows) {
        println!("{line}");
    }
    if let Some(path) = opts.json {
        super::write_json(path, &report)?;
    }
    Ok(())
}

/// Per-pass times from a separate timestamped run: timestamps need one submission
/// per step, which would slow the throughput figure.
fn gpu_pass_times(l: &Loaded, steps: u32) -> Vec<(String, f64)> {
    let Ok(Some(mut prof)) = gpu_backend(l, true) else {
        return Vec::new();
    };
    prof.prime();
    let k = steps.clamp(1, 5);
    prof.run_steps(k);
    per_step(prof.take_pass_times(), k)
}

/// Per scene and backend, how the cost of a particle-step grows from the smallest
/// size measured to the largest (docs/design.md asks for at most 40% from 1e4 to 1e6,
/// then at most 20% on to 1e7), and why: the same cost per fluid particle-step
/// and per fluid pair (a scaled scene keeps its walls a few layers thick, so
/// small scenes are mostly wall, whose particles cost a fraction of a fluid
/// one's), and each pass's share of the change.
/// What a melt-pool step costs per particle against a plain fluid step: per
/// backend, each line_melt row over the dam_break_3d row nearest its size
/// (within a third of it).
fn heat_ratio_lines(rows: &[BenchRow]) -> Vec<String> {
    let mut out = Vec::new();
    for heat in rows.iter().filter(|r| r.scene == "line_melt") {
        let near = rows
            .iter()
            .filter(|r| r.scene == "dam_break_3d" && r.backend == heat.backend)
            .filter(|r| (r.particles as f64 / heat.particles as f64 - 1.0).abs() < 1.0 / 3.0)
            .min_by_key(|r| r.particles.abs_diff(heat.particles));
        if let Some(fluid) = near {
            out.push(format!(
                "line_melt / dam_break_3d, {}: a melt-pool step costs {:.2}x a fluid step per particle ({} and {} particles)",
                heat.backend,
                fluid.particle_steps_per_s / heat.particle_steps_per_s,
                heat.particles,
                fluid.particles
            ));
        }
    }
    out
}

fn print_growth(rows: &[BenchRow]) {
    let mut keys: Vec<(&str, &str)> = Vec::new();
    for r in rows {
        if !keys.contains(&(r.scene.as_str(), r.backend.as_str())) {
            keys.push((&r.scene, &r.backend));
        }
    }
    for (scene, b) in keys {
        let mine: Vec<&BenchRow> = rows
            .iter()
            .filter(|r| r.scene == scene && r.backend == b)
            .collect();
        let (Some(small), Some(large)) = (
            mine.iter().min_by_key(|r| r.particles),
            mine.iter().max_by_key(|r| r.particles),
        ) else {
            continue;
        };
        if small.particles == large.particles {
            continue;
        }
        for line in growth_lines(scene, b, small, large) {
            println!("{line}");
        }
    }
}

fn growth_lines(scene: &str, b: &str, small: &BenchRow, large: &BenchRow) -> Vec<String> {
    let change = |a: f64, b: f64| 100.0 * (b / a - 1.0);
    let ns = |r: &BenchRow| 1e9 / r.particle_steps_per_s;
    let mut out = vec![format!(
        "{scene}, {b}: cost per particle-step {:.1} ns at {} particles, {:.1} ns at {} ({:+.0}%)",
        ns(small),
        small.particles,
        ns(large),
        large.particles,
        change(ns(small), ns(large))
    )];
    let share = |r: &BenchRow| r.fluid_particles as f64 / r.particles as f64;
    if small.fluid_particles > 0 && large.fluid_particles > 0 {
        let per_fluid = |r: &BenchRow| ns(r) / share(r);
        let per_pair = |r: &BenchRow| 1e9 / r.pair_interactions_per_s;
        out.push(format!(
            "  fluid share {:.0}% -> {:.0}%: per fluid particle-step {:.1} -> {:.1} ns ({:+.0}%), per fluid pair {:.2} -> {:.2} ns ({:+.0}%)",
            100.0 * share(small),
            100.0 * share(large),
            per_fluid(small),
            per_fluid(large),
            change(per_fluid(small), per_fluid(large)),
            per_pair(small),
            per_pair(large),
            change(per_pair(small), per_pair(large)),
        ));
    }
    // Each pass's ns per particle-step at both ends: where the growth is.
    let per_particle = |r: &BenchRow, pass: &str| {
        r.pass_ms
            .iter()
            .find(|(n, _)| n == pass)
            .map(|(_, ms)| 1e6 * ms / r.particles as f64)
    };
    let mut passes: Vec<(String, f64, f64)> = small
        .pass_ms
        .iter()
        .filter_map(|(n, _)| Some((n.clone(), per_particle(small, n)?, per_particle(large, n)?)))
        .collect();
    passes.sort_by(|a, b| (b.2 - b.1).abs().total_cmp(&(a.2 - a.1).abs()));
    let shown: Vec<String> = passes
        .iter()
        .take(4)
        .map(|(n, a, b)| format!("{n} {a:.1} -> {b:.1} ({:+.1})", b - a))
        .collect();
    if !shown.is_empty() {
        out.push(format!(
            "  largest changes, ns per particle-step: {}",
            shown.join(", ")
        ));
    }
    out
}

fn print_costs(costs: &[PassCost]) {
    if let Some(c) = costs.first() {
        println!(
            "  optional passes, {} particles, {}: each left out of the same scene",
            c.particles, c.backend
        );
    }
    for c in costs {
        let timer = c
            .timer_ms_per_step
            .map_or(String::new(), |t| format!("; its timer: {t:.3}"));
        println!(
            "    {:<17} {:.3} ms/step ({:.1}% of the step; {:.3} with, {:.3} without{timer})",
            c.pass,
            c.ms_per_step,
            100.0 * c.share_of_step,
            c.ms_per_step_with,
            c.ms_per_step_without,
        );
    }
}

fn print_row(r: &BenchRow) {
    let (neighbours, pairs) = if r.neighbours_per_fluid_particle.is_finite() {
        (
            format!("{:.1} neighbours", r.neighbours_per_fluid_particle),
            format!("{:.3e}", r.pair_interactions_per_s),
        )
    } else {
        ("no fluid at the start".into(), "-".into())
    };
    let list = r
        .list_bytes_per_particle
        .map_or(String::new(), |b| format!(" + {b:.0} B neighbour list"));
    println!(
        "{} | {} particles (dx {:.3e} m, {neighbours}, {:.0} B/particle{list}) | {:.3e} particle-steps/s | {pairs} fluid pair interactions/s | {:.3} s for {} steps",
        r.backend, r.particles, r.dx, r.bytes_per_particle, r.particle_steps_per_s, r.wall_s, r.steps
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

#[cfg(test)]
mod tests {
    use super::*;

    fn row(particles: usize, fluid: usize, pairs_per_fluid: f64, ns: f64) -> BenchRow {
        let rate = 1e9 / ns;
        BenchRow {
            scene: "s".into(),
            kind: "fluid-only".into(),
            backend: "cpu".into(),
            particles,
            dx: 1.0,
            steps: 1,
            wall_s: 1.0,
            fluid_particles: fluid,
            particle_steps_per_s: rate,
            pair_interactions_per_s: rate * fluid as f64 / particles as f64 * pairs_per_fluid,
            neighbours_per_fluid_particle: pairs_per_fluid,
            bytes_per_particle: 0.0,
            list_bytes_per_particle: None,
            pass_ms: vec![
                ("density".into(), 1e-6 * ns * 0.4 * particles as f64),
                ("forces".into(), 1e-6 * ns * 0.6 * particles as f64),
            ],
        }
    }

    /// Twice the cost per particle-step with five times the fluid share: the
    /// growth line, and per fluid particle-step and per pair 60% cheaper.
    #[test]
    fn growth_separates_the_fluid_share_from_the_cost_per_pair() {
        let (small, large) = (
            row(1000, 100, 100.0, 100.0),
            row(100_000, 50_000, 100.0, 200.0),
        );
        let lines = growth_lines("s", "cpu", &small, &large);
        assert!(
            lines[0].contains("100.0 ns at 1000 particles, 200.0 ns at 100000 (+100%)"),
            "{}",
            lines[0]
        );
        assert!(lines[1].contains("fluid share 10% -> 50%"), "{}", lines[1]);
        assert!(
            lines[1].contains("per fluid particle-step 1000.0 -> 400.0 ns (-60%)"),
            "{}",
            lines[1]
        );
        assert!(
            lines[1].contains("per fluid pair 10.00 -> 4.00 ns (-60%)"),
            "{}",
            lines[1]
        );
        // forces grew by 60 ns per particle-step, density by 40.
        assert!(
            lines[2].contains("forces 60.0 -> 120.0 (+60.0), density 40.0 -> 80.0 (+40.0)"),
            "{}",
            lines[2]
        );
    }
}
