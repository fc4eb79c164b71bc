//! Process maps: a grid of `--set` overrides over one scene,
//! run on this machine N at a time or as a Slurm job array, and the figures of
//! every run gathered into one CSV and a map.
//!
//! - `spatter sweep SCENE --vary KEY=V1,V2 [--vary ...] --out DIR`: the grid is
//!   the product of the lists; DIR/manifest.json names each cell (its index,
//!   overrides and folder DIR/cell_NNN). Each cell runs `spatter run SCENE
//!   --set ... --out cell/run.mcap --summary cell/figures.json` as a child
//!   process (its log in cell/run.log) and leaves cell/summary.json (overrides,
//!   exit code, figures). A rerun skips every cell whose summary records a
//!   finished run (completed, or stopped unstable) and runs the others again
//!   (interrupted, killed, failed to start).
//! - `--slurm`: writes the manifest and DIR/sweep.slurm, a job array whose task
//!   i runs `spatter sweep cell DIR i`: the very command a local sweep runs per
//!   cell, so a cluster and a workstation produce the same folders.
//! - `spatter sweep collect DIR`: every summary.json into DIR/sweep.csv and the
//!   map DIR/process_map.png (pool depth and width over the first two varied
//!   keys, each run marked by its regime).
//!
//! Regime: keyhole when the surface under the beam sank deeper than the beam's
//! radius (the vapour depression as deep as the spot is wide over two, the
//! aspect ratio 1/2 at which the depression traps the beam), conduction
//! otherwise; a run that did not complete is marked by its exit code.

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One cell of the grid.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Cell {
    pub index: usize,
    /// (key, value) per varied key, in the order of the --vary options.
    pub vary: Vec<(String, String)>,
    pub folder: String,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Manifest {
    pub scene: String,
    pub backend: String,
    /// Overrides every cell shares (--set).
    pub sets: Vec<String>,
    pub keys: Vec<String>,
    pub cells: Vec<Cell>,
}

/// `KEY=V1,V2,...` into the key and its values.
pub fn parse_vary(spec: &str) -> Result<(String, Vec<String>), String> {
    let (key, values) = spec
        .split_once('=')
        .ok_or_else(|| format!("--vary {spec}: expected KEY=V1,V2,..."))?;
    let values: Vec<String> = values
        .split(',')
        .map(|v| v.trim().to_string())
        .filter(|v| !v.is_empty())
        .collect();
    if key.trim().is_empty() || values.is_empty() {
        return Err(format!("--vary {spec}: expected KEY=V1,V2,..."));
    }
    Ok((key.trim().to_string(), values))
}

/// The grid: the product of the lists, the last key varying fastest.
pub fn grid(vary: &[(String, Vec<String>)]) -> Vec<Cell> {
    let mut rows: Vec<Vec<(String, String)>> = vec![Vec::new()];
    for (key, values) in vary {
        rows = rows
            .into_iter()
            .flat_map(|r| {
                values.iter().map(move |v| {
                    let mut r = r.clone();
                    r.push((key.clone(), v.clone()));
                    r
                })
            })
            .collect();
    }
    rows.into_iter()
        .enumerate()
        .map(|(index, vary)| Cell {
            index,
            vary,
            folder: format!("cell_{index:03}"),
        })
        .collect()
}

pub fn manifest_path(dir: &Path) -> PathBuf {
    dir.join("manifest.json")
}

pub fn write_manifest(dir: &Path, m: &Manifest) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    let text = serde_json::to_string_pretty(m).map_err(|e| e.to_string())?;
    crate::output::write_atomic(&manifest_path(dir), text.as_bytes())
}

pub fn read_manifest(dir: &Path) -> Result<Manifest, String> {
    let p = manifest_path(dir);
    let text = std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", p.display()))
}

