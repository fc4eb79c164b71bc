//! Every malformed scenario in tests/bad_input/ exits with code 2 and a message that
//! names the file and the key (listed in expected.txt), never a panic.

mod common;
use common::{spatter, text};

#[test]
fn malformed_scenarios_exit_2_naming_the_key() {
    let dir = format!("{}/tests/bad_input", env!("CARGO_MANIFEST_DIR"));
    let expected = std::fs::read_to_string(format!("{dir}/expected.txt")).unwrap();
    let mut checked = 0;
    for line in expected.lines() {
        let (file, key) = line.split_once(' ').unwrap();
        let path = format!("{dir}/{file}");
        for cmd in ["validate", "run"] {
            let out =
                spatter(&[cmd, &path, "--backend", "cpu"][..if cmd == "run" { 4 } else { 2 }]);
            let (stdout, stderr) = text(&out);
            assert_eq!(
                out.status.code(),
                Some(2),
                "{cmd} {file}: exit {:?}\n{stdout}{stderr}",
                out.status.code()
            );
            assert!(
                stderr.contains(file),
                "{file}: message does not name the file: {stderr}"
            );
            assert!(
                stderr.contains(key),
                "{file}: message does not name `{key}`: {stderr}"
            );
            assert!(!stderr.contains("panicked"), "{file}: panicked: {stderr}");
        }
        checked += 1;
    }
    assert!(checked >= 12, "only {checked} malformed scenarios");
}

#[test]
fn bad_overrides_exit_2() {
    let scene = common::scene("poiseuille_2d");
    for (set, key) in [
        ("dx=-1", "simulation.dx"),
        ("materials.fluid.density=0", "materials.fluid.density"),
        ("noequals", "noequals"),
        // An array-of-tables entry that is not there, or no such array.
        ("shapes[7].velocity=[0.0,0.0]", "shapes[7].velocity"),
        ("powder[0].seed=2", "powder[0].seed"),
        // Malformed indices, and an index with no key after it.
        ("shapes[-1].velocity=[0.0,0.0]", "shapes[-1].velocity"),
        ("shapes[].velocity=[0.0,0.0]", "shapes[].velocity"),
        ("shapes[0]x.velocity=[0.0,0.0]", "shapes[0]x.velocity"),
        ("shapes[0]=1", "shapes[0]"),
        // a check's key of the wrong type; a whole [check] given inline
        ("check.tolerance=\"tight\"", "check.tolerance"),
        (
            "check={ kind = \"hydrostatic\", tolerance = 0.02 }",
            "check.surface",
        ),
    ] {
        let out = spatter(&["validate", &scene, "--set", set]);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "--set {set}: {stderr}");
        assert!(stderr.contains(key), "--set {set}: {stderr}");
    }
}

/// A key in a check's sub-table is named with its table.
#[test]
fn a_nested_check_key_is_named_whole() {
    common::assert_input_error(
        &[
            "validate",
            &common::scene_at("pbf/amb2018_02_c"),
            "--set",
            "check.measured.depth=\"deep\"",
        ],
        "check.measured.depth",
    );
}

