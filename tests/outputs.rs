//! Run outputs: MCAP and VTK decoded by the Python reader, endings by
//! signal and by instability, checkpoint/resume bit-identity, `spatter inspect`.

mod common;
use common::{reader, scratch, spatter, text};
use spatter::checkpoint;
use spatter::output::{particle_fields, Values};
use std::path::Path;
use std::process::{Command, Stdio};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn summary(mcap: &Path) -> serde_json::Value {
    let out = reader(&["summary", s(mcap)]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stdout}{stderr}");
    serde_json::from_str(&stdout).expect("summary JSON")
}

/// The newest checkpoint in a folder.
fn newest_checkpoint(dir: &Path) -> checkpoint::Checkpoint {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .expect("checkpoint folder")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ckpt"))
        .collect();
    files.sort();
    let last = files.last().expect("a checkpoint");
    checkpoint::load(s(last)).expect("checkpoint loads")
}

#[test]
fn dam_break_3d_mcap_and_vtk_decode_in_python() {
    let dir = scratch("outputs_dam_break_3d");
    let (mcap, vtk, ck) = (dir.join("d.mcap"), dir.join("vtk"), dir.join("ck"));
    let out = spatter(&[
        "run",
        &common::scene("dam_break_3d"),
        "--backend",
        "cpu",
        "--steps",
        "300",
        "--out",
        s(&mcap),
        "--vtk",
        s(&vtk),
        "--checkpoint-every",
        "1e9",
        "--checkpoint-dir",
        s(&ck),
    ]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stdout}{stderr}");

    // Every frame decodes with the foxglove.PointCloud schema, every diagnostics
    // message with its JSON schema; particle counts match the scene.
    let loaded = spatter::run::load(&common::scene("dam_break_3d"), &[]).unwrap();
    let particles = loaded.state.len();
    let water = loaded.model.phase_index("water").unwrap() as u32;
    let water_particles = loaded.state.phase.iter().filter(|&&p| p == water).count();
    let sum = summary(&mcap);
    let frames = sum["frames"].as_u64().unwrap();
    assert_eq!(
        sum["particles_per_frame"],
        serde_json::json!([particles]),
        "every frame holds every particle: {sum}"
    );
    assert_eq!(sum["diagnostics"].as_u64(), Some(frames), "{sum}");
    assert_eq!(sum["schemas"]["/particles"], "foxglove.PointCloud");
    assert_eq!(sum["schemas"]["/diagnostics"], "spatter.Diagnostics");
    assert_eq!(sum["complete"], true);
    assert_eq!(sum["has_scenario"], true);
    let last = &sum["last_diagnostics"];
    assert_eq!(last["step"], 300);
    assert_eq!(last["particles"]["water"], water_particles);
    // A frame at the start and at every output interval the run passed.
    let intervals = last["time"].as_f64().unwrap() / loaded.model.output_interval;
    assert!(
        frames as f64 >= intervals.floor() + 1.0,
        "{frames} frames: {sum}"
    );
    // Fluid mass: 2000 particles of ρ0 Δx³ = 1e-3 kg, each scaled by the hydrostatic
    // start's 1 + p/(ρ0 c²); p runs over (k + ½) ρ0 g Δx down each 20-particle
    // column, so the mean factor is 1 + g H/(2c²) with H = 0.2 m, c = 20 m/s.
    // Conserved to summation rounding (frames are reordered by cell).
    let first_mass = sum["first_diagnostics"]["total_mass"].as_f64().unwrap();
    let expected = 2.0 * (1.0 + 9.81 * 0.2 / (2.0 * 400.0));
    assert!(
        (first_mass - expected).abs() < 1e-5,
        "{first_mass} vs {expected}"
    );
    assert!(
        (last["total_mass"].as_f64().unwrap() - first_mass).abs() < 1e-9,
        "{last}"
    );

    // The last frame equals the last .vtu, field by field.
    let cmp = reader(&["compare-vtk", s(&mcap), s(&vtk)]);
    let (o, e) = text(&cmp);
    assert_eq!(cmp.status.code(), Some(0), "{o}{e}");
    let pvd = std::fs::read_to_string(vtk.join("particles.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count() as u64, frames, "{pvd}");

    // The decoded arrays equal the simulator's own final state (its checkpoint).
    let export = dir.join("last");
    let ex = reader(&["export-last", s(&mcap), s(&export)]);
    assert_eq!(ex.status.code(), Some(0), "{:?}", text(&ex));
    let ckpt = newest_checkpoint(&ck);
    assert_eq!(ckpt.state.sim.step, 300);
    for f in particle_fields(&loaded.model, &ckpt.state) {
        let (suffix, expected): (&str, Vec<u8>) = match &f.values {
            Values::F32(v) => ("f32", v.iter().flat_map(|x| x.to_le_bytes()).collect()),
            Values::U32(v) => ("u32", v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        };
        let got = std::fs::read(export.join(format!("{}.{suffix}", f.name))).unwrap();
        assert!(
            got == expected,
            "field {} differs between MCAP and the final state",
            f.name
        );
    }

    // Diagnostics plot to PNG.
    let png = dir.join("diagnostics.png");
    let pl = reader(&["plot", s(&mcap), s(&png)]);
    assert_eq!(pl.status.code(), Some(0), "{:?}", text(&pl));
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));

    // inspect names channels, schemas and counts.
    let ins = spatter(&["inspect", s(&mcap)]);
    let (o, _) = text(&ins);
    assert_eq!(ins.status.code(), Some(0), "{o}");
    assert!(o.contains("complete: yes"), "{o}");
    assert!(
        o.contains(&format!(
            "/particles: schema foxglove.PointCloud (protobuf), {frames} messages"
        )),
        "{o}"
    );
    assert!(
        o.contains(&format!("{particles} particles per frame")),
        "{o}"
    );
    assert!(
        o.contains("/diagnostics: schema spatter.Diagnostics (jsonschema)"),
        "{o}"
    );
    assert!(
        o.contains("kind = \"dam_break_front\""),
        "stored scenario: {o}"
    );
}

/// Start a long CPU run writing MCAP and VTK; return once three frames are on disk.
fn start_long_run(dir: &Path) -> std::process::Child {
    let xdg = std::env::temp_dir().join("spatter-xdg");
    let _ = std::fs::create_dir_all(&xdg);
    let child = Command::new(env!("CARGO_BIN_EXE_spatter"))
        .args(["run", &common::scene("dam_break_3d"), "--backend", "cpu"])
        .args([
            "--out",
            s(&dir.join("run.mcap")),
            "--vtk",
            s(&dir.join("vtk")),
        ])
        .env("XDG_RUNTIME_DIR", xdg)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start spatter");
    // The VTK frame is written after the MCAP frame of the same step, so once
    // frame 2 exists the MCAP holds three flushed frames.
    let third = dir.join("vtk/frame_000002.vtu");
    let t0 = std::time::Instant::now();
    while !third.exists() {
        assert!(t0.elapsed().as_secs() < 300, "run produced no third frame");
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    child
}

fn signal(child: &std::process::Child, sig: &str) {
    let st = Command::new("kill")
        .args([sig, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(st.success());
}

#[test]
fn sigint_half_way_leaves_a_finished_mcap() {
    let dir = scratch("outputs_sigint");
    let child = start_long_run(&dir);
    signal(&child, "-INT");
    let out = child.wait_with_output().unwrap();
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(130), "{stdout}{stderr}");
    assert!(stderr.contains("interrupted by a signal"), "{stderr}");
    let sum = summary(&dir.join("run.mcap"));
    assert_eq!(sum["complete"], true, "{sum}");
    assert!(
        sum["frames"].as_u64().unwrap() >= 4,
        "3 frames + the last: {sum}"
    );
    // The interrupted run leaves a checkpoint of where it stopped.
    let ck = newest_checkpoint(&dir.join("run.checkpoints"));
    assert!(
        stdout.contains(&format!("step_{:010}.ckpt", ck.state.sim.step)),
        "{stdout}"
    );
}

#[test]
fn sigterm_finishes_the_mcap_too() {
    let dir = scratch("outputs_sigterm");
    let child = start_long_run(&dir);
    signal(&child, "-TERM");
    let out = child.wait_with_output().unwrap();
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(130), "{stdout}{stderr}");
    let sum = summary(&dir.join("run.mcap"));
    assert_eq!(sum["complete"], true, "{sum}");
    assert!(sum["frames"].as_u64().unwrap() >= 4, "{sum}");
}

#[test]
fn hard_kill_leaves_mcap_readable_to_its_last_chunk() {
    let dir = scratch("outputs_sigkill");
    let mut child = start_long_run(&dir);
    signal(&child, "-KILL");
    child.wait().unwrap();
    let mcap = dir.join("run.mcap");
    let sum = summary(&mcap);
    assert_eq!(sum["complete"], false, "{sum}");
    assert!(sum["frames"].as_u64().unwrap() >= 3, "{sum}");
    let particles = spatter::run::load(&common::scene("dam_break_3d"), &[])
        .unwrap()
        .state
        .len();
    assert_eq!(
        sum["particles_per_frame"],
        serde_json::json!([particles]),
        "{sum}"
    );
    assert_eq!(sum["has_scenario"], true, "{sum}");
    let ins = spatter(&["inspect", s(&mcap)]);
    let (o, e) = text(&ins);
    assert_eq!(ins.status.code(), Some(0), "{o}{e}");
    assert!(o.contains("complete: no"), "{o}");
}

/// 200 steps straight against 100 + resume 100: the final states are identical.
/// The scene is the dam break with a moving gate, so a resumed run must also pick
/// up the gate where it was.
fn resume_is_bit_identical(backend: &str) {
    let dir = scratch(&format!("outputs_resume_{backend}"));
    let scene = common::scene("dam_break_gate_2d");
    let (_, last) = common::assert_resume_bit_identical(&dir, &scene, backend, 100);
    assert_eq!(last.sim.step, 200);
}

#[test]
fn resume_is_bit_identical_on_cpu() {
    resume_is_bit_identical("cpu");
}

#[test]
fn resume_is_bit_identical_on_the_software_adapter() {
    resume_is_bit_identical("gpu");
}

/// A time-ended run resumed from a checkpoint it wrote on the way, toward the
/// same end, lands on that end with the same bits as the uninterrupted run:
/// the end time is set again on resume and the approach's steps are the same
/// (DFSPH's dam break, whose Δt follows the flow).
#[test]
fn time_ended_resume_lands_on_the_same_end_with_the_same_bits() {
    let dir = scratch("outputs_resume_until");
    let scene = common::scene("dam_break_2d");
    let sets = [
        "simulation.formulation=\"dfsph\"",
        "simulation.pressure_floor=false",
        "simulation.initial_pressure=\"zero\"",
        "dx=0.01",
    ];
    let run = |extra: &[&str], name: &str| {
        let ckdir = dir.join(name);
        let ck = ckdir.to_string_lossy().to_string();
        let mut args = vec!["run", "--backend", "cpu", "--until", "0.0301"];
        args.extend_from_slice(extra);
        args.extend(["--checkpoint-every", "0.02", "--checkpoint-dir", &ck]);
        for s in &sets {
            args.extend(["--set", s]);
        }
        let out = common::spatter(&args);
        assert_eq!(out.status.code(), Some(0), "{:?}", common::text(&out));
        let mut files: Vec<_> = std::fs::read_dir(&ckdir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        files
    };
    let straight = run(&[&scene], "straight");
    assert_eq!(straight.len(), 2, "{straight:?}");
    let mid = straight[0].to_string_lossy().to_string();
    let resumed = run(&["--resume", &mid], "resumed");
    let load = |p: &std::path::Path| {
        spatter::checkpoint::load(p.to_str().unwrap())
            .unwrap()
            .state
    };
    let (a, b) = (load(&straight[1]), load(resumed.last().unwrap()));
    assert_eq!(a.sim, b.sim);
    assert_eq!(a.sim.time, 0.0301f32);
    for (fa, fb) in a.fields().iter().zip(b.fields().iter()) {
        assert!(
            fa.words == fb.words,
            "field {} differs after resume",
            fa.name
        );
    }
}

#[test]
fn unstable_run_stops_with_exit_3_and_a_readable_mcap() {
    let dir = scratch("outputs_unstable");
    let mcap = dir.join("u.mcap");
    // Fixed Δt ten times the acoustic limit (0.25 h/c = 3.125e-5 s), check disabled.
    let out = spatter(&[
        "run",
        &common::scene("dam_break_2d"),
        "--backend",
        "cpu",
        "--set",
        "dt=3.125e-4",
        "--set",
        "dt_check=false",
        "--out",
        s(&mcap),
    ]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(3), "{stdout}{stderr}");
    let msg = stderr
        .lines()
        .find(|l| l.contains("unstable at step"))
        .expect("diagnosis");
    assert!(msg.contains("particle ") && msg.contains("field "), "{msg}");
    let step: u64 = msg
        .split("unstable at step ")
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let sum = summary(&mcap);
    assert_eq!(sum["complete"], true, "{sum}");
    // The last frame is the failing step; the checkpoint the step before it.
    assert_eq!(
        sum["last_diagnostics"]["step"].as_u64(),
        Some(step),
        "{sum}"
    );
    let ck = newest_checkpoint(&dir.join("u.checkpoints"));
    assert_eq!(ck.state.sim.step as u64 + 1, step);
    assert!(spatter::watchdog::scan(
        &spatter::run::load(
            &common::scene("dam_break_2d"),
            &["dt=3.125e-4".into(), "dt_check=false".into()]
        )
        .unwrap()
        .model,
        &ck.state
    )
    .is_none());
    let ins = spatter(&["inspect", s(&mcap)]);
    assert_eq!(ins.status.code(), Some(0));
}

/// A drop that disperses into its gas does not end with exit 0 in
/// silence. square_drop_2d at density ratio 100, its viscosities cut to 5e-3 /
/// 5e-5 Pa s and no interface viscosity: by t = 0.284 s 14 of its 256 particles
/// are alone in the gas. The watchdog stops it (exit 3, naming the share);
/// with `watchdog.on_dispersion = "warn"` it runs on and warns
/// (and the scene's drop-shape check fails: the outline spreads over 15 dx).
/// (With F22's interface viscosity 7.2 the same drop holds together.)
#[test]
fn a_drop_dispersing_into_its_gas_stops_the_run_or_warns() {
    let dir = scratch("outputs_dispersion");
    let run = |extra: &[&str]| {
        let mcap = dir.join("d.mcap");
        let mut args = vec!["run", "--backend", "cpu", "--out", s(&mcap)];
        let scene = common::scene("square_drop_2d");
        args.push(&scene);
        for set in [
            "materials.gas.density=10.0",
            "materials.gas.viscosity=5e-5",
            "materials.liquid.viscosity=5e-3",
            "run.end_time=0.32",
        ]
        .iter()
        .chain(extra)
        {
            args.extend(["--set", set]);
        }
        let out = spatter(&args);
        let (stdout, stderr) = text(&out);
        (out.status.code(), format!("{stdout}{stderr}"))
    };
    let (code, log) = run(&[]);
    assert_eq!(code, Some(3), "{log}");
    let msg = log
        .lines()
        .find(|l| l.contains("unstable at step"))
        .expect("diagnosis");
    assert!(
        msg.contains("field liquid_dispersion") && msg.contains("dispersing into its gas"),
        "{msg}"
    );
    // It runs to its end; the scene's drop-shape check then fails (exit 1).
    let (code, log) = run(&["watchdog.on_dispersion=\"warn\""]);
    assert_eq!(code, Some(1), "{log}");
    assert!(
        log.contains("check drop_shape") && log.contains("FAIL"),
        "{log}"
    );
    assert!(
        log.lines()
            .any(|l| l.starts_with("warning: t = ") && l.contains("dispersing into its gas")),
        "{log}"
    );
}

#[test]
fn a_fixed_dt_above_the_limit_is_refused_unless_the_check_is_off() {
    let out = spatter(&[
        "validate",
        &common::scene("dam_break_2d"),
        "--set",
        "dt=3.125e-4",
    ]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("run.dt") && stderr.contains("stability limit"),
        "{stderr}"
    );
}

#[test]
fn checkpoint_every_without_a_folder_is_an_input_error() {
    let out = spatter(&[
        "run",
        &common::scene("dam_break_2d"),
        "--checkpoint-every",
        "0.01",
    ]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--checkpoint-every"), "{stderr}");
}

#[test]
fn a_damaged_checkpoint_is_refused_with_its_name() {
    let dir = scratch("outputs_bad_checkpoint");
    let bad = dir.join("bad.ckpt");
    std::fs::write(&bad, b"SPATCKPT not really a checkpoint").unwrap();
    let out = spatter(&["run", "--resume", s(&bad)]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("bad.ckpt") && stderr.contains("checkpoint"),
        "{stderr}"
    );
}

/// A heat scene's frames carry temperature, liquid fraction and enthalpy, and its
/// diagnostics the heat figures.
#[test]
fn heat_fields_and_diagnostics_reach_the_mcap() {
    let dir = scratch("outputs_heat");
    let mcap = dir.join("s.mcap");
    let out = spatter(&[
        "run",
        &common::scene("stefan_1d"),
        "--backend",
        "cpu",
        "--set",
        "dx=4e-3",
        "--out",
        s(&mcap),
        "--pool-csv",
    ]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stdout}{stderr}");
    assert!(
        stdout.lines().any(|l| l.starts_with("heat: max T ")),
        "{stdout}"
    );
    // The pool's series beside the MCAP, a row per /diagnostics record, and
    // its plot.
    let csv = std::fs::read_to_string(dir.join("s.pool.csv")).unwrap();
    let mut rows = csv.lines();
    assert_eq!(rows.next(), Some(spatter::run::pool_csv::HEADER));
    let n = rows.clone().count();
    assert!(rows.all(|r| r.split(',').count() == 10), "{csv}");
    let png = dir.join("pool.png");
    let plotted = common::reader(&["pool", s(&mcap), s(&png)]);
    assert_eq!(plotted.status.code(), Some(0), "{:?}", text(&plotted));
    assert!(png.exists());
    let sum = summary(&mcap);
    for f in ["temperature", "liquid_fraction", "enthalpy"] {
        assert!(
            sum["fields"].as_array().unwrap().iter().any(|v| v == f),
            "{sum}"
        );
    }
    let last = &sum["last_diagnostics"];
    for k in [
        "max_temperature",
        "total_enthalpy",
        "melted_volume",
        "pool_depth",
    ] {
        assert!(last[k].as_f64().is_some(), "{k}: {last}");
    }
    let t_max = last["max_temperature"].as_f64().unwrap();
    assert!(t_max > 600.0 && t_max < 700.0, "{last}");
    assert_eq!(Some(n as u64), sum["diagnostics"].as_u64(), "{sum}");
    // Without --out there is nowhere beside to write it: exit 2.
    common::assert_input_error(
        &["run", &common::scene("stefan_1d"), "--pool-csv"],
        "--pool-csv",
    );
}

/// The 3D dam break at Δx = 4 cm, without its wall barrier: the scene file.
/// 0.1/0.04 is not a whole number: the column and tank leave half-spacing gaps
/// (warned about), and the coarse column leaks into the walls early, which makes
/// it a watchdog case.
fn coarse_dam_break_3d_scene() -> String {
    let text = std::fs::read_to_string(common::scene("dam_break_3d")).unwrap();
    let bare: String = text
        .lines()
        .filter(|l| !l.starts_with("barrier = "))
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(bare.len() < text.len(), "the scene has a barrier line");
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("coarse_dam_break_3d");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("dam_break_3d_no_barrier.toml");
    std::fs::write(&path, bare).unwrap();
    path.to_str().unwrap().to_string()
}

/// `spatter run` of the coarse 3D dam break on the CPU, with more arguments.
fn coarse_dam_break_3d(extra: &[&str]) -> std::process::Output {
    let scene = coarse_dam_break_3d_scene();
    let mut args = vec!["run", &scene, "--backend", "cpu", "--set", "dx=0.04"];
    args.extend_from_slice(extra);
    spatter(&args)
}

/// The final state is scanned too: a run whose instability starts after the last
/// scheduled scan does not complete on a state the watchdog refuses. The coarse 3D
/// dam break (Δx = 4 cm) puts a particle 0.51 Δx into the floor at step 254, which
/// the strict threshold (0.5 Δx) refuses; with no frame (hence no scan) inside 300
/// steps it used to finish with exit 0 and evaluate its check on that state (found
/// by `bench stability`, random seed 22).
#[test]
fn instability_after_the_last_scan_still_stops_the_run() {
    let sets = [
        "dx=0.04",
        "run.output_interval=1e3",
        "watchdog.wall_penetration=0.5",
    ];
    let steps = Some(spatter::model::EndCondition::Steps(300));
    let r = common::run_path(&coarse_dam_break_3d_scene(), &sets, steps);
    let spatter::run::RunEnd::Unstable(trip) = &r.end else {
        panic!("completed on a state the watchdog refuses: {:?}", r.end)
    };
    assert!(
        trip.step == 254 && trip.reason.contains("penetrated the z_min wall"),
        "{}",
        trip.message()
    );
    // The leakage names the same particle and face.
    assert_eq!(
        (trip.particle, r.leakage.particle, r.leakage.face),
        (Some(445), Some(445), Some((2, 0))),
        "{}",
        r.leakage.summary()
    );
    assert!(
        r.leakage
            .summary()
            .starts_with("deepest fluid penetration 0.51 dx"),
        "{}",
        r.leakage.summary()
    );
}

/// By default a leak into the wall layers is measured and warned
/// about, and only a fluid particle through all the layers stops the run. The
/// coarse 3D dam break leaks 0.54 Δx into the floor at t = 0.125 s (a warning) and
/// particle 445 comes out under the third layer at step 411.
#[test]
fn a_leak_into_the_walls_warns_and_only_a_leak_through_them_stops() {
    let out = coarse_dam_break_3d(&["--until", "0.25"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(3), "{stdout}{stderr}");
    assert!(
        stderr.contains("warning: fluid leaks into the walls"),
        "{stderr}"
    );
    assert!(
        stderr.contains("unstable at step 411")
            && stderr.contains("passed through all 3 layers of the z_min wall"),
        "{stderr}"
    );
    assert!(
        stdout.contains("wall leakage: deepest fluid penetration 3.02 dx (particle 445"),
        "{stdout}"
    );
    let bad = spatter(&[
        "validate",
        &common::scene("dam_break_3d"),
        "--set",
        "watchdog.wall_penetration=-1",
    ]);
    let (_, stderr) = text(&bad);
    assert_eq!(bad.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("watchdog.wall_penetration"), "{stderr}");
}