/// The Slurm job-array script of a sweep: task i runs cell i.
/// `extra` are the site's own options (`--partition=gpu`), one #SBATCH line each.
pub fn slurm_script(
    dir: &Path,
    exe: &Path,
    cells: usize,
    backend: &str,
    extra: &[String],
) -> String {
    let mut gpus = if backend == "cpu" {
        String::new()
    } else {
        "#SBATCH --gpus=1\n".to_string()
    };
    for e in extra {
        gpus.push_str(&format!("#SBATCH {e}\n"));
    }
    format!(
        "#!/bin/bash\n\
         # spatter sweep: one array task per cell of {dir}/manifest.json.\n\
         # Submit with: sbatch {dir}/sweep.slurm ; then: spatter sweep collect {dir}\n\
         #SBATCH --job-name=spatter-sweep\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --output=\"{dir}/slurm_%a.log\"\n\
         #SBATCH --ntasks=1\n\
         {gpus}\
         set -euo pipefail\n\
         export XDG_RUNTIME_DIR=\"${{XDG_RUNTIME_DIR:-$(mktemp -d)}}\"\n\
         \"{exe}\" sweep cell \"{dir}\" \"$SLURM_ARRAY_TASK_ID\"\n",
        dir = dir.display(),
        exe = exe.display(),
        last = cells.saturating_sub(1),
    )
}

/// A cell is done when its summary.json says the run completed or stopped
/// unstable (exit 0, 1 for a failed check, 3); an interrupted, killed or
/// failed-to-start run is run again.
pub fn done(dir: &Path, c: &Cell) -> bool {
    finished(&dir.join(&c.folder).join("summary.json")).is_some()
}

/// The summary at `path` if it records a finished run.
fn finished(path: &Path) -> Option<CellSummary> {
    let s: CellSummary = serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()?;
    let end = s.figures.as_ref()?.get("end")?.as_str()?;
    (matches!(s.exit_code, Some(0 | 1 | 3)) && matches!(end, "completed" | "unstable")).then_some(s)
}

/// What a cell leaves in summary.json.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CellSummary {
    pub index: usize,
    pub vary: Vec<(String, String)>,
    pub exit_code: Option<i32>,
    /// The run's figures (`spatter run --summary`), when it wrote them.
    pub figures: Option<serde_json::Value>,
}

/// Run cell `index` of the sweep in `dir` (a child `spatter run`), unless done.
pub fn run_cell(dir: &Path, index: usize, exe: &Path) -> Result<CellSummary, String> {
    let m = read_manifest(dir)?;
    let c = m
        .cells
        .get(index)
        .ok_or_else(|| format!("{}: no cell {index} (of {})", dir.display(), m.cells.len()))?;
    let folder = dir.join(&c.folder);
    let summary_path = folder.join("summary.json");
    if let Some(s) = finished(&summary_path) {
        return Ok(s);
    }
    std::fs::create_dir_all(&folder)
        .map_err(|e| format!("{}: cannot create: {e}", folder.display()))?;
    let figures = folder.join("figures.json");
    let _ = std::fs::remove_file(&figures);
    let log = std::fs::File::create(folder.join("run.log")).map_err(|e| e.to_string())?;
    let mut cmd = std::process::Command::new(exe);
    cmd.arg("run")
        .arg(&m.scene)
        .args(["--backend", &m.backend])
        .arg("--out")
        .arg(folder.join("run.mcap"))
        .arg("--summary")
        .arg(&figures);
    for s in m
        .sets
        .iter()
        .cloned()
        .chain(c.vary.iter().map(|(k, v)| format!("{k}={v}")))
    {
        cmd.args(["--set", &s]);
    }
    let status = cmd
        .stdout(log.try_clone().map_err(|e| e.to_string())?)
        .stderr(log)
        .status()
        .map_err(|e| format!("{}: cannot start: {e}", exe.display()))?;
    let figures = std::fs::read_to_string(&figures)
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let s = CellSummary {
        index,
        vary: c.vary.clone(),
        exit_code: status.code(),
        figures,
    };
    let text = serde_json::to_string_pretty(&s).map_err(|e| e.to_string())?;
    crate::output::write_atomic(&summary_path, text.as_bytes())?;
    Ok(s)
}

