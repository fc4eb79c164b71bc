//! `spatter bench stability`: a stress suite. Every case ends as survived, stopped
//! by the watchdog (with its diagnosis) or crashed. A crash — a panic, an error, a
//! non-finite value the watchdog let through, a mass that is not exactly
//! conserved, or an output that does not read back — is a bug, and the command
//! exits 1 when it finds one.
//!
//! Three groups: long runs of every validation and process scene at a coarse
//! resolution (1e5 steps, past the scene's own end, within 1e8 particle-steps),
//! parameter extremes on a few scenes, and seeded random scenes.

use super::random_scene;
use crate::checkpoint::{self, CheckpointSink};
use crate::error::{InputError, SpatterError};
use crate::model::{self, EndCondition, Model};
use crate::output::mcap_out::{McapSink, Provenance};
use crate::run::{self, BackendChoice, Loaded, Outputs, RunEnd, RunOptions};
use crate::scene::CheckKind;
use crate::state::State;
use crate::{scene, watchdog};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::Instant;

macro_rules! scene_file {
    ($path:literal) => {
        (
            concat!("scenarios/", $path, ".toml"),
            include_str!(concat!("../../scenarios/", $path, ".toml")),
        )
    };
}

/// Every validation and process scene with the `--set` overrides that make it
/// coarse (each fills its boxes with whole rows at that Δx).
const LONG_RUNS: &[((&str, &str), &[&str])] = &[
    (scene_file!("validation/adiabatic_box"), &[]),
    (scene_file!("validation/conduction_1d"), &[]),
    (scene_file!("validation/collision_2d"), &[]),
    (scene_file!("validation/column_expansion_2d"), &["dx=0.1"]),
    (scene_file!("validation/conduction_two_materials"), &[]),
    (scene_file!("validation/conduction_tables_2d"), &[]),
    (
        scene_file!("validation/couette_2d"),
        &["dx=6.666666666666667e-5"],
    ),
    (scene_file!("validation/dam_break_2d"), &["dx=0.01"]),
    (scene_file!("validation/dam_break_3d"), &["dx=0.02"]),
    // Past its window the lamella leaks through the wall on δ-SPH without
    // F22 (34)'s barrier (the scene's header): long runs take the barrier.
    (
        scene_file!("validation/drop_impact_3d"),
        &[
            "dx=4.1666667e-6",
            "simulation.barrier={ radius_dx = 0.75, stiffness = 600.0, damping = 20.0 }",
        ],
    ),
    (scene_file!("validation/dam_break_air_2d"), &["dx=0.01"]),
    (scene_file!("validation/dam_break_gate_2d"), &["dx=0.01"]),
    (scene_file!("validation/flotation_2d"), &["dx=0.02"]),
    (scene_file!("validation/free_rotation_3d"), &[]),
    (scene_file!("validation/hydrostatic_2d"), &["dx=0.025"]),
    (scene_file!("validation/hydrostatic_3d"), &["dx=0.025"]),
    (
        scene_file!("validation/hydrostatic_dfsph_2d"),
        &["dx=0.025"],
    ),
    (scene_file!("validation/jet_outflow_2d"), &[]),
    (scene_file!("validation/laplace_disc_2d"), &["dx=2e-3"]),
    (scene_file!("validation/laplace_free_disc_2d"), &["dx=2e-3"]),
    (
        scene_file!("validation/laplace_free_disc_r18_2d"),
        &["dx=0.1"],
    ),
    (
        scene_file!("validation/laplace_free_sphere_3d"),
        &["dx=4e-3"],
    ),
    (scene_file!("validation/laplace_sphere_3d"), &["dx=4e-3"]),
    (scene_file!("validation/laser_flat_plate"), &["dx=2e-5"]),
    (scene_file!("validation/laser_ray_plate"), &["dx=1e-5"]),
    (
        scene_file!("validation/laser_plate_under_gas_2d"),
        &["dx=2e-5"],
    ),
    (scene_file!("validation/melt_block_3d"), &["dx=1e-5"]),
    (scene_file!("validation/melting_grain_2d"), &[]),
    (
        scene_file!("validation/poiseuille_2d"),
        &["dx=6.666666666666667e-5"],
    ),
    (scene_file!("validation/poiseuille_dfsph_2d"), &[]),
    (scene_file!("validation/powder_bed_at_rest_2d"), &[]),
    (scene_file!("validation/recoil_layer_2d"), &[]),
    (scene_file!("validation/rosenthal_2d"), &["dx=5e-5"]),
    (scene_file!("validation/sessile_drop_2d"), &[]),
    (scene_file!("validation/sessile_free_drop_2d"), &[]),
    (scene_file!("validation/settling_disc_2d"), &["dx=0.02"]),
    (scene_file!("validation/square_drop_2d"), &["dx=4e-3"]),
    (scene_file!("validation/stefan_1d"), &["dx=2e-3"]),
    (scene_file!("validation/solidification_1d"), &[]),
    (scene_file!("validation/sinking_blob_2d"), &["dx=0.04"]),
    (scene_file!("validation/thermal_cycle_drop_2d"), &["dx=0.1"]),
    (
        scene_file!("validation/rising_amplitude_drop_2d"),
        &["dx=0.1"],
    ),
    (scene_file!("validation/thermocapillary_2d"), &[]),
    (scene_file!("validation/two_layer_2d"), &["dx=0.01"]),
    (
        scene_file!("validation/two_layer_ratio1000_2d"),
        &["dx=0.01"],
    ),
    (
        scene_file!("validation/two_layer_ratio1000_3d"),
        &["dx=0.025"],
    ),
    (scene_file!("pbf/line_melt_bare_plate"), &["dx=2e-5"]),
    (scene_file!("pbf/hatch_bare_plate_3d"), &["dx=2e-5"]),
    (scene_file!("pbf/amb2018_02_a"), &["dx=2e-5"]),
    (scene_file!("pbf/amb2018_02_b"), &["dx=2e-5"]),
    (scene_file!("pbf/amb2018_02_c"), &["dx=2e-5"]),
    (scene_file!("pbf/line_melt_coarse_2d"), &[]),
    (scene_file!("pbf/line_melt_scan_2d"), &[]),
    (scene_file!("pbf/r18_track_2d"), &[]),
    (
        scene_file!("pbf/powder_bed_line_melt_coarse_2d"),
        &["dx=1e-5"],
    ),
    (scene_file!("pbf/powder_bed_line_melt"), &["dx=1e-5"]),
    (scene_file!("pbf/point_melt_coarse_2d"), &[]),
    (scene_file!("pbf/point_melt"), &["dx=1e-5"]),
    (scene_file!("ded/laser_on_coarse_3d"), &[]),
    (scene_file!("ded/laser_off_coarse_3d"), &[]),
    (scene_file!("ded/laser_on"), &["dx=8e-6"]),
    (scene_file!("bjt/binder_1ms_coarse_2d"), &[]),
    (scene_file!("bjt/binder_10ms_coarse_2d"), &[]),
    (scene_file!("bjt/binder_50ms_coarse_2d"), &[]),
    (scene_file!("bjt/binder_1ms"), &["dx=1e-5"]),
    (scene_file!("bjt/binder_10ms"), &["dx=1e-5"]),
    (scene_file!("bjt/binder_50ms"), &["dx=1e-5"]),
    (scene_file!("spray/j22_fluent_case_2d"), &[]),
    (scene_file!("spray/j22_fluent_case_3d"), &[]),
    (scene_file!("spray/j22_spread_30um_3d"), &[]),
    (scene_file!("spray/j22_spread_45um_3d"), &[]),
    (scene_file!("spray/j22_spread_62um_3d"), &[]),
    (scene_file!("mjt/drop_on_hot_substrate_3d"), &[]),
    (scene_file!("mjt/drop_on_cold_substrate_3d"), &[]),
    (scene_file!("mjt/two_drops_3d"), &[]),
    (scene_file!("mjt/three_drops_3d"), &[]),
];

