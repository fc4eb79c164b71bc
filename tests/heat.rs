//! Heat: each validation scene's [check] against its reference solution,
//! held to the tolerance stated and justified here (which must be the scene
//! file's), the Stefan front at three resolutions, and which passes a scene runs.

mod common;
use common::{assert_stated_tolerance, run_check, scene, spatter, text};
use spatter::diagnostics::heat_diagnostics;
use spatter::model::EndCondition;

/// Conduction (into a half-space against erf; through two materials against the
/// steady profile): the largest temperature error relative to the temperature
/// scale of the scene, 1%.
const CONDUCTION_TOLERANCE: f64 = 0.01;
/// Enthalpy in an adiabatic box after 10⁴ steps: 1e-6 relative. Each
/// step rounds every h to f32 (1.5e-8 relative), a random walk of about 1e-7 for
/// the sum.
const ADIABATIC_TOLERANCE: f64 = 1e-6;
/// The Stefan front: within 3% at the finest of three resolutions.
const STEFAN_TOLERANCE: f64 = 0.03;
/// Laser energy: the absorbed power within 1% of ζP, or energy in − losses =
/// enthalpy change within 1%.
const LASER_ENERGY_TOLERANCE: f64 = 0.01;
/// A beam switched off half-way: the balance holds to one step's energy at the
/// switch, P Δt out of P t/2 = 1/26 here, so 5%.
const SWITCHED_BEAM_TOLERANCE: f64 = 0.05;
/// The radiated power against the flat-surface flux σ (T⁴ − T_a⁴) × width: 2%
/// (the two corner columns next to the side walls radiate less).
const FLAT_SURFACE_FLUX_TOLERANCE: f64 = 0.02;
/// Rosenthal's moving source: within 5% outside two beam radii.
const ROSENTHAL_TOLERANCE: f64 = 0.05;

/// `spatter ARGS... --set S...`: exit code and output.
fn spatter_with(args: &[&str], sets: &[&str]) -> (Option<i32>, String) {
    let mut args = args.to_vec();
    for s in sets {
        args.extend_from_slice(&["--set", s]);
    }
    let out = spatter(&args);
    let (stdout, stderr) = text(&out);
    (out.status.code(), format!("{stdout}{stderr}"))
}

/// The line of a command's output that starts with `prefix`.
fn line_of<'a>(output: &'a str, prefix: &str) -> &'a str {
    output
        .lines()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no `{prefix}` line: {output}"))
}

/// Scene `name`'s check, with overrides that keep its tolerance, passes the
/// tolerance the test states, which is the scene file's.
fn assert_check(name: &str, sets: &[&str], stated: f64) {
    assert_stated_tolerance(&scene(name), stated);
    let c = run_check(name, sets);
    assert!(
        c.pass && c.tolerance == stated,
        "{name} {sets:?}: {}",
        c.line()
    );
}

#[test]
fn conduction_1d_within_1_percent_of_erf() {
    assert_check("conduction_1d", &[], CONDUCTION_TOLERANCE);
}

#[test]
fn two_materials_steady_profile_within_1_percent() {
    assert_check("conduction_two_materials", &[], CONDUCTION_TOLERANCE);
}

#[test]
fn adiabatic_box_conserves_enthalpy_to_1e_6_over_1e4_steps() {
    assert_check("adiabatic_box", &[], ADIABATIC_TOLERANCE);
}

/// Stefan front within 3% at the finest of three resolutions, the error
/// falling as Δx falls.
#[test]
fn stefan_front_converges_and_is_within_3_percent() {
    assert_stated_tolerance(&scene("stefan_1d"), STEFAN_TOLERANCE);
    let errors: Vec<f64> = ["dx=4e-3", "dx=2e-3", "dx=1e-3"]
        .iter()
        .map(|s| run_check("stefan_1d", &[s]).value)
        .collect();
    println!("stefan_1d rms front error at dx = 4, 2, 1 mm: {errors:?}");
    assert!(errors[0] > errors[1] && errors[1] > errors[2], "{errors:?}");
    assert!(errors[2] <= STEFAN_TOLERANCE, "{errors:?}");
}