/// Run every cell not yet done, `jobs` at a time; a line per finished cell.
pub fn run_local(dir: &Path, jobs: usize, exe: &Path) -> Result<Vec<CellSummary>, String> {
    let m = read_manifest(dir)?;
    let todo: Vec<usize> = m
        .cells
        .iter()
        .filter(|c| !done(dir, c))
        .map(|c| c.index)
        .collect();
    println!(
        "sweep: {} cells, {} done, {} to run, {} at a time",
        m.cells.len(),
        m.cells.len() - todo.len(),
        todo.len(),
        jobs
    );
    let next = std::sync::atomic::AtomicUsize::new(0);
    let errors = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..jobs.max(1).min(todo.len().max(1)) {
            s.spawn(|| loop {
                let k = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                let Some(&i) = todo.get(k) else { break };
                match run_cell(dir, i, exe) {
                    Ok(r) => println!("  cell {i} {:?}: exit {:?}", r.vary, r.exit_code),
                    Err(e) => errors.lock().unwrap().push(e),
                }
            });
        }
    });
    let errors = errors.into_inner().unwrap();
    if let Some(e) = errors.first() {
        return Err(e.clone());
    }
    // Every cell's summary, as it ended (one that did not finish says how).
    m.cells
        .iter()
        .map(|c| {
            let p = dir.join(&c.folder).join("summary.json");
            let text = std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))?;
            serde_json::from_str(&text).map_err(|e| format!("{}: {e}", p.display()))
        })
        .collect()
}

/// A run's figures for its summary (`spatter run --summary`): how it ended,
/// its cost, the beam, and the track's pool figures.
pub fn run_figures(m: &crate::model::Model, r: &crate::run::RunReport) -> serde_json::Value {
    use crate::run::RunEnd;
    let (end, diagnosis) = match &r.end {
        RunEnd::Completed => ("completed", None),
        RunEnd::Interrupted => ("interrupted", None),
        RunEnd::Unstable(t) => ("unstable", Some(t.message())),
    };
    let track = r.track.as_ref().map(|t| {
        serde_json::json!({
            "pool": t.pool,
            "slices": t.slices.len(),
            "mean_depth": t.mean(|s| s.depth),
            "mean_width": t.mean(|s| s.width),
            "mean_height": t.mean(|s| s.height),
            "width_spread": t.width_spread(),
            "steady_depth": t.steady_mean(|s| s.depth),
            "steady_width": t.steady_mean(|s| s.width),
            "tracks": t.tracks,
        })
    });
    serde_json::json!({
        "end": end,
        "diagnosis": diagnosis,
        "steps": r.steps,
        "sim_time": r.sim_time,
        "wall_s": r.wall_s,
        "particles": r.particles,
        "dim": m.dim,
        "laser_radius": m.laser.as_ref().map(|l| l.radius),
        "laser_peak_power": m.laser.as_ref().map(|l| l.power.iter().map(|p| p.1).fold(0.0, f64::max)),
        "layer_thickness": m.powder.as_ref().map(|b| b.thickness),
        "dx": m.dx,
        "track": track,
        "laser": r.laser,
        "check": r.check.as_ref().map(|c| serde_json::json!({
            "name": c.name, "value": c.value, "tolerance": c.tolerance, "pass": c.pass,
            "figures": c.figures.iter().map(|(k, v)| (k.clone(), serde_json::json!(v)))
                .collect::<serde_json::Map<String, serde_json::Value>>(),
        })),
    })
}

