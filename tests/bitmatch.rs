//! Bit-match contract (docs/backends.md): on the software adapter (lavapipe) the GPU passes
//! give the same bits as their CPU twins, every field after every pass of 200 steps.

mod common;
use spatter::backend::cpu::CpuBackend;
use spatter::backend::gpu::{AdapterChoice, GpuBackend, GpuContext};
use spatter::compare::{compare, CompareMode, ToleranceScales};
use spatter::params::Params;
use spatter::run::load;

/// Returns the particles removed by the end.
fn assert_bit_identical(name: &str, sets: &[&str], steps: u64) -> u32 {
    assert_bit_identical_at(&common::scene(name), sets, steps).removed
}

/// The same for a scene file anywhere; returns the CPU's final Sim.
fn assert_bit_identical_at(path: &str, sets: &[&str], steps: u64) -> spatter::state::Sim {
    bit_identical_state(path, sets, steps).sim
}

/// The same, returning the CPU's final state.
fn bit_identical_state(path: &str, sets: &[&str], steps: u64) -> spatter::state::State {
    bit_identical_prepared(path, sets, steps, |_| {})
}

/// The same from the scene's initial state as `prepare` leaves it.
fn bit_identical_prepared(
    path: &str,
    sets: &[&str],
    steps: u64,
    prepare: impl FnOnce(&mut spatter::state::State),
) -> spatter::state::State {
    let name = path;
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let mut l = load(path, &sets).unwrap();
    prepare(&mut l.state);
    let params = Params::new(&l.model, l.state.len() as u32);
    std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    let ctx = GpuContext::open(AdapterChoice::AnyGpu, false)
        .expect("a Vulkan adapter (the test command installs lavapipe)");
    assert!(
        ctx.is_software(),
        "bit-match needs the software adapter; hardware is compared by tolerance"
    );
    let mut gpu = GpuBackend::new(ctx, params, &l.state, false).unwrap();
    let mut cpu = CpuBackend::new(params, l.state.clone());
    let report = compare(&mut cpu, &mut gpu, steps, &CompareMode::Exact).unwrap();
    if let Some(d) = report.first_difference {
        panic!(
            "{name} {sets:?}: step {} pass {} field {} particle {}: cpu {} gpu {}",
            d.step, d.pass, d.field, d.particle, d.cpu, d.gpu
        );
    }
    // Every stage as the GPU records it (a repeat's max_iterations times).
    let stages = spatter::backend::Pipeline::for_scene(&params, &l.state);
    let prime: usize = stages.prime.iter().map(|n| n.recorded().len()).sum();
    assert_eq!(
        report.stages_compared,
        (prime + stages.recorded_step().len() * steps as usize) as u64
    );
    cpu.st
}

#[test]
fn dam_break_2d_200_steps() {
    assert_bit_identical("dam_break_2d", &[], 200);
}

/// Particles leave through an open side (from step 111 on), are sorted
/// after every cell and skipped by every pass, the same on both backends.
#[test]
fn jet_outflow_2d_with_removals_200_steps() {
    let removed = assert_bit_identical("jet_outflow_2d", &[], 200);
    assert!(removed >= 16, "{removed} particles left in 200 steps");
}

/// The F22 (34) wall barrier: the jet of jet_outflow_2d moved down to the floor
/// and thrown at it at 6 m/s, so that particles come within r_b of the wall
/// particles from step 60 on (the barrier changes the state: checked against the
/// same run without it).
#[test]
fn wall_barrier_on_a_jet_into_the_floor_200_steps() {
    let text = std::fs::read_to_string(common::scene("jet_outflow_2d"))
        .unwrap()
        .replace(
            "min = [0.15, 0.08], max = [0.29, 0.12]",
            "min = [0.15, 0.02], max = [0.29, 0.06]",
        )
        .replace("velocity = [1.5, 0.0]", "velocity = [1.5, -6.0]");
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("bitmatch_barrier");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("jet_into_floor.toml");
    std::fs::write(&path, text).unwrap();
    let path = path.to_str().unwrap();
    let barrier = "simulation.barrier={radius_dx=0.75, stiffness=1.0e5, damping=2.0e4}";
    let with = assert_bit_identical_at(path, &[barrier], 200);
    let l = load(path, &[]).unwrap();
    let mut plain = CpuBackend::new(Params::new(&l.model, l.state.len() as u32), l.state.clone());
    use spatter::backend::Backend;
    plain.prime();
    plain.run_steps(200);
    assert_ne!(with, plain.st.sim, "the barrier acted (Δt follows |a|max)");
}

#[test]
fn poiseuille_2d_periodic_200_steps() {
    assert_bit_identical("poiseuille_2d", &[], 200);
}

#[test]
fn two_layer_2d_200_steps() {
    assert_bit_identical("two_layer_2d", &[], 200);
}

/// F22 (31)–(32) interface viscosity at density ratio 1000, 2D and 3D.
#[test]
fn interface_viscosity_ratio_1000_200_steps() {
    assert_bit_identical("two_layer_ratio1000_2d", &[], 200);
    // 4 312 particles at Δx = 0.0125 instead of 6 656 (the interface sweeps
    // are the same; the finer lattice cost 45 s here on lavapipe).
    assert_bit_identical("two_layer_ratio1000_3d", &["dx=0.0125"], 200);
}

#[test]
fn couette_2d_moving_wall_200_steps() {
    assert_bit_identical("couette_2d", &[], 200);
}

/// A gate lifted out of the tank (moving wall particles, wall pass and neighbour
/// sort on moving walls), and a lid that slides along a periodic axis, wrapping.
#[test]
fn moving_walls_200_steps() {
    assert_bit_identical("dam_break_gate_2d", &[], 200);
    assert_bit_identical("couette_2d", &common::TRANSLATING_LID, 200);
}

