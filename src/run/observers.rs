//! Host-side observers of a run: each sees every state the run reads back, and
//! concludes at the end. The run feeds them at one place per moment (`observe_all`)
//! and never names one; a new observer is one entry in `list`.

use super::{Outputs, RunEnd, RunOptions};
use crate::checks::{CheckResult, Checker};
use crate::diagnostics::{Diagnostics, Leakage, CHECK_TOPIC, TRACK_TOPIC};
use crate::model::Model;
use crate::solidification;
use crate::state::State;
use crate::track::{Track, TrackProfile};

/// Which state an observer is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Moment {
    /// The state the run starts from (the initial state, or the resumed one).
    Initial,
    /// A state read back at an output time; `frame`: a frame is written of it.
    Sample { frame: bool },
    /// The first bad state of an unstable run, as the replay found it.
    Unstable,
    /// The state a completed or interrupted run ends on.
    Final,
}

/// What the observers conclude: their part of the `RunReport`.
#[derive(Default)]
pub struct Findings {
    pub check: Option<CheckResult>,
    pub leakage: Leakage,
    pub track: Option<TrackProfile>,
    pub laser: Option<crate::diagnostics::LaserSummary>,
}

/// A host-side observer of the states a run reads back.
pub trait Observer {
    /// Take in a state. The run shows it to every observer before writing any
    /// output of it, so `annotate` describes the state being written.
    fn observe(&mut self, m: &Model, st: &State, when: Moment);
    /// Add this observer's figures to the `/diagnostics` record of the state it
    /// observed last.
    fn annotate(&self, _d: &mut Diagnostics) {}
    /// Conclude from the state the run ends on (`last`, already observed), into
    /// `found`; an observer with a topic of its own writes it to `out` (still open).
    /// An observer that only warns concludes nothing.
    fn finish(
        self: Box<Self>,
        _m: &Model,
        _last: &State,
        _end: &RunEnd,
        _out: &mut Outputs,
        _found: &mut Findings,
    ) -> Result<(), String> {
        Ok(())
    }
}

/// The observers of a run of `m`, in the order they see each state.
pub fn list(m: &Model, opts: &RunOptions) -> Vec<Box<dyn Observer>> {
    let mut list: Vec<Box<dyn Observer>> = vec![Box::new(WallLeakage {
        worst: Leakage::default(),
        warned: false,
        quiet: opts.quiet,
    })];
    if let Some(c) = Checker::new(m) {
        list.push(Box::new(CheckObserver(c)));
    }
    if crate::track::wanted(m) {
        list.push(Box::new(TrackObserver(None)));
    }
    if m.laser.as_ref().is_some_and(|l| l.rays.is_some()) {
        list.push(Box::<LaserAbsorption>::default());
    }
    if m.melts() {
        list.push(Box::<SolidificationRecords>::default());
    }
    let solves = crate::diagnostics::solver_names(m);
    if !solves.is_empty() && !opts.quiet {
        list.push(Box::new(SolverCaps { last: None, solves }));
    }
    if m.watchdog.enabled
        && m.dispersion_action() == crate::scene::DispersionAction::Warn
        && !opts.quiet
    {
        list.push(Box::<DispersionWarning>::default());
    }
    // Where the CSF skips those particles (δ-SPH) there is nothing to warn of.
    if m.free_surface_csf() && !m.csf_skips_interior() && !opts.quiet {
        list.push(Box::new(InteriorNormals { warned: false }));
    }
    list
}

/// Share of the free-surface measure inside the liquid (`interior_normals`) from
/// which a run on summation density is warned, once. R18's disc there: not
/// warned from the lattice over 0.2 s, 0.32 with 0.1Δx of disorder and 0.51 with
/// 0.2Δx (on δ-SPH, where the tension skips those particles: 0.07 from the
/// lattice, 0.39 with 0.1Δx, which before that rule drifted off; docs/physics.md,
/// free-surface form, "Disorder"). The powder-bed slice reads 0.35 at 20 µs.
pub const INTERIOR_NORMALS_WARNING: f64 = 0.3;