/// Keyhole where the track's depth over its width exceeds this (3D): a pool
/// deeper than half its width is no longer a conduction-mode half ellipse
/// (the depth-to-width criterion of the keyhole literature, e.g. King et al.
/// 2014's transition, where it reaches about 0.5).
pub const KEYHOLE_DEPTH_OVER_WIDTH: f64 = 0.5;
/// An unstable (balling) track where its width's coefficient of variation
/// along the steady part exceeds this: a stable track's width varies by about
/// a particle over its width at the resolutions swept (0.1–0.2 at 5–10
/// particles across); a track breaking into beads varies by its whole width.
pub const UNSTABLE_WIDTH_SPREAD: f64 = 0.3;
/// A 3D track's shape is not judged below this many particles deep (or twice
/// as many across): a pool one particle deep has a depth/width set by the
/// lattice, not by the physics.
pub const RESOLVED_DEPTH_DX: f64 = 2.0;

/// One row of the collected CSV.
struct Row {
    vary: Vec<(String, String)>,
    exit: Option<i32>,
    dim: u32,
    dx: f64,
    depth: f64,
    width: f64,
    length: f64,
    mean_depth: f64,
    mean_width: f64,
    width_spread: f64,
    depression: f64,
    peak_t: f64,
    layer: f64,
    regime: String,
}

/// The regime of a run that completed, by the criteria in order: lack of
/// fusion (the steady track shallower than the layer), unresolved (3D: the
/// track less than RESOLVED_DEPTH_DX particles deep or twice that across,
/// too coarse to judge its shape), keyhole (3D: depth
/// over width above KEYHOLE_DEPTH_OVER_WIDTH; 2D, where width is not defined:
/// the surface under the beam sunk deeper than the beam radius), unstable
/// (the width's spread above UNSTABLE_WIDTH_SPREAD), else conduction.
fn regime(r: &Row, radius: f64) -> &'static str {
    if r.layer > 0.0 && r.mean_depth < r.layer {
        "lack_of_fusion"
    } else if r.dim == 3
        && r.dx > 0.0
        && (r.mean_depth < RESOLVED_DEPTH_DX * r.dx
            || r.mean_width < 2.0 * RESOLVED_DEPTH_DX * r.dx)
    {
        "unresolved"
    } else if (r.dim == 3 && r.mean_depth / r.mean_width > KEYHOLE_DEPTH_OVER_WIDTH)
        || (r.dim != 3 && radius > 0.0 && r.depression > radius)
    {
        "keyhole"
    } else if r.width_spread > UNSTABLE_WIDTH_SPREAD {
        "unstable"
    } else {
        "conduction"
    }
}

fn row(s: &CellSummary, layer: Option<f64>) -> Row {
    let f = s.figures.as_ref();
    let num = |path: &[&str]| {
        let mut v = f;
        for k in path {
            v = v.and_then(|x| x.get(*k));
        }
        v.and_then(|x| x.as_f64()).unwrap_or(f64::NAN)
    };
    let mut r = Row {
        vary: s.vary.clone(),
        exit: s.exit_code,
        dim: num(&["dim"]) as u32,
        dx: num(&["dx"]),
        depth: num(&["track", "pool", "max_depth"]),
        width: num(&["track", "pool", "max_width"]),
        length: num(&["track", "pool", "max_length"]),
        // the steady part's (runs collected before it existed: all slices')
        mean_depth: {
            let v = num(&["track", "steady_depth"]);
            if v.is_finite() {
                v
            } else {
                num(&["track", "mean_depth"])
            }
        },
        mean_width: {
            let v = num(&["track", "steady_width"]);
            if v.is_finite() {
                v
            } else {
                num(&["track", "mean_width"])
            }
        },
        width_spread: num(&["track", "width_spread"]),
        depression: num(&["track", "pool", "max_depression"]),
        peak_t: num(&["track", "pool", "max_temperature"]),
        layer: layer.unwrap_or(num(&["layer_thickness"])),
        regime: String::new(),
    };
    let completed = f.and_then(|x| x.get("end")).and_then(|e| e.as_str()) == Some("completed");
    let melted = num(&["track", "slices"]) > 0.0;
    r.regime = match s.exit_code {
        Some(0) | Some(1) if completed && !melted => "no_melt".to_string(),
        Some(0) | Some(1) if completed && r.mean_depth.is_finite() => {
            regime(&r, num(&["laser_radius"])).to_string()
        }
        code => format!("exit {}", code.map_or("?".into(), |c| c.to_string())),
    };
    r
}

