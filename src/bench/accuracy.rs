//! `spatter bench accuracy`: work–precision of the validation scenes. Each scene
//! with a reference solution runs at several resolutions (Δx = L/n over a table of
//! cell counts n that fill its boxes exactly) and with each kernel; every run gives
//! its check's error, wall time, steps, particle-steps/s and memory. Per scene and
//! kernel the observed convergence order (least-squares slope of log error against
//! log Δx) is printed beside the order the method should reach.

use super::plot::{self, Figure, Guide, Series};
use crate::error::{InputError, SpatterError};
use crate::run::{self, BackendChoice, Loaded, Outputs, RunEnd, RunOptions};
use crate::scene::KernelKind;
use crate::setup;
use std::path::Path;

/// One scene's resolution sweep.
pub struct Sweep {
    /// The scene's file stem, with `@variant` when `sets` change its formulation.
    pub name: &'static str,
    text: &'static str,
    /// `--set` overrides of the variant (another formulation side by side).
    sets: &'static [&'static str],
    /// Reference length L (m): the runs use Δx = L/n.
    length: f64,
    /// Cell counts n across L, coarse to fine; each fills the scene's boxes with
    /// whole rows (a fill that does not is reported as a warning on the run).
    cells: &'static [u32],
    /// The order the error should fall with Δx; None where the metric is a
    /// conservation error that sits at round-off at every resolution.
    pub expected_order: Option<f64>,
    /// Why that order (printed beside the fit).
    why: &'static str,
    /// Part of `--quick` (its two coarsest resolutions, quintic kernel only).
    quick: bool,
}

macro_rules! scene_text {
    ($name:literal) => {
        include_str!(concat!("../../scenarios/validation/", $name, ".toml"))
    };
}

/// With h/Δx fixed, SPH sums are 2nd order in h only until the kernel's own
/// discretisation error takes over (Quinlan, Basa & Lastiwka 2006): a floor that
/// depends on the kernel and h/Δx, not on Δx.
const SECOND_ORDER: &str =
    "2nd order in h at fixed h/dx, down to the kernel's discretisation floor";

