use clap::{Parser, Subcommand};
use spatter::backend::cpu::CpuBackend;
use spatter::backend::gpu::{AdapterChoice, GpuBackend, GpuContext};
use spatter::backend::Pipeline;
use spatter::checkpoint::CheckpointSink;
use spatter::error::InputError;
use spatter::error::SpatterError;
use spatter::model::EndCondition;
use spatter::output::mcap_out::{McapSink, Provenance};
use spatter::output::vtk::VtkSink;
use spatter::params::Params;
use spatter::run::pool_csv::PoolCsv;
use spatter::run::{self, BackendChoice, Outputs, RunEnd, RunOptions};
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
        } => cmd_sweep(&args, &vary, &sets, jobs, &out, backend, slurm),
    }
}

fn cmd_sweep(
    args: &[String],
    vary: &[String],
    sets: &[String],
    jobs: usize,
    out: &str,
    backend: BackendChoice,
    slurm: bool,
) -> Result<ExitCode, SpatterError> {
    use spatter::sweep;
    use std::path::Path;
    let exe = std::env::current_exe().map_err(|e| SpatterError::Runtime(e.to_string()))?;
    let rt = SpatterError::Runtime;
    match args {
        [c, dir] if c == "collect" => {
            let (csv, png) = sweep::collect(Path::new(dir)).map_err(rt)?;
            println!("sweep: {}", csv.display());
            match png {
                Some(p) => println!("sweep: {}", p.display()),
                None => println!("sweep: no map (fewer than one numeric key, or runs missing)"),
            }
            return Ok(ExitCode::SUCCESS);
        }
        [c, dir, i] if c == "cell" => {
            let i: usize = i.parse().map_err(|_| {
                SpatterError::Input(InputError::new(
                    dir,
                    "INDEX",
                    format!("not a cell index: {i}"),
                ))
            })?;
            let s = sweep::run_cell(Path::new(dir), i, &exe).map_err(rt)?;
            println!("cell {i} {:?}: exit {:?}", s.vary, s.exit_code);
            return Ok(ExitCode::SUCCESS);
        }
        [_] => {}
        _ => {
            return Err(InputError::new(
                "sweep",
                "",
                "expected SCENE, `cell DIR INDEX` or `collect DIR`",
            )
            .into())
        }
    }
    let scene = std::fs::canonicalize(&args[0])
        .map_err(|e| InputError::new(&args[0], "", format!("cannot read scenario: {e}")))?;
    let scene = scene.to_string_lossy().to_string();
    if vary.is_empty() {
        return Err(InputError::new(&scene, "--vary", "give at least one KEY=V1,V2,...").into());
    }
    let mut lists = Vec::new();
    for v in vary {
        lists.push(sweep::parse_vary(v).map_err(|m| InputError::new(&scene, "--vary", m))?);
    }
    let cells = sweep::grid(&lists);
    // Every cell must load: a bad value is refused before anything runs.
    for c in &cells {
        let mut all = sets.to_vec();
        all.extend(c.vary.iter().map(|(k, v)| format!("{k}={v}")));
        run::load(&scene, &all)?;
    }
    let backend = match backend {
        BackendChoice::Auto => "auto",
        BackendChoice::Cpu => "cpu",
        BackendChoice::Gpu => "gpu",
    };
    let manifest = sweep::Manifest {
        scene,
        backend: backend.into(),
        sets: sets.to_vec(),
        keys: lists.iter().map(|l| l.0.clone()).collect(),
        cells,
    };
    let dir = Path::new(out);
    if let Ok(old) = sweep::read_manifest(dir) {
        if old.cells != manifest.cells || old.scene != manifest.scene || old.sets != manifest.sets {
            return Err(InputError::new(
                out,
                "--out",
                "holds a different sweep (its manifest.json): give another folder",
            )
            .into());
        }
    }
    sweep::write_manifest(dir, &manifest).map_err(rt)?;
    if slurm {
        let script = dir.join("sweep.slurm");
        let dir_abs = std::fs::canonicalize(dir).map_err(|e| rt(e.to_string()))?;
        spatter::output::write_atomic(
            &script,
            sweep::slurm_script(&dir_abs, &exe, manifest.cells.len(), backend).as_bytes(),
        )
        .map_err(rt)?;
        println!(
            "sweep: {} cells; submit with `sbatch {}`, then `spatter sweep collect {}`",
            manifest.cells.len(),
            script.display(),
            dir.display()
        );
        return Ok(ExitCode::SUCCESS);
    }
    let done = sweep::run_local(dir, jobs, &exe).map_err(rt)?;
    let failed = done.iter().filter(|s| s.exit_code != Some(0)).count();
    let (csv, png) = sweep::collect(dir).map_err(rt)?;
    println!(
        "sweep: {} runs, {failed} not exit 0; {}",
        done.len(),
        csv.display()
    );
    if let Some(p) = png {
        println!("sweep: {}", p.display());
    }
    Ok(ExitCode::SUCCESS)
}