/// Gather the summaries of `dir` into sweep.csv and process_map.png. `layer`
/// (m) is the lack-of-fusion depth; without it a powder scene's layer.
pub fn collect(dir: &Path, layer: Option<f64>) -> Result<(PathBuf, Option<PathBuf>), String> {
    let m = read_manifest(dir)?;
    let mut rows = Vec::new();
    for c in &m.cells {
        let p = dir.join(&c.folder).join("summary.json");
        match std::fs::read_to_string(&p) {
            Ok(t) => {
                let s: CellSummary =
                    serde_json::from_str(&t).map_err(|e| format!("{}: {e}", p.display()))?;
                rows.push(row(&s, layer));
            }
            Err(_) => println!("  cell {} {:?}: not run yet", c.index, c.vary),
        }
    }
    let mut csv = m.keys.join(",");
    csv.push_str(
        ",exit_code,max_depth_m,max_width_m,max_length_m,steady_remelt_depth_m,\
         steady_width_m,depth_over_width,width_spread,max_depression_m,peak_temperature_K,\
         layer_m,regime\n",
    );
    for r in &rows {
        let vals: Vec<&str> = r.vary.iter().map(|(_, v)| v.as_str()).collect();
        csv.push_str(&format!(
            "{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{}\n",
            vals.join(","),
            r.exit.map_or(String::new(), |c| c.to_string()),
            r.depth,
            r.width,
            r.length,
            r.mean_depth,
            r.mean_width,
            if r.dim == 3 {
                r.mean_depth / r.mean_width
            } else {
                f64::NAN
            },
            r.width_spread,
            r.depression,
            r.peak_t,
            r.layer,
            r.regime
        ));
    }
    let csv_path = dir.join("sweep.csv");
    crate::output::write_atomic(&csv_path, csv.as_bytes())?;
    let png = dir.join("process_map.png");
    let drawn = process_map(&png, &m.keys, &rows)?;
    Ok((csv_path, drawn.then_some(png)))
}

/// A varied key's axis: the factor from SI to what is drawn, and the label.
fn axis(key: &str, dim: u32) -> (f64, String) {
    match key {
        "laser.power" if dim == 2 => (1e-3, "laser power (kW per m of depth)".into()),
        "laser.power" => (1.0, "laser power (W)".into()),
        "scan.speed" => (1e3, "scan speed (mm/s)".into()),
        "scan.hatch_spacing" => (1e6, "hatch spacing (µm)".into()),
        "laser.radius" => (1e6, "beam radius (µm)".into()),
        _ => (1.0, key.to_string()),
    }
}

/// A tick label without an exponent: 1500, 2.5, 0.35.
fn plain(v: f64) -> String {
    if v != 0.0 && v.abs() < 0.01 {
        return format!("{v:.2e}");
    }
    let s = if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.3}")
    };
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Colours of the filled contours, low to high (viridis at eight stops).
const BANDS: [(u8, u8, u8); 8] = [
    (68, 1, 84),
    (70, 50, 127),
    (54, 92, 141),
    (39, 127, 142),
    (31, 161, 135),
    (74, 194, 109),
    (159, 218, 58),
    (253, 231, 37),
];