/// The long runs `--quick` keeps (one per kind of physics).
const QUICK_LONG_RUNS: &[&str] = &[
    "scenarios/validation/poiseuille_2d.toml",
    "scenarios/validation/dam_break_2d.toml",
    "scenarios/validation/two_layer_2d.toml",
    "scenarios/validation/adiabatic_box.toml",
    "scenarios/validation/laser_flat_plate.toml",
];

/// Steps of a long run, past the scene's own end: a run goes on after the event a
/// check samples (a dam break sloshes on), and that is where drift and leaks show.
const LONG_STEPS: u64 = 100_000;
/// ...but no more particle-steps than this per case (about 100 s on 2 cores), so
/// the full suite stays under an hour: the 3D scenes run fewer steps.
const LONG_PARTICLE_STEPS: f64 = 1.0e8;
const QUICK_LONG_STEPS: u64 = 1_500;
const RANDOM_SCENES: u64 = 24;
const QUICK_RANDOM_SCENES: u64 = 4;

/// What a case holds constant, and so what drift it reports.
#[derive(Clone, Copy, Default)]
struct Conserves {
    momentum: bool,
    enthalpy: bool,
}

struct Case {
    group: &'static str,
    /// Parameter family of an extreme ("density ratio"), for the envelope.
    family: String,
    /// The parameter's value in that family.
    value: f64,
    name: String,
    label: String,
    text: String,
    sets: Vec<String>,
    max_steps: u64,
    /// Run `max_steps` (within LONG_PARTICLE_STEPS) even past the scene's end.
    past_end: bool,
    conserves: Option<Conserves>,
}