fn passes(name: &str, sets: &[&str]) -> String {
    let (code, output) = spatter_with(&["validate", &scene(name)], sets);
    assert_eq!(code, Some(0), "{output}");
    line_of(&output, "passes: ").to_string()
}

#[test]
fn validate_lists_heat_only_where_there_is_temperature() {
    assert_eq!(
        passes("dam_break_3d", &[]),
        "passes: neighbors, density, wall, forces, integrate, timestep"
    );
    // A solid-only heat scene runs no flow pass.
    assert_eq!(
        passes("stefan_1d", &[]),
        "passes: neighbors, heat, timestep"
    );
    let hot = [
        "materials.water.conductivity=0.6",
        "materials.water.heat_capacity=4186.0",
        "phases.water.temperature=350.0",
    ];
    assert_eq!(
        passes("dam_break_3d", &hot),
        "passes: neighbors, density, wall, forces, heat, integrate, timestep"
    );
}

#[test]
fn conduction_limit_binds_and_is_named() {
    let out = spatter(&["validate", &scene("conduction_1d")]);
    let (stdout, _) = text(&out);
    assert!(
        stdout.contains("binding: conduction 0.1 rho c_p h^2/k"),
        "{stdout}"
    );
    assert!(stdout.contains("conduction 1.0000e-1 s"), "{stdout}");
}

/// Absorbed power within 1% of ζP for both laser models (and, for the
/// surface model, all three kernels: the surface-delta normalisation κ differs).
#[test]
fn laser_flat_plate_absorbs_zeta_p_within_1_percent() {
    assert_check("laser_flat_plate", &[], LASER_ENERGY_TOLERANCE);
    for kernel in ["quintic", "wendland_c2", "cubic"] {
        let k = format!("kernel=\"{kernel}\"");
        assert_check(
            "laser_flat_plate",
            &["laser.model=\"gaussian_surface\"", &k],
            LASER_ENERGY_TOLERANCE,
        );
    }
}

/// A moving beam switched off half-way: the energy balance holds to
/// `SWITCHED_BEAM_TOLERANCE`, which the run is given in place of the scene's.
#[test]
fn laser_scan_path_and_power_schedule_deposit_what_the_schedule_says() {
    let tolerance = format!("check.tolerance={SWITCHED_BEAM_TOLERANCE}");
    let c = run_check(
        "laser_flat_plate",
        &[
            "laser.power=[[0.0, 2.0e4], [5.0e-5, 0.0]]",
            "laser.path=[[0.0, 1.0e-4], [1.0e-4, 3.0e-4]]",
            &tolerance,
        ],
    );
    assert!(
        c.pass && c.tolerance == SWITCHED_BEAM_TOLERANCE,
        "{}",
        c.line()
    );
}