/// The process map: over the first two varied keys, filled contours (eight
/// bands, bilinear between the runs) of the steady track's depth and of its
/// width (2D: the pool's length, width being undefined in a slice), each
/// run's point with its regime, and the boundaries between runs of different
/// regimes drawn midway. False when a key's values are not numbers.
fn process_map(path: &Path, keys: &[String], rows: &[Row]) -> Result<bool, String> {
    use plotters::prelude::*;
    let value = |r: &Row, k: usize| r.vary.get(k).and_then(|(_, v)| v.parse::<f64>().ok());
    let two = keys.len() >= 2;
    let dim = rows.iter().map(|r| r.dim).max().unwrap_or(3);
    let (sx, xlabel) = axis(&keys[0], dim);
    let (sy, ylabel) = if two {
        axis(&keys[1], dim)
    } else {
        (1.0, String::new())
    };
    let pts: Vec<(f64, f64, &Row)> = rows
        .iter()
        .filter_map(|r| {
            Some((
                value(r, 0)? * sx,
                if two { value(r, 1)? * sy } else { 0.0 },
                r,
            ))
        })
        .collect();
    if pts.is_empty() || pts.len() < rows.len() {
        return Ok(false);
    }
    let distinct = |k: usize| {
        let mut v: Vec<f64> = pts.iter().map(|p| if k == 0 { p.0 } else { p.1 }).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    };
    let (xs, ys) = (distinct(0), distinct(1));
    // The runs on a full grid: value at (i, j), where the contours are drawn.
    let at = |i: usize, j: usize| {
        pts.iter()
            .find(|p| p.0 == xs[i] && p.1 == ys[j])
            .map(|p| p.2)
    };
    let full = xs.len() >= 2 && ys.len() >= 2 && pts.len() == xs.len() * ys.len();
    crate::bench::plot::register_fonts();
    let range = |v: &[f64]| {
        let (lo, hi) = (v[0], v[v.len() - 1]);
        let pad = if hi > lo {
            0.08 * (hi - lo)
        } else {
            0.5 * lo.abs().max(1.0)
        };
        (lo - pad)..(hi + pad)
    };
    let (xr, yr) = (range(&xs), range(&ys));
    // room on the right for the legend (bands and regimes)
    let x_end = xr.end;
    let xr = xr.start..xr.end + 0.45 * (xs[xs.len() - 1] - xs[0]).max(xr.end - xr.start);
    let root = BitMapBackend::new(path, (1300, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let panels = root.split_evenly((1, 2));
    let second: (&str, fn(&Row) -> f64) = if dim == 3 {
        ("steady track width (µm)", |r| r.mean_width)
    } else {
        ("pool length (µm); width is not defined in 2D", |r| {
            r.length
        })
    };
    for (panel, (name, pick)) in panels.iter().zip([
        (
            "steady track depth (µm)",
            (|r: &Row| r.mean_depth) as fn(&Row) -> f64,
        ),
        second,
    ]) {
        let mut chart = ChartBuilder::on(panel)
            .caption(name, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(xr.clone(), yr.clone())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(xlabel.as_str())
            .y_desc(ylabel.as_str())
            .label_style(("sans-serif", 13))
            .x_label_formatter(&|v| plain(*v))
            .y_label_formatter(&|v| plain(*v))
            .draw()
            .map_err(|e| e.to_string())?;
        let vals: Vec<f64> = pts
            .iter()
            .map(|p| pick(p.2) * 1e6)
            .filter(|v| v.is_finite())
            .collect();
        let (lo, hi) = vals
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |a, &v| {
                (a.0.min(v), a.1.max(v))
            });
        if full && hi > lo {
            let band = |v: f64| (((v - lo) / (hi - lo) * 8.0).floor() as usize).min(7);
            let n = 48;
            let mut cells = Vec::new();
            for gi in 0..xs.len() - 1 {
                for gj in 0..ys.len() - 1 {
                    let corner =
                        |a: usize, b: usize| at(gi + a, gj + b).map_or(f64::NAN, |r| pick(r) * 1e6);
                    let (v00, v10, v01, v11) =
                        (corner(0, 0), corner(1, 0), corner(0, 1), corner(1, 1));
                    let (x0, x1, y0, y1) = (xs[gi], xs[gi + 1], ys[gj], ys[gj + 1]);
                    for a in 0..n {
                        for b in 0..n {
                            let (u, w) = ((a as f64 + 0.5) / n as f64, (b as f64 + 0.5) / n as f64);
                            let v = v00 * (1.0 - u) * (1.0 - w)
                                + v10 * u * (1.0 - w)
                                + v01 * (1.0 - u) * w
                                + v11 * u * w;
                            if v.is_finite() {
                                let (c0, c1) = (
                                    x0 + (x1 - x0) * a as f64 / n as f64,
                                    x0 + (x1 - x0) * (a + 1) as f64 / n as f64,
                                );
                                let (d0, d1) = (
                                    y0 + (y1 - y0) * b as f64 / n as f64,
                                    y0 + (y1 - y0) * (b + 1) as f64 / n as f64,
                                );
                                let (r, g, bl) = BANDS[band(v)];
                                cells.push(Rectangle::new(
                                    [(c0, d0), (c1, d1)],
                                    RGBColor(r, g, bl).filled(),
                                ));
                            }
                        }
                    }
                }
            }
            chart.draw_series(cells).map_err(|e| e.to_string())?;
            for (k, &(r, g, bl)) in BANDS.iter().enumerate() {
                let (a, b) = (
                    lo + (hi - lo) * k as f64 / 8.0,
                    lo + (hi - lo) * (k + 1) as f64 / 8.0,
                );
                chart
                    .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                    .map_err(|e| e.to_string())?
                    .label(format!("{a:.0}–{b:.0}"))
                    .legend(move |(x, y)| {
                        Rectangle::new([(x, y - 5), (x + 12, y + 5)], RGBColor(r, g, bl).filled())
                    });
            }
            // Regime boundaries: midway between neighbouring runs whose
            // regimes differ.
            let mut lines = Vec::new();
            for i in 0..xs.len() {
                for j in 0..ys.len() {
                    let here = at(i, j).map(|r| r.regime.as_str());
                    if i + 1 < xs.len() && here != at(i + 1, j).map(|r| r.regime.as_str()) {
                        let xm = 0.5 * (xs[i] + xs[i + 1]);
                        let y0 = if j == 0 {
                            yr.start
                        } else {
                            0.5 * (ys[j - 1] + ys[j])
                        };
                        let y1 = if j + 1 == ys.len() {
                            yr.end
                        } else {
                            0.5 * (ys[j] + ys[j + 1])
                        };
                        lines.push(PathElement::new(
                            vec![(xm, y0), (xm, y1)],
                            BLACK.stroke_width(3),
                        ));
                    }
                    if j + 1 < ys.len() && here != at(i, j + 1).map(|r| r.regime.as_str()) {
                        let ym = 0.5 * (ys[j] + ys[j + 1]);
                        let x0 = if i == 0 {
                            xr.start
                        } else {
                            0.5 * (xs[i - 1] + xs[i])
                        };
                        let x1 = if i + 1 == xs.len() {
                            x_end
                        } else {
                            0.5 * (xs[i] + xs[i + 1])
                        };
                        lines.push(PathElement::new(
                            vec![(x0, ym), (x1, ym)],
                            BLACK.stroke_width(3),
                        ));
                    }
                }
            }
            chart.draw_series(lines).map_err(|e| e.to_string())?;
        }
        let marker = |regime: &str| match regime {
            "conduction" => WHITE,
            "keyhole" => RED,
            "lack_of_fusion" => CYAN,
            "unstable" => MAGENTA,
            "unresolved" => RGBColor(160, 160, 160),
            "no_melt" => RGBColor(255, 200, 0),
            _ => BLACK,
        };
        let mut seen: Vec<&str> = Vec::new();
        for &(_, _, r) in &pts {
            if !seen.contains(&r.regime.as_str()) {
                seen.push(r.regime.as_str());
                let c = marker(&r.regime);
                chart
                    .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                    .map_err(|e| e.to_string())?
                    .label(r.regime.replace('_', " "))
                    .legend(move |(x, y)| {
                        EmptyElement::at((x + 6, y))
                            + Circle::new((0, 0), 5, c.filled())
                            + Circle::new((0, 0), 5, BLACK.stroke_width(1))
                    });
            }
        }
        for &(x, y, r) in &pts {
            let v = pick(r) * 1e6;
            let label = if v.is_finite() {
                format!("{v:.0}")
            } else {
                r.regime.clone()
            };
            let colour = marker(&r.regime);
            let font = ("sans-serif", 13).into_font().color(&BLACK);
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at((x, y))
                        + Circle::new((0, 0), 6, colour.filled())
                        + Circle::new((0, 0), 6, BLACK.stroke_width(1))
                        + Text::new(label, (9, -6), font),
                ))
                .map_err(|e| e.to_string())?;
        }
        {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 11))
                .draw()
                .map_err(|e| e.to_string())?;
        }
    }
    root.present().map_err(|e| e.to_string())?;
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_is_the_product_with_the_last_key_fastest() {
        let vary = vec![
            parse_vary("laser.power=100,200").unwrap(),
            parse_vary("speed=1, 2 ,3").unwrap(),
        ];
        let g = grid(&vary);
        assert_eq!(g.len(), 6);
        assert_eq!(
            g[1].vary,
            vec![
                ("laser.power".into(), "100".into()),
                ("speed".into(), "2".into())
            ]
        );
        assert_eq!(g[5].folder, "cell_005");
        assert!(parse_vary("power").is_err());
        assert!(parse_vary("power=").is_err());
    }

    /// The regimes by their stated criteria, in order: lack of fusion below
    /// the layer; keyhole at depth/width above 0.5 (3D) or a depression deeper
    /// than the beam radius (2D); unstable at a width spread above 0.3.
    #[test]
    fn regimes_follow_their_criteria() {
        let r = |dim: u32, depth: f64, width: f64, spread: f64, depression: f64, layer: f64| Row {
            vary: Vec::new(),
            exit: Some(0),
            dim,
            dx: 10e-6,
            depth,
            width,
            length: f64::NAN,
            mean_depth: depth,
            mean_width: width,
            width_spread: spread,
            depression,
            peak_t: f64::NAN,
            layer,
            regime: String::new(),
        };
        let radius = 50e-6;
        assert_eq!(
            regime(&r(3, 40e-6, 100e-6, 0.1, 0.0, f64::NAN), radius),
            "conduction"
        );
        assert_eq!(
            regime(&r(3, 60e-6, 100e-6, 0.1, 0.0, f64::NAN), radius),
            "keyhole"
        );
        assert_eq!(
            regime(&r(3, 40e-6, 100e-6, 0.4, 0.0, f64::NAN), radius),
            "unstable"
        );
        assert_eq!(
            regime(&r(3, 40e-6, 100e-6, 0.1, 0.0, 50e-6), radius),
            "lack_of_fusion"
        );
        assert_eq!(
            regime(&r(2, 40e-6, 0.0, f64::NAN, 60e-6, f64::NAN), radius),
            "keyhole"
        );
        assert_eq!(
            regime(&r(2, 40e-6, 0.0, f64::NAN, 10e-6, f64::NAN), radius),
            "conduction"
        );
        // one particle deep at 40 µm: not judged
        let mut coarse = r(3, 40e-6, 60e-6, 0.1, 0.0, f64::NAN);
        coarse.dx = 40e-6;
        assert_eq!(regime(&coarse, radius), "unresolved");
        assert_eq!(plain(1500.0), "1500");
        assert_eq!(plain(2.5), "2.5");
        assert_eq!(plain(0.35), "0.35");
    }
}
