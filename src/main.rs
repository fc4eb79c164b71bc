use clap::{Parser, Subcommand};
use spatter::backend::cpu::CpuBackend;
use spatter::backend::gpu::{AdapterChoice, GpuBackend, GpuContext};
use spatter::backend::Pipeline;
use spatter::error::SpatterError;
use spatter::model::EndCondition;
use spatter::params::Params;
use spatter::run::{self, BackendChoice, RunOptions};
use spatter::{bench, compare, setup};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "spatter",
    version,
    about = "GPU SPH for additive-manufacturing process physics"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario.
    Run {
        scenario: String,
        #[arg(long, value_enum, default_value = "auto")]
        backend: BackendChoice,
        /// Simulated end time in seconds (overrides the scenario).
        #[arg(long, conflicts_with = "steps")]
        until: Option<f64>,
        /// Number of steps (overrides the scenario).
        #[arg(long)]
        steps: Option<u64>,
        /// Override a scenario value: key=value (e.g. dx=2e-3, materials.water.viscosity=1e-3).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Per-pass GPU timestamps (or CPU pass timers), printed at the end.
        #[arg(long)]
        profile: bool,
    },
    /// Parse and check a scenario; print particles, memory, time-step limits and passes.
    Validate {
        scenario: String,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
    },
    /// Compare the CPU reference with the GPU path after every pass of every step.
    Compare {
        scenario: String,
        #[arg(long, default_value_t = 10)]
        steps: u64,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
    },
    /// Benchmarks.
    Bench {
        #[command(subcommand)]
        which: BenchKind,
    },
}

