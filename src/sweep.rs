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
pub fn slurm_script(dir: &Path, exe: &Path, cells: usize, backend: &str) -> String {
    let gpus = if backend == "cpu" {
        ""
    } else {
        "#SBATCH --gpus=1\n"
    };
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
        "track": track,
        "laser": r.laser,
        "check": r.check.as_ref().map(|c| serde_json::json!({
            "name": c.name, "value": c.value, "tolerance": c.tolerance, "pass": c.pass,
            "figures": c.figures.iter().map(|(k, v)| (k.clone(), serde_json::json!(v)))
                .collect::<serde_json::Map<String, serde_json::Value>>(),
        })),
    })
}

/// One row of the collected CSV.
struct Row {
    vary: Vec<(String, String)>,
    exit: Option<i32>,
    depth: f64,
    width: f64,
    length: f64,
    mean_depth: f64,
    depression: f64,
    peak_t: f64,
    regime: String,
}

fn row(s: &CellSummary) -> Row {
    let f = s.figures.as_ref();
    let num = |path: &[&str]| {
        let mut v = f;
        for k in path {
            v = v.and_then(|x| x.get(*k));
        }
        v.and_then(|x| x.as_f64()).unwrap_or(f64::NAN)
    };
    let depression = num(&["track", "pool", "max_depression"]);
    let radius = num(&["laser_radius"]);
    let regime = match (
        s.exit_code,
        f.and_then(|x| x.get("end")).and_then(|e| e.as_str()),
    ) {
        (Some(0) | Some(1), Some("completed")) if depression.is_finite() && radius > 0.0 => {
            if depression > radius {
                "keyhole"
            } else {
                "conduction"
            }
            .to_string()
        }
        (code, _) => format!("exit {}", code.map_or("?".into(), |c| c.to_string())),
    };
    Row {
        vary: s.vary.clone(),
        exit: s.exit_code,
        depth: num(&["track", "pool", "max_depth"]),
        width: num(&["track", "pool", "max_width"]),
        length: num(&["track", "pool", "max_length"]),
        mean_depth: num(&["track", "mean_depth"]),
        depression,
        peak_t: num(&["track", "pool", "max_temperature"]),
        regime,
    }
}

/// Gather the summaries of `dir` into sweep.csv and process_map.png.
pub fn collect(dir: &Path) -> Result<(PathBuf, Option<PathBuf>), String> {
    let m = read_manifest(dir)?;
    let mut rows = Vec::new();
    for c in &m.cells {
        let p = dir.join(&c.folder).join("summary.json");
        match std::fs::read_to_string(&p) {
            Ok(t) => {
                let s: CellSummary =
                    serde_json::from_str(&t).map_err(|e| format!("{}: {e}", p.display()))?;
                rows.push(row(&s));
            }
            Err(_) => println!("  cell {} {:?}: not run yet", c.index, c.vary),
        }
    }
    let mut csv = m.keys.join(",");
    csv.push_str(",exit_code,max_depth_m,max_width_m,max_length_m,mean_remelt_depth_m,max_depression_m,peak_temperature_K,regime\n");
    for r in &rows {
        let vals: Vec<&str> = r.vary.iter().map(|(_, v)| v.as_str()).collect();
        csv.push_str(&format!(
            "{},{},{:e},{:e},{:e},{:e},{:e},{:e},{}\n",
            vals.join(","),
            r.exit.map_or(String::new(), |c| c.to_string()),
            r.depth,
            r.width,
            r.length,
            r.mean_depth,
            r.depression,
            r.peak_t,
            r.regime
        ));
    }
    let csv_path = dir.join("sweep.csv");
    crate::output::write_atomic(&csv_path, csv.as_bytes())?;
    let png = dir.join("process_map.png");
    let drawn = process_map(&png, &m.keys, &rows)?;
    Ok((csv_path, drawn.then_some(png)))
}

/// Depth and width (µm, beside each point, with the regime) over the first
/// two varied keys; false when a key's values are not numbers.
fn process_map(path: &Path, keys: &[String], rows: &[Row]) -> Result<bool, String> {
    use plotters::prelude::*;
    let value = |r: &Row, k: usize| r.vary.get(k).and_then(|(_, v)| v.parse::<f64>().ok());
    let two = keys.len() >= 2;
    let pts: Vec<(f64, f64, &Row)> = rows
        .iter()
        .filter_map(|r| Some((value(r, 0)?, if two { value(r, 1)? } else { 0.0 }, r)))
        .collect();
    if pts.is_empty() || pts.len() < rows.len() {
        return Ok(false);
    }
    crate::bench::plot::register_fonts();
    let range = |v: Vec<f64>| {
        let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &x| {
            (a.0.min(x), a.1.max(x))
        });
        let pad = if hi > lo {
            0.15 * (hi - lo)
        } else {
            0.5 * lo.abs().max(1.0)
        };
        (lo - pad)..(hi + pad)
    };
    let (xr, yr) = (
        range(pts.iter().map(|p| p.0).collect()),
        range(pts.iter().map(|p| p.1).collect()),
    );
    let root = BitMapBackend::new(path, (1200, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let panels = root.split_evenly((1, 2));
    for (panel, (name, pick)) in panels.iter().zip([
        ("pool depth", (|r: &Row| r.depth) as fn(&Row) -> f64),
        ("pool width", |r: &Row| r.width),
    ]) {
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("{name} (µm) and regime"), ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(xr.clone(), yr.clone())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(keys[0].as_str())
            .y_desc(if two { keys[1].as_str() } else { "" })
            .label_style(("sans-serif", 13))
            .x_label_formatter(&|v| format!("{v:.3e}"))
            .y_label_formatter(&|v| format!("{v:.3e}"))
            .draw()
            .map_err(|e| e.to_string())?;
        for &(x, y, r) in &pts {
            let colour = match r.regime.as_str() {
                "keyhole" => RED,
                "conduction" => BLUE,
                _ => BLACK,
            };
            let v = pick(r);
            // 2D runs have no width: the point carries its regime only.
            let label = if v.is_finite() && v > 0.0 {
                format!("{:.0} {}", v * 1e6, r.regime)
            } else {
                r.regime.clone()
            };
            let font = ("sans-serif", 13).into_font().color(&colour);
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at((x, y))
                        + Circle::new((0, 0), 6, colour.filled())
                        + Text::new(label, (9, -6), font),
                ))
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
}
