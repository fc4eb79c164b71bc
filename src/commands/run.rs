//! `spatter run`: a scene (or a checkpoint) to its end, with its outputs, its
//! closing lines and its check's verdict as the exit code.

use super::*;
use crate::*;
use spatter::checkpoint::CheckpointSink;
use spatter::error::InputError;
use spatter::error::SpatterError;
use spatter::model::EndCondition;
use spatter::output::mcap_out::{McapSink, Provenance};
use spatter::output::vtk::VtkSink;
use spatter::run::pool_csv::PoolCsv;
use spatter::run::{self, BackendChoice, Outputs, RunEnd, RunOptions};
use std::process::ExitCode;

/// Exit code of a run stopped by SIGINT/SIGTERM (shell convention 128 + SIGINT).
const EXIT_INTERRUPTED: u8 = 130;

/// Exit code of a run the watchdog stopped.
const EXIT_UNSTABLE: u8 = 3;

pub(crate) fn cmd_run(
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