#[test]
fn missing_file_exits_2() {
    let out = spatter(&["validate", "/nonexistent/scene.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out).1.contains("/nonexistent/scene.toml"));
}

/// The formulation and heat-integration keys (δ-SPH's `simulation.delta`,
/// `density_diffusion` and `viscosity_form`; `[heat]`'s integrator and its
/// iterations): each wrong combination exits 2 naming its key; δ-SPH with a
/// pressure floor validates with a warning naming `simulation.pressure_floor`.
#[test]
fn formulation_and_heat_integration_keys() {
    let dam = common::scene("dam_break_2d");
    let heat = common::scene("conduction_1d");
    let delta = "simulation.formulation=\"delta_wcsph\"";
    let cases: [(&str, &[&str], &str); 7] = [
        (&dam, &["simulation.delta=0.1"], "simulation.delta"),
        (
            &dam,
            &["simulation.density_diffusion=\"raw\""],
            "simulation.density_diffusion",
        ),
        (
            &dam,
            &[delta, "simulation.density_diffusion=\"smooth\""],
            "simulation.density_diffusion",
        ),
        (&dam, &[delta, "simulation.delta=1.5"], "simulation.delta"),
        (
            &dam,
            &["simulation.viscosity_form=\"marrone\""],
            "simulation.viscosity_form",
        ),
        (&dam, &["heat.integrator=\"trapezoidal\""], "key `heat`"),
        (&heat, &["heat.max_iterations=0"], "heat.max_iterations"),
    ];
    for (scene, sets, key) in cases {
        let mut args = vec!["validate", scene];
        for s in sets {
            args.extend(["--set", s]);
        }
        common::assert_input_error(&args, key);
    }
    let out = spatter(&[
        "validate",
        &common::scene("laplace_free_disc_2d"),
        "--set",
        "simulation.pressure_floor=true",
    ]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stdout}{stderr}");
    assert!(
        format!("{stdout}{stderr}").contains("key `simulation.pressure_floor`"),
        "{stdout}{stderr}"
    );
}

/// Thermal expansion's keys: a density law needs δ-SPH, a fluid phase with a
/// temperature, 2..8 points of rising temperature; a temperature program needs
/// a non-melting phase, an amplitude a period, the explicit heat step.
#[test]
fn density_law_and_temperature_program_keys() {
    let drop = common::scene("thermal_cycle_drop_2d");
    let column = common::scene("column_expansion_2d");
    let law = "materials.fluid.density_law";
    let rising = common::scene("rising_amplitude_drop_2d");
    let cases: [(&str, &[&str], &str); 10] = [
        (&drop, &["simulation.formulation=\"wcsph\""], law),
        (
            &drop,
            &["materials.fluid.density_law=[[300.0, 1000.0]]"],
            law,
        ),
        (
            &drop,
            &["materials.fluid.density_law=[[300.0, 1000.0], [250.0, 950.0]]"],
            law,
        ),
        (
            &drop,
            &["materials.fluid.density_law=[[300.0, -1.0], [350.0, 950.0]]"],
            law,
        ),
        (
            &drop,
            &["phases.fluid.temperature_program={ amplitude = 50.0 }"],
            "phases.fluid.temperature_program.period",
        ),
        (
            &drop,
            &["heat.integrator=\"trapezoidal\""],
            "phases.fluid.temperature_program",
        ),
        (
            &rising,
            &["phases.fluid.temperature_program.amplitude_rate=-1.0"],
            "phases.fluid.temperature_program.amplitude_rate",
        ),
        // 1000 K - 200 K/s x 10 s falls below 0 K.
        (
            &rising,
            &["phases.fluid.temperature_program.amplitude_rate=200.0"],
            "phases.fluid.temperature_program",
        ),
        (&rising, &["check.swing=0.0"], "check.swing"),
        (
            &column,
            &["materials.wall.density_law=[[300.0, 1000.0], [400.0, 900.0]]"],
            "materials.wall.density_law",
        ),
    ];
    for (scene, sets, key) in cases {
        let mut args = vec!["validate", scene];
        for s in sets {
            args.extend(["--set", s]);
        }
        common::assert_input_error(&args, key);
    }
}

/// R18 (4.2)'s solute term: positive constants, a negative heat of adsorption,
/// and a heat scene with the reference temperature T_m.
#[test]
fn sahoo_keys() {
    let melt = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/pbf/line_melt_coarse_2d.toml"
    );
    let sahoo = |gamma: &str, dh: &str| {
        format!("surface_tension.sahoo={{ surface_excess = {gamma}, segregation_constant = 0.0032, activity = 0.0022, adsorption_enthalpy = {dh} }}")
    };
    let cases = [
        (
            sahoo("-1.3e-8", "-1.66e5"),
            "surface_tension.sahoo.surface_excess",
        ),
        (
            sahoo("1.3e-8", "1.66e5"),
            "surface_tension.sahoo.adsorption_enthalpy",
        ),
    ];
    for (set, key) in &cases {
        common::assert_input_error(&["validate", melt, "--set", set], key);
    }
    let drop = common::scene("laplace_free_disc_2d");
    common::assert_input_error(
        &["validate", &drop, "--set", &sahoo("1.3e-8", "-1.66e5")],
        "surface_tension.sahoo.surface_excess",
    );
}

/// R18 §4.4's sound speed lowered ×5 on melting, as a key: the liquid phase a
/// solid melts into takes `phases.<name>.sound_speed` in place of its
/// material's, and the acoustic step limit follows it; a solid or wall phase has
/// none of its own.
#[test]
fn a_phase_takes_its_own_sound_speed() {
    let melt = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/pbf/line_melt_coarse_2d.toml"
    );
    let base = spatter::run::load(melt, &[]).unwrap().model;
    let slow = spatter::run::load(melt, &["phases.melt.sound_speed=7.34".into()])
        .unwrap()
        .model;
    let c = |m: &spatter::model::Model| {
        m.phases
            .iter()
            .find(|p| p.name == "melt")
            .unwrap()
            .sound_speed
    };
    assert_eq!((c(&base), c(&slow)), (36.7, 7.34));
    assert_eq!(slow.max_sound_speed(), 7.34);
    common::assert_input_error(
        &["validate", melt, "--set", "phases.plate.sound_speed=10.0"],
        "phases.plate.sound_speed",
    );
    common::assert_input_error(
        &["validate", melt, "--set", "phases.melt.sound_speed=-1.0"],
        "phases.melt.sound_speed",
    );
}