#[derive(serde::Serialize, Clone)]
pub struct CaseResult {
    pub group: String,
    pub family: String,
    pub value: f64,
    pub name: String,
    /// "survived", "stopped" (by the watchdog) or "crashed".
    pub outcome: String,
    pub diagnosis: String,
    pub particles: usize,
    pub steps: u64,
    pub sim_time: f64,
    pub wall_s: f64,
    /// (M_end − M_0)/M_0 over every particle, those in the domain and those that
    /// left (exact sums of the f32 masses): must be exactly 0.
    pub mass_drift: f64,
    /// Particles that left the domain through an open side.
    pub removed: u64,
    /// |P_end − P_0| / Σ m|v| at the end, where the scene conserves momentum.
    pub momentum_drift: Option<f64>,
    /// (H_end − H_0)/|H_0|, where the scene conserves enthalpy.
    pub enthalpy_drift: Option<f64>,
    /// Deepest fluid penetration behind a wall face over the run, in Δx.
    pub wall_penetration_max_dx: f64,
    /// Scene warnings at this resolution (a box that does not fill whole rows).
    pub warnings: Vec<String>,
}

#[derive(serde::Serialize)]
pub struct StabilityReport {
    pub backend: String,
    pub quick: bool,
    pub cases: Vec<CaseResult>,
    pub envelope: Vec<String>,
}

pub struct Options<'a> {
    pub backend: BackendChoice,
    pub quick: bool,
    pub json: Option<&'a str>,
    pub seed: u64,
    /// Run only the cases whose group, parameter family or name contains this.
    pub only: Option<&'a str>,
}

/// The cases `--only` keeps: those whose group, family or name contains it
/// (all without it); none is an input error that lists what there is.
fn select(mut cases: Vec<Case>, only: Option<&str>) -> Result<Vec<Case>, SpatterError> {
    let Some(only) = only else {
        return Ok(cases);
    };
    let mut kinds: Vec<&str> = Vec::new();
    for c in &cases {
        for k in [c.group, c.family.as_str()] {
            if !k.is_empty() && !kinds.contains(&k) {
                kinds.push(k);
            }
        }
    }
    let kinds = kinds.join(", ");
    cases.retain(|c| c.group.contains(only) || c.family.contains(only) || c.name.contains(only));
    if cases.is_empty() {
        return Err(InputError::new(
            "bench stability",
            "--only",
            format!("no case matches `{only}` (groups and families: {kinds}; or part of a scene's name)"),
        )
        .into());
    }
    Ok(cases)
}

fn long_runs(quick: bool) -> Vec<Case> {
    LONG_RUNS
        .iter()
        .filter(|((label, _), _)| !quick || QUICK_LONG_RUNS.contains(label))
        .map(|((label, text), sets)| Case {
            group: "long run",
            family: String::new(),
            value: f64::NAN,
            name: label
                .trim_start_matches("scenarios/")
                .trim_end_matches(".toml")
                .into(),
            label: label.to_string(),
            text: text.to_string(),
            sets: sets.iter().map(|s| s.to_string()).collect(),
            max_steps: if quick { QUICK_LONG_STEPS } else { LONG_STEPS },
            past_end: true,
            conserves: None,
        })
        .collect()
}

