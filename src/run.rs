//! Choosing a backend and driving the step loop (a scene is loaded by `load`).

pub(crate) mod observers;
pub mod pool_csv;

use observers::observe_all;
pub use observers::{Findings, Moment, Observer};

use crate::backend::cpu::CpuBackend;
use crate::backend::gpu::{AdapterChoice, GpuBackend, GpuContext};
use crate::backend::{Backend, DeviceLost};
use crate::checkpoint::CheckpointSink;
use crate::checks::CheckResult;
use crate::diagnostics::{self, Leakage, BODIES_TOPIC, DIAGNOSTICS_TOPIC, REMOVED_TOPIC};
use crate::error::SpatterError;
pub use crate::load::{load, load_checkpoint, load_str, Loaded};
use crate::model::{EndCondition, Model};
use crate::outflow::RemovalLog;
use crate::output::{mcap_out::McapSink, vtk::VtkSink};
use crate::params::Params;
use crate::state::{dt_limit_name, State};
use crate::watchdog::{self, Trip};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BackendChoice {
    Auto,
    Gpu,
    Cpu,
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
    /// The state came from a checkpoint: it already holds accelerations and Δt,
    /// so the priming passes are skipped (re-running them would change nothing in
    /// positions but would recompute accelerations from full-step velocities).
    pub resumed: bool,
}

/// Set by the SIGINT/SIGTERM handler; the step loop stops at the next step boundary.
pub static STOP: AtomicBool = AtomicBool::new(false);

#[derive(Debug, Clone, PartialEq)]
pub enum RunEnd {
    Completed,
    Interrupted,
    Unstable(Trip),
}

pub struct RunReport {
    pub steps: u64,
    pub sim_time: f64,
    pub wall_s: f64,
    pub particles: usize,
    pub check: Option<CheckResult>,
    pub final_state: State,
    pub end: RunEnd,
    /// The checkpoint written last, if any.
    pub last_checkpoint: Option<PathBuf>,
    /// Wall leakage over every state the run read back.
    pub leakage: Leakage,
    /// The melt track of a laser scene.
    pub track: Option<crate::track::TrackProfile>,
    /// Why the run ended before its end time (`run.stop_when`).
    pub stop_reason: Option<String>,
    /// Where and how the metal froze, in scenes with a melting phase.
    pub solidification: Option<crate::solidification::Summary>,
    /// The ray-traced laser's absorbed fraction over the states read back.
    pub laser: Option<crate::diagnostics::LaserSummary>,
}

impl RunReport {
    pub fn particle_steps_per_s(&self) -> f64 {
        self.particles as f64 * self.steps as f64 / self.wall_s.max(1e-9)
    }
}

/// Where a run writes: any of an MCAP stream, a VTK series and checkpoints.
#[derive(Default)]
pub struct Outputs {
    pub mcap: Option<McapSink>,
    pub vtk: Option<VtkSink>,
    /// `--pool-csv`: the melt pool's time series beside the MCAP.
    pub pool_csv: Option<pool_csv::PoolCsv>,
    pub checkpoints: Option<CheckpointSink>,
    /// Simulated time between periodic checkpoints; None writes them only at the end,
    /// on interruption and on an instability stop.
    pub checkpoint_every: Option<f64>,
    pub backend: String,
    last_diag_step: Option<u32>,
    last_checkpoint: Option<PathBuf>,
    /// The `/removed` events written so far.
    removals: RemovalLog,
}

