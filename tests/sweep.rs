//! Process maps: `spatter sweep` runs a grid of overrides,
//! skips finished cells on a rerun, writes a Slurm job array whose per-task
//! command runs one cell, and `sweep collect` gathers the runs into a CSV and a
//! map. On the README's 2D line melt cut to 30 µs (a few seconds a run).

mod common;
use common::{spatter, text};

fn line_melt() -> String {
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/pbf/line_melt_coarse_2d.toml"
    )
    .to_string()
}

fn sweep(dir: &std::path::Path, extra: &[&str]) -> (Option<i32>, String) {
    let scene = line_melt();
    let mut args = vec![
        "sweep",
        &scene,
        "--vary",
        "laser.power=1.0e6,2.0e6",
        "--set",
        "run.end_time=3e-5",
        "--backend",
        "cpu",
        "--out",
        dir.to_str().unwrap(),
    ];
    args.extend(extra);
    let out = spatter(&args);
    let (o, e) = text(&out);
    (out.status.code(), format!("{o}{e}"))
}

#[test]
fn a_local_sweep_runs_each_cell_once_and_collects_a_map() {
    let dir = common::scratch("sweep_local");
    let (code, log) = sweep(&dir, &["--jobs", "2"]);
    assert_eq!(code, Some(0), "{log}");
    assert!(log.contains("2 to run"), "{log}");
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 3, "{csv}");
    assert!(
        rows[0].starts_with("laser.power,exit_code,max_depth_m"),
        "{csv}"
    );
    // More power melts deeper; both conduction mode at 30 µs.
    let depth = |r: &str| r.split(',').nth(2).unwrap().parse::<f64>().unwrap();
    assert!(depth(rows[2]) > depth(rows[1]), "{csv}");
    assert!(
        rows[1..].iter().all(|r| r.ends_with(",conduction")),
        "{csv}"
    );
    assert!(dir.join("process_map.png").exists());
    for cell in ["cell_000", "cell_001"] {
        for f in ["run.mcap", "run.log", "summary.json"] {
            assert!(dir.join(cell).join(f).exists(), "{cell}/{f}");
        }
    }
    // A rerun skips the finished cells.
    let (code, log) = sweep(&dir, &[]);
    assert_eq!(code, Some(0), "{log}");
    assert!(log.contains("2 done, 0 to run"), "{log}");
    // With a layer thicker than any track, every run is lack of fusion; the
    // CSV carries the figures the map's criteria use (2D: no depth/width).
    let out = spatter(&["sweep", "collect", dir.to_str().unwrap(), "--layer", "1.0"]);
    assert!(out.status.success(), "{:?}", text(&out));
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    for column in ["depth_over_width", "width_spread", "layer_m", "regime"] {
        assert!(header.contains(&column), "{csv}");
    }
    assert!(
        csv.lines().skip(1).all(|r| r.ends_with(",lack_of_fusion")),
        "{csv}"
    );
}

/// The Slurm path writes a job array over the cells; where `sbatch` is not
/// installed the script itself runs one array task (SLURM_ARRAY_TASK_ID = 1)
/// and leaves that cell's summary, which `sweep collect` gathers.
#[test]
fn the_slurm_script_runs_one_cell_per_array_task() {
    let dir = common::scratch("sweep_slurm");
    let (code, log) = sweep(&dir, &["--slurm"]);
    assert_eq!(code, Some(0), "{log}");
    let script = std::fs::read_to_string(dir.join("sweep.slurm")).unwrap();
    assert!(script.contains("#SBATCH --array=0-1"), "{script}");
    assert!(
        script.contains(" sweep cell ") && script.contains("$SLURM_ARRAY_TASK_ID"),
        "{script}"
    );
    assert!(!dir.join("cell_000").exists(), "--slurm runs nothing");
    let task = std::process::Command::new("bash")
        .arg(dir.join("sweep.slurm"))
        .env("SLURM_ARRAY_TASK_ID", "1")
        .output()
        .unwrap();
    assert!(task.status.success(), "{:?}", text(&task));
    assert!(dir.join("cell_001/summary.json").exists());
    assert!(!dir.join("cell_000").exists());
    let out = spatter(&["sweep", "collect", dir.to_str().unwrap()]);
    let (o, e) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{o}{e}");
    assert!(o.contains("cell 0") && o.contains("not run yet"), "{o}");
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 2, "{csv}");
}

/// A value a cell's scene refuses stops the sweep before anything is written.
#[test]
fn a_bad_value_in_the_grid_is_an_input_error_before_any_run() {
    let dir = common::scratch("sweep_bad");
    let _ = std::fs::remove_dir_all(&dir);
    let scene = line_melt();
    common::assert_input_error(
        &[
            "sweep",
            &scene,
            "--vary",
            "laser.absorptivity=0.3,-1.0",
            "--out",
            dir.to_str().unwrap(),
        ],
        "laser.absorptivity",
    );
    assert!(!dir.join("manifest.json").exists());
    common::assert_input_error(&["sweep", &scene, "--vary", "laser.absorptivity"], "--vary");
    // the README's line melt gives its power as one number, so a map can vary it
    let out = common::spatter(&["validate", &scene, "--set", "laser.power=2.0e6"]);
    assert_eq!(out.status.code(), Some(0), "{}", common::text(&out).1);
    common::assert_input_error(
        &["validate", &scene, "--set", "laser.power_until=0.0"],
        "laser.power_until",
    );
}

/// A real Slurm: tools/slurm_cluster.sh starts a one-node cluster (munged,
/// slurmctld, slurmd), submits a sweep's job array with `sbatch --wait` and
/// checks that every cell's figures equal a local sweep's. It needs Slurm
/// installed and root (the daemons run as root); elsewhere this test says so
/// and passes, and the script is run by hand (it installs Slurm itself).
#[test]
fn a_real_slurm_runs_the_array_with_the_local_figures() {
    let have = |cmd: &str| {
        std::process::Command::new("sh")
            .args(["-c", &format!("command -v {cmd}")])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    let root = std::process::Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    if !(have("slurmctld") && have("slurmd") && have("munged") && have("sbatch") && root) {
        eprintln!("Slurm is not installed here, or not as root: tools/slurm_cluster.sh not run");
        return;
    }
    let out = std::process::Command::new("bash")
        .arg(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tools/slurm_cluster.sh"
        ))
        .arg(env!("CARGO_BIN_EXE_spatter"))
        .output()
        .unwrap();
    let (o, e) = text(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(
        o.contains("2 cells through sbatch, figures equal"),
        "{o}{e}"
    );
}