/// The melt block's energy balance within 1%; on the way a pool melts
/// (solid particles become liquid) and resolidifies once the beam is off.
#[test]
fn melt_block_3d_energy_balance_and_resolidification() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("heat_melt_block");
    let _ = std::fs::create_dir_all(&dir);
    let mcap = dir.join("m.mcap");
    assert_check("melt_block_3d", &[], LASER_ENERGY_TOLERANCE);
    assert_check(
        "melt_block_3d",
        &["laser.model=\"beer_lambert\""],
        LASER_ENERGY_TOLERANCE,
    );
    let out = spatter(&[
        "run",
        "--backend",
        "cpu",
        &scene("melt_block_3d"),
        "--until",
        "4e-4",
        "--out",
        mcap.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{:?}", text(&out));
    let r = common::reader(&["summary", mcap.to_str().unwrap()]);
    let sum: serde_json::Value = serde_json::from_slice(&r.stdout).expect("summary");
    let peak = &sum["diagnostics_max"];
    assert!(peak["max_temperature"].as_f64().unwrap() > 1705.0, "{peak}");
    assert!(peak["melted_volume"].as_f64().unwrap() > 0.0, "{peak}");
    assert!(peak["pool_depth"].as_f64().unwrap() >= 5.0e-6, "{peak}");
    // Beam off at 3e-4 s: by 4e-4 s every particle is solid again.
    let last = &sum["last_diagnostics"];
    assert_eq!(last["particles"]["melt"], 0, "{last}");
    assert_eq!(last["melted_volume"].as_f64(), Some(0.0), "{last}");
}

/// Radiation from the free surface of a hot plate (beam off): the enthalpy lost
/// equals σ ε (T⁴ − T_a⁴) integrated over the surface and time, and the power is
/// within 2% of the flat-surface value σ (T⁴ − T_a⁴) × width (the two corner
/// columns next to the side walls radiate less).
#[test]
fn radiation_loss_balances_and_matches_the_flat_surface_flux() {
    let sets = [
        "laser.power=[[0.0, 0.0]]",
        "phases.plate.temperature=2000.0",
        "materials.steel.emissivity=1.0",
        "laser.model=\"gaussian_surface\"",
    ];
    assert_check("laser_flat_plate", &sets, LASER_ENERGY_TOLERANCE);
    let (l, r) = common::run_loaded(
        &scene("laser_flat_plate"),
        &sets,
        Some(EndCondition::Steps(1)),
    );
    let radiated = heat_diagnostics(&l.model, &r.final_state)
        .expect("a heat scene")
        .radiated_power;
    // σ (CODATA 2018) written out, not the simulator's constant.
    let ideal = 5.670374419e-8 * (2000f64.powi(4) - 300f64.powi(4)) * 4.0e-4;
    assert!(
        (radiated / ideal - 1.0).abs() < FLAT_SURFACE_FLUX_TOLERANCE,
        "{radiated} vs {ideal}"
    );
}

/// A moving source over a plate, conduction only, against Rosenthal's
/// quasi-steady solution (window and normalisation in checks/heat.rs, rosenthal).
#[test]
fn rosenthal_scan_line_within_5_percent() {
    assert_check("rosenthal_2d", &[], ROSENTHAL_TOLERANCE);
}

/// The surface flux through the condensed–gas interface of F22 (19)–(20).
#[test]
fn laser_through_the_gas_interface_within_1_percent() {
    assert_check("laser_plate_under_gas_2d", &[], LASER_ENERGY_TOLERANCE);
}

/// Viscous heating (R18 (3.43)–(3.44) role, written as the power the F22 (23)
/// viscous force dissipates): in start-up Couette flow the enthalpy gained between
/// t = 0.1 and 0.2 s equals η W ∫(∂u/∂y)² dy dt from the series solution,
/// η W U²/L [Δt + 2 Σ_n (e^{−a t1} − e^{−a t2})/a], a = 2 n²π²ν/L². Measured +0.06%;
/// 3% leaves room for the kernel-discretised shear near the walls at other settings.
#[test]
fn viscous_heating_matches_couette_dissipation() {
    let sets: Vec<String> = [
        "materials.fluid.conductivity=0.6",
        "materials.fluid.heat_capacity=4186.0",
        "phases.liquid.temperature=300.0",
        "simulation.viscous_heating=true",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let l = spatter::run::load(&scene("couette_2d"), &sets).unwrap();
    let mut b = spatter::run::make_backend(spatter::run::BackendChoice::Cpu, &l, false).unwrap();
    b.prime();
    // Stored enthalpies are relative to the initial temperature, so their sum
    // resolves the tiny heating directly.
    let stored = |st: &spatter::state::State| -> f64 {
        (0..st.len())
            .filter(|&i| l.model.phases[st.phase[i] as usize].conducts())
            .map(|i| st.mass[i] as f64 * st.heat[i][0] as f64)
            .sum()
    };
    let mut samples = vec![];
    for target in [0.1, 0.2] {
        while (b.read_sim().unwrap().time as f64) < target {
            b.run_steps(1);
        }
        let st = b.read_state().unwrap();
        samples.push((st.sim.time as f64, stored(&st)));
    }
    let (eta, u, len, width, nu) = (1e-3, 2.5e-5f64, 1e-3, 6e-4, 1e-6);
    let (t1, t2) = (samples[0].0, samples[1].0);
    let series: f64 = (1..400)
        .map(|n| {
            let a = 2.0 * (n * n) as f64 * std::f64::consts::PI.powi(2) * nu / (len * len);
            2.0 * ((-a * t1).exp() - (-a * t2).exp()) / a
        })
        .sum();
    let exact = eta * width * u * u / len * (t2 - t1 + series);
    let got = samples[1].1 - samples[0].1;
    println!(
        "viscous heating {got:e} J/m vs series {exact:e} J/m ({:+.2}%)",
        100.0 * (got / exact - 1.0)
    );
    assert!((got / exact - 1.0).abs() < 0.03, "{got} vs {exact}");
}

/// The F22 §4.5 line-melting schedule on a bare plate (scenarios/pbf): the coarse
/// quick-look setting its header names runs and melts a track.
#[test]
fn line_melt_example_runs_at_its_quick_look_resolution() {
    let path = format!(
        "{}/scenarios/pbf/line_melt_bare_plate.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let (l, r) = common::run_loaded(&path, &["dx=2e-5"], Some(EndCondition::Time(1.2e-4)));
    assert_eq!(r.end, spatter::run::RunEnd::Completed);
    let heat = heat_diagnostics(&l.model, &r.final_state).expect("a heat scene");
    assert!(heat.melted_volume > 0.0, "{heat:?}");
}

/// A particle without a temperature (adiabatic_box's insulating
/// walls have none) is written as the scene's ambient temperature, not 0 K, so a
/// colour scale over a frame spans only the temperatures the scene has.
#[test]
fn particles_without_a_temperature_write_the_ambient_temperature() {
    let l = spatter::run::load(&common::scene("adiabatic_box"), &[]).unwrap();
    let fields = spatter::output::heat_channels(&l.model, &l.state);
    let t = fields.iter().find(|f| f.name == "temperature").unwrap();
    let spatter::output::Values::F32(t) = &t.values else {
        panic!("temperature is f32")
    };
    let insulation = l.model.phase_index("insulation").unwrap() as u32;
    let mut walls = 0;
    for (i, &ti) in t.iter().enumerate() {
        assert!(ti.is_finite() && ti > 1.0, "particle {i}: {ti} K");
        if l.state.phase[i] == insulation {
            assert_eq!(ti, l.model.ambient_temperature as f32);
            walls += 1;
        }
    }
    assert!(walls > 0);
}

/// The README's first command (on δ-SPH since that formulation landed): the
/// coarse 2D line melt with surface tension, Marangoni and recoil runs to its end
/// (no watchdog stop), writes an MCAP whose /track `tools/spatter_read.py track`
/// plots, and prints the melt pool and the track. F22 §4.5 reports only shapes:
/// the hottest melt passes T_v = 3000 K (measured 3258 K), the remelt depth is
/// largest where the scan starts (measured 21.8 against 11.7 µm, means of the
/// first and last tenth of the track; 19.9 against 10.9 on summation density),
/// and the resolidified surface ends below the initial one (measured −2.3 µm on
/// average).
#[test]
fn coarse_line_melt_main_job() {
    let dir = common::scratch("coarse_line_melt");
    let mcap = dir.join("line_melt.mcap");
    let path = format!(
        "{}/scenarios/pbf/line_melt_coarse_2d.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let l = spatter::run::load(&path, &[]).unwrap();
    let mut out = common::mcap_outputs(&mcap, &l.model);
    let r = common::run_with_outputs(&path, &[], None, &mut out);
    assert_eq!(r.end, spatter::run::RunEnd::Completed);
    assert!(r.check.as_ref().is_none_or(|c| c.pass));
    let track = r.track.expect("a melt track");
    assert!(track.pool.max_temperature > 3000.0, "{:?}", track.pool);
    let (start, end) = track.end_depths().expect("melted slices");
    assert!(start > end, "first tenth {start}, last tenth {end}");
    let height = track.mean(|s| s.height);
    assert!(height < 0.0, "surface height mean {height}");
    // The depression under the beam reaches /diagnostics (9.9e-6 m at most,
    // measured; half a row is asked) and the track its own channel.
    let r = common::reader(&["summary", mcap.to_str().unwrap()]);
    let sum: serde_json::Value = serde_json::from_slice(&r.stdout).expect("summary");
    let sunk = sum["diagnostics_max"]["depression_depth"].as_f64().unwrap();
    assert!(sunk >= 5.0e-6, "{sum}");
    // The scan covers 640 µm = 64 slices (68 measured with the beam's reach).
    assert!(sum["track_slices"].as_u64().unwrap() >= 60, "{sum}");
    let png = dir.join("track.png");
    let r = common::reader(&["track", mcap.to_str().unwrap(), png.to_str().unwrap()]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);
    // The reader as a package: the same run as DataFrames.
    let py = "import sys, json; import spatter_read as s; p = sys.argv[1]; \
              d = s.diagnostics(p); ps = s.pool_series(p); fr = s.frames(p); \
              tr = s.track_slices(p); \
              print(json.dumps([len(d), float(ps['pool_length'].max()), len(fr), \
              fr[-1].attrs['time'], int(len(fr[-1])), 'temperature' in fr[-1], \
              len(tr), float(tr['depth'].max())]))";
    let o = std::process::Command::new(common::python())
        .args(["-c", py, mcap.to_str().unwrap()])
        .output()
        .unwrap();
    let (so, se) = common::text(&o);
    let v: serde_json::Value =
        serde_json::from_str(so.trim()).unwrap_or_else(|_| panic!("{so}{se}"));
    assert_eq!(v[0].as_u64(), sum["diagnostics"].as_u64(), "{v} {sum}");
    let longest = sum["diagnostics_max"]["pool_length"].as_f64().unwrap();
    assert!(
        (v[1].as_f64().unwrap() - longest).abs() <= 1e-12 * longest,
        "{v} {sum}"
    );
    assert_eq!(v[2].as_u64(), sum["frames"].as_u64(), "{v} {sum}");
    assert!(
        v[4].as_u64().unwrap() > 1000 && v[5].as_bool() == Some(true),
        "{v}"
    );
    assert!(v[6].as_u64().unwrap() >= 60, "{v}");
    assert!(
        (v[7].as_f64().unwrap() - track.slices.iter().map(|s| s.depth).fold(0.0, f64::max)).abs()
            < 1e-9,
        "{v}"
    );
}

/// A Dirichlet wall particle appears in frames at its fixed
/// temperature, not at the mirror temperature 2 T_wall − T̃ the conduction pass
/// gives it (which falls below T_wall beside a colder solid: 2·400 − 300 = 500 K
/// here at the start, and went to −681 K under a melt pool), with enthalpy 0.
#[test]
fn dirichlet_walls_appear_in_frames_at_their_own_temperature() {
    use spatter::output::{heat_channels, Values};
    let (l, r) = common::run_loaded(&scene("conduction_1d"), &["run.end_time=5.0"], None);
    let (m, st) = (&l.model, &r.final_state);
    let fields = heat_channels(m, st);
    let column = |name: &str| match &fields.iter().find(|f| f.name == name).unwrap().values {
        Values::F32(v) => v.clone(),
        _ => panic!("{name} is not f32"),
    };
    let (t, h) = (column("temperature"), column("enthalpy"));
    let walls: Vec<usize> = (0..st.len())
        .filter(|&i| m.phases[st.phase[i] as usize].kind == spatter::scene::PhaseKind::Wall)
        .collect();
    assert!(!walls.is_empty());
    // The mirror temperature the state holds differs from T_wall somewhere.
    assert!(walls
        .iter()
        .any(|&i| (st.heat[i][spatter::state::H_TEMPERATURE] - 400.0).abs() > 1.0));
    for &i in &walls {
        assert_eq!(t[i], 400.0, "wall particle {i}");
        assert_eq!(h[i], 0.0, "wall particle {i}");
    }
}

/// Melt apart from the pool (a splashed droplet) is detached
/// and does not stretch the pool. On line_melt_coarse_2d's plate, a 10 × 5
/// particle pool at the surface and a one-particle droplet lifted 3 Δx clear
/// 30 spacings along x: without the track (the largest region) the pool is 10 Δx
/// long and 5 Δx high (the droplet used to make it 31 Δx long), one detached
/// region of one particle with the droplet's mass. The track's pool is the
/// same, 5 Δx deep below the initial surface; a second patch of melt in the
/// plate, parted from the first by one solid column, is detached too.
#[test]
fn pool_figures_ignore_a_splashed_droplet() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/pbf/line_melt_coarse_2d.toml"
    );
    let l = spatter::run::load(path, &[]).unwrap();
    let (m, mut st) = (l.model, l.state);
    let initial = st.clone();
    let plate: Vec<usize> = (0..st.active())
        .filter(|&i| m.phases[st.phase[i] as usize].kind == spatter::scene::PhaseKind::Solid)
        .collect();
    let x = |i: usize| m.to_world(st.pos[i]);
    let top = plate
        .iter()
        .map(|&i| x(i)[1])
        .fold(f64::NEG_INFINITY, f64::max);
    let x0 = plate.iter().map(|&i| x(i)[0]).fold(f64::INFINITY, f64::min) + 20.0 * m.dx;
    let inside = |p: [f64; 3], cols: f64, rows: f64| {
        p[0] > x0 - 0.5 * m.dx
            && p[0] < x0 + (cols - 0.5) * m.dx
            && p[1] > top - (rows - 0.5) * m.dx
    };
    let (mut pool, mut drop_mass) = (0, 0.0);
    let world: Vec<[f64; 3]> = (0..st.active()).map(x).collect();
    for &i in &plate {
        let p = world[i];
        let droplet = (p[0] - (x0 + 40.0 * m.dx)).abs() < 0.5 * m.dx && p[1] > top - 0.5 * m.dx;
        if inside(p, 10.0, 5.0) || droplet {
            st.heat[i][2] = 1.0;
            if droplet {
                drop_mass = st.mass[i] as f64;
                // Lift it clear of the plate.
                st.pos[i][1] += (3.0 * m.dx) as f32;
            } else {
                pool += 1;
            }
        }
    }
    assert_eq!(pool, 50);
    let h = heat_diagnostics(&m, &st).unwrap();
    let close = |a: f64, b: f64| (a - b).abs() < 1e-3 * m.dx;
    assert!(close(h.pool_length, 10.0 * m.dx), "{h:?}");
    assert!(close(h.pool_depth, 5.0 * m.dx), "{h:?}");
    assert!(close(h.pool_volume, 50.0 * m.dx * m.dx), "{h:?}");
    assert_eq!((h.detached_melt_regions, h.detached_melt_particles), (1, 1));
    assert!((h.detached_melt_mass - drop_mass).abs() < 1e-9 * drop_mass);
    let mut track = spatter::track::Track::new(&m, &initial).unwrap();
    track.observe(&m, &st);
    let p = track.pool_now();
    assert!(
        close(p.length, 10.0 * m.dx) && close(p.depth, 5.0 * m.dx),
        "{p:?}"
    );
    assert_eq!((p.detached_regions, p.detached_particles), (1, 1));
    // A 3 × 2 patch one solid column beyond the pool's end.
    for &i in &plate {
        let p = world[i];
        if p[0] > x0 + 10.5 * m.dx && p[0] < x0 + 13.5 * m.dx && p[1] > top - 1.5 * m.dx {
            st.heat[i][2] = 1.0;
        }
    }
    track.observe(&m, &st);
    let p = track.pool_now();
    assert!(close(p.length, 10.0 * m.dx), "{p:?}");
    assert!(close(p.volume, 50.0 * m.dx * m.dx), "{p:?}");
    assert_eq!((p.detached_regions, p.detached_particles), (2, 7));
}

/// `run.stop_when = "solidified"` ends the README's line melt
/// once the beam is off (3.7e-4 s) and no melt is left, before its 6e-4 s, and
/// says why; with `run.stop_grace` it ends that long after the beam went off
/// with melt still there. Without a laser the key is refused (exit 2).
#[test]
fn a_laser_run_stops_when_the_melt_has_solidified() {
    let melt = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/pbf/line_melt_coarse_2d.toml"
    );
    let stop = "run.stop_when=\"solidified\"";
    let r = common::run_path(melt, &[stop], None);
    let why = r.stop_reason.expect("a reason");
    assert!(why.contains("no melt is left"), "{why}");
    assert!(r.sim_time > 3.7e-4 && r.sim_time < 5.9e-4, "{}", r.sim_time);
    let r = common::run_path(melt, &[stop, "run.stop_grace=1e-6"], None);
    let why = r.stop_reason.expect("a reason");
    assert!(why.contains("still molten"), "{why}");
    assert!(r.sim_time < 3.9e-4, "{}", r.sim_time);
    common::assert_input_error(
        &["validate", &scene("dam_break_2d"), "--set", stop],
        "run.stop_when",
    );
    common::assert_input_error(
        &["validate", melt, "--set", "run.stop_grace=1e-5"],
        "run.stop_grace",
    );
}

/// The two-material bar with both materials' properties given as tables
/// (`enthalpy_table`, `conductivity_table`), written to a scratch scene.
fn tabled_bar(name: &str, enthalpy: &str, conductivity: &str) -> String {
    let text = std::fs::read_to_string(scene("conduction_two_materials")).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        let t = line.trim_start();
        if t.starts_with("heat_capacity") {
            out.push_str(&format!("enthalpy_table = {enthalpy}\n"));
        } else if t.starts_with("conductivity") {
            out.push_str(&format!("conductivity_table = {conductivity}\n"));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    let path = common::scratch(name).with_extension("toml");
    std::fs::write(&path, out).unwrap();
    path.to_string_lossy().into_owned()
}

/// Tables that repeat the constant material (c = 1000 J/(kg K), λ = 1 W/(m K)
/// in both layers: the check's two-layer reference then holds with k1 = k2)
/// give the constant material's steady profile: the check's figure to 1e-4 of
/// the temperature scale (the stored enthalpy's origin differs, so the bits do).
#[test]
fn tables_that_repeat_constants_give_the_same_profile() {
    let same = tabled_bar(
        "tabled_constant_bar",
        "[[200.0, 2.0e5], [600.0, 6.0e5]]",
        "[[200.0, 1.0], [600.0, 1.0]]",
    );
    let tabled = common::run_path(&same, &[], None).check.expect("a check");
    let constant = run_check(
        "conduction_two_materials",
        &["materials.high_k.conductivity=1.0"],
    );
    assert!(
        (tabled.value - constant.value).abs() < 1e-4,
        "tabled {} against constant {}",
        tabled.line(),
        constant.line()
    );
}

/// scenarios/validation/conduction_tables_2d: λ(T) = 1 + 0.01 (T − 300) W/(m K)
/// (1 at the cold wall, 3 at the hot one) and an h(T) whose slope steps at
/// 400 K. The steady profile is linear in Kirchhoff's
/// Θ = ∫_300^T λ dT = (T − 300) + 0.005 (T − 300)², Θ = 400 (1 − y/L), so
/// T = 300 + (√(1 + 0.02 Θ) − 1)/0.01; a constant λ would give the straight
/// line 200 (1 − y/L), up to 25 K (12%) away in the middle. Every particle
/// within 1% of the 200 K scale (the conduction tolerance; measured 0.63%).
#[test]
fn conductivity_table_gives_kirchhoffs_steady_profile() {
    let (loaded, r) = common::run_loaded(&scene("conduction_tables_2d"), &[], None);
    let m = &loaded.model;
    let st = &r.final_state;
    let l = 0.02;
    let mut worst: f64 = 0.0;
    for i in 0..st.active() {
        if !m.phases[st.phase[i] as usize].conducts() {
            continue;
        }
        let y = m.to_world(st.pos[i])[1];
        let theta = 400.0 * (1.0 - y / l);
        let exact = 300.0 + ((1.0 + 0.02 * theta).sqrt() - 1.0) / 0.01;
        let t = st.heat[i][spatter::state::H_TEMPERATURE] as f64;
        worst = worst.max((t - exact).abs() / 200.0);
    }
    assert!(
        worst < CONDUCTION_TOLERANCE,
        "largest error {worst:.4} of 200 K"
    );
    println!("lambda(T) bar: largest error {worst:.3e} of 200 K");
}

/// Table input: each bad table and each constant it replaces exits 2 naming the key.
#[test]
fn bad_tables_name_the_key() {
    let tabled = tabled_bar(
        "tabled_bad_bar",
        "[[200.0, 2.0e5], [600.0, 6.0e5]]",
        "[[200.0, 1.0], [600.0, 1.0]]",
    );
    for (set, key) in [
        (
            "materials.low_k.enthalpy_table=[[300.0, 3.0e5]]",
            "materials.low_k.enthalpy_table",
        ),
        (
            "materials.low_k.enthalpy_table=[[300.0, 3.0e5], [200.0, 4.0e5]]",
            "materials.low_k.enthalpy_table",
        ),
        (
            "materials.low_k.enthalpy_table=[[300.0, 3.0e5], [400.0, 2.0e5]]",
            "materials.low_k.enthalpy_table",
        ),
        (
            "materials.low_k.conductivity_table=[[300.0, -1.0], [400.0, 2.0]]",
            "materials.low_k.conductivity_table",
        ),
    ] {
        common::assert_input_error(&["validate", &tabled, "--set", set], key);
    }
    for (set, key) in [
        (
            "materials.low_k.heat_capacity=1000.0",
            "materials.low_k.heat_capacity",
        ),
        (
            "materials.low_k.latent_heat=1.0e5",
            "materials.low_k.latent_heat",
        ),
        (
            "materials.low_k.conductivity=1.0",
            "materials.low_k.conductivity",
        ),
    ] {
        common::assert_input_error(&["validate", &tabled, "--set", set], key);
    }
}

/// An enthalpy table through the band model's own points (c = 1000 J/(kg K),
/// L = 1e5 J/kg spread over [599.5, 600.5] K: the kinks of h(T) are the table's
/// points) melts stefan_1d's bar as the constants do: every particle's
/// temperature after 200 s within 0.1 K of the constant material's (of 100 K
/// over the bar; the stored enthalpy's origin and so its rounding differ).
#[test]
fn enthalpy_table_with_latent_heat_melts_as_the_band_model() {
    let text = std::fs::read_to_string(scene("stefan_1d")).unwrap();
    let table =
        "enthalpy_table = [[500.0, 5.0e5], [599.5, 5.995e5], [600.5, 7.005e5], [800.0, 9.0e5]]\n";
    let mut out = String::new();
    // Without the check: stefan_1d's reference takes constant properties.
    for line in text[..text.find("[check]").unwrap()].lines() {
        let t = line.trim_start();
        if t.starts_with("heat_capacity") {
            out.push_str(table);
        } else if !t.starts_with("latent_heat") {
            out.push_str(line);
            out.push('\n');
        }
    }
    let path = common::scratch("tabled_stefan").with_extension("toml");
    std::fs::write(&path, out).unwrap();
    let tabled = common::run_path(&path.to_string_lossy(), &[], None).final_state;
    let constant = common::run_path(&scene("stefan_1d"), &[], None).final_state;
    assert_eq!(tabled.active(), constant.active());
    let t = spatter::state::H_TEMPERATURE;
    let (mut worst, mut melted) = (0.0f32, 0);
    for i in 0..tabled.active() {
        assert_eq!(tabled.id[i], constant.id[i]);
        worst = worst.max((tabled.heat[i][t] - constant.heat[i][t]).abs());
        if constant.heat[i][t] > 600.5 && constant.phase[i] == tabled.phase[i] {
            melted += 1;
        }
    }
    assert!(
        melted > 100,
        "the bar melts ({melted} particles above the liquidus)"
    );
    assert!(worst < 0.1, "largest temperature difference {worst} K");
    println!("tabled Stefan bar: largest temperature difference {worst:.3e} K");
}

/// κ for the three kernels at the h/Δx where it was measured by the absorbed
/// power on a flat plate without normalisation (quintic at Δx 1.0595,
/// Wendland at 1.2Δx 1.0284, the cubic at Δx 1.1081; at today's defaults
/// this file holds the normalised absorbed power to 1%).
#[test]
fn surface_delta_integral_matches_the_flat_plate_measurement() {
    let expected = [
        ("quintic", 1.0, 1.0595),
        ("wendland_c2", 1.2, 1.0284),
        ("cubic", 1.0, 1.1081),
    ];
    for (k, h_over_dx, kappa) in expected {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/validation/laser_flat_plate.toml"
        );
        let sets = vec![
            format!("kernel=\"{k}\""),
            format!("h_over_dx={h_over_dx}"),
            "laser.model=\"gaussian_surface\"".to_string(),
        ];
        let l = spatter::load::load(path, &sets).unwrap();
        let p = spatter::params::Params::new(&l.model, l.state.len() as u32);
        let got = spatter::params::surface_delta_integral(&p, l.model.dx);
        assert!((got - kappa).abs() < 1e-4, "{k}: {got}");
    }
}