/// The scenes with a reference solution and their sweeps.
pub const SWEEPS: &[Sweep] = &[
    Sweep {
        name: "poiseuille_2d",
        text: scene_text!("poiseuille_2d"),
        sets: &[],
        length: 1.0e-3,
        cells: &[15, 20, 25, 30, 40],
        expected_order: Some(2.0),
        why: SECOND_ORDER,
        quick: true,
    },
    Sweep {
        name: "couette_2d",
        text: scene_text!("couette_2d"),
        sets: &[],
        length: 1.0e-3,
        cells: &[15, 20, 25, 30, 40],
        expected_order: Some(2.0),
        why: SECOND_ORDER,
        quick: true,
    },
    Sweep {
        name: "hydrostatic_2d",
        text: scene_text!("hydrostatic_2d"),
        sets: &[],
        length: 0.1,
        cells: &[4, 5, 8, 10],
        expected_order: Some(1.0),
        why: "the wall layer and the free surface truncate the kernel: 1st order there",
        quick: false,
    },
    Sweep {
        name: "hydrostatic_2d@dfsph",
        text: scene_text!("hydrostatic_2d"),
        sets: &[
            "simulation.formulation=\"dfsph\"",
            "simulation.pressure_floor=false",
            "simulation.initial_pressure=\"zero\"",
            "simulation.dfsph={ density_tolerance = 5e-4 }",
            "run.max_dt=2.5e-3",
        ],
        length: 0.1,
        cells: &[4, 5, 8, 10],
        expected_order: Some(1.0),
        why: "the column on DFSPH (hydrostatic_dfsph_2d's tolerance and step cap): the same truncation, and the solve's tolerance",
        quick: false,
    },
    Sweep {
        name: "poiseuille_dfsph_2d",
        text: scene_text!("poiseuille_dfsph_2d"),
        sets: &[],
        length: 1.0e-3,
        cells: &[15, 20, 25, 30, 40],
        expected_order: Some(2.0),
        why: "DFSPH's implicit viscosity at 100x the explicit step (steady state: no time error)",
        quick: false,
    },
    Sweep {
        name: "dam_break_2d",
        text: scene_text!("dam_break_2d"),
        sets: &[],
        length: 0.1,
        cells: &[10, 20, 40],
        expected_order: None,
        why: "against an experiment: the front error does not vanish with dx",
        quick: false,
    },
    Sweep {
        name: "dam_break_2d@dfsph",
        text: scene_text!("dam_break_2d"),
        sets: &[
            "simulation.formulation=\"dfsph\"",
            "simulation.pressure_floor=false",
            "simulation.initial_pressure=\"zero\"",
        ],
        length: 0.1,
        cells: &[10, 20, 40],
        expected_order: None,
        why: "the same on DFSPH: no sound speed, the flow's CFL step",
        quick: false,
    },
    Sweep {
        name: "drop_impact_3d",
        text: scene_text!("drop_impact_3d"),
        sets: &[],
        length: 5.0e-5,
        cells: &[12, 16, 20, 24],
        expected_order: None,
        why: "against a measured peak (0.8 rho V^2 D^2) with its scatter: no order",
        quick: false,
    },
    Sweep {
        name: "drop_impact_3d@dfsph",
        text: scene_text!("drop_impact_3d"),
        sets: &[
            "simulation.formulation=\"dfsph\"",
            "simulation.initial_pressure=\"zero\"",
        ],
        length: 5.0e-5,
        cells: &[12, 16, 20, 24],
        expected_order: None,
        why: "the same impact on DFSPH: no sound speed, the flow's CFL step",
        quick: false,
    },
    Sweep {
        name: "hydrostatic_3d",
        text: scene_text!("hydrostatic_3d"),
        sets: &[],
        length: 0.1,
        cells: &[4, 5, 8],
        expected_order: Some(1.0),
        why: "the wall layer and the free surface truncate the kernel: 1st order there",
        quick: false,
    },
    Sweep {
        name: "two_layer_2d",
        text: scene_text!("two_layer_2d"),
        sets: &[],
        length: 0.1,
        cells: &[10, 16, 20, 25],
        expected_order: Some(1.0),
        why: "the density jump is smeared over one kernel support: 1st order at the interface",
        quick: false,
    },
    Sweep {
        name: "laplace_disc_2d",
        text: scene_text!("laplace_disc_2d"),
        sets: &[],
        // The disc's radius: R = 10, 20, 40 Δx.
        length: 0.02,
        cells: &[10, 20, 40],
        expected_order: Some(1.0),
        why: "the CSF force sits on the first liquid row, whose curvature and surface delta are O(dx/R)",
        quick: false,
    },
    Sweep {
        name: "laplace_free_disc_2d",
        text: scene_text!("laplace_free_disc_2d"),
        sets: &[],
        // The disc's radius: R = 10, 20, 40 Δx.
        length: 0.02,
        cells: &[10, 20, 40],
        expected_order: Some(1.0),
        why: "R18's free-surface CSF on δ-SPH (the scene's formulation): 1st order like the gas form; measured not monotonic (+23.7 / -3.0 / +7.2%)",
        quick: false,
    },
    Sweep {
        name: "laplace_free_sphere_3d",
        text: scene_text!("laplace_free_sphere_3d"),
        sets: &[],
        // The sphere's radius: R = 5, 8, 10 Δx (10 Δx: 4 224 particles, 28–49 s).
        length: 0.02,
        cells: &[5, 8, 10],
        expected_order: Some(1.0),
        why: "the free-surface CSF on δ-SPH in 3D: 1st order like the 2D disc",
        quick: false,
    },
    Sweep {
        name: "thermal_cycle_drop_2d",
        text: scene_text!("thermal_cycle_drop_2d"),
        sets: &[],
        // The drop's radius R = 1 m: 10, 15, 20 Δx (20 Δx: R18's, 102 s).
        length: 1.0,
        cells: &[10, 15, 20],
        expected_order: None,
        why: "R18 Test 1: the start's acoustic ringing (about u/c) sets the worst error, not the resolution",
        quick: false,
    },
    Sweep {
        name: "rising_amplitude_drop_2d",
        text: scene_text!("rising_amplitude_drop_2d"),
        sets: &[],
        // The drop's radius R = 1 m: 10, 15, 20 Δx (20 Δx: 249 s).
        length: 1.0,
        cells: &[10, 15, 20],
        expected_order: None,
        why: "R18 Test 2: where the drop splits is set by the expanded rim's neighbours (h), not by the resolution",
        quick: false,
    },
    Sweep {
        name: "column_expansion_2d",
        text: scene_text!("column_expansion_2d"),
        sets: &[],
        // L0 = 1 m: 10, 15, 20 Δx (20 Δx: R18's, 81 s).
        length: 1.0,
        cells: &[10, 15, 20],
        expected_order: Some(1.0),
        why: "R18 Test 3: the fluids' heights carry their free surface's and interface's first-order error",
        quick: false,
    },
    Sweep {
        name: "sinking_blob_2d",
        text: scene_text!("sinking_blob_2d"),
        sets: &[],
        // The 1 m pool: dx = 40, 25, 20 mm (the blob's radius 2.5, 4, 5 dx).
        length: 1.0,
        cells: &[25, 40, 50],
        expected_order: None,
        why: "R18 Test 4: a noise level, read against the same sweep on summation density (@wcsph)",
        quick: false,
    },
    Sweep {
        name: "sinking_blob_2d@wcsph",
        text: scene_text!("sinking_blob_2d"),
        sets: &["simulation.formulation=\"wcsph\"", "simulation.pressure_floor=true"],
        length: 1.0,
        cells: &[25, 40, 50],
        expected_order: None,
        why: "R18 Test 4 on summation density: the noise R18 shows for standard WCSPH",
        quick: false,
    },
    Sweep {
        name: "laplace_free_disc_2d@wcsph",
        text: scene_text!("laplace_free_disc_2d"),
        sets: &["simulation.formulation=\"wcsph\"", "simulation.pressure_floor=true"],
        length: 0.02,
        cells: &[10, 20, 40],
        expected_order: Some(1.0),
        why: "the same disc on summation density: the surface row compacts and the error grows",
        quick: false,
    },
    Sweep {
        name: "square_drop_2d",
        text: scene_text!("square_drop_2d"),
        sets: &[],
        // dx = 4, 2, 1 mm (divisors of the 0.08 m period): the square's side is
        // 8, 16, 31 particles.
        length: 0.04,
        cells: &[10, 20, 40],
        expected_order: None,
        why: "a shape check: the outline spread is a few tenths of dx at every resolution (lattice noise); the capillary number is the figure to watch",
        quick: false,
    },
    Sweep {
        name: "thermocapillary_2d",
        text: scene_text!("thermocapillary_2d"),
        sets: &[],
        // The liquid layer's thickness a: 10, 20, 40 Δx (the 1 mm period 40,
        // 80, 160 Δx).
        length: 2.5e-4,
        cells: &[10, 20, 40],
        expected_order: Some(1.0),
        why: "the Marangoni stress acts as a body force over the liquid side's surface delta, about a dx thick: 1st order",
        quick: false,
    },
    Sweep {
        name: "conduction_1d",
        text: scene_text!("conduction_1d"),
        sets: &[],
        length: 0.01,
        // Periodic in x: at least three quintic supports (9 Δx) across.
        cells: &[10, 12, 14, 16],
        expected_order: Some(2.0),
        why: SECOND_ORDER,
        quick: true,
    },
    Sweep {
        name: "conduction_two_materials",
        text: scene_text!("conduction_two_materials"),
        sets: &[],
        length: 0.02,
        // Periodic in x (at least 9 Δx across); n even puts the material jump on a row gap.
        cells: &[10, 12, 14, 16],
        expected_order: Some(2.0),
        why: "harmonic-mean conductivity keeps the flux across the material jump 2nd order",
        quick: false,
    },
    Sweep {
        name: "stefan_1d",
        text: scene_text!("stefan_1d"),
        sets: &[],
        length: 0.04,
        cells: &[20, 25, 32, 40, 50],
        expected_order: Some(1.0),
        why: "the front crosses one particle at a time: 1st order in its position",
        quick: true,
    },
    Sweep {
        name: "solidification_1d",
        text: scene_text!("solidification_1d"),
        sets: &[],
        length: 0.01,
        // Periodic in x: at least 9 Δx across.
        cells: &[10, 16, 20],
        expected_order: Some(1.0),
        why: "R is a gradient of crossing times that advance one particle row at a time",
        quick: false,
    },
    Sweep {
        name: "rosenthal_2d",
        text: scene_text!("rosenthal_2d"),
        sets: &[],
        length: 2.0e-4,
        cells: &[4, 5, 8, 10],
        expected_order: Some(2.0),
        why: SECOND_ORDER,
        quick: false,
    },
    Sweep {
        name: "laser_flat_plate",
        text: scene_text!("laser_flat_plate"),
        sets: &[],
        length: 2.0e-4,
        cells: &[10, 16, 20, 25],
        expected_order: None,
        why: "energy balance: conserved to f32 round-off at every resolution",
        quick: true,
    },
    Sweep {
        name: "recoil_layer_2d",
        text: scene_text!("recoil_layer_2d"),
        sets: &[],
        // The hot half of the layer: 5, 10, 20 rows.
        length: 5.0e-5,
        cells: &[5, 10, 20],
        expected_order: None,
        why: "momentum balance: the error is the surface delta's normalisation on the compressed surface rows, not a truncation order",
        quick: false,
    },
];

