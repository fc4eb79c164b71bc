//! Loading a scene, choosing a backend and driving the step loop.

use crate::backend::cpu::CpuBackend;
use crate::backend::gpu::{AdapterChoice, GpuBackend, GpuContext};
use crate::backend::Backend;
use crate::checks::{CheckResult, Checker};
use crate::error::{InputError, SpatterError};
use crate::model::{self, EndCondition, Model};
use crate::params::Params;
use crate::scene;
use crate::setup;
use crate::state::{State, DT_LIMIT_NAMES};
use std::io::IsTerminal;
use std::time::Instant;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BackendChoice {
    Auto,
    Gpu,
    Cpu,
}

/// A scene ready to run: validated model and initial particles.
pub struct Loaded {
    pub model: Model,
    pub state: State,
}

pub fn load(path: &str, sets: &[String]) -> Result<Loaded, InputError> {
    let (scene, resolved) = scene::load(path, sets)?;
    let model = model::build(path, &scene, &resolved)?;
    let state = setup::generate(&model, &scene)?;
    Ok(Loaded { model, state })
}

pub fn make_backend(
    choice: BackendChoice,
    l: &Loaded,
    profile: bool,
) -> Result<Box<dyn Backend>, SpatterError> {
    let params = Params::new(&l.model, l.state.len() as u32);
    let gpu = |c| -> Result<Box<dyn Backend>, SpatterError> {
        let ctx = GpuContext::open(c, profile).map_err(SpatterError::Runtime)?;
        Ok(Box::new(
            GpuBackend::new(ctx, params, &l.state, profile).map_err(SpatterError::Runtime)?,
        ))
    };
    match choice {
        BackendChoice::Cpu => Ok(Box::new(CpuBackend::new(params, l.state.clone()))),
        BackendChoice::Gpu => gpu(AdapterChoice::AnyGpu),
        BackendChoice::Auto => match gpu(AdapterChoice::HardwareOnly) {
            Ok(b) => Ok(b),
            Err(_) => Ok(Box::new(CpuBackend::new(params, l.state.clone()))),
        },
    }
}

pub struct RunOptions {
    pub end: EndCondition,
    pub quiet: bool,
}

pub struct RunReport {
    pub steps: u64,
    pub sim_time: f64,
    pub wall_s: f64,
    pub particles: usize,
    pub check: Option<CheckResult>,
    pub final_state: State,
}

impl RunReport {
    pub fn particle_steps_per_s(&self) -> f64 {
        self.particles as f64 * self.steps as f64 / self.wall_s.max(1e-9)
    }
}

struct Progress {
    bar: Option<indicatif::ProgressBar>,
    last_print: Instant,
    start: Instant,
}

impl Progress {
    fn new(quiet: bool) -> Progress {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let b = indicatif::ProgressBar::new(1000);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{bar:40} {percent:>3}% | {msg} | ETA {eta}",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            b
        });
        Progress {
            bar,
            last_print: Instant::now(),
            start: Instant::now(),
        }
    }
    fn update(
        &mut self,
        quiet: bool,
        frac: f64,
        t: f64,
        step: u64,
        dt: f32,
        limit: u32,
        rate: f64,
    ) {
        let msg = format!(
            "t = {t:.4e} s, step {step}, dt = {dt:.3e} ({}), {rate:.3e} particle-steps/s",
            DT_LIMIT_NAMES[limit as usize % 4]
        );
        if let Some(b) = &self.bar {
            b.set_position((frac.clamp(0.0, 1.0) * 1000.0) as u64);
            b.set_message(msg);
        } else if !quiet && self.last_print.elapsed().as_secs_f64() >= 5.0 {
            let elapsed = self.start.elapsed().as_secs_f64();
            let eta = if frac > 0.0 {
                elapsed * (1.0 - frac) / frac
            } else {
                0.0
            };
            eprintln!("progress {:5.1}% | {msg} | ETA {eta:.0} s", 100.0 * frac);
            self.last_print = Instant::now();
        }
    }
    fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// Run the step loop to the end condition, sampling state every output interval.
pub fn run(
    l: &Loaded,
    backend: &mut dyn Backend,
    opts: &RunOptions,
) -> Result<RunReport, SpatterError> {
    let m = &l.model;
    let mut checker = Checker::new(m);
    let start = Instant::now();
    backend.prime();
    let mut progress = Progress::new(opts.quiet);
    let mut next_sample = 0.0f64;
    let mut steps_done = 0u64;
    let mut sim = backend.read_sim();
    if let Some(c) = checker.as_mut() {
        c.observe(m, &backend.read_state());
    }
    next_sample += m.output_interval;
    loop {
        let t = sim.time as f64;
        let (done, frac) = match opts.end {
            EndCondition::Steps(n) => (steps_done >= n, steps_done as f64 / n.max(1) as f64),
            EndCondition::Time(te) => (t >= te, t / te),
        };
        if done {
            break;
        }
        if !(sim.dt.is_finite() && sim.dt > 0.0) {
            return Err(SpatterError::Runtime(format!(
                "unstable: time step became {} at step {} (t = {t:.6e} s); the run stopped",
                sim.dt, sim.step
            )));
        }
        // Steps until the next sample or the end, from the current Δt (it changes slowly).
        let target = match opts.end {
            EndCondition::Time(te) => next_sample.min(te),
            EndCondition::Steps(_) => next_sample,
        };
        let mut chunk = (((target - t) / sim.dt as f64).ceil().max(1.0)) as u64;
        if let EndCondition::Steps(n) = opts.end {
            chunk = chunk.min(n - steps_done);
        }
        let chunk = chunk.min(200) as u32;
        backend.run_steps(chunk);
        steps_done += chunk as u64;
        sim = backend.read_sim();
        let rate = l.state.len() as f64 * steps_done as f64 / start.elapsed().as_secs_f64();
        progress.update(
            opts.quiet,
            frac,
            sim.time as f64,
            steps_done,
            sim.dt,
            sim.dt_limit,
            rate,
        );
        if sim.time as f64 >= next_sample - 1e-12 {
            if let Some(c) = checker.as_mut() {
                c.observe(m, &backend.read_state());
            }
            while next_sample <= sim.time as f64 {
                next_sample += m.output_interval;
            }
        }
    }
    progress.finish();
    let final_state = backend.read_state();
    let wall_s = start.elapsed().as_secs_f64();
    let check = checker.as_mut().map(|c| c.finish(m, &final_state));
    Ok(RunReport {
        steps: steps_done,
        sim_time: final_state.sim.time as f64,
        wall_s,
        particles: final_state.len(),
        check,
        final_state,
    })
}