#[derive(Subcommand)]
enum BenchKind {
    /// 3D dam break at several sizes on each available backend.
    Throughput {
        /// Write the figures as JSON.
        #[arg(long)]
        json: Option<String>,
        /// Particle counts to aim for.
        #[arg(long, value_delimiter = ',', default_values_t = vec![1e4, 1e5, 1e6])]
        sizes: Vec<f64>,
        /// Steps timed per size.
        #[arg(long, default_value_t = 20)]
        steps: u32,
        /// Backends to measure (default: cpu, and gpu when an adapter exists).
        #[arg(long, value_enum)]
        backend: Vec<BackendChoice>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run {
            scenario,
            backend,
            until,
            steps,
            sets,
            profile,
        } => cmd_run(&scenario, backend, until, steps, &sets, profile),
        Command::Validate { scenario, sets } => cmd_validate(&scenario, &sets),
        Command::Compare {
            scenario,
            steps,
            sets,
        } => cmd_compare(&scenario, steps, &sets),
        Command::Bench {
            which:
                BenchKind::Throughput {
                    json,
                    sizes,
                    steps,
                    backend,
                },
        } => bench::throughput(&sizes, steps, &backend, json.as_deref()).map(|_| ExitCode::SUCCESS),
    };
    match result {
        Ok(code) => code,
        Err(SpatterError::Input(e)) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
        Err(SpatterError::Runtime(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(if m.starts_with("unstable") { 3 } else { 1 })
        }
    }
}

fn cmd_run(
    path: &str,
    choice: BackendChoice,
    until: Option<f64>,
    steps: Option<u64>,
    sets: &[String],
    profile: bool,
) -> Result<ExitCode, SpatterError> {
    let loaded = run::load(path, sets)?;
    let end = match (until, steps) {
        (Some(t), _) if t > 0.0 => EndCondition::Time(t),
        (Some(t), _) => {
            return Err(spatter::error::InputError::new(
                path,
                "--until",
                format!("must be positive (got {t})"),
            )
            .into())
        }
        (None, Some(n)) => EndCondition::Steps(n),
        (None, None) => loaded.model.end,
    };
    let mut backend = run::make_backend(choice, &loaded, profile)?;
    println!("scenario: {path}");
    println!("backend: {}", backend.describe());
    println!("particles: {}", loaded.state.len());
    let report = run::run(&loaded, backend.as_mut(), &RunOptions { end, quiet: false })?;
    println!(
        "steps: {}, simulated time: {:.6e} s",
        report.steps, report.sim_time
    );
    if profile {
        let times = backend.take_pass_times();
        let steps = report.steps.max(1) as f64;
        for (name, ms) in times {
            println!("pass {name}: {:.4} ms/step", ms / steps);
        }
    }
    let mut code = ExitCode::SUCCESS;
    if let Some(c) = &report.check {
        for d in &c.details {
            println!("{d}");
        }
        println!("{}", c.line());
        if !c.pass {
            code = ExitCode::from(1);
        }
    }
    println!(
        "wall time: {:.3} s, particle-steps/s: {:.4e}",
        report.wall_s,
        report.particle_steps_per_s()
    );
    Ok(code)
}

fn cmd_validate(path: &str, sets: &[String]) -> Result<ExitCode, SpatterError> {
    let loaded = run::load(path, sets)?;
    let m = &loaded.model;
    let st = &loaded.state;
    println!("scenario: {path}");
    println!(
        "dimension: {}, formulation: wcsph, kernel: {} (h = {:.4e} m, support {:.4e} m), dx = {:.4e} m",
        m.dim,
        m.kernel.name(),
        m.h,
        m.support,
        m.dx
    );
    println!("particles: {}", st.len());
    for (i, ph) in m.phases.iter().enumerate() {
        let n = st.phase.iter().filter(|&&p| p as usize == i).count();
        println!("  {} ({:?}): {n}", ph.name, ph.kind);
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
    println!(
        "time-step limits: acoustic {:.4e} s, viscous {:.4e} s, body force {:.4e} s; binding: {which}",
        l.acoustic, l.viscous, l.body_force
    );
    match m.fixed_dt {
        Some(dt) => println!("time step: fixed {dt:.4e} s (limit {lim:.4e} s)"),
        None => println!("time step: adaptive, initially {lim:.4e} s"),
    }
    let params = Params::new(m, st.len() as u32);
    println!(
        "passes: {}",
        Pipeline::for_scene(&params, st).pass_names().join(", ")
    );
    Ok(ExitCode::SUCCESS)
}

fn cmd_compare(path: &str, steps: u64, sets: &[String]) -> Result<ExitCode, SpatterError> {
    let loaded = run::load(path, sets)?;
    let params = Params::new(&loaded.model, loaded.state.len() as u32);
    let ctx = GpuContext::open(AdapterChoice::AnyGpu, false).map_err(SpatterError::Runtime)?;
    let mut gpu =
        GpuBackend::new(ctx, params, &loaded.state, false).map_err(SpatterError::Runtime)?;
    let mut cpu = CpuBackend::new(params, loaded.state.clone());
    use spatter::backend::Backend;
    let software = gpu.is_software();
    println!("scenario: {path}, particles: {}", loaded.state.len());
    println!("reference: {}", cpu.describe());
    println!("device: {}", gpu.describe());
    let report = compare::compare(&mut cpu, &mut gpu, steps, software);
    if software {
        println!(
            "compared every field after {} passes ({} steps)",
            report.stages_compared, steps
        );
        if let Some(d) = &report.first_difference {
            println!(
                "first difference: step {}, pass {}, field {}, particle {} component {}: cpu {} vs gpu {}",
                d.step, d.pass, d.field, d.particle, d.component, d.cpu, d.gpu
            );
            println!("bit-identical: no");
            return Ok(ExitCode::from(1));
        }
        println!("bit-identical: yes");
    } else {
        println!("hardware adapter: largest relative difference per field after one step");
        for (f, r) in &report.max_rel {
            println!("  {f}: {r:.3e}");
        }
        let exact = report.max_rel.iter().all(|(_, r)| *r == 0.0);
        println!("bit-identical: {}", if exact { "yes" } else { "no" });
    }
    Ok(ExitCode::SUCCESS)
}
