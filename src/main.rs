use clap::{Parser, Subcommand};
use spatter::error::SpatterError;
use spatter::run::BackendChoice;
use std::process::ExitCode;

mod commands;
use commands::{
    bench::cmd_bench, compare::cmd_compare, inspect::cmd_inspect, run::cmd_run, sweep::cmd_sweep,
    validate::cmd_validate,
};

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
    /// Run a scenario (or continue one from a checkpoint with --resume).
    Run {
        /// Scenario TOML; omit it with --resume (the checkpoint carries its scenario).
        #[arg(required_unless_present = "resume", conflicts_with = "resume")]
        scenario: Option<String>,
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
        #[command(flatten)]
        outputs: OutputArgs,
    },
    /// Summarise an MCAP run file: channels, schemas, counts, time span, scenario.
    Inspect { file: String },
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
        /// Compare by tolerance, per pass, as on a hardware GPU, also on a software
        /// adapter (where every difference should then be 0).
        #[arg(long)]
        by_tolerance: bool,
    },
    /// Process maps: run a grid of --set overrides (`sweep SCENE --vary
    /// KEY=V1,V2 ... --out DIR`), write it as a Slurm job array (--slurm), run
    /// one cell (`sweep cell DIR I`, what each array task runs) or gather the
    /// runs into a CSV and a map (`sweep collect DIR`).
    Sweep {
        /// SCENE, or `cell DIR I`, or `collect DIR`.
        #[arg(required = true, num_args = 1..=3)]
        args: Vec<String>,
        /// A key and its values: KEY=V1,V2,... (repeat for a grid).
        #[arg(long, value_name = "KEY=V1,V2")]
        vary: Vec<String>,
        /// Overrides every run shares.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Runs at a time on this machine.
        #[arg(long, default_value_t = 1)]
        jobs: usize,
        /// The sweep's folder.
        #[arg(long, value_name = "DIR", default_value = "sweep")]
        out: String,
        #[arg(long, value_enum, default_value = "auto")]
        backend: BackendChoice,
        /// Write the manifest and a Slurm job-array script instead of running.
        #[arg(long)]
        slurm: bool,
        /// Layer thickness (m): a steady track shallower than this is lack of
        /// fusion on the map (default: a powder scene's layer, else none).
        #[arg(long, value_name = "M")]
        layer: Option<f64>,
        /// An #SBATCH option for the job array (repeat): `--slurm-arg=--partition=gpu`.
        #[arg(long = "slurm-arg", value_name = "OPTION", allow_hyphen_values = true)]
        slurm_args: Vec<String>,
    },
    /// Benchmarks.
    Bench {
        #[command(subcommand)]
        which: BenchKind,
    },
}

#[derive(clap::Args)]
struct OutputArgs {
    /// Write an MCAP stream (/particles as foxglove.PointCloud, /diagnostics as JSON).
    #[arg(long, value_name = "FILE")]
    out: Option<String>,
    /// Write a VTK series (.vtu per frame and particles.pvd) into this folder.
    #[arg(long, value_name = "DIR")]
    vtk: Option<String>,
    /// Heat scenes: the melt pool's figures per diagnostics record as CSV,
    /// beside the --out stream (RUN.mcap -> RUN.pool.csv).
    #[arg(long)]
    pool_csv: bool,
    /// Write the run's figures as JSON at its end (how it ended, cost, the
    /// track's pool figures, the check): what `spatter sweep` collects.
    #[arg(long, value_name = "FILE")]
    summary: Option<String>,
    /// Write a checkpoint every T seconds of simulated time (and at the end).
    #[arg(long, value_name = "T")]
    checkpoint_every: Option<f64>,
    /// Folder for checkpoints (default: beside --out, else inside --vtk).
    #[arg(long, value_name = "DIR")]
    checkpoint_dir: Option<String>,
    /// Continue from a checkpoint file; bit-identical to an uninterrupted run.
    #[arg(long, value_name = "FILE")]
    resume: Option<String>,
}