/// The free-surface CSF acting on particle disorder: a warning at the first
/// sample at which `INTERIOR_NORMALS_WARNING` or more of the liquid's surface
/// measure sits on particles with a full support.
struct InteriorNormals {
    warned: bool,
}

impl Observer for InteriorNormals {
    fn observe(&mut self, m: &Model, st: &State, when: Moment) {
        if self.warned || !matches!(when, Moment::Sample { .. } | Moment::Final) {
            return;
        }
        let Some(d) = crate::diagnostics::surface_diagnostics(m, st) else {
            return;
        };
        if d.interior_normals >= INTERIOR_NORMALS_WARNING {
            self.warned = true;
            eprintln!(
                "warning: t = {:.6e} s: {:.0}% of the liquid's free-surface measure (sum of V delta) \
                 lies on particles inside the liquid (Shepard sum >= {}): particle disorder has given \
                 them normals, and the free-surface tension acts on that noise as well as on the \
                 surface: surface-driven figures from here on carry that error. On \
                 formulation = \"delta_wcsph\" the tension skips them (docs/physics.md, \
                 free-surface form, \"Disorder\")",
                st.sim.time as f64,
                100.0 * d.interior_normals,
                crate::diagnostics::INTERIOR_SHEPARD
            );
        }
    }
}

/// `watchdog.on_dispersion = "warn"`: a warning at the first sample at which
/// the liquid is dispersing into its gas, or breaking up without gas
/// (crate::watchdog::dispersion), and again whenever the share has grown by
/// half since the last warning (a melt track that sheds spatter for its whole
/// run warned at each of its 18 samples); with "stop" the watchdog ends the
/// run instead.
#[derive(Default)]
struct DispersionWarning {
    /// The share at the last warning (0: none yet).
    warned: f64,
}

/// Growth of the dispersed share that warns again.
const DISPERSION_GROWTH: f64 = 1.5;

impl DispersionWarning {
    /// Warn at this share (past the bound)? The first time, and then once it
    /// has grown by DISPERSION_GROWTH since the last warning.
    fn due(&mut self, share: f64) -> bool {
        if share < DISPERSION_GROWTH * self.warned {
            return false;
        }
        self.warned = share;
        true
    }
}

impl Observer for DispersionWarning {
    fn observe(&mut self, m: &Model, st: &State, when: Moment) {
        if !matches!(when, Moment::Sample { .. } | Moment::Final) {
            return;
        }
        let Some(d) = crate::watchdog::dispersion(m, st).filter(|d| d.beyond(m)) else {
            return;
        };
        if !self.due(d.share()) {
            return;
        }
        eprintln!(
            "warning: t = {:.6e} s: {}",
            st.sim.time as f64,
            d.describe(m)
        );
    }
}

/// Iterative solves that stop at their bound instead of their tolerance: a
/// warning at each sample after which two or more steps since the previous
/// one ended capped, naming the solve, its bound and its last residual.
struct SolverCaps {
    /// The step and each slot's capped count at the previous sample.
    last: Option<(u32, Vec<u32>)>,
    solves: Vec<&'static str>,
}

impl Observer for SolverCaps {
    fn observe(&mut self, m: &Model, st: &State, when: Moment) {
        if st.solvers.is_empty() {
            return;
        }
        let now: Vec<u32> = st.solvers.iter().map(|s| s.capped).collect();
        let sample = matches!(when, Moment::Sample { .. } | Moment::Final);
        if let (true, Some((step0, before))) = (sample, self.last.as_ref()) {
            let steps = st.sim.step.saturating_sub(*step0);
            for (slot, name) in crate::backend::SOLVER_SLOTS.iter() {
                let k = *slot as usize;
                let capped = now[k].saturating_sub(before[k]);
                if capped >= 2 && self.solves.contains(name) {
                    eprintln!(
                        "warning: t = {:.6e} s: the {name} solve stopped at its bound of {} \
                         iterations unconverged on {capped} of the {steps} steps since the last \
                         sample (last residual {:.3e}); raise its max_iterations or loosen its tolerance",
                        st.sim.time as f64,
                        max_iterations(m, *slot),
                        st.solvers[k].residual
                    );
                }
            }
        }
        self.last = Some((st.sim.step, now));
    }
}