const KERNELS: [KernelKind; 3] = [
    KernelKind::Quintic,
    KernelKind::WendlandC2,
    KernelKind::Cubic,
];

fn kernel_key(k: KernelKind) -> &'static str {
    match k {
        KernelKind::Quintic => "quintic",
        KernelKind::WendlandC2 => "wendland_c2",
        KernelKind::Cubic => "cubic",
    }
}

#[derive(serde::Serialize, Clone)]
pub struct AccuracyRun {
    pub scene: String,
    pub kernel: String,
    pub cells: u32,
    pub dx: f64,
    pub particles: usize,
    pub steps: u64,
    pub wall_s: f64,
    pub particle_steps_per_s: f64,
    /// Memory the scene's particle state takes (setup::memory_estimate).
    pub state_bytes: f64,
    /// Peak resident memory of the process during this run (Linux VmHWM after a reset).
    pub peak_rss_bytes: Option<u64>,
    pub metric: String,
    pub error: f64,
    pub tolerance: f64,
    pub pass: bool,
    /// "completed", or the watchdog's diagnosis.
    pub end: String,
    /// Scene warnings at this resolution (e.g. a box that does not fill whole rows).
    pub warnings: Vec<String>,
}

#[derive(serde::Serialize, Clone)]
pub struct OrderFit {
    pub scene: String,
    pub kernel: String,
    /// Least-squares slope of ln(error) against ln(Δx); None with fewer than two
    /// runs with a positive finite error.
    pub observed_order: Option<f64>,
    pub expected_order: Option<f64>,
    pub why: String,
    /// The error falls from each resolution to the next finer one.
    pub monotone: bool,
}