/// One case of a parameter family on a scene.
fn extreme(
    (label, text): (&str, &str),
    family: &str,
    value: f64,
    sets: Vec<String>,
    max_steps: u64,
) -> Case {
    let short = label
        .trim_start_matches("scenarios/")
        .trim_end_matches(".toml");
    Case {
        group: "extreme",
        family: family.into(),
        value,
        name: format!("{short}, {family} {value}"),
        label: label.into(),
        text: text.into(),
        sets,
        max_steps,
        past_end: false,
        conserves: None,
    }
}

fn extremes(quick: bool) -> Result<Vec<Case>, SpatterError> {
    let two_layer = scene_file!("validation/two_layer_2d");
    let dam = scene_file!("validation/dam_break_2d");
    let melt = scene_file!("pbf/line_melt_bare_plate");
    let steps = if quick { 400 } else { LONG_STEPS };
    let coarse = |d: &str| vec![format!("dx={d}")];
    let with = |mut v: Vec<String>, s: String| {
        v.push(s);
        v
    };
    let mut cases = Vec::new();
    // Liquid 1000 kg/m³ over gas of density 1000/ratio (gas sound speed from its
    // reference pressure).
    let ratios: &[f64] = if quick {
        &[1000.0]
    } else {
        &[10.0, 100.0, 1000.0]
    };
    for &r in ratios {
        let sets = with(
            coarse("0.01"),
            format!("materials.gas.density={}", 1000.0 / r),
        );
        cases.push(extreme(two_layer, "density ratio", r, sets, steps));
    }
    // Liquid viscosity 0.1 Pa s over gas of 0.1/ratio.
    let ratios: &[f64] = if quick { &[100.0] } else { &[1.0, 10.0, 100.0] };
    for &r in ratios {
        let sets = with(
            coarse("0.01"),
            format!("materials.gas.viscosity={:e}", 0.1 / r),
        );
        cases.push(extreme(two_layer, "viscosity ratio", r, sets, steps));
    }
    let powers: &[f64] = if quick {
        &[400.0]
    } else {
        &[50.0, 100.0, 200.0, 400.0]
    };
    for &w in powers {
        let sets = with(coarse("2e-5"), format!("laser.power={w}"));
        cases.push(extreme(melt, "laser power (W)", w, sets, steps));
    }
    // Fixed Δt as a fraction of the F22 (42) limit at that resolution.
    let limit = dt_limit(dam, &coarse("0.01"))?;
    let fractions: &[f64] = if quick {
        &[1.0]
    } else {
        &[0.25, 0.5, 0.75, 1.0]
    };
    for &f in fractions {
        let sets = with(coarse("0.01"), format!("run.dt={:e}", f * limit));
        cases.push(extreme(dam, "fixed dt / limit", f, sets, steps));
    }
    let jitters: &[f64] = if quick { &[0.3] } else { &[0.0, 0.1, 0.2, 0.3] };
    for &j in jitters {
        let sets = with(coarse("0.01"), format!("jitter={j}"));
        cases.push(extreme(dam, "jitter / dx", j, sets, steps));
    }
    // J22's droplet on DFSPH (2D) hitting the cold wall at 1 to 200 m/s.
    let speeds: &[f64] = if quick {
        &[200.0]
    } else {
        &[1.0, 10.0, 50.0, 200.0]
    };
    for &v in speeds {
        let (label, text) = impact_scene(v);
        cases.push(extreme(
            (label, &text),
            "impact speed (m/s)",
            v,
            Vec::new(),
            steps,
        ));
    }
    Ok(cases)
}

