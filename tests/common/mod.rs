#![allow(dead_code)]
use std::process::{Command, Output};

/// The test command exports XDG_RUNTIME_DIR; set it here too so a bare `cargo test`
/// keeps the Vulkan loader quiet.
pub fn spatter(args: &[&str]) -> Output {
    let dir = std::env::temp_dir().join("spatter-xdg");
    let _ = std::fs::create_dir_all(&dir);
    Command::new(env!("CARGO_BIN_EXE_spatter"))
        .args(args)
        .env("XDG_RUNTIME_DIR", dir)
        .output()
        .expect("run spatter")
}

pub fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

pub fn scene(name: &str) -> String {
    format!(
        "{}/scenarios/validation/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// A scene file by its path under scenarios/ (e.g. "spray/j22_fluent_case_2d").
pub fn scene_at(path: &str) -> String {
    format!("{}/scenarios/{path}.toml", env!("CARGO_MANIFEST_DIR"))
}

/// The Python with the reader (python/, tools/requirements.txt) installed: $SPATTER_PYTHON, else the
/// repository's .venv that tools/test.sh sets up.
pub fn python() -> std::path::PathBuf {
    if let Ok(p) = std::env::var("SPATTER_PYTHON") {
        return p.into();
    }
    let venv = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python");
    assert!(
        venv.exists(),
        "no Python environment for the reader: run tools/test.sh, or python3 -m venv .venv \
         && .venv/bin/pip install -r tools/requirements.txt && .venv/bin/pip install ./python"
    );
    venv
}

/// Run the installed reader (`python -m spatter_read`, the `spatter-read`
/// command) with `args`.
pub fn reader(args: &[&str]) -> Output {
    Command::new(python())
        .args(["-m", "spatter_read"])
        .args(args)
        .output()
        .expect("run python -m spatter_read")
}

/// A fresh, empty scratch folder for one test.
pub fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// `--set` overrides that turn couette_2d's lid into a moving wall: it translates
/// at 2.5 mm/s (100 times the scene's lid velocity, so it travels 10 Δx in the
/// scene's 0.2 s and wraps across the periodic x axis), with the sound speed (10 U)
/// and the background pressure (5 ρ c²) raised to match.
pub const TRANSLATING_LID: [&str; 4] = [
    "phases.lid.moves=true",
    "phases.lid.velocity=[2.5e-3, 0.0]",
    "materials.fluid.sound_speed=2.5e-2",
    "background_pressure=3.125",
];

/// A run of `2 half` steps straight against `half` steps, then `half` more resumed
/// from the checkpoint between them, on `backend`, checkpoints under `dir`.
/// Asserts the two final states identical, field by field and Sim; returns the
/// state at the resume point and the final one.
pub fn assert_resume_bit_identical(
    dir: &std::path::Path,
    scene: &str,
    backend: &str,
    half: u64,
) -> (spatter::state::State, spatter::state::State) {
    let ck = |name: &str| dir.join(name);
    let run = |extra: &[&str], ckdir: &std::path::Path| {
        let mut args = vec!["run", "--backend", backend, "--steps"];
        args.extend_from_slice(extra);
        let ckdir = ckdir.to_str().unwrap();
        args.extend_from_slice(&["--checkpoint-every", "1e9", "--checkpoint-dir", ckdir]);
        let out = spatter(&args);
        assert_eq!(out.status.code(), Some(0), "{:?}", text(&out));
    };
    let (n, total) = (half.to_string(), (2 * half).to_string());
    run(&[&total, scene], &ck("straight"));
    run(&[&n, scene], &ck("first"));
    let at = |name: &str, step: u64| {
        let path = dir.join(format!("{name}/step_{step:010}.ckpt"));
        spatter::checkpoint::load(path.to_str().unwrap())
            .unwrap()
            .state
    };
    let mid_path = dir.join(format!("first/step_{half:010}.ckpt"));
    run(
        &[&n, "--resume", mid_path.to_str().unwrap()],
        &ck("resumed"),
    );
    let (a, b) = (at("straight", 2 * half), at("resumed", 2 * half));
    for (fa, fb) in a.fields().iter().zip(b.fields().iter()) {
        assert!(
            fa.words == fb.words,
            "{backend}: field {} differs after resume",
            fa.name
        );
    }
    assert_eq!(a.sim, b.sim);
    (at("first", half), a)
}

/// `spatter args…` exits 2 with a message naming `key` (bad input).
pub fn assert_input_error(args: &[&str], key: &str) {
    let out = spatter(args);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(stderr.contains(key), "{args:?}: no `{key}` in {stderr}");
}

/// Issue 17's bonding scene (tests/bitmatch.rs, tests/bodies.rs): a cold grain
/// (1000 K) resting on a cold plate under a layer of melt at 1750 K, which
/// freezes against both and bonds the grain; a second grain falls towards the
/// melt from above.
pub const BONDING_2D: &str = r#"
[simulation]
dimension = 2
kernel = "quintic"
dx = 5.0e-6
gravity = [0.0, -9.81]
pressure_floor = true

[domain]
min = [0.0, 0.0]
max = [1.5e-4, 1.2e-4]
wall_phase = "holder"
open_sides = ["y_max"]

[materials.steel]
density = 7430.0
viscosity = 6.0e-3
sound_speed = 10.0
conductivity = 35.95
heat_capacity = 965.0
solidus = 1695.0
liquidus = 1705.0
latent_heat = 2.7e5

[phases.plate]
kind = "solid"
material = "steel"
temperature = 1000.0
melts_into = "melt"

[phases.melt]
kind = "liquid"
material = "steel"
temperature = 1750.0

[phases.holder]
kind = "wall"
material = "steel"
temperature = 1000.0

[contact]
stiffness = 1.0e4
damping = 6.1e-2

[[shapes]]
phase = "plate"
box = { min = [0.0, 0.0], max = [1.5e-4, 3.0e-5] }

[[shapes]]
phase = "melt"
box = { min = [0.0, 3.0e-5], max = [1.5e-4, 6.0e-5] }

[[shapes]]
phase = "plate"
body = true
sphere = { center = [4.0e-5, 4.6e-5], radius = 1.5e-5 }

[[shapes]]
phase = "plate"
body = true
sphere = { center = [1.1e-4, 9.0e-5], radius = 1.0e-5 }
velocity = [0.0, -0.3]

[run]
steps = 200
"#;

/// `[check] tolerance` as scene file `path` states it (read from the TOML here,
/// not through the simulator's scene parser).
pub fn file_tolerance(path: &str) -> f64 {
    file_check_value(path, "tolerance")
}

/// A number of scene file `path`'s `[check]` section, as the file states it.
pub fn file_check_value(path: &str, key: &str) -> f64 {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let doc: toml::Table = toml::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"));
    doc.get("check")
        .and_then(|c| c.get(key))
        .and_then(|v| v.as_float())
        .unwrap_or_else(|| panic!("{path}: no [check] {key}"))
}

/// The tolerance a test states (and justifies) for the check of scene file
/// `path` is the one the file states: a scene edit that loosens or tightens its
/// check fails the test that gives the reason for it.
pub fn assert_stated_tolerance(path: &str, stated: f64) {
    let file = file_tolerance(path);
    assert_eq!(
        file, stated,
        "{path}: [check] tolerance = {file}, the test states {stated}"
    );
}

/// Run scene file `path` with `--set`-style overrides on the CPU, through the
/// library, to `end` (None: the scene's own end); no outputs.
pub fn run_path(
    path: &str,
    sets: &[&str],
    end: Option<spatter::model::EndCondition>,
) -> spatter::run::RunReport {
    run_with_outputs(path, sets, end, &mut spatter::run::Outputs::default())
}

/// `run_path` writing to `out`.
pub fn run_with_outputs(
    path: &str,
    sets: &[&str],
    end: Option<spatter::model::EndCondition>,
    out: &mut spatter::run::Outputs,
) -> spatter::run::RunReport {
    run_loaded_with_outputs(path, sets, end, out).1
}

/// `run_path`, with the scene it loaded.
pub fn run_loaded(
    path: &str,
    sets: &[&str],
    end: Option<spatter::model::EndCondition>,
) -> (spatter::run::Loaded, spatter::run::RunReport) {
    run_loaded_with_outputs(path, sets, end, &mut spatter::run::Outputs::default())
}

fn run_loaded_with_outputs(
    path: &str,
    sets: &[&str],
    end: Option<spatter::model::EndCondition>,
    out: &mut spatter::run::Outputs,
) -> (spatter::run::Loaded, spatter::run::RunReport) {
    use spatter::run::{load, make_backend, run, BackendChoice, RunOptions};
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let l = load(path, &sets).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut b = make_backend(BackendChoice::Cpu, &l, false).unwrap();
    let opts = RunOptions {
        end: end.unwrap_or(l.model.end),
        quiet: true,
        resumed: false,
    };
    let r = run(&l, b.as_mut(), &opts, out).unwrap_or_else(|e| panic!("{path}: {e}"));
    (l, r)
}

/// Outputs that write an MCAP stream to `path` (as `spatter run --out` does).
pub fn mcap_outputs(path: &std::path::Path, m: &spatter::model::Model) -> spatter::run::Outputs {
    use spatter::output::mcap_out::{McapSink, Provenance};
    let prov = Provenance {
        backend: "cpu",
        command: "cargo test",
    };
    let topics = spatter::diagnostics::topics(m);
    let sink = McapSink::create(path.to_str().unwrap(), m, &prov, &topics).unwrap();
    let mut out = spatter::run::Outputs::default();
    out.mcap = Some(sink);
    out.backend = "cpu".into();
    out
}

/// The check of a run of validation scene `name` (with overrides) to its end on
/// the CPU; the run must complete. Prints the check's lines.
pub fn run_check(name: &str, sets: &[&str]) -> spatter::checks::CheckResult {
    let r = run_path(&scene(name), sets, None);
    assert_eq!(r.end, spatter::run::RunEnd::Completed, "{name} {sets:?}");
    let c = r.check.expect("the scene has a check");
    print_check(name, sets, &c);
    c
}

pub fn print_check(name: &str, sets: &[&str], c: &spatter::checks::CheckResult) {
    println!("{name} {sets:?}");
    for d in &c.details {
        println!("{d}");
    }
    println!("{}", c.line());
}

/// The check of validation scene `name` run as its file says, with the
/// tolerance the test states (which must be the file's); it must pass.
pub fn assert_check_passes(name: &str, stated: f64) -> spatter::checks::CheckResult {
    assert_stated_tolerance(&scene(name), stated);
    let c = run_check(name, &[]);
    assert_eq!(
        c.tolerance, stated,
        "the run held {name} to another tolerance"
    );
    assert!(c.pass, "{}", c.line());
    c
}

/// A named figure of a check result.
pub fn figure(c: &spatter::checks::CheckResult, name: &str) -> f64 {
    c.figures
        .iter()
        .find(|f| f.0 == name)
        .map(|f| f.1)
        .unwrap_or_else(|| panic!("no figure {name} in {}: {:?}", c.line(), c.figures))
}

/// Two lone DFSPH particles (2D, no walls, no gravity), the second closing
/// on the first at 1 m/s (tests/dfsph.rs and tests/bitmatch.rs move it to
/// the first's support edge).
pub const DFSPH_LONE_PAIR: &str = r#"
[simulation]
dimension = 2
formulation = "dfsph"
kernel = "quintic"
dx = 1.0e-3
gravity = [0.0, 0.0]

[domain]
min = [0.0, 0.0]
max = [0.02, 0.02]
wall_phase = "wall"
open_sides = ["x_min", "x_max", "y_min", "y_max"]

[materials.liquid]
density = 1000.0
viscosity = 1.0e-3
sound_speed = 1.0

[phases.drop]
kind = "liquid"
material = "liquid"

[phases.wall]
kind = "wall"
material = "liquid"

[[shapes]]
phase = "drop"
box = { min = [0.005, 0.010], max = [0.006, 0.011] }

[[shapes]]
phase = "drop"
box = { min = [0.012, 0.010], max = [0.013, 0.011] }
velocity = [-1.0, 0.0]

[run]
end_time = 1.0e-2
max_dt = 1.0e-3
output_interval = 1.0e-3
"#;

/// Moves DFSPH_LONE_PAIR's moving particle to `gap` (in spacings of 1 mm)
/// from the one at rest; returns its index.
pub fn close_lone_pair(st: &mut spatter::state::State, gap: f32) -> usize {
    let moving = (0..st.len()).find(|&i| st.vel[i][0] != 0.0).unwrap();
    let rest = (0..st.len())
        .find(|&i| i != moving && st.phase[i] == st.phase[moving])
        .unwrap();
    st.pos[moving][0] = st.pos[rest][0] + gap * 1.0e-3;
    moving
}