#[derive(serde::Serialize)]
pub struct AccuracyReport {
    pub backend: String,
    pub quick: bool,
    pub runs: Vec<AccuracyRun>,
    pub orders: Vec<OrderFit>,
}

pub struct Options<'a> {
    pub scenes: &'a [String],
    pub backend: BackendChoice,
    pub quick: bool,
    pub json: Option<&'a str>,
    pub plots: Option<&'a str>,
}

/// The sweeps `--scenes` names (all, or the quick ones with `--quick`).
fn chosen(opts: &Options) -> Result<Vec<&'static Sweep>, SpatterError> {
    if opts.scenes.is_empty() {
        return Ok(SWEEPS.iter().filter(|s| s.quick || !opts.quick).collect());
    }
    opts.scenes
        .iter()
        .map(|n| {
            SWEEPS.iter().find(|s| s.name == n).ok_or_else(|| {
                let known: Vec<&str> = SWEEPS.iter().map(|s| s.name).collect();
                InputError::new(
                    "bench accuracy",
                    "--scenes",
                    format!("unknown scene `{n}` (known: {})", known.join(", ")),
                )
                .into()
            })
        })
        .collect()
}

fn load(sw: &Sweep, kernel: KernelKind, cells: u32) -> Result<Loaded, SpatterError> {
    let dx = sw.length / cells as f64;
    let mut sets = vec![
        format!("dx={dx:e}"),
        format!("kernel={}", kernel_key(kernel)),
    ];
    sets.extend(sw.sets.iter().map(|s| s.to_string()));
    let stem = sw.name.split('@').next().unwrap_or(sw.name);
    let label = format!("scenarios/validation/{stem}.toml");
    Ok(run::load_str(&label, sw.text, &sets)?)
}