/// scenarios/spray/j22_fluent_case_2d with the droplet 2 µm above the wall at
/// `speed`, run to 5 D0 / speed (the spread and the first rebound).
fn impact_scene(speed: f64) -> (&'static str, String) {
    let (label, text) = scene_file!("spray/j22_fluent_case_2d");
    let swap = |t: &str, from: &str, to: &str| {
        assert!(t.contains(from), "{label} no longer holds `{from}`");
        t.replace(from, to)
    };
    let text = swap(
        text,
        "velocity = [0.0, -200.0]",
        &format!("velocity = [0.0, {:e}]", -speed),
    );
    let text = swap(&text, "center = [0.0, 1.31e-4]", "center = [0.0, 3.3e-5]");
    let text = swap(
        &text,
        "end_time = 2.0e-6",
        &format!("end_time = {:e}", 5.0 * 62.0e-6 / speed),
    );
    let text = swap(
        &text,
        "output_interval = 5.0e-8",
        &format!("output_interval = {:e}", 0.25 * 62.0e-6 / speed),
    );
    // J22's 10 ns CFL max is for 200 m/s: scaled, every speed takes the same
    // steps per D0/V.
    let text = swap(
        &text,
        "max_dt = 1.0e-8",
        &format!("max_dt = {:e}", 1.0e-8 * 200.0 / speed),
    );
    (label, text)
}

fn dt_limit((label, text): (&str, &str), sets: &[String]) -> Result<f64, SpatterError> {
    let (sc, resolved) = scene::parse_str(label, text, sets)?;
    Ok(model::build(label, &sc, &resolved)?.limits.min().0)
}

fn random_cases(quick: bool, seed: u64) -> Vec<Case> {
    let n = if quick {
        QUICK_RANDOM_SCENES
    } else {
        RANDOM_SCENES
    };
    (0..n)
        .map(|k| {
            let s = random_scene::generate(seed.wrapping_add(k));
            Case {
                group: "random",
                family: String::new(),
                value: f64::NAN,
                name: format!("seed {} ({})", seed.wrapping_add(k), s.summary),
                label: format!("random scene, seed {}", seed.wrapping_add(k)),
                text: s.toml,
                sets: Vec::new(),
                max_steps: if quick { 300 } else { 3_000 },
                past_end: false,
                conserves: Some(Conserves {
                    momentum: s.conserves_momentum,
                    enthalpy: false,
                }),
            }
        })
        .collect()
}

fn load(c: &Case) -> Result<Loaded, SpatterError> {
    let l = run::load_str(&c.label, &c.text, &c.sets)?;
    if l.model.output_interval.is_finite() {
        return Ok(l);
    }
    // A scene that ends after a step count has no output interval: give it ten
    // frames (and watchdog scans) over the case's budget.
    let dt = l.model.fixed_dt.unwrap_or(l.model.limits.min().0);
    let mut sets = c.sets.clone();
    sets.push(format!(
        "run.output_interval={:e}",
        dt * (c.max_steps as f64 / 10.0).max(1.0)
    ));
    Ok(run::load_str(&c.label, &c.text, &sets)?)
}

/// The scene's own end, or `max` steps if that comes first (judged by the initial Δt).
fn end_of(m: &Model, max: u64) -> EndCondition {
    match m.end {
        EndCondition::Steps(n) => EndCondition::Steps(n.min(max)),
        EndCondition::Time(t) => {
            let dt = m.fixed_dt.unwrap_or(m.limits.min().0);
            if t / dt < max as f64 {
                EndCondition::Time(t)
            } else {
                EndCondition::Steps(max)
            }
        }
    }
}

fn momentum(st: &State) -> ([f64; 3], f64) {
    let mut p = [0.0; 3];
    let mut scale = 0.0;
    for (v, &m) in st.vel.iter().zip(&st.mass) {
        for a in 0..3 {
            p[a] += m as f64 * v[a] as f64;
        }
        scale += m as f64 * (v[0] as f64).hypot(v[1] as f64).hypot(v[2] as f64);
    }
    (p, scale)
}

/// Σ m h over conducting particles (a Dirichlet wall's heat.x is its temperature).
fn enthalpy(m: &Model, st: &State) -> f64 {
    (0..st.len())
        .filter(|&i| m.phases[st.phase[i] as usize].conducts())
        .map(|i| st.heat[i][0] as f64 * st.mass[i] as f64)
        .sum()
}

/// What a case holds constant when its definition does not say: enthalpy in an
/// adiabatic-box check, momentum never (walls and gravity act on the fluid).
fn conserves(c: &Case, m: &Model) -> Conserves {
    c.conserves.unwrap_or(Conserves {
        momentum: false,
        enthalpy: m.check.as_ref().map(|k| k.kind()) == Some(CheckKind::Adiabatic),
    })
}