impl Outputs {
    /// A frame of `st` (MCAP `/particles` with its `/bodies` message, VTK).
    fn frame(&mut self, m: &Model, st: &State) -> Result<(), String> {
        if let Some(s) = self.mcap.as_mut() {
            let written = s.frame(m, st)?;
            if written && s.has(BODIES_TOPIC) {
                let bodies = diagnostics::bodies_message(m, st);
                s.message(BODIES_TOPIC, st.sim.time as f64, &bodies)?;
            }
        }
        if let Some(v) = self.vtk.as_mut() {
            v.frame(m, st)?;
        }
        Ok(())
    }
    /// The `/removed` events since the last record, then the `/diagnostics`
    /// record of `st` (once per step), with the figures of the observers, which
    /// have seen `st` already.
    fn diagnostics(
        &mut self,
        m: &Model,
        st: &State,
        observers: &[Box<dyn Observer>],
    ) -> Result<(), String> {
        if self.last_diag_step == Some(st.sim.step) {
            return Ok(());
        }
        self.last_diag_step = Some(st.sim.step);
        let Some(s) = self.mcap.as_mut() else {
            return Ok(());
        };
        for e in self.removals.new_events(m, st) {
            s.message(REMOVED_TOPIC, e.time, &e)?;
        }
        let mut d = diagnostics::record(m, st);
        for o in observers {
            o.annotate(&mut d);
        }
        if let Some(csv) = self.pool_csv.as_mut() {
            csv.record(&d)?;
        }
        s.message(DIAGNOSTICS_TOPIC, d.time, &d)
    }
    fn checkpoint(&mut self, m: &Model, st: &State) -> Result<(), String> {
        if let Some(c) = self.checkpoints.as_mut() {
            self.last_checkpoint = Some(c.write(m, st, &self.backend)?);
        }
        Ok(())
    }
    /// Close every file properly (MCAP summary and footer).
    pub fn finish(&mut self) -> Result<(), String> {
        match self.mcap.as_mut() {
            Some(s) => s.finish(),
            None => Ok(()),
        }
    }
}

/// Tell the timestep pass the run's end time (0 for a run of so many steps), so
/// its last steps land on it, and shorten the step already computed (by the
/// prime or before a checkpoint) where it would cross it.
fn land_on_end(backend: &mut dyn Backend, sim: &mut crate::state::Sim, end: EndCondition) {
    sim.end_time = match end {
        EndCondition::Time(te) => te as f32,
        EndCondition::Steps(_) => 0.0,
    };
    if let Some(dt) = crate::model::limits::toward_end(sim.end_time, sim.time, sim.dt) {
        sim.dt = dt;
        sim.dt_limit = crate::model::limits::Limit::End.code();
    }
    backend.write_sim(sim);
}

/// Whether the end time is reached: within END_SLACK of it, as the timestep
/// pass counts it (f32 time).
fn end_reached(end: f64, time: f32) -> bool {
    let end = end as f32;
    end - time <= crate::model::limits::END_SLACK * end
}

/// The most steps to run before reading back, `left` seconds before the end:
/// the fewest steps of the longest possible advance that cover it, so every
/// step before the last ends short of it and a chunk never runs past the step
/// that lands on the end (the steps after it would go on past). A step advances
/// time by at most `longest` plus f32 time's rounding, under an ulp of the end.
/// An estimate from the current Δt alone overshot by up to a third of the run
/// when Δt grew inside a chunk (a DFSPH splat slowing down). Single steps
/// where nothing bounds Δt (DFSPH without `run.max_dt`: any step may be the one
/// that lands); no bound without an end.
fn steps_toward(left: f64, longest: f64, end: f64) -> u64 {
    if left == f64::INFINITY {
        return u64::MAX;
    }
    let e = end as f32;
    let ulp = (f32::from_bits(e.to_bits() + 1) - e) as f64;
    let covering = (left / (longest + ulp)).ceil();
    if covering.is_finite() && covering > 1.0 {
        covering as u64
    } else {
        1
    }
}

/// The binding limit's name for the progress line. Under DFSPH the acoustic
/// limit's sound speed is 0 (`Model::max_sound_speed`), so it is the flow's
/// CFL 0.25 h/|u|: say so rather than "acoustic".
fn progress_limit_name(m: &Model, code: u32) -> &'static str {
    if code == crate::model::limits::Limit::Acoustic.code() && m.max_sound_speed() == 0.0 {
        return "flow CFL";
    }
    dt_limit_name(code)
}

/// Steps between host reads of Δt and time: about 2e6 particle-updates, at most
/// 200 steps. It depends on the particle count only. Where a run ends is the
/// device's choice (the steps land on `Sim::end_time`), not the chunking's.
fn chunk_cap(particles: usize) -> u64 {
    (2_000_000 / particles.max(1) as u64).clamp(1, 200)
}