/// A solve's bound of iterations per step.
fn max_iterations(m: &Model, slot: crate::backend::SolverSlot) -> u32 {
    use crate::backend::SolverSlot;
    match slot {
        SolverSlot::Heat => m.heat.max_iterations,
        SolverSlot::Density | SolverSlot::Divergence => m.dfsph.max_iterations,
        SolverSlot::Viscosity => m.dfsph.viscosity_max_iterations,
    }
}

/// Show `st` to every observer.
pub fn observe_all(observers: &mut [Box<dyn Observer>], m: &Model, st: &State, when: Moment) {
    for o in observers.iter_mut() {
        o.observe(m, st, when);
    }
}

/// The scene's check: it samples the initial state and every frame; its verdict
/// needs a completed run (an interrupted or unstable one may hold no sample the
/// reference covers).
struct CheckObserver(Checker);

impl Observer for CheckObserver {
    fn observe(&mut self, m: &Model, st: &State, when: Moment) {
        let sampled = match when {
            Moment::Initial => true,
            Moment::Sample { frame } => frame || self.0.every_sample(),
            _ => false,
        };
        if sampled {
            self.0.observe(m, st);
        }
    }
    fn finish(
        mut self: Box<Self>,
        m: &Model,
        last: &State,
        end: &RunEnd,
        out: &mut Outputs,
        found: &mut Findings,
    ) -> Result<(), String> {
        // `Checker::finish` samples the final state itself.
        if *end == RunEnd::Completed {
            let result = self.0.finish(m, last);
            if let Some(sink) = out.mcap.as_mut() {
                sink.message(CHECK_TOPIC, last.sim.time as f64, &result.message())?;
            }
            found.check = Some(result);
        }
        Ok(())
    }
}

/// Wall leakage over every state read back: the deepest penetration,
/// warned about once (on the first sample that has one) unless the run is quiet.
struct WallLeakage {
    worst: Leakage,
    warned: bool,
    quiet: bool,
}

impl Observer for WallLeakage {
    fn observe(&mut self, m: &Model, st: &State, when: Moment) {
        let now = Leakage::of(m, st);
        if when == Moment::Initial {
            self.worst = now;
            return;
        }
        self.worst.absorb(now);
        let sample = matches!(when, Moment::Sample { .. });
        if sample && !self.warned && self.worst.beyond_half_dx > 0 && !self.quiet {
            self.warned = true;
            eprintln!(
                "warning: fluid leaks into the walls: {}; the run stops at {} dx (watchdog.wall_penetration)",
                self.worst.summary(),
                m.wall_stop_depth()
            );
        }
    }
    fn finish(
        self: Box<Self>,
        _m: &Model,
        _last: &State,
        _end: &RunEnd,
        _out: &mut Outputs,
        found: &mut Findings,
    ) -> Result<(), String> {
        found.leakage = self.worst;
        Ok(())
    }
}

/// The melt track of a laser scene with melting: started on the
/// initial state, it writes the depression under the beam and the pool's
/// figures (crate::pool, depth below the initial surface) into each
/// `/diagnostics` record and its profile to `/track` at the end.
struct TrackObserver(Option<Track>);

impl Observer for TrackObserver {
    fn observe(&mut self, m: &Model, st: &State, when: Moment) {
        match (when, self.0.as_mut()) {
            (Moment::Initial, _) => self.0 = Track::new(m, st),
            (_, Some(t)) => t.observe(m, st),
            (_, None) => {}
        }
    }
    fn annotate(&self, d: &mut Diagnostics) {
        d.depression_depth = self.0.as_ref().and_then(Track::depression_now);
        if let (Some(t), Some(h)) = (self.0.as_ref(), d.heat.as_mut()) {
            crate::diagnostics::set_pool(h, &t.pool_now());
        }
    }
    fn finish(
        self: Box<Self>,
        m: &Model,
        last: &State,
        _end: &RunEnd,
        out: &mut Outputs,
        found: &mut Findings,
    ) -> Result<(), String> {
        let Some(track) = self.0 else {
            return Ok(());
        };
        let profile = track.finish(m, last);
        if let Some(sink) = out.mcap.as_mut() {
            sink.message(TRACK_TOPIC, last.sim.time as f64, &profile)?;
        }
        found.track = Some(profile);
        Ok(())
    }
}