fn same_words(a: &State, b: &State) -> bool {
    let (fa, fb) = (a.fields(), b.fields());
    fa.len() == fb.len() && fa.iter().zip(&fb).all(|(x, y)| x.words == y.words) && a.sim == b.sim
}

/// The run's MCAP must be complete with at least one frame, and its last
/// checkpoint must load back to the final state.
fn read_back(dir: &std::path::Path, report: &run::RunReport) -> Result<(), String> {
    let mcap = dir.join("run.mcap");
    let ins = crate::inspect::inspect(&mcap.to_string_lossy()).map_err(|e| e.to_string())?;
    let frames = ins.channels.get("/particles").map_or(0, |c| c.0);
    if !ins.complete || frames == 0 {
        return Err(format!(
            "MCAP incomplete or without frames ({frames} frames)"
        ));
    }
    let ck = report
        .last_checkpoint
        .as_ref()
        .ok_or("no checkpoint written")?;
    let back = checkpoint::load(&ck.to_string_lossy()).map_err(|e| e.to_string())?;
    let expected = match &report.end {
        // An instability stop checkpoints the last good state, not the bad one.
        RunEnd::Unstable(_) => None,
        _ => Some(&report.final_state),
    };
    if let Some(st) = expected {
        if !same_words(&back.state, st) {
            return Err("checkpoint does not read back to the final state".into());
        }
    }
    Ok(())
}

fn outputs(dir: &std::path::Path, l: &Loaded, backend: &str) -> Result<Outputs, String> {
    let prov = Provenance {
        backend,
        command: "spatter bench stability",
    };
    let mut o = Outputs::default();
    o.backend = backend.into();
    // Checkpoints at the end only (and at an instability stop).
    o.checkpoint_every = Some(f64::MAX);
    o.mcap = Some(McapSink::create(
        &dir.join("run.mcap").to_string_lossy(),
        &l.model,
        &prov,
        &crate::diagnostics::topics(&l.model),
    )?);
    o.checkpoints = Some(CheckpointSink::create(&dir.join("ckpt").to_string_lossy())?);
    Ok(o)
}

fn run_case(c: &Case, dir: &std::path::Path, choice: BackendChoice) -> CaseResult {
    let mut r = CaseResult {
        group: c.group.into(),
        family: c.family.clone(),
        value: c.value,
        name: c.name.clone(),
        outcome: "crashed".into(),
        diagnosis: String::new(),
        particles: 0,
        steps: 0,
        sim_time: 0.0,
        wall_s: 0.0,
        mass_drift: f64::NAN,
        removed: 0,
        momentum_drift: None,
        enthalpy_drift: None,
        wall_penetration_max_dx: 0.0,
        warnings: Vec::new(),
    };
    let t0 = Instant::now();
    let outcome = catch_unwind(AssertUnwindSafe(|| run_and_judge(c, choice, dir, &mut r)));
    r.wall_s = t0.elapsed().as_secs_f64();
    match outcome {
        Ok(Ok(())) => {}
        Ok(Err(e)) => {
            r.outcome = "crashed".into();
            r.diagnosis = e;
        }
        Err(p) => {
            r.outcome = "crashed".into();
            r.diagnosis = format!(
                "panic: {}",
                p.downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default()
            );
        }
    }
    r
}