/// Periodic on both axes: no wall particles, so no wall pass.
#[test]
fn fully_periodic_without_wall_pass_100_steps() {
    assert_bit_identical("poiseuille_2d", &["domain.periodic=[true,true]"], 100);
}

/// The other two kernels, in 2D and 3D.
#[test]
fn wendland_and_cubic_kernels_50_steps() {
    assert_bit_identical("poiseuille_2d", &["kernel=\"wendland_c2\""], 50);
    assert_bit_identical("dam_break_2d", &["kernel=\"cubic\"", "dx=0.005"], 50);
    assert_bit_identical("dam_break_3d", &["kernel=\"wendland_c2\"", "dx=0.02"], 50);
    assert_bit_identical("dam_break_3d", &["kernel=\"cubic\"", "dx=0.02"], 50);
}

/// The `spatter compare` command, as a user runs it, over 50 steps: the library
/// cases run dam_break_3d 200 steps (heat_in_a_flowing_liquid_3d_200_steps,
/// dfsph_dam_break_2d_and_3d_200_steps); 200 here cost CI about 40 s more.
#[test]
fn compare_cli_dam_break_3d_50_steps() {
    let out = common::spatter(&["compare", &common::scene("dam_break_3d"), "--steps", "50"]);
    let (stdout, stderr) = common::text(&out);
    assert!(
        stdout.trim_end().ends_with("bit-identical: yes"),
        "{stdout}{stderr}"
    );
    assert_eq!(out.status.code(), Some(0));
}

/// Heat: conduction with Dirichlet walls and two materials, melting
/// through the enthalpy band, an adiabatic box, and heat carried by a flowing 3D
/// liquid (reordered every step with the other arrays).
#[test]
fn heat_passes_200_steps() {
    assert_bit_identical("stefan_1d", &[], 200);
    assert_bit_identical("conduction_two_materials", &[], 200);
    // h(T) and λ(T) from tables.
    assert_bit_identical("conduction_tables_2d", &[], 200);
    assert_bit_identical("adiabatic_box", &[], 200);
    assert_bit_identical("laser_flat_plate", &[], 200);
    assert_bit_identical(
        "laser_flat_plate",
        &["laser.model=\"gaussian_surface\""],
        200,
    );
    // F22 (19)-(20) interface between the plate and gas particles.
    assert_bit_identical("laser_plate_under_gas_2d", &[], 200);
    // Radiation through the free surface of a hot plate.
    assert_bit_identical(
        "laser_flat_plate",
        &[
            "laser.model=\"gaussian_surface\"",
            "materials.steel.emissivity=0.8",
            "phases.plate.temperature=1800.0",
        ],
        200,
    );
    // A moving beam switched off half-way.
    assert_bit_identical(
        "laser_flat_plate",
        &[
            "laser.power=[[0.0, 2.0e4], [1.0e-4, 0.0]]",
            "laser.path=[[0.0, 1.0e-4], [2.0e-4, 3.0e-4]]",
        ],
        200,
    );
}

/// Viscous heating in sheared flow (forces pass writes it, heat pass adds it).
#[test]
fn viscous_heating_couette_200_steps() {
    assert_bit_identical(
        "couette_2d",
        &[
            "materials.fluid.conductivity=0.6",
            "materials.fluid.heat_capacity=4186.0",
            "phases.liquid.temperature=300.0",
            "simulation.viscous_heating=true",
        ],
        200,
    );
}

const HOT_WATER: [&str; 4] = [
    "materials.water.conductivity=0.6",
    "materials.water.heat_capacity=4186.0",
    "phases.water.temperature=350.0",
    "phases.wall.temperature=290.0",
];

#[test]
fn heat_in_a_flowing_liquid_3d_200_steps() {
    let mut sets = HOT_WATER.to_vec();
    sets.push("dx=0.02");
    assert_bit_identical("dam_break_3d", &sets, 200);
}

#[test]
fn heat_in_a_flowing_liquid_2d_200_steps() {
    assert_bit_identical("dam_break_2d", &HOT_WATER, 200);
}

/// The melt block over 200 steps, through the start of melting (solid
/// particles switching to liquid and flowing) under the surface laser: interface,
/// laser, heat and phase passes.
#[test]
fn melt_block_3d_200_steps() {
    assert_bit_identical_text("melt_block_small_3d", &melt_block_small_3d(), 200);
}

/// melt_block_3d on a quarter of its footprint and 30 µm deep (3 084 particles
/// instead of 10 168, the beam still at the centre): every pass of the full
/// block, and it melts more within 200 steps (7.8e-15 m³ against 2.8e-15: the
/// beam's power goes into less steel). The full block cost 100 s here on
/// lavapipe, most of it the interface and conduction sweeps over the solid.
fn melt_block_small_3d() -> String {
    let text = std::fs::read_to_string(common::scene("melt_block_3d")).unwrap();
    let swaps = [
        (
            "max = [1.0e-4, 1.0e-4, 6.0e-5]",
            "max = [5.0e-5, 5.0e-5, 4.0e-5]",
        ),
        (
            "box = { min = [0.0, 0.0, 0.0], max = [1.0e-4, 1.0e-4, 5.0e-5] }",
            "box = { min = [0.0, 0.0, 0.0], max = [5.0e-5, 5.0e-5, 3.0e-5] }",
        ),
        (
            "path = [[0.0, 5.0e-5, 5.0e-5]]",
            "path = [[0.0, 2.5e-5, 2.5e-5]]",
        ),
    ];
    swaps.iter().fold(text, |t, (from, to)| {
        assert!(t.contains(from), "melt_block_3d.toml no longer has {from}");
        t.replace(from, to)
    })
}

