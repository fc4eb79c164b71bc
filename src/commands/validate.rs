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

/// One class of scene's measured throughput (particle-steps/s), a table of
/// docs/benchmarks/cost_rates.toml.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Rate {
    /// How the cost line names the class.
    what: String,
    /// One H100; none where no device has measured the class.
    gpu: Option<f64>,
    /// 2 CPU cores of the CI machine kind.
    cpu: f64,
    /// Said after the step count (how far the projection can be off).
    note: Option<String>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Rates {
    plain: Rate,
    heat: Rate,
    ray_traced: Rate,
    dfsph: Rate,
}

/// The measured throughputs, read from the benchmarks' record at build time.
fn rates() -> Rates {
    toml::from_str(include_str!("../../docs/benchmarks/cost_rates.toml"))
        .expect("docs/benchmarks/cost_rates.toml: the cost rates (checked by a unit test)")
}

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
    let traced = m
        .laser
        .as_ref()
        .is_some_and(|l| l.model == spatter::scene::LaserModel::RayTraced);
    let all = rates();
    let rate = if m.formulation == spatter::scene::Formulation::Dfsph {
        &all.dfsph
    } else if traced {
        &all.ray_traced
    } else if heat {
        &all.heat
    } else {
        &all.plain
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
    let adaptive = match (&rate.note, m.fixed_dt) {
        (_, Some(_)) => String::new(),
        (Some(note), None) => format!(" ({note})"),
        (None, None) => " (the step adapts: more steps where the flow speeds up)".to_string(),
    };
    let on_gpu = match rate.gpu {
        Some(gpu) => format!("{} on one H100 ({gpu:.2e}/s)", hours(gpu)),
        None => "on one H100 not measured yet".to_string(),
    };
    let (which, cpu) = (&rate.what, rate.cpu);
    println!(
        "cost: about {steps:.3e} steps{adaptive}, {work:.3e} particle-steps; at {which} measured \
         rates (docs/benchmarks/cost_rates.toml) {on_gpu}, {} on 2 CPU cores ({cpu:.2e}/s)",
        hours(cpu)
    );
}

#[cfg(test)]
mod tests {
    /// The build's cost rates parse, and every figure is a positive rate.
    #[test]
    fn cost_rates_parse() {
        let r = super::rates();
        for rate in [&r.plain, &r.heat, &r.ray_traced, &r.dfsph] {
            assert!(
                rate.cpu > 0.0 && rate.gpu.is_none_or(|g| g > 0.0),
                "{}",
                rate.what
            );
        }
    }
}
