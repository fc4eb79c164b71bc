//! `spatter sweep`: a grid of `--set` values run locally or as a Slurm job
//! array, and `sweep cell` / `sweep collect`.

use spatter::error::InputError;
use spatter::error::SpatterError;
use spatter::run::{self, BackendChoice};
use std::process::ExitCode;

/// `spatter sweep`'s command line.
pub(crate) struct SweepArgs<'a> {
    pub args: &'a [String],
    pub vary: &'a [String],
    pub sets: &'a [String],
    pub jobs: usize,
    pub out: &'a str,
    pub backend: BackendChoice,
    pub slurm: bool,
    pub layer: Option<f64>,
    pub slurm_args: &'a [String],
}

pub(crate) fn cmd_sweep(a: SweepArgs) -> Result<ExitCode, SpatterError> {
    let SweepArgs {
        args,
        vary,
        sets,
        jobs,
        out,
        backend,
        slurm,
        layer,
        slurm_args,
    } = a;
    if let Some(l) = layer {
        if !(l.is_finite() && l > 0.0) {
            return Err(InputError::new(
                "sweep",
                "--layer",
                format!("a thickness > 0 in m, got {l}"),
            )
            .into());
        }
    }
    use spatter::sweep;
    use std::path::Path;
    let exe = std::env::current_exe().map_err(|e| SpatterError::Runtime(e.to_string()))?;
    let rt = SpatterError::Runtime;
    match args {
        [c, dir] if c == "collect" => {
            let (csv, png) = sweep::collect(Path::new(dir), layer).map_err(rt)?;
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
            sweep::slurm_script(&dir_abs, &exe, manifest.cells.len(), backend, slurm_args)
                .as_bytes(),
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
    let (csv, png) = sweep::collect(dir, layer).map_err(rt)?;
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