#[derive(Subcommand)]
enum BenchKind {
    /// Fluid-only (3D dam break), heat (line melt) and rigid-body (powder bed) scenes at several sizes on each
    /// available backend; per-pass times and the cost of each optional pass.
    Throughput {
        /// Write the figures as JSON.
        #[arg(long)]
        json: Option<String>,
        /// Particle counts to aim for (a size that does not fit in memory, or whose
        /// projected time exceeds 4 minutes on the CPU, is skipped and says so).
        #[arg(long, value_delimiter = ',', default_values_t = vec![1e4, 1e5, 1e6, 1e7])]
        sizes: Vec<f64>,
        /// Scenes: dam_break_3d, line_melt, powder_bed (default all).
        #[arg(long, value_delimiter = ',')]
        scenes: Vec<String>,
        /// Size at which each optional pass is costed by running without it (0: never).
        #[arg(long, default_value_t = 1e5)]
        pass_costs_at: f64,
        /// Steps timed per size.
        #[arg(long, default_value_t = 20)]
        steps: u32,
        /// Backends to measure (default: cpu, and gpu when an adapter exists).
        #[arg(long, value_enum)]
        backend: Vec<BackendChoice>,
    },
    /// Work-precision: each validation scene at 3-5 resolutions and each kernel;
    /// error, cost, memory and the observed convergence order.
    Accuracy {
        /// Scenes to sweep (default: all; with --quick the quick set).
        #[arg(long, value_delimiter = ',')]
        scenes: Vec<String>,
        #[arg(long, value_enum, default_value = "auto")]
        backend: BackendChoice,
        /// The two coarsest resolutions of a few scenes, quintic kernel only (CI).
        #[arg(long)]
        quick: bool,
        /// Write every figure as JSON.
        #[arg(long)]
        json: Option<String>,
        /// Write a work-precision PNG per scene and a convergence summary here.
        #[arg(long, value_name = "DIR")]
        plots: Option<String>,
    },
    /// Stress suite: long runs, parameter extremes, seeded random scenes; each case
    /// survived, stopped by the watchdog, or crashed (exit 1: a crash is a bug).
    Stability {
        #[arg(long, value_enum, default_value = "auto")]
        backend: BackendChoice,
        /// A few cases of each group, a few hundred to 1,500 steps each (CI).
        #[arg(long)]
        quick: bool,
        /// Write every case as JSON.
        #[arg(long)]
        json: Option<String>,
        /// First seed of the random scenes (scene k uses seed + k).
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Only the cases whose group ("long run", "extreme", "random"),
        /// parameter family ("impact speed") or scene name contains this text.
        #[arg(long)]
        only: Option<String>,
    },
}

/// The Vulkan loader's window-system probe (libwayland) prints `error:
/// XDG_RUNTIME_DIR is invalid or not set in the environment.` when that variable is
/// missing, as in a fresh Debian shell or a container: a newcomer reads it as a
/// failure. Point it at a private directory (`$TMPDIR/spatter-runtime-<uid>`, mode
/// 0700, reused; owned by someone else, it is left alone) before any wgpu instance
/// exists. Called first in `main`, while the process has a single thread.
#[cfg(unix)]
fn ensure_runtime_dir() {
    use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
    let usable = |d: &std::path::Path| {
        std::fs::metadata(d).is_ok_and(|m| m.is_dir() && !m.permissions().readonly())
    };
    if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| usable(d.as_ref())) {
        return;
    }
    let Ok(uid) = std::fs::metadata("/proc/self").map(|m| m.uid()) else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("spatter-runtime-{uid}"));
    let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
    let ours = std::fs::symlink_metadata(&dir)
        .is_ok_and(|m| m.is_dir() && m.uid() == uid && m.permissions().mode() & 0o777 == 0o700);
    if ours {
        std::env::set_var("XDG_RUNTIME_DIR", &dir);
    }
}

#[cfg(not(unix))]
fn ensure_runtime_dir() {}

fn main() -> ExitCode {
    ensure_runtime_dir();
    let cli = Cli::parse();
    // The main thread is worker 0 of the rayon pool, so it takes part in every
    // parallel pass. With the pool beside it, the pool's idle workers spun
    // (sched_yield) while the main thread did the host's serial work: three
    // threads on two cores, and the README's line melt spent 45% of its samples
    // in the scheduler.
    let _ = rayon::ThreadPoolBuilder::new()
        .use_current_thread()
        .build_global();
    let result = dispatch(cli);
    match result {
        Ok(code) => code,
        Err(SpatterError::Input(e)) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
        Err(SpatterError::Runtime(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(1)
        }
    }
}

fn dispatch(cli: Cli) -> Result<ExitCode, SpatterError> {
    match cli.command {
        Command::Run {
            scenario,
            backend,
            until,
            steps,
            sets,
            profile,
            outputs,
        } => cmd_run(
            scenario.as_deref(),
            backend,
            until,
            steps,
            &sets,
            profile,
            &outputs,
        ),
        Command::Inspect { file } => cmd_inspect(&file),
        Command::Validate { scenario, sets } => cmd_validate(&scenario, &sets),
        Command::Compare {
            scenario,
            steps,
            sets,
            by_tolerance,
        } => cmd_compare(&scenario, steps, &sets, by_tolerance),
        Command::Bench { which } => cmd_bench(which),
        Command::Sweep {
            args,
            vary,
            sets,
            jobs,
            out,
            backend,
            slurm,
            layer,
            slurm_args,
        } => cmd_sweep(commands::sweep::SweepArgs {
            args: &args,
            vary: &vary,
            sets: &sets,
            jobs,
            out: &out,
            backend,
            slurm,
            layer,
            slurm_args: &slurm_args,
        }),
    }
}