/// A repeat node: R18's trapezoidal heat, a fixed-point
/// iteration ended by the device's converged flag, with Dirichlet mirror walls
/// at the conduction limit's Δt (conduction_1d: the iteration contracts by about
/// 0.46 per round there, so 1e-3 takes ~9), through the melting band (stefan_1d)
/// and under a Beer–Lambert laser (laser_flat_plate). The iterations the CPU
/// skips after convergence return at once on the GPU. (Tolerances below ~1e-5
/// meet the f32 rounding of the rates and do not converge.)
#[test]
fn implicit_heat_repeat() {
    let scenes = [
        ("conduction_1d", 1.0e-3, 40),
        ("stefan_1d", 1.0e-4, 100),
        ("laser_flat_plate", 1.0e-4, 100),
    ];
    for (name, tolerance, steps) in scenes {
        let implicit = format!(
            "\n[heat]\nintegrator = \"trapezoidal\"\ntolerance = {tolerance:e}\nmax_iterations = 12\n"
        );
        let text = std::fs::read_to_string(common::scene(name)).unwrap() + &implicit;
        let st = assert_bit_identical_text(&format!("{name}_implicit"), &text, steps);
        let s = st.solvers[spatter::backend::SolverSlot::Heat as usize];
        assert!(s.iterations >= 2, "{name}: {s:?}");
        assert!(
            s.converged == 1 && s.residual <= tolerance as f32,
            "{name}: {s:?}"
        );
    }
}

const DELTA: &str = "simulation.formulation=\"delta_wcsph\"";

/// R18's δ-SPH (continuity density, the same-phase density diffusion,
/// the Shepard pressure R18 (3.17); sorted density), 2D and 3D: a dam break
/// against walls, liquid under gas at density ratio 1000, the free-surface
/// tension disc, and R18 (3.18)'s viscosity option in a channel.
#[test]
fn delta_sph_2d_and_3d() {
    assert_bit_identical("dam_break_2d", &[DELTA], 100);
    assert_bit_identical("two_layer_ratio1000_2d", &[DELTA], 100);
    assert_bit_identical("laplace_free_disc_2d", &[DELTA], 200);
    assert_bit_identical(
        "poiseuille_2d",
        &[DELTA, "simulation.viscosity_form=\"marrone\""],
        200,
    );
    assert_bit_identical("dam_break_3d", &[DELTA, "dx=0.02"], 100);
}

/// δ-SPH with heat and melting, and with rigid bodies in a walled liquid (the
/// body pass's reaction through the Shepard pressure); the line melt's forces on
/// summation density (the main job's scene runs δ-SPH in
/// `line_melt_with_every_force_200_steps`).
#[test]
fn delta_sph_with_heat_and_bodies() {
    bit_identical_text_with("melt_block_small_3d", &melt_block_small_3d(), &[DELTA], 100);
    assert_bit_identical("settling_disc_2d", &[DELTA], 100);
    assert_bit_identical_at(
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/pbf/line_melt_coarse_2d.toml"
        ),
        &[
            "simulation.formulation=\"wcsph\"",
            "simulation.pressure_floor=true",
            "phases.plate.temperature=1650.0",
            "laser.power=[[0.0, 4.0e6]]",
        ],
        200,
    );
}

/// Thermal expansion on δ-SPH: a density law ρ0(T) in the EOS and the
/// diffusion, temperatures imposed by a program (the portable sine of R18
/// Test 1's cycle, Test 3's ramp beside a walled tank with a hydrostatic start).
#[test]
fn thermal_expansion_by_density_law_and_program() {
    // Three cycles in the 200 steps: the sine through all its quadrants.
    assert_bit_identical(
        "thermal_cycle_drop_2d",
        &["phases.fluid.temperature_program.period=0.025"],
        200,
    );
    assert_bit_identical(
        "column_expansion_2d",
        &[
            "simulation.dx=0.1",
            "phases.lower.temperature_program.rate=1000.0",
        ],
        200,
    );
    // R18 Test 2's growing amplitude (fast enough to matter within the steps).
    assert_bit_identical(
        "rising_amplitude_drop_2d",
        &[
            "simulation.dx=0.1",
            "run.end_time=0.1",
            "phases.fluid.temperature_program.period=0.025",
            "phases.fluid.temperature_program.amplitude_rate=5000.0",
        ],
        200,
    );
}

/// R18 Test 4's raw-ρ density diffusion (across the two fluids) beside the
/// compatible one, on the sinking blob at half resolution.
#[test]
fn density_diffusion_raw_and_compatible_on_the_sinking_blob() {
    assert_bit_identical(
        "sinking_blob_2d",
        &["simulation.dx=0.04", "simulation.density_diffusion=\"raw\""],
        200,
    );
    assert_bit_identical("sinking_blob_2d", &["simulation.dx=0.04"], 200);
}

/// R18 (4.2)'s Sahoo law (portable exp and ln inside the surface force) on the
/// README's line melt (δ-SPH, free-surface tension, Marangoni), its plate
/// started near the solidus so the melt and its tension appear within the steps.
#[test]
fn sahoo_surface_tension_on_the_line_melt() {
    assert_bit_identical_at(
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/pbf/line_melt_coarse_2d.toml"
        ),
        &[
            "surface_tension.sahoo={ surface_excess = 1.3e-8, segregation_constant = 0.0032, activity = 0.0022, adsorption_enthalpy = -1.66e5 }",
            "phases.plate.temperature=1650.0",
            "laser.power=[[0.0, 4.0e6]]",
        ],
        150,
    );
}

/// The hardware comparison (by tolerance, each pass started from the CPU state) run
/// on the software adapter: loading the CPU state into the device before a pass must
/// leave nothing behind, so every pass and the free-running step differ by exactly 0.
#[test]
fn tolerance_mode_is_exact_on_the_software_adapter() {
    let l = load(&common::scene("dam_break_3d"), &[]).unwrap();
    let params = Params::new(&l.model, l.state.len() as u32);
    std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    let ctx = GpuContext::open(AdapterChoice::AnyGpu, false).expect("a Vulkan adapter");
    let mut gpu = GpuBackend::new(ctx, params, &l.state, false).unwrap();
    let mut cpu = CpuBackend::new(params, l.state.clone());
    let report = compare(
        &mut cpu,
        &mut gpu,
        5,
        &CompareMode::Tolerance(ToleranceScales::new(&params)),
    )
    .unwrap();
    let stages = spatter::backend::Pipeline::for_scene(&params, &l.state);
    assert_eq!(
        report.per_pass.len(),
        stages.step.len(),
        "every pass reported"
    );
    for d in &report.max_rel {
        assert_eq!(d.relative, 0.0, "free-running step, {}", d.field);
    }
    for p in &report.per_pass {
        assert_eq!(p.largest.relative, 0.0, "pass {}", p.pass);
    }
}