fn run_and_judge(
    c: &Case,
    choice: BackendChoice,
    dir: &std::path::Path,
    r: &mut CaseResult,
) -> Result<(), String> {
    let l = load(c).map_err(|e| format!("scene rejected: {e}"))?;
    r.warnings = l.model.warnings.clone();
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    let mut backend = run::make_backend(choice, &l, false).map_err(|e| e.to_string())?;
    let mut out = outputs(dir, &l, &backend.describe())?;
    let end = match c.past_end {
        true => {
            let budget = (LONG_PARTICLE_STEPS / l.state.len().max(1) as f64) as u64;
            EndCondition::Steps(c.max_steps.min(budget).max(1))
        }
        false => end_of(&l.model, c.max_steps),
    };
    let opts = RunOptions {
        end,
        quiet: true,
        resumed: false,
    };
    let report = run::run(&l, backend.as_mut(), &opts, &mut out).map_err(|e| e.to_string())?;
    let (st0, st1) = (&l.state, &report.final_state);
    r.particles = st1.len();
    r.steps = report.steps;
    r.sim_time = report.sim_time;
    let balance = crate::outflow::MassBalance::of(st0, st1);
    let m0 = balance.initial.value();
    r.mass_drift = (balance.domain.value() + balance.removed.value() - m0) / m0;
    r.removed = st1.sim.removed as u64;
    r.wall_penetration_max_dx = report.leakage.deepest_dx;
    let keeps = conserves(c, &l.model);
    if keeps.momentum {
        let ((p0, _), (p1, scale)) = (momentum(st0), momentum(st1));
        let d =
            ((p1[0] - p0[0]).powi(2) + (p1[1] - p0[1]).powi(2) + (p1[2] - p0[2]).powi(2)).sqrt();
        r.momentum_drift = Some(if scale > 0.0 { d / scale } else { d });
    }
    if keeps.enthalpy && !st0.heat.is_empty() {
        let h0 = enthalpy(&l.model, st0);
        r.enthalpy_drift = Some((enthalpy(&l.model, st1) - h0) / h0.abs().max(f64::MIN_POSITIVE));
    }
    read_back(dir, &report)?;
    let _ = std::fs::remove_dir_all(dir);
    match &report.end {
        RunEnd::Unstable(t) => {
            r.outcome = "stopped".into();
            r.diagnosis = t.message();
        }
        _ => {
            // A completed run whose state the watchdog would refuse let a bad value through.
            if let Some(t) = watchdog::scan(&l.model, st1) {
                return Err(format!("escaped the watchdog: {}", t.message()));
            }
            r.outcome = "survived".into();
            if let Some(t) = emptied_at(&l.model, st0, st1) {
                r.diagnosis = format!(
                    "every fluid particle had left the domain by t = {t:.4e} s: the steps after measured nothing"
                );
            }
        }
    }
    if !balance.exact() {
        return Err(format!("mass not conserved: {}", balance.summary()));
    }
    Ok(())
}

/// When a run that started with fluid ends with none in the domain: the time
/// its last fluid particle left (a removed particle's pos.w).
fn emptied_at(m: &Model, st0: &State, st1: &State) -> Option<f64> {
    let fluid =
        |st: &State, i: usize| m.phases[st.phase[i] as usize].kind != scene::PhaseKind::Wall;
    let had = (0..st0.active()).any(|i| fluid(st0, i));
    if !had || (0..st1.active()).any(|i| fluid(st1, i)) {
        return None;
    }
    (st1.active()..st1.len())
        .filter(|&i| fluid(st1, i))
        .map(|i| st1.pos[i][3] as f64)
        .reduce(f64::max)
}

/// Per parameter family: the values that survived and those that stopped.
fn envelope(cases: &[CaseResult]) -> Vec<String> {
    let mut families: Vec<&str> = Vec::new();
    for c in cases.iter().filter(|c| !c.family.is_empty()) {
        if !families.contains(&c.family.as_str()) {
            families.push(&c.family);
        }
    }
    let list = |f: &str, outcome: &str| -> String {
        let v: Vec<String> = cases
            .iter()
            .filter(|c| c.family == f && c.outcome == outcome)
            .map(|c| format!("{}", c.value))
            .collect();
        if v.is_empty() {
            "none".into()
        } else {
            v.join(", ")
        }
    };
    let mut lines: Vec<String> = families
        .iter()
        .map(|f| {
            format!(
                "{f}: survived {}; stopped {}; crashed {}",
                list(f, "survived"),
                list(f, "stopped"),
                list(f, "crashed")
            )
        })
        .collect();
    for (group, plural) in [("long run", "long runs"), ("random", "random scenes")] {
        let mine: Vec<&CaseResult> = cases.iter().filter(|c| c.group == group).collect();
        if mine.is_empty() {
            continue;
        }
        let count = |o: &str| mine.iter().filter(|c| c.outcome == o).count();
        lines.push(format!(
            "{plural}: {} survived, {} stopped, {} crashed",
            count("survived"),
            count("stopped"),
            count("crashed")
        ));
    }
    lines
}

