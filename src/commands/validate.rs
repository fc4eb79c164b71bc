//! `spatter validate`: what a scene would run and what it would cost, without
//! running it.

use super::*;
use spatter::backend::Pipeline;
use spatter::error::SpatterError;
use spatter::params::Params;
use spatter::run;
use spatter::setup;
use std::process::ExitCode;

pub(crate) fn cmd_validate(path: &str, sets: &[String]) -> Result<ExitCode, SpatterError> {
    let loaded = run::load(path, sets)?;
    print_warnings(&loaded.model);
    let m = &loaded.model;
    let st = &loaded.state;
    println!("scenario: {path}");
    println!(
        "dimension: {}, formulation: {}, kernel: {} (h = {:.4e} m, support {:.4e} m), dx = {:.4e} m",
        m.dim,
        m.formulation.name(),
        m.kernel.name(),
        m.h,
        m.support,
        m.dx
    );
    println!("particles: {}", st.len());
    for (i, ph) in m.phases.iter().enumerate() {
        let n = st.phase.iter().filter(|&&p| p as usize == i).count();
        let motion = if ph.moves {
            let v = &ph.velocity[..m.dim as usize];
            format!(", moving at {v:?} m/s")
        } else {
            String::new()
        };
        println!("  {} ({:?}{motion}): {n}", ph.name, ph.kind);
    }
    if let Some(b) = &m.powder {
        println!("{}", b.summary(m.dim as usize));
    }
    println!(
        "cell grid: {} x {} x {} = {} cells",
        m.grid[0],
        m.grid[1],
        m.grid[2],
        m.n_cells()
    );
    println!(
        "memory: {:.2} MiB (estimate)",
        setup::memory_estimate(m, st.len() as f64) / 1048576.0
    );
    let l = &m.limits;
    let (lim, which) = l.min();
    // A limit whose physics the scene lacks (no heat, no viscosity, no body force)
    // is infinite: say so instead of printing "inf s".
    let limit = |v: f64| {
        if v.is_finite() {
            format!("{v:.4e} s")
        } else {
            "none (not in this scene)".to_string()
        }
    };
    // Every limit of the table the scene has (limits::LIMITS); the first four
    // always, saying "none" where the physics is absent.
    use spatter::model::limits::Limit;
    let always = [
        Limit::Acoustic,
        Limit::Viscous,
        Limit::Force,
        Limit::Conduction,
    ];
    let listed: Vec<String> = l
        .rows()
        .iter()
        .filter(|(k, v)| always.contains(k) || v.is_finite())
        .map(|(k, v)| {
            let name = if *k == Limit::Force {
                "body force"
            } else {
                k.def().name
            };
            if *k == Limit::Viscous && m.implicit_viscosity() {
                return format!("{name} none (implicit: DFSPH's conjugate gradients)");
            }
            format!("{name} {}", limit(*v))
        })
        .collect();
    println!("time-step limits: {}; binding: {which}", listed.join(", "));
    match m.fixed_dt {
        Some(dt) => println!("time step: fixed {dt:.4e} s (limit {lim:.4e} s)"),
        None => println!("time step: adaptive, initially {lim:.4e} s"),
    }
    let params = Params::new(m, st.len() as u32);
    print_cost(m, &params, st, lim);
    let pipeline = Pipeline::for_scene(&params, st);
    println!("passes: {}", pipeline.pass_names().join(", "));
    println!("step: {}", pipeline.describe_step());
    Ok(ExitCode::SUCCESS)
}

/// Measured throughputs (particle-steps/s) a scene's cost is projected from,
/// docs/benchmarks.md: (one H100, 2 CPU cores of the CI machine kind). Plain
/// WCSPH: the H100 at 1.6e7 particles (2026-11-23), this 2-core machine's CPU
/// at 1e6 (dam_break_3d). Heat and laser scenes: the H100 on
/// line_melt_bare_plate (2.8e5 particles, 2026-11-23), the CPU on melt_block_3d.
const PLAIN_RATES: (f64, f64) = (1.34e8, 1.7e6);

const HEAT_RATES: (f64, f64) = (3.65e7, 4.3e5);

/// DFSPH (its solves are several neighbour sweeps a step): the CPU on the
/// 62 um spray spread at 27 048 particles (2026-12-05, after the CPU's pair
/// table; the slowest per particle of the spray scenes: the 30 um spread ran
/// at 2.0e5, the 3D Fluent case at 11 364 particles at 5.9e5). No GPU figure:
/// no device has been lent since DFSPH landed.
const DFSPH_CPU_RATE: f64 = 1.3e5;

/// `validate`'s cost line: steps at the initial time step (the smallest of the
/// scene's limits and of the flow's own CFL at its initial speeds, which binds
/// a 200 m/s droplet on DFSPH), particle-steps, and the wall time they project
/// to on one H100 and on 2 CPU cores.
fn print_cost(m: &spatter::model::Model, params: &Params, st: &spatter::state::State, limit: f64) {
    // The timestep pass's own formula at the initial speeds (acoustic, or
    // DFSPH's flow CFL) beside the scene's constant limits.
    let umax2 = (0..st.len())
        .filter(|&i| m.phases[st.phase[i] as usize].is_fluid())
        .map(|i| {
            let v = st.vel[i];
            v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
        })
        .fold(0.0f32, f32::max);
    let dt0 = limit.min(spatter::backend::cpu::next_dt(params, umax2, 0.0).0 as f64);
    let steps = match m.end {
        spatter::model::EndCondition::Steps(n) => n as f64,
        spatter::model::EndCondition::Time(t) => (t / m.fixed_dt.unwrap_or(dt0)).ceil(),
    };
    let work = steps * st.len() as f64;
    let heat = m.phases.iter().any(|p| p.conducts());
    let dfsph = m.formulation == spatter::scene::Formulation::Dfsph;
    let ((gpu, cpu), which) = if dfsph {
        ((f64::NAN, DFSPH_CPU_RATE), "a DFSPH spray scene's")
    } else if heat {
        (HEAT_RATES, "a laser heat scene's")
    } else {
        (PLAIN_RATES, "plain WCSPH's")
    };
    let hours = |rate: f64| {
        let s = work / rate;
        if s < 120.0 {
            format!("{s:.0} s")
        } else if s < 3600.0 {
            format!("{:.1} min", s / 60.0)
        } else {
            format!("{:.1} h", s / 3600.0)
        }
    };
    let adaptive = if m.fixed_dt.is_some() {
        ""
    } else if dfsph {
        " (at the initial speeds; DFSPH's step follows the flow: the spray scenes took \
         0.37-1.23 times this)"
    } else {
        " (the step adapts: more steps where the flow speeds up)"
    };
    let on_gpu = if gpu.is_finite() {
        format!("{} on one H100 ({gpu:.2e}/s)", hours(gpu))
    } else {
        "on one H100 not measured yet (no device lent since DFSPH landed)".to_string()
    };
    println!(
        "cost: about {steps:.3e} steps{adaptive}, {work:.3e} particle-steps; at {which} measured \
         rates (docs/benchmarks.md) {on_gpu}, {} on 2 CPU cores ({cpu:.2e}/s)",
        hours(cpu)
    );
}