fn cmd_bench(which: BenchKind) -> Result<ExitCode, SpatterError> {
    match which {
        BenchKind::Throughput {
            json,
            sizes,
            scenes,
            pass_costs_at,
            steps,
            backend,
        } => bench::throughput(&bench::throughput::Options {
            sizes: &sizes,
            steps,
            backends: &backend,
            scenes: &scenes,
            pass_costs_at: (pass_costs_at > 0.0).then_some(pass_costs_at),
            json: json.as_deref(),
        })
        .map(|_| ExitCode::SUCCESS),
        BenchKind::Accuracy {
            scenes,
            backend,
            quick,
            json,
            plots,
        } => bench::accuracy::accuracy(&bench::accuracy::Options {
            scenes: &scenes,
            backend,
            quick,
            json: json.as_deref(),
            plots: plots.as_deref(),
        })
        .map(|_| ExitCode::SUCCESS),
        BenchKind::Stability {
            backend,
            quick,
            json,
            seed,
            only,
        } => bench::stability::stability(&bench::stability::Options {
            backend,
            quick,
            json: json.as_deref(),
            seed,
            only: only.as_deref(),
        })
        .map(|ok| {
            if ok {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }),
    }
}

/// Exit code of a run stopped by SIGINT/SIGTERM (shell convention 128 + SIGINT).
const EXIT_INTERRUPTED: u8 = 130;
/// Exit code of a run the watchdog stopped.
const EXIT_UNSTABLE: u8 = 3;

fn cmd_run(
    path: Option<&str>,
    choice: BackendChoice,
    until: Option<f64>,
    steps: Option<u64>,
    sets: &[String],
    profile: bool,
    out_args: &OutputArgs,
) -> Result<ExitCode, SpatterError> {
    let (loaded, resumed_from) = match (&out_args.resume, path) {
        (Some(ckpt), _) => (run::load_checkpoint(ckpt, sets)?, Some(ckpt.as_str())),
        (None, Some(p)) => (run::load(p, sets)?, None),
        (None, None) => unreachable!("clap requires a scenario or --resume"),
    };
    print_warnings(&loaded.model);
    let label = path.or(resumed_from).unwrap_or_default();
    let end = match (until, steps) {
        (Some(t), _) if t > 0.0 => EndCondition::Time(t),
        (Some(t), _) => {
            return Err(
                InputError::new(label, "--until", format!("must be positive (got {t})")).into(),
            )
        }
        (None, Some(n)) => EndCondition::Steps(n),
        // A scene's step count is a total: a resumed run continues up to it.
        (None, None) => match loaded.model.end {
            EndCondition::Steps(n) => {
                EndCondition::Steps(n.saturating_sub(loaded.state.sim.step as u64))
            }
            e => e,
        },
    };
    if let Some(t) = out_args.checkpoint_every {
        if !(t.is_finite() && t > 0.0) {
            return Err(InputError::new(
                label,
                "--checkpoint-every",
                format!("must be positive (got {t})"),
            )
            .into());
        }
    }
    if let Some(dt) = loaded.model.fixed_dt {
        let (lim, which) = loaded.model.limits.min();
        if dt > lim {
            eprintln!("warning: fixed dt {dt:e} s exceeds the stability limit {lim:e} s ({which}); run.dt_check = false lets it through");
        }
    }
    let mut backend = run::make_backend(choice, &loaded, profile)?;
    let backend_name = backend.describe();
    let mut outputs = open_outputs(out_args, &loaded, &backend_name)?;
    install_signal_handler();
    match resumed_from {
        Some(c) => println!(
            "resumed: {c} (step {}, t = {:.6e} s)",
            loaded.state.sim.step, loaded.state.sim.time
        ),
        None => println!("scenario: {label}"),
    }
    println!("backend: {backend_name}");
    println!("particles: {}", loaded.state.len());
    if let Some(b) = &loaded.model.powder {
        println!("{}", b.summary(loaded.model.dim as usize));
    }
    let opts = RunOptions {
        end,
        quiet: false,
        resumed: resumed_from.is_some(),
    };
    let report = run::run(&loaded, backend.as_mut(), &opts, &mut outputs)?;
    if let Some(p) = &out_args.summary {
        let fig = spatter::sweep::run_figures(&loaded.model, &report);
        spatter::output::write_atomic(
            std::path::Path::new(p),
            serde_json::to_string_pretty(&fig)
                .unwrap_or_default()
                .as_bytes(),
        )
        .map_err(SpatterError::Runtime)?;
    }
    println!(
        "steps: {}, simulated time: {:.6e} s",
        report.steps, report.sim_time
    );
    if let Some(why) = &report.stop_reason {
        println!("{why}");
    }
    if let Some(h) = spatter::diagnostics::heat_diagnostics(&loaded.model, &report.final_state) {
        // 2D figures are per metre of depth.
        let (per, vol) = if loaded.model.dim == 2 {
            ("/m", "m^2")
        } else {
            ("", "m^3")
        };
        println!(
            "heat: max T {:.2} K, enthalpy {:.6e} J{per}, absorbed laser power {:.4e} W{per}, evaporated {:.4e} W{per}, radiated {:.4e} W{per}, melted volume {:.4e} {vol}",
            h.max_temperature,
            h.total_enthalpy,
            h.absorbed_laser_power,
            h.evaporated_power,
            h.radiated_power,
            h.melted_volume,
        );
        let melts = loaded.model.melts();
        // Laser scenes print the track's pool figures below instead.
        if melts && report.track.is_none() {
            println!(
            "melt pool now (largest connected melt region): height {:.3e} m, width {:.3e} m, length {:.3e} m, volume {:.4e} {vol}; detached melt: {} regions, {} particles, {:.4e} kg{per}",
            h.pool_depth,
            h.pool_width,
            h.pool_length,
            h.pool_volume,
            h.detached_melt_regions,
            h.detached_melt_particles,
            h.detached_melt_mass
        );
        }
    }
    if loaded
        .model
        .laser
        .as_ref()
        .is_some_and(|l| l.rays.is_some())
    {
        if let Some(b) = spatter::diagnostics::LaserBalance::of(&loaded.model, &report.final_state)
        {
            let per = if loaded.model.dim == 2 { "/m" } else { "" };
            println!(
                "laser (ray-traced, last step): incident {:.4e} W{per}, absorbed {:.4e} W{per} ({:.4} of it; {:.3e} W{per} of that at the bounce limit), leaving {:.4e} W{per}; absorbed + leaving - incident = {:.1e} W{per}",
                b.incident,
                b.absorbed,
                b.fraction(),
                b.at_limit,
                b.leaving,
                b.absorbed + b.leaving - b.incident,
            );
        }
        if let Some(s) = &report.laser {
            let per = if loaded.model.dim == 2 { "/m" } else { "" };
            println!(
                "laser (ray-traced, {} samples with the beam on): absorbed fraction {:.4} (per sample {:.4} to {:.4}), mean absorbed {:.4e} W{per} of {:.4e} W{per} incident, {:.3e} W{per} of it at the bounce limit",
                s.samples,
                s.absorbed_fraction,
                s.fraction_min,
                s.fraction_max,
                s.absorbed_mean,
                s.incident_mean,
                s.at_limit_mean,
            );
        }
    }
    if let Some(t) = &report.track {
        for line in t.summary(loaded.model.dim) {
            println!("{line}");
        }
    }
    if let Some(s) = &report.solidification {
        println!("{}", s.line());
    }
    if !report.final_state.bodies.is_empty() {
        let tally = spatter::bodies::BodyTally::of(&report.final_state);
        println!("bodies: {}", tally.summary());
    }
    if let Some((ejected, grains)) =
        spatter::bodies::ejected_grains(&loaded.model, &report.final_state)
    {
        println!("powder: of {grains} rigid grains {ejected} ejected (centre more than a diameter above the bed's initial top)");
    }
    if loaded.model.has_walls_and_fluid() {
        println!("wall leakage: {}", report.leakage.summary());
    }
    let fin = &report.final_state;
    if fin.sim.removed > 0 || loaded.model.open_sides.iter().flatten().any(|&o| o) {
        use spatter::outflow::{MassBalance, Outflow};
        println!("outflow: {}", Outflow::of(&loaded.model, fin).summary());
        println!("mass: {}", MassBalance::of(&loaded.state, fin).summary());
    }
    if profile {
        let times = backend.take_pass_times();
        let steps = report.steps.max(1) as f64;
        for (name, ms) in times {
            println!("pass {name}: {:.4} ms/step", ms / steps);
        }
    }
    print_outputs(&outputs, &report);
    let mut code = ExitCode::SUCCESS;
    match &report.end {
        RunEnd::Completed => {}
        RunEnd::Interrupted => {
            eprintln!(
                "interrupted by a signal at step {}: outputs finished",
                report.final_state.sim.step
            );
            code = ExitCode::from(EXIT_INTERRUPTED);
        }
        RunEnd::Unstable(trip) => {
            eprintln!("error: {}", trip.message());
            code = ExitCode::from(EXIT_UNSTABLE);
        }
    }
    // A run the command line cut short (or stretched) may hold no sample the
    // reference covers; that is "not evaluated", not a failure.
    let scene_end = end == loaded.model.end && resumed_from.is_none();
    if let Some(c) = &report.check {
        for d in &c.details {
            println!("{d}");
        }
        if !scene_end && !c.value.is_finite() {
            println!(
                "check {}: not evaluated (--steps/--until changed the scene's end)",
                c.name
            );
        } else {
            println!("{}", c.line());
            if !c.pass {
                code = ExitCode::from(1);
            }
        }
    }
    println!(
        "wall time: {:.3} s, particle-steps/s: {:.4e}",
        report.wall_s,
        report.particle_steps_per_s()
    );
    Ok(code)
}

/// Open every requested output before the first step, so a bad path fails early
/// (exit 2, nothing simulated).
fn open_outputs(a: &OutputArgs, l: &run::Loaded, backend: &str) -> Result<Outputs, SpatterError> {
    let io_err = |key: &str, m: String| SpatterError::Input(InputError::new(&l.model.file, key, m));
    let command: Vec<String> = std::env::args().collect();
    // Refused before any file is written.
    let pool_csv = match (a.pool_csv, a.out.as_ref()) {
        (false, _) => None,
        (true, Some(out)) if !l.state.heat.is_empty() => {
            Some(format!("{}.pool.csv", out.trim_end_matches(".mcap")))
        }
        (true, _) => {
            return Err(io_err(
                "--pool-csv",
                "needs --out (the CSV goes beside the MCAP) and a heat scene".into(),
            ))
        }
    };
    let mut o = Outputs::default();
    o.backend = backend.to_string();
    o.checkpoint_every = a.checkpoint_every;
    if let Some(p) = &a.out {
        let prov = Provenance {
            backend,
            command: &command.join(" "),
        };
        o.mcap = Some(
            McapSink::create(p, &l.model, &prov, &spatter::diagnostics::topics(&l.model))
                .map_err(|e| io_err("--out", e))?,
        );
    }
    if let Some(d) = &a.vtk {
        o.vtk = Some(VtkSink::create(d).map_err(|e| io_err("--vtk", e))?);
    }
    if let Some(path) = &pool_csv {
        o.pool_csv = Some(PoolCsv::create(path).map_err(|e| io_err("--pool-csv", e))?);
    }
    let ckpt_dir = a.checkpoint_dir.clone().or_else(|| {
        a.out
            .as_ref()
            .map(|p| format!("{}.checkpoints", p.trim_end_matches(".mcap")))
            .or_else(|| a.vtk.as_ref().map(|d| format!("{d}/checkpoints")))
    });
    match ckpt_dir {
        Some(d) => {
            o.checkpoints =
                Some(CheckpointSink::create(&d).map_err(|e| io_err("--checkpoint-dir", e))?)
        }
        None if a.checkpoint_every.is_some() => {
            return Err(io_err(
                "--checkpoint-every",
                "needs a place to write: give --checkpoint-dir, --out or --vtk".into(),
            ))
        }
        None => {}
    }
    Ok(o)
}

fn print_outputs(o: &Outputs, r: &run::RunReport) {
    if let Some(m) = &o.mcap {
        println!("mcap: {} frames", m.frames);
    }
    match &r.last_checkpoint {
        Some(p) => println!("checkpoint: {}", p.display()),
        None if matches!(r.end, RunEnd::Unstable(_) | RunEnd::Interrupted) => {
            println!("checkpoint: none written (give --out, --vtk or --checkpoint-dir)")
        }
        None => {}
    }
}

/// SIGINT/SIGTERM ask the step loop to stop and finish its files; a second signal
/// exits at once (files stay readable up to their last complete chunk).
fn install_signal_handler() {
    let _ = ctrlc::set_handler(|| {
        if run::STOP.swap(true, std::sync::atomic::Ordering::SeqCst) {
            std::process::exit(EXIT_INTERRUPTED as i32);
        }
    });
}

fn cmd_inspect(path: &str) -> Result<ExitCode, SpatterError> {
    let i = spatter::inspect::inspect(path)?;
    print!("{}", i.text);
    Ok(ExitCode::SUCCESS)
}

/// Input that is valid but probably not meant (model::Model::warnings), on stderr.
fn print_warnings(m: &spatter::model::Model) {
    for w in &m.warnings {
        eprintln!("warning: {w}");
    }
}

fn cmd_validate(path: &str, sets: &[String]) -> Result<ExitCode, SpatterError> {
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

/// Hardware adapter: differences by tolerance (docs/backends.md), per field after one
/// free-running step and per pass with each pass started from the CPU state.
fn print_hardware_comparison(
    report: &compare::CompareReport,
    model: &spatter::model::Model,
    steps: u64,
) -> ExitCode {
    let rel = |d: &compare::FieldDifference| {
        if d.relative == 0.0 {
            return "0 (identical)".to_string();
        }
        format!(
            "{:.3e} (particle {} component {}: cpu {:e}, gpu {:e})",
            d.relative, d.particle, d.component, d.cpu, d.gpu
        )
    };
    println!("compared by tolerance, each difference relative to the field's scale (its largest magnitude; p0 for pressure, p0/(rho0 h) for accelerations)");
    println!("after one free-running step, per field:");
    for d in &report.max_rel {
        println!("  {}: {}", d.field, rel(d));
    }
    let tol = compare::HARDWARE_PASS_TOLERANCE;
    println!("per pass, each started from the CPU state, largest over {steps} steps:");
    for p in &report.per_pass {
        let phase = model
            .phases
            .get(p.phase as usize)
            .map_or("?", |ph| ph.name.as_str());
        if p.largest.relative == 0.0 {
            println!("  {}: 0 (identical)", p.pass);
            continue;
        }
        println!(
            "  {}: {} {} at step {}, id {}, phase {}",
            p.pass,
            p.largest.field,
            rel(&p.largest),
            p.step,
            p.id,
            phase
        );
    }
    let worst = report
        .per_pass
        .iter()
        .map(|p| p.largest.relative)
        .fold(0.0, f64::max);
    let exact = report.max_rel.iter().all(|d| d.relative == 0.0) && worst == 0.0;
    println!("bit-identical: {}", if exact { "yes" } else { "no" });
    let pass = worst <= tol;
    println!(
        "within hardware tolerance ({tol:e} per pass): {} (largest {worst:.3e})",
        if pass { "yes" } else { "no" }
    );
    if pass {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

fn cmd_compare(
    path: &str,
    steps: u64,
    sets: &[String],
    by_tolerance: bool,
) -> Result<ExitCode, SpatterError> {
    let loaded = run::load(path, sets)?;
    let params = Params::new(&loaded.model, loaded.state.len() as u32);
    let ctx = GpuContext::open(AdapterChoice::AnyGpu, false).map_err(SpatterError::Runtime)?;
    let mut gpu =
        GpuBackend::new(ctx, params, &loaded.state, false).map_err(SpatterError::Runtime)?;
    let mut cpu = CpuBackend::new(params, loaded.state.clone());
    use spatter::backend::Backend;
    let software = gpu.is_software() && !by_tolerance;
    println!("scenario: {path}, particles: {}", loaded.state.len());
    println!("reference: {}", cpu.describe());
    println!("device: {}", gpu.describe());
    let mode = if software {
        compare::CompareMode::Exact
    } else {
        compare::CompareMode::Tolerance(compare::ToleranceScales::new(&params))
    };
    let report = compare::compare(&mut cpu, &mut gpu, steps, &mode)
        .map_err(|e| SpatterError::Runtime(e.to_string()))?;
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
        return Ok(print_hardware_comparison(&report, &loaded.model, steps));
    }
    Ok(ExitCode::SUCCESS)
}