fn print_case(c: &CaseResult) {
    let drift = |d: Option<f64>| d.map_or("-".into(), |v| format!("{v:.1e}"));
    println!(
        "  {:<9} {:<64} {:<9} {:>6} particles {:>7} steps  t {:.3e} s  {:>7.2} s  mass {:.0e}  momentum {}  enthalpy {}  leak {:.2} dx  left {}",
        c.group,
        c.name,
        c.outcome,
        c.particles,
        c.steps,
        c.sim_time,
        c.wall_s,
        c.mass_drift,
        drift(c.momentum_drift),
        drift(c.enthalpy_drift),
        c.wall_penetration_max_dx,
        c.removed
    );
    if !c.diagnosis.is_empty() {
        println!("      {}", c.diagnosis);
    }
    for w in &c.warnings {
        println!("      warning: {w}");
    }
}

/// Runs the suite; Ok(true) when nothing crashed.
pub fn stability(opts: &Options) -> Result<bool, SpatterError> {
    let choice = super::resolve_backend(opts.backend);
    let mut cases = long_runs(opts.quick);
    cases.extend(extremes(opts.quick)?);
    cases.extend(random_cases(opts.quick, opts.seed));
    let cases = select(cases, opts.only)?;
    let work = std::env::temp_dir().join(format!("spatter-stability-{}", std::process::id()));
    println!(
        "bench stability: {} cases{} (outputs written to and read back from {})",
        cases.len(),
        if opts.quick { ", quick" } else { "" },
        work.display()
    );
    let mut results = Vec::new();
    for (k, c) in cases.iter().enumerate() {
        let r = run_case(c, &work.join(format!("case{k}")), choice);
        print_case(&r);
        results.push(r);
    }
    let _ = std::fs::remove_dir_all(&work);
    let backend = match run::make_backend(choice, &load(&cases[0])?, false) {
        Ok(b) => b.describe(),
        Err(_) => format!("{choice:?}"),
    };
    println!("backend: {backend}");
    let envelope = envelope(&results);
    println!("stable envelope:");
    for line in &envelope {
        println!("  {line}");
    }
    let crashed = results.iter().filter(|c| c.outcome == "crashed").count();
    let report = StabilityReport {
        backend,
        quick: opts.quick,
        cases: results,
        envelope,
    };
    if let Some(path) = opts.json {
        super::write_json(path, &report)?;
    }
    if crashed > 0 {
        println!("{crashed} case(s) crashed: each is a bug");
    }
    Ok(crashed == 0)
}

#[cfg(test)]
mod every_scene {
    use super::LONG_RUNS;

    /// "Long runs of every validation and process scene": each scene file under
    /// scenarios/validation, pbf, spray, mjt, ded and bjt has a LONG_RUNS row.
    #[test]
    fn every_validation_and_process_scene_has_a_long_run() {
        for dir in ["validation", "pbf", "spray", "mjt", "ded", "bjt"] {
            let path = format!("{}/scenarios/{dir}", env!("CARGO_MANIFEST_DIR"));
            for entry in std::fs::read_dir(&path).unwrap() {
                let name = entry.unwrap().file_name().into_string().unwrap();
                let label = format!("scenarios/{dir}/{name}");
                assert!(
                    LONG_RUNS.iter().any(|((l, _), _)| *l == label),
                    "{label} has no LONG_RUNS row"
                );
            }
        }
    }
}

#[cfg(test)]
mod emptied {
    use super::emptied_at;

    /// A run whose fluid has all left says when the last of it went; one with
    /// a fluid particle still in the domain says nothing.
    #[test]
    fn the_last_departure_of_a_box_left_empty() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/validation/laplace_free_disc_2d.toml"
        );
        let l = crate::load::load(path, &[]).unwrap();
        let (m, st0) = (&l.model, &l.state);
        let mut st1 = st0.clone();
        st1.sim.removed = st1.len() as u32 - 1;
        assert_eq!(emptied_at(m, st0, &st1), None, "one particle still in");
        st1.sim.removed = st1.len() as u32;
        for (k, p) in st1.pos.iter_mut().enumerate() {
            p[3] = 0.5 + k as f32 * 1e-3;
        }
        let last = 0.5 + (st1.len() - 1) as f32 * 1e-3;
        assert_eq!(emptied_at(m, st0, &st1), Some(last as f64));
    }
}