/// The ray-traced laser's absorbed fraction over the run, from the power split
/// of each state read back with the beam on.
#[derive(Default)]
struct LaserAbsorption(crate::diagnostics::LaserSummary);

impl Observer for LaserAbsorption {
    fn observe(&mut self, m: &Model, st: &State, when: Moment) {
        if matches!(when, Moment::Sample { .. } | Moment::Final) {
            if let Some(b) = crate::diagnostics::LaserBalance::of(m, st) {
                self.0.add(&b);
            }
        }
    }
    fn finish(
        self: Box<Self>,
        _m: &Model,
        _last: &State,
        _end: &RunEnd,
        _out: &mut Outputs,
        found: &mut Findings,
    ) -> Result<(), String> {
        if self.0.samples > 0 {
            found.laser = Some(self.0);
        }
        Ok(())
    }
}

/// The observer that turns the device's records into `/solidification`
/// messages: at each state read back, the records whose crossing count changed;
/// at the end, R of each from every record seen, one message per sample.
#[derive(Default)]
struct SolidificationRecords {
    /// Crossings seen per particle id.
    seen: Vec<u32>,
    /// (sample time, records new at it).
    samples: Vec<(f64, Vec<solidification::Record>)>,
}

impl SolidificationRecords {
    /// The records new in `st` since the last state taken in.
    fn take(&mut self, m: &Model, st: &State) -> Vec<solidification::Record> {
        let n = st.solidification.len() / 2;
        self.seen.resize(n, 0);
        let mut new = Vec::new();
        for k in 0..n {
            let Some(r) = crate::solidification::raw_record(m, st, k) else {
                continue;
            };
            if r.crossings != self.seen[k] {
                self.seen[k] = r.crossings;
                new.push(r);
            }
        }
        new
    }
}

impl Observer for SolidificationRecords {
    fn observe(&mut self, m: &Model, st: &State, when: Moment) {
        let new = self.take(m, st);
        // The initial state's records (a resumed run's) are not new.
        if when != Moment::Initial && !new.is_empty() {
            self.samples.push((st.sim.time as f64, new));
        }
    }
    fn finish(
        self: Box<Self>,
        m: &Model,
        _last: &State,
        _end: &RunEnd,
        out: &mut Outputs,
        _found: &mut Findings,
    ) -> Result<(), String> {
        let Some(sink) = out.mcap.as_mut() else {
            return Ok(());
        };
        let sizes: Vec<usize> = self.samples.iter().map(|s| s.1.len()).collect();
        let all: Vec<solidification::Record> =
            self.samples.iter().flat_map(|s| s.1.clone()).collect();
        let mut all = solidification::with_front_speeds(m, all).into_iter();
        for ((time, _), size) in self.samples.iter().zip(sizes) {
            let mut batch = solidification::Batch {
                time: *time,
                ..solidification::Batch::default()
            };
            for r in all.by_ref().take(size) {
                batch.push(&r);
            }
            sink.message(solidification::SOLIDIFICATION_TOPIC, *time, &batch)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::DispersionWarning;

    /// A share past the bound warns the first time, then only once it has
    /// grown by half since the last warning (shares in the order sampled).
    #[test]
    fn dispersion_warns_again_only_when_the_share_grows_by_half() {
        let mut w = DispersionWarning::default();
        let warned: Vec<bool> = [0.06, 0.07, 0.089, 0.09, 0.12, 0.05, 0.135]
            .iter()
            .map(|&s| w.due(s))
            .collect();
        assert_eq!(warned, [true, false, false, true, false, false, true]);
    }
}