/// The longest step the timestep pass can take: its own formula at rest (|u|
/// only shortens the acoustic limit; with no acceleration the force limit is
/// left out, since the flow's can fall below gravity's); the fixed Δt where
/// there is one. ∞ when nothing bounds it (DFSPH without `run.max_dt` and
/// without other limits).
fn longest_step(pr: &Params) -> f64 {
    match crate::backend::cpu::next_dt(pr, 0.0, 0.0).0 {
        f32::MAX => f64::INFINITY,
        dt => dt as f64,
    }
}

/// The first multiple of `interval` after `t` (∞ for an infinite interval).
fn next_multiple(t: f64, interval: f64) -> f64 {
    if !interval.is_finite() {
        return f64::INFINITY;
    }
    ((t / interval + 1e-9).floor() + 1.0) * interval
}

/// When the next frame, diagnostics record and checkpoint are due, in simulated
/// time.
struct OutputSchedule {
    frame: f64,
    diag: f64,
    ckpt: f64,
}

impl OutputSchedule {
    fn new(m: &Model, t: f64, ckpt_every: Option<f64>) -> OutputSchedule {
        OutputSchedule {
            frame: next_multiple(t, m.output_interval),
            diag: next_multiple(t, m.diagnostics_interval),
            ckpt: ckpt_every.map_or(f64::INFINITY, |c| next_multiple(t, c)),
        }
    }
    fn next(&self) -> f64 {
        self.frame.min(self.diag).min(self.ckpt)
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
    #[allow(clippy::too_many_arguments)] // one progress line's figures, read where the loop has them
    fn update(
        &mut self,
        quiet: bool,
        frac: f64,
        t: f64,
        step: u64,
        dt: f32,
        limit: &str,
        rate: f64,
    ) {
        let msg = format!(
            "t = {t:.4e} s, step {step}, dt = {dt:.3e} ({limit}), {rate:.3e} particle-steps/s"
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

/// Run the step loop to the end condition, writing outputs on the way. Every
/// ending (completed, interrupted, unstable) writes a last frame; checkpoints go
/// where `out.checkpoints` points.
pub fn run(
    l: &Loaded,
    backend: &mut dyn Backend,
    opts: &RunOptions,
    out: &mut Outputs,
) -> Result<RunReport, SpatterError> {
    let m = &l.model;
    let rt = SpatterError::Runtime;
    let mut observers = observers::list(m, opts);
    let start = Instant::now();
    if !opts.resumed {
        backend.prime();
    }
    let mut progress = Progress::new(opts.quiet);
    let mut st = backend
        .read_state()
        .map_err(|e| device_lost(m, out, &l.state, e))?;
    land_on_end(backend, &mut st.sim, opts.end);
    let mut last_good = st.clone();
    let mut sim = st.sim;
    let start_step = sim.step as u64;
    let mut sched = OutputSchedule::new(m, sim.time as f64, out.checkpoint_every);
    observe_all(&mut observers, m, &st, Moment::Initial);
    out.frame(m, &st).map_err(rt)?;
    out.diagnostics(m, &st, &observers).map_err(rt)?;
    let cap = chunk_cap(st.len());
    // The approach to the end may stretch a step by END_STRETCH.
    let longest =
        longest_step(&Params::new(m, st.len() as u32)) * crate::model::limits::END_STRETCH as f64;
    let mut steps_done = 0u64;
    let start_dt = sim.dt;
    let mut trip = watchdog::check_sim(m, &sim, start_dt).or_else(|| watchdog::scan(m, &st));
    let mut end = RunEnd::Completed;
    let mut stop_reason = None;
    while trip.is_none() {
        let t = sim.time as f64;
        let (done, frac) = match opts.end {
            EndCondition::Steps(n) => (steps_done >= n, steps_done as f64 / n.max(1) as f64),
            EndCondition::Time(te) => (end_reached(te, sim.time), t / te),
        };
        if done {
            break;
        }
        if STOP.load(Ordering::SeqCst) {
            end = RunEnd::Interrupted;
            break;
        }
        // The device's end is the f32 one.
        let end_time = match opts.end {
            EndCondition::Time(te) => (te as f32) as f64,
            EndCondition::Steps(_) => f64::INFINITY,
        };
        let target = sched.next().min(end_time);
        // Toward an output, the current Δt's estimate (a frame may come late
        // where Δt grows); never past the step that lands on the end.
        let estimate = ((target - t) / sim.dt as f64).ceil().max(1.0) as u64;
        let mut chunk = estimate.min(steps_toward(end_time - t, longest, end_time));
        if let EndCondition::Steps(n) = opts.end {
            chunk = chunk.min(n - steps_done);
        }
        steps_done += run_interruptible(backend, chunk.min(cap));
        sim = backend
            .read_sim()
            .map_err(|e| device_lost(m, out, &last_good, e))?;
        let rate = st.len() as f64 * steps_done as f64 / start.elapsed().as_secs_f64();
        progress.update(
            opts.quiet,
            frac,
            sim.time as f64,
            steps_done,
            sim.dt,
            progress_limit_name(m, sim.dt_limit),
            rate,
        );
        trip = watchdog::check_sim(m, &sim, start_dt);
        let t = sim.time as f64;
        let eps = 1e-12;
        let due = (
            t >= sched.frame - eps,
            t >= sched.diag - eps,
            t >= sched.ckpt - eps,
        );
        if trip.is_some() || !(due.0 || due.1 || due.2) {
            continue;
        }
        st = backend
            .read_state()
            .map_err(|e| device_lost(m, out, &last_good, e))?;
        trip = watchdog::scan(m, &st);
        if trip.is_some() {
            continue;
        }
        last_good = st.clone();
        observe_all(&mut observers, m, &st, Moment::Sample { frame: due.0 });
        if due.1 {
            out.diagnostics(m, &st, &observers).map_err(rt)?;
        }
        if due.0 {
            out.frame(m, &st).map_err(rt)?;
        }
        if due.2 {
            out.checkpoint(m, &st).map_err(rt)?;
        }
        sched = OutputSchedule::new(m, t, out.checkpoint_every);
        stop_reason = solidified(m, &st);
        if stop_reason.is_some() {
            break;
        }
    }
    progress.finish();
    // The last chunk can end between two scans: the final state is scanned too, so
    // a run never completes on a state the watchdog would refuse.
    let mut fin = None;
    if trip.is_none() {
        let st = backend
            .read_state()
            .map_err(|e| device_lost(m, out, &last_good, e))?;
        trip = watchdog::scan(m, &st);
        fin = Some(st);
    }
    let final_state = match trip {
        Some(first) => {
            let (precise, bad, good) = replay_to_trip(m, backend, &last_good, first, start_dt)
                .map_err(|e| device_lost(m, out, &last_good, e))?;
            observe_all(&mut observers, m, &bad, Moment::Unstable);
            out.frame(m, &bad).map_err(rt)?;
            out.diagnostics(m, &bad, &observers).map_err(rt)?;
            out.checkpoint(m, &good).map_err(rt)?;
            end = RunEnd::Unstable(precise);
            bad
        }
        None => {
            let fin = fin.expect("the final state is read when nothing tripped");
            observe_all(&mut observers, m, &fin, Moment::Final);
            out.frame(m, &fin).map_err(rt)?;
            out.diagnostics(m, &fin, &observers).map_err(rt)?;
            if out.checkpoint_every.is_some() || end == RunEnd::Interrupted {
                out.checkpoint(m, &fin).map_err(rt)?;
            }
            fin
        }
    };
    let mut found = Findings::default();
    for o in observers {
        o.finish(m, &final_state, &end, out, &mut found)
            .map_err(rt)?;
    }
    out.finish().map_err(rt)?;
    let wall_s = start.elapsed().as_secs_f64();
    let solidification = crate::solidification::Summary::of(m, &final_state);
    Ok(RunReport {
        steps: final_state.sim.step as u64 - start_step,
        sim_time: final_state.sim.time as f64,
        wall_s,
        particles: final_state.len(),
        check: found.check,
        final_state,
        end,
        last_checkpoint: out.last_checkpoint.clone(),
        leakage: found.leakage,
        track: found.track,
        stop_reason,
        solidification,
        laser: found.laser,
    })
}

/// `run.stop_when = "solidified"`: why the run stops at the
/// sample `st`, if it does: the beam is off for good and no melt is left, or the
/// grace after the beam went off has passed.
fn solidified(m: &Model, st: &State) -> Option<String> {
    let (off, grace) = m.stop_when_solidified?;
    let t = st.sim.time as f64;
    if t < off {
        return None;
    }
    let melt = (0..st.active())
        .filter(|&i| crate::pool::is_melt(m, st, i))
        .count();
    if melt == 0 {
        Some(format!(
            "stopped at t = {t:.6e} s: the beam is off since {off:.6e} s and no melt is left (run.stop_when = \"solidified\")"
        ))
    } else if t >= off + grace {
        Some(format!(
            "stopped at t = {t:.6e} s: {grace:e} s after the beam went off (run.stop_grace), {melt} particle(s) still molten"
        ))
    } else {
        None
    }
}

/// Run `n` steps in small batches, stopping early if a signal arrived.
fn run_interruptible(backend: &mut dyn Backend, n: u64) -> u64 {
    const BATCH: u64 = 8;
    let mut done = 0;
    while done < n {
        if STOP.load(Ordering::SeqCst) {
            break;
        }
        let k = (n - done).min(BATCH);
        backend.run_steps(k as u32);
        done += k;
    }
    done
}

/// Rewind to the last good state and step one at a time until the watchdog trips
/// again, so the report names the first bad step. Returns the trip, the first bad
/// state and the last good one. Steps are deterministic, so the replay meets the
/// same failure; if it somehow does not within twice the distance, the original
/// trip and the current state are reported.
fn replay_to_trip(
    m: &Model,
    backend: &mut dyn Backend,
    last_good: &State,
    first: Trip,
    start_dt: f32,
) -> Result<(Trip, State, State), DeviceLost> {
    let span = (first.step.saturating_sub(last_good.sim.step as u64) + 1) * 2;
    backend.load_state(last_good);
    let mut good = last_good.clone();
    for _ in 0..span {
        backend.run_steps(1);
        let st = backend.read_state()?;
        // The scan first: it names the particle where check_sim only counts.
        if let Some(t) =
            watchdog::scan(m, &st).or_else(|| watchdog::check_sim(m, &st.sim, start_dt))
        {
            return Ok((t, st, good));
        }
        good = st;
    }
    let current = backend.read_state()?;
    Ok((first, current, good))
}

/// The device stopped answering mid-run: close the outputs at the last state read
/// back (with its checkpoint, where checkpoints are on) so every file stays
/// readable, and say where the run stopped.
fn device_lost(m: &Model, out: &mut Outputs, last_good: &State, e: DeviceLost) -> SpatterError {
    let mut msg = format!(
        "{e}; the run stopped after step {} (t = {:.6e} s), where its outputs end",
        last_good.sim.step, last_good.sim.time
    );
    if let Err(w) = out.checkpoint(m, last_good) {
        msg.push_str(&format!("; the checkpoint of that state failed too: {w}"));
    }
    if let Err(w) = out.finish() {
        msg.push_str(&format!("; closing the outputs failed too: {w}"));
    }
    SpatterError::Runtime(msg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::{Pipeline, Stage};
    use crate::output::mcap_out::Provenance;

    /// The CPU backend, except that its device is lost at the `fail_at`-th readback.
    struct Losing {
        inner: CpuBackend,
        reads: u32,
        fail_at: u32,
    }

    impl Losing {
        fn read(&mut self) -> Result<(), DeviceLost> {
            self.reads += 1;
            if self.reads >= self.fail_at {
                return Err(DeviceLost(
                    "GPU device lost while reading back: test".into(),
                ));
            }
            Ok(())
        }
    }

    impl Backend for Losing {
        fn describe(&self) -> String {
            "losing".into()
        }
        fn is_software(&self) -> bool {
            true
        }
        fn pipeline(&self) -> &Pipeline {
            self.inner.pipeline()
        }
        fn skip_stage(&mut self, stage: Stage) {
            self.inner.skip_stage(stage)
        }
        fn run_stage(&mut self, stage: Stage) {
            self.inner.run_stage(stage)
        }
        fn read_state(&mut self) -> Result<State, DeviceLost> {
            self.read()?;
            self.inner.read_state()
        }
        fn load_state(&mut self, st: &State) {
            self.inner.load_state(st)
        }
        fn read_sim(&mut self) -> Result<crate::state::Sim, DeviceLost> {
            self.read()?;
            self.inner.read_sim()
        }
        fn write_sim(&mut self, sim: &crate::state::Sim) {
            self.inner.write_sim(sim)
        }
    }

    /// A chunk is at most the fewest steps of the longest possible advance (the
    /// step plus an ulp of the end) that cover the time left, so all but its
    /// last end short of the end; single steps where nothing bounds Δt;
    /// unbounded without an end.
    #[test]
    fn chunks_never_reach_past_the_end() {
        assert_eq!(steps_toward(10.0, 1.0, 20.0), 10);
        assert_eq!(steps_toward(10.5, 1.0, 20.0), 11);
        assert_eq!(steps_toward(0.1, 1.0, 20.0), 1);
        assert_eq!(steps_toward(10.0, f64::INFINITY, 20.0), 1);
        assert_eq!(steps_toward(f64::INFINITY, 1.0, f64::INFINITY), u64::MAX);
        for left in [3.3, 7.0, 12.9] {
            let k = steps_toward(left, 1.0, 20.0) as f64;
            assert!(
                k - 1.0 < left && k >= left - 1e-5,
                "{k} steps of 1 for {left}"
            );
        }
        // Past f32's resolution of a step, the ulp is the bound's share.
        let end = 4.0e4_f64;
        let ulp = (f32::from_bits((end as f32).to_bits() + 1) - end as f32) as f64;
        assert_eq!(steps_toward(10.0 * (1.0 + ulp), 1.0, end), 10);
    }

    /// A device lost mid-run ends it with an error naming the step it stopped at,
    /// the MCAP stream closed (summary and footer) and a checkpoint of the last
    /// state read back; no panic.
    #[test]
    fn a_lost_device_ends_the_run_with_its_outputs_closed() {
        let scene = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/validation/poiseuille_2d.toml"
        );
        let l = load(scene, &[]).unwrap();
        let params = Params::new(&l.model, l.state.len() as u32);
        let dir = std::env::temp_dir().join(format!("spatter-lost-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let mcap = dir.join("run.mcap").to_string_lossy().into_owned();
        let prov = Provenance {
            backend: "losing",
            command: "test",
        };
        let mut out = Outputs {
            mcap: Some(
                McapSink::create(&mcap, &l.model, &prov, &diagnostics::topics(&l.model)).unwrap(),
            ),
            checkpoints: Some(CheckpointSink::create(&dir.join("ckpt").to_string_lossy()).unwrap()),
            ..Default::default()
        };
        let mut b = Losing {
            inner: CpuBackend::new(params, l.state.clone()),
            reads: 0,
            fail_at: 4,
        };
        let opts = RunOptions {
            end: EndCondition::Steps(2000),
            quiet: true,
            resumed: false,
        };
        let err = match run(&l, &mut b, &opts, &mut out) {
            Err(SpatterError::Runtime(m)) => m,
            Err(e) => panic!("wrong error: {e}"),
            Ok(_) => panic!("the run went on without its device"),
        };
        assert!(
            err.contains("device lost") && err.contains("stopped after step"),
            "{err}"
        );
        let seen = crate::inspect::inspect(&mcap).unwrap();
        assert!(seen.complete, "MCAP closed with summary and footer");
        let ckpt = out
            .last_checkpoint
            .clone()
            .expect("checkpoint of the last good state");
        let c = crate::checkpoint::load(&ckpt.to_string_lossy()).unwrap();
        assert!(
            c.state.sim.step > 0,
            "a state after the first chunk was kept"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