fn run_one(
    sw: &Sweep,
    kernel: KernelKind,
    cells: u32,
    choice: BackendChoice,
) -> Result<(AccuracyRun, String), SpatterError> {
    let l = load(sw, kernel, cells)?;
    super::reset_peak_rss();
    let mut backend = run::make_backend(choice, &l, false)?;
    let opts = RunOptions {
        end: l.model.end,
        quiet: true,
        resumed: false,
    };
    let report = run::run(&l, backend.as_mut(), &opts, &mut Outputs::default())?;
    let (metric, error, tolerance, pass) = match &report.check {
        Some(c) => (c.metric.clone(), c.value, c.tolerance, c.pass),
        None => (String::new(), f64::NAN, f64::NAN, false),
    };
    let end = match &report.end {
        RunEnd::Completed => "completed".to_string(),
        RunEnd::Interrupted => "interrupted".to_string(),
        RunEnd::Unstable(t) => format!("stopped: {}", t.message()),
    };
    let n = l.state.len();
    let row = AccuracyRun {
        scene: sw.name.into(),
        kernel: kernel_key(kernel).into(),
        cells,
        dx: l.model.dx,
        particles: n,
        steps: report.steps,
        wall_s: report.wall_s,
        particle_steps_per_s: report.particle_steps_per_s(),
        state_bytes: setup::memory_estimate(&l.model, n as f64),
        peak_rss_bytes: super::peak_rss(),
        metric,
        error,
        tolerance,
        pass,
        end,
        warnings: l.model.warnings.clone(),
    };
    Ok((row, backend.describe()))
}