/// CSF surface tension with gas particles (curvature, the liquid's
/// force), isothermal, 200 steps of the Laplace disc.
#[test]
fn surface_tension_static_drop_200_steps() {
    assert_bit_identical("laplace_disc_2d", &[], 200);
}

/// The same drop hot inside a colder gas, with α(T), its clip at α_min, the F22
/// (21) ramp above the liquid's solidus and the Marangoni term (∇T across and
/// along the interface): the liquid starts at 1716 K, where α is clipped, and its
/// surface cools below 1715 K, where it is not; the gas at 1500 K sits below the
/// ramp (f = 0), the liquid above it (f = 1). Every branch of the pass.
#[test]
fn surface_tension_with_temperature_200_steps() {
    let full = std::fs::read_to_string(common::scene("laplace_disc_2d")).unwrap();
    // Without the Laplace check (it needs a constant coefficient).
    let text = full[..full.find("[check]").unwrap()]
        .replace(
            "reference_pressure = 1000.0     # c = 1 m/s: sigma / R = 5 Pa is 0.5% of p0",
            "reference_pressure = 1000.0\nconductivity = 20.0\nheat_capacity = 500.0\nsolidus = 1690.0\nliquidus = 1700.0\nlatent_heat = 1.0e4",
        )
        .replace(
            "reference_pressure = 1000.0     # c = 3.2 m/s",
            "reference_pressure = 1000.0\nconductivity = 0.5\nheat_capacity = 500.0",
        )
        .replace(
            "kind = \"liquid\"\nmaterial = \"liquid\"",
            "kind = \"liquid\"\nmaterial = \"liquid\"\ntemperature = 1716.0",
        )
        .replace(
            "kind = \"gas\"\nmaterial = \"gas\"",
            "kind = \"gas\"\nmaterial = \"gas\"\ntemperature = 1500.0",
        )
        .replace(
            "coefficient = 0.1               # N/m",
            "coefficient = 0.1\ntemperature_coefficient = -2.0e-3\nreference_temperature = 1700.0\nminimum = 0.07\nmelting_width = 20.0",
        );
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("bitmatch_tension");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("hot_drop.toml");
    std::fs::write(&path, text).unwrap();
    assert_bit_identical_at(path.to_str().unwrap(), &[], 200);
}

/// Surface tension in the free-surface form (R18, no gas particles):
/// capped curvature, its smoothing, the force with ρ0; 200 steps of the free disc.
#[test]
fn free_surface_tension_static_drop_200_steps() {
    assert_bit_identical("laplace_free_disc_2d", &[], 200);
    // Disordered, so that particles inside the drop get normals and the tension
    // must skip them (a full support and a weak gradient: backend::cpu::
    // surface_forces::bears_tension).
    let path = common::scene("laplace_free_disc_2d");
    let st = bit_identical_state(&path, &["jitter=0.1"], 200);
    let l = spatter::run::load(&path, &["jitter=0.1".to_string()]).unwrap();
    let pr = spatter::params::Params::new(&l.model, st.len() as u32);
    let weak = pr.surfaces.interior_delta;
    assert!(weak > 0.0, "δ-SPH without gas skips interior particles");
    let n = st.len();
    let skipped = (0..st.active())
        .filter(|&i| {
            let delta = st.surface[i][spatter::state::S_DELTA];
            delta != 0.0
                && delta < weak
                && st.surface[n + i][spatter::state::S_SHEPARD] >= spatter::state::INTERIOR_SHEPARD
        })
        .count();
    assert!(
        skipped > 0,
        "no particle skipped by the tension at step 200"
    );
    // J22 (5)-(8)'s colour Laplacian in place of CSF (on δ-SPH, where its force
    // is not below the threshold everywhere).
    assert_bit_identical(
        "laplace_free_disc_2d",
        &["surface_tension.model=\"muller\""],
        200,
    );
}

/// The free-surface form with temperature: the drop at 1716 K sits on a floor
/// held at 1500 K (Dirichlet wall), so its surface cools along its length (the
/// Shepard-corrected ∇T with wall neighbours, the Marangoni term), crosses the
/// α_min clip and enters the F22 (21) ramp above the solidus.
#[test]
fn free_surface_tension_with_temperature_200_steps() {
    let full = std::fs::read_to_string(common::scene("laplace_free_disc_2d")).unwrap();
    let text = full[..full.find("[check]").unwrap()]
        .replace(
            "open_sides = [\"x_min\", \"x_max\", \"y_min\", \"y_max\"]",
            "open_sides = [\"x_min\", \"x_max\", \"y_max\"]\nwall_phase = \"floor\"",
        )
        .replace(
            "reference_pressure = 1000.0     # c = 1 m/s: sigma / R = 5 Pa is 0.5% of p0",
            "reference_pressure = 1000.0\nconductivity = 20.0\nheat_capacity = 500.0\nsolidus = 1690.0\nliquidus = 1700.0\nlatent_heat = 1.0e4",
        )
        .replace(
            "kind = \"liquid\"\nmaterial = \"liquid\"",
            "kind = \"liquid\"\nmaterial = \"liquid\"\ntemperature = 1716.0\n\n[phases.floor]\nkind = \"wall\"\nmaterial = \"liquid\"\ntemperature = 1500.0",
        )
        .replace("center = [0.04, 0.04]", "center = [0.04, 0.021]")
        .replace(
            "coefficient = 0.1               # N/m",
            "coefficient = 0.1\ntemperature_coefficient = -2.0e-3\nreference_temperature = 1700.0\nminimum = 0.07\nmelting_width = 20.0",
        );
    let dir = common::scratch("bitmatch_free_tension");
    let path = dir.join("hot_sessile_drop.toml");
    std::fs::write(&path, text).unwrap();
    assert_bit_identical_at(path.to_str().unwrap(), &[], 200);
}