/// Least-squares slope of ln(error) against ln(Δx) over the runs with a positive
/// finite error.
pub fn fit_order(runs: &[&AccuracyRun]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = runs
        .iter()
        .filter(|r| r.error.is_finite() && r.error > 0.0)
        .map(|r| (r.dx.ln(), r.error.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxx: f64 = pts.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

fn print_run(r: &AccuracyRun) {
    println!(
        "  {:<24} {:<11} n {:>3}  dx {:.3e}  {:>6} particles  {:>7} steps  {:>8.2} s  {:.2e} p-steps/s  {:>7.2} MiB state  error {:.3e} {}{}",
        r.scene,
        r.kernel,
        r.cells,
        r.dx,
        r.particles,
        r.steps,
        r.wall_s,
        r.particle_steps_per_s,
        r.state_bytes / (1024.0 * 1024.0),
        r.error,
        if r.pass { "PASS" } else { "FAIL" },
        if r.end == "completed" { String::new() } else { format!(" ({})", r.end) }
    );
    for w in &r.warnings {
        println!("    warning: {w}");
    }
}

fn print_fit(f: &OrderFit) {
    let observed = f.observed_order.map_or("n/a".into(), |o| format!("{o:.2}"));
    let expected = f
        .expected_order
        .map_or("none".into(), |o| format!("{o:.0}"));
    println!(
        "  {:<24} {:<11} observed order {:>5}, expected {} ({}){}",
        f.scene,
        f.kernel,
        observed,
        expected,
        f.why,
        if f.monotone {
            ""
        } else {
            "; error not monotone in dx"
        }
    );
}

pub fn accuracy(opts: &Options) -> Result<(), SpatterError> {
    let sweeps = chosen(opts)?;
    let choice = super::resolve_backend(opts.backend);
    let kernels: &[KernelKind] = if opts.quick { &KERNELS[..1] } else { &KERNELS };
    let mut runs = Vec::new();
    let mut orders = Vec::new();
    let mut backend = String::new();
    println!(
        "bench accuracy: {} scene(s) x {} kernel(s){}",
        sweeps.len(),
        kernels.len(),
        if opts.quick {
            ", quick (two coarsest resolutions)"
        } else {
            ""
        }
    );
    for sw in &sweeps {
        let cells = if opts.quick { &sw.cells[..2] } else { sw.cells };
        for &k in kernels {
            let first = runs.len();
            for &n in cells {
                // A kernel with a wider support does not fit the coarsest boxes
                // (a periodic axis under three supports): that row is skipped.
                let (row, described) = match run_one(sw, k, n, choice) {
                    Err(SpatterError::Input(e)) => {
                        println!(
                            "  {:<24} {:<11} n {n:>3}  skipped: {e}",
                            sw.name,
                            kernel_key(k)
                        );
                        continue;
                    }
                    other => other?,
                };
                backend = described;
                print_run(&row);
                runs.push(row);
            }
            let mine: Vec<&AccuracyRun> = runs[first..].iter().collect();
            let fit = OrderFit {
                scene: sw.name.into(),
                kernel: kernel_key(k).into(),
                observed_order: fit_order(&mine),
                expected_order: sw.expected_order,
                why: sw.why.into(),
                monotone: mine.windows(2).all(|w| w[1].error < w[0].error),
            };
            print_fit(&fit);
            orders.push(fit);
        }
    }
    let table = formulation_table(&runs);
    if !table.is_empty() {
        println!("formulations side by side (each scene as written and as its @variant):");
        for line in table {
            println!("{line}");
        }
    }
    println!("backend: {backend}");
    let report = AccuracyReport {
        backend,
        quick: opts.quick,
        runs,
        orders,
    };
    if let Some(dir) = opts.plots {
        write_plots(Path::new(dir), &report)?;
    }
    if let Some(path) = opts.json {
        super::write_json(path, &report)?;
    }
    Ok(())
}

/// Every resolution at which a scene ran both as written and as
/// an `@variant` (another formulation), the two errors and wall times on one
/// line, so a user sees which formulation buys its error for less time.
fn formulation_table(runs: &[AccuracyRun]) -> Vec<String> {
    let mut lines = Vec::new();
    for v in runs.iter().filter(|r| r.scene.contains('@')) {
        let (base, variant) = v.scene.split_once('@').unwrap_or((&v.scene, ""));
        let Some(b) = runs
            .iter()
            .find(|b| b.scene == base && b.kernel == v.kernel && b.cells == v.cells)
        else {
            continue;
        };
        // A run that failed (error NaN: stopped unstable) wins nothing.
        let cheaper = match (b.error <= v.error, b.wall_s <= v.wall_s) {
            _ if !v.error.is_finite() && !b.error.is_finite() => "both failed".to_string(),
            _ if !v.error.is_finite() => format!("{variant} failed"),
            _ if !b.error.is_finite() => "as written failed".to_string(),
            (true, true) => "as written: smaller error in less time".to_string(),
            (false, false) => format!("{variant}: smaller error in less time"),
            (true, false) => "as written: smaller error, more time".to_string(),
            (false, true) => format!("{variant}: smaller error, more time"),
        };
        lines.push(format!(
            "  {base:<24} {:<11} n {:>3}: as written error {:.3e} in {:.2} s; {variant} error {:.3e} in {:.2} s ({cheaper})",
            v.kernel, v.cells, b.error, b.wall_s, v.error, v.wall_s
        ));
    }
    lines
}

fn write_plots(dir: &Path, rep: &AccuracyReport) -> Result<(), SpatterError> {
    let io = |e: String| SpatterError::Runtime(e);
    std::fs::create_dir_all(dir)
        .map_err(|e| io(format!("cannot create {}: {e}", dir.display())))?;
    let mut scenes: Vec<&str> = rep.runs.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    let mut summary = Vec::new();
    for scene in &scenes {
        let mut series = Vec::new();
        for fit in rep.orders.iter().filter(|f| f.scene == *scene) {
            let points = rep
                .runs
                .iter()
                .filter(|r| r.scene == *scene && r.kernel == fit.kernel)
                .map(|r| (r.wall_s, r.error, format!("dx {:.2e}", r.dx)))
                .collect();
            let order = fit
                .observed_order
                .map_or("n/a".into(), |o| format!("{o:.2}"));
            series.push(Series {
                label: format!("{} (order {order})", fit.kernel),
                points,
            });
        }
        let title = format!("{scene}: error against wall time ({})", rep.backend);
        let path = dir.join(format!("{scene}.png"));
        let fig = Figure {
            title: &title,
            x_label: "wall time (s)",
            y_label: "error (check metric)",
            series: &series,
            guides: &[],
        };
        if plot::log_log(&path, &fig).map_err(io)? {
            println!("wrote {}", path.display());
        }
        // A conservation error sits at round-off: it has no order to compare.
        let converges = rep
            .orders
            .iter()
            .any(|f| f.scene == *scene && f.expected_order.is_some());
        if converges {
            summary.push(convergence_series(rep, scene));
        }
    }
    let path = dir.join("summary.png");
    let guides = [1.0, 2.0].map(|s| Guide {
        label: format!("order {s:.0}"),
        slope: s,
        through: (1.0, 1.0),
    });
    let fig = Figure {
        title: "Convergence: error / error at the coarsest dx (quintic kernel)",
        x_label: "dx / coarsest dx",
        y_label: "relative error",
        series: &summary,
        guides: &guides,
    };
    if plot::log_log(&path, &fig).map_err(io)? {
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// A scene's quintic-kernel errors against Δx, both scaled by the coarsest run, so
/// every scene shares the summary figure's axes.
fn convergence_series(rep: &AccuracyReport, scene: &str) -> Series {
    let mine: Vec<&AccuracyRun> = rep
        .runs
        .iter()
        .filter(|r| r.scene == scene && r.kernel == "quintic")
        .collect();
    let points = match mine.first() {
        Some(c) => mine
            .iter()
            .map(|r| (r.dx / c.dx, r.error / c.error, String::new()))
            .collect(),
        None => Vec::new(),
    };
    Series {
        label: scene.to_string(),
        points,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(scene: &str, cells: u32, error: f64, wall_s: f64) -> AccuracyRun {
        AccuracyRun {
            scene: scene.into(),
            kernel: "quintic".into(),
            cells,
            dx: 1.0 / cells as f64,
            particles: 0,
            steps: 0,
            wall_s,
            particle_steps_per_s: 0.0,
            state_bytes: 0.0,
            peak_rss_bytes: None,
            metric: String::new(),
            error,
            tolerance: 1.0,
            pass: true,
            end: "completed".into(),
            warnings: Vec::new(),
        }
    }

    /// One line per resolution both formulations ran, pairing each variant with
    /// the scene as written at the same n and kernel.
    #[test]
    fn formulations_pair_by_resolution() {
        let runs = [
            run("disc", 10, 0.2, 1.0),
            run("disc", 20, 0.03, 4.0),
            run("disc@wcsph", 10, 2.1, 0.8),
            run("disc@wcsph", 20, 2.9, 3.0),
            run("disc@wcsph", 40, 7.6, 12.0),
            run("other", 10, 0.1, 1.0),
        ];
        let t = formulation_table(&runs);
        assert_eq!(t.len(), 2, "{t:?}");
        assert!(
            t[0].contains("n  10") && t[0].contains("as written error 2.000e-1"),
            "{}",
            t[0]
        );
        assert!(
            t[1].contains("wcsph error 2.900e0")
                && t[1].contains("as written: smaller error, more time"),
            "{}",
            t[1]
        );
        // A variant that stopped unstable (error NaN) wins nothing.
        let failed = [
            run("col", 8, 5.3e-3, 9.2),
            run("col@dfsph", 8, f64::NAN, 0.1),
        ];
        let t = formulation_table(&failed);
        assert!(t[0].ends_with("(dfsph failed)"), "{}", t[0]);
    }
}