/// The line-melt scene with every force it has (the README's
/// first command: heat, melting, the surface laser, evaporation, recoil, surface
/// tension with Marangoni in the free-surface form, on δ-SPH, with R18 §4.4's
/// rule for thin layers), 200 steps. The plate starts
/// at 1650 K under 4e6 W/m so that within the 200 steps (14 µs) it melts and
/// passes T_v (3359 K measured, recoil power 18 W/m): at the scene's own start
/// nothing has melted yet by then.
#[test]
fn line_melt_with_every_force_200_steps() {
    let path = format!(
        "{}/scenarios/pbf/line_melt_coarse_2d.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    // R18 §4.4's thin-layer rule on: the melt starts as a film of a row or two.
    let sets = [
        "phases.plate.temperature=1650.0",
        "laser.power=[[0.0, 4.0e6]]",
        "surface_tension.thin_layer_rows=2",
    ];
    let st = bit_identical_state(&path, &sets, 200);
    let n = st.len();
    let thin = (0..n)
        .filter(|&i| st.surface[n + i][spatter::state::S_THIN] != 0.0)
        .count();
    assert!(thin > 0, "no particle of a thin layer at step 200");
}

/// The ray-traced laser (Fresnel absorption with reflections) in the line melt
/// with every force, as above, 200 steps: the plate melts and its surface
/// moves under the rays; the bins' integer counts make each bin's power the
/// same in any thread order.
#[test]
fn line_melt_with_ray_traced_laser_200_steps() {
    let text = ray_traced(
        &std::fs::read_to_string(format!(
            "{}/scenarios/pbf/line_melt_coarse_2d.toml",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap(),
    );
    let sets = [
        "phases.plate.temperature=1650.0",
        "laser.power=[[0.0, 4.0e6]]",
    ];
    let st = bit_identical_text_with("line_melt_ray_traced", &text, &sets, 200);
    let c = &st.laser_rays;
    assert!(c[spatter::state::RAYS_ABSORBED] > 0, "{c:?}");
    assert_eq!(
        c[spatter::state::RAYS_INCIDENT] as u64,
        c[spatter::state::RAYS_ABSORBED] as u64 + c[spatter::state::RAYS_LEAVING] as u64
    );
    assert!(st.heat.iter().any(|h| h[2] > 0.0), "nothing melted");
}

/// The same on the small 3D melt block, 200 steps.
#[test]
fn melt_block_3d_ray_traced_200_steps() {
    let text = ray_traced(&melt_block_small_3d());
    assert_bit_identical_text("melt_block_small_3d_ray_traced", &text, 200);
}

/// A laser scene's text with the ray-traced model in place of its own: its
/// absorptivity line and its check (which compare with a fixed ζ) go, and each
/// material takes nickel's (n, k) at 1.07 µm.
fn ray_traced(text: &str) -> String {
    let mut out = String::new();
    let mut in_check = false;
    for line in text.lines() {
        let t = line.trim_start();
        if t.starts_with('[') {
            in_check = t.starts_with("[check]");
        }
        if in_check || t.starts_with("absorptivity") || t.starts_with("absorption_coefficient") {
            continue;
        }
        if t.starts_with("model = \"gaussian_surface\"")
            || t.starts_with("model = \"beer_lambert\"")
        {
            out.push_str("model = \"ray_traced\"\n");
            continue;
        }
        out.push_str(line);
        out.push('\n');
        if t.starts_with("[materials.") {
            out.push_str("refractive_index = [2.88, 5.26]\n");
        }
    }
    assert!(out.contains("ray_traced"), "no laser model to replace");
    out
}

/// Wetting by a prescribed normal (F22 (27)–(29)), the sessile
/// drop at 60° spreading on its wall, 200 steps.
#[test]
fn wetting_sessile_drop_200_steps() {
    assert_bit_identical(
        "sessile_drop_2d",
        &["surface_tension.contact_angle=60.0"],
        200,
    );
}

/// Wetting at a free surface (no gas) with F22 (31)-(32)'s interface viscosity
/// on the free-surface δ: the gas-free sessile drop at 60° with α_0^lg = 1,
/// 200 steps.
#[test]
fn free_surface_wetting_and_interface_viscosity_200_steps() {
    assert_bit_identical(
        "sessile_free_drop_2d",
        &[
            "surface_tension.contact_angle=60.0",
            "simulation.interface_viscosity=1.0",
        ],
        200,
    );
}

/// The thermocapillary channel (Marangoni flow between a wall
/// heated as a cosine and a cold one), 200 steps: every Dirichlet wall particle
/// mirrors its own fixed temperature (heat.x), the Marangoni term along a flat
/// interface, conduction through both fluids.
#[test]
fn thermocapillary_channel_200_steps() {
    assert_bit_identical("thermocapillary_2d", &[], 200);
}

/// Per-phase contact angles: the sessile drop straddles two floor phases (60°
/// on the left, 120° on the right), so the wetting pass averages the two
/// angles' directions near the seam; 200 steps.
#[test]
fn wetting_two_floor_phases_200_steps() {
    let full = std::fs::read_to_string(common::scene("sessile_drop_2d")).unwrap();
    let text = full[..full.find("[check]").unwrap()]
        .replace("min = [0.0, 0.0]\nmax = [0.12, 0.06]", "min = [0.0, -0.0061]\nmax = [0.12, 0.06]")
        .replace(
            "[[shapes]]\nphase = \"gas\"",
            "[phases.patch]\nkind = \"wall\"\nmaterial = \"liquid\"\n\n\
             [[shapes]]\nphase = \"substrate\"\nbox = { min = [0.0, -0.0061], max = [0.06, 0.0] }\n\n\
             [[shapes]]\nphase = \"patch\"\nbox = { min = [0.06, -0.0061], max = [0.12, 0.0] }\n\n\
             [[shapes]]\nphase = \"gas\"",
        )
        .replace(
            "contact_angle = 90.0            # degrees",
            "contact_angle = { substrate = 60.0, patch = 120.0 }",
        );
    assert!(text.contains("patch = 120.0") && text.contains("max = [0.12, 0.0]"));
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("bitmatch_wetting");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("two_floors.toml");
    std::fs::write(&path, text).unwrap();
    assert_bit_identical_at(path.to_str().unwrap(), &[], 200);
}

/// The 2D tank of water with four rigid bodies (without its [run] table).
const TANK_2D: &str = r#"
[simulation]
dimension = 2
kernel = "quintic"
dx = 0.01
gravity = [0.0, -9.81]
pressure_floor = true

[domain]
min = [0.0, 0.0]
max = [0.4, 0.4]
wall_phase = "wall"
open_sides = ["y_max"]

[materials.liquid]
density = 1000.0
viscosity = 1.0
sound_speed = 30.0

[materials.solid]
density = 2000.0
viscosity = 0.0
sound_speed = 30.0

[phases.water]
kind = "liquid"
material = "liquid"

[phases.wall]
kind = "wall"
material = "liquid"

[phases.grain]
kind = "wall"
material = "solid"

[contact]
stiffness = 1.0e5
damping = 50.0

[[shapes]]
phase = "water"
box = { min = [0.0, 0.0], max = [0.4, 0.2] }

[[shapes]]
phase = "grain"
body = true
box = { min = [0.05, 0.22], max = [0.1, 0.26] }
velocity = [1.0, -0.5]
angular_velocity = [4.0]

[[shapes]]
phase = "grain"
body = true
box = { min = [0.1, 0.22], max = [0.13, 0.28] }
velocity = [-1.0, 0.0]
angular_velocity = [-3.0]

[[shapes]]
phase = "grain"
body = true
sphere = { center = [0.3, 0.035], radius = 0.025 }
velocity = [0.3, -1.0]

[[shapes]]
phase = "grain"
body = true
box = { min = [0.2, 0.19], max = [0.26, 0.23] }
velocity = [0.0, -0.8]
angular_velocity = [1.0]

"#;

/// Rigid bodies in a 2D tank of water, 200 steps. Two boxes side by
/// side spin and move into each other, a disc is thrown at the floor and a
/// third box falls into the water: contact between bodies and with walls from
/// the first steps, the fluid's reaction on every body particle near water,
/// Newton–Euler with quaternions, the per-body sums and the wall pass's body
/// velocities.
#[test]
fn rigid_bodies_in_a_tank_2d_200_steps() {
    let text = format!("{TANK_2D}[run]\nsteps = 200\n");
    assert_bit_identical_text("bodies_tank_2d", &text, 200);
}

/// A rigid disc thrown up through the tank's open top: body_drift marks the
/// body as left once its centre crosses the open face, body_place stamps its
/// members with the time, and the sort removes them (wall-kind particles with
/// w > 0) on both twins; the other bodies carry on.
#[test]
fn rigid_body_leaves_through_an_open_side_2d() {
    let text = format!(
        "{TANK_2D}[[shapes]]
phase = \"grain\"
body = true
sphere = {{ center = [0.34, 0.37], radius = 0.015 }}
velocity = [0.0, 4.0]

[run]
steps = 200
"
    );
    let st = assert_bit_identical_text("bodies_leave_2d", &text, 200);
    let thrown = &st.bodies[4];
    assert!(
        thrown.left(),
        "the thrown disc has not left: {:?}",
        thrown.x
    );
    assert_eq!(
        st.sim.removed, thrown.count,
        "its members are the removed ones"
    );
    assert!(
        st.bodies[..4].iter().all(|b| b.moves()),
        "the others still move"
    );
}

/// Rigid bodies in 3D, 200 steps: a tumbling block hits a sphere, a
/// second block lands on the floor beside a pool of water.
#[test]
fn rigid_bodies_3d_200_steps() {
    let text = r#"
[simulation]
dimension = 3
kernel = "wendland_c2"
h_over_dx = 1.2
dx = 0.02
gravity = [0.0, 0.0, -9.81]
pressure_floor = true

[domain]
min = [0.0, 0.0, 0.0]
max = [0.3, 0.2, 0.3]
wall_phase = "wall"
open_sides = ["z_max"]

[materials.liquid]
density = 1000.0
viscosity = 1.0
sound_speed = 20.0

[materials.solid]
density = 3000.0
viscosity = 0.0
sound_speed = 20.0

[phases.water]
kind = "liquid"
material = "liquid"

[phases.wall]
kind = "wall"
material = "liquid"

[phases.grain]
kind = "wall"
material = "solid"

[contact]
stiffness = 1.0e6
damping = 100.0

[[shapes]]
phase = "water"
box = { min = [0.0, 0.0, 0.0], max = [0.14, 0.2, 0.1] }

[[shapes]]
phase = "grain"
body = true
box = { min = [0.04, 0.04, 0.12], max = [0.1, 0.1, 0.2] }
velocity = [1.0, 0.2, -0.5]
angular_velocity = [3.0, -2.0, 5.0]

[[shapes]]
phase = "grain"
body = true
sphere = { center = [0.15, 0.09, 0.17], radius = 0.03 }
velocity = [-0.5, 0.0, 0.0]

[[shapes]]
phase = "grain"
body = true
box = { min = [0.2, 0.06, 0.0], max = [0.26, 0.14, 0.06] }
velocity = [0.0, 0.0, -1.0]
angular_velocity = [0.0, 1.0, 0.0]

[run]
steps = 200
"#;
    assert_bit_identical_text("bodies_3d", text, 200);
}

/// The same for a scene given as TOML text (written to a scratch file `name`).
fn assert_bit_identical_text(name: &str, text: &str, steps: u64) -> spatter::state::State {
    bit_identical_text_with(name, text, &[], steps)
}

/// The same with `--set` overrides.
fn bit_identical_text_with(
    name: &str,
    text: &str,
    sets: &[&str],
    steps: u64,
) -> spatter::state::State {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("bitmatch_bodies");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    bit_identical_state(path.to_str().unwrap(), sets, steps)
}

/// A rigid grain melting in a pool (the melting-grain check's
/// scene with the grain just below its solidus, so that 10 of its 52 particles
/// leave in 200 steps): body_melt's departures (material velocity, own force),
/// the recomputed mass, centre and principal axes (f32 Jacobi) and F22 (37);
/// with F22 (33)'s solid–fluid viscosity and F22 (34)'s barrier on, whose
/// reactions the body pass sums.
#[test]
fn melting_grain_2d_200_steps() {
    let st = bit_identical_state(
        &common::scene("melting_grain_2d"),
        &[
            "phases.grain.temperature=1690.0",
            "simulation.solid_fluid_viscosity={coefficient=1.0, width=300.0}",
            // The barrier's reaction on the grain too.
            "simulation.barrier={radius_dx=0.9, stiffness=1.0e4, damping=1.0e-2}",
        ],
        200,
    );
    let b = st.bodies[0];
    assert!(b.count < b.initial_count && b.count > 0, "{b:?}");
}

/// Melt that solidifies against rigid grains bonds them into
/// the substrate (body_bond, then body_melt's bonding), 200 steps: a cold grain
/// resting on a cold plate under a layer of melt at 1750 K; a second grain
/// falls towards the melt.
#[test]
fn bonding_grains_2d_200_steps() {
    let text = common::BONDING_2D;
    let st = assert_bit_identical_text("bonding_2d", text, 200);
    assert_eq!(st.bodies[0].bonded, 1, "the grain in the melt bonded");
    assert_eq!(st.bodies[1].bonded, 0, "the falling grain is still free");
}

/// In 3D: a grain just below its solidus in a pool of melt at
/// 2500 K, weightless, 200 steps: departures and the full 3D Jacobi (every
/// off-diagonal entry is non-zero once members leave unevenly).
#[test]
fn melting_grain_3d_200_steps() {
    let text = r#"
[simulation]
dimension = 3
kernel = "wendland_c2"
h_over_dx = 1.2
dx = 5.0e-6
gravity = [0.0, 0.0, 0.0]
pressure_floor = true

[domain]
min = [0.0, 0.0, 0.0]
max = [1.2e-4, 8.0e-5, 8.0e-5]
wall_phase = "wall"
open_sides = ["x_min", "x_max", "y_min", "y_max", "z_min", "z_max"]

[materials.steel]
density = 7430.0
viscosity = 6.0e-3
sound_speed = 10.0
conductivity = 35.95
heat_capacity = 965.0
solidus = 1695.0
liquidus = 1705.0
latent_heat = 2.7e5

[phases.grain]
kind = "solid"
material = "steel"
temperature = 1690.0
melts_into = "melt"

[phases.melt]
kind = "liquid"
material = "steel"
temperature = 2500.0

[phases.wall]
kind = "wall"
material = "steel"

[contact]
stiffness = 1000.0
damping = 0.0

[[shapes]]
phase = "melt"
sphere = { center = [7.0e-5, 4.0e-5, 4.0e-5], radius = 2.5e-5 }

[[shapes]]
phase = "grain"
body = true
velocity = [0.5, 0.1, 0.0]
angular_velocity = [0.0, 2.0e4, 1.0e4]
sphere = { center = [3.4e-5, 4.2e-5, 3.9e-5], radius = 1.2e-5 }

[run]
steps = 200
"#;
    let st = assert_bit_identical_text("melting_grain_3d", text, 200);
    let b = st.bodies[0];
    assert!(b.count < b.initial_count, "{b:?}");
}

/// A bed of 1000 rigid grains (the bed-at-rest scene widened to
/// 2.4 mm and poured with exactly 1000 grains: 2D, 16–32 µm discs at Δx = 5 µm,
/// 18 278 particles), 200 steps: contact between grains and with the holder,
/// per-body sums over 1000 bodies.
#[test]
fn powder_bed_of_1000_rigid_grains_200_steps() {
    let sets = [
        "domain.max=[2.4e-3, 3.5e-4]",
        "powder.box={min = [0.0, 0.0], max = [2.4e-3, 1.0e-4]}",
        "powder.max_grains=1000",
    ];
    let l = load(
        &common::scene("powder_bed_at_rest_2d"),
        &sets.map(String::from),
    )
    .unwrap();
    assert_eq!(l.state.bodies.len(), 1000);
    assert_bit_identical("powder_bed_at_rest_2d", &sets, 200);
}

const DFSPH: &str = "simulation.formulation=\"dfsph\"";

/// A DFSPH droplet with heat hits a cold free-slip wall (J22's
/// Fluent case, 2D at Δx = 4 µm): the implicit viscosity with XSPH, J22's
/// cohesion and adhesion, the free-surface tension, the conduction into the
/// Dirichlet wall and the mushy-zone sink as the melt freezes, 150 steps (the
/// impact at about 100).
#[test]
fn dfsph_spray_droplet_150_steps() {
    let path = format!(
        "{}/scenarios/spray/j22_fluent_case_2d.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    assert_bit_identical_at(
        &path,
        &[
            "dx=4e-6",
            "simulation.dfsph={ xsph = 0.3, max_iterations = 20, viscosity_max_iterations = 20, \
             cohesion = 2e14, adhesion = 1e14 }",
        ],
        150,
    );
    // J22's kernel (the cubic spline at h = Δx) over one Akinci boundary layer
    // (wall masses ρ0/Σ_b W from setup, the same bits on both sides).
    assert_bit_identical_at(
        &path,
        &[
            "dx=4e-6",
            "simulation.kernel=\"cubic\"",
            "simulation.h_over_dx=1.0",
            "simulation.dfsph={ xsph = 0.3, max_iterations = 20, viscosity_max_iterations = 20, \
             boundary = \"akinci\" }",
        ],
        150,
    );
}

/// DFSPH's factor, both pressure solves and the implicit viscosity
/// with XSPH (repeats: every iteration's dispatches, the tree-summed
/// residuals and dot products, the converged flags), the walls' head and
/// no-slip velocities, predict and drift: a 2D dam break (free surface,
/// walls) and a 3D one, with a bound of 20 iterations so the recorded passes
/// stay few; the Poiseuille channel with Weiler's projected viscosity.
#[test]
fn dfsph_dam_break_2d_and_3d_200_steps() {
    let sets = [
        DFSPH,
        "simulation.pressure_floor=false",
        "simulation.initial_pressure=\"zero\"",
        "simulation.dfsph={ max_iterations = 20, viscosity_max_iterations = 20, xsph = 0.3 }",
    ];
    assert_bit_identical(
        "poiseuille_dfsph_2d",
        &["simulation.viscosity_form=\"marrone\""],
        20,
    );
    let mut with_dx = sets.to_vec();
    with_dx.push("dx=0.005");
    assert_bit_identical("dam_break_2d", &with_dx, 200);
    let mut coarse = sets.to_vec();
    coarse.push("dx=0.04");
    assert_bit_identical("dam_break_3d", &coarse, 200);
}

/// The divergence solve skips a particle with fewer than a
/// quarter of the lattice's neighbours (spray) on both twins: a lone pair
/// meeting at 2.999 Δx, where the solve without the rule read 4e15 Pa.
#[test]
fn dfsph_lone_pair_skips_the_divergence_solve_on_both_twins() {
    let path = common::scratch("bitmatch_lone_pair").join("lone_pair.toml");
    std::fs::write(&path, common::DFSPH_LONE_PAIR).unwrap();
    let st = bit_identical_prepared(path.to_str().unwrap(), &[], 12, |st| {
        common::close_lone_pair(st, 2.999);
    });
    assert!(st.press.iter().all(|&p| p == 0.0), "{:?}", st.press);
}

/// The timestep pass lands on the run's end (`Sim::end_time`, which the run
/// loop sets): within 8 steps of it the time left is shared out in equal
/// steps, the last ending on it, and after it the steps go on unclamped (the
/// run loop stops there; `compare` does not). The same bits on both twins, on
/// WCSPH's and on DFSPH's step.
#[test]
fn timestep_lands_on_the_end_time_on_both_twins() {
    use spatter::backend::Backend;
    let end_code = spatter::model::limits::Limit::End.code();
    let dfsph = [
        DFSPH,
        "simulation.pressure_floor=false",
        "simulation.initial_pressure=\"zero\"",
        "simulation.dfsph={ max_iterations = 20, viscosity_max_iterations = 20 }",
        "dx=0.01",
    ];
    for sets in [&["dx=0.01"][..], &dfsph[..]] {
        let path = common::scene("dam_break_2d");
        let owned: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let l = load(&path, &owned).unwrap();
        let params = Params::new(&l.model, l.state.len() as u32);
        // An end between steps 20 and 21 of the unclamped run.
        let mut probe = CpuBackend::new(params, l.state.clone());
        probe.prime();
        probe.run_steps(20);
        let sim = probe.read_sim().unwrap();
        let end = sim.time + 0.37 * sim.dt;
        let st = bit_identical_prepared(&path, sets, 30, |st| st.sim.end_time = end);
        // Replay on the CPU: the run reaches the end exactly, on a shortened step.
        let mut prepared = l.state.clone();
        prepared.sim.end_time = end;
        let mut cpu = CpuBackend::new(params, prepared);
        cpu.prime();
        let (mut landed, mut shortened) = (false, 0);
        for _ in 0..30 {
            let before = cpu.read_sim().unwrap();
            shortened += (before.dt_limit == end_code) as u32;
            cpu.run_steps(1);
            landed |= cpu.read_sim().unwrap().time == end;
        }
        assert!(landed, "{sets:?}: never at t = {end:e}");
        // Eight or nine at a steady limit; more where the flow shortens it meanwhile.
        assert!(shortened >= 8, "{sets:?}: {shortened} shortened steps");
        assert!(st.sim.time > end, "{sets:?}: the steps after the end go on");
    }
}

/// The ray-traced laser's reflections: a 90° groove in the nickel plate (its
/// particles handed to the non-absorbing wall phase), the beam on its left
/// wall, so every ray reflects across and hits the right wall (tests/laser_rays.rs
/// checks the total against Fresnel), 20 steps.
#[test]
fn ray_traced_groove_reflections_20_steps() {
    let path = common::scene("laser_ray_plate");
    let l = load(&path, &[]).unwrap();
    let id = |name: &str| l.model.phases.iter().position(|p| p.name == name).unwrap() as u32;
    let (plate, void) = (id("plate"), id("insulation"));
    let sets = ["laser.radius=1.5e-5", "laser.path=[[0.0, 1.6e-4]]"];
    let st = bit_identical_prepared(&path, &sets, 20, |st| {
        for i in 0..st.len() {
            let p = st.pos[i];
            if st.phase[i] == plate && p[1] > 7.0e-5 + (p[0] - 2.0e-4).abs() {
                st.phase[i] = void;
            }
        }
    });
    assert!(st.laser_rays[spatter::state::RAYS_ABSORBED] > 0);
}
